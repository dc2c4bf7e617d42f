//! Reproducible large IGES files for the benchmarks (shared by `benches/parse.rs` and
//! `examples/iges_bench.rs`, which writes them for the OCCT side-by-side run).

use cadmorph_iges::write::DocumentBuilder;
use cadmorph_iges::{Status, Units, Value};
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsSurface};

/// `x` rounded to 9 significant digits, as OCCT and most CAD systems write IGES reals.
fn sig9(x: f64) -> f64 {
    format!("{x:.8e}").parse().expect("a number")
}

/// Clamped uniform knots of degree 3 for `n` poles, rounded to 9 digits.
fn knots(n: usize) -> KnotVector {
    let spans = n - 3;
    let mut k = vec![0.0; 4];
    k.extend((1..spans).map(|i| sig9(i as f64 / spans as f64)));
    k.extend([1.0; 4]);
    KnotVector::try_new(k).expect("increasing knots")
}

/// A bicubic surface with `n_u × n_v` poles shaped like a piece of hull side, over
/// `x ∈ [x0, x0 + length]`; numbers have 9 significant digits, as OCCT writes them.
fn hull_patch(n_u: usize, n_v: usize, x0: f64, length: f64) -> NurbsSurface {
    let mut pts = Vec::with_capacity(n_u * n_v);
    for i in 0..n_u {
        let s = i as f64 / (n_u - 1) as f64;
        let x = x0 + length * s;
        for j in 0..n_v {
            let t = j as f64 / (n_v - 1) as f64;
            let beam = 9.5 * (1.0 - (2.0 * (x / 142.0) - 1.0).powi(4)).max(0.05);
            let y = beam * (std::f64::consts::FRAC_PI_2 * t).sin() * (1.0 - 0.1 * t * t);
            let z = 6.3 * t - 0.37 * (3.1 * s).sin() * t;
            pts.push(Point3::new(sig9(x), sig9(y), sig9(z)));
        }
    }
    NurbsSurface::new((3, 3), (knots(n_u), knots(n_v)), (n_u, n_v), pts, None)
}

/// Three trimmed (144 → 128) hull patches of `n_u × n_v` poles each, in metres.
pub fn hull(n_u: usize, n_v: usize) -> Vec<u8> {
    let mut b = DocumentBuilder::new(Units::Metre).timestamp("20250101.000000");
    for k in 0..3 {
        add_trimmed(&mut b, &hull_patch(n_u, n_v, 142.0 * k as f64 / 3.0, 142.0 / 3.0));
    }
    b.to_bytes()
}

/// `n` trimmed (144 → 128) bicubic faces of 8 × 8 poles, in millimetres.
pub fn many_faces(n: usize) -> Vec<u8> {
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20250101.000000");
    for k in 0..n {
        let mut s = hull_patch(8, 8, 0.47 * k as f64, 0.47);
        for p in s.control_points_mut() {
            p.z = sig9(p.z + 0.013 * k as f64);
        }
        add_trimmed(&mut b, &s);
    }
    b.to_bytes()
}

fn add_trimmed(b: &mut DocumentBuilder, s: &NurbsSurface) {
    // The 144 comes first and points to the 128 after it (as OCCT writes them).
    let trim_id = 2 * (b.len()) + 1;
    let surface_de = trim_id + 2;
    b.add_entity(
        0,
        Status::default(),
        vec![
            Value::Integer(144),
            Value::Integer(surface_de as i64),
            Value::Integer(0),
            Value::Integer(0),
            Value::Integer(0),
        ],
    );
    let id = b.add_surface(s);
    assert_eq!(id.0 as usize, surface_de);
    b.set_status(id, Status { subordinate: 1, ..Status::default() });
}
