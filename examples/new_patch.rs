//! A new patch to IGES and STEP: build a bicubic B-spline surface, write it as a new IGES
//! file and a new STEP file, and read both back as models.
//!
//! ```text
//! cargo run --release --example new_patch -- patch.igs patch.stp
//! ```

use std::path::PathBuf;

use cadmorph::nurbs::math::Point3;
use cadmorph::nurbs::{KnotVector, NurbsSurface, Surface};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let igs = args.next().map_or_else(|| std::env::temp_dir().join("new_patch.igs"), PathBuf::from);
    let stp = args.next().map_or_else(|| std::env::temp_dir().join("new_patch.stp"), PathBuf::from);

    // A 4 x 4 bicubic Bezier patch, a saddle 100 mm across.
    let knots = KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0])?;
    let mut poles = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            let (x, y) = (100.0 * f64::from(i) / 3.0, 100.0 * f64::from(j) / 3.0);
            poles.push(Point3::new(x, y, 0.002 * (x - 50.0) * (y - 50.0)));
        }
    }
    let patch = NurbsSurface::try_new((3, 3), (knots.clone(), knots), (4, 4), poles, None)?;

    let mut iges = cadmorph::iges::write::DocumentBuilder::new(cadmorph::iges::Units::Millimetre);
    iges.add_surface(&patch);
    cadmorph::model::write_atomic(&igs, &iges.to_bytes())?;

    let mut step = cadmorph::step::DocumentBuilder::new(cadmorph::step::Schema::Ap214, "saddle", 1e-3, 1e-6)?;
    step.add_shell(std::slice::from_ref(&patch), 1e-6);
    cadmorph::model::write_atomic(&stp, &step.build()?.write())?;

    for path in [&igs, &stp] {
        let m = cadmorph::open(path)?;
        let s = &m.patches()[0].surface;
        let d = (s.eval(0.5, 0.5) - patch.eval(0.5, 0.5)).norm();
        println!(
            "{} ({}, {}): {} face, centre off by {d:.1e}",
            path.display(),
            m.format(),
            m.unit(),
            m.patches().len()
        );
    }
    Ok(())
}
