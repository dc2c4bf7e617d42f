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
    /// Print the outcome as JSON (schema `cadmorph.convert/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// Runs `convert`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.input)?;
    cadmorph::save_as(&m, &a.output)?;
    let to = cadmorph::Format::from_extension(&a.output).map_or_else(String::new, |f| f.to_string());
    if a.json {
        return crate::schema::print(
            "convert",
            serde_json::json!({
                "input": a.input.display().to_string(),
                "input_format": m.format().to_string(),
                "output": a.output.display().to_string(),
                "output_format": to,
                "faces": m.patches().len(),
            }),
        );
    }
    println!("{} ({}) -> {} ({to}): {} faces", a.input.display(), m.format(), a.output.display(), m.patches().len());
    Ok(())
}
