//! Reading: the exchange-structure grammar, checked in one pass over the bytes.

pub(crate) mod lexer;
pub(crate) mod param;

use std::collections::{BTreeMap, HashMap};

use lexer::{reference_id, Kind, LexError, Lexer, Token};

use crate::document::{position, Document, Index, Instance};
use crate::error::{Error, Position, Result};
use crate::EntityId;

const MAGIC: &[u8] = b"ISO-10303-21";
const END_MAGIC: &[u8] = b"END-ISO-10303-21";

struct Reader<'a> {
    lx: Lexer<'a>,
    /// The instance being read, for error positions.
    current: Option<EntityId>,
}

impl<'a> Reader<'a> {
    fn at(&self, offset: usize) -> Position {
        let mut p = position(self.lx.src, offset);
        p.id = self.current;
        p
    }

    fn lex_error(&self, e: LexError) -> Error {
        match e {
            LexError::UnterminatedString(o) => Error::UnterminatedString { at: self.at(o) },
            LexError::UnterminatedComment(o) => Error::UnterminatedComment { at: self.at(o) },
            LexError::Unexpected(o) => {
                Error::Syntax { at: self.at(o), expected: "a token", found: excerpt(self.lx.src, o) }
            }
        }
    }

    fn next(&mut self) -> Result<Token> {
        self.lx.next_token().map_err(|e| self.lex_error(e))
    }

    fn unexpected(&self, tok: Token, expected: &'static str) -> Error {
        if tok.kind == Kind::End {
            Error::Truncated { at: self.at(tok.start), expected }
        } else {
            Error::Syntax { at: self.at(tok.start), expected, found: excerpt(self.lx.src, tok.start) }
        }
    }

    fn expect(&mut self, kind: Kind, expected: &'static str) -> Result<Token> {
        let t = self.next()?;
        if t.kind == kind {
            Ok(t)
        } else {
            Err(self.unexpected(t, expected))
        }
    }

    /// Checks a parameter list after its `(` up to and including the matching `)`,
    /// collecting references.
    fn params(&mut self, refs: &mut Vec<(u64, usize)>) -> Result<()> {
        let mut depth = 1usize;
        let mut want_param = true; // a parameter or `)` may follow
        let mut after_comma = false;
        loop {
            let t = self.next()?;
            if want_param {
                match t.kind {
                    Kind::Close if !after_comma => {
                        depth -= 1;
                        if depth == 0 {
                            return Ok(());
                        }
                        want_param = false;
                    }
                    Kind::Open => {
                        depth += 1;
                        if depth > param::MAX_DEPTH {
                            return Err(Error::Limit { at: self.at(t.start), what: "lists nested too deeply" });
                        }
                        after_comma = false;
                    }
                    Kind::Keyword => {
                        self.expect(Kind::Open, "'(' after a typed parameter's name")?;
                        depth += 1;
                        if depth > param::MAX_DEPTH {
                            return Err(Error::Limit { at: self.at(t.start), what: "lists nested too deeply" });
                        }
                        after_comma = false;
                    }
                    Kind::Reference => {
                        let id = reference_id(&self.lx.src[t.start..t.end]).ok_or_else(|| Error::Limit {
                            at: self.at(t.start),
                            what: "instance id does not fit 64 bits",
                        })?;
                        refs.push((id, t.start));
                        want_param = false;
                    }
                    Kind::Integer
                    | Kind::Real
                    | Kind::String
                    | Kind::Binary
                    | Kind::Enumeration
                    | Kind::Unset
                    | Kind::Derived => want_param = false,
                    _ => return Err(self.unexpected(t, "a parameter")),
                }
            } else {
                match t.kind {
                    Kind::Comma => {
                        want_param = true;
                        after_comma = true;
                    }
                    Kind::Close => {
                        depth -= 1;
                        if depth == 0 {
                            return Ok(());
                        }
                    }
                    _ => return Err(self.unexpected(t, "',' or ')'")),
                }
            }
        }
    }

    /// `NAME(params)` after the name.
    fn record(&mut self, refs: &mut Vec<(u64, usize)>) -> Result<()> {
        self.expect(Kind::Open, "'(' after an entity name")?;
        self.params(refs)
    }

    fn section_keyword(&mut self) -> Result<(Token, &'a [u8])> {
        let t = self.next()?;
        if t.kind != Kind::Keyword {
            return Err(self.unexpected(t, "a section keyword"));
        }
        Ok((t, &self.lx.src[t.start..t.end]))
    }
}

fn excerpt(src: &[u8], offset: usize) -> String {
    if offset >= src.len() {
        return "end of file".into();
    }
    let end = (offset + 24).min(src.len());
    let cut = src[offset..end].iter().position(|&b| b == b'\n').map_or(end, |i| offset + i);
    String::from_utf8_lossy(&src[offset..cut]).into_owned()
}

impl Document {
    /// Reads an ISO 10303-21 exchange structure.
    ///
    /// Checks the whole grammar (header, any number of data sections, simple and complex
    /// instances, every parameter form, comments anywhere), that ids are unique and that
    /// every `#n` reference names an instance. Parameters are converted later, by the
    /// typed views. Memory is linear in the input: nothing is sized from numbers read in
    /// the file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`], [`Error::UnterminatedString`], [`Error::UnterminatedComment`],
    /// [`Error::Truncated`], [`Error::DuplicateId`], [`Error::DanglingReference`],
    /// [`Error::Limit`], each naming line, column and instance.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_step::{Document, Error};
    /// let err = Document::parse(b"ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = POINT('abc").unwrap_err();
    /// assert_eq!(err.to_string(), "line 5, column 12, instance #1: unterminated string");
    /// ```
    pub fn parse(bytes: &[u8]) -> Result<Document> {
        let mut r = Reader { lx: Lexer::new(bytes, 0), current: None };
        if !r.lx.eat_literal(MAGIC).map_err(|e| r.lex_error(e))? {
            return Err(Error::Syntax {
                at: r.at(r.lx.pos),
                expected: "ISO-10303-21;",
                found: excerpt(bytes, r.lx.pos),
            });
        }
        r.expect(Kind::Semicolon, "';' after ISO-10303-21")?;

        let mut header = Vec::new();
        let mut instances: Vec<Instance> = Vec::new();
        let mut refs: Vec<(u64, usize)> = Vec::new();
        let mut ref_owner: Vec<u32> = Vec::new(); // instance position of each reference
        let mut insert_at = None;
        let mut max_id = 0u64;

        loop {
            if r.lx.eat_literal(END_MAGIC).map_err(|e| r.lex_error(e))? {
                r.expect(Kind::Semicolon, "';' after END-ISO-10303-21")?;
                break;
            }
            let (t, kw) = r.section_keyword().map_err(|e| match e {
                Error::Truncated { at, .. } => Error::Truncated { at, expected: "END-ISO-10303-21;" },
                e => e,
            })?;
            match kw {
                b"HEADER" => {
                    r.expect(Kind::Semicolon, "';' after HEADER")?;
                    loop {
                        let t = r.next()?;
                        match t.kind {
                            Kind::Keyword if &bytes[t.start..t.end] == b"ENDSEC" => {
                                r.expect(Kind::Semicolon, "';' after ENDSEC")?;
                                break;
                            }
                            Kind::Keyword => {
                                let mut sink = Vec::new();
                                r.record(&mut sink)?;
                                header.push((t.start, r.lx.pos));
                                r.expect(Kind::Semicolon, "';' after a header entity")?;
                            }
                            _ => return Err(r.unexpected(t, "a header entity or ENDSEC")),
                        }
                    }
                }
                b"DATA" => {
                    let mut t = r.next()?;
                    if t.kind == Kind::Open {
                        let mut sink = Vec::new();
                        r.params(&mut sink)?;
                        t = r.next()?;
                    }
                    if t.kind != Kind::Semicolon {
                        return Err(r.unexpected(t, "';' after DATA"));
                    }
                    loop {
                        let t = r.next()?;
                        match t.kind {
                            Kind::Keyword if &bytes[t.start..t.end] == b"ENDSEC" => {
                                insert_at = Some(t.start);
                                r.expect(Kind::Semicolon, "';' after ENDSEC")?;
                                break;
                            }
                            Kind::Reference if bytes[t.start] == b'#' => {
                                let id = reference_id(&bytes[t.start..t.end]).ok_or_else(|| Error::Limit {
                                    at: r.at(t.start),
                                    what: "instance id does not fit 64 bits",
                                })?;
                                r.current = Some(EntityId(id));
                                r.expect(Kind::Equals, "'=' after the instance id")?;
                                let n_refs = refs.len();
                                let body = r.next()?;
                                let (complex, name_len) = match body.kind {
                                    Kind::Keyword => {
                                        r.record(&mut refs)?;
                                        (false, body.end - body.start)
                                    }
                                    Kind::Open => {
                                        let mut first = None;
                                        loop {
                                            let leaf = r.next()?;
                                            match leaf.kind {
                                                Kind::Keyword => {
                                                    first.get_or_insert(leaf.end - leaf.start);
                                                    r.record(&mut refs)?;
                                                }
                                                Kind::Close if first.is_some() => break,
                                                _ => {
                                                    return Err(
                                                        r.unexpected(leaf, "a leaf record of a complex instance")
                                                    )
                                                }
                                            }
                                        }
                                        (true, first.unwrap_or(0))
                                    }
                                    _ => return Err(r.unexpected(body, "an entity name or '('")),
                                };
                                let semi = r.expect(Kind::Semicolon, "';' after an instance")?;
                                ref_owner.resize(refs.len(), instances.len() as u32);
                                let _ = n_refs;
                                max_id = max_id.max(id);
                                instances.push(Instance {
                                    id,
                                    start: t.start,
                                    end: semi.end,
                                    body: (body.start - t.start) as u32,
                                    name_len: name_len as u32,
                                    complex,
                                });
                                r.current = None;
                            }
                            _ => return Err(r.unexpected(t, "an instance '#n = ...;' or ENDSEC")),
                        }
                    }
                }
                _ => {
                    // Other sections (ANCHOR, REFERENCE, SIGNATURE ...): kept verbatim, checked
                    // only for well-formed tokens up to their ENDSEC.
                    loop {
                        let u = r.next()?;
                        if u.kind == Kind::End {
                            return Err(r.unexpected(u, "ENDSEC"));
                        }
                        if u.kind == Kind::Keyword && &bytes[u.start..u.end] == b"ENDSEC" {
                            r.expect(Kind::Semicolon, "';' after ENDSEC")?;
                            break;
                        }
                    }
                    let _ = t;
                }
            }
        }

        // Index. A dense table when ids are compact (its size is bounded by the input
        // length), a hash map otherwise.
        let n = instances.len();
        let mut index = if max_id <= (bytes.len() as u64).min(8 * n as u64 + 1024) {
            Index::Dense(vec![u32::MAX; max_id as usize + 1])
        } else {
            Index::Sparse(HashMap::with_capacity(n))
        };
        for (k, inst) in instances.iter().enumerate() {
            if let Some(first) = index.get(inst.id) {
                let mut at = position(bytes, inst.start);
                at.id = Some(EntityId(inst.id));
                return Err(Error::DuplicateId {
                    at,
                    id: EntityId(inst.id),
                    first_line: position(bytes, instances[first].start).line,
                });
            }
            index.insert(inst.id, k);
        }
        for (i, &(target, offset)) in refs.iter().enumerate() {
            if index.get(target).is_none() {
                let mut at = position(bytes, offset);
                at.id = ref_owner.get(i).map(|&k| EntityId(instances[k as usize].id));
                return Err(Error::DanglingReference { at, target: EntityId(target) });
            }
        }
        let insert_at = insert_at.unwrap_or(r.lx.pos);
        Ok(Document {
            source: bytes.to_vec(),
            header,
            n_original: instances.len(),
            instances,
            index,
            texts: BTreeMap::new(),
            insert_at,
            max_id,
            units_cache: std::sync::OnceLock::new(),
        })
    }
}

/// Checks the text of one instance `#id = ...;` (for edits and added instances) and
/// returns its metadata (offsets relative to the text) and the ids it references.
pub(crate) fn scan_instance(text: &[u8]) -> Result<(Instance, Vec<u64>)> {
    let mut r = Reader { lx: Lexer::new(text, 0), current: None };
    let t = r.expect(Kind::Reference, "an instance id")?;
    let id = reference_id(&text[t.start..t.end])
        .ok_or_else(|| Error::Limit { at: r.at(t.start), what: "instance id does not fit 64 bits" })?;
    r.expect(Kind::Equals, "'='")?;
    let mut refs = Vec::new();
    let body = r.next()?;
    let (complex, name_len) = match body.kind {
        Kind::Keyword => {
            r.record(&mut refs)?;
            (false, body.end - body.start)
        }
        Kind::Open => {
            let mut first = None;
            loop {
                let leaf = r.next()?;
                match leaf.kind {
                    Kind::Keyword => {
                        first.get_or_insert(leaf.end - leaf.start);
                        r.record(&mut refs)?;
                    }
                    Kind::Close if first.is_some() => break,
                    _ => return Err(r.unexpected(leaf, "a leaf record")),
                }
            }
            (true, first.unwrap_or(0))
        }
        _ => return Err(r.unexpected(body, "an entity name or '('")),
    };
    let semi = r.expect(Kind::Semicolon, "';'")?;
    let end = r.next()?;
    if end.kind != Kind::End {
        return Err(r.unexpected(end, "the end of the instance text"));
    }
    Ok((
        Instance { id, start: 0, end: semi.end, body: body.start as u32, name_len: name_len as u32, complex },
        refs.into_iter().map(|(id, _)| id).collect(),
    ))
}
