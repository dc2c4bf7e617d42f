//! `cadmorph eval`: cadmorph's evaluation of OCCT reference surfaces against OCCT's.

use std::path::PathBuf;

use anyhow::{Context, Result};
use cadmorph::nurbs::Surface;
use cadmorph_testkit::refdata::read_faces;

/// Arguments of `eval`.
#[derive(clap::Args)]
pub struct Args {
    /// A `*.ref.json` file.
    file: PathBuf,
    /// Grid points per direction (2 to 1000).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=1000))]
    grid: u32,
    /// Only this face (its index in the reference file, the numbering of `cadmorph info`).
    #[arg(long)]
    face: Option<usize>,
    /// Print JSON instead of a table (schema `cadmorph.eval/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// Runs `eval`.
pub fn run(a: Args) -> Result<()> {
    let (file, grid, only, json) = (&a.file, a.grid as usize, a.face, a.json);
    let text = std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let faces = read_faces(&text).with_context(|| format!("reading {}", file.display()))?;
    let mut out = Vec::new();
    for f in faces.iter().filter(|f| only.is_none_or(|i| i == f.index)) {
        let Some(s) = &f.surface else {
            if !json {
                println!("face {}: {} (analytic: see `cadmorph sample` on the data file)\n", f.index, f.class);
            }
            continue;
        };
        let scale = s.control_extent().max(f64::MIN_POSITIVE);
        let (mut dp, mut dn) = (0.0f64, 0.0f64);
        for smp in &f.samples {
            dp = dp.max((s.eval(smp.u, smp.v) - smp.point).norm() / scale);
            if let (Some(a), Some(b)) = (s.normal(smp.u, smp.v), smp.normal) {
                dn = dn.max((a.into_inner() - b).norm());
            }
        }
        let rows = crate::grid::rows(s, grid, false);
        if json {
            out.push(serde_json::json!({
                "face": f.index,
                "degrees": [s.u_degree(), s.v_degree()],
                "poles": [s.n_u(), s.n_v()],
                "rational": s.is_rational(),
                "occt_samples": f.samples.len(),
                "max_point_difference_relative": dp,
                "max_normal_difference": dn,
                "grid": crate::grid::json(&rows),
            }));
        } else {
            println!(
                "face {}: degree {}x{}, {}x{} poles{}; against OCCT at {} samples: max |Δp| = {:.1e} (relative), max |Δn| = {:.1e}",
                f.index,
                s.u_degree(),
                s.v_degree(),
                s.n_u(),
                s.n_v(),
                if s.is_rational() { ", rational" } else { "" },
                f.samples.len(),
                dp,
                dn
            );
            crate::grid::print(&rows);
            println!();
        }
    }
    if json {
        return crate::schema::print("eval", serde_json::json!({ "file": file.display().to_string(), "faces": out }));
    }
    Ok(())
}
