//! Closing seams and poles: a face closed in u pairs its own two u sides (measured like
//! any edge), a collapsed side (a pole) pairs with nothing, and a narrow strip's two
//! long sides are not mistaken for a closing seam.

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsSurface, Side};
use cadmorph_seam::{closing_seams, measure_boundary, shared_boundaries, Face};

/// A square pyramid's mantle as one bilinear-by-pieces patch: u runs around the base
/// square (first and last poles equal, so it is closed in u), v from the apex (a pole:
/// the whole v = 0 side is one point) to the base. `open` moves the last u row by that
/// much in x, away from the first.
fn pyramid(open: f64) -> NurbsSurface {
    let base = [[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0], [1.0, 1.0]];
    let mut pts = Vec::new();
    for (i, [x, y]) in base.iter().enumerate() {
        let dx = if i == base.len() - 1 { open } else { 0.0 };
        pts.push(Point3::new(dx, 0.0, 2.0));
        pts.push(Point3::new(x + dx, *y, 0.0));
    }
    NurbsSurface::try_new(
        (1, 1),
        (KnotVector::clamped_uniform(1, 5), KnotVector::clamped_uniform(1, 2)),
        (5, 2),
        pts,
        None,
    )
    .unwrap()
}

#[test]
fn a_closed_face_pairs_its_own_sides_and_its_pole_pairs_with_nothing() {
    let s = pyramid(0.0);
    let edges = shared_boundaries(&[&s], 1e-6, 64, 0.9);
    assert_eq!(edges.len(), 1, "{edges:?}");
    let e = &edges[0];
    assert_eq!((e.a.patch, e.b.patch, e.a.side, e.b.side), (0, 0, Side::UMin, Side::UMax));
    let faces = [Face { surface: &s, reversed: false }];
    let r = measure_boundary(&faces, e, 50);
    assert!(r.gap_closest.max <= 1e-15 && r.gap_matched.max <= 1e-15, "{r:?}");
    // The seam runs down a corner of the pyramid: a crease (the mantle's faces meet at
    // the dihedral angle of a square pyramid of height 2 over a 2 x 2 base).
    assert!(r.sharp, "{r:?}");
    // Its length is the lateral edge: sqrt(1 + 1 + 4).
    assert!((r.length - 6f64.sqrt()).abs() < 1e-12, "{}", r.length);
}

#[test]
fn a_closing_seam_opened_beyond_the_pairing_tolerance_is_still_seen() {
    // 0.02 apart: 20 000 times the pairing tolerance, but 0.5 % of the way around the
    // face (the loop at mid height is 4 long).
    let s = pyramid(0.02);
    let edges = shared_boundaries(&[&s], 1e-6, 64, 0.9);
    assert_eq!(edges.len(), 1, "{edges:?}");
    let faces = [Face { surface: &s, reversed: false }];
    let r = measure_boundary(&faces, &edges[0], 101);
    // The boundary is the last pole row, moved by 0.02 along its whole length.
    assert!((r.gap_matched.max - 0.02).abs() < 1e-12, "{r:?}");
}

#[test]
fn a_narrow_strip_is_not_closed() {
    // A 10 x 0.01 strip: its two long sides are 0.01 apart, the whole way across.
    let strip = NurbsSurface::bilinear([[0., 0., 0.], [10., 0., 0.], [0., 0.01, 0.], [10., 0.01, 0.]]);
    assert!(closing_seams(&[&strip], 1e-6, 64, 0.9).is_empty());
    assert!(shared_boundaries(&[&strip], 1e-6, 64, 0.9).is_empty());
}

/// A whole torus is closed in both directions, and each pair of its sides are circles
/// themselves: matched by their shared parameter, both closing seams are exact (paired
/// by projection instead, a circle's end lands on either end of the other and the
/// "seam" compared points half a turn apart: 2(R + r) = 50 on this torus, as measured on
/// an OCCT-written torus before the fix).
#[test]
fn a_torus_has_two_exact_closing_seams() {
    use cadmorph_nurbs::analytic::{AnalyticSurface, Placement, Torus};
    use std::f64::consts::{PI, TAU};
    let t = Torus::try_new(Placement::standard(), 20.0, 5.0).unwrap();
    let s = t.to_nurbs(0.0..=TAU, -PI..=PI).unwrap().surface;
    let edges = closing_seams(&[&s], 1e-6, 64, 0.9);
    assert_eq!(edges.len(), 2, "{edges:?}");
    let faces = [Face { surface: &s, reversed: false }];
    for e in &edges {
        let r = measure_boundary(&faces, e, 101);
        assert!(r.gap_closest.max <= 1e-12 && r.gap_matched.max <= 1e-12, "{e:?}: {r:?}");
        assert!(r.length > 0.999 * 2.0 * PI * 5.0, "{e:?}: the whole side, {}", r.length);
    }
}
