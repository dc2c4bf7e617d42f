//! Moving the seam of a closed surface (`reseamed_u`, `reseamed_v`): the same points
//! under the parameter shift, the new domain, and refusals for surfaces that do not close.

use cadmorph_nurbs::analytic::{AnalyticSurface, Placement, Sphere, Torus};
use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{NurbsSurface, Surface};
use std::f64::consts::{FRAC_PI_2, TAU};

/// `r(u, v) == s(u', v)` for `u' ≡ u` modulo the period, over a grid of the new domain
/// (knots of both included), to `tol`.
fn same_under_shift(s: &NurbsSurface, r: &NurbsSurface, in_u: bool, tol: f64) {
    let (sd, rd) = (s.domain(), r.domain());
    let (a, b) = if in_u { (sd.0.clone(), rd.0.clone()) } else { (sd.1.clone(), rd.1.clone()) };
    let period = a.end() - a.start();
    assert!(((b.end() - b.start()) - period).abs() <= 1e-12 * period, "the period is kept");
    let other = if in_u { rd.1.clone() } else { rd.0.clone() };
    for i in 0..=40 {
        let t = b.start() + (b.end() - b.start()) * i as f64 / 40.0;
        let back = (a.start() + (t - a.start()).rem_euclid(period)).min(*a.end());
        for j in 0..=8 {
            let w = other.start() + (other.end() - other.start()) * j as f64 / 8.0;
            let (p, q) = if in_u { (r.eval(t, w), s.eval(back, w)) } else { (r.eval(w, t), s.eval(w, back)) };
            assert!((p - q).norm() <= tol, "at {t}, {w}: {:e}", (p - q).norm());
        }
    }
}

#[test]
fn a_sphere_reseamed_anywhere_is_the_same_sphere() {
    let f =
        Placement::try_new(Point3::new(10.0, -3.0, 2.0), Vector3::new(0.3, -0.2, 0.9), Vector3::new(0.9, 0.0, -0.3))
            .unwrap();
    let s = Sphere::try_new(f, 3.0).unwrap().to_nurbs(0.0..=TAU, -FRAC_PI_2..=FRAC_PI_2).unwrap().surface;
    let (ud, _) = s.domain();
    let (u0, u1) = (*ud.start(), *ud.end());
    // Inside a span, on a knot between quarter arcs, and beyond the domain (taken modulo).
    for c in [u0 + 0.1 * (u1 - u0), u0 + 0.25 * (u1 - u0), u0 + 0.6180339 * (u1 - u0), u1 + 0.3 * (u1 - u0)] {
        let r = s.reseamed_u(c, 1e-12).unwrap();
        let start = u0 + (c - u0).rem_euclid(u1 - u0);
        assert!((r.domain().0.start() - start).abs() < 1e-12);
        same_under_shift(&s, &r, true, 1e-12);
        // The new seam closes: its first and last iso-lines are one curve.
        let (rd, vd) = r.domain();
        for j in 0..=6 {
            let v = vd.start() + (vd.end() - vd.start()) * j as f64 / 6.0;
            assert!((r.eval(*rd.start(), v) - r.eval(*rd.end(), v)).norm() < 1e-12);
        }
    }
    // At the seam itself: unchanged.
    assert_eq!(s.reseamed_u(u0, 1e-12).unwrap(), s);
}

#[test]
fn a_torus_reseamed_in_both_directions() {
    let s = Torus::try_new(Placement::standard(), 5.0, 1.5).unwrap().to_nurbs(0.0..=TAU, 0.0..=TAU).unwrap().surface;
    let (ud, vd) = s.domain();
    let cu = ud.start() + 0.37 * (ud.end() - ud.start());
    let cv = vd.start() + 0.81 * (vd.end() - vd.start());
    let r = s.reseamed_u(cu, 1e-12).unwrap();
    same_under_shift(&s, &r, true, 1e-12);
    let rv = s.reseamed_v(cv, 1e-12).unwrap();
    same_under_shift(&s, &rv, false, 1e-12);
    let both = r.reseamed_v(cv, 1e-12).unwrap();
    same_under_shift(&r, &both, false, 1e-12);
}

#[test]
fn a_surface_that_does_not_close_is_refused() {
    // Half a sphere in u: its first and last meridians are half a turn apart.
    let s = Sphere::try_new(Placement::standard(), 1.0).unwrap().to_nurbs(0.0..=3.0, -1.0..=1.0).unwrap().surface;
    let (ud, _) = s.domain();
    let c = 0.5 * (ud.start() + ud.end());
    assert!(matches!(s.reseamed_u(c, 1e-9), Err(cadmorph_nurbs::Error::Periodic { .. })));
    assert!(s.reseamed_u(f64::NAN, 1e-9).is_err());
}
