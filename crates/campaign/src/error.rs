//! The campaign's errors: each names the file, and where it can, the line and field.

use std::path::PathBuf;

/// What went wrong in a campaign.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A campaign file field is missing, malformed or out of range.
    #[error("{path}: line {line}, field `{field}`: {message}")]
    Field {
        /// The campaign file.
        path: PathBuf,
        /// 1-based line (0 when the file has no line for it, e.g. a missing table).
        line: usize,
        /// The field, as written in the file (`parameter[2].entry`).
        field: String,
        /// What was expected and what was found.
        message: String,
    },
    /// A command-line value (a shard, a count) is malformed or out of range.
    #[error("{what}: {message}")]
    Argument {
        /// The argument (`--shard`, `SLURM_ARRAY_TASK_ID`).
        what: String,
        /// What was expected and what was found.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (printed in the message, so not a `source()`: each cause once).
        error: std::io::Error,
    },
    /// The base geometry or the deformation could not be read or applied.
    #[error("{context}: {error}")]
    Cad {
        /// What was being done (`reading samples/hull3.igs`, `variant v0003`).
        context: String,
        /// The cadmorph error (in the message, not a `source()`).
        error: cadmorph::Error,
    },
    /// The deformation parameters could not be read or built.
    #[error("{context}: {error}")]
    Morph {
        /// The parameter file or what was being built.
        context: String,
        /// The morph error (in the message, not a `source()`).
        error: cadmorph::morph::Error,
    },
    /// The manifest on disk was planned from other inputs than the campaign now has.
    #[error("{path}: planned from other inputs (campaign hash {found}, now {expected}); plan again into a new folder")]
    StaleManifest {
        /// The manifest.
        path: PathBuf,
        /// The hash of the campaign now.
        expected: String,
        /// The hash the manifest was planned with.
        found: String,
    },
    /// A results or manifest table is malformed.
    #[error("{path}: line {line}: {message}")]
    Table {
        /// The table.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected.
        message: String,
    },
    /// A numerical fit has too few or degenerate samples.
    #[error("{0}")]
    Fit(String),
    /// An external program (sbatch, sacct) failed.
    #[error("{program}: {message}")]
    External {
        /// The program.
        program: String,
        /// Its error output or exit status.
        message: String,
    },
}

/// Results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `e` with the path of the file it concerns.
pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
    let path = path.into();
    move |error| Error::Io { path, error }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_message_names_its_position() {
        let all = [
            Error::Field {
                path: "c.toml".into(),
                line: 7,
                field: "parameter[1].range".into(),
                message: "empty range [0.1, 0.1]".into(),
            },
            Error::Argument { what: "--shard".into(), message: "K = 3 must be below N = 3".into() },
            Error::Table { path: "r.csv".into(), line: 4, message: "expected 7 columns".into() },
        ];
        let text: Vec<String> = all.iter().map(|e| e.to_string()).collect();
        assert_eq!(text[0], "c.toml: line 7, field `parameter[1].range`: empty range [0.1, 0.1]");
        assert_eq!(text[1], "--shard: K = 3 must be below N = 3");
        assert_eq!(text[2], "r.csv: line 4: expected 7 columns");
    }
}
