//! Default tolerances, each with its origin. No operation reads these implicitly:
//! functions take `tol` or `ptol` arguments, and these constants are the usual values.

/// Two points closer than this coincide (OCCT `Precision::Confusion`, model units, tuned for mm).
pub const CONFUSION: f64 = 1e-7;
/// Angular equality in radians (OCCT `Precision::Angular`).
pub const ANGULAR: f64 = 1e-12;
/// Two knots closer than this (relative to the knot span of the whole vector) are the
/// same knot. OCCT's `BSplCLib` uses an absolute `Epsilon(knot)`; a relative value is
/// safe for parameter ranges of any size.
pub const KNOT_EQUALITY: f64 = 1e-12;

/// Parametric tolerance from a model-space one: `ptol = tol / |∂S/∂u|` (OCCT `PConfusion`).
///
/// # Examples
///
/// ```
/// assert!((cadmorph_nurbs::tol::parametric(1e-7, 100.0) - 1e-9).abs() < 1e-24);
/// ```
pub fn parametric(tol: f64, speed: f64) -> f64 {
    tol / speed
}
