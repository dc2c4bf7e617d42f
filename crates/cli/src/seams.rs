//! `cadmorph seams`: continuity along every shared edge.

use std::path::PathBuf;

use anyhow::Result;

use crate::progress::Bar;

/// Arguments of `seams`.
#[derive(clap::Args)]
pub struct Args {
    /// An IGES or STEP file.
    file: PathBuf,
    /// Samples per edge.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    samples: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `seams`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.file)?;
    crate::skipped::warn(&m.info().skipped);
    let r = {
        let bar = Bar::new();
        m.seams_with_progress(a.samples as usize, &bar)
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        println!("{} ({}):", a.file.display(), m.unit());
        print!("{}", r.table());
    }
    Ok(())
}
