//! Errors of seam analysis and repair.

/// What went wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The two sides share only part of their length, so their rows cannot be merged.
    #[error("patches {a} and {b} share only part of an edge; repair needs the whole side of both")]
    PartialEdge {
        /// First patch.
        a: usize,
        /// Second patch.
        b: usize,
    },
    /// A kernel operation failed.
    #[error(transparent)]
    Nurbs(#[from] cadmorph_nurbs::Error),
}

/// Result with the seam crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
