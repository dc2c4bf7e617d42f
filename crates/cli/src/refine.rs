//! `cadmorph refine`: insert knots without moving anything.

use std::path::PathBuf;

use anyhow::{bail, Result};
use cadmorph::model::MorphOptions;
use cadmorph::seam::SeamRefineOptions;

/// Arguments of `refine`.
#[derive(clap::Args)]
pub struct Args {
    /// The input IGES or STEP file.
    input: PathBuf,
    /// The output file.
    #[arg(short, long)]
    output: PathBuf,
    /// This many evenly spaced knots per direction on every face.
    #[arg(long, conflicts_with_all = ["for_params", "tol"])]
    knots: Option<usize>,
    /// Refine for this morph: a parameter file (PyGeM .prm or .toml) whose kind, FFD,
    /// RBF or IDW, is read from the file ...
    #[arg(long = "for", requires = "tol")]
    for_params: Option<PathBuf>,
    /// ... so that the seams stay within this gap (model units) after it.
    #[arg(long, value_parser = crate::limits::positive)]
    tol: Option<f64>,
    /// Refine the faces that convert and keep the others as they are.
    #[arg(long)]
    skip_unsupported: bool,
    /// Print the outcome as JSON (schema `cadmorph.refine/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// Runs `refine`.
pub fn run(a: Args) -> Result<()> {
    let mut m = cadmorph::open(&a.input)?;
    crate::skipped::check(&m.info().skipped, a.skip_unsupported)?;
    let (before, after) = match (a.knots, &a.for_params, a.tol) {
        (Some(n), _, _) => m.refine(&MorphOptions { uniform_knots: Some(n), ..Default::default() }, None)?,
        (None, Some(p), Some(t)) => {
            crate::limits::check_gap_tolerance("--tol", t, m.size(), m.unit())?;
            let d = crate::params::deformation(p, None)?;
            let opts = MorphOptions { refine: Some(SeamRefineOptions::new(t, 0.01)), ..Default::default() };
            m.refine(&opts, Some(d.as_ref()))?
        }
        _ => bail!("give --knots N, or --for PARAMS with --tol T"),
    };
    cadmorph::save_as(&m, &a.output)?;
    if a.json {
        let info = m.info();
        return crate::schema::print(
            "refine",
            serde_json::json!({
                "input": a.input.display().to_string(),
                "output": a.output.display().to_string(),
                "unit": crate::units::json(info.metres_per_unit, &info.unit),
                "faces": m.patches().len(),
                "control_points_before": before,
                "control_points_after": after,
            }),
        );
    }
    println!("{} -> {}: control points {before} -> {after}", a.input.display(), a.output.display());
    Ok(())
}
