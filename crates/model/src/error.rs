//! Errors of the model layer.

/// What went wrong.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The IGES layer failed (its error names section, line, column and entity).
    #[error("IGES: {0}")]
    Iges(#[from] cadmorph_iges::Error),
    /// The STEP layer failed (its error names line, column and instance).
    #[error("STEP: {0}")]
    Step(#[from] cadmorph_step::Error),
    /// Seam repair failed.
    #[error("seam repair: {0}")]
    Seam(#[from] cadmorph_seam::Error),
    /// The morph sends a control point to NaN or infinity.
    #[error("the morph sends control point {point} of face {face} to a non-finite position")]
    NonFinite {
        /// The face (its entity).
        face: String,
        /// Index of the control point.
        point: usize,
    },
    /// The morph folds space at a control point (its Jacobian determinant is not positive).
    #[error("the morph folds space at control point {point} of face {face} (Jacobian determinant {det:e})")]
    Folded {
        /// The face (its entity).
        face: String,
        /// Index of the control point.
        point: usize,
        /// The determinant found.
        det: f64,
    },
    /// Something this version cannot do yet for this format.
    #[error("{0}")]
    Unsupported(&'static str),
}

/// Result with the model's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
