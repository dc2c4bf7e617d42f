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
    /// How faces are written to IGES: `brep` makes each set of faces that closes up a
    /// 186 solid (the others trimmed surfaces), `trimmed` writes every face as a 144
    /// trimmed surface (128 when untrimmed), as OCCT does by default.
    #[arg(long, value_enum, default_value_t = IgesFaces::Brep)]
    iges_faces: IgesFaces,
    /// Print the outcome as JSON (schema `cadmorph.convert/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// The IGES form of faces ([`cadmorph::IgesFaces`]).
#[derive(Clone, Copy, clap::ValueEnum)]
enum IgesFaces {
    /// 186 solids where faces close up.
    Brep,
    /// Every face a 144 (or 128).
    Trimmed,
}

/// Runs `convert`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.input)?;
    let iges_faces = match a.iges_faces {
        IgesFaces::Brep => cadmorph::IgesFaces::Brep,
        IgesFaces::Trimmed => cadmorph::IgesFaces::Trimmed,
    };
    cadmorph::save_as_with(&m, &a.output, &cadmorph::ConvertOptions { iges_faces })?;
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
