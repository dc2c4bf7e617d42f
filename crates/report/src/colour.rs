//! The logarithmic colour scale of seam gaps and G1 angles.
//!
//! A value is placed on a log10 axis between `good` (at or below: green) and `bad` (at
//! or above: [`BAD`], pure red), through yellow at their geometric mean. The tolerance
//! the user asked for is the middle of the scale by default ([`Scale::around`]): a seam
//! at the tolerance is yellow, 100× under it green, 100× over it red.

use serde::Serialize;

/// The colour of a value at or above the scale's `bad` end (sRGB, 0–255).
pub const BAD: [u8; 3] = [230, 20, 20];
/// The colour of a value at or below the scale's `good` end.
pub const GOOD: [u8; 3] = [20, 170, 60];
/// The middle of the scale (the tolerance).
pub const MID: [u8; 3] = [240, 200, 20];

/// A logarithmic scale from `good` to `bad` (both positive, `good < bad`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scale {
    /// Values at or below are [`GOOD`].
    pub good: f64,
    /// Values at or above are [`BAD`].
    pub bad: f64,
}

impl Scale {
    /// The scale from `tol / 100` to `tol × 100`; a non-positive or non-finite `tol`
    /// is taken as `1e-12` so that every value still has a colour.
    pub fn around(tol: f64) -> Self {
        let tol = if tol.is_finite() && tol > 0.0 { tol } else { 1e-12 };
        Self { good: tol / 100.0, bad: tol * 100.0 }
    }

    /// Position of `v` on the scale, 0 (good) to 1 (bad); NaN counts as bad.
    pub fn position(&self, v: f64) -> f64 {
        if v.is_nan() {
            return 1.0;
        }
        if v <= self.good {
            return 0.0;
        }
        let (lo, hi) = (self.good.log10(), self.bad.log10());
        ((v.log10() - lo) / (hi - lo)).clamp(0.0, 1.0)
    }

    /// The colour of `v`.
    pub fn colour(&self, v: f64) -> [u8; 3] {
        ramp(self.position(v))
    }
}

/// The colour at position `t` in `[0, 1]`: [`GOOD`] → [`MID`] → [`BAD`].
pub fn ramp(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let (a, b, s) = if t < 0.5 { (GOOD, MID, t * 2.0) } else { (MID, BAD, t * 2.0 - 1.0) };
    let mix = |i: usize| (a[i] as f64 + (b[i] as f64 - a[i] as f64) * s).round() as u8;
    [mix(0), mix(1), mix(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_middle() {
        let s = Scale::around(1e-5);
        assert_eq!(s.colour(0.0), GOOD);
        assert_eq!(s.colour(1e-8), GOOD);
        assert_eq!(s.colour(1e-5), MID);
        assert_eq!(s.colour(2e-3), BAD);
        assert_eq!(s.colour(f64::NAN), BAD);
        // One decade over the tolerance is a quarter of the way from MID to BAD.
        assert!((s.position(1e-4) - 0.75).abs() < 1e-12);
    }
}
