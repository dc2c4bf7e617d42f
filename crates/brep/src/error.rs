//! Errors of a document layer.

use std::fmt;

use crate::Format;

/// An error of a format layer (the IGES or STEP reader, a view, an edit), carried
/// unchanged: `Display` is the format error's own message and [`source`] is its source,
/// so a chain printed cause by cause shows each message once. The typed error is
/// reached with [`downcast_ref`](Self::downcast_ref).
///
/// [`source`]: std::error::Error::source
#[derive(Debug)]
pub struct Error {
    format: Format,
    inner: Box<dyn std::error::Error + Send + Sync + 'static>,
}

impl Error {
    /// Wraps the format layer's error `e`.
    pub fn new(format: Format, e: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self { format, inner: Box::new(e) }
    }

    /// The format whose layer failed.
    pub fn format(&self) -> Format {
        self.format
    }

    /// The format layer's error as its own type (`cadmorph_iges::Error`,
    /// `cadmorph_step::Error`), when it is one.
    pub fn downcast_ref<E: std::error::Error + 'static>(&self) -> Option<&E> {
        self.inner.downcast_ref()
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.inner.fmt(f)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.inner.source()
    }
}

/// Result with the document layer's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `e`'s message followed by each of its sources' (`message: cause: cause`): the one
/// way errors are printed whole, since no error's `Display` repeats its source.
///
/// ```
/// let io = std::io::Error::other("disk full");
/// let e = cadmorph_brep::Error::new(cadmorph_brep::Format::Step, io);
/// assert_eq!(cadmorph_brep::chain(&e), "disk full");
/// ```
pub fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut out = e.to_string();
    let mut next = e.source();
    while let Some(s) = next {
        out.push_str(": ");
        out.push_str(&s.to_string());
        next = s.source();
    }
    out
}
