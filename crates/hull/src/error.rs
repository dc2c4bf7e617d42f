//! Errors of the hull laws and constrained morphs.

use cadmorph_brep::EntityRef;

/// What can go wrong.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A face is trimmed inside its surface and is not planar: its share of the enclosed
    /// volume needs its trimming loops in the surface's parameters, which are not known.
    #[error("face {face} is trimmed inside its {kind} surface and is not planar: cadmorph cannot integrate its enclosed volume exactly (faces must be bounded by their surface's own boundary, or planar)")]
    TrimmedFace {
        /// The face.
        face: EntityRef,
        /// Its surface type.
        kind: String,
    },
    /// The bounding curves of a planar face do not close into loops.
    #[error("the bounding curves of planar face {face} do not close into loops (gap {gap:.3e})")]
    OpenLoop {
        /// The face.
        face: EntityRef,
        /// The smallest gap at the loose end.
        gap: f64,
    },
    /// The faces do not enclose a volume.
    #[error("the faces do not enclose a volume (signed volume {volume:.6e}): the model must be a closed, consistently oriented shell")]
    NotClosed {
        /// What the divergence theorem gave.
        volume: f64,
    },
    /// A constrained morph cannot reach its target.
    #[error(transparent)]
    Constraint(#[from] cadmorph_morph::Error),
    /// The morph moves a face whose enclosed volume cannot be followed exactly.
    #[error("the morph moves face {face}, which is trimmed inside its surface: the volume after the morph cannot be computed exactly; keep trimmed faces outside the FFD box")]
    MovesTrimmedFace {
        /// The face.
        face: EntityRef,
    },
    /// A model operation failed.
    #[error(transparent)]
    Model(#[from] cadmorph_model::Error),
    /// Bad input to a hull law.
    #[error("{0}")]
    Invalid(String),
}

/// `Result` with this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
