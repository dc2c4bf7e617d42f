//! Convert a file: IGES to STEP or STEP to IGES, the writer chosen by the output's
//! extension; then read the result back and compare the faces.
//!
//! ```text
//! cargo run --release --example convert_file -- samples/hull3.igs hull3.stp
//! ```

use std::path::PathBuf;

use cadmorph::nurbs::Surface;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut args = std::env::args().skip(1);
    let input = args.next().map_or_else(|| root.join("samples/hull3.igs"), PathBuf::from);
    let output = args.next().map_or_else(|| std::env::temp_dir().join("hull3_converted.stp"), PathBuf::from);

    let model = cadmorph::open(&input)?;
    cadmorph::save_as(&model, &output)?;
    let back = cadmorph::open(&output)?;
    let mut worst = 0.0f64;
    for (a, b) in model.patches().iter().zip(back.patches()) {
        let (ud, vd) = a.surface.domain();
        for i in 0..=4 {
            for j in 0..=4 {
                let u = ud.start() + (ud.end() - ud.start()) * f64::from(i) / 4.0;
                let v = vd.start() + (vd.end() - vd.start()) * f64::from(j) / 4.0;
                worst = worst.max((a.surface.eval(u, v) - b.surface.eval(u, v)).norm());
            }
        }
    }
    println!(
        "{} ({}) -> {} ({}): {} faces, largest difference {worst:.2e} {}",
        input.display(),
        model.format(),
        output.display(),
        back.format(),
        back.patches().len(),
        back.unit()
    );
    Ok(())
}
