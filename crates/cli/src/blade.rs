//! `cadmorph blade ...`: blades and propellers from design tables (cadmorph-blade).
//!
//! Self-contained so it can move into the CLI crate as it is: a clap [`BladeCommand`]
//! and [`run`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cadmorph::blade::export::{iges_solids, step_solids};
use cadmorph::blade::{errors_txt, export_ppg, reverse, BladeSolid, DesignTable, ParamFile, Propeller};
use cadmorph::model::write_atomic;
use cadmorph_report::chart::{Plot, PlotFormat};
use cadmorph_report::profiles::profiles_plot;
use cadmorph_report::radial::radial_law_plot;
use clap::Subcommand;

/// The blade subcommands.
#[derive(Subcommand)]
pub enum BladeCommand {
    /// Build the closed blade solid of a design table and write it as STEP or IGES.
    Build {
        /// The design table (TOML).
        table: PathBuf,
        /// Output `.stp`/`.step` or `.igs`/`.iges` (written through a temporary file).
        #[arg(short, long)]
        output: PathBuf,
        /// Deform the table's radial laws with a BladeX parameter file (`.prm`, or its `.toml` form) first.
        #[arg(long)]
        prm: Option<PathBuf>,
        /// RBF samples for fitting the radial laws (BladeX default 1000; 0 = none).
        #[arg(long, default_value_t = 1000)]
        rbf_points: usize,
        /// Also write BladeX's per-point error report (`errors.txt` layout) here.
        #[arg(long)]
        errors: Option<PathBuf>,
        /// Also write the blade in BladeX's `.ppg` layout here (diameter = 2 × tip radius).
        #[arg(long)]
        ppg: Option<PathBuf>,
        /// Print a JSON report (section errors, seam gaps, volume, area, timings).
        #[arg(long)]
        json: bool,
        /// Also write a plot of the blade's sections (`profiles.svg`, `profiles.png`) into
        /// this folder.
        #[arg(long)]
        plots: Option<PathBuf>,
    },
    /// Build a propeller (blades of the table around the x axis and a cylinder hub).
    Propeller {
        /// The design table (TOML) with a `[propeller]` table, or give `--blades`.
        table: PathBuf,
        /// Output `.stp` or `.igs`.
        #[arg(short, long)]
        output: PathBuf,
        /// Number of blades (overrides the table).
        #[arg(long)]
        blades: Option<usize>,
        /// Deform the radial laws with a BladeX parameter file first.
        #[arg(long)]
        prm: Option<PathBuf>,
        /// Print a JSON report.
        #[arg(long)]
        json: bool,
    },
    /// Recover sections at given radii from a blade STEP file written by `blade build`
    /// (its first two faces are the upper and lower faces): chord, pitch, rake, skew.
    Reverse {
        /// The blade file (`.stp`).
        input: PathBuf,
        /// Radii, comma-separated.
        #[arg(long, value_delimiter = ',', required = true)]
        radii: Vec<f64>,
        /// The blade was built without BladeX's reflection.
        #[arg(long)]
        no_reflect: bool,
        /// Points per side of each recovered section.
        #[arg(long, default_value_t = 50)]
        points: usize,
        /// Print JSON (with the section points) instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Apply a BladeX parameter file to its own radial distributions (BladeX
    /// `Deformation.compute_all`) and write the deformed parameter file.
    Deform {
        /// The `.prm` file.
        prm: PathBuf,
        /// The deformed parameter file.
        #[arg(short, long)]
        output: PathBuf,
        /// RBF samples (BladeX default 1000).
        #[arg(long, default_value_t = 1000)]
        rbf_points: usize,
        /// Sampling tolerance per law (chord, pitch, rake, skew, camber).
        #[arg(long, value_delimiter = ',', default_value = "1e-3,1e-3,1e-2,1e-2,1e-2")]
        tol: Vec<f64>,
        /// Also write a plot per radial law (`law_chord.svg` and `law_chord.png`, ...:
        /// original and deformed, with their control points) into this folder.
        #[arg(long)]
        plots: Option<PathBuf>,
    },
}

fn table(path: &Path, prm: Option<&Path>, rbf_points: usize) -> Result<DesignTable> {
    let mut t = DesignTable::read(path).with_context(|| format!("reading {}", path.display()))?;
    if let Some(p) = prm {
        let f = ParamFile::read_any(p).with_context(|| format!("reading {}", p.display()))?;
        t.deform(&f, rbf_points).with_context(|| format!("applying {}", p.display()))?;
    }
    Ok(t)
}

/// Writes `plot` as `dir/stem.svg` or `dir/stem.png` (creating `dir`) through the
/// atomic writer.
fn write_plot(dir: &Path, stem: &str, plot: &Plot) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let (path, bytes) = match plot {
        Plot::Svg(s) => (dir.join(format!("{stem}.svg")), s.as_bytes()),
        Plot::Png(p) => (dir.join(format!("{stem}.png")), p.as_slice()),
    };
    write_atomic(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

fn is_step(path: &Path) -> Result<bool> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("stp") | Some("step") => Ok(true),
        Some("igs") | Some("iges") => Ok(false),
        _ => bail!("{}: the output must end in .stp, .step, .igs or .iges", path.display()),
    }
}

/// Runs one blade subcommand.
///
/// # Errors
///
/// Unreadable or invalid tables and parameter files (the message names the field and
/// section, or the file line), unwritable outputs.
pub fn run(cmd: BladeCommand) -> Result<()> {
    match cmd {
        BladeCommand::Build { table: path, output, prm, rbf_points, errors, ppg, json, plots } => {
            let t0 = Instant::now();
            let t = table(&path, prm.as_deref(), rbf_points)?;
            let blade = t.blade()?;
            let coords = blade.apply_transformations(t.reflect)?;
            let solid = BladeSolid::from_coordinates(&coords, t.loft.u_degree, t.loft.v_degree)?;
            let t_build = t0.elapsed().as_secs_f64();
            let diameter = 2.0 * blade.radii[blade.len() - 1];
            let tol = 1e-9 * diameter;
            let bytes = if is_step(&output)? {
                step_solids(&t.name, &[solid.faces()], t.unit, tol)?
            } else {
                iges_solids(&[solid.faces()], t.unit, tol, None)
            };
            write_atomic(&output, &bytes)?;
            let t_total = t0.elapsed().as_secs_f64();
            if let Some(e) = &errors {
                write_atomic(e, errors_txt(&solid, &coords)?.as_bytes())?;
            }
            if let Some(p) = &ppg {
                write_atomic(p, export_ppg(&blade, diameter, 2.0 * blade.radii[0], 1, false)?.as_bytes())?;
            }
            if let Some(dir) = &plots {
                let named: Vec<(String, &cadmorph::blade::Profile)> =
                    blade.radii.iter().zip(&blade.sections).map(|(r, p)| (format!("r = {r}"), p)).collect();
                for format in [PlotFormat::Svg, PlotFormat::Png] {
                    let plot = profiles_plot(&format!("{} sections", t.name), &named, (900, 500), format)?;
                    write_plot(dir, "profiles", &plot)?;
                }
            }
            let sections = solid.section_errors(&coords)?;
            let worst = sections.iter().map(|s| s.upper.max(s.lower)).fold(0.0, f64::max);
            let seams = solid.seams(1e-6 * diameter, 100);
            let gaps = solid.edge_gaps(tol, 200);
            let max_gap = gaps.iter().map(|g| g.gap).fold(0.0, f64::max);
            if json {
                let out = serde_json::json!({
                    "output": output.display().to_string(),
                    "faces": solid.faces().len(),
                    "volume": solid.volume(),
                    "area": solid.area(),
                    "max_section_error": worst,
                    "section_errors": sections,
                    "edges": gaps,
                    "max_edge_gap": max_gap,
                    "cadmorph_seam": seams,
                    "build_s": t_build,
                    "total_s": t_total,
                });
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                println!(
                    "{} -> {}: {} faces, volume {:.9e}, area {:.9e}, max section error {:.3e}, {} edges (max gap {:.3e}), {:.1} ms",
                    path.display(),
                    output.display(),
                    solid.faces().len(),
                    solid.volume(),
                    solid.area(),
                    worst,
                    gaps.len(),
                    max_gap,
                    1e3 * t_total
                );
            }
            Ok(())
        }
        BladeCommand::Propeller { table: path, output, blades, prm, json } => {
            let t = table(&path, prm.as_deref(), 1000)?;
            let blade = t.blade()?;
            let spec = t.propeller.clone();
            let n = blades.or(spec.as_ref().map(|p| p.blades)).context("give --blades or a [propeller] table")?;
            let coords = blade.apply_transformations(t.reflect)?;
            let solid = BladeSolid::from_coordinates(&coords, t.loft.u_degree, t.loft.v_degree)?;
            let hub_r = spec.as_ref().and_then(|p| p.hub_radius).unwrap_or(blade.radii[0]);
            let cmax = blade.chord.iter().copied().fold(0.0, f64::max);
            let len = spec.as_ref().and_then(|p| p.hub_length).unwrap_or(3.0 * cmax);
            let p = Propeller::new(&solid, n, hub_r, -len / 2.0, len / 2.0)?;
            let diameter = 2.0 * blade.radii[blade.len() - 1];
            let tol = 1e-9 * diameter;
            let bytes = if is_step(&output)? {
                step_solids(&t.name, &p.solids(), t.unit, tol)?
            } else {
                iges_solids(&p.solids(), t.unit, tol, None)
            };
            write_atomic(&output, &bytes)?;
            let blade_v = solid.volume();
            if json {
                let out = serde_json::json!({
                    "output": output.display().to_string(),
                    "blades": n,
                    "solids": n + 1,
                    "blade_volume": blade_v,
                    "hub_volume": p.hub_volume(),
                    "hub_radius": hub_r,
                });
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                println!(
                    "{} -> {}: {n} blades (volume {blade_v:.9e} each) + hub, {} solids",
                    path.display(),
                    output.display(),
                    n + 1
                );
            }
            Ok(())
        }
        BladeCommand::Reverse { input, radii, no_reflect, points, json } => {
            let bytes = std::fs::read(&input).with_context(|| format!("reading {}", input.display()))?;
            let doc =
                cadmorph::step::Document::parse(&bytes).with_context(|| format!("reading {}", input.display()))?;
            let faces = doc.world_surfaces().with_context(|| format!("reading the faces of {}", input.display()))?;
            if faces.len() < 2 {
                bail!("{}: {} faces; a blade file has its upper and lower faces first", input.display(), faces.len());
            }
            let got = reverse(&faces[0].surface, &faces[1].surface, &radii, !no_reflect, points)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&got)?);
            } else {
                println!("{:>14} {:>14} {:>14} {:>14} {:>14}", "radius", "chord", "pitch", "rake", "skew[deg]");
                for s in &got {
                    println!(
                        "{:>14.9} {:>14.9} {:>14.9} {:>14.9} {:>14.9}",
                        s.radius, s.chord, s.pitch, s.rake, s.skew
                    );
                }
            }
            Ok(())
        }
        BladeCommand::Deform { prm, output, rbf_points, tol, plots } => {
            let f = ParamFile::read_any(&prm).with_context(|| format!("reading {}", prm.display()))?;
            let tol: [f64; 5] = tol.try_into().map_err(|_| anyhow::anyhow!("--tol takes five values"))?;
            let d = cadmorph::blade::Deformation::compute_all(f, rbf_points, tol)?;
            d.deformed_param_file().write(&output)?;
            if let Some(dir) = &plots {
                for law in &d.laws {
                    let deformed = d.deformed_laws.iter().find(|x| x.param == law.param);
                    for format in [PlotFormat::Svg, PlotFormat::Png] {
                        let plot = radial_law_plot(law, deformed, (720, 480), format)?;
                        write_plot(dir, &format!("law_{}", law.param.name()), &plot)?;
                    }
                }
            }
            println!("{} -> {}", prm.display(), output.display());
            Ok(())
        }
    }
}
