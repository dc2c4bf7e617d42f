//! Errors of the mesh crate: malformed files (with the file, line or index of the problem),
//! inconsistent topology, and morphs that would spoil the mesh.

use std::path::PathBuf;

/// Everything that can go wrong reading, checking, morphing or writing a mesh.
///
/// Readers name the position of the problem: a 1-based line for text formats, a byte
/// offset for binary ones, an index (point, face, cell) for topology errors. Nothing in
/// this crate panics on bad input.
///
/// # Examples
///
/// ```
/// use cadmorph_mesh::{format::elmer::ElmerNodes, Error};
/// match ElmerNodes::parse("1 -1 0 0 0\n2 -1 0 x 0\n") {
///     Err(Error::Syntax { line, .. }) => assert_eq!(line, 2),
///     other => panic!("unexpected {other:?}"),
/// }
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A text record did not parse.
    #[error("line {line}: expected {expected}, found {found:?}")]
    Syntax {
        /// 1-based line number.
        line: usize,
        /// What the reader expected there.
        expected: &'static str,
        /// The offending text (cut to 60 characters).
        found: String,
    },
    /// Binary data ended early or a size field is inconsistent.
    #[error("byte {offset}: {what}")]
    Binary {
        /// Byte offset where the problem was found.
        offset: usize,
        /// What was expected there.
        what: String,
    },
    /// A point coordinate is NaN or infinite.
    #[error("point {index}: coordinate is not finite ({value})")]
    NonFinite {
        /// 0-based point index.
        index: usize,
        /// The coordinate.
        value: f64,
    },
    /// An element, face or cell refers to something that does not exist.
    #[error("{what} {index}: refers to {target_kind} {target}, but there are only {count}")]
    OutOfRange {
        /// What refers (`face`, `owner entry`, `element`).
        what: &'static str,
        /// Its 0-based index (or the element label for formats with labels).
        index: usize,
        /// What it refers to (`point`, `cell`).
        target_kind: &'static str,
        /// The index it refers to.
        target: i64,
        /// How many of those there are.
        count: usize,
    },
    /// The mesh topology is inconsistent (a face with no cell, a count mismatch).
    #[error("{0}")]
    Topology(String),
    /// A list has the wrong length.
    #[error("{what}: expected {expected}, found {found}")]
    CountMismatch {
        /// Which list.
        what: String,
        /// Expected length.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// The file's format or variant is not supported.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// A morph would leave inverted or degenerate cells; nothing was written.
    #[error("the morphed mesh fails {failed} quality check(s): {summary}")]
    Degraded {
        /// Number of failed checks.
        failed: usize,
        /// Which checks failed, with the worst value and where.
        summary: String,
    },
    /// An error of the morph crate (building a deformation).
    #[error(transparent)]
    Morph(#[from] cadmorph_morph::Error),
    /// An I/O error, with the path it happened on.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Any of the above, in a named file.
    #[error("{path}: {source}")]
    InFile {
        /// The file.
        path: PathBuf,
        /// The error.
        source: Box<Error>,
    },
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// A [`Error::Syntax`] with the found text cut to 60 characters.
    pub(crate) fn syntax(line: usize, expected: &'static str, found: &str) -> Error {
        let found: String = found.chars().take(60).collect();
        Error::Syntax { line, expected, found }
    }

    /// This error, attributed to `path` (kept as is when it already names a file).
    pub fn in_file(self, path: impl Into<PathBuf>) -> Error {
        match self {
            e @ (Error::InFile { .. } | Error::Io { .. }) => e,
            e => Error::InFile { path: path.into(), source: Box::new(e) },
        }
    }
}

/// An I/O error on `path`.
pub(crate) fn io(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io { path: path.to_path_buf(), source }
}
