//! Errors of the NURBS kernel.

/// What went wrong while building or editing a curve or surface.
///
/// Every variant carries the numbers needed to find the culprit: the index of the
/// bad knot, weight or control point and the value found there.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{Error, KnotVector};
/// let err = KnotVector::try_new(vec![0.0, 1.0, 0.5]).unwrap_err();
/// assert!(matches!(err, Error::DecreasingKnots { index: 2, .. }));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A knot is smaller than the one before it.
    #[error("knot {index} ({value}) is smaller than knot {} ({previous})", index - 1)]
    DecreasingKnots {
        /// Index of the offending knot.
        index: usize,
        /// Its value.
        value: f64,
        /// The value of the knot before it.
        previous: f64,
    },
    /// A knot, weight or coordinate is NaN or infinite.
    #[error("{what} {index} is not finite ({value})")]
    NotFinite {
        /// `"knot"`, `"weight"` or `"control point"`.
        what: &'static str,
        /// Index of the offending value.
        index: usize,
        /// The value found (one coordinate for points).
        value: f64,
    },
    /// The knot vector spans no parameter range (all knots equal).
    #[error("knot vector spans an empty range [{start}, {end}]")]
    EmptyDomain {
        /// Domain start.
        start: f64,
        /// Domain end.
        end: f64,
    },
    /// The number of knots does not fit the degree and the number of control points.
    #[error(
        "{direction}expected {expected} knots for degree {degree} and {control_points} control points, found {found}"
    )]
    KnotCount {
        /// `""`, `"u: "` or `"v: "`.
        direction: &'static str,
        /// Knots expected: control points + degree + 1.
        expected: usize,
        /// Knots found.
        found: usize,
        /// The degree.
        degree: usize,
        /// The number of control points.
        control_points: usize,
    },
    /// A knot value is repeated more often than degree + 1 times.
    #[error("knot {value} has multiplicity {multiplicity}, more than degree + 1 = {max}")]
    Multiplicity {
        /// The knot value.
        value: f64,
        /// Its multiplicity.
        multiplicity: usize,
        /// The largest allowed multiplicity.
        max: usize,
    },
    /// The degree is 0 or larger than [`MAX_DEGREE`](crate::MAX_DEGREE).
    #[error("degree {degree} is outside 1..={}", crate::MAX_DEGREE)]
    Degree {
        /// The degree asked for.
        degree: usize,
    },
    /// Fewer control points than degree + 1.
    #[error("{found} control points cannot carry degree {degree} (need at least {})", degree + 1)]
    TooFewControlPoints {
        /// The degree.
        degree: usize,
        /// Control points found.
        found: usize,
    },
    /// The control net is not `n_u × n_v`.
    #[error("control net has {found} points, expected {n_u} x {n_v} = {}", n_u * n_v)]
    NetSize {
        /// Rows in u.
        n_u: usize,
        /// Columns in v.
        n_v: usize,
        /// Points found.
        found: usize,
    },
    /// Weights and control points differ in number.
    #[error("{weights} weights for {control_points} control points")]
    WeightCount {
        /// Weights found.
        weights: usize,
        /// Control points.
        control_points: usize,
    },
    /// A weight is negative (zero is accepted: a control point at infinity).
    #[error("weight {index} is {value}; weights must be positive")]
    NonPositiveWeight {
        /// Index of the weight.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A parameter lies outside the domain, or on its end where an interior value is needed.
    #[error("parameter {value} is not inside the domain [{start}, {end}]")]
    OutsideDomain {
        /// The parameter.
        value: f64,
        /// Domain start.
        start: f64,
        /// Domain end.
        end: f64,
    },
    /// Knot multiplicities passed with distinct knots do not match in length, or are zero.
    #[error("{knots} distinct knots but {mults} multiplicities (each must be >= 1)")]
    MultiplicityList {
        /// Number of distinct knots.
        knots: usize,
        /// Number of multiplicities.
        mults: usize,
    },
    /// A periodic curve or surface whose data does not close up.
    #[error("periodic data: {reason}")]
    Periodic {
        /// What does not fit.
        reason: &'static str,
    },
    /// An analytic surface with a non-positive radius, zero axis or bad angle range.
    #[error("analytic {shape}: {reason}")]
    Analytic {
        /// `"cylinder"`, `"sphere"`, ...
        shape: &'static str,
        /// What is wrong.
        reason: &'static str,
    },
    /// An interpolation or fit that cannot be done: wrong point count, a singular
    /// system, non-finite points, or a tolerance not reached (with the deviation reached).
    #[error("fit: {reason}{}", if reached.is_finite() { format!(" (deviation {reached:e})") } else { String::new() })]
    Fit {
        /// What failed.
        reason: String,
        /// The deviation reached, or infinity where none applies.
        reached: f64,
    },
    /// A Cartesian point asked for where the curve is at infinity (homogeneous weight
    /// zero; only curves with zero weights get there).
    #[error("the curve is at infinity at t = {parameter} (its homogeneous weight is 0)")]
    AtInfinity {
        /// The parameter.
        parameter: f64,
    },
    /// A Cartesian point asked for where the surface is at infinity (homogeneous weight
    /// zero; only surfaces with zero weights get there).
    #[error("the surface is at infinity at (u, v) = ({u}, {v}) (its homogeneous weight is 0)")]
    SurfaceAtInfinity {
        /// The u parameter.
        u: f64,
        /// The v parameter.
        v: f64,
    },
    /// An exact composition (FFD of a patch, [`BezierVolume`](crate::BezierVolume)) that
    /// would need a degree above the largest allowed (OCCT's limit of 25).
    #[error("the exact composition needs degree {u_degree} x {v_degree}, above the maximum of {max} (OCCT's limit)")]
    ComposedDegree {
        /// The degree needed in u (along a curve).
        u_degree: usize,
        /// The degree needed in v (0 for a curve).
        v_degree: usize,
        /// The largest degree allowed.
        max: usize,
    },
    /// An exact composition above the largest allowed degree whose degree reduction to
    /// that degree (see [`NurbsSurface::composed_within`](crate::NurbsSurface::composed_within))
    /// would move it by more than the tolerance.
    #[error(
        "the exact composition needs degree {u_degree} x {v_degree}, above the maximum of {max} (OCCT's limit), \
         and reducing it to {max} would move it by {bound:.3e}, more than the tolerance {tol:.3e}"
    )]
    ComposedReduction {
        /// The degree needed in u (along a curve).
        u_degree: usize,
        /// The degree needed in v (0 for a curve).
        v_degree: usize,
        /// The largest degree allowed.
        max: usize,
        /// The reduction's deviation bound (model units).
        bound: f64,
        /// The tolerance asked for.
        tol: f64,
    },
    /// A data reduction (degree reduction, knot removal) that would move the curve by
    /// more than the tolerance.
    #[error("{operation}: the curve would move by more than {tol}{}", if bound.is_finite() { format!(" (bound {bound:e})") } else { String::from(" (no bound: a knot cannot be removed within it, or a weight would not stay positive)") })]
    Tolerance {
        /// `"degree reduction"`.
        operation: &'static str,
        /// The deviation bound reached, or infinity where a step failed before it.
        bound: f64,
        /// The tolerance asked for.
        tol: f64,
    },
}

/// Result with the kernel's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
