//! Where a polynomial curve's coordinate along a direction is extreme: the sign changes
//! of the derivative of `h(t) = C(t)·d`, found on each Bézier piece of the curve.
//!
//! On a piece, `h` is a Bernstein polynomial whose coefficients are the control points'
//! coordinates `cₖ = Pₖ·d`, and its derivative one of degree `p − 1` with coefficients
//! `p (cₖ₊₁ − cₖ)` (Piegl & Tiller eq. 5.7 on a Bézier segment). The roots are isolated
//! by the variation-diminishing property of the Bernstein basis (Descartes' rule of
//! signs: a polynomial has at most as many roots in its interval as its coefficients
//! have sign changes, and exactly one when they change sign once and its ends differ in
//! sign), subdividing by de Casteljau where the count says more than one (Lane &
//! Riesenfeld, *IEEE PAMI* 3(1), 1981), then bisected to the last bit. The answer is
//! exact up to rounding, where sampling with a local search can only approach it.

use nalgebra::Vector3;

use crate::NurbsCurve;

/// Subdivisions after which an interval still holding several sign changes is taken
/// as one root (a double root, where `h` has no extreme, or a cluster narrower than
/// 2⁻⁴⁰ of the piece): its midpoint is returned as a candidate.
const MAX_DEPTH: u32 = 40;

impl NurbsCurve {
    /// Parameters in the open interval `(t0, t1)` among which `h(t) = C(t)·d` reaches
    /// each of its local extremes: the roots of `h′` where it changes sign, and the
    /// knots (where `h′` may jump). With `t0` and `t1` they bound `h` over `[t0, t1]`
    /// exactly: `min h` and `max h` are among the values there. Sorted, no repeats.
    ///
    /// `None` for a rational curve (unequal weights), where `h′`'s numerator has degree
    /// `2p − 2` and no Bézier form of `h` itself, and when `t0 < t1` does not hold.
    ///
    /// ```
    /// use cadmorph_nurbs::{KnotVector, NurbsCurve};
    /// use nalgebra::{Point3, Vector3};
    /// // A parabola's arc x = t, y = 1 − (2t − 1)², t in [0, 1]: y is largest at t = ½.
    /// let knots = KnotVector::try_new(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]).unwrap();
    /// let pts = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(0.5, 2.0, 0.0), Point3::new(1.0, 0.0, 0.0)];
    /// let c = NurbsCurve::new(2, knots, pts, None);
    /// assert_eq!(c.extreme_params(&Vector3::y(), 0.0, 1.0), Some(vec![0.5]));
    /// assert_eq!(c.extreme_params(&Vector3::x(), 0.0, 1.0), Some(vec![]));
    /// ```
    pub fn extreme_params(&self, d: &Vector3<f64>, t0: f64, t1: f64) -> Option<Vec<f64>> {
        if let Some(w) = self.weights() {
            if w.iter().any(|&x| x != w[0]) {
                return None;
            }
        }
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) {
            return None;
        }
        let p = self.degree();
        let mut out = Vec::new();
        for piece in self.bezier_segments() {
            let k = piece.knots().as_slice();
            let (a, b) = (k[0], k[k.len() - 1]);
            if b <= t0 || a >= t1 {
                continue;
            }
            out.push(a);
            if p == 0 {
                continue;
            }
            let c: Vec<f64> = piece.control_points().iter().map(|q| q.coords.dot(d)).collect();
            let e: Vec<f64> = c.windows(2).map(|w| w[1] - w[0]).collect();
            let mut roots = Vec::new();
            sign_change_roots(&e, 0.0, 1.0, 0, &mut roots);
            out.extend(roots.into_iter().map(|s| a + s * (b - a)));
        }
        out.retain(|&t| t > t0 && t < t1);
        out.sort_by(f64::total_cmp);
        out.dedup();
        Some(out)
    }
}

/// Roots in `(lo, hi)` of the polynomial with Bernstein coefficients `e` over `[lo, hi]`
/// where it changes sign, appended to `out` (see the module docs).
fn sign_change_roots(e: &[f64], lo: f64, hi: f64, depth: u32, out: &mut Vec<f64>) {
    let mut changes = 0;
    let mut last = 0.0;
    for &x in e {
        if x != 0.0 {
            if last * x < 0.0 {
                changes += 1;
            }
            last = x;
        }
    }
    let (first, end) = (e[0], e[e.len() - 1]);
    if changes == 0 {
        return;
    }
    if changes == 1 && first * end < 0.0 {
        // Exactly one root: bisect the sign change to adjacent floats.
        let (mut a, mut b) = (0.0f64, 1.0f64);
        loop {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if de_casteljau(e, m) * first > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        out.push(lo + 0.5 * (a + b) * (hi - lo));
        return;
    }
    let mid = 0.5 * (lo + hi);
    if depth >= MAX_DEPTH || mid <= lo || mid >= hi {
        out.push(mid);
        return;
    }
    let (left, right) = split_half(e);
    sign_change_roots(&left, lo, mid, depth + 1, out);
    sign_change_roots(&right, mid, hi, depth + 1, out);
}

/// The value at `s` in `[0, 1]` of the Bernstein polynomial with coefficients `e`
/// (P&T A1.5).
fn de_casteljau(e: &[f64], s: f64) -> f64 {
    let mut q = e.to_vec();
    for k in 1..q.len() {
        for i in 0..q.len() - k {
            q[i] = (1.0 - s) * q[i] + s * q[i + 1];
        }
    }
    q[0]
}

/// The coefficients of the same polynomial over `[0, ½]` and `[½, 1]`, each
/// reparameterised to `[0, 1]` (de Casteljau subdivision).
fn split_half(e: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = e.len();
    let mut q = e.to_vec();
    let mut left = Vec::with_capacity(n);
    let mut right = vec![0.0; n];
    left.push(q[0]);
    right[n - 1] = q[n - 1];
    for k in 1..n {
        for i in 0..n - k {
            q[i] = 0.5 * (q[i] + q[i + 1]);
        }
        left.push(q[0]);
        right[n - 1 - k] = q[n - 1 - k];
    }
    (left, right)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Curve, KnotVector};
    use nalgebra::Point3;
    use proptest::prelude::*;

    fn curve(p: usize, pts: Vec<Point3<f64>>) -> NurbsCurve {
        let n = pts.len();
        let mut k = vec![0.0; p + 1];
        k.extend((1..n - p).map(|i| i as f64 / (n - p) as f64));
        k.extend(vec![1.0; p + 1]);
        NurbsCurve::new(p, KnotVector::try_new(k).unwrap(), pts, None)
    }

    /// The range of `C(t)·d` over `[t0, t1]` from the ends and the returned parameters.
    fn range_from(c: &NurbsCurve, d: &Vector3<f64>, t0: f64, t1: f64) -> (f64, f64) {
        let mut ts = c.extreme_params(d, t0, t1).unwrap();
        ts.extend([t0, t1]);
        let h: Vec<f64> = ts.iter().map(|&t| c.eval(t).coords.dot(d)).collect();
        (h.iter().copied().fold(f64::INFINITY, f64::min), h.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    }

    #[test]
    fn a_cubic_s_curve_has_both_extremes_in_closed_form() {
        // y = B(t) with Bernstein coefficients 0, 3, −3, 0: y′ ∝ 1 − 6t + 6t², roots
        // (3 ∓ √3) / 6.
        let c = curve(
            3,
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 3.0, 0.0),
                Point3::new(2.0, -3.0, 0.0),
                Point3::new(3.0, 0.0, 0.0),
            ],
        );
        let ts = c.extreme_params(&Vector3::y(), 0.0, 1.0).unwrap();
        let want = [(3.0 - 3f64.sqrt()) / 6.0, (3.0 + 3f64.sqrt()) / 6.0];
        assert_eq!(ts.len(), 2, "{ts:?}");
        for (t, w) in ts.iter().zip(want) {
            assert!((t - w).abs() <= 4.0 * f64::EPSILON, "{t} vs {w}");
        }
        // Only the roots inside the asked interval, and none for rational curves.
        assert_eq!(c.extreme_params(&Vector3::y(), 0.5, 1.0).unwrap().len(), 1);
        let r = NurbsCurve::new(3, c.knots().clone(), c.control_points().to_vec(), Some(vec![1.0, 2.0, 1.0, 1.0]));
        assert_eq!(r.extreme_params(&Vector3::y(), 0.0, 1.0), None);
        assert_eq!(c.extreme_params(&Vector3::y(), 1.0, 0.0), None);
    }

    #[test]
    fn a_double_root_or_a_flat_coordinate_gives_no_false_extreme_outside() {
        // y = (2t − 1)³ is monotone with y′ = 0 at ½; x constant.
        let c = curve(
            3,
            vec![
                Point3::new(1.0, -1.0, 0.0),
                Point3::new(1.0, 1.0 / 3.0, 0.0),
                Point3::new(1.0, -1.0 / 3.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
            ],
        );
        for t in c.extreme_params(&Vector3::y(), 0.0, 1.0).unwrap() {
            assert!((t - 0.5).abs() < 1e-6, "{t}");
        }
        assert_eq!(c.extreme_params(&Vector3::x(), 0.0, 1.0), Some(vec![]));
    }

    proptest! {
        /// No point of the curve lies outside the range of `h` over the ends and the
        /// returned parameters (a missed extreme would put samples beyond it; the
        /// range is reached by construction).
        #[test]
        fn the_range_bounds_every_sample(
            p in 1usize..5,
            ys in proptest::collection::vec(-10.0f64..10.0, 8),
            cut in 0.0f64..0.4,
        ) {
            let pts: Vec<Point3<f64>> = ys.iter().enumerate().map(|(i, &y)| Point3::new(i as f64, y, 0.5 * y)).collect();
            let c = curve(p, pts);
            let d = Vector3::new(0.3, 1.0, -0.2);
            let (t0, t1) = (cut, 1.0 - cut / 2.0);
            let (lo, hi) = range_from(&c, &d, t0, t1);
            let h = |t: f64| c.eval(t).coords.dot(&d);
            for i in 0..=4000 {
                let t = t0 + (t1 - t0) * i as f64 / 4000.0;
                prop_assert!(h(t) >= lo - 1e-12 && h(t) <= hi + 1e-12, "{} outside [{}, {}] at {}", h(t), lo, hi, t);
            }
        }
    }
}
