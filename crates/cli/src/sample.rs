//! `cadmorph sample`: points and normals of every face on a grid.

use std::path::PathBuf;

use anyhow::Result;

/// Arguments of `sample`.
#[derive(clap::Args)]
pub struct Args {
    /// An IGES or STEP file.
    file: PathBuf,
    /// Grid points per direction (2 to 1000).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=1000))]
    grid: u32,
    /// Print JSON (schema `cadmorph.sample/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// Runs `sample`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.file)?;
    crate::skipped::warn(&m.info().skipped);
    let mut out = Vec::new();
    let info = m.info();
    let unit = crate::units::words(info.metres_per_unit, &info.unit);
    for (i, p) in m.patches().iter().enumerate() {
        let rows = crate::grid::rows(&p.surface, a.grid as usize, p.reversed);
        if a.json {
            out.push(serde_json::json!({
                "face": crate::faces::json(i, &p.entity, &p.surface_entity),
                "grid": crate::grid::json(&rows),
            }));
        } else {
            println!(
                "face {} ({}), points in {unit}, unit normals oriented with the face:",
                crate::faces::label(i, &p.entity),
                p.type_name
            );
            crate::grid::print(&rows);
        }
    }
    if a.json {
        return crate::schema::print(
            "sample",
            serde_json::json!({
                "file": a.file.display().to_string(),
                "unit": crate::units::json(info.metres_per_unit, &info.unit),
                "grid": a.grid,
                "faces": out,
            }),
        );
    }
    Ok(())
}
