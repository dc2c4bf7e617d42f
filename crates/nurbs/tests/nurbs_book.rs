//! Worked examples of Piegl & Tiller, *The NURBS Book*, 2nd ed., with their printed numbers.

use approx::assert_relative_eq;
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{basis_funs, ders_basis_funs, Curve, KnotVector, NurbsCurve};

fn ex23_knots() -> KnotVector {
    KnotVector::try_new(vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap()
}

/// Ex. 2.3 and eq. (2.12)-(2.14): span 4 at u = 5/2 and N₂,₂ = 1/8, N₃,₂ = 6/8, N₄,₂ = 1/8.
#[test]
fn example_2_3_basis_at_five_halves() {
    let u = ex23_knots();
    assert_eq!(u.find_span(2, 2.5), 4);
    assert_eq!(basis_funs(&u, 2, 2.5), vec![1.0 / 8.0, 6.0 / 8.0, 1.0 / 8.0]);
}

/// Ex. 2.4: first derivatives at 5/2: N'₂,₂ = −1/2, N'₃,₂ = 0, N'₄,₂ = 1/2; second: 1, −2, 1.
#[test]
fn example_2_4_derivatives_at_five_halves() {
    let d = ders_basis_funs(&ex23_knots(), 2, 2.5, 3);
    assert_eq!(d[0], vec![0.125, 0.75, 0.125]);
    assert_eq!(d[1], vec![-0.5, 0.0, 0.5]);
    assert_eq!(d[2], vec![1.0, -2.0, 1.0]);
    assert_eq!(d[3], vec![0.0, 0.0, 0.0], "degree 2 has no third derivative");
}

/// Span search at knots, ends and repeated knots (A2.1 conventions).
#[test]
fn span_search_edges() {
    let u = ex23_knots();
    assert_eq!(u.find_span(2, 0.0), 2);
    assert_eq!(u.find_span(2, 1.0), 3);
    assert_eq!(u.find_span(2, 4.0), 7, "a double knot belongs to the span starting at its last copy");
    assert_eq!(u.find_span(2, 5.0), 7, "the domain end belongs to the last span");
    assert_eq!(u.find_span(2, 6.0), 7, "outside clamps");
    assert_eq!(u.find_span(2, -1.0), 2);
}

fn ex51_curve() -> NurbsCurve {
    let pts: Vec<Point3<f64>> =
        (0..8).map(|i| Point3::new(i as f64, (i * i) as f64, (i * i * i) as f64 * 0.1)).collect();
    NurbsCurve::new(3, KnotVector::try_new(vec![0., 0., 0., 0., 1., 2., 3., 4., 5., 5., 5., 5.]).unwrap(), pts, None)
}

/// Ex. 5.1: p = 3, U = {0,0,0,0,1,2,3,4,5,5,5,5}, insert u = 5/2 once (k = 5):
/// Q₃ = 5/6 P₃ + 1/6 P₂, Q₄ = 1/2 P₄ + 1/2 P₃, Q₅ = 1/6 P₅ + 5/6 P₄; the rest are copies.
#[test]
fn example_5_1_knot_insertion() {
    let c = ex51_curve();
    let p = c.control_points().to_vec();
    let mut q = c.clone();
    assert_eq!(q.insert_knot(2.5, 1).unwrap(), 1);
    assert_eq!(q.knots().as_slice(), &[0., 0., 0., 0., 1., 2., 2.5, 3., 4., 5., 5., 5., 5.]);
    let qp = q.control_points();
    assert_eq!(qp.len(), 9);
    let mix = |a: f64, i: usize| Point3::from(p[i].coords * a + p[i - 1].coords * (1.0 - a));
    for i in 0..=2 {
        assert_eq!(qp[i], p[i]);
    }
    assert_relative_eq!(qp[3], mix(5.0 / 6.0, 3), epsilon = 1e-14);
    assert_relative_eq!(qp[4], mix(0.5, 4), epsilon = 1e-14);
    assert_relative_eq!(qp[5], mix(1.0 / 6.0, 5), epsilon = 1e-14);
    for i in 6..9 {
        assert_eq!(qp[i], p[i - 1]);
    }
}

/// Refinement (A5.4) equals repeated single insertion (A5.1), and a double insertion
/// follows eq. (5.10)'s triangular scheme.
#[test]
fn refinement_equals_repeated_insertion() {
    let c = ex51_curve();
    let x = [0.5, 2.5, 2.5, 3.0, 4.75];
    let mut a = c.clone();
    a.refine(&x).unwrap();
    let mut b = c.clone();
    for &u in &x {
        b.insert_knot(u, 1).unwrap();
    }
    assert_eq!(a.knots(), b.knots());
    for (p, q) in a.control_points().iter().zip(b.control_points()) {
        assert_relative_eq!(p, q, epsilon = 1e-13);
    }
}

/// Degree elevation of a Bézier curve (eq. 5.36): a quadratic P₀P₁P₂ becomes the cubic
/// P₀, (P₀ + 2P₁)/3, (2P₁ + P₂)/3, P₂.
#[test]
fn bezier_degree_elevation_eq_5_36() {
    let p = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 2.0, 0.0), Point3::new(3.0, 0.0, 1.0)];
    let mut c = NurbsCurve::new(2, KnotVector::clamped_uniform(2, 3), p.to_vec(), None);
    c.elevate_degree(1).unwrap();
    assert_eq!(c.degree(), 3);
    assert_eq!(c.knots().as_slice(), &[0., 0., 0., 0., 1., 1., 1., 1.]);
    let q = c.control_points();
    assert_relative_eq!(q[0], p[0]);
    assert_relative_eq!(q[1], Point3::from((p[0].coords + p[1].coords * 2.0) / 3.0), epsilon = 1e-15);
    assert_relative_eq!(q[2], Point3::from((p[1].coords * 2.0 + p[2].coords) / 3.0), epsilon = 1e-15);
    assert_relative_eq!(q[3], p[2]);
}

/// Ex. 5.? of A5.9: elevating a B-spline keeps the knot values, raises each multiplicity by t
/// and keeps the geometry.
#[test]
fn bspline_degree_elevation_raises_multiplicities() {
    let c = ex51_curve();
    let mut e = c.clone();
    e.elevate_degree(2).unwrap();
    assert_eq!(e.degree(), 5);
    let (vals, mults) = e.knots().distinct();
    assert_eq!(vals, vec![0., 1., 2., 3., 4., 5.]);
    assert_eq!(mults, vec![6, 3, 3, 3, 3, 6]);
    assert_eq!(e.control_points().len(), 8 + 2 * 5);
    for i in 0..=100 {
        let t = i as f64 * 0.05;
        assert_relative_eq!(e.eval(t), c.eval(t), epsilon = 1e-12, max_relative = 1e-12);
    }
}

/// Knot removal (A5.8): a knot inserted twice comes out twice, giving the original back;
/// a knot that carries the shape does not come out at a small tolerance.
#[test]
fn removal_undoes_insertion() {
    let c = ex51_curve();
    let mut d = c.clone();
    d.insert_knot(2.5, 2).unwrap();
    assert_eq!(d.remove_knot(2.5, 2, 1e-10), 2);
    assert_eq!(d.knots(), c.knots());
    for (p, q) in d.control_points().iter().zip(c.control_points()) {
        assert_relative_eq!(p, q, epsilon = 1e-12);
    }
    let mut e = c.clone();
    assert_eq!(e.remove_knot(2.0, 1, 1e-6), 0, "P = (i, i², 0.1 i³) is not C3 at u = 2... removal must fail");
}

/// The rational quadratic quarter circle (eq. 7.?): every point at radius 1, and the
/// midpoint at 45°.
#[test]
fn rational_quarter_circle() {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let arc = NurbsCurve::new(
        2,
        KnotVector::clamped_uniform(2, 3),
        vec![Point3::new(1., 0., 0.), Point3::new(1., 1., 0.), Point3::new(0., 1., 0.)],
        Some(vec![1.0, w, 1.0]),
    );
    let m = arc.eval(0.5);
    assert_relative_eq!(m.x, w, epsilon = 1e-15);
    assert_relative_eq!(m.y, w, epsilon = 1e-15);
    for i in 0..=20 {
        let t = i as f64 / 20.0;
        let d = arc.derivs(t, 2);
        assert_relative_eq!(d[0].norm(), 1.0, epsilon = 1e-15);
        // The tangent is perpendicular to the radius.
        assert!(d[0].dot(&d[1]).abs() < 1e-14);
    }
}

/// An affine map of the control points maps every point of a rational curve and surface.
#[test]
fn affine_transform_commutes_with_evaluation() {
    use cadmorph_nurbs::math::{Matrix4, Rotation3, Vector3};
    use cadmorph_nurbs::{NurbsSurface, Surface};
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let arc = NurbsCurve::new(
        2,
        KnotVector::clamped_uniform(2, 3),
        vec![Point3::new(1., 0., 0.), Point3::new(1., 1., 0.), Point3::new(0., 1., 0.)],
        Some(vec![1.0, w, 1.0]),
    );
    let m = Matrix4::new_translation(&Vector3::new(1.0, -2.0, 3.0))
        * Rotation3::from_euler_angles(0.3, -0.2, 1.1).to_homogeneous()
        * Matrix4::new_nonuniform_scaling(&Vector3::new(2.0, 0.5, 1.5));
    let t = arc.transformed(&m);
    for i in 0..=10 {
        let u = i as f64 / 10.0;
        assert_relative_eq!(t.eval(u), m.transform_point(&arc.eval(u)), epsilon = 1e-13);
    }
    let s = NurbsSurface::new(
        (2, 1),
        (KnotVector::clamped_uniform(2, 3), KnotVector::clamped_uniform(1, 2)),
        (3, 2),
        vec![
            Point3::new(1., 0., 0.),
            Point3::new(1., 0., 1.),
            Point3::new(1., 1., 0.),
            Point3::new(1., 1., 1.),
            Point3::new(0., 1., 0.),
            Point3::new(0., 1., 1.),
        ],
        Some(vec![1.0, 1.0, w, w, 1.0, 1.0]),
    );
    let ts = s.transformed(&m);
    for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5)] {
        assert_relative_eq!(ts.eval(u, v), m.transform_point(&s.eval(u, v)), epsilon = 1e-13);
    }
}

/// A periodic cubic through one period of 6 poles on a hexagon: closed, and C² across
/// the seam, like OCCT's periodic `Geom_BSplineCurve`.
#[test]
fn periodic_curve_is_closed_and_smooth() {
    let poles: Vec<Point3<f64>> = (0..6)
        .map(|k| {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            Point3::new(a.cos(), a.sin(), 0.1 * k as f64)
        })
        .collect();
    let values = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let c = NurbsCurve::try_periodic(3, &values, &[1; 7], poles, None).unwrap();
    assert_eq!(c.domain(), 0.0..=6.0);
    let (a, b) = (c.derivs(0.0, 2), c.derivs(6.0, 2));
    for k in 0..=2 {
        assert_relative_eq!(a[k], b[k], epsilon = 1e-13);
    }
    // Uniform cubic B-spline: C(j) = (P_{j-1} + 4 P_j + P_{j+1}) / 6 with the first pole
    // of the period sitting at the segment [0, 1]'s start shifted as OCCT does.
    let p = c.control_points();
    let expect = (p[0].coords + p[1].coords * 4.0 + p[2].coords) / 6.0;
    assert_relative_eq!(c.eval(0.0).coords, expect, epsilon = 1e-14);
    // OCCT 7.9's periodic Geom_BSplineCurve(poles, knots 0..6, mults 1, degree 3,
    // periodic) on the same data (printed by OCP), so the pole numbering agrees.
    for (t, occt) in [
        (0.0, [0.41666666666666674, 0.7216878364870323, 0.10000000000000002]),
        (0.5, [1.6653345369377348e-16, 0.8299410119600871, 0.15000000000000002]),
        (2.3, [-0.7905833333333336, -0.2559105068183013, 0.33000000000000007]),
    ] {
        assert_relative_eq!(c.eval(t), Point3::from(occt), epsilon = 1e-14);
    }
    // Bad periodic data is rejected, not mis-built.
    assert!(NurbsCurve::try_periodic(3, &values, &[1; 7], vec![Point3::origin(); 5], None).is_err());
    assert!(NurbsCurve::try_periodic(3, &values, &[2, 1, 1, 1, 1, 1, 1], vec![Point3::origin(); 6], None).is_err());
}
