//! Cheap tests that tell, for most faces, that a face check cannot change the result, so
//! that the exact check (square roots and divisions) runs only where it may. Each test
//! answers `true` only with a margin far above the rounding of both computations, so a
//! face it passes gets from the exact check exactly what the test assumes (bit for bit),
//! and `false` whenever it is unsure (tiny, huge or non-finite magnitudes, NaN).
//!
//! * [`surely_convex`]: every corner of the face turns the way of its area vector, so
//!   `concavity` finds no concave corner and gives 0.
//! * [`skew_surely_below`]: an internal face's skewness `|s| / max(0.2 |d|, …)` is at most
//!   `|s| / (0.2 |d|)`; when that bound is below the largest skewness already found (and
//!   below the threshold), the face changes neither the maximum nor the count.

use nalgebra::{Point3, Vector3};

use super::ROOTVSMALL;
use crate::format::foam::Label;

/// A squared length in the range where the tests' margins hold (no underflow to
/// subnormals, no overflow in products of three of them).
fn sane(sq: f64) -> bool {
    sq > 1e-200 && sq < 1e200
}

/// Whether every corner of face `f` is convex beyond doubt: for the edges `a` into and `b`
/// out of each corner, `(a × b) · S_f > 10⁻⁹ |a| |b| |S_f|` (in squares). `concavity`
/// normalises the edges and the area vector and tests the same product against
/// `SMALL` = 10⁻¹⁵; the rounding of either side is below 10⁻¹⁴ of the unit product.
pub(super) fn surely_convex(points: &[Point3<f64>], f: &[Label], fa: &Vector3<f64>) -> bool {
    let n = f.len();
    let fa2 = fa.norm_squared();
    if n < 3 || !sane(fa2) {
        return false;
    }
    let mut a = points[f[0] as usize] - points[f[n - 1] as usize];
    let mut a2 = a.norm_squared();
    for k in 0..n {
        let b = points[f[if k + 1 == n { 0 } else { k + 1 }] as usize] - points[f[k] as usize];
        let b2 = b.norm_squared();
        let s = a.cross(&b).dot(fa);
        if !(sane(a2) && sane(b2) && s > 0.0 && s * s > 1e-18 * (a2 * b2 * fa2)) {
            return false;
        }
        (a, a2) = (b, b2);
    }
    true
}

/// Whether the skewness of the internal face with centre `fc`, area `fa`, owner centre
/// `co` and neighbour centre `cn` is below `limit` beyond doubt. `s` is computed as
/// `skewness` computes it, and `skewness ≤ |s| / (0.2 |d|)` up to a few roundings (its
/// denominator is the larger of `0.2 |d| + ROOTVSMALL` and the points' extent), so
/// `|s|² < (0.2 · limit · (1 − 10⁻⁶))² |d|²` proves it.
pub(super) fn skew_surely_below(
    fc: &Point3<f64>,
    fa: &Vector3<f64>,
    co: &Point3<f64>,
    cn: &Point3<f64>,
    limit: f64,
) -> bool {
    if !(limit > 1e-50 && limit < 1e50) {
        return false;
    }
    let cpf = fc - co;
    let d = cn - co;
    let sv = cpf - (fa.dot(&cpf) / (fa.dot(&d) + ROOTVSMALL)) * d;
    let (s2, d2) = (sv.norm_squared(), d.norm_squared());
    let l = 0.2 * limit * (1.0 - 1e-6);
    sane(d2) && s2 < l * l * d2
}
