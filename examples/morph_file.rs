//! Morph a file: open an IGES or STEP file, deform it with a PyGeM FFD parameter file,
//! refine so the seams stay closed, write the result and check what was written.
//!
//! ```text
//! cargo run --release --example morph_file -- samples/hull3.stp samples/prm/bow_dome.prm out.stp
//! ```

use std::path::PathBuf;

use cadmorph::model::MorphOptions;
use cadmorph::morph::Ffd;
use cadmorph::seam::SeamRefineOptions;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut args = std::env::args().skip(1);
    let input = args.next().map_or_else(|| root.join("samples/hull3.stp"), PathBuf::from);
    let prm = args.next().map_or_else(|| root.join("samples/prm/bow_dome.prm"), PathBuf::from);
    let output = args.next().map_or_else(|| std::env::temp_dir().join("hull3_morphed.stp"), PathBuf::from);

    let mut model = cadmorph::open(&input)?;
    let ffd = Ffd::from_prm(&std::fs::read_to_string(&prm)?)?;
    // Refine until the seams stay within 1e-7 of the model size after the morph.
    let opts = MorphOptions { refine: Some(SeamRefineOptions::new(1e-7 * model.size(), 0.01)), ..Default::default() };
    let outcome = model.morph(&ffd, &opts)?;
    cadmorph::save_as(&model, &output)?;
    let check = model.verify()?;
    println!(
        "{} -> {}: {} faces, {} curves rewritten; control points {} -> {}",
        input.display(),
        output.display(),
        outcome.faces_rewritten,
        outcome.curves_rewritten,
        outcome.control_points_before,
        outcome.control_points_after
    );
    println!("seams of the written file:\n{}", check.seams.table());
    Ok(())
}
