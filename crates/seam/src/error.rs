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
    /// A refinement would need more memory than the budget allows
    /// ([`cadmorph_morph::budget`]); nothing was allocated.
    #[error("{what} would need {} of memory, over the budget of {}", cadmorph_morph::budget::human_bytes(*needed), cadmorph_morph::budget::human_bytes(*limit as u128))]
    TooLarge {
        /// What was to be refined, and to what size.
        what: String,
        /// Bytes it would need.
        needed: u128,
        /// The budget in force, in bytes.
        limit: u64,
    },
    /// A kernel operation failed.
    #[error(transparent)]
    Nurbs(#[from] cadmorph_nurbs::Error),
}

/// Result with the seam crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
