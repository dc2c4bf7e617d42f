//! `cadmorph morph`: morph every face, keep the seams, write the result.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cadmorph::model::MorphOptions;
use cadmorph::seam::SeamRefineOptions;
use cadmorph::Format;

use crate::progress::Bar;

/// Which parameter file gives the morph.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
pub struct Source {
    /// FFD parameters (PyGeM .prm or TOML).
    #[arg(long)]
    ffd: Option<PathBuf>,
    /// RBF parameters (PyGeM .prm or TOML).
    #[arg(long)]
    rbf: Option<PathBuf>,
    /// IDW parameters (PyGeM .prm or TOML).
    #[arg(long)]
    idw: Option<PathBuf>,
}

/// Arguments of `morph`.
#[derive(clap::Args)]
pub struct Args {
    /// The input IGES or STEP file.
    input: PathBuf,
    /// The output file (written through a temporary file and a rename), in the format
    /// its extension names (.igs/.iges, .stp/.step).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    source: Source,
    /// Refine so that the seams stay within this gap (model units) after the morph.
    #[arg(long)]
    refine_tol: Option<f64>,
    /// With --refine-tol: the largest normal angle across a seam, degrees.
    #[arg(long, default_value_t = 0.01, requires = "refine_tol")]
    angle_tol: f64,
    /// PyGeM-style refinement instead: this many evenly spaced knots per direction.
    #[arg(long, conflicts_with = "refine_tol")]
    uniform_knots: Option<usize>,
    /// Make knots compatible across seams and make both sides identical after the morph.
    #[arg(long)]
    repair: bool,
    /// Write the seam report (before and after) as JSON here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Print the outcome as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `morph`.
pub fn run(a: Args) -> Result<()> {
    let start = Instant::now();
    if Format::from_extension(&a.output).is_none() {
        return Err(cadmorph::Error::UnknownExtension { path: a.output.clone() }.into());
    }
    let (path, kind) = match (&a.source.ffd, &a.source.rbf, &a.source.idw) {
        (Some(p), _, _) => (p, "ffd"),
        (_, Some(p), _) => (p, "rbf"),
        (_, _, Some(p)) => (p, "idw"),
        _ => bail!("one of --ffd, --rbf, --idw is needed"),
    };
    let d = crate::params::deformation(path, Some(kind))?;
    let opts = MorphOptions {
        refine: a.refine_tol.map(|t| SeamRefineOptions::new(t, a.angle_tol)),
        uniform_knots: a.uniform_knots,
        repair: a.repair,
    };
    let mut m = cadmorph::open(&a.input)?;
    let mut outcome = {
        let bar = Bar::new();
        m.morph_with_progress(d.as_ref(), &opts, &bar).with_context(|| format!("morphing {}", a.input.display()))?
    };
    cadmorph::save_as(&m, &a.output)?;
    let elapsed = start.elapsed().as_secs_f64();
    // The "after" report describes the written document, read back.
    outcome.seams_after = m.verify()?.seams;
    if let Some(r) = &a.report {
        let text = serde_json::to_string_pretty(&outcome)?;
        cadmorph::model::write_atomic(r, text.as_bytes())?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&outcome)?);
        return Ok(());
    }
    println!(
        "{} -> {} in {:.1} ms: {} faces and {} curves rewritten, control points {} -> {}",
        a.input.display(),
        a.output.display(),
        elapsed * 1e3,
        outcome.faces_rewritten,
        outcome.curves_rewritten,
        outcome.control_points_before,
        outcome.control_points_after
    );
    if let Some(r) = &outcome.refinement {
        println!(
            "seam refinement: {} rounds, {}; max gap {:.3e}, max angle {:.4} deg",
            r.rounds,
            if r.converged { "converged" } else { "NOT converged" },
            r.max_gap,
            r.max_angle_deg
        );
    }
    println!("seams before ({}):\n{}", m.unit(), outcome.seams_before.table());
    println!("seams after, read back from the written document:\n{}", outcome.seams_after.table());
    Ok(())
}
