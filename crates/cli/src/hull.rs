//! `cadmorph hull volume|dims|chine` (exact volume and centroid of a closed model, LCB shift, the
//! planing-hull chine law) and the hook of
//! `cadmorph morph --ffd P --keep-volume --keep-barycentre`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cadmorph::model::{Model, Staged};
use cadmorph::morph::{Deformation, Ffd, LinearInParameters, Parameters};
use cadmorph_hull::{change_dimensions, chine, enclosed, keep, ChineLaw, DimsChange, Keep, KeepReport, Law, Side};

/// `cadmorph hull` subcommands.
#[derive(clap::Subcommand)]
pub enum HullCommand {
    /// Exact enclosed volume and centroid of a closed model (divergence theorem, Gauss
    /// quadrature on the faces; agrees with OCCT BRepGProp to 1e-12 on the samples).
    Volume {
        /// The input IGES or STEP file.
        input: PathBuf,
        /// Print the result as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Principal-dimension changes of a closed hull (x along the length, y across, z up),
    /// in this order: a Lackenby-style section shift (LCB and block coefficient, at the
    /// same length, beam and draft), the length by stretching the parallel middle body
    /// (bow and stern translated, kept in shape), beam and draft by scaling about the
    /// centreline and the baseline.
    Dims {
        /// The input IGES or STEP file (a closed hull).
        input: PathBuf,
        /// Move the LCB (the centroid of the enclosed volume) by this much along +x,
        /// model units.
        #[arg(long, allow_hyphen_values = true)]
        lcb_shift: Option<f64>,
        /// The new block coefficient V / (L B T), reached by moving sections along the
        /// length.
        #[arg(long)]
        block_coefficient: Option<f64>,
        /// The new length (the model's x extent), model units.
        #[arg(long)]
        length: Option<f64>,
        /// The parallel middle body the length change stretches, `X0,X1` (model units);
        /// without it the whole length scales about the aft end.
        #[arg(long, value_name = "X0,X1", allow_hyphen_values = true)]
        middle_body: Option<String>,
        /// The new beam (the y extent).
        #[arg(long)]
        beam: Option<f64>,
        /// The new draft (baseline to waterline).
        #[arg(long)]
        draft: Option<f64>,
        /// The waterline height z of the draft and block coefficient (default: the top
        /// of the model, right for an underwater body closed at its waterplane).
        #[arg(long, allow_hyphen_values = true)]
        waterline: Option<f64>,
        /// Largest distance of a face from the length stretch where it is not exact,
        /// model units (default 1e-7 × the model size).
        #[arg(long)]
        tol: Option<f64>,
        /// The output file (its extension names the format).
        #[arg(short, long)]
        output: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The planing-hull chine law (paper section 2.2.1): each transverse section's bottom
    /// rotates about the keel by θ(x), the chine strip follows the inner chine rigidly
    /// (optionally turning by φ(x)), the straight wall follows between the moved outer
    /// chine and its deck edge, the deck and everything above it stay. Keel and chine
    /// lines are the model's sharp edges along x (y to starboard, z up); faces are refined
    /// along the length until they are within --tol of the law.
    Chine {
        /// The input IGES or STEP file.
        input: PathBuf,
        /// θ along the length, degrees: control values of a B-spline law from the aft end
        /// (first) to the fore end (last), comma-separated; one value is a constant.
        /// Positive raises the chines (more deadrise).
        #[arg(long, allow_hyphen_values = true, value_name = "DEG,DEG,...")]
        theta: String,
        /// φ along the length, degrees: the chine strip's own rotation about the moved
        /// inner chine (double-chine hulls), same form as --theta.
        #[arg(long, allow_hyphen_values = true, value_name = "DEG,DEG,...")]
        chine_rotation: Option<String>,
        /// Largest distance of a morphed face from the law, model units (default 1e-7 ×
        /// the model size).
        #[arg(long)]
        tol: Option<f64>,
        /// The output file (its extension names the format).
        #[arg(short, long)]
        output: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// A law from the command line: comma-separated degrees.
fn law(arg: &str, what: &str) -> Result<Law> {
    let values = arg
        .split(',')
        .enumerate()
        .map(|(i, t)| {
            t.trim().parse::<f64>().map(f64::to_radians).map_err(|e| {
                anyhow::anyhow!("{what}: value {} ({:?}) is not a number of degrees: {e}", i + 1, t.trim())
            })
        })
        .collect::<Result<Vec<f64>>>()?;
    Law::new(&values).with_context(|| what.to_string())
}

/// The format an output's extension names (checked before any work is done).
fn output_format(output: &Path) -> Result<cadmorph::Format> {
    Ok(cadmorph::Format::from_extension(output)
        .ok_or_else(|| cadmorph::Error::UnknownExtension { path: output.to_path_buf() })?)
}

/// Writes the morphed model as `format` (converted when that is not its own), staged so a
/// failed write leaves nothing.
fn save_as(m: &Model, output: &Path, format: cadmorph::Format) -> Result<()> {
    let bytes = if format == m.format() { m.to_bytes() } else { cadmorph::convert(m, format)?.to_bytes() };
    Staged::new(output, &bytes)?.commit()?;
    Ok(())
}

/// Runs `cadmorph hull ...`.
pub fn run(cmd: HullCommand) -> Result<()> {
    match cmd {
        HullCommand::Volume { input, json } => {
            let m = cadmorph::open(&input)?;
            crate::skipped::check(&m.info().skipped, false)?;
            let e = enclosed(m.patches(), m.bound_curves(), m.size())
                .with_context(|| format!("the volume of {}", input.display()))?;
            let c = e.total.centroid();
            if json {
                let out = serde_json::json!({
                    "file": input.display().to_string(),
                    "unit": crate::units::json(m.units().metres_per_unit, m.unit()),
                    "volume": e.total.volume,
                    "area": e.total.area,
                    "centroid": [c.x, c.y, c.z],
                    "orientation": e.orientation,
                    "turned": e.turned.iter().map(|&i| m.patches()[i].entity.to_string()).collect::<Vec<_>>(),
                    "methods": e.methods,
                });
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                println!(
                    "{}: volume {:.12e} cubic {}, area {:.12e} square {2}, centroid ({:.9}, {:.9}, {:.9}); {} faces ({} planar trimmed)",
                    input.display(),
                    e.total.volume,
                    crate::units::words(m.units().metres_per_unit, m.unit()),
                    e.total.area,
                    c.x,
                    c.y,
                    c.z,
                    e.methods.len(),
                    e.methods.iter().filter(|k| **k == cadmorph_hull::FaceMethod::Planar).count()
                );
                if !e.turned.is_empty() {
                    println!(
                        "  {} faces carry no orientation the shell agrees with and were turned to close it: {}",
                        e.turned.len(),
                        e.turned.iter().map(|&i| m.patches()[i].entity.to_string()).collect::<Vec<_>>().join(", ")
                    );
                }
            }
            Ok(())
        }
        HullCommand::Chine { input, theta, chine_rotation, tol, output, json } => {
            let format = output_format(&output)?;
            let theta = law(&theta, "--theta")?;
            let phi = chine_rotation.as_deref().map(|a| law(a, "--chine-rotation")).transpose()?;
            let mut m = cadmorph::open(&input)?;
            crate::skipped::check(&m.info().skipped, false)?;
            let tol = tol.unwrap_or(1e-7 * m.size());
            let law = ChineLaw::new(&m, theta, phi)
                .with_context(|| format!("the chine law on {}; nothing written", input.display()))?;
            let (x0, x1) = law.x_range();
            let stations: Vec<f64> = (0..=4).map(|k| x0 + (x1 - x0) * k as f64 / 4.0).collect();
            let before: Vec<_> = stations.iter().map(|&x| law.section(x, Side::Starboard)).collect::<Result<_, _>>()?;
            let report = chine(&mut m, &law, tol)
                .with_context(|| format!("the chine law on {}; nothing written", input.display()))?;
            let gap = report.morph.seams_after.max_gap_closest;
            if gap > tol {
                bail!(
                    "the chine law opened a seam of {gap:.3e} {} (tolerance {tol:.3e}); nothing written",
                    crate::units::words(m.units().metres_per_unit, m.unit())
                );
            }
            save_as(&m, &output, format)?;
            if json {
                let sections: Vec<_> = stations
                    .iter()
                    .zip(&before)
                    .map(|(&x, s)| {
                        serde_json::json!({
                            "x": x,
                            "theta_deg": law.theta(x).to_degrees(),
                            "phi_deg": law.phi(x).to_degrees(),
                            "keel": [s.keel.x, s.keel.y, s.keel.z],
                            "inner_chine": [s.inner_chine.x, s.inner_chine.y, s.inner_chine.z],
                            "deck_edge": [s.deck_edge.x, s.deck_edge.y, s.deck_edge.z],
                        })
                    })
                    .collect();
                let out = serde_json::json!({
                    "input": input.display().to_string(),
                    "output": output.display().to_string(),
                    "unit": crate::units::json(m.units().metres_per_unit, m.unit()),
                    "lines": report.lines,
                    "rounds": report.rounds,
                    "control_points_before": report.control_points_before,
                    "control_points_after": report.control_points_after,
                    "max_deviation": report.max_deviation,
                    "tolerance": report.tolerance,
                    "max_gap_after": gap,
                    "sharp_edges_before": report.morph.seams_before.sharp_edges,
                    "sharp_edges_after": report.morph.seams_after.sharp_edges,
                    "sections": sections,
                });
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                println!(
                    "{} -> {}: chine law over x {x0} .. {x1} {} ({} keel/chine/deck lines); refined along the length in {} rounds, {} -> {} control points, within {:.3e} {} of the law; seams after: max gap {gap:.3e}, {} sharp edges (before {})",
                    input.display(),
                    output.display(),
                    crate::units::words(m.units().metres_per_unit, m.unit()),
                    report.lines.len(),
                    report.rounds,
                    report.control_points_before,
                    report.control_points_after,
                    report.max_deviation,
                    crate::units::words(m.units().metres_per_unit, m.unit()),
                    report.morph.seams_after.sharp_edges,
                    report.morph.seams_before.sharp_edges
                );
                for &x in &stations {
                    println!("  x {x:>10.4}: θ {:+.4}°, φ {:+.4}°", law.theta(x).to_degrees(), law.phi(x).to_degrees());
                }
            }
            Ok(())
        }
        HullCommand::Dims {
            input,
            lcb_shift,
            block_coefficient,
            length,
            middle_body,
            beam,
            draft,
            waterline,
            tol,
            output,
            json,
        } => {
            let format = output_format(&output)?;
            let middle_body = middle_body
                .map(|t| -> Result<(f64, f64)> {
                    let v: Vec<&str> = t.split(',').collect();
                    let num = |s: &str| s.trim().parse::<f64>().ok();
                    match v.as_slice() {
                        [a, b] => match (num(a), num(b)) {
                            (Some(a), Some(b)) => Ok((a, b)),
                            _ => bail!("--middle-body: expected two numbers X0,X1, got {t:?}"),
                        },
                        _ => bail!("--middle-body: expected two numbers X0,X1, got {t:?}"),
                    }
                })
                .transpose()?;
            if [lcb_shift, block_coefficient, length, beam, draft].iter().all(Option::is_none) {
                bail!(
                    "hull dims: nothing to change (give --lcb-shift, --block-coefficient, --length, --beam or --draft)"
                );
            }
            let mut m = cadmorph::open(&input)?;
            crate::skipped::check(&m.info().skipped, false)?;
            let unit = crate::units::words(m.units().metres_per_unit, m.unit());
            let change = DimsChange { length, middle_body, beam, draft, waterline, lcb_shift, block_coefficient };
            let tol = tol.unwrap_or(1e-7 * m.size());
            let r = change_dimensions(&mut m, &change, tol)
                .with_context(|| format!("changing the dimensions of {}; nothing written", input.display()))?;
            if r.max_gap_after > tol {
                bail!(
                    "changing the dimensions opened a seam of {:.3e} {unit} (tolerance {tol:.3e}); nothing written",
                    r.max_gap_after
                );
            }
            save_as(&m, &output, format)?;
            if json {
                let mut out = serde_json::to_value(&r)?;
                out["input"] = input.display().to_string().into();
                out["output"] = output.display().to_string().into();
                out["unit"] = crate::units::json(m.units().metres_per_unit, m.unit());
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                let (a, b) = (&r.before, &r.after);
                println!("{} -> {} ({unit}):", input.display(), output.display());
                println!(
                    "  length {:.9} -> {:.9}, beam {:.9} -> {:.9}, draft {:.9} -> {:.9}",
                    a.length, b.length, a.beam, b.beam, a.draft, b.draft
                );
                println!(
                    "  volume {:.9e} -> {:.9e} cubic {unit} ({:+.3e} relative), block coefficient {:.9} -> {:.9}, LCB {:.9} -> {:.9}",
                    a.volume,
                    b.volume,
                    (b.volume - a.volume) / a.volume,
                    a.block_coefficient,
                    b.block_coefficient,
                    a.lcb,
                    b.lcb
                );
                if let Some((sa, sb)) = r.section_shift {
                    println!("  section shift a = {sa:.6}, b = {sb:.6}");
                }
                if let Some(s) = r.stretch {
                    println!(
                        "  stretched {:.6} .. {:.6} by {:+.6} ({} knots where the stretch bends); seams after: max gap {:.3e}",
                        s.x0, s.x1, s.added, r.knots_at_bends, r.max_gap_after
                    );
                }
            }
            Ok(())
        }
    }
}

/// The FFD of `path` with its displacements corrected to the nearest ones that keep the
/// enclosed volume and/or barycentre of `m`. Only the lattice nodes the file moves
/// (any non-zero component) may change, in all three components: the others keep the
/// lattice joined to the unmoved part of the model.
pub fn keep_hook(m: &Model, path: &Path, volume: bool, barycentre: bool) -> Result<Box<dyn Deformation + Send>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let params = if path.extension().is_some_and(|e| e == "toml") {
        Parameters::from_toml(&text)
    } else {
        Parameters::from_prm(&text)
    }
    .with_context(|| format!("reading {}", path.display()))?;
    let Parameters::Ffd(ffd) = params else {
        bail!("--keep-volume and --keep-barycentre need FFD parameters; {} holds others", path.display());
    };
    let free = moved_nodes(&ffd);
    if !free.iter().any(|&f| f) {
        bail!("{} moves no lattice node: there is nothing to correct to keep the volume or barycentre", path.display());
    }
    let what = Keep { volume, barycentre, volume_factor: 1.0 };
    let (kept, report) = keep(m.patches(), m.bound_curves(), m.size(), &ffd, what, Some(&free))
        .context("keeping the enclosed volume/barycentre; nothing written")?;
    print_report(&report, &crate::units::words(m.units().metres_per_unit, m.unit()));
    Ok(Box::new(kept))
}

/// Every component of the nodes with a non-zero displacement.
fn moved_nodes(ffd: &Ffd) -> Vec<bool> {
    let theta = ffd.params();
    let n = theta.len() / 3;
    let moved: Vec<bool> = (0..n).map(|j| (0..3).any(|c| theta[c * n + j] != 0.0)).collect();
    (0..3 * n).map(|i| moved[i % n]).collect()
}

fn print_report(r: &KeepReport, unit: &str) {
    let rel = |v: f64| (v - r.before.volume) / r.before.volume;
    let (c0, c1) = (r.before.centroid(), r.after.centroid());
    eprintln!(
        "keep: volume {:.12e} cubic {unit} before, {:+.3e} relative with the file's displacements, {:+.3e} after the correction \
         (|Δμ| {:.3e}, {} Newton steps); centroid moved by {:.3e} {unit}",
        r.before.volume,
        rel(r.unconstrained.volume),
        rel(r.after.volume),
        r.change,
        r.iterations,
        (c1 - c0).norm()
    );
}
