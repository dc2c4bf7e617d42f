//! The lossless document: every line of the file, the parsed Global section, and every
//! entity with its directory entry and parameter record.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::{Arc, OnceLock};

use crate::error::{Error, Position, Result};
use crate::global::Global;
use crate::read::lexer::Raw;
use crate::read::tokens::Tokens;

/// The DE sequence number of an entity (odd, 1-based: the first entity is DE 1, the
/// second DE 3). Pointers in IGES are these numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EntityId(pub u32);

impl EntityId {
    /// The index of the entity in directory order (`(de − 1) / 2`).
    pub fn index(self) -> usize {
        (self.0.saturating_sub(1) / 2) as usize
    }
    /// The id of the entity at directory index `index`.
    pub fn from_index(index: usize) -> Self {
        EntityId((2 * index + 1) as u32)
    }
}

impl fmt::Display for EntityId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "DE {}", self.0)
    }
}

/// The status number of a directory entry (field 9): four two-digit flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Status {
    /// 0 visible, 1 blanked.
    pub blank: u8,
    /// 0 independent, 1 physically dependent, 2 logically dependent, 3 both.
    pub subordinate: u8,
    /// 0 geometry, 1 annotation, 2 definition, 3 other, 4 logical/positional,
    /// 5 2D parametric, 6 construction geometry.
    pub entity_use: u8,
    /// 0 global top down, 1 global defer, 2 use the hierarchy property.
    pub hierarchy: u8,
}

/// The twenty fields of a directory entry, as read (pointers as signed integers:
/// negative values point to definition entities, 0 is "none").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Directory {
    /// Field 1 (and 11): the entity type number.
    pub entity_type: u32,
    /// Field 2: first P-section line of the parameter record.
    pub parameter_data: i64,
    /// Field 3: structure (negated pointer) or 0.
    pub structure: i64,
    /// Field 4: line font pattern or negated pointer.
    pub line_font: i64,
    /// Field 5: level or negated pointer.
    pub level: i64,
    /// Field 6: view pointer.
    pub view: i64,
    /// Field 7: transformation matrix (124) pointer, 0 for none.
    pub transform: i64,
    /// Field 8: label display associativity pointer.
    pub label_display: i64,
    /// Field 9: status flags.
    pub status: Status,
    /// Field 12: line weight number.
    pub line_weight: i64,
    /// Field 13: colour number or negated pointer to a 314.
    pub color: i64,
    /// Field 14: number of parameter lines.
    pub parameter_lines: i64,
    /// Field 15: form number.
    pub form: i64,
    /// Field 18: entity label (up to 8 characters, blanks trimmed).
    pub label: String,
    /// Field 19: entity subscript number.
    pub subscript: i64,
}

/// One parameter as read, borrowing strings from the record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Param<'a> {
    /// An empty (defaulted) parameter.
    Default,
    /// An integer (also pointers).
    Integer(i64),
    /// A real.
    Real(f64),
    /// A Hollerith string's characters.
    Text(&'a [u8]),
}

impl Param<'_> {
    /// The value as a real (integers convert; default and text give `None`).
    pub fn as_real(&self) -> Option<f64> {
        match *self {
            Param::Integer(i) => Some(i as f64),
            Param::Real(x) => Some(x),
            _ => None,
        }
    }
    /// The value as an integer (reals with integral value convert).
    pub fn as_integer(&self) -> Option<i64> {
        match *self {
            Param::Integer(i) => Some(i),
            Param::Real(x) if x.fract() == 0.0 && x.abs() < 9.0e15 => Some(x as i64),
            _ => None,
        }
    }
    /// An owned copy.
    pub fn to_value(&self) -> Value {
        match *self {
            Param::Default => Value::Default,
            Param::Integer(i) => Value::Integer(i),
            Param::Real(x) => Value::Real(x),
            Param::Text(t) => Value::Text(t.to_vec()),
        }
    }
}

/// An owned parameter value, for writing records.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// An empty (defaulted) parameter.
    Default,
    /// An integer or pointer.
    Integer(i64),
    /// A real; written with the shortest text that reads back to the same bits.
    Real(f64),
    /// A string, written as a Hollerith constant.
    Text(Vec<u8>),
}

/// One entity: its directory entry and its parameter record.
#[derive(Debug, Clone)]
pub struct Entity {
    pub(crate) id: EntityId,
    pub(crate) directory: Directory,
    /// The record text: columns 1–64 of its parameter lines, concatenated.
    pub(crate) text: RecordText,
    /// Parameters, the entity type first.
    pub(crate) tokens: Tokens,
    /// Whether a parameter is a string (else slices of numbers need no check for one).
    pub(crate) strings: bool,
    /// The file's delimiters (to recompute token offsets for error positions).
    pub(crate) delimiters: (u8, u8),
    /// Index of its first line in the P section (0-based) and line count, as read.
    pub(crate) p_first: usize,
    pub(crate) p_count: usize,
    /// Physical file line (1-based) of its first parameter line; 0 once rewritten.
    pub(crate) p_line: usize,
    /// Physical file line (1-based) of its first directory line.
    pub(crate) d_line: usize,
    /// New parameter lines (content of columns 1–64) after an edit.
    pub(crate) new_lines: Option<Vec<Vec<u8>>>,
    /// Directory fields 1, 11 or 15 changed by an edit.
    pub(crate) directory_changed: bool,
    /// For an entity an edit appended (a copy, see `Document::unshare_subfigures`): the
    /// index of the entity as read whose directory lines it is written from.
    pub(crate) template: Option<usize>,
}

impl Entity {
    /// Its DE number.
    pub fn id(&self) -> EntityId {
        self.id
    }
    /// Its entity type number (directory field 1).
    pub fn entity_type(&self) -> u32 {
        self.directory.entity_type
    }
    /// Its form number (directory field 15).
    pub fn form(&self) -> i64 {
        self.directory.form
    }
    /// The directory entry.
    pub fn directory(&self) -> &Directory {
        &self.directory
    }
    /// The number of parameters, the leading entity type included.
    pub fn param_count(&self) -> usize {
        self.tokens.len()
    }
    /// Parameter `i` (0 is the entity type).
    pub fn param(&self, i: usize) -> Option<Param<'_>> {
        self.tokens.get(i).map(|t| self.resolve(t))
    }
    /// All parameters, the entity type first.
    pub fn params(&self) -> impl Iterator<Item = Param<'_>> + '_ {
        self.tokens.iter().map(|t| self.resolve(t))
    }
    /// All parameters as owned values.
    pub fn values(&self) -> Vec<Value> {
        self.params().map(|p| p.to_value()).collect()
    }
    /// The parameter record text (columns 1–64 of its lines, concatenated).
    pub fn record_text(&self) -> &[u8] {
        self.text.get()
    }
    /// Whether an edit rewrote its parameter record.
    pub fn is_rewritten(&self) -> bool {
        self.new_lines.is_some()
    }

    fn resolve(&self, raw: Raw) -> Param<'_> {
        match raw {
            Raw::Default => Param::Default,
            Raw::Integer(i) => Param::Integer(i),
            Raw::Real(x) => Param::Real(x),
            Raw::Text { start, len } => {
                let (s, l) = (start as usize, len as usize);
                Param::Text(self.text.get().get(s..s + l).unwrap_or(&[]))
            }
        }
    }

    /// The file position of parameter `i` (or of the record's end when `i` is past it).
    pub fn position(&self, i: usize) -> Position {
        let text = self.text.get();
        let offsets = crate::read::lexer::offsets(text, self.delimiters.0, self.delimiters.1);
        let off = offsets.get(i).copied().unwrap_or(text.len());
        self.offset_position(off)
    }

    pub(crate) fn offset_position(&self, off: usize) -> Position {
        if self.p_line == 0 {
            return Position { section: 'P', line: 0, column: off + 1, entity: Some(self.id.0) };
        }
        Position { section: 'P', line: self.p_line + off / 64, column: off % 64 + 1, entity: Some(self.id.0) }
    }

    pub(crate) fn directory_position(&self, column: usize) -> Position {
        Position { section: 'D', line: self.d_line, column, entity: Some(self.id.0) }
    }
}

/// The input bytes and their lines, shared by the document and its entities (whose
/// record texts are built from them when first asked for).
#[derive(Debug)]
pub(crate) struct Source {
    pub bytes: Vec<u8>,
    pub lines: Vec<Line>,
}

impl Source {
    /// Columns 1–`width` of lines `range`, concatenated.
    pub fn columns(&self, range: std::ops::Range<usize>, width: usize) -> Vec<u8> {
        let mut text = Vec::with_capacity(range.len() * width);
        for l in &self.lines[range] {
            text.extend_from_slice(&self.bytes[l.start..l.start + width]);
        }
        text
    }
}

/// A record's text: given (edited records, short records read whole), or built from the
/// input's lines on first use (long records are tokenized through a small window and
/// their text is not kept unless asked for).
#[derive(Clone)]
pub(crate) struct RecordText {
    text: OnceLock<Vec<u8>>,
    /// The input and the record's line range in it (columns 1–64 of each line).
    lines: Option<(Arc<Source>, std::ops::Range<usize>)>,
}

impl RecordText {
    /// A text held from the start.
    pub fn owned(text: Vec<u8>) -> Self {
        RecordText { text: OnceLock::from(text), lines: None }
    }
    /// The text of `lines` of `source`, built when first asked for.
    pub fn lazy(source: Arc<Source>, lines: std::ops::Range<usize>) -> Self {
        RecordText { text: OnceLock::new(), lines: Some((source, lines)) }
    }
    /// The text.
    pub fn get(&self) -> &[u8] {
        self.text.get_or_init(|| match &self.lines {
            Some((source, range)) => source.columns(range.clone(), crate::read::P_WIDTH),
            None => Vec::new(),
        })
    }
}

impl fmt::Debug for RecordText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&String::from_utf8_lossy(self.get()), f)
    }
}

/// A physical line: content `start..end`, line terminator `end..next`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Line {
    pub start: usize,
    pub end: usize,
    pub next: usize,
}

/// Line index ranges of the sections.
#[derive(Debug, Clone, Default)]
pub(crate) struct Layout {
    pub start: std::ops::Range<usize>,
    pub global: std::ops::Range<usize>,
    pub directory: std::ops::Range<usize>,
    pub parameter: std::ops::Range<usize>,
    pub terminate: usize,
    /// Byte offset of anything after the Terminate line (kept verbatim).
    pub trailer: usize,
}

/// A run of P-section lines: an entity's record, or lines no entity points to.
#[derive(Debug, Clone)]
pub(crate) enum PBlock {
    Entity(usize),
    Loose(std::ops::Range<usize>),
}

/// An IGES 5.3 file held losslessly: [`write`](Document::write) of an unchanged
/// document gives back the input bytes, and edits rewrite only the records they change.
///
/// # Examples
///
/// ```
/// use cadmorph_iges::Document;
/// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/bspline_surface.igs")).unwrap();
/// let doc = Document::parse(&bytes).unwrap();
/// assert_eq!(doc.write(), bytes);
/// assert_eq!(doc.counts_by_type()[&128], 1);
/// ```
#[derive(Debug, Clone)]
pub struct Document {
    pub(crate) src: Arc<Source>,
    pub(crate) layout: Layout,
    pub(crate) global: Global,
    pub(crate) entities: Vec<Entity>,
    pub(crate) p_blocks: Vec<PBlock>,
    pub(crate) edited: bool,
    /// Sequence numbers written `0000001` (true) or `      1`.
    pub(crate) zero_padded: bool,
    /// What the reader accepted but would not write itself ([`Document::warnings`]).
    pub(crate) warnings: Vec<crate::Warning>,
}

impl Document {
    /// Reads an IGES file (fixed 80-column ASCII form).
    ///
    /// # Errors
    ///
    /// Any [`Error`] reader variant, naming section, line, column and entity; no input
    /// panics, and no allocation is made from a count before checking it against the
    /// input left.
    pub fn parse(bytes: &[u8]) -> Result<Self> {
        crate::read::parse(bytes.to_vec())
    }

    /// Like [`parse`](Self::parse), keeping `bytes` as the document's text instead of a
    /// copy (for `std::fs::read` output).
    ///
    /// # Errors
    ///
    /// As [`parse`](Self::parse).
    ///
    /// ```
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/nurbs_arc.igs")).unwrap();
    /// let doc = cadmorph_iges::Document::from_bytes(bytes.clone()).unwrap();
    /// assert_eq!(doc.write(), bytes);
    /// ```
    pub fn from_bytes(bytes: Vec<u8>) -> Result<Self> {
        crate::read::parse(bytes)
    }

    /// The file text: the input bytes if nothing was edited, otherwise the input with
    /// the edited parameter records rewritten and sequence numbers, directory pointers
    /// and the Terminate record updated.
    pub fn write(&self) -> Vec<u8> {
        crate::write::write(self)
    }

    /// The Global section.
    pub fn global(&self) -> &Global {
        &self.global
    }

    /// Every entity, in directory order.
    pub fn entities(&self) -> impl ExactSizeIterator<Item = &Entity> + '_ {
        self.entities.iter()
    }

    /// The number of entities.
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether the document has no entities.
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    /// The entity with DE number `id`.
    ///
    /// # Errors
    ///
    /// [`Error::NoEntity`] if there is none.
    pub fn entity(&self, id: EntityId) -> Result<&Entity> {
        self.index_of(id).map(|i| &self.entities[i])
    }

    pub(crate) fn index_of(&self, id: EntityId) -> Result<usize> {
        if id.0 % 2 == 1 && id.index() < self.entities.len() {
            Ok(id.index())
        } else {
            Err(Error::NoEntity { de: id.0 })
        }
    }

    /// Number of entities of each type.
    pub fn counts_by_type(&self) -> BTreeMap<u32, usize> {
        let mut m = BTreeMap::new();
        for e in &self.entities {
            *m.entry(e.entity_type()).or_insert(0) += 1;
        }
        m
    }

    /// Checks the Terminate record's line counts against the sections (the reader itself
    /// does not insist on them, as OCCT does not).
    ///
    /// # Errors
    ///
    /// [`Error::Terminate`] naming the first section whose count differs, or
    /// [`Error::Syntax`] if the record does not hold four counts.
    ///
    /// ```
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3.igs")).unwrap();
    /// cadmorph_iges::Document::parse(&bytes).unwrap().check_terminate().unwrap();
    /// ```
    pub fn check_terminate(&self) -> Result<()> {
        let t = self.layout.terminate;
        let line = self.line_bytes(t);
        let found = [
            ('S', self.layout.start.len()),
            ('G', self.layout.global.len()),
            ('D', self.layout.directory.len()),
            ('P', self.layout.parameter.len()),
        ];
        for (k, (letter, n)) in found.into_iter().enumerate() {
            let field = &line[8 * k..8 * k + 8];
            let at = Position { section: 'T', line: t + 1, column: 8 * k + 1, entity: None };
            let digits = std::str::from_utf8(&field[1..]).ok().map(str::trim).and_then(|d| d.parse::<i64>().ok());
            let Some(declared) = digits.filter(|_| field[0] == letter as u8) else {
                return Err(Error::Syntax {
                    at,
                    expected: "a section letter and a 7-digit count",
                    found: crate::error::snippet(field),
                });
            };
            if declared != n as i64 {
                return Err(Error::Terminate { at, section: letter, declared, found: n });
            }
        }
        Ok(())
    }

    /// What the reader accepted although the file breaks the standard (a Hollerith count
    /// past the end of the Global section, read as OCCT reads it), each with its position.
    pub fn warnings(&self) -> &[crate::Warning] {
        &self.warnings
    }

    /// Whether any edit has been made.
    pub fn is_edited(&self) -> bool {
        self.edited
    }

    /// Entities whose type this crate has no typed view for (kept verbatim).
    pub fn unknown_entities(&self) -> Vec<EntityId> {
        self.entities.iter().filter(|e| !crate::entity::is_known_type(e.entity_type())).map(|e| e.id).collect()
    }

    /// Line terminator of the file (that of its first line), used for new lines.
    pub(crate) fn eol(&self) -> &[u8] {
        match self.src.lines.first() {
            Some(l) if l.next > l.end => &self.src.bytes[l.end..l.next],
            _ => b"\n",
        }
    }

    pub(crate) fn line_bytes(&self, k: usize) -> &[u8] {
        let l = self.src.lines[k];
        &self.src.bytes[l.start..l.end]
    }

    pub(crate) fn line_with_eol(&self, k: usize) -> &[u8] {
        let l = self.src.lines[k];
        &self.src.bytes[l.start..l.next]
    }
}
