//! Evaluation, first derivatives and normals of every B-spline surface and curve in
//! `samples/*.ref.json` against OCCT 7.9's own evaluation of the same data.

use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{Curve, Surface};
use cadmorph_testkit::occt::reference;
use cadmorph_testkit::samples_with_suffix;

/// Relative to the model size (the diagonal of the control net's box). OCCT and
/// cadmorph evaluate the same data in f64 with different operation orders; the
/// observed differences are ~1e-15 relative, so 1e-9 is the claim of the issue.
const OCCT_EVAL: f64 = 1e-9;

fn diagonal(points: impl Iterator<Item = Point3<f64>>) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    (hi - lo).norm()
}

#[test]
fn every_bspline_surface_matches_occt() {
    let mut checked = 0;
    let mut degenerate = 0;
    let mut worst = 0.0f64;
    for name in samples_with_suffix(".ref.json") {
        let r = reference(name.trim_end_matches(".ref.json"));
        for (index, face) in r.faces.iter().enumerate() {
            let Some(surface) = face.to_nurbs() else { continue };
            let s = surface.unwrap_or_else(|e| panic!("{name} face {index}: {e}"));
            let scale = diagonal(s.control_points().iter().copied());
            // Derivatives scale with size / parameter range.
            let (ud, vd) = s.domain();
            let du_scale = scale / (ud.end() - ud.start());
            let dv_scale = scale / (vd.end() - vd.start());
            assert!(face.samples.len() >= 50, "{name} face {index}: {} samples", face.samples.len());
            for smp in &face.samples {
                let d = s.eval_d1(smp.u, smp.v);
                let p = s.eval(smp.u, smp.v);
                let ep = (p - Point3::from(smp.p)).norm() / scale;
                let ep1 = (d.point - Point3::from(smp.p)).norm() / scale;
                let edu = (d.du - Vector3::from(smp.du)).norm() / du_scale;
                let edv = (d.dv - Vector3::from(smp.dv)).norm() / dv_scale;
                // The general-order path must agree with the fast path.
                let g = s.derivs(smp.u, smp.v, 2);
                let eg = (g[(1, 0)] - d.du).norm() / du_scale + (g[(0, 1)] - d.dv).norm() / dv_scale;
                let at = format!("{name} face {index} at ({}, {})", smp.u, smp.v);
                for (what, e) in [("point", ep), ("point(d1)", ep1), ("du", edu), ("dv", edv), ("derivs", eg)] {
                    assert!(e <= OCCT_EVAL, "{at}: {what} differs by {e:e} (relative)");
                    worst = worst.max(e);
                }
                match (s.normal(smp.u, smp.v), smp.n) {
                    (Some(n), Some(on)) => {
                        let e = (n.into_inner() - Vector3::from(on)).norm();
                        assert!(e <= OCCT_EVAL, "{at}: normal differs by {e:e}");
                        worst = worst.max(e);
                    }
                    (None, _) => {
                        // A degenerate point (collapsed edge, tangent partials): OCCT's
                        // sample normalises whatever rounding noise du × dv holds, so
                        // check instead that OCCT's own partials are parallel there.
                        let (odu, odv) = (Vector3::from(smp.du), Vector3::from(smp.dv));
                        let sine = odu.cross(&odv).norm() / (odu.norm() * odv.norm());
                        assert!(
                            sine.is_nan() || sine <= 1e-12,
                            "{at}: cadmorph finds no normal, OCCT's sine is {sine:e}"
                        );
                        degenerate += 1;
                    }
                    (Some(n), None) => panic!("{at}: normal {n:?}, OCCT none"),
                }
                checked += 1;
            }
        }
    }
    eprintln!("{checked} surface samples ({degenerate} degenerate), worst relative difference {worst:e}");
    assert!(checked >= 500, "only {checked} surface samples checked");
}

#[test]
fn every_bspline_curve_matches_occt() {
    let mut checked = 0;
    let mut worst = 0.0f64;
    for name in samples_with_suffix(".ref.json") {
        let r = reference(name.trim_end_matches(".ref.json"));
        for (index, cref) in r.free_curves.iter().enumerate() {
            let Some(curve) = cref.to_nurbs() else { continue };
            let c = curve.unwrap_or_else(|e| panic!("{name} curve {index}: {e}"));
            let scale = diagonal(c.control_points().iter().copied());
            let d = c.domain();
            let d_scale = scale / (d.end() - d.start());
            for smp in &cref.samples {
                let ders = c.derivs(smp.t, 1);
                let ep = (c.eval(smp.t) - Point3::from(smp.p)).norm() / scale;
                let ed0 = (ders[0] - Vector3::from(smp.p)).norm() / scale;
                let ed1 = (ders[1] - Vector3::from(smp.d1)).norm() / d_scale;
                for (what, e) in [("point", ep), ("derivs[0]", ed0), ("d1", ed1)] {
                    assert!(e <= OCCT_EVAL, "{name} curve {index} at t={}: {what} differs by {e:e}", smp.t);
                    worst = worst.max(e);
                }
                checked += 1;
            }
        }
    }
    eprintln!("{checked} curve samples, worst relative difference {worst:e}");
    assert!(checked >= 200, "only {checked} curve samples checked");
}
