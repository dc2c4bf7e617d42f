//! Reproducible large STEP files for the benchmarks (shared by `benches/parse.rs` and
//! `examples/step_bench.rs`, which writes them for the side-by-side runs; `tests/roundtrip.rs`
//! reads `faces300` in parallel).

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsSurface};
use cadmorph_step::{DocumentBuilder, Schema};

/// A cubic patch of `n_u x n_v` poles over `[x0, x1]` of a hull-like shape with a small
/// deterministic ripple (so the numbers have full-length decimals like real files).
fn hull_patch(n_u: usize, n_v: usize, x0: f64, x1: f64) -> NurbsSurface {
    let mut pts = Vec::with_capacity(n_u * n_v);
    for i in 0..n_u {
        let x = x0 + (x1 - x0) * i as f64 / (n_u - 1) as f64;
        for j in 0..n_v {
            let t = j as f64 / (n_v - 1) as f64;
            let beam = 8.0 * (1.0 - (2.0 * x / 140.0 - 1.0).powi(4)).max(0.05);
            let y = beam * (t * std::f64::consts::FRAC_PI_2).sin() + 1e-3 * ((i * 7 + j * 3) % 11) as f64 / 11.0;
            let z = 12.5 * (1.0 - (t * std::f64::consts::FRAC_PI_2).cos()) + 0.01 * (x / 13.0).sin();
            pts.push(Point3::new(x, y, z));
        }
    }
    NurbsSurface::try_new(
        (3, 3),
        (KnotVector::clamped_uniform(3, n_u), KnotVector::clamped_uniform(3, n_v)),
        (n_u, n_v),
        pts,
        None,
    )
    .expect("valid patch")
}

/// The 3-patch hull (200 x 150 poles per cubic patch), about 8.75 MB of STEP.
pub fn hull3() -> Vec<u8> {
    let patches: Vec<NurbsSurface> =
        (0..3).map(|k| hull_patch(200, 150, 140.0 * k as f64 / 3.0, 140.0 * (k + 1) as f64 / 3.0)).collect();
    let mut b = DocumentBuilder::new(Schema::Ap214, "hull3_200x150", 1.0, 1e-7).expect("builder");
    b.add_shell(&patches, 1e-9);
    b.build().expect("document").write()
}

/// 300 bicubic 8 x 8 patches tiling a sheet (shared edges), about 2.8 MB of STEP.
pub fn faces300() -> Vec<u8> {
    let mut patches = Vec::with_capacity(300);
    for a in 0..20 {
        for c in 0..15 {
            let mut s = hull_patch(8, 8, 7.0 * a as f64, 7.0 * (a + 1) as f64);
            // Stack the rows in z so the 20 x 15 patches tile a sheet.
            for p in s.control_points_mut() {
                p.z += 25.0 * c as f64;
            }
            patches.push(s);
        }
    }
    let mut b = DocumentBuilder::new(Schema::Ap214, "faces300", 1.0, 1e-7).expect("builder");
    b.add_shell(&patches, 1e-9);
    b.build().expect("document").write()
}
