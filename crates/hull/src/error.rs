//! Errors of the hull laws and constrained morphs.

use cadmorph_brep::EntityRef;

/// What can go wrong.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A face trimmed inside its curved surface whose loops cannot be followed in the
    /// surface's parameters: its curves do not lie on the surface, or they cross a
    /// closed surface's seam wherever it is put (see `FaceMethod::Reseamed`).
    #[error("face {face} is trimmed inside its {kind} surface along curves that do not lie on it or that cross its seam wherever it is put: cadmorph cannot integrate its share of the enclosed volume")]
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
    /// The faces' vector area `∮ n dA` does not vanish, nor `∮ x ⊗ n dA − V I`, as on
    /// every closed, consistently oriented surface, whatever faces are turned: the shell
    /// has open borders, and a volume would depend on the origin.
    #[error(
        "the faces do not close a solid: their vector area ∮ n dA is ({:.3e}, {:.3e}, {:.3e}), and the closure residual {ratio:.2e} relative to their area {area:.6e} (0 on a closed shell, however its faces are oriented); the volume of an open shell is not defined",
        vector_area[0], vector_area[1], vector_area[2]
    )]
    OpenShell {
        /// `∮ n dA`.
        vector_area: [f64; 3],
        /// `∮ dA`.
        area: f64,
        /// The closure residual (`|∮ n dA| / A` plus the relative deviation of
        /// `∮ x ⊗ n dA` from a multiple of `I`), after the best turning of faces.
        ratio: f64,
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
