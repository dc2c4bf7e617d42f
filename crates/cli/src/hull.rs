//! `cadmorph hull volume|dims` (exact volume and centroid of a closed model, LCB shift) and the hook of
//! `cadmorph morph --ffd P --keep-volume --keep-barycentre`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cadmorph::model::{Model, MorphOptions, Staged};
use cadmorph::morph::{Deformation, Ffd, LinearInParameters, Parameters};
use cadmorph_hull::{enclosed, keep, lcb_shift, Keep, KeepReport};

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
    /// Principal-dimension changes of a closed hull: a Lackenby-style shift of the
    /// longitudinal centre of buoyancy (sections moved along x, volume kept).
    Dims {
        /// The input IGES or STEP file (a closed hull, x along the length).
        input: PathBuf,
        /// Move the LCB (the centroid of the enclosed volume) by this much along +x,
        /// model units.
        #[arg(long, allow_hyphen_values = true)]
        lcb_shift: f64,
        /// The output file (its extension names the format).
        #[arg(short, long)]
        output: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
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
                    "unit": m.unit(),
                    "volume": e.total.volume,
                    "centroid": [c.x, c.y, c.z],
                    "orientation": e.orientation,
                    "methods": e.methods,
                });
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                println!(
                    "{}: volume {:.12e} {}^3, centroid ({:.9}, {:.9}, {:.9}); {} faces ({} planar trimmed)",
                    input.display(),
                    e.total.volume,
                    m.unit(),
                    c.x,
                    c.y,
                    c.z,
                    e.methods.len(),
                    e.methods.iter().filter(|k| **k == cadmorph_hull::FaceMethod::Planar).count()
                );
            }
            Ok(())
        }
        HullCommand::Dims { input, lcb_shift: dx, output, json } => {
            let format = cadmorph::Format::from_extension(&output)
                .ok_or_else(|| cadmorph::Error::UnknownExtension { path: output.clone() })?;
            let mut m = cadmorph::open(&input)?;
            crate::skipped::check(&m.info().skipped, false)?;
            let (shift, report) = lcb_shift(m.patches(), m.bound_curves(), m.size(), dx)
                .with_context(|| format!("shifting the LCB of {}; nothing written", input.display()))?;
            m.morph(&shift, &MorphOptions::default()).with_context(|| format!("morphing {}", input.display()))?;
            let bytes = if format == m.format() { m.to_bytes() } else { cadmorph::convert(&m, format)?.to_bytes() };
            Staged::new(&output, &bytes)?.commit()?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                println!(
                    "{} -> {}: LCB {:.9} -> {:.9} {} (asked {:+}, reached {:+.3e}), volume change {:+.3e} relative; shift a = {:.6}, b = {:.6}",
                    input.display(),
                    output.display(),
                    report.before.centroid().x,
                    report.after.centroid().x,
                    m.unit(),
                    dx,
                    report.reached,
                    (report.after.volume - report.before.volume) / report.before.volume,
                    shift.a,
                    shift.b
                );
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
    print_report(&report, m.unit());
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
        "keep: volume {:.12e} {unit}^3 before, {:+.3e} relative with the file's displacements, {:+.3e} after the correction \
         (|Δμ| {:.3e}, {} Newton steps); centroid moved by {:.3e} {unit}",
        r.before.volume,
        rel(r.unconstrained.volume),
        rel(r.after.volume),
        r.change,
        r.iterations,
        (c1 - c0).norm()
    );
}
