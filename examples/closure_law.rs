//! A custom law from a closure: widen a hull at mid-length (a sine law along x, nothing at
//! the ends), as an object-specific law would, and morph the file with it.
//!
//! ```text
//! cargo run --release --example closure_law -- samples/hull3.igs widened.igs
//! ```

use std::path::PathBuf;

use cadmorph::model::MorphOptions;
use cadmorph::morph::from_fn;
use cadmorph::nurbs::math::Point3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut args = std::env::args().skip(1);
    let input = args.next().map_or_else(|| root.join("samples/hull3.igs"), PathBuf::from);
    let output = args.next().map_or_else(|| std::env::temp_dir().join("hull3_widened.igs"), PathBuf::from);

    let mut model = cadmorph::open(&input)?;
    let length = 145.0; // the sample hull, metres
    let widen = from_fn(move |p: &Point3<f64>| {
        let s = (std::f64::consts::PI * (p.x / length).clamp(0.0, 1.0)).sin();
        Point3::new(p.x, p.y * (1.0 + 0.03 * s), p.z)
    });
    let outcome = model.morph(&widen, &MorphOptions::default())?;
    cadmorph::save_as(&model, &output)?;
    println!(
        "{} -> {}: {} faces rewritten; seams after: max gap {:.2e} {}, max G1 {:.3e} deg",
        input.display(),
        output.display(),
        outcome.faces_rewritten,
        outcome.seams_after.max_gap_closest,
        model.unit(),
        outcome.seams_after.max_g1_angle_deg
    );
    Ok(())
}
