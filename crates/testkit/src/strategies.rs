//! proptest strategies for random valid curves and surfaces.

use std::ops::RangeInclusive;

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use proptest::prelude::*;

/// A clamped knot vector for `n` control points of degree `p` on `[a, a + len]`, with
/// random interior knots (repeated knots allowed up to multiplicity `p`).
pub fn knot_vector(p: usize, n: usize) -> impl Strategy<Value = KnotVector> {
    let interior = n - p - 1;
    (
        prop::collection::vec(0.02f64..1.0, interior + 1),
        prop::collection::vec(0usize..4, interior),
        -5.0f64..5.0,
        0.5f64..20.0,
    )
        .prop_map(move |(gaps, repeat, a, len)| {
            // Cumulative gaps give increasing interior knots; `repeat == 0` glues a
            // knot to its predecessor (multiplicity > 1) as long as that stays ≤ p.
            let total: f64 = gaps.iter().sum();
            let mut knots = vec![a; p + 1];
            let mut acc = 0.0;
            let mut run = 0;
            for i in 0..interior {
                acc += gaps[i];
                let mut k = a + len * acc / total;
                if repeat[i] == 0 && run + 1 < p && i > 0 {
                    k = *knots.last().expect("nonempty");
                    run += 1;
                } else {
                    run = 0;
                }
                knots.push(k);
            }
            knots.extend(std::iter::repeat_n(a + len, p + 1));
            KnotVector::try_new(knots).expect("constructed increasing")
        })
}

fn point() -> impl Strategy<Value = Point3<f64>> {
    (-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

/// A random curve with degree in `degrees`, rational with probability 1/2.
pub fn nurbs_curve(degrees: RangeInclusive<usize>) -> impl Strategy<Value = NurbsCurve> {
    (degrees, 0usize..6)
        .prop_flat_map(|(p, extra)| {
            let n = p + 1 + extra;
            (
                Just(p),
                knot_vector(p, n),
                prop::collection::vec(point(), n),
                prop::option::of(prop::collection::vec(0.2f64..5.0, n)),
            )
        })
        .prop_map(|(p, k, pts, w)| NurbsCurve::try_new(p, k, pts, w).expect("valid by construction"))
}

/// A random surface with degrees in `degrees`, rational with probability 1/2.
pub fn nurbs_surface(degrees: RangeInclusive<usize>) -> impl Strategy<Value = NurbsSurface> {
    (degrees.clone(), degrees, 0usize..4, 0usize..4)
        .prop_flat_map(|(p, q, eu, ev)| {
            let (n_u, n_v) = (p + 1 + eu, q + 1 + ev);
            (
                Just((p, q, n_u, n_v)),
                knot_vector(p, n_u),
                knot_vector(q, n_v),
                prop::collection::vec(point(), n_u * n_v),
                prop::option::of(prop::collection::vec(0.2f64..5.0, n_u * n_v)),
            )
        })
        .prop_map(|((p, q, n_u, n_v), uk, vk, pts, w)| {
            NurbsSurface::try_new((p, q), (uk, vk), (n_u, n_v), pts, w).expect("valid by construction")
        })
}

/// A parameter strictly inside `d`, as a fraction `f ∈ (0, 1)` of it.
pub fn lerp(d: &RangeInclusive<f64>, f: f64) -> f64 {
    d.start() + (d.end() - d.start()) * f
}
