//! Property tests: operations that must not change the geometry, on random valid
//! curves and surfaces, rational ones included.

use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface, Side, Surface};
use cadmorph_testkit::strategies::{lerp, nurbs_curve, nurbs_surface};
use proptest::prelude::*;

/// Insertion, refinement, elevation and splitting are exact in real arithmetic; in f64
/// the convex combinations lose a few ulps per step. 1e-12 of the model size is the
/// issue's claim.
const REFINE_INVARIANCE: f64 = 1e-12;
/// Central differences with h = 1e-6 of the parameter range: truncation error
/// ~h²·|C'''|, rounding ~ε·|C|/h; 1e-6 relative covers both for these random nets.
const FINITE_DIFFERENCE: f64 = 1e-6;

fn curve_scale(c: &NurbsCurve) -> f64 {
    c.control_points().iter().map(|p| p.coords.norm()).fold(1.0, f64::max)
}

fn surface_scale(s: &NurbsSurface) -> f64 {
    s.control_points().iter().map(|p| p.coords.norm()).fold(1.0, f64::max)
}

fn curve_params(c: &NurbsCurve, n: usize) -> Vec<f64> {
    let d = c.domain();
    let mut t: Vec<f64> = (0..=n).map(|i| lerp(&d, i as f64 / n as f64)).collect();
    t.extend(c.knots().distinct().0.into_iter().filter(|k| d.contains(k)));
    t
}

fn same_curve(a: &NurbsCurve, b: &NurbsCurve, tol: f64) -> Result<(), TestCaseError> {
    let scale = curve_scale(a);
    for t in curve_params(a, 23) {
        let e = (a.eval(t) - b.eval(t)).norm() / scale;
        prop_assert!(e <= tol, "differ by {e:e} relative at t = {t}");
    }
    Ok(())
}

fn same_surface(a: &NurbsSurface, b: &NurbsSurface, tol: f64) -> Result<(), TestCaseError> {
    let scale = surface_scale(a);
    for (u, v) in cadmorph_testkit::grid(a, 9) {
        let e = (a.eval(u, v) - b.eval(u, v)).norm() / scale;
        prop_assert!(e <= tol, "differ by {e:e} relative at ({u}, {v})");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn curve_insertion_keeps_geometry(c in nurbs_curve(1..=5), f in 0.0f64..=1.0, times in 1usize..4) {
        let u = lerp(&c.domain(), f);
        let mut d = c.clone();
        let r = d.insert_knot(u, times).unwrap();
        prop_assert_eq!(d.control_points().len(), c.control_points().len() + r);
        same_curve(&c, &d, REFINE_INVARIANCE)?;
    }

    #[test]
    fn curve_refinement_keeps_geometry(c in nurbs_curve(1..=5), fs in prop::collection::vec(0.001f64..0.999, 0..12)) {
        let d0 = c.domain();
        // Keep multiplicities within the degree.
        let mut x: Vec<f64> = fs.iter().map(|&f| lerp(&d0, f)).collect();
        x.retain(|&k| c.knots().multiplicity(k, 0.0) == 0);
        x.sort_by(f64::total_cmp);
        x.dedup();
        let mut d = c.clone();
        d.refine(&x).unwrap();
        prop_assert_eq!(d.knots().len(), c.knots().len() + x.len());
        same_curve(&c, &d, REFINE_INVARIANCE)?;
    }

    #[test]
    fn curve_elevation_keeps_geometry(c in nurbs_curve(1..=4), t in 1usize..3) {
        let mut d = c.clone();
        d.elevate_degree(t).unwrap();
        prop_assert_eq!(d.degree(), c.degree() + t);
        same_curve(&c, &d, REFINE_INVARIANCE)?;
    }

    #[test]
    fn curve_removal_of_inserted_knot_restores(c in nurbs_curve(2..=5), f in 0.01f64..0.99) {
        let u = lerp(&c.domain(), f);
        prop_assume!(c.knots().multiplicity(u, 0.0) == 0);
        let mut d = c.clone();
        let r = d.insert_knot(u, 2).unwrap();
        prop_assert_eq!(d.remove_knot(u, r, 1e-9 * curve_scale(&c)), r);
        prop_assert_eq!(d.knots(), c.knots());
        let scale = curve_scale(&c);
        for (p, q) in d.control_points().iter().zip(c.control_points()) {
            prop_assert!((p - q).norm() <= 1e-9 * scale);
        }
        same_curve(&c, &d, REFINE_INVARIANCE)?;
    }

    #[test]
    fn curve_split_and_reverse(c in nurbs_curve(1..=5), f in 0.01f64..0.99) {
        let d = c.domain();
        let t = lerp(&d, f);
        let (l, r) = c.split(t).unwrap();
        let scale = curve_scale(&c);
        for s in curve_params(&c, 31) {
            let half = if s <= t { &l } else { &r };
            prop_assert!((half.eval(s) - c.eval(s)).norm() <= REFINE_INVARIANCE * scale);
        }
        let rev = c.reversed();
        for s in curve_params(&c, 17) {
            let e = (rev.eval(d.start() + d.end() - s) - c.eval(s)).norm();
            prop_assert!(e <= REFINE_INVARIANCE * scale);
        }
        let segs = c.bezier_segments();
        for seg in &segs {
            prop_assert_eq!(seg.control_points().len(), c.degree() + 1);
            for i in 0..=4 {
                let s = lerp(&seg.domain(), i as f64 / 4.0);
                prop_assert!((seg.eval(s) - c.eval(s)).norm() <= REFINE_INVARIANCE * scale);
            }
        }
    }

    #[test]
    fn curve_derivatives_match_central_differences(c in nurbs_curve(1..=5), f in 0.02f64..0.98) {
        let d = c.domain();
        let t = lerp(&d, f);
        // Stay inside one knot span so the difference quotient sees one polynomial.
        let h = 1e-6 * (d.end() - d.start());
        prop_assume!(c.knots().as_slice().iter().all(|&k| (k - t).abs() > 2.0 * h));
        let ders = c.derivs(t, 2);
        let fd1 = (c.eval(t + h) - c.eval(t - h)) / (2.0 * h);
        let scale = curve_scale(&c) / (d.end() - d.start());
        prop_assert!((ders[1] - fd1).norm() <= FINITE_DIFFERENCE * scale * c.degree() as f64 * 10.0,
            "d1 {:?} vs {:?}", ders[1], fd1);
        let f2 = c.derivs(t + h, 1)[1] - c.derivs(t - h, 1)[1];
        let fd2: Vector3<f64> = f2 / (2.0 * h);
        prop_assert!((ders[2] - fd2).norm() <= FINITE_DIFFERENCE * (1.0 + ders[2].norm()) * 100.0,
            "d2 {:?} vs {:?}", ders[2], fd2);
    }

    #[test]
    fn surface_insertion_refinement_keep_geometry(s in nurbs_surface(1..=4), fu in 0.01f64..0.99, fv in 0.01f64..0.99) {
        let (ud, vd) = s.domain();
        let (u, v) = (lerp(&ud, fu), lerp(&vd, fv));
        let mut a = s.clone();
        a.insert_u_knot(u, 1).unwrap();
        a.insert_v_knot(v, 2).unwrap();
        same_surface(&s, &a, REFINE_INVARIANCE)?;
        let mut b = s.clone();
        let xu: Vec<f64> = (1..6).map(|i| lerp(&ud, i as f64 / 6.3)).filter(|k| s.u_knots().multiplicity(*k, 0.0) == 0).collect();
        let xv: Vec<f64> = (1..4).map(|i| lerp(&vd, i as f64 / 4.1)).filter(|k| s.v_knots().multiplicity(*k, 0.0) == 0).collect();
        b.refine_u(&xu).unwrap();
        b.refine_v(&xv).unwrap();
        prop_assert_eq!(b.n_u(), s.n_u() + xu.len());
        prop_assert_eq!(b.n_v(), s.n_v() + xv.len());
        same_surface(&s, &b, REFINE_INVARIANCE)?;
    }

    #[test]
    fn surface_elevation_keeps_geometry(s in nurbs_surface(1..=3)) {
        let mut a = s.clone();
        a.elevate_u_degree(1).unwrap();
        a.elevate_v_degree(2).unwrap();
        prop_assert_eq!((a.u_degree(), a.v_degree()), (s.u_degree() + 1, s.v_degree() + 2));
        same_surface(&s, &a, REFINE_INVARIANCE)?;
    }

    #[test]
    fn surface_removal_of_inserted_knot_restores(s in nurbs_surface(2..=4), f in 0.05f64..0.95) {
        let (ud, _) = s.domain();
        let u = lerp(&ud, f);
        prop_assume!(s.u_knots().multiplicity(u, 0.0) == 0);
        let mut a = s.clone();
        a.insert_u_knot(u, 1).unwrap();
        prop_assert_eq!(a.remove_u_knot(u, 1, 1e-9 * surface_scale(&s)), 1);
        prop_assert_eq!(a.n_u(), s.n_u());
        same_surface(&s, &a, REFINE_INVARIANCE)?;
    }

    #[test]
    fn surface_split_reverse_iso(s in nurbs_surface(1..=4), fu in 0.05f64..0.95, fv in 0.05f64..0.95) {
        let (ud, vd) = s.domain();
        let (tu, tv) = (lerp(&ud, fu), lerp(&vd, fv));
        let scale = surface_scale(&s);
        let (l, r) = s.split_u(tu).unwrap();
        let (b, t) = s.split_v(tv).unwrap();
        let ur = s.u_reversed();
        let vr = s.v_reversed();
        let iso_u = s.u_iso(tu);
        let iso_v = s.v_iso(tv);
        for (u, v) in cadmorph_testkit::grid(&s, 7) {
            let p = s.eval(u, v);
            let half_u = if u <= tu { &l } else { &r };
            let half_v = if v <= tv { &b } else { &t };
            prop_assert!((half_u.eval(u, v) - p).norm() <= REFINE_INVARIANCE * scale);
            prop_assert!((half_v.eval(u, v) - p).norm() <= REFINE_INVARIANCE * scale);
            prop_assert!((ur.eval(ud.start() + ud.end() - u, v) - p).norm() <= REFINE_INVARIANCE * scale);
            prop_assert!((vr.eval(u, vd.start() + vd.end() - v) - p).norm() <= REFINE_INVARIANCE * scale);
            prop_assert!((iso_u.eval(v) - s.eval(tu, v)).norm() <= REFINE_INVARIANCE * scale);
            prop_assert!((iso_v.eval(u) - s.eval(u, tv)).norm() <= REFINE_INVARIANCE * scale);
        }
        for side in Side::ALL {
            let c = s.boundary(side);
            let d = c.domain();
            for i in 0..=8 {
                let w = lerp(&d, i as f64 / 8.0);
                let q = match side {
                    Side::UMin => s.eval(*ud.start(), w),
                    Side::UMax => s.eval(*ud.end(), w),
                    Side::VMin => s.eval(w, *vd.start()),
                    Side::VMax => s.eval(w, *vd.end()),
                };
                prop_assert!((c.eval(w) - q).norm() <= REFINE_INVARIANCE * scale);
            }
        }
    }

    #[test]
    fn surface_bezier_patches_reproduce(s in nurbs_surface(1..=4)) {
        let patches = s.bezier_patches();
        let scale = surface_scale(&s);
        let (nu, nv) = (s.u_knots().distinct().0.len() - 1, s.v_knots().distinct().0.len() - 1);
        prop_assert_eq!(patches.len(), nu);
        for row in &patches {
            prop_assert_eq!(row.len(), nv);
            for b in row {
                prop_assert_eq!((b.n_u(), b.n_v()), (s.u_degree() + 1, s.v_degree() + 1));
                for (u, v) in cadmorph_testkit::grid(b, 4) {
                    prop_assert!((b.eval(u, v) - s.eval(u, v)).norm() <= REFINE_INVARIANCE * scale);
                }
            }
        }
    }

    #[test]
    fn surface_derivatives_match_central_differences(s in nurbs_surface(1..=4), fu in 0.02f64..0.98, fv in 0.02f64..0.98) {
        let (ud, vd) = s.domain();
        let (u, v) = (lerp(&ud, fu), lerp(&vd, fv));
        let (hu, hv) = (1e-6 * (ud.end() - ud.start()), 1e-6 * (vd.end() - vd.start()));
        prop_assume!(s.u_knots().as_slice().iter().all(|&k| (k - u).abs() > 2.0 * hu));
        prop_assume!(s.v_knots().as_slice().iter().all(|&k| (k - v).abs() > 2.0 * hv));
        let d = s.derivs(u, v, 2);
        let fast = s.eval_d1(u, v);
        let fdu = (s.eval(u + hu, v) - s.eval(u - hu, v)) / (2.0 * hu);
        let fdv = (s.eval(u, v + hv) - s.eval(u, v - hv)) / (2.0 * hv);
        let su = surface_scale(&s) / (ud.end() - ud.start());
        let sv = surface_scale(&s) / (vd.end() - vd.start());
        prop_assert!((d[(1, 0)] - fdu).norm() <= FINITE_DIFFERENCE * su * 50.0, "Su {:?} vs {:?}", d[(1, 0)], fdu);
        prop_assert!((d[(0, 1)] - fdv).norm() <= FINITE_DIFFERENCE * sv * 50.0, "Sv {:?} vs {:?}", d[(0, 1)], fdv);
        prop_assert!((fast.du - d[(1, 0)]).norm() <= 1e-12 * su * 10.0);
        prop_assert!((fast.dv - d[(0, 1)]).norm() <= 1e-12 * sv * 10.0);
        prop_assert!((Point3::from(d[(0, 0)]) - s.eval(u, v)).norm() <= 1e-13 * surface_scale(&s));
        // Mixed second derivative against differences of first derivatives.
        let fduv = (s.eval_d1(u, v + hv).du - s.eval_d1(u, v - hv).du) / (2.0 * hv);
        prop_assert!((d[(1, 1)] - fduv).norm() <= FINITE_DIFFERENCE * (1.0 + d[(1, 1)].norm()) * 100.0,
            "Suv {:?} vs {:?}", d[(1, 1)], fduv);
    }
}

/// Surface refinement runs A5.4's coefficients once for the whole net, in groups of
/// rows: row by row it must give what the curve refinement (A5.4 on one row) gives, for
/// rational and non-rational nets of more rows than one group, in both directions.
#[test]
fn surface_refinement_equals_refining_each_row_as_a_curve() {
    use cadmorph_nurbs::KnotVector;
    for rational in [false, true] {
        let (n_u, n_v) = (37, 9);
        let (p, q) = (3, 2);
        let mut pts = Vec::new();
        let mut w = Vec::new();
        for i in 0..n_u {
            for j in 0..n_v {
                let (x, y) = (i as f64, j as f64);
                pts.push(Point3::new(x, y, (0.3 * x).sin() * (0.7 * y).cos() + 0.01 * x * y));
                w.push(1.0 + 0.4 * ((i * 7 + j * 3) % 5) as f64 / 5.0);
            }
        }
        let s = NurbsSurface::try_new(
            (p, q),
            (KnotVector::clamped_uniform(p, n_u), KnotVector::clamped_uniform(q, n_v)),
            (n_u, n_v),
            pts,
            rational.then_some(w),
        )
        .unwrap();
        let xv: Vec<f64> = (1..40).map(|k| k as f64 / 40.0 + 0.003).collect();
        let xu: Vec<f64> = (1..25).map(|k| k as f64 / 25.0 - 0.002).collect();
        let mut b = s.clone();
        b.refine_v(&xv).unwrap();
        for i in 0..n_u {
            let row: Vec<Point3<f64>> = (0..n_v).map(|j| s.control_point(i, j)).collect();
            let rw = s.weights().map(|w| w[i * n_v..(i + 1) * n_v].to_vec());
            let mut c = NurbsCurve::try_new(q, s.v_knots().clone(), row, rw).unwrap();
            c.refine(&xv).unwrap();
            assert_eq!(c.knots().as_slice(), b.v_knots().as_slice());
            for (j, cp) in c.control_points().iter().enumerate() {
                let e = (cp - b.control_point(i, j)).norm();
                assert!(e <= 1e-13, "rational {rational} row {i} point {j}: {e:e}");
                if let (Some(cw), Some(bw)) = (c.weights(), b.weights()) {
                    assert!((cw[j] - bw[i * b.n_v() + j]).abs() <= 1e-13);
                }
            }
        }
        let mut bu = b.clone();
        bu.refine_u(&xu).unwrap();
        for j in 0..b.n_v() {
            let col: Vec<Point3<f64>> = (0..n_u).map(|i| b.control_point(i, j)).collect();
            let cw = b.weights().map(|w| (0..n_u).map(|i| w[i * b.n_v() + j]).collect());
            let mut c = NurbsCurve::try_new(p, b.u_knots().clone(), col, cw).unwrap();
            c.refine(&xu).unwrap();
            for (i, cp) in c.control_points().iter().enumerate() {
                let e = (cp - bu.control_point(i, j)).norm();
                assert!(e <= 1e-13, "rational {rational} column {j} point {i}: {e:e}");
            }
        }
        same_surface(&s, &bu, REFINE_INVARIANCE).unwrap();
    }
}
