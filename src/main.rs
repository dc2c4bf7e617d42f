//! The `cadmorph` command-line tool.
//!
//! Exit codes: 0 success, 1 runtime failure (unreadable or malformed input),
//! 2 bad command line (clap's own code).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use cadmorph::nurbs::Surface;
use cadmorph::refdata::read_faces;
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "cadmorph", version, about = "CAD/NURBS kernel and IGES/STEP processor for shape parameterisation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Evaluate the B-spline faces of an OCCT reference file (`samples/*.ref.json`) on a
    /// grid, and compare cadmorph's evaluation with OCCT's samples.
    Eval {
        /// A `*.ref.json` file.
        file: PathBuf,
        /// Grid points per direction.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=1000))]
        grid: u32,
        /// Only this face (0-based).
        #[arg(long)]
        face: Option<usize>,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn eval(file: &PathBuf, grid: usize, only: Option<usize>, json: bool) -> Result<()> {
    let text = std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let faces = read_faces(&text).with_context(|| format!("reading {}", file.display()))?;
    let mut out = Vec::new();
    for f in faces.iter().filter(|f| only.is_none_or(|i| i == f.index)) {
        let Some(s) = &f.surface else {
            if !json {
                println!("face {}: {} (analytic; converted once the readers land)\n", f.index, f.class);
            }
            continue;
        };
        let scale = s.control_points().iter().map(|p| p.coords.norm()).fold(f64::MIN_POSITIVE, f64::max);
        let (mut dp, mut dn) = (0.0f64, 0.0f64);
        for smp in &f.samples {
            dp = dp.max((s.eval(smp.u, smp.v) - smp.point).norm() / scale);
            if let (Some(a), Some(b)) = (s.normal(smp.u, smp.v), smp.normal) {
                dn = dn.max((a.into_inner() - b).norm());
            }
        }
        let (ud, vd) = s.domain();
        let mut rows = Vec::new();
        for i in 0..grid {
            for j in 0..grid {
                let u = ud.start() + (ud.end() - ud.start()) * i as f64 / (grid - 1) as f64;
                let v = vd.start() + (vd.end() - vd.start()) * j as f64 / (grid - 1) as f64;
                let p = s.eval(u, v);
                let n = s.normal(u, v).map(|n| [n.x, n.y, n.z]);
                rows.push((u, v, [p.x, p.y, p.z], n));
            }
        }
        if json {
            out.push(serde_json::json!({
                "face": f.index,
                "degrees": [s.u_degree(), s.v_degree()],
                "poles": [s.n_u(), s.n_v()],
                "rational": s.is_rational(),
                "occt_samples": f.samples.len(),
                "max_point_difference_relative": dp,
                "max_normal_difference": dn,
                "grid": rows.iter().map(|(u, v, p, n)| serde_json::json!({"u": u, "v": v, "p": p, "n": n})).collect::<Vec<_>>(),
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
            println!("{:>8} {:>8} {:>14} {:>14} {:>14} {:>9} {:>9} {:>9}", "u", "v", "x", "y", "z", "nx", "ny", "nz");
            for (u, v, p, n) in &rows {
                let n = n.map_or("    (degenerate point)".to_string(), |n| {
                    format!("{:>9.5} {:>9.5} {:>9.5}", n[0], n[1], n[2])
                });
                println!("{u:>8.4} {v:>8.4} {:>14.6} {:>14.6} {:>14.6} {n}", p[0], p[1], p[2]);
            }
            println!();
        }
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Eval { file, grid, face, json } => eval(file, *grid as usize, *face, *json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cadmorph: {e:#}");
            ExitCode::FAILURE
        }
    }
}
