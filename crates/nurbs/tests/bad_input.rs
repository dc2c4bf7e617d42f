//! Bad input gets a typed error naming what is wrong; nothing panics.

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Error, KnotVector, NurbsCurve, NurbsSurface};
use proptest::prelude::*;

fn pts(n: usize) -> Vec<Point3<f64>> {
    (0..n).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect()
}

#[test]
fn decreasing_knots() {
    let e = KnotVector::try_new(vec![0.0, 0.0, 1.0, 0.5, 1.0]).unwrap_err();
    assert_eq!(e, Error::DecreasingKnots { index: 3, value: 0.5, previous: 1.0 });
}

#[test]
fn nan_knot_and_point_and_weight() {
    assert!(matches!(
        KnotVector::try_new(vec![0.0, f64::NAN, 1.0]),
        Err(Error::NotFinite { what: "knot", index: 1, .. })
    ));
    let mut p = pts(3);
    p[2].y = f64::INFINITY;
    assert!(matches!(
        NurbsCurve::try_new(2, KnotVector::clamped_uniform(2, 3), p, None),
        Err(Error::NotFinite { what: "control point", index: 2, .. })
    ));
    assert!(matches!(
        NurbsCurve::try_new(2, KnotVector::clamped_uniform(2, 3), pts(3), Some(vec![1.0, f64::NAN, 1.0])),
        Err(Error::NotFinite { what: "weight", index: 1, .. })
    ));
}

#[test]
fn wrong_counts() {
    let e = NurbsCurve::try_new(3, KnotVector::clamped_uniform(3, 5), pts(6), None).unwrap_err();
    assert_eq!(e, Error::KnotCount { direction: "", expected: 10, found: 9, degree: 3, control_points: 6 });
    let e = NurbsCurve::try_new(3, KnotVector::clamped_uniform(1, 2), pts(2), None).unwrap_err();
    assert_eq!(e, Error::TooFewControlPoints { degree: 3, found: 2 });
    let e = NurbsCurve::try_new(0, KnotVector::clamped_uniform(1, 2), pts(2), None).unwrap_err();
    assert_eq!(e, Error::Degree { degree: 0 });
    let e = NurbsCurve::try_new(2, KnotVector::clamped_uniform(2, 3), pts(3), Some(vec![1.0; 2])).unwrap_err();
    assert_eq!(e, Error::WeightCount { weights: 2, control_points: 3 });
    let k = || KnotVector::clamped_uniform(1, 2);
    let e = NurbsSurface::try_new((1, 1), (k(), k()), (2, 2), pts(3), None).unwrap_err();
    assert_eq!(e, Error::NetSize { n_u: 2, n_v: 2, found: 3 });
    let e = NurbsSurface::try_new((1, 1), (k(), KnotVector::clamped_uniform(1, 3)), (2, 2), pts(4), None).unwrap_err();
    assert!(matches!(e, Error::KnotCount { direction: "v: ", .. }), "{e}");
    let e = KnotVector::from_multiplicities(&[0.0, 1.0], &[2]).unwrap_err();
    assert_eq!(e, Error::MultiplicityList { knots: 2, mults: 1 });
}

#[test]
fn zero_and_negative_weights() {
    for (w, index) in [(vec![1.0, -0.5, 1.0], 1), (vec![1.0, 1.0, -2.0], 2)] {
        let value = w[index];
        let e = NurbsCurve::try_new(2, KnotVector::clamped_uniform(2, 3), pts(3), Some(w)).unwrap_err();
        assert_eq!(e, Error::NonPositiveWeight { index, value });
    }
    // Curves and surfaces take a weight of zero (a point at infinity), not a negative one.
    assert!(NurbsCurve::try_new(2, KnotVector::clamped_uniform(2, 3), pts(3), Some(vec![1.0, 0.0, 1.0])).is_ok());
    let k = || KnotVector::clamped_uniform(1, 2);
    let s = NurbsSurface::try_new((1, 1), (k(), k()), (2, 2), pts(4), Some(vec![1.0, 0.0, 1.0, 1.0])).unwrap();
    // The corner (0, 1) carries all the weight at (u, v) = (0, 1).
    assert_eq!(s.try_eval(0.0, 1.0), Err(Error::SurfaceAtInfinity { u: 0.0, v: 1.0 }));
    assert!(s.try_eval(0.5, 0.5).is_ok());
    assert!(s.bounding_box().max.x.is_infinite());
    let e = NurbsSurface::try_new((1, 1), (k(), k()), (2, 2), pts(4), Some(vec![1.0, -1.0, 1.0, 1.0])).unwrap_err();
    assert_eq!(e, Error::NonPositiveWeight { index: 1, value: -1.0 });
    // Where all the weight sits on a point at infinity, no Cartesian point is given.
    let c = NurbsCurve::try_new(2, KnotVector::clamped_uniform(2, 3), pts(3), Some(vec![0.0, 1.0, 1.0])).unwrap();
    assert_eq!(c.try_eval(0.0), Err(Error::AtInfinity { parameter: 0.0 }));
    assert!(c.try_eval(0.5).is_ok());
}

#[test]
fn excess_multiplicity_and_empty_domain() {
    let e = NurbsCurve::try_new(1, KnotVector::try_new(vec![0., 0., 0.5, 0.5, 0.5, 1., 1.]).unwrap(), pts(5), None)
        .unwrap_err();
    assert_eq!(e, Error::Multiplicity { value: 0.5, multiplicity: 3, max: 2 });
    assert!(matches!(KnotVector::try_new(vec![1.0, 1.0]), Err(Error::EmptyDomain { .. })));
    assert!(matches!(KnotVector::try_new(vec![]), Err(Error::EmptyDomain { .. })));
}

#[test]
fn operations_outside_the_domain() {
    let mut c = NurbsCurve::new(2, KnotVector::clamped_uniform(2, 4), pts(4), None);
    assert!(matches!(c.insert_knot(1.5, 1), Err(Error::OutsideDomain { value: 1.5, .. })));
    assert!(matches!(c.refine(&[0.5, f64::NAN]), Err(Error::NotFinite { what: "knot", index: 1, .. })));
    assert!(matches!(c.refine(&[0.5, 0.5, 0.5]), Err(Error::Multiplicity { .. })));
    assert!(matches!(c.split(0.0), Err(Error::OutsideDomain { .. })));
    assert!(matches!(c.elevate_degree(30), Err(Error::Degree { degree: 32 })));
}

/// Every message, printed once so its wording is reviewed with the code.
#[test]
fn messages_read_well() {
    let all = [
        Error::DecreasingKnots { index: 3, value: 0.5, previous: 1.0 },
        Error::NotFinite { what: "weight", index: 1, value: f64::NAN },
        Error::EmptyDomain { start: 1.0, end: 1.0 },
        Error::KnotCount { direction: "u: ", expected: 10, found: 9, degree: 3, control_points: 6 },
        Error::Multiplicity { value: 0.5, multiplicity: 3, max: 2 },
        Error::Degree { degree: 0 },
        Error::TooFewControlPoints { degree: 3, found: 2 },
        Error::NetSize { n_u: 2, n_v: 2, found: 3 },
        Error::WeightCount { weights: 2, control_points: 3 },
        Error::NonPositiveWeight { index: 1, value: 0.0 },
        Error::OutsideDomain { value: 1.5, start: 0.0, end: 1.0 },
        Error::MultiplicityList { knots: 2, mults: 1 },
        Error::Periodic { reason: "first and last knot multiplicities differ" },
        Error::AtInfinity { parameter: 0.0 },
        Error::SurfaceAtInfinity { u: 0.0, v: 1.0 },
        Error::Tolerance { operation: "degree reduction", bound: 2.0, tol: 1.5 },
        Error::Tolerance { operation: "degree reduction", bound: f64::INFINITY, tol: 1.5 },
    ];
    let text: Vec<String> = all.iter().map(ToString::to_string).collect();
    for t in &text {
        println!("{t}");
    }
    assert_eq!(text[0], "knot 3 (0.5) is smaller than knot 2 (1)");
    assert_eq!(text[3], "u: expected 10 knots for degree 3 and 6 control points, found 9");
}

proptest! {
    /// Arbitrary numbers either build a valid curve or give an error; building never
    /// panics, and a curve that builds evaluates to finite points in its domain.
    #[test]
    fn arbitrary_input_never_panics(
        p in 0usize..7,
        knots in prop::collection::vec(prop_oneof![-1e3f64..1e3, Just(f64::NAN), Just(0.0), Just(1.0)], 0..14),
        n in 0usize..9,
        weights in prop::option::of(prop::collection::vec(prop_oneof![-1.0f64..3.0, Just(0.0)], 0..9)),
    ) {
        let kv = match KnotVector::try_new(knots) { Ok(k) => k, Err(_) => return Ok(()) };
        if let Ok(c) = NurbsCurve::try_new(p, kv, pts(n), weights) {
            use cadmorph_nurbs::Curve;
            let d = c.domain();
            for i in 0..=10 {
                let t = d.start() + (d.end() - d.start()) * i as f64 / 10.0;
                prop_assert!(c.eval(t).coords.iter().all(|x| x.is_finite()));
            }
        }
    }
}

/// `NurbsSurface::check_net` (a net checked before its points are read) refuses what
/// `try_new` refuses for the same degrees, knots, counts and weights, with the same error,
/// and accepts what it accepts.
#[test]
fn checking_a_net_without_its_points_agrees_with_building_it() {
    let k = |p: usize, n: usize| KnotVector::clamped_uniform(p, n);
    type Case = ((usize, usize), (KnotVector, KnotVector), (usize, usize), usize, Option<Vec<f64>>);
    let cases: Vec<Case> = vec![
        ((1, 1), (k(1, 2), k(1, 2)), (2, 2), 4, None),
        ((1, 1), (k(1, 2), k(1, 2)), (2, 2), 3, None),
        ((1, 1), (k(1, 2), k(1, 3)), (2, 2), 4, None),
        ((0, 1), (k(1, 2), k(1, 2)), (2, 2), 4, None),
        ((3, 2), (k(3, 4), k(2, 5)), (4, 5), 20, Some(vec![1.0; 20])),
        ((3, 2), (k(3, 4), k(2, 5)), (4, 5), 20, Some(vec![1.0; 19])),
        ((3, 2), (k(3, 4), k(2, 5)), (4, 5), 20, Some([vec![1.0; 19], vec![-1.0]].concat())),
        ((3, 2), (k(3, 4), k(2, 5)), (4, 5), 20, Some([vec![1.0; 19], vec![0.0]].concat())),
    ];
    for (n, (degrees, knots, counts, points, weights)) in cases.into_iter().enumerate() {
        let checked = NurbsSurface::check_net(degrees, (&knots.0, &knots.1), counts, points, weights.as_deref());
        let built = NurbsSurface::try_new(degrees, knots, counts, pts(points), weights).map(|_| ());
        assert_eq!(checked, built, "case {n}");
    }
}
