//! `cadmorph info`: units, entity counts and faces.

use std::path::PathBuf;

use anyhow::Result;
use cadmorph::model::PatchInfo;

/// Arguments of `info`.
#[derive(clap::Args)]
pub struct Args {
    /// An IGES or STEP file.
    file: PathBuf,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `DE 5`, `DE 5 (surface DE 7)`, `#12 (surface #15)`.
pub fn face_label(p: &PatchInfo) -> String {
    if p.face == p.surface {
        p.face.to_string()
    } else {
        format!("{} (surface {})", p.face, p.surface)
    }
}

/// Runs `info`.
pub fn run(a: Args) -> Result<()> {
    let i = cadmorph::open(&a.file)?.info();
    if a.json {
        println!("{}", serde_json::to_string_pretty(&i)?);
        return Ok(());
    }
    println!("{}: {:?}, unit {}", a.file.display(), i.format, i.unit);
    let counts: Vec<String> = i.entity_counts.iter().map(|(k, v)| format!("{k}: {v}")).collect();
    println!("entities: {}", counts.join(", "));
    if i.unknown_entities > 0 {
        println!("kept verbatim without a typed view: {}", i.unknown_entities);
    }
    println!(
        "{:<28} {:<22} {:>7} {:>9} {:>9} {:>8} {:>8}",
        "face", "surface", "degree", "poles", "rational", "trimmed", "analytic"
    );
    for p in &i.patches {
        println!(
            "{:<28} {:<22} {:>7} {:>9} {:>9} {:>8} {:>8}",
            face_label(p),
            p.kind,
            format!("{}x{}", p.u_degree, p.v_degree),
            format!("{}x{}", p.n_u, p.n_v),
            p.rational,
            p.trimmed,
            p.analytic
        );
    }
    for s in &i.skipped {
        println!("not converted: {}: {}", s.entity, s.reason);
    }
    Ok(())
}
