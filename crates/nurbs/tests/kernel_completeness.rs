//! The kernel operations of issue 21 checked against the existing ones and against
//! closed forms: knot insertion to multiplicity p + 1 (and splitting there), degree
//! elevation of periodic splines without clamping, degree reduction (of curves and of
//! surfaces in u or v), removal of every
//! removable knot within a tolerance, and control points at infinity (weight 0).

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, Error, KnotVector, NurbsCurve, NurbsSurface, Surface};
use cadmorph_testkit::strategies::{lerp, nurbs_curve, nurbs_surface};
use proptest::prelude::*;

/// Insertion, elevation and the unclamping after it are exact in real arithmetic;
/// in f64 each convex combination (or its inverse) loses a few ulps.
const EXACT_OPS: f64 = 1e-11;

fn curve_scale(c: &NurbsCurve) -> f64 {
    c.control_points().iter().map(|p| p.coords.norm()).fold(1.0, f64::max)
}

fn surface_scale(s: &NurbsSurface) -> f64 {
    s.control_points().iter().map(|p| p.coords.norm()).fold(1.0, f64::max)
}

/// Parameters across the domain of `a`, its knots included.
fn params(d: &std::ops::RangeInclusive<f64>, knots: &KnotVector, n: usize) -> Vec<f64> {
    let mut t: Vec<f64> = (0..=n).map(|i| lerp(d, i as f64 / n as f64)).collect();
    t.extend(knots.distinct().0.into_iter().filter(|k| d.contains(k)));
    t
}

fn same_curve(a: &NurbsCurve, b: &NurbsCurve, tol: f64) -> Result<(), TestCaseError> {
    let scale = curve_scale(a);
    for t in params(&a.domain(), a.knots(), 29) {
        let e = (a.eval(t) - b.eval(t)).norm() / scale;
        prop_assert!(e <= tol, "differ by {e:e} relative at t = {t}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Inserting to multiplicity p + 1 changes no point; the curve's two sides of the
    /// knot then have separate control points that meet at C(u), and the pieces from
    /// `split` evaluate like the curve on their side.
    #[test]
    fn insertion_to_p_plus_one_keeps_both_sides(c in nurbs_curve(1..=5), f in 0.02f64..0.98) {
        let p = c.degree();
        let u = lerp(&c.domain(), f);
        let s = c.knots().multiplicity(u, 0.0);
        let mut d = c.clone();
        let r = d.insert_knot(u, p + 3).unwrap();
        prop_assert_eq!(r, p + 1 - s);
        prop_assert_eq!(d.knots().multiplicity(u, 0.0), p + 1);
        prop_assert_eq!(d.control_points().len(), c.control_points().len() + r);
        same_curve(&c, &d, EXACT_OPS)?;
        // Just left of u, the derivative from the left piece agrees with the original.
        let h = 1e-7 * (c.domain().end() - c.domain().start());
        let scale = curve_scale(&c);
        for t in [u - h, u + h] {
            prop_assert!((d.eval(t) - c.eval(t)).norm() <= EXACT_OPS * scale);
        }
        // The doubled control point is C(u) (on the curve, both copies).
        let last = d.knots().as_slice().iter().rposition(|&k| k == u).unwrap();
        let (a, b) = (d.control_points()[last - p], d.control_points()[last - p - 1]);
        prop_assert!((a - c.eval(u)).norm() <= EXACT_OPS * scale, "right piece starts at C(u)");
        prop_assert!((b - c.eval(u)).norm() <= EXACT_OPS * scale, "left piece ends at C(u)");
        // No further copy fits.
        prop_assert_eq!(d.insert_knot(u, 1).unwrap(), 0);
        // Splitting at the C⁻¹ knot gives the two pieces.
        let (l, rr) = d.split(u).unwrap();
        for t in params(&c.domain(), c.knots(), 19) {
            let half = if t <= u { &l } else { &rr };
            prop_assert!((half.eval(t) - c.eval(t)).norm() <= EXACT_OPS * scale);
        }
        prop_assert_eq!(l.control_points().len() + rr.control_points().len(), d.control_points().len());
        // Knot removal (A5.8) takes the copies out again, the C⁻¹ one included.
        let mut back = d.clone();
        prop_assert_eq!(back.remove_knot(u, r, 1e-9 * scale), r);
        prop_assert_eq!(back.knots(), c.knots());
        same_curve(&c, &back, 1e-9)?;
        // Bézier segments after a knot of multiplicity p + 1 are still the curve's.
        for seg in d.bezier_segments() {
            for i in 0..=4 {
                let t = lerp(&seg.domain(), f64::from(i) / 4.0);
                prop_assert!((seg.eval(t) - c.eval(t)).norm() <= EXACT_OPS * scale);
            }
        }
    }

    /// Degree reduction undoes degree elevation: same degree, knots and control points,
    /// and a bound at rounding level.
    #[test]
    fn reduce_after_elevate_is_identity(c in nurbs_curve(1..=4), t in 1usize..3) {
        let scale = curve_scale(&c);
        let mut d = c.clone();
        d.elevate_degree(t).unwrap();
        for _ in 0..t {
            let bound = d.reduce_degree(1e-9 * scale).unwrap();
            prop_assert!(bound <= 1e-9 * scale);
        }
        prop_assert_eq!(d.degree(), c.degree());
        prop_assert_eq!(d.knots().len(), c.knots().len());
        for (a, b) in d.knots().as_slice().iter().zip(c.knots().as_slice()) {
            prop_assert!((a - b).abs() <= 1e-12 * scale, "{:?} vs {:?}", d.knots(), c.knots());
        }
        for (a, b) in d.control_points().iter().zip(c.control_points()) {
            prop_assert!((a - b).norm() <= 1e-8 * scale, "{} vs {}", a, b);
        }
        same_curve(&c, &d, 1e-9)?;
    }

    /// On curves that are not of lower degree, the bound reduction reports holds: no
    /// sampled point moves further, and a tolerance below the bound is refused with the
    /// curve left untouched.
    #[test]
    fn reduction_bound_holds(c in nurbs_curve(2..=5)) {
        let mut d = c.clone();
        let bound = match d.reduce_degree(1e9) {
            Ok(bound) => bound,
            Err(e) => {
                // Only a rational curve whose reduced weights leave the positive range
                // has no bound.
                prop_assert!(c.is_rational(), "{e}");
                prop_assert!(matches!(e, Error::Tolerance { bound, .. } if bound.is_infinite()), "{e}");
                prop_assert_eq!(&d, &c);
                return Ok(());
            }
        };
        prop_assert_eq!(d.degree(), c.degree() - 1);
        for t in params(&c.domain(), c.knots(), 101) {
            let e = (d.eval(t) - c.eval(t)).norm();
            prop_assert!(e <= bound * (1.0 + 1e-9) + 1e-12 * curve_scale(&c), "moved {e} > bound {bound} at {t}");
        }
        if bound > 1e-6 {
            let mut e = c.clone();
            let refused = matches!(e.reduce_degree(bound * 0.5), Err(Error::Tolerance { .. }));
            prop_assert!(refused, "a tolerance below the bound was accepted");
            prop_assert_eq!(&e, &c);
        }
    }

    /// Knots inserted into a curve come out again under `remove_knots_within`, and the
    /// bound it reports holds on samples for a coarse tolerance.
    #[test]
    fn remove_knots_within_undoes_refinement(c in nurbs_curve(1..=4), fs in prop::collection::vec(0.01f64..0.99, 1..6)) {
        let scale = curve_scale(&c);
        let mut x: Vec<f64> = fs.iter().map(|&f| lerp(&c.domain(), f)).collect();
        x.retain(|&k| c.knots().multiplicity(k, 0.0) == 0);
        x.sort_by(f64::total_cmp);
        x.dedup();
        let mut d = c.clone();
        d.refine(&x).unwrap();
        let out = d.remove_knots_within(1e-9 * scale);
        prop_assert!(out.removed >= x.len(), "removed {} of {} inserted", out.removed, x.len());
        prop_assert!(d.knots().len() <= c.knots().len());
        prop_assert!(out.bound <= 1e-9 * scale);
        same_curve(&c, &d, 1e-8)?;
        let mut e = c.clone();
        let coarse = e.remove_knots_within(0.05 * scale);
        for t in params(&c.domain(), c.knots(), 101) {
            let dev = (e.eval(t) - c.eval(t)).norm();
            prop_assert!(dev <= coarse.bound * (1.0 + 1e-9) + 1e-12 * scale, "moved {dev} > bound {}", coarse.bound);
        }
        prop_assert!(coarse.bound <= 0.05 * scale);
    }

    /// The same on surfaces, in u then in v.
    #[test]
    fn surface_insertion_to_p_plus_one(s in nurbs_surface(1..=3), fu in 0.05f64..0.95, fv in 0.05f64..0.95) {
        let (ud, vd) = s.domain();
        let (u, v) = (lerp(&ud, fu), lerp(&vd, fv));
        let mut a = s.clone();
        a.insert_u_knot(u, s.u_degree() + 1).unwrap();
        a.insert_v_knot(v, s.v_degree() + 1).unwrap();
        prop_assert_eq!(a.u_knots().multiplicity(u, 0.0), s.u_degree() + 1);
        prop_assert_eq!(a.v_knots().multiplicity(v, 0.0), s.v_degree() + 1);
        let scale = surface_scale(&s);
        for (x, y) in cadmorph_testkit::grid(&s, 9) {
            prop_assert!((a.eval(x, y) - s.eval(x, y)).norm() <= EXACT_OPS * scale);
        }
    }

    /// Degree elevation of an unclamped spline keeps it unclamped and unchanged.
    #[test]
    fn unclamped_elevation_keeps_geometry(c in nurbs_curve(1..=4), t in 1usize..3) {
        let p = c.degree();
        // Unclamp `c` by giving it uniform outer knots: the same control points on
        // another knot vector make another, unclamped curve.
        let ks = c.knots().as_slice();
        let (a, b) = (ks[0], ks[ks.len() - 1]);
        let h = (b - a) / 7.0;
        let mut u = ks.to_vec();
        for i in 0..p {
            u[i] = a - (p - i) as f64 * h;
            let m = u.len() - 1;
            u[m - i] = b + (p - i) as f64 * h;
        }
        let unclamped = NurbsCurve::try_new(p, KnotVector::try_new(u).unwrap(), c.control_points().to_vec(),
            c.weights().map(<[f64]>::to_vec)).unwrap();
        let mut e = unclamped.clone();
        e.elevate_degree(t).unwrap();
        prop_assert_eq!(e.degree(), p + t);
        prop_assert_eq!(e.domain(), unclamped.domain());
        prop_assert!(!e.knots().is_clamped(p + t), "stays unclamped");
        // The outer knots keep their values, each gaining t copies.
        let ek = e.knots().as_slice();
        prop_assert!(ek[..p].iter().all(|&k| k < a), "{:?}", ek);
        prop_assert!(ek[p..=p + t].iter().all(|&k| k == a), "{:?}", ek);
        same_curve(&unclamped, &e, EXACT_OPS)?;
    }
}

/// A periodic cubic (OCCT form, The NURBS Book §12.2) elevated to degree 5: the
/// result is the periodic quintic on the same knots with every multiplicity raised by
/// 2 (`KnotVector::periodic` builds that vector independently), its first 5 poles
/// repeat at the end, and it is the same curve.
#[test]
fn periodic_elevation_stays_periodic() {
    let values: Vec<f64> = (0..=6).map(f64::from).collect();
    let poles: Vec<Point3<f64>> = (0..6)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / 6.0;
            Point3::new(2.0 * a.cos(), a.sin(), 0.3 * f64::from(i % 2))
        })
        .collect();
    for (weights, mults) in [(None, vec![1; 7]), (Some(vec![1.0, 2.0, 0.5, 1.5, 1.0, 3.0]), vec![1; 7])] {
        let c = NurbsCurve::try_periodic(3, &values, &mults, poles.clone(), weights).unwrap();
        let mut e = c.clone();
        e.elevate_degree(2).unwrap();
        let raised: Vec<usize> = mults.iter().map(|m| m + 2).collect();
        let expected = KnotVector::periodic(5, &values, &raised).unwrap();
        assert_eq!(e.knots().len(), expected.len());
        for (a, b) in e.knots().as_slice().iter().zip(expected.as_slice()) {
            assert!((a - b).abs() < 1e-12, "{:?} vs {:?}", e.knots(), expected);
        }
        let n = e.control_points().len();
        for i in 0..5 {
            let (a, b) = (e.control_points()[i], e.control_points()[n - 5 + i]);
            assert!((a - b).norm() < 1e-10, "pole {i} does not wrap: {a} vs {b}");
        }
        for i in 0..=60 {
            let t = 6.0 * f64::from(i) / 60.0;
            assert!((e.eval(t) - c.eval(t)).norm() < 1e-11, "at {t}");
        }
    }
}

/// A surface periodic in u elevated in u stays unclamped there and unchanged.
#[test]
fn periodic_surface_elevation() {
    let p = 2;
    let values: Vec<f64> = (0..=5).map(f64::from).collect();
    let uk = KnotVector::periodic(p, &values, &[1; 6]).unwrap();
    let vk = KnotVector::clamped_uniform(1, 2);
    let n_u = uk.len() - p - 1;
    let mut pts = Vec::new();
    for i in 0..n_u {
        let a = std::f64::consts::TAU * ((i % 5) as f64) / 5.0;
        for j in 0..2 {
            pts.push(Point3::new(a.cos(), a.sin(), j as f64));
        }
    }
    let s = NurbsSurface::try_new((p, 1), (uk, vk), (n_u, 2), pts, None).unwrap();
    let mut e = s.clone();
    e.elevate_u_degree(1).unwrap();
    assert!(!e.u_knots().is_clamped(3));
    for (u, v) in cadmorph_testkit::grid(&s, 11) {
        assert!((e.eval(u, v) - s.eval(u, v)).norm() < 1e-11);
    }
}

/// Surface points across both domains, knots included.
fn surface_params(s: &NurbsSurface, n: usize) -> Vec<(f64, f64)> {
    let (du, dv) = s.domain();
    let us = params(&du, s.u_knots(), n);
    let vs = params(&dv, s.v_knots(), n);
    us.iter().flat_map(|&u| vs.iter().map(move |&v| (u, v))).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Surface degree reduction undoes elevation in either direction: same degrees,
    /// knots and net, a bound at rounding level.
    #[test]
    fn surface_reduce_after_elevate_is_identity(s in nurbs_surface(1..=3), t in 1usize..3, in_v in any::<bool>()) {
        let scale = surface_scale(&s);
        let mut d = s.clone();
        if in_v { d.elevate_v_degree(t).unwrap() } else { d.elevate_u_degree(t).unwrap() }
        for _ in 0..t {
            let bound = if in_v { d.reduce_v_degree(1e-9 * scale) } else { d.reduce_u_degree(1e-9 * scale) }.unwrap();
            prop_assert!(bound <= 1e-9 * scale);
        }
        prop_assert_eq!((d.u_degree(), d.v_degree()), (s.u_degree(), s.v_degree()));
        prop_assert_eq!((d.n_u(), d.n_v()), (s.n_u(), s.n_v()));
        for (a, b) in d.control_points().iter().zip(s.control_points()) {
            prop_assert!((a - b).norm() <= 1e-8 * scale, "{} vs {}", a, b);
        }
        for (u, v) in surface_params(&s, 9) {
            prop_assert!((d.eval(u, v) - s.eval(u, v)).norm() <= 1e-9 * scale);
        }
    }

    /// On surfaces not of lower degree, the reported bound holds at sampled points, and
    /// a tolerance below it is refused with the surface untouched.
    #[test]
    fn surface_reduction_bound_holds(s in nurbs_surface(2..=4), in_v in any::<bool>()) {
        let mut d = s.clone();
        let reduced = if in_v { d.reduce_v_degree(1e9) } else { d.reduce_u_degree(1e9) };
        let bound = match reduced {
            Ok(bound) => bound,
            Err(e) => {
                prop_assert!(s.is_rational(), "{e}");
                prop_assert!(matches!(e, Error::Tolerance { bound, .. } if bound.is_infinite()), "{e}");
                prop_assert_eq!(&d, &s);
                return Ok(());
            }
        };
        let want = if in_v { (s.u_degree(), s.v_degree() - 1) } else { (s.u_degree() - 1, s.v_degree()) };
        prop_assert_eq!((d.u_degree(), d.v_degree()), want);
        for (u, v) in surface_params(&s, 17) {
            let e = (d.eval(u, v) - s.eval(u, v)).norm();
            prop_assert!(e <= bound * (1.0 + 1e-9) + 1e-12 * surface_scale(&s), "moved {e} > bound {bound} at ({u}, {v})");
        }
        if bound > 1e-6 {
            let mut e = s.clone();
            let r = if in_v { e.reduce_v_degree(bound * 0.5) } else { e.reduce_u_degree(bound * 0.5) };
            prop_assert!(matches!(r, Err(Error::Tolerance { .. })), "a tolerance below the bound was accepted");
            prop_assert_eq!(&e, &s);
        }
    }
}

/// The parabola `(2t, 4t(1 − t))`, a quadratic Bézier on (0,0), (1,2), (2,0), reduced
/// to the line from (0,0) to (2,0): the true deviation is the height 1 at t = 1/2, the
/// bound (re-elevated middle point (1,0) against (1,2)) is 2. Below 2 it is refused.
#[test]
fn parabola_to_line() {
    let k = KnotVector::clamped_uniform(2, 3);
    let pts = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 2.0, 0.0), Point3::new(2.0, 0.0, 0.0)];
    let c = NurbsCurve::try_new(2, k, pts, None).unwrap();
    assert!((c.eval(0.5).y - 1.0).abs() < 1e-15);
    let mut d = c.clone();
    assert!(matches!(d.reduce_degree(1.5), Err(Error::Tolerance { operation: "degree reduction", .. })));
    let bound = d.reduce_degree(2.0).unwrap();
    assert!((bound - 2.0).abs() < 1e-15);
    assert_eq!(d.degree(), 1);
    assert_eq!(d.control_points(), &[Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 0.0, 0.0)]);
    let mut line = d.clone();
    assert!(matches!(line.reduce_degree(10.0), Err(Error::Degree { degree: 0 })));
}

/// The parabola of [`parabola_to_line`] swept along z (quadratic in u, linear in v):
/// reduced in u it becomes the plane strip between the two lines, with the same bound 2;
/// below 2 it is refused; in v (already linear) there is nothing to reduce.
#[test]
fn parabolic_strip_to_plane() {
    let ku = KnotVector::clamped_uniform(2, 3);
    let kv = KnotVector::clamped_uniform(1, 2);
    let row = [(0.0, 0.0), (1.0, 2.0), (2.0, 0.0)];
    let pts: Vec<Point3<f64>> =
        row.iter().flat_map(|&(x, y)| [Point3::new(x, y, 0.0), Point3::new(x, y, 3.0)]).collect();
    let s = NurbsSurface::try_new((2, 1), (ku, kv), (3, 2), pts, None).unwrap();
    let mut d = s.clone();
    assert!(matches!(d.reduce_u_degree(1.5), Err(Error::Tolerance { operation: "degree reduction", .. })));
    assert_eq!(d, s);
    let bound = d.reduce_u_degree(2.0).unwrap();
    assert!((bound - 2.0).abs() < 1e-15);
    assert_eq!((d.u_degree(), d.v_degree()), (1, 1));
    let corners = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(0.0, 0.0, 3.0),
        Point3::new(2.0, 0.0, 0.0),
        Point3::new(2.0, 0.0, 3.0),
    ];
    assert_eq!(d.control_points(), &corners);
    assert!(matches!(d.clone().reduce_v_degree(10.0), Err(Error::Degree { degree: 0 })));
}

/// The full ellipse of semi-axes `a`, `b` from two infinite control points (The NURBS
/// Book §7.3: `Pʷ = {(a,0,0,1), (0,b,0,0), (−a,0,0,1), (0,−b,0,0), (a,0,0,1)}`,
/// `U = {0,0,0,½,½,1,1,1}`), against its closed form: on the first half, with
/// `s = 2t`, `x = a((1−s)² − s²)/D`, `y = 2b·s(1−s)/D`, `D = (1−s)² + s²`, and the
/// mirror image below on the second half. `a = b = 1` is the circle.
fn infinite_point_ellipse(a: f64, b: f64) -> NurbsCurve {
    NurbsCurve::try_new(
        2,
        KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0]).unwrap(),
        vec![
            Point3::new(a, 0.0, 0.0),
            Point3::new(0.0, b, 0.0),
            Point3::new(-a, 0.0, 0.0),
            Point3::new(0.0, -b, 0.0),
            Point3::new(a, 0.0, 0.0),
        ],
        Some(vec![1.0, 0.0, 1.0, 0.0, 1.0]),
    )
    .unwrap()
}

fn ellipse_closed_form(a: f64, b: f64, t: f64) -> Point3<f64> {
    let (s, sign) = if t < 0.5 { (2.0 * t, 1.0) } else { (2.0 * t - 1.0, -1.0) };
    let d = (1.0 - s) * (1.0 - s) + s * s;
    Point3::new(sign * a * ((1.0 - s) * (1.0 - s) - s * s) / d, sign * 2.0 * b * s * (1.0 - s) / d, 0.0)
}

#[test]
fn zero_weight_circle_and_ellipse_match_the_closed_form() {
    for (a, b) in [(1.0, 1.0), (3.0, 2.0), (0.5, 4.0)] {
        let c = infinite_point_ellipse(a, b);
        for i in 0..=200 {
            let t = f64::from(i) / 200.0;
            let p = c.try_eval(t).unwrap();
            let want = ellipse_closed_form(a, b, t);
            assert!((p - want).norm() < 1e-14 * a.max(b), "t = {t}: {p} vs {want}");
            assert!(((p.x / a).powi(2) + (p.y / b).powi(2) - 1.0).abs() < 1e-14);
            assert_eq!(c.eval(t), p);
            // The homogeneous point: weight (1−s)² + s², never 0 on this curve.
            let h = c.eval_homogeneous(t);
            assert!(h.w >= 0.5 - 1e-15);
        }
        // Derivative at t = 0: dC/dt = 2 · (2b/1)·ŷ (s = 2t, dy/ds = 2b at s = 0).
        let d = c.derivs(0.0, 1);
        assert!((d[1] - cadmorph_nurbs::math::Vector3::new(0.0, 4.0 * b, 0.0)).norm() < 1e-12, "{:?}", d[1]);
        // The box of the ellipse is [−a, a] × [−b, b] (its control points at infinity
        // are directions and do not bound it).
        let bbox = c.bounding_box();
        assert!(bbox.contains(&Point3::new(a, 0.0, 0.0)) && bbox.contains(&Point3::new(0.0, -b, 0.0)));
        assert!(bbox.max.x <= 2.0 * a && bbox.max.y <= 2.0 * b && bbox.min.y >= -2.0 * b);
        for i in 0..=50 {
            assert!(bbox.contains(&c.eval(f64::from(i) / 50.0)));
        }
        // Moving the ellipse moves its centre, not its directions at infinity.
        let m = nalgebra::Matrix4::new_translation(&cadmorph_nurbs::math::Vector3::new(5.0, -1.0, 2.0));
        let moved = c.transformed(&m);
        for i in 0..=20 {
            let t = f64::from(i) / 20.0;
            let want = ellipse_closed_form(a, b, t) + cadmorph_nurbs::math::Vector3::new(5.0, -1.0, 2.0);
            assert!((moved.eval(t) - want).norm() < 1e-13);
        }
    }
}

/// A curve some of whose control points are at infinity: the exact operations keep
/// its homogeneous form `Cʷ(t)` (they are linear maps of the homogeneous net).
fn with_zero_weights() -> impl Strategy<Value = NurbsCurve> {
    (nurbs_curve(2..=4), prop::collection::vec(any::<bool>(), 10)).prop_map(|(c, zero)| {
        let n = c.control_points().len();
        let mut w = c.weights().map_or_else(|| vec![1.0; n], <[f64]>::to_vec);
        // Interior points only, never two side by side: the curve stays finite.
        for i in (1..n - 1).step_by(2) {
            if zero[i % zero.len()] {
                w[i] = 0.0;
            }
        }
        NurbsCurve::try_new(c.degree(), c.knots().clone(), c.control_points().to_vec(), Some(w)).unwrap()
    })
}

fn same_homogeneous(a: &NurbsCurve, b: &NurbsCurve) -> Result<(), TestCaseError> {
    let scale = curve_scale(a);
    for t in params(&a.domain(), a.knots(), 23) {
        let (x, y) = (a.eval_homogeneous(t), b.eval_homogeneous(t));
        prop_assert!((x - y).norm() <= EXACT_OPS * scale, "differ at {t}: {x:?} vs {y:?}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn zero_weight_curves_under_exact_operations(c in with_zero_weights(), f in 0.05f64..0.95) {
        let u = lerp(&c.domain(), f);
        let mut d = c.clone();
        d.insert_knot(u, c.degree() + 1).unwrap();
        same_homogeneous(&c, &d)?;
        let mut e = c.clone();
        e.elevate_degree(1).unwrap();
        same_homogeneous(&c, &e)?;
        let (l, r) = c.split(u).unwrap();
        for t in params(&c.domain(), c.knots(), 17) {
            let half = if t <= u { &l } else { &r };
            prop_assert!((half.eval_homogeneous(t) - c.eval_homogeneous(t)).norm() <= EXACT_OPS * curve_scale(&c));
        }
        // The box encloses the curve.
        let bbox = c.bounding_box().inflated(1e-9 * curve_scale(&c));
        for t in params(&c.domain(), c.knots(), 17) {
            prop_assert!(bbox.contains(&c.eval(t)), "{} outside {:?}", c.eval(t), bbox);
        }
        // The Cartesian point is the homogeneous one divided, where it is finite.
        for t in params(&c.domain(), c.knots(), 17) {
            let h = c.eval_homogeneous(t);
            match c.try_eval(t) {
                Ok(p) => prop_assert!((p.coords * h.w - h.xyz()).norm() <= 1e-12 * curve_scale(&c)),
                Err(_) => prop_assert_eq!(h.w, 0.0),
            }
        }
    }
}

/// The elliptic cylinder swept from the ellipse with points at infinity along z
/// (degree (2, 1)): `S(u, v) = E(u) + (0, 0, 2v)` with `E` the closed form above.
/// Evaluation, first derivatives, iso curves, refinement, elevation and the bounding
/// box all see the closed form.
#[test]
fn zero_weight_cylinder_matches_the_closed_form() {
    let (a, b) = (3.0, 2.0);
    let ring = infinite_point_ellipse(a, b);
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for (p, &wi) in ring.control_points().iter().zip(ring.weights().unwrap()) {
        for j in 0..2 {
            // A direction is the same on both ends of the sweep; a point moves up.
            let z = if wi == 0.0 { 0.0 } else { 2.0 * f64::from(j) };
            pts.push(Point3::new(p.x, p.y, z));
            w.push(wi);
        }
    }
    let s =
        NurbsSurface::try_new((2, 1), (ring.knots().clone(), KnotVector::clamped_uniform(1, 2)), (5, 2), pts, Some(w))
            .unwrap();
    let mut refined = s.clone();
    refined.refine_u(&[0.2, 0.7]).unwrap();
    refined.refine_v(&[0.4]).unwrap();
    let mut elevated = s.clone();
    elevated.elevate_u_degree(1).unwrap();
    elevated.elevate_v_degree(1).unwrap();
    let bbox = s.bounding_box();
    for i in 0..=40 {
        for j in 0..=4 {
            let (u, v) = (f64::from(i) / 40.0, f64::from(j) / 4.0);
            let want = ellipse_closed_form(a, b, u) + cadmorph_nurbs::math::Vector3::new(0.0, 0.0, 2.0 * v);
            for (name, x) in [("plain", &s), ("refined", &refined), ("elevated", &elevated)] {
                let p = x.try_eval(u, v).unwrap();
                assert!((p - want).norm() < 1e-13, "{name} at ({u}, {v}): {p} vs {want}");
                assert!((x.eval(u, v) - want).norm() < 1e-13, "{name}");
            }
            assert!(bbox.inflated(1e-12).contains(&want));
            let d = s.eval_d1(u, v);
            assert!((d.dv - cadmorph_nurbs::math::Vector3::new(0.0, 0.0, 2.0)).norm() < 1e-12);
            let dc = ring.derivs(u, 1)[1];
            assert!((d.du - dc).norm() < 1e-11 * (1.0 + dc.norm()), "{:?} vs {:?}", d.du, dc);
        }
    }
    assert!(bbox.max.x <= 2.0 * a && bbox.min.y >= -2.0 * b);
    let iso = s.v_iso(0.5);
    for i in 0..=20 {
        let u = f64::from(i) / 20.0;
        assert!(
            (iso.eval(u) - (ellipse_closed_form(a, b, u) + cadmorph_nurbs::math::Vector3::new(0.0, 0.0, 1.0))).norm()
                < 1e-13
        );
    }
}
