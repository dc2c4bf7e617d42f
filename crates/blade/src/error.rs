//! The error type of the crate: every variant names where the bad input is.

/// What went wrong, with the field, section, line or entity it concerns.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A NACA designation that is not a 4- or 5-digit code BladeX knows.
    #[error("NACA code {code:?}: {reason}")]
    NacaCode {
        /// The code as given.
        code: String,
        /// What is wrong with it.
        reason: String,
    },
    /// Profile coordinates that do not make an airfoil (`CustomProfile._check_coordinates`).
    #[error("profile: {field}: {reason}")]
    Profile {
        /// The array or quantity (`xup`, `ydown[3]`, ...).
        field: String,
        /// What was expected.
        reason: String,
    },
    /// A design-table field that is wrong at one section (or for the whole table when
    /// `section` is `None`).
    #[error("design table: field `{field}`{}: {reason}", section.map(|s| format!(", section {s}")).unwrap_or_default())]
    Table {
        /// The field (`radii`, `chord`, `sections`, ...).
        field: String,
        /// The section index (0 = root), when the problem is at one section.
        section: Option<usize>,
        /// What was expected.
        reason: String,
    },
    /// A BladeX parameter file (`.prm`) that does not parse.
    #[error("{file}: line {line}: {reason}")]
    Prm {
        /// The file name (or `<string>`).
        file: String,
        /// 1-based line of the offending value (0 when the whole file is concerned).
        line: usize,
        /// What was expected.
        reason: String,
    },
    /// A radial law that cannot be built or evaluated.
    #[error("radial law `{param}`: {reason}")]
    RadialLaw {
        /// `chord`, `pitch`, `rake`, `skew`, `camber` or `thickness`.
        param: String,
        /// What is wrong.
        reason: String,
    },
    /// A linear system that has no (unique) solution, with its size.
    #[error("{what}: singular {n}x{n} system")]
    Singular {
        /// Which solve.
        what: &'static str,
        /// The system size.
        n: usize,
    },
    /// A geometric construction that failed (loft, split, reverse intersection).
    #[error("geometry: {0}")]
    Geometry(String),
    /// An error of the NURBS kernel.
    #[error(transparent)]
    Nurbs(#[from] cadmorph_nurbs::Error),
    /// An error of the STEP layer.
    #[error(transparent)]
    Step(#[from] cadmorph_step::Error),
    /// An error of the IGES layer.
    #[error(transparent)]
    Iges(#[from] cadmorph_iges::Error),
    /// A TOML design table or law file that does not parse.
    #[error("TOML: {0}")]
    Toml(String),
    /// An I/O error, with the path.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub(crate) fn table(field: &str, section: Option<usize>, reason: impl Into<String>) -> Self {
        Error::Table { field: field.to_owned(), section, reason: reason.into() }
    }
    pub(crate) fn profile(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Profile { field: field.into(), reason: reason.into() }
    }
}
