//! Errors of the model layer.
//!
//! One rule for wrapping: an error that has a cause returns it from
//! [`source`](std::error::Error::source) and does not print it in its `Display`, so a
//! chain printed cause by cause (the CLI does, [`cadmorph_brep::chain`] does) shows each
//! message once.

use std::path::PathBuf;

use cadmorph_brep::EntityRef;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read.
    #[error("reading {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// An output path names something that is not a regular file (nothing was written).
    #[error("{}: is {kind}; cadmorph writes only regular files", path.display())]
    NotAFile {
        /// The path given.
        path: PathBuf,
        /// What it is.
        kind: &'static str,
    },
    /// A file was read but its contents are not a valid document of its format.
    #[error("reading {}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The format layer's error (names the position in the file).
        source: cadmorph_brep::Error,
    },
    /// The input is neither IGES nor STEP.
    #[error("{what}: not an IGES or STEP file")]
    NotCad {
        /// The file (or `bytes` for input given in memory), and why when the file is
        /// empty.
        what: String,
    },
    /// The output file's extension names no format this crate writes.
    #[error("{}: the extension names no format cadmorph writes (use .igs, .iges, .stp, .step)", path.display())]
    UnknownExtension {
        /// The file.
        path: PathBuf,
    },
    /// The document layer (IGES or STEP) failed; its message is shown as it is.
    #[error(transparent)]
    Document(#[from] cadmorph_brep::Error),
    /// Seam repair failed.
    #[error("seam repair")]
    Seam(#[from] cadmorph_seam::Error),
    /// The morph sends a control point to NaN or infinity.
    #[error("the morph sends control point {point} of face {face} to a non-finite position")]
    NonFinite {
        /// The face.
        face: EntityRef,
        /// Index of the control point.
        point: usize,
    },
    /// The morph folds space at a control point (its Jacobian determinant is not positive).
    #[error("the morph folds space at control point {point} of face {face} (Jacobian determinant {det:e})")]
    Folded {
        /// The face.
        face: EntityRef,
        /// Index of the control point.
        point: usize,
        /// The determinant found.
        det: f64,
    },
    /// The exact FFD of a face or curve cannot be built (see `Model::morph_exact`): the
    /// degree it needs is above OCCT's limit of 25 and does not reduce to it within the
    /// tolerance, or the result is not finite. The kernel's reason is the source.
    #[error("exact FFD of {what}")]
    Exact {
        /// What: `"face #17"`, `"curve DE 45"`, `"the lattice"`.
        what: String,
        /// The kernel's reason, with the degree needed.
        source: cadmorph_nurbs::Error,
    },
    /// No patch with this index.
    #[error("no patch {index} (the model has {len})")]
    NoPatch {
        /// The index asked for.
        index: usize,
        /// How many patches there are.
        len: usize,
    },
    /// What was written does not read back as what was meant.
    #[error("the written document reads back differently: {0}")]
    ReadBack(String),
    /// Something this version cannot do yet.
    #[error("{0}")]
    Unsupported(&'static str),
    /// A surface that two faces of the model use (one part placed twice) where the
    /// document could not give the placements copies of the part (STEP assemblies and
    /// mapped items, IGES 408 subfigure instances get copies, see
    /// `CadDocument::unshare`; a surface shared some other way, or reached through
    /// entities without a typed view, does not): a morph moves the two placements
    /// differently, which one surface cannot hold.
    #[error(
        "surface {surface} is used by face {first} and face {second} (one part placed more than once): a morph \
         would move each placement differently, and the placements could not be given their own copies of the \
         part; nothing was changed"
    )]
    SharedSurface {
        /// The surface entity.
        surface: cadmorph_brep::EntityRef,
        /// The first face using it.
        first: cadmorph_brep::EntityRef,
        /// Another face using it.
        second: cadmorph_brep::EntityRef,
    },
    /// A face cannot be written in another format (its bounds do not form closed loops).
    #[error("converting face {face}: {reason}")]
    Convert {
        /// The face entity.
        face: cadmorph_brep::EntityRef,
        /// What is wrong with its bounds.
        reason: String,
    },
}

/// Result with the model's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
