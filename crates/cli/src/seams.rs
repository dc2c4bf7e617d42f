//! `cadmorph seams`: continuity along every shared edge, and a pass/fail check of it.

use std::path::PathBuf;

use anyhow::{bail, Result};
use serde_json::json;

use crate::progress::Bar;
use crate::seam_report::Check;

/// Arguments of `seams`.
#[derive(clap::Args)]
#[command(after_help = "Exit status: 0 when every edge meets --tol and --angle-tol (or none is given), \
                        1 when an edge fails them (each failing edge is named on standard error) or the file \
                        cannot be read, 2 for a bad command line.")]
pub struct Args {
    /// An IGES or STEP file.
    file: PathBuf,
    /// Samples per edge (2 to 100000).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    samples: u32,
    /// Fail (exit 1) when an edge's closest-point gap is above this, in model units.
    #[arg(long, value_parser = crate::limits::positive, value_name = "GAP")]
    tol: Option<f64>,
    /// Fail (exit 1) when a smooth edge's G1 normal angle is above this, in degrees
    /// (sharp edges, creases by design, are not checked).
    #[arg(long, value_parser = crate::limits::positive, value_name = "DEGREES")]
    angle_tol: Option<f64>,
    /// Print JSON (schema `cadmorph.seams/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// Runs `seams`.
pub fn run(a: Args) -> Result<()> {
    if let Some(d) = a.angle_tol {
        crate::limits::check_angle_tolerance("--angle-tol", d)?;
    }
    let m = cadmorph::open(&a.file)?;
    let info = m.info();
    crate::skipped::warn(&info.skipped);
    let r = {
        let bar = Bar::new();
        m.seams_with_progress(a.samples as usize, &bar)
    };
    let check = Check { tol: a.tol, angle_tol: a.angle_tol };
    let unit = crate::units::words(info.metres_per_unit, &info.unit);
    if a.json {
        let mut body = crate::seam_report::json(&r, m.patches(), &check);
        body["file"] = json!(a.file.display().to_string());
        body["format"] = json!(m.format().to_string());
        body["unit"] = crate::units::json(info.metres_per_unit, &info.unit);
        body["samples"] = json!(a.samples);
        crate::schema::print("seams", body)?;
    } else {
        println!("{}: {} shared edges, lengths and gaps in {unit}, angles in degrees", a.file.display(), r.edges.len());
        print!("{}", crate::seam_report::table(&r, m.patches(), &unit, &check));
        print!("{}", crate::seam_report::legend(&unit, &check));
    }
    let failed: Vec<String> = r
        .edges
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let f = check.failures(e);
            (!f.is_empty()).then(|| {
                let mut why = Vec::new();
                if f.contains(&"gap") {
                    why.push(format!("gap {:.4e} {unit} > --tol {:e}", e.gap_closest.max, check.tol.unwrap_or(0.0)));
                }
                if f.contains(&"angle") {
                    why.push(format!(
                        "G1 angle {:.4e} degrees > --angle-tol {}",
                        e.g1_angle_deg.max,
                        check.angle_tol.unwrap_or(0.0)
                    ));
                }
                format!("{}: {}", crate::seam_report::edge_name(i, e, m.patches()), why.join(", "))
            })
        })
        .collect();
    if !failed.is_empty() {
        bail!("{} of {} edges fail: {}", failed.len(), r.edges.len(), failed.join("; "));
    }
    Ok(())
}
