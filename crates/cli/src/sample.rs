//! `cadmorph sample`: points and normals of every face on a grid.

use std::path::PathBuf;

use anyhow::Result;

/// Arguments of `sample`.
#[derive(clap::Args)]
pub struct Args {
    /// An IGES or STEP file.
    file: PathBuf,
    /// Grid points per direction.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=1000))]
    grid: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `sample`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.file)?;
    crate::skipped::warn(&m.info().skipped);
    let mut out = Vec::new();
    for p in m.patches() {
        let rows = crate::grid::rows(&p.surface, a.grid as usize, p.reversed);
        if a.json {
            out.push(serde_json::json!({ "face": p.entity, "grid": crate::grid::json(&rows) }));
        } else {
            println!("face {} ({}):", p.entity, p.type_name);
            crate::grid::print(&rows);
        }
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    }
    Ok(())
}
