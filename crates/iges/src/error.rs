//! Errors of the IGES reader, the typed views, the conversions and the edits.

use std::fmt;

/// Where in the file something went wrong: section letter, 1-based physical line,
/// 1-based column, and the entity (DE sequence number) when there is one.
///
/// ```
/// use cadmorph_iges::Position;
/// let p = Position { section: 'P', line: 12, column: 5, entity: Some(7) };
/// assert_eq!(p.to_string(), "section P, line 12, column 5, entity DE 7");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Position {
    /// `'S'`, `'G'`, `'D'`, `'P'` or `'T'`; `'?'` before any section could be told.
    pub section: char,
    /// Physical line of the file, 1-based (0 when the position is not a line, e.g. an
    /// entity built in memory).
    pub line: usize,
    /// Column, 1-based (the 80-column record's column).
    pub column: usize,
    /// The entity's DE sequence number, if the problem belongs to one.
    pub entity: Option<u32>,
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "section {}, line {}, column {}", self.section, self.line, self.column)?;
        if let Some(de) = self.entity {
            write!(f, ", entity DE {de}")?;
        }
        Ok(())
    }
}

/// What went wrong while reading, viewing, converting or editing an IGES document.
///
/// Every reader error carries a [`Position`] that names section, line, column and entity.
///
/// # Examples
///
/// ```
/// use cadmorph_iges::{Document, Error};
/// // A record whose section letter (column 73) is not one of S, G, D, P, T.
/// let bad = format!("{:72}X0000001\n", "");
/// let err = Document::parse(bad.as_bytes()).unwrap_err();
/// assert!(matches!(err, Error::Section { .. }));
/// assert!(err.to_string().starts_with("section ?, line 1, column 73"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A token did not have the expected form (a number, a Hollerith string, a delimiter).
    #[error("{at}: expected {expected}, found {found:?}")]
    Syntax {
        /// Where.
        at: Position,
        /// What the reader wanted.
        expected: &'static str,
        /// What it found (at most 40 characters).
        found: String,
    },
    /// A line is not an IGES record of the expected section: wrong letter in column 73,
    /// sections out of order, line too short, or a compressed/binary file.
    #[error("{at}: expected {expected}, found {found:?}")]
    Section {
        /// Where.
        at: Position,
        /// What the reader wanted.
        expected: &'static str,
        /// The section letter or text found.
        found: String,
    },
    /// The file ended before a section or record was complete.
    #[error("{at}: file ends early: {what}")]
    Truncated {
        /// The last position read.
        at: Position,
        /// What is missing.
        what: &'static str,
    },
    /// A Hollerith string's length runs past the end of its record or section.
    #[error("{at}: Hollerith string of {length} characters runs past the end of the {within}")]
    Hollerith {
        /// Where the string starts.
        at: Position,
        /// The declared length.
        length: usize,
        /// `"record"` or `"global section"`.
        within: &'static str,
    },
    /// A directory entry's parameter-data pointer or line count lies outside the P section,
    /// or overlaps another entity's parameter lines.
    #[error("{at}: parameter data lines {first}..{first}+{count} not in the P section of {available} lines{detail}")]
    ParamRange {
        /// The directory entry.
        at: Position,
        /// The first line (P sequence number) the entry points to.
        first: i64,
        /// The line count it gives.
        count: i64,
        /// Lines in the P section.
        available: usize,
        /// Extra explanation (overlap), may be empty.
        detail: &'static str,
    },
    /// A parameter record does not belong to the entity that points to it (wrong entity
    /// type as first parameter, or wrong DE back pointer in columns 65–72).
    #[error("{at}: parameter record belongs to {found}, expected {expected}")]
    Mismatch {
        /// Where.
        at: Position,
        /// What the directory entry says.
        expected: String,
        /// What the record says.
        found: String,
    },
    /// A pointer names a directory entry that does not exist (or is even, or negative
    /// where that is not allowed).
    #[error("{at}: pointer {target} names no directory entry (the D section has {entries} entries)")]
    DanglingPointer {
        /// Where the pointer is.
        at: Position,
        /// The pointer value.
        target: i64,
        /// Entries in the D section.
        entries: usize,
    },
    /// A count is negative, or larger than the parameters that remain.
    #[error("{at}: count {count} of {what} is negative or exceeds the {remaining} parameters left")]
    Count {
        /// Where the count is.
        at: Position,
        /// What is counted.
        what: &'static str,
        /// The value read.
        count: i64,
        /// Parameters left after it.
        remaining: usize,
    },
    /// A parameter is missing (the record ends early) or has the wrong kind.
    #[error("{at}: parameter {index} ({what}): expected {expected}")]
    Parameter {
        /// Where the parameter is (or where the record ends).
        at: Position,
        /// 1-based index of the parameter after the entity type.
        index: usize,
        /// What the parameter means.
        what: &'static str,
        /// The kind wanted.
        expected: &'static str,
    },
    /// A line's sequence number (columns 74–80) is not its place in its section.
    #[error("{at}: sequence number {found} where line {expected} of the section was expected (lines out of order or missing)")]
    Sequence {
        /// The line's sequence field.
        at: Position,
        /// Its place in the section, 1-based.
        expected: usize,
        /// The field's text.
        found: String,
    },
    /// The Terminate section's counts disagree with the sections.
    #[error("{at}: terminate section says {section} has {declared} lines, found {found}")]
    Terminate {
        /// The T record.
        at: Position,
        /// Section letter.
        section: char,
        /// The count in the T record.
        declared: i64,
        /// The count found.
        found: usize,
    },
    /// No entity has this DE number.
    #[error("no entity with DE {de}")]
    NoEntity {
        /// The DE number asked for.
        de: u32,
    },
    /// The entity is not of a type this operation accepts.
    #[error("entity DE {de}: type {entity_type} form {form}: {reason}")]
    Unsupported {
        /// The entity.
        de: u32,
        /// Its type.
        entity_type: u32,
        /// Its form.
        form: i64,
        /// Why.
        reason: &'static str,
    },
    /// The entity's numbers do not make valid geometry.
    #[error("entity DE {de}: invalid geometry")]
    Geometry {
        /// The entity.
        de: u32,
        /// The kernel's complaint.
        source: cadmorph_nurbs::Error,
    },
    /// A transformation matrix chain loops or is too deep, or a matrix is singular.
    #[error("entity DE {de}: {reason}")]
    Transform {
        /// The entity.
        de: u32,
        /// Why.
        reason: &'static str,
    },
    /// A subfigure structure that cannot be read (IGES 5.3 §4.74 type 308, §4.137 type
    /// 408): an instance of an entity that is not a 308 definition, a definition that
    /// contains itself (directly or through its instances), nesting deeper than 64 or
    /// more placed entities than the file can describe.
    #[error("entity DE {de}: {reason}")]
    Subfigure {
        /// The 408 instance or 308 definition where reading stopped.
        de: u32,
        /// Why, naming the other entity involved.
        reason: String,
    },
    /// An edit was refused (wrong sizes, non-finite values).
    #[error("entity DE {de}: edit refused: {reason}")]
    Edit {
        /// The entity.
        de: u32,
        /// Why.
        reason: String,
    },
}

/// Something the reader accepted although the file breaks the standard.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// Where.
    pub at: Position,
    /// What was accepted, and how it was read.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.at, self.message)
    }
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// The first 40 characters of `bytes`, lossily decoded, for error messages.
pub(crate) fn snippet(bytes: &[u8]) -> String {
    let end = bytes.len().min(40);
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prints every message once so the wording can be reviewed (`cargo test -- --nocapture`).
    #[test]
    fn messages() {
        let at = Position { section: 'P', line: 3, column: 9, entity: Some(5) };
        let all = [
            Error::Syntax { at, expected: "a number", found: "1.2.3".into() },
            Error::Section { at, expected: "S, G, D, P or T in column 73", found: "X".into() },
            Error::Truncated { at, what: "no Terminate section" },
            Error::Hollerith { at, length: 99, within: "record" },
            Error::ParamRange { at, first: 40, count: 3, available: 12, detail: "" },
            Error::Mismatch { at, expected: "type 128".into(), found: "type 126".into() },
            Error::DanglingPointer { at, target: 8, entries: 3 },
            Error::Count { at, what: "knots", count: -1, remaining: 4 },
            Error::Parameter { at, index: 2, what: "degree", expected: "an integer" },
            Error::Terminate { at, section: 'P', declared: 4, found: 5 },
            Error::NoEntity { de: 9 },
            Error::Unsupported { de: 9, entity_type: 140, form: 0, reason: "ellipse not in standard position" },
            Error::Transform { de: 9, reason: "transformation chain loops" },
            Error::Edit { de: 9, reason: "expected 12 points, found 11".into() },
            Error::Subfigure {
                de: 9,
                reason: "408 instance of DE 7 (type 110), which is not a 308 subfigure definition".into(),
            },
        ];
        for e in &all {
            let text = e.to_string();
            println!("{text}");
            assert!(!text.is_empty());
        }
        assert_eq!(all[0].to_string(), "section P, line 3, column 9, entity DE 5: expected a number, found \"1.2.3\"");
    }
}
