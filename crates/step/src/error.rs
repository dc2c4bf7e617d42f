//! Errors of the STEP reader, the typed views and the editor.
//!
//! Every error that comes from the file names where: the line and column (1-based, columns
//! counted in bytes) and, inside the data section, the instance (`#id`) it belongs to.

use std::fmt;

use crate::EntityId;

/// Where in the file an error was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Position {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in bytes.
    pub column: usize,
    /// The instance the position belongs to, if any.
    pub id: Option<EntityId>,
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}, column {}", self.line, self.column)?;
        if let Some(id) = self.id {
            write!(f, ", instance {id}")?;
        }
        Ok(())
    }
}

/// What went wrong while reading, viewing or editing a STEP document.
///
/// # Examples
///
/// ```
/// use cadmorph_step::{Document, Error};
/// let bad = b"ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = CARTESIAN_POINT('', (0., 0., 0.));\n#2 = VERTEX_POINT('', #9);\nENDSEC;\nEND-ISO-10303-21;\n";
/// let err = Document::parse(bad).unwrap_err();
/// assert!(matches!(err, Error::DanglingReference { .. }));
/// assert_eq!(err.to_string(), "line 6, column 23, instance #2: reference to #9, which is not in the file");
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The text does not follow the ISO 10303-21 grammar at this point.
    #[error("{at}: expected {expected}, found {found}")]
    Syntax {
        /// Where.
        at: Position,
        /// What the grammar wanted.
        expected: &'static str,
        /// What is there (a short excerpt, or "end of file").
        found: String,
    },
    /// A string literal has no closing apostrophe.
    #[error("{at}: unterminated string")]
    UnterminatedString {
        /// Where the string starts.
        at: Position,
    },
    /// A comment `/* ...` has no closing `*/`.
    #[error("{at}: unterminated comment")]
    UnterminatedComment {
        /// Where the comment starts.
        at: Position,
    },
    /// The file ends before `END-ISO-10303-21;` (or inside an instance).
    #[error("{at}: file ends early, {expected} missing")]
    Truncated {
        /// The end of the file (and the open instance, if any).
        at: Position,
        /// What is missing.
        expected: &'static str,
    },
    /// Two instances have the same id.
    #[error("{at}: instance {id} is defined twice (first on line {first_line})")]
    DuplicateId {
        /// Where the second definition starts.
        at: Position,
        /// The id.
        id: EntityId,
        /// Line of the first definition.
        first_line: usize,
    },
    /// A `#n` reference names no instance of the file.
    #[error("{at}: reference to {target}, which is not in the file")]
    DanglingReference {
        /// Where the reference is.
        at: Position,
        /// The missing instance.
        target: EntityId,
    },
    /// Following references from an instance leads back to it.
    #[error("{at}: reference cycle through {target}")]
    ReferenceCycle {
        /// The instance that closes the cycle.
        at: Position,
        /// The instance that is reached again.
        target: EntityId,
    },
    /// A record has the wrong number of parameters for its entity type.
    #[error("{at}: {entity} takes {expected} parameters, found {found}")]
    Arity {
        /// Where the record starts.
        at: Position,
        /// The entity (leaf) name.
        entity: String,
        /// Parameters the entity has.
        expected: usize,
        /// Parameters found.
        found: usize,
    },
    /// A parameter has the wrong type or value for its entity.
    #[error("{at}: {entity} parameter {index}: expected {expected}")]
    Parameter {
        /// Where the parameter is.
        at: Position,
        /// The entity (leaf) name.
        entity: String,
        /// 0-based index of the parameter within its record.
        index: usize,
        /// What was expected.
        expected: &'static str,
    },
    /// A reference leads to an instance of an unexpected or unsupported entity type.
    #[error("{at}: {found} is not {expected}")]
    UnexpectedEntity {
        /// Where the referenced instance starts.
        at: Position,
        /// What the reference should point to.
        expected: &'static str,
        /// The entity found.
        found: String,
    },
    /// A count or size does not fit what the input can hold (a list longer than the
    /// file, an id beyond `u64`, nesting deeper than the reader allows).
    #[error("{at}: {what}")]
    Limit {
        /// Where.
        at: Position,
        /// Which limit.
        what: &'static str,
    },
    /// The geometry of an instance is invalid (the NURBS kernel refused it).
    #[error("{at}: invalid geometry")]
    Geometry {
        /// Where the instance starts.
        at: Position,
        /// The kernel's reason.
        source: cadmorph_nurbs::Error,
    },
    /// An edit names an instance that does not exist.
    #[error("no instance {0} in the document")]
    NoSuchInstance(EntityId),
    /// An edit does not fit the instance it is applied to.
    #[error("{at}: cannot edit: {reason}")]
    Edit {
        /// The instance.
        at: Position,
        /// Why.
        reason: String,
    },
}

impl Error {
    /// The position the error names, if it names one.
    pub fn position(&self) -> Option<Position> {
        match self {
            Error::Syntax { at, .. }
            | Error::UnterminatedString { at }
            | Error::UnterminatedComment { at }
            | Error::Truncated { at, .. }
            | Error::DuplicateId { at, .. }
            | Error::DanglingReference { at, .. }
            | Error::ReferenceCycle { at, .. }
            | Error::Arity { at, .. }
            | Error::Parameter { at, .. }
            | Error::UnexpectedEntity { at, .. }
            | Error::Limit { at, .. }
            | Error::Geometry { at, .. }
            | Error::Edit { at, .. } => Some(*at),
            Error::NoSuchInstance(_) => None,
        }
    }
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
