//! Exact composition with a Bézier volume (the exact FFD): the composed patch equals the
//! pointwise image, a zero morph is the identity, the degree is `p·(l+m+n)` and is
//! refused above 25, and surface knot removal keeps the surface within its bound.

use cadmorph_nurbs::analytic::{AnalyticSurface, Cylinder, Placement};
use cadmorph_nurbs::math::{Matrix3, Point3, Rotation3, Vector3};
use cadmorph_nurbs::{BezierVolume, Curve, Error, KnotVector, NurbsCurve, NurbsSurface, Surface};
use rand::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

/// The composition is exact: it differs from the pointwise map only by rounding (a few
/// hundred ulps of the model size at degree ≤ 25).
const COMPOSE_EXACT: f64 = 1e-12;

/// A box around `[-1, 3] × [-2, 2] × [-1.5, 2.5]`, rotated, with its lattice nodes
/// moved at random by up to `amp` of the box (a non-affine map unless `amp` is 0).
fn volume(degrees: [usize; 3], amp: f64, seed: u64) -> BezierVolume {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    let origin = Point3::new(-1.0, -2.0, -1.5);
    let r = Rotation3::from_euler_angles(0.1, -0.2, 0.3).into_inner();
    let len = Vector3::new(4.0, 4.0, 4.0);
    let frame = r * Matrix3::from_diagonal(&len);
    let to_unit = frame.try_inverse().expect("invertible");
    let [l, m, n] = degrees;
    let mut q = Vec::new();
    for i in 0..=l {
        for j in 0..=m {
            for k in 0..=n {
                let mut u = Vector3::new(i as f64 / l as f64, j as f64 / m as f64, k as f64 / n as f64);
                u += Vector3::new(rng.gen_range(-amp..=amp), rng.gen_range(-amp..=amp), rng.gen_range(-amp..=amp));
                q.push(origin + frame * u);
            }
        }
    }
    // The box origin in these tests is the lattice origin, rotated frame included.
    BezierVolume::try_new(degrees, q, origin, to_unit).expect("valid volume")
}

/// A bicubic (or other degree) surface with several spans and a double knot, inside the box.
fn surface(p: usize, q: usize, rational: bool, seed: u64) -> NurbsSurface {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    let (n_u, n_v) = (p + 4, q + 3);
    let knots = |d: usize, n: usize, double: bool| {
        let inner = n - d - 1;
        let mut k = vec![0.0; d + 1];
        let mut vals: Vec<f64> = (1..=inner).map(|i| i as f64 / (inner + 1) as f64).collect();
        if double && inner >= 2 && d >= 2 {
            vals[1] = vals[0];
        }
        k.extend(vals);
        k.extend(vec![1.0; d + 1]);
        KnotVector::try_new(k).expect("knots")
    };
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for i in 0..n_u {
        for j in 0..n_v {
            let x = i as f64 / (n_u - 1) as f64 * 1.6;
            let y = j as f64 / (n_v - 1) as f64 * 1.4 - 0.5;
            pts.push(Point3::new(x, y, 0.3 * (3.0 * x).sin() * y + rng.gen_range(-0.2..0.2)));
            w.push(rng.gen_range(0.5..2.0));
        }
    }
    NurbsSurface::try_new((p, q), (knots(p, n_u, true), knots(q, n_v, false)), (n_u, n_v), pts, rational.then_some(w))
        .expect("valid surface")
}

fn size(s: &NurbsSurface) -> f64 {
    s.control_extent().max(1.0)
}

/// The largest distance between `r(u, v)` and `f(s(u, v))` on a grid that includes
/// every knot value.
fn max_dev(r: &NurbsSurface, s: &NurbsSurface, f: impl Fn(&Point3<f64>) -> Point3<f64>) -> f64 {
    cadmorph_testkit::grid(s, 13).into_iter().map(|(u, v)| (r.eval(u, v) - f(&s.eval(u, v))).norm()).fold(0.0, f64::max)
}

#[test]
fn composed_surface_is_the_pointwise_ffd() {
    for (degrees, p, q, rational) in [
        ([1, 1, 1], 3, 3, false),
        ([2, 2, 2], 3, 2, false),
        ([2, 1, 3], 2, 2, true),
        ([1, 1, 1], 3, 3, true),
        ([3, 3, 3], 1, 1, false),
    ] {
        let v = volume(degrees, 0.08, 7);
        let s = surface(p, q, rational, 11);
        let r = s.composed_with(&v).expect("degree within limits");
        let d = v.degree_factor();
        assert_eq!((r.u_degree(), r.v_degree()), (p * d, q * d));
        assert_eq!(r.is_rational(), rational);
        assert_eq!(r.domain(), s.domain());
        let dev = max_dev(&r, &s, |x| v.eval(x));
        assert!(dev <= COMPOSE_EXACT * size(&s), "{degrees:?} ({p}, {q}) rational {rational}: {dev:e}");
    }
}

#[test]
fn composed_cylinder_through_its_homogeneous_form() {
    let pl = Placement::try_new(Point3::new(0.5, 0.0, 0.0), Vector3::new(0.0, 0.0, 1.0), Vector3::new(1.0, 0.0, 0.0))
        .expect("placement");
    let cyl = Cylinder::try_new(pl, 0.8).expect("cylinder");
    let s = cyl.to_nurbs(0.0..=2.0 * std::f64::consts::PI, -1.0..=1.5).expect("exact form").surface;
    assert!(s.is_rational());
    let v = volume([2, 2, 1], 0.05, 3);
    let r = s.composed_with(&v).expect("degree 10 x 5");
    assert_eq!((r.u_degree(), r.v_degree()), (2 * 5, 5));
    let dev = max_dev(&r, &s, |x| v.eval(x));
    assert!(dev <= COMPOSE_EXACT * size(&s), "{dev:e}");
}

#[test]
fn zero_morph_is_the_identity() {
    let v = volume([2, 3, 1], 0.0, 0);
    for rational in [false, true] {
        let s = surface(3, 3, rational, 5);
        let r = s.composed_with(&v).expect("degree 18");
        let dev = max_dev(&r, &s, |x| *x);
        assert!(dev <= COMPOSE_EXACT * size(&s), "rational {rational}: {dev:e}");
    }
}

#[test]
fn composed_curve_is_the_pointwise_ffd_and_lies_on_the_composed_surface() {
    let v = volume([1, 2, 1], 0.1, 9);
    let s = surface(3, 2, true, 2);
    let r = s.composed_with(&v).expect("degree 12 x 8");
    // The iso-line u = 0.37 of s, as a curve: its composition is the iso-line of r.
    let c = s.u_iso(0.37);
    let rc = c.composed_with(&v).expect("degree 8");
    assert_eq!(rc.degree(), 2 * 4);
    for k in 0..=40 {
        let t = k as f64 / 40.0;
        let want = v.eval(&c.eval(t));
        assert!((rc.eval(t) - want).norm() <= COMPOSE_EXACT * size(&s));
        assert!((rc.eval(t) - r.eval(0.37, t)).norm() <= COMPOSE_EXACT * size(&s));
    }
    // A polynomial curve stays polynomial.
    let line = NurbsCurve::try_new(
        1,
        KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).expect("knots"),
        vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0)],
        None,
    )
    .expect("line");
    let rl = line.composed_with(&v).expect("degree 4");
    assert!(!rl.is_rational());
    assert_eq!(rl.degree(), 4);
}

#[test]
fn degree_above_25_is_refused_with_the_degree_needed() {
    // PyGeM's 5 x 4 x 4 lattice (degrees 4, 3, 3) on a bicubic patch needs 3 · 10 = 30.
    let v = volume([4, 3, 3], 0.01, 1);
    let s = surface(3, 3, false, 1);
    match s.composed_with(&v) {
        Err(Error::ComposedDegree { u_degree: 30, v_degree: 30, max: 25 }) => {}
        other => panic!("expected a refusal naming degree 30, got {other:?}"),
    }
    let msg = s.composed_with(&v).unwrap_err().to_string();
    assert!(msg.contains("30 x 30") && msg.contains("25"), "{msg}");
    let c = s.u_iso(0.5);
    assert!(matches!(c.composed_with(&v), Err(Error::ComposedDegree { u_degree: 30, v_degree: 0, .. })));
    // Degree 8·3 = 24 (a degree-8 patch, trilinear box) is allowed.
    let s8 = surface(8, 1, false, 4);
    let r = s8.composed_with(&volume([1, 1, 1], 0.05, 2)).expect("degree 24 x 3");
    assert_eq!((r.u_degree(), r.v_degree()), (24, 3));
}

#[test]
fn bad_volume_is_refused() {
    let q = vec![Point3::origin(); 7];
    assert!(matches!(
        BezierVolume::try_new([1, 1, 1], q, Point3::origin(), Matrix3::identity()),
        Err(Error::NetSize { .. })
    ));
    let q = vec![Point3::origin(); 8];
    assert!(matches!(
        BezierVolume::try_new([1, 0, 1], q.clone(), Point3::origin(), Matrix3::identity()),
        Err(Error::Degree { degree: 0 })
    ));
    let mut m = Matrix3::identity();
    m[(1, 1)] = f64::NAN;
    assert!(matches!(BezierVolume::try_new([1, 1, 1], q, Point3::origin(), m), Err(Error::NotFinite { .. })));
}

/// Knot removal on the composed patch: the C^k joints the composition keeps go at a
/// rounding-level tolerance (2 copies of each simple knot of a bicubic, 1 of the double
/// knot), the surface stays within the reported bound, and a loose tolerance removes more.
#[test]
fn knot_removal_recovers_the_continuity_of_the_composition() {
    let v = volume([1, 1, 1], 0.08, 7);
    let s = surface(3, 3, false, 11);
    let r = s.composed_with(&v).expect("degree 9");
    let tol = 1e-12 * size(&s);
    let mut reduced = r.clone();
    let out = reduced.remove_knots_within(tol);
    assert!(out.bound <= tol);
    // u: simple knots at 1/4 (double: C¹, one copy goes) and 3/4... see `surface`: the u
    // knots are [1/4, 1/4, 3/4] (p + 4 − p − 1 = 3 interior), v: [1/3, 2/3] simple.
    let (uv, um) = reduced.u_knots().distinct();
    let (vv, vm) = reduced.v_knots().distinct();
    assert_eq!(uv.len(), 4);
    assert_eq!(&um[1..3], &[8, 7], "u multiplicities {um:?}");
    assert_eq!(vv.len(), 4);
    assert_eq!(&vm[1..3], &[7, 7], "v multiplicities {vm:?}");
    assert_eq!(out.removed, (9 + 9 - 8 - 7) + 2 * 2);
    let dev = max_dev(&reduced, &s, |x| v.eval(x));
    assert!(dev <= tol + COMPOSE_EXACT * size(&s), "{dev:e}");
    // A looser tolerance removes at least as much and keeps its bound.
    let mut loose = r.clone();
    let lo = loose.remove_knots_within(1e-3 * size(&s));
    assert!(lo.removed >= out.removed && lo.bound <= 1e-3 * size(&s));
    let dev = max_dev(&loose, &r, |x| *x);
    assert!(dev <= lo.bound * (1.0 + 1e-9) + 1e-14, "{dev:e} > {:e}", lo.bound);
    // Nothing to remove on a Bézier patch; a negative or NaN tolerance removes nothing.
    let mut b = r.bezier_patches()[0][0].clone();
    assert_eq!(b.remove_knots_within(1.0).removed, 0);
    let mut n = r.clone();
    assert_eq!(n.remove_knots_within(f64::NAN).removed, 0);
    assert_eq!(n, r);
}

/// `nodes` (C order, `dims` per direction) elevated by one degree along `axis` with the
/// elevation formula `Qᵢ = (i/(d+1)) Pᵢ₋₁ + (1 − i/(d+1)) Pᵢ` (Piegl & Tiller eq. (5.36)).
fn elevate_nodes(dims: [usize; 3], nodes: &[Point3<f64>], axis: usize) -> ([usize; 3], Vec<Point3<f64>>) {
    let mut out_dims = dims;
    out_dims[axis] += 1;
    let at = |d: [usize; 3], c: [usize; 3]| (c[0] * d[1] + c[1]) * d[2] + c[2];
    let mut out = vec![Point3::origin(); out_dims.iter().product()];
    let d1 = dims[axis] as f64; // the new degree
    for i in 0..out_dims[0] {
        for j in 0..out_dims[1] {
            for k in 0..out_dims[2] {
                let c = [i, j, k];
                let r = c[axis];
                let get = |r: usize| {
                    let mut c = c;
                    c[axis] = r;
                    nodes[at(dims, c)].coords
                };
                let a = r as f64 / d1;
                let v = if r == 0 {
                    get(0)
                } else if r == dims[axis] {
                    get(r - 1)
                } else {
                    get(r - 1) * a + get(r) * (1.0 - a)
                };
                out[at(out_dims, c)] = Point3::from(v);
            }
        }
    }
    (out_dims, out)
}

#[test]
fn lowering_finds_the_degrees_a_lattice_was_elevated_from() {
    let low = volume([2, 2, 1], 0.05, 21);
    let (mut dims, mut nodes) = ([3, 3, 2], low.control_points());
    for axis in [0, 0, 1, 2, 2] {
        (dims, nodes) = elevate_nodes(dims, &nodes, axis);
    }
    assert_eq!(dims, [5, 4, 4]);
    let full = BezierVolume::try_new([4, 3, 3], nodes, low.origin(), *low.to_unit()).unwrap();
    let (found, bound) = full.lowered(1e-13);
    assert_eq!(found.degrees(), [2, 2, 1]);
    assert!(bound <= 1e-13, "{bound:e}");
    for (a, b) in found.control_points().iter().zip(&low.control_points()) {
        assert!((a - b).norm() <= 1e-13, "{a} {b}");
    }
    // Composed through the lowered map: degree 3·5 instead of 3·10, the same surface.
    let s = surface(3, 3, false, 4);
    let r = s.composed_with(&found).unwrap();
    assert_eq!((r.u_degree(), r.v_degree()), (15, 15));
    assert!(matches!(s.composed_with(&full), Err(Error::ComposedDegree { u_degree: 30, .. })));
    assert!(max_dev(&r, &s, |x| full.eval(x)) <= COMPOSE_EXACT * size(&s));
    // A generic lattice has its full degrees, and the zero tolerance lowers nothing that
    // is not exact in floating point.
    let generic = volume([4, 3, 3], 0.05, 22);
    let (same, bound) = generic.lowered(1e-9);
    assert_eq!((same.degrees(), bound), ([4, 3, 3], 0.0));
    let (_, b0) = full.lowered(0.0);
    assert_eq!(b0, 0.0);
}

/// Two degree-(8, 1) patches sharing a boundary along u (the first's `v = 1` row is the
/// second's `v = 0` row), several u spans.
fn neighbours() -> (NurbsSurface, NurbsSurface) {
    let n_u = 12;
    let mut ku = vec![0.0; 9];
    ku.extend([0.25, 0.5, 0.75]);
    ku.extend(vec![1.0; 9]);
    let ku = KnotVector::try_new(ku).unwrap();
    let kv = KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).unwrap();
    let row = |y: f64, z: f64| -> Vec<Point3<f64>> {
        (0..n_u)
            .map(|i| {
                let x = i as f64 / (n_u - 1) as f64 * 1.8;
                Point3::new(x, y + 0.1 * (4.0 * x).sin(), z + 0.3 * (2.0 * x).cos())
            })
            .collect()
    };
    let (a, b, c) = (row(-0.4, 0.0), row(0.3, 0.4), row(0.9, 0.2));
    let net = |r0: &[Point3<f64>], r1: &[Point3<f64>]| -> Vec<Point3<f64>> {
        r0.iter().zip(r1).flat_map(|(p, q)| [*p, *q]).collect()
    };
    let s = |r0: &[Point3<f64>], r1: &[Point3<f64>]| {
        NurbsSurface::try_new((8, 1), (ku.clone(), kv.clone()), (n_u, 2), net(r0, r1), None).unwrap()
    };
    (s(&a, &b), s(&b, &c))
}

#[test]
fn an_image_above_degree_25_is_reduced_within_the_tolerance_and_shared_edges_stay_shared() {
    // A 3x3x3 lattice (degree factor 6) on degree-8 patches: the exact image is degree
    // 48 x 6, reduced to 25 x 6.
    let v = volume([2, 2, 2], 0.03, 9);
    let (s1, s2) = neighbours();
    assert!(matches!(s1.composed_with(&v), Err(Error::ComposedDegree { u_degree: 48, v_degree: 6, max: 25 })));
    let tol = 1e-6;
    let (r1, b1) = s1.composed_within(&v, tol).unwrap();
    let (r2, b2) = s2.composed_within(&v, tol).unwrap();
    assert_eq!((r1.u_degree(), r1.v_degree()), (25, 6));
    println!("reduction bounds {b1:e} {b2:e}");
    assert!(b1 > 0.0 && b1 <= tol && b2 <= tol);
    // The bound holds against the pointwise map.
    assert!(max_dev(&r1, &s1, |x| v.eval(x)) <= b1 + COMPOSE_EXACT * size(&s1));
    assert!(max_dev(&r2, &s2, |x| v.eval(x)) <= b2 + COMPOSE_EXACT * size(&s2));
    // The shared edge, reduced along its own direction, is the same curve on both.
    for k in 0..=40 {
        let u = k as f64 / 40.0;
        let gap = (r1.eval(u, 1.0) - r2.eval(u, 0.0)).norm();
        assert!(gap <= COMPOSE_EXACT * size(&s1), "gap {gap:e} at u = {u}");
    }
    // The curve of the edge, composed and reduced alone, is that curve too.
    let (edge, _) = s1.v_iso(1.0).composed_within(&v, tol).unwrap();
    assert_eq!(edge.degree(), 25);
    for k in 0..=40 {
        let u = k as f64 / 40.0;
        assert!((edge.eval(u) - r1.eval(u, 1.0)).norm() <= COMPOSE_EXACT * size(&s1));
    }
    // Too tight a tolerance: refused, naming the degree and the bound.
    match s1.composed_within(&v, b1 / 10.0) {
        Err(Error::ComposedReduction { u_degree: 48, v_degree: 6, max: 25, bound, .. }) => {
            assert_eq!(bound, b1)
        }
        other => panic!("expected a refused reduction, got {other:?}"),
    }
    // Above degree 64 nothing is tried: 8 · (4 + 3 + 3) = 80.
    let big = volume([4, 3, 3], 0.0, 3);
    assert!(matches!(s1.composed_within(&big, 1.0), Err(Error::ComposedDegree { u_degree: 80, .. })));
}
