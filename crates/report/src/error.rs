//! The errors of report building and writing.

use std::path::PathBuf;

/// What can go wrong while building or writing a report.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The "after" model does not have the faces of the "before" model.
    #[error("the morphed model has {after} faces, the original {before}: not the same model")]
    FaceCountMismatch {
        /// Faces before.
        before: usize,
        /// Faces after.
        after: usize,
    },
    /// A model with nothing to draw.
    #[error("the model has no faces to draw")]
    Empty,
    /// A coordinate that is not finite (NaN or infinite) where a picture needs one.
    #[error("{what} has a non-finite coordinate: nothing to draw")]
    NotFinite {
        /// What held it.
        what: String,
    },
    /// A picture size out of range.
    #[error("image size {width}x{height} is out of range (1..=8192 each)")]
    ImageSize {
        /// Width asked.
        width: u32,
        /// Height asked.
        height: u32,
    },
    /// PNG encoding failed.
    #[error("encoding PNG: {0}")]
    Png(#[from] png::EncodingError),
    /// A campaign folder could not be read.
    #[error("reading {path}: {source}")]
    Read {
        /// The path.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Nothing to plot, or the plotting backend failed.
    #[error("plot {what}: {reason}")]
    Plot {
        /// Which plot.
        what: String,
        /// Why.
        reason: String,
    },
    /// A blade law or profile could not be sampled.
    #[error("blade: {0}")]
    Blade(#[from] cadmorph_blade::Error),
    /// Serialising the embedded data failed.
    #[error("serialising report data: {0}")]
    Json(#[from] serde_json::Error),
}

/// `Result` with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
