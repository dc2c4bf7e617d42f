//! 104 hyperbola and parabola arcs as exact rational quadratic B-splines.
//!
//! A conic arc is a rational quadratic Bézier `[P₀, P₁, P₂]` with weights `(1, w, 1)`:
//! `P₀`, `P₂` the end points, `P₁` the intersection of the tangents there, and `w`
//! fixed by the conic. With `M` the symmetric 3×3 matrix of the implicit equation
//! `A x² + B xy + C y² + D x + E y + F = 0` (IGES 5.3 §4.5) and `p = (x, y, 1)`,
//!
//! ```text
//! P₁ = (M p₀) × (M p₂)        (the poles of the two tangent lines meet there)
//! w² = −(p₀ᵀ M p₂) / (2 p₁ᵀ M p₁)
//! ```
//!
//! because on the curve `X(t) = (1−t)² p₀ + 2t(1−t) w p₁ + t² p₂` the quadratic form is
//! `t²(1−t)² (4 w² p₁ᵀMp₁ + 2 p₀ᵀMp₂)` (the other terms vanish: `p₀`, `p₂` are on the conic
//! and `p₁` on both tangents). So the B-spline satisfies the file's implicit equation up
//! to rounding, whatever the position of the conic (B, D, E need not be zero).
//!
//! `w > 1` is a hyperbola arc, `w = 1` a parabola arc (a polynomial quadratic, written
//! without weights). A hyperbola arc is split at its middle (de Casteljau on the
//! homogeneous points, which halves the hyperbolic angle: `w' = √((1 + w)/2)`) until
//! every segment has `w ≤ 1.5` (at most 1.92 of hyperbolic angle).
//!
//! Direction and parameter: the arc runs from the start point `(X1, Y1)` to the
//! terminate point `(X2, Y2)` (for these open conics the connected arc between the two
//! points is unique). For a hyperbola the NURBS parameter runs over `[0, H]`, `H` the
//! hyperbolic angle of the arc, with the segment joints at equal steps of it (where
//! OCCT's `Geom_Hyperbola` parameter, shifted, agrees); for a parabola over `[0, |Δt|]`
//! with `t` the coordinate across the axis, which is OCCT's `Geom_Parabola` parameter up
//! to shift and sign, and the NURBS parameter is affine in it everywhere.

use cadmorph_nurbs::{KnotVector, NurbsCurve};
use nalgebra::{Matrix3, Point3, Vector3};

use crate::entity::ConicArc;

/// Largest weight of a hyperbola segment (hyperbolic half-angle acosh 1.5 ≈ 0.96).
const MAX_WEIGHT: f64 = 1.5;
/// Most halvings of a hyperbola arc (2¹² segments; an arc of hyperbolic angle 690, the
/// most an f64 can hold, needs 10).
const MAX_HALVINGS: usize = 12;
/// The end points may miss the conic by this much, relative to the size of its terms.
const ON_CONIC: f64 = 1e-6;
/// `B² − 4AC` counts as zero (parabola) below this fraction of `max(A², B², C²)`.
const PARABOLIC: f64 = 1e-9;

/// Why a conic arc was not converted.
#[derive(Debug)]
pub(crate) enum ConicError {
    /// The entity's numbers do not make the arc its form says.
    Invalid(&'static str),
    /// The kernel refused the result.
    Geometry(cadmorph_nurbs::Error),
}

impl From<cadmorph_nurbs::Error> for ConicError {
    fn from(e: cadmorph_nurbs::Error) -> Self {
        ConicError::Geometry(e)
    }
}

fn invalid<T>(reason: &'static str) -> Result<T, ConicError> {
    Err(ConicError::Invalid(reason))
}

/// Which conic a 104 is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Hyperbola,
    Parabola,
}

/// The residual of the implicit equation at `(x, y)` divided by the sum of the sizes of its
/// terms (0 on the conic, 1 when the terms do not cancel at all).
pub(crate) fn relative_residual(k: &[f64; 6], x: f64, y: f64) -> f64 {
    let terms = [k[0] * x * x, k[1] * x * y, k[2] * y * y, k[3] * x, k[4] * y, k[5]];
    let scale: f64 = terms.iter().map(|t| t.abs()).sum();
    let sum: f64 = terms.iter().sum();
    if scale == 0.0 {
        0.0
    } else {
        sum.abs() / scale
    }
}

/// The 104 arc of form 2 (hyperbola), 3 (parabola) or 0 (classified by `B² − 4AC`) as
/// an exact rational quadratic B-spline in the plane `z = ZT` of its definition space.
pub(crate) fn conic_arc(c: &ConicArc) -> Result<NurbsCurve, ConicError> {
    let k = c.coefficients;
    let [a, b, cc, d, e, f] = k;
    if !k.iter().chain(&c.start).chain(&c.end).all(|x| x.is_finite()) || !c.z.is_finite() {
        return invalid("conic arc with non-finite numbers");
    }
    let quad = a.abs().max(b.abs()).max(cc.abs());
    if quad == 0.0 {
        return invalid("conic arc with A = B = C = 0 (a line, not a conic)");
    }
    let disc = (b * b - 4.0 * a * cc) / (quad * quad);
    let kind = if disc.abs() <= PARABOLIC {
        Kind::Parabola
    } else if disc > 0.0 {
        Kind::Hyperbola
    } else {
        return invalid("conic arc: the coefficients make an ellipse (B² < 4AC) but the form is not 1");
    };
    match (c.form, kind) {
        (0, _) | (2, Kind::Hyperbola) | (3, Kind::Parabola) => {}
        (2, _) => return invalid("conic arc of form 2 (hyperbola) whose coefficients make a parabola (B² = 4AC)"),
        (3, _) => return invalid("conic arc of form 3 (parabola) whose coefficients make a hyperbola (B² > 4AC)"),
        _ => return invalid("conic arc with a form number other than 0, 1, 2 or 3"),
    }
    let m = Matrix3::new(a, b / 2.0, d / 2.0, b / 2.0, cc, e / 2.0, d / 2.0, e / 2.0, f);
    let mnorm = m.abs().max();
    if m.determinant().abs() <= 1e-14 * mnorm.powi(3) {
        return invalid("degenerate conic arc (the coefficients make a pair of lines or a point)");
    }
    for p in [c.start, c.end] {
        if relative_residual(&k, p[0], p[1]) > ON_CONIC {
            return invalid("conic arc whose start or terminate point is not on the conic");
        }
    }
    if c.start == c.end {
        return invalid("hyperbola or parabola arc whose start and terminate points coincide");
    }
    let p0 = Vector3::new(c.start[0], c.start[1], 1.0);
    let p2 = Vector3::new(c.end[0], c.end[1], 1.0);
    let (l0, l2) = (m * p0, m * p2);
    let p1h = l0.cross(&l2);
    if !(p1h.z.abs() > 1e-14 * p1h.xy().norm() && p1h.z.is_finite()) {
        return invalid("conic arc whose end tangents are parallel (start and terminate on different branches)");
    }
    let p1 = p1h / p1h.z;
    let w2 = -(p0.dot(&(m * p2))) / (2.0 * p1.dot(&(m * p1)));
    if !(w2.is_finite() && w2 > 0.0) {
        return invalid("hyperbola arc whose start and terminate points are on different branches");
    }
    let w = w2.sqrt();
    let z = c.z;
    let pt = |v: &Vector3<f64>| Point3::new(v.x / v.z, v.y / v.z, z);
    match kind {
        Kind::Parabola => {
            if (w - 1.0).abs() > 1e-6 {
                return invalid("parabola arc whose end points and tangents do not fit a parabola");
            }
            // The axis is the null direction of the quadratic part; t runs across it.
            let n1 = Vector3::new(cc, -b / 2.0, 0.0);
            let n2 = Vector3::new(-b / 2.0, a, 0.0);
            let axis = if n1.norm() >= n2.norm() { n1 } else { n2 }.normalize();
            let across = Vector3::new(-axis.y, axis.x, 0.0);
            let dt = ((p2 - p0).dot(&across)).abs();
            if !(dt > 0.0 && dt.is_finite()) {
                return invalid("parabola arc whose end points are mirror images across the axis");
            }
            let knots = KnotVector::try_new(vec![0.0, 0.0, 0.0, dt, dt, dt])?;
            Ok(NurbsCurve::try_new(2, knots, vec![pt(&p0), pt(&p1), pt(&p2)], None)?)
        }
        Kind::Hyperbola => {
            if !(w > 1.0 && w.is_finite()) {
                return invalid("hyperbola arc whose end points and tangents do not fit a hyperbola");
            }
            // Homogeneous segments (x w, y w, w), halved until the weights are small.
            let mut segs = vec![[p0, p1 * w, p2]];
            let mut halvings = 0;
            let mut wseg = w;
            while wseg > MAX_WEIGHT {
                halvings += 1;
                if halvings > MAX_HALVINGS {
                    return invalid("hyperbola arc too long to convert");
                }
                segs = segs.iter().flat_map(halve).collect();
                wseg = ((1.0 + wseg) / 2.0).sqrt();
            }
            let n = segs.len();
            let h = 2.0 * w.acosh();
            let mut knots = vec![0.0; 3];
            let mut points = Vec::with_capacity(2 * n + 1);
            let mut weights = Vec::with_capacity(2 * n + 1);
            for (i, s) in segs.iter().enumerate() {
                // Standard form: end weights 1, middle weight b / √(a c).
                let wm = s[1].z / (s[0].z * s[2].z).sqrt();
                points.push(pt(&s[0]));
                weights.push(1.0);
                points.push(pt(&s[1]));
                weights.push(wm);
                if i + 1 < n {
                    let t = h * (i + 1) as f64 / n as f64;
                    knots.extend([t, t]);
                }
            }
            points.push(pt(&p2));
            weights.push(1.0);
            knots.extend([h; 3]);
            Ok(NurbsCurve::try_new(2, KnotVector::try_new(knots)?, points, Some(weights))?)
        }
    }
}

/// The two halves of a homogeneous quadratic Bézier segment (de Casteljau at ½).
/// The segment is first brought to the standard form (end weights 1, by the
/// reparameterisation that scales the weights by `1, ρ, ρ²`), where `t = ½` is the middle
/// of the hyperbolic angle.
fn halve(s: &[Vector3<f64>; 3]) -> [[Vector3<f64>; 3]; 2] {
    let (a, c) = (s[0].z, s[2].z);
    let s = [s[0] / a, s[1] / (a * c).sqrt(), s[2] / c];
    let l = (s[0] + s[1]) / 2.0;
    let r = (s[1] + s[2]) / 2.0;
    let mid = (l + r) / 2.0;
    [[s[0], l, mid], [mid, r, s[2]]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_nurbs::Curve;

    /// `|Q(x, y)| / |∇Q(x, y)|`: the distance of `(x, y)` from the conic to first order
    /// (infinite at the centre of a hyperbola, where the gradient vanishes).
    fn conic_distance(k: &[f64; 6], x: f64, y: f64) -> f64 {
        let q = k[0] * x * x + k[1] * x * y + k[2] * y * y + k[3] * x + k[4] * y + k[5];
        let gx = 2.0 * k[0] * x + k[1] * y + k[3];
        let gy = k[1] * x + 2.0 * k[2] * y + k[4];
        q.abs() / gx.hypot(gy)
    }

    fn arc(form: i64, k: [f64; 6], start: [f64; 2], end: [f64; 2]) -> ConicArc {
        ConicArc { form, coefficients: k, z: 0.5, start, end }
    }

    /// Largest first-order distance `|Q| / |∇Q|` of the curve's points from the conic,
    /// relative to the size of the control polygon.
    fn worst_residual(c: &NurbsCurve, k: &[f64; 6]) -> f64 {
        let d = c.domain();
        let pts = c.control_points();
        let size = pts.iter().map(|p| (p - pts[0]).norm()).fold(0.0, f64::max);
        (0..=400)
            .map(|i| {
                let t = d.start() + (d.end() - d.start()) * i as f64 / 400.0;
                let p = c.eval(t);
                conic_distance(k, p.x, p.y) / size
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn hyperbola_in_standard_position() {
        // x²/4 − y² = 1: (2 cosh t, sinh t); cosh = 17/8, sinh = −15/8 to cosh = 5/4, sinh = 3/4.
        let k = [1.0, 0.0, -4.0, 0.0, 0.0, -4.0];
        let c = conic_arc(&arc(2, k, [4.25, -1.875], [2.5, 0.75])).unwrap();
        assert!(worst_residual(&c, &k) < 1e-12, "{}", worst_residual(&c, &k));
        let d = c.domain();
        assert_eq!(c.eval(*d.start()), Point3::new(4.25, -1.875, 0.5));
        assert_eq!(c.eval(*d.end()), Point3::new(2.5, 0.75, 0.5));
        // Hyperbolic angle: asinh(15/8) + asinh(3/4).
        let h = (15.0f64 / 8.0).asinh() + 0.75f64.asinh();
        assert!((d.end() - h).abs() < 1e-14);
        assert!(c.weights().unwrap().iter().all(|w| (1.0..=MAX_WEIGHT).contains(w)));
    }

    #[test]
    fn long_hyperbola_in_general_position() {
        // The hyperbola xy = 1 shifted by (1, −2): (x − 1)(y + 2) = 1.
        let k = [0.0, 1.0, 0.0, 2.0, -1.0, -3.0];
        let (s, e) = ([1.0 + 1e-4, -2.0 + 1e4], [1.0 + 1e5, -2.0 + 1e-5]);
        let c = conic_arc(&arc(0, k, s, e)).unwrap();
        assert!(worst_residual(&c, &k) < 1e-12, "{}", worst_residual(&c, &k));
        assert!(c.weights().unwrap().iter().all(|w| (1.0..=MAX_WEIGHT).contains(w)));
        assert!(c.control_points().len() > 3);
        let d = c.domain();
        assert!((c.eval(*d.start()) - Point3::new(s[0], s[1], 0.5)).norm() < 1e-9);
        assert!((c.eval(*d.end()) - Point3::new(e[0], e[1], 0.5)).norm() < 1e-9);
    }

    #[test]
    fn parabola() {
        // y² = 4x from (4, −4) to (2.25, 3).
        let k = [0.0, 0.0, 1.0, -4.0, 0.0, 0.0];
        let c = conic_arc(&arc(3, k, [4.0, -4.0], [2.25, 3.0])).unwrap();
        assert!(!c.is_rational());
        assert!(worst_residual(&c, &k) < 1e-12, "{}", worst_residual(&c, &k));
        assert_eq!(c.domain(), 0.0..=7.0);
        // The parameter is affine in y.
        assert!((c.eval(3.5).y - (-0.5)).abs() < 1e-15);
    }

    #[test]
    fn bad_arcs_are_refused() {
        let hyp = [1.0, 0.0, -4.0, 0.0, 0.0, -4.0];
        // Different branches.
        assert!(conic_arc(&arc(2, hyp, [2.5, 0.75], [-2.5, 0.75])).is_err());
        assert!(conic_arc(&arc(2, hyp, [2.5, 0.75], [-2.5, -0.75])).is_err());
        // Wrong form for the coefficients.
        assert!(conic_arc(&arc(3, hyp, [2.5, 0.75], [4.25, -1.875])).is_err());
        assert!(conic_arc(&arc(2, [1.0, 0.0, 1.0, 0.0, 0.0, -1.0], [1.0, 0.0], [0.0, 1.0])).is_err());
        // Off the conic, coincident, degenerate, non-finite.
        assert!(conic_arc(&arc(2, hyp, [2.5, 0.8], [4.25, -1.875])).is_err());
        assert!(conic_arc(&arc(2, hyp, [2.5, 0.75], [2.5, 0.75])).is_err());
        assert!(conic_arc(&arc(2, [1.0, 0.0, -1.0, 0.0, 0.0, 0.0], [1.0, 1.0], [2.0, 2.0])).is_err());
        assert!(conic_arc(&arc(2, [f64::NAN, 0.0, -1.0, 0.0, 0.0, 0.0], [1.0, 1.0], [2.0, 2.0])).is_err());
        assert!(conic_arc(&arc(3, [0.0; 6], [1.0, 1.0], [2.0, 2.0])).is_err());
        // Extreme numbers: an error or a finite curve, never a panic.
        for k in [[1e300, 0.0, -1e300, 0.0, 0.0, -1e300], [1e-300, 0.0, -1e-300, 0.0, 0.0, -1e-300]] {
            for (s, e) in
                [([1e300, 0.0], [-1e300, 1e300]), ([1.0, 0.0], [2.0, 3f64.sqrt()]), ([f64::MAX, 0.0], [1.0, 0.0])]
            {
                if let Ok(c) = conic_arc(&arc(2, k, s, e)) {
                    assert!(c.control_points().iter().all(|p| p.coords.iter().all(|x| x.is_finite())));
                }
            }
        }
    }
}
