//! Uniform refinement on hostile surfaces (issue 13): a knot span near `f64::MAX` and a
//! knot count whose refined net cannot be held give errors, not panics or aborts.

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsSurface, Surface};
use cadmorph_seam::{refine_uniform, Error};

/// The surface of `tests/repro/gen_knots_huge_span.igs`: u knots up to 1e308.
fn huge_span() -> NurbsSurface {
    let u = KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.0, 1e307, 5e307, 1e308, 1e308, 1e308, 1e308]).unwrap();
    let v = KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]).unwrap();
    let pts =
        (0..6).flat_map(|i| (0..4).map(move |j| Point3::new(i as f64, j as f64, ((i * j) as f64).sin()))).collect();
    NurbsSurface::try_new((3, 3), (u, v), (6, 4), pts, None).unwrap()
}

#[test]
fn repro_huge_knot_span_refines_without_overflow() {
    let mut s = huge_span();
    let before = s.clone();
    let added = refine_uniform(&mut s, 3).unwrap();
    // u: 2.5e307 and 7.5e307 (5e307 is a knot already); v: 0.25, 0.5, 0.75.
    assert_eq!(added, 5);
    assert!(s.u_knots().as_slice().iter().all(|k| k.is_finite()));
    // Refinement keeps the geometry.
    for &(u, v) in &[(0.0, 0.0), (2e307, 0.3), (7.5e307, 0.9), (1e308, 1.0)] {
        assert!((s.eval(u, v) - before.eval(u, v)).norm() < 1e-9, "at ({u:e}, {v})");
    }
}

#[test]
fn repro_refinement_beyond_memory_is_refused() {
    // `refine --knots 100000`: 100 006 × 100 004 control points, 640 GB.
    let mut s = huge_span();
    let err = refine_uniform(&mut s, 100_000).unwrap_err();
    assert!(matches!(err, Error::TooLarge { .. }), "{err}");
    assert!(err.to_string().contains("100006x100004"), "{err}");
    assert_eq!(s.n_u(), 6, "nothing was refined");
}
