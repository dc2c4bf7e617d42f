//! `cadmorph convert`: IGES to STEP and STEP to IGES.

use std::path::PathBuf;

use anyhow::Result;

/// Arguments of `convert`.
#[derive(clap::Args)]
pub struct Args {
    /// The input IGES or STEP file.
    input: PathBuf,
    /// The output file; its extension (.igs/.iges, .stp/.step) chooses the writer.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `convert`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.input)?;
    cadmorph::save_as(&m, &a.output)?;
    let to = cadmorph::Format::from_extension(&a.output).map_or_else(String::new, |f| f.to_string());
    println!("{} ({}) -> {} ({to}): {} faces", a.input.display(), m.format(), a.output.display(), m.patches().len());
    Ok(())
}
