//! The lossless document: the file's bytes, an index of its instances, and the edits.

use std::collections::{BTreeMap, HashMap};

use crate::error::{Error, Position, Result};
use crate::read::param::{parse_body, parse_body_in, Body, Param};
use crate::EntityId;

/// One instance of the data section: where its text is and what it is.
#[derive(Debug, Clone)]
pub(crate) struct Instance {
    /// The id `n` of `#n`.
    pub id: u64,
    /// Byte span of `#n = ... ;` in the source (empty for added instances).
    pub start: usize,
    pub end: usize,
    /// Offset of the body (keyword or `(`) relative to the instance text.
    pub body: u32,
    /// Length of the (first) entity name.
    pub name_len: u32,
    /// A complex (multi-leaf) instance `( A() B() )`.
    pub complex: bool,
}

/// Ids to instance positions: a dense table when ids are compact, a hash map otherwise.
#[derive(Debug, Clone)]
pub(crate) enum Index {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl Index {
    pub fn get(&self, id: u64) -> Option<usize> {
        match self {
            Index::Dense(v) => match v.get(usize::try_from(id).ok()?) {
                Some(&k) if k != u32::MAX => Some(k as usize),
                _ => None,
            },
            Index::Sparse(m) => m.get(&id).map(|&k| k as usize),
        }
    }

    pub fn insert(&mut self, id: u64, k: usize) {
        match self {
            Index::Dense(v) => {
                let i = id as usize;
                if i >= v.len() {
                    v.resize(i + 1, u32::MAX);
                }
                v[i] = k as u32;
            }
            Index::Sparse(m) => {
                m.insert(id, k as u32);
            }
        }
    }
}

/// An ISO 10303-21 exchange structure, kept byte for byte.
///
/// [`Document::parse`] checks the whole grammar, indexes every instance and checks every
/// `#` reference, but converts parameters only when a typed view asks for them. Every
/// instance keeps its exact original text: [`Document::write`] of an unchanged document
/// returns the input, and after edits only the edited instances are rewritten.
///
/// # Examples
///
/// ```
/// use cadmorph_step::{Document, EntityId};
/// let text = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nENDSEC;\nDATA;\n\
///             #1 = CARTESIAN_POINT('p', (1., 2., 3.)); /* kept */\nENDSEC;\nEND-ISO-10303-21;\n";
/// let mut doc = Document::parse(text.as_bytes()).unwrap();
/// assert_eq!(doc.write(), text.as_bytes());
/// assert_eq!(doc.point(EntityId(1)).unwrap().y, 2.0);
/// doc.set_point(EntityId(1), [4.0, 5.0, 6.0].into()).unwrap();
/// let out = String::from_utf8(doc.write()).unwrap();
/// assert!(out.contains("#1 = CARTESIAN_POINT('p', (4.,5.,6.)); /* kept */"));
/// ```
#[derive(Debug, Clone)]
pub struct Document {
    pub(crate) source: Vec<u8>,
    /// Spans of the header entities `NAME(...)` (without the `;`).
    pub(crate) header: Vec<(usize, usize)>,
    pub(crate) instances: Vec<Instance>,
    pub(crate) index: Index,
    /// Rewritten or added instance texts, by instance position.
    pub(crate) texts: BTreeMap<usize, String>,
    /// Number of instances read from the file (the rest were added).
    pub(crate) n_original: usize,
    /// Where added instances go: before the `ENDSEC` of the last data section.
    pub(crate) insert_at: usize,
    /// The highest id in use.
    pub(crate) max_id: u64,
    /// The model units, once computed (cleared by edits).
    /// With the id of the context instance they were read from (none for the defaults).
    pub(crate) units_cache: std::sync::OnceLock<(crate::views::Units, Option<u64>)>,
    /// Surfaces [`faces`](Document::faces) read, for the conversion that follows (cleared
    /// by edits).
    pub(crate) surface_cache: crate::views::SurfaceCache,
    /// Added instances written even though nothing references them: roots of the
    /// product structure an edit added (see `unshare.rs`).
    pub(crate) pinned: std::collections::BTreeSet<usize>,
    /// Added instances that are unedited copies of the file's (see `unshare.rs`).
    pub(crate) pristine: std::collections::BTreeSet<usize>,
}

/// A read-only handle on one instance.
#[derive(Debug, Clone, Copy)]
pub struct InstanceRef<'a> {
    doc: &'a Document,
    k: usize,
}

impl<'a> InstanceRef<'a> {
    /// The instance id.
    pub fn id(&self) -> EntityId {
        EntityId(self.doc.instances[self.k].id)
    }
    /// The entity name of a simple instance, or the first leaf's name of a complex one.
    pub fn name(&self) -> &'a str {
        self.doc.name_of(self.k)
    }
    /// Whether this is a complex (multi-leaf) instance.
    pub fn is_complex(&self) -> bool {
        self.doc.instances[self.k].complex
    }
    /// The instance's current text `#n = ...;` (its original bytes unless edited).
    pub fn text(&self) -> &'a [u8] {
        self.doc.text(self.k)
    }
    /// Whether the instance was rewritten or added since parsing.
    pub fn is_edited(&self) -> bool {
        self.doc.texts.contains_key(&self.k)
    }
    /// Its parameters, parsed.
    ///
    /// # Errors
    ///
    /// Never for text that came through [`Document::parse`]; kept fallible because the
    /// conversion of integers may overflow ([`Error::Limit`]).
    pub fn body(&self) -> Result<Body<'a>> {
        self.doc.body_at(self.k)
    }
    /// The position of the instance in the file (line 0 for added instances).
    pub fn position(&self) -> Position {
        self.doc.position_of(self.k, 0)
    }
}

impl Document {
    /// Number of instances in the data section(s), added ones included.
    pub fn len(&self) -> usize {
        self.instances.len()
    }

    /// Whether the data section is empty.
    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// The highest instance id in use.
    pub fn max_id(&self) -> EntityId {
        EntityId(self.max_id)
    }

    /// The instance `#id`.
    pub fn get(&self, id: EntityId) -> Option<InstanceRef<'_>> {
        self.index.get(id.0).map(|k| InstanceRef { doc: self, k })
    }

    /// Every instance in file order (added ones last).
    pub fn instances(&self) -> impl Iterator<Item = InstanceRef<'_>> + '_ {
        (0..self.instances.len()).map(move |k| InstanceRef { doc: self, k })
    }

    /// Instance counts by entity name. A complex instance counts once, under its leaf
    /// names joined in parentheses, e.g. `(BOUNDED_SURFACE B_SPLINE_SURFACE ...)`.
    ///
    /// # Examples
    ///
    /// ```
    /// let doc = cadmorph_step::Document::parse(&std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/nurbs_cylinder.stp")).unwrap()).unwrap();
    /// assert_eq!(doc.entity_counts()["CARTESIAN_POINT"], 25);
    /// ```
    pub fn entity_counts(&self) -> BTreeMap<String, usize> {
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        for k in 0..self.instances.len() {
            if self.instances[k].complex {
                let key = match self.body_at(k) {
                    Ok(Body::Complex(leaves)) => {
                        format!("({})", leaves.iter().map(|r| r.name).collect::<Vec<_>>().join(" "))
                    }
                    _ => self.name_of(k).to_owned(),
                };
                *counts.entry(key).or_default() += 1;
            } else if let Some(c) = counts.get_mut(self.name_of(k)) {
                *c += 1;
            } else {
                counts.insert(self.name_of(k).to_owned(), 1);
            }
        }
        counts
    }

    /// The header entities (`FILE_DESCRIPTION`, `FILE_NAME`, `FILE_SCHEMA`, ...), parsed.
    pub fn header(&self) -> Vec<crate::read::param::Record<'_>> {
        self.header
            .iter()
            .filter_map(|&(s, e)| match parse_body(&self.source[s..e], 0) {
                Ok(Body::Simple(r)) => Some(r),
                _ => None,
            })
            .collect()
    }

    /// The schema names of `FILE_SCHEMA`, e.g. `AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }`.
    pub fn schemas(&self) -> Vec<String> {
        use crate::read::param::Value;
        self.header()
            .iter()
            .filter(|r| r.name == "FILE_SCHEMA")
            .flat_map(|r| match r.params.first().map(|p| &p.value) {
                Some(Value::List(items)) => items
                    .iter()
                    .filter_map(|p| match &p.value {
                        Value::String(s) => Some(crate::read::param::decode_string(s)),
                        _ => None,
                    })
                    .collect(),
                _ => vec![],
            })
            .collect()
    }

    /// Forgets what the views read: called by every edit of the instances.
    pub(crate) fn views_changed(&mut self) {
        self.units_cache = std::sync::OnceLock::new();
        self.surface_cache = crate::views::SurfaceCache::default();
    }

    pub(crate) fn text(&self, k: usize) -> &[u8] {
        match self.texts.get(&k) {
            Some(t) => t.as_bytes(),
            None => &self.source[self.instances[k].start..self.instances[k].end],
        }
    }

    pub(crate) fn name_of(&self, k: usize) -> &str {
        std::str::from_utf8(self.name_bytes(k)).unwrap_or("")
    }

    /// [`name_of`](Self::name_of) as bytes (no UTF-8 check: for comparisons in loops
    /// over every instance).
    pub(crate) fn name_bytes(&self, k: usize) -> &[u8] {
        let inst = &self.instances[k];
        let text = self.text(k);
        let mut s = inst.body as usize;
        if inst.complex {
            // Skip `(` and blanks/comments to the first keyword.
            let mut lx = crate::read::lexer::Lexer::new(text, s + 1);
            if let Ok(t) = lx.next_token() {
                s = t.start;
            }
        }
        &text[s..s + inst.name_len as usize]
    }

    pub(crate) fn body_at(&self, k: usize) -> Result<Body<'_>> {
        self.body_at_in(k, &mut Vec::new())
    }

    /// [`body_at`](Self::body_at) gathering the parameter lists on the caller's `stack`
    /// (see [`parse_body_in`]).
    pub(crate) fn body_at_in<'d>(&'d self, k: usize, stack: &mut Vec<Param<'d>>) -> Result<Body<'d>> {
        let inst = &self.instances[k];
        let text = self.text(k);
        parse_body_in(&text[inst.body as usize..], inst.body as usize, stack)
            .map_err(|rel| Error::Limit { at: self.position_of(k, rel), what: "integer does not fit 64 bits" })
    }

    /// The position of byte `rel` of instance `k`'s text. Edited and added instances
    /// report the start of the original instance (line 0 if added).
    pub(crate) fn position_of(&self, k: usize, rel: usize) -> Position {
        let inst = &self.instances[k];
        let id = Some(EntityId(inst.id));
        if k >= self.n_original {
            return Position { line: 0, column: 0, id };
        }
        let off = if self.texts.contains_key(&k) { inst.start } else { inst.start + rel.min(inst.end - inst.start) };
        let mut p = position(&self.source, off);
        p.id = id;
        p
    }

    /// Position of an instance by id (the instance start), for errors about references.
    pub(crate) fn position_of_id(&self, id: EntityId) -> Position {
        match self.index.get(id.0) {
            Some(k) => self.position_of(k, 0),
            None => Position { line: 0, column: 0, id: Some(id) },
        }
    }
}

/// Line and column (1-based) of byte `offset`.
pub(crate) fn position(src: &[u8], offset: usize) -> Position {
    let offset = offset.min(src.len());
    let before = &src[..offset];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    Position { line, column: offset - line_start + 1, id: None }
}
