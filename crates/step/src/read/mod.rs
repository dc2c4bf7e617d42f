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

    #[inline(always)]
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

    #[inline(always)]
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
            if fast_forms() {
                // The bulk of large files: parameters, commas and parentheses with no blank
                // or comment between them, read from their first byte without tokens. The
                // general steps below would read the same and stand at the same place;
                // anything else (and every error but the depth limit) is left to them.
                let (s, p) = (self.lx.src, self.lx.pos);
                let c = s.get(p).copied().unwrap_or(0);
                if want_param {
                    let value_end = match c {
                        b'#' => lexer::reference_end(s, p),
                        b'+' | b'-' | b'0'..=b'9' => lexer::number_end(s, p).map(|(e, _)| e),
                        b'$' | b'*' => Some(p + 1),
                        b'.' => lexer::enumeration_end(s, p),
                        // A string without doubled apostrophes.
                        b'\'' => s[p + 1..]
                            .iter()
                            .position(|&b| b == b'\'')
                            .map(|k| p + k + 2)
                            .filter(|&e| s.get(e) != Some(&b'\'')),
                        _ => None,
                    };
                    if let Some(e) = value_end {
                        if c == b'#' {
                            let id = reference_id(&s[p..e]).ok_or_else(|| Error::Limit {
                                at: self.at(p),
                                what: "instance id does not fit 64 bits",
                            })?;
                            refs.push((id, p));
                        }
                        self.lx.pos = e;
                        want_param = false;
                        continue;
                    }
                    if c == b'(' {
                        depth += 1;
                        if depth > param::MAX_DEPTH {
                            return Err(Error::Limit { at: self.at(p), what: "lists nested too deeply" });
                        }
                        after_comma = false;
                        self.lx.pos = p + 1;
                        continue;
                    }
                    if c == b')' && !after_comma {
                        self.lx.pos = p + 1;
                        depth -= 1;
                        if depth == 0 {
                            return Ok(());
                        }
                        want_param = false;
                        continue;
                    }
                } else if c == b',' {
                    self.lx.pos = p + 1;
                    want_param = true;
                    after_comma = true;
                    continue;
                } else if c == b')' {
                    self.lx.pos = p + 1;
                    depth -= 1;
                    if depth == 0 {
                        return Ok(());
                    }
                    continue;
                }
            }
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

/// `#n` at the start of the next line (after the `;` of the previous instance at `i`,
/// with its line break `\n` or `\r\n`): the reference token the general reading gives
/// there. `None` for anything else, left to that reading.
#[inline]
fn next_instance_id(s: &[u8], mut i: usize) -> Option<Token> {
    if s.get(i) == Some(&b'\r') {
        i += 1;
    }
    if s.get(i) == Some(&b'\n') {
        i += 1;
    }
    if s.get(i) != Some(&b'#') {
        return None;
    }
    let end = lexer::reference_end(s, i)?;
    Some(Token { kind: Kind::Reference, start: i, end })
}

/// ` = NAME(` after an instance id at `i`, with blanks only (no line break or comment)
/// around `=`, as writers lay instances out: the name's token, which the general reading
/// (`=` and a token) would give there. `None` for anything else, left to that reading.
#[inline]
fn instance_head(s: &[u8], mut i: usize) -> Option<Token> {
    while s.get(i) == Some(&b' ') {
        i += 1;
    }
    if s.get(i) != Some(&b'=') {
        return None;
    }
    i += 1;
    while s.get(i) == Some(&b' ') {
        i += 1;
    }
    let end = lexer::keyword_end(s, i)?;
    (s.get(end) == Some(&b'(')).then_some(Token { kind: Kind::Keyword, start: i, end })
}

#[cfg(test)]
thread_local! {
    /// Tests only: every parameter read through tokens, the fast forms of
    /// [`Reader::params`] and of the views' [`param::parse_body`] off (the reference
    /// they are checked against).
    static TOKENS_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether [`Reader::params`] and [`param::parse_body`] may read parameters, commas and
/// parentheses without tokens (always, but in the tests that compare it with the token
/// reading).
fn fast_forms() -> bool {
    #[cfg(test)]
    return !TOKENS_ONLY.with(std::cell::Cell::get);
    #[cfg(not(test))]
    true
}

/// What the instance loop gathered from (part of) a data section.
#[derive(Default)]
struct Gathered {
    instances: Vec<Instance>,
    /// Every reference: target id and byte offset (inside the instance that holds it:
    /// instances come in file order, so the holder is found by the offset when needed).
    refs: Vec<(u64, usize)>,
    max_id: u64,
}

impl Gathered {
    /// Appends `other`, read after `self`.
    fn append(&mut self, other: Gathered) {
        if self.instances.is_empty() && self.refs.is_empty() {
            // Nothing to keep: take `other` whole (no copy).
            let max_id = self.max_id.max(other.max_id);
            *self = other;
            self.max_id = max_id;
            return;
        }
        self.instances.extend(other.instances);
        self.refs.extend(other.refs);
        self.max_id = self.max_id.max(other.max_id);
    }
}

/// Where [`Reader::instances`] stopped.
enum DataEnd {
    /// At `ENDSEC` (consumed, not its `;`), starting at the offset.
    Endsec(usize),
    /// At the given stop offset, between instances.
    Stop,
}

/// Data sections of at least this many bytes are read in parallel (see
/// [`Reader::data_parallel`]); below it the threads cost more than they save.
const PARALLEL_BYTES: usize = 1 << 20;

/// The offsets of up to `n - 1` line starts `\n#` in `src[from..]`, evenly spread and
/// increasing: where a writer that puts each instance on its own line starts one.
fn cut_points(src: &[u8], from: usize, n: usize) -> Vec<usize> {
    let mut cuts = Vec::with_capacity(n);
    let len = src.len() - from;
    for i in 1..n {
        let target = from + len * i / n;
        let after = cuts.last().map_or(target, |&c: &usize| c.max(target));
        if let Some(k) = src[after..].windows(2).position(|w| w == b"\n#") {
            let cut = after + k + 1;
            if cuts.last() != Some(&cut) {
                cuts.push(cut);
            }
        }
    }
    cuts
}

impl Reader<'_> {
    /// An instance's body after its `=`, whose first token `body` has been read: a
    /// record `NAME(...)` or a complex instance `( A(...) B(...) )`, references collected.
    /// Returns whether it is complex and the length of its (first) entity name.
    fn body(&mut self, body: Token, refs: &mut Vec<(u64, usize)>) -> Result<(bool, usize)> {
        match body.kind {
            Kind::Keyword => {
                self.record(refs)?;
                Ok((false, body.end - body.start))
            }
            Kind::Open => {
                let mut first = None;
                loop {
                    let leaf = self.next()?;
                    match leaf.kind {
                        Kind::Keyword => {
                            first.get_or_insert(leaf.end - leaf.start);
                            self.record(refs)?;
                        }
                        Kind::Close if first.is_some() => break,
                        _ => return Err(self.unexpected(leaf, "a leaf record of a complex instance")),
                    }
                }
                Ok((true, first.unwrap_or(0)))
            }
            _ => Err(self.unexpected(body, "an entity name or '('")),
        }
    }

    /// Reads instances `#n = ...;` up to `ENDSEC`, or with `stop` up to the first token
    /// at or after `stop` (the reader then stands there, after blanks and comments).
    fn instances(&mut self, g: &mut Gathered, stop: Option<usize>) -> Result<DataEnd> {
        let bytes = self.lx.src;
        loop {
            if let Some(stop) = stop {
                self.lx.skip_space().map_err(|e| self.lex_error(e))?;
                if self.lx.pos >= stop {
                    return Ok(DataEnd::Stop);
                }
            }
            let t = match fast_forms().then(|| next_instance_id(bytes, self.lx.pos)).flatten() {
                Some(t) => {
                    self.lx.pos = t.end;
                    t
                }
                None => self.next()?,
            };
            match t.kind {
                Kind::Keyword if &bytes[t.start..t.end] == b"ENDSEC" => return Ok(DataEnd::Endsec(t.start)),
                Kind::Reference if bytes[t.start] == b'#' => {
                    let id = reference_id(&bytes[t.start..t.end]).ok_or_else(|| Error::Limit {
                        at: self.at(t.start),
                        what: "instance id does not fit 64 bits",
                    })?;
                    self.current = Some(EntityId(id));
                    let body = match fast_forms().then(|| instance_head(bytes, self.lx.pos)).flatten() {
                        Some(name) => {
                            self.lx.pos = name.end;
                            name
                        }
                        None => {
                            self.expect(Kind::Equals, "'=' after the instance id")?;
                            self.next()?
                        }
                    };
                    let (complex, name_len) = self.body(body, &mut g.refs)?;
                    let semi = match bytes.get(self.lx.pos) {
                        Some(b';') if fast_forms() => {
                            self.lx.pos += 1;
                            Token { kind: Kind::Semicolon, start: self.lx.pos - 1, end: self.lx.pos }
                        }
                        _ => self.expect(Kind::Semicolon, "';' after an instance")?,
                    };
                    g.max_id = g.max_id.max(id);
                    g.instances.push(Instance {
                        id,
                        start: t.start,
                        end: semi.end,
                        body: (body.start - t.start) as u32,
                        name_len: name_len as u32,
                        complex,
                    });
                    self.current = None;
                }
                _ => return Err(self.unexpected(t, "an instance '#n = ...;' or ENDSEC")),
            }
        }
    }

    /// [`instances`](Self::instances) up to `ENDSEC` on all of rayon's threads: the rest
    /// of the input is cut at line starts `\n#` ([`cut_points`]) and each piece read from
    /// its cut to the next on its own. A piece counts only when the piece before it
    /// stopped exactly at its cut, so that its cut is an instance start of the sequential
    /// reading (not inside a string or a comment); the first piece starts where the
    /// sequential reading stands, so each accepted piece is what the sequential reading
    /// would have read there. The piece that reaches `ENDSEC` ends the section (the pieces
    /// after it are dropped). Any mismatch or error reads the section again on this
    /// thread, so results and errors are the sequential reading's. Returns the offset of
    /// `ENDSEC`.
    fn data_parallel(&mut self, g: &mut Gathered) -> Result<usize> {
        use rayon::prelude::*;
        let src = self.lx.src;
        let from = self.lx.pos;
        let pieces = (rayon::current_num_threads() * 4).min((src.len() - from) / (64 << 10)).max(1);
        let cuts = cut_points(src, from, pieces);
        let sequential = |r: &mut Self, g: &mut Gathered| match r.instances(g, None)? {
            DataEnd::Endsec(at) => Ok(at),
            DataEnd::Stop => unreachable!("no stop was given"),
        };
        if cuts.is_empty() {
            return sequential(self, g);
        }
        let starts: Vec<usize> = std::iter::once(from).chain(cuts.iter().copied()).collect();
        let read: Vec<(Result<(Gathered, DataEnd)>, usize)> = starts
            .par_iter()
            .enumerate()
            .map(|(i, &start)| {
                let mut r = Reader { lx: Lexer::new(src, start), current: None };
                let mut piece = Gathered::default();
                let end = r.instances(&mut piece, cuts.get(i).copied());
                (end.map(|e| (piece, e)), r.lx.pos)
            })
            .collect();
        // Room for every piece read, so that appending them copies each once.
        let (n_inst, n_refs) = read
            .iter()
            .filter_map(|(r, _)| r.as_ref().ok())
            .fold((0, 0), |(i, r), (p, _)| (i + p.instances.len(), r + p.refs.len()));
        let mut all = Gathered::default();
        for (i, (result, pos)) in read.into_iter().enumerate() {
            if i == 1 {
                all.instances.reserve(n_inst.saturating_sub(all.instances.len()));
                all.refs.reserve(n_refs.saturating_sub(all.refs.len()));
            }
            match result {
                Ok((piece, DataEnd::Stop)) if Some(pos) == cuts.get(i).copied() => all.append(piece),
                Ok((piece, DataEnd::Endsec(at))) => {
                    all.append(piece);
                    g.append(all);
                    self.lx.pos = pos;
                    return Ok(at);
                }
                _ => break,
            }
        }
        self.lx.pos = from;
        sequential(self, g)
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
        Self::parse_with(bytes, PARALLEL_BYTES)
    }

    /// [`parse`](Self::parse), reading data sections of at least `parallel_bytes` bytes
    /// in parallel.
    fn parse_with(bytes: &[u8], parallel_bytes: usize) -> Result<Document> {
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
        let mut data = Gathered::default();
        let mut insert_at = None;

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
                    let endsec = if bytes.len() - r.lx.pos >= parallel_bytes {
                        r.data_parallel(&mut data)?
                    } else {
                        // Room for the instances and references of a typical file (about
                        // 40 bytes per instance and 20 per reference), so that the vectors
                        // do not grow and copy themselves a dozen times.
                        let rest = bytes.len() - r.lx.pos;
                        data.instances.reserve(rest / 40);
                        data.refs.reserve(rest / 20);
                        match r.instances(&mut data, None)? {
                            DataEnd::Endsec(at) => at,
                            DataEnd::Stop => unreachable!("no stop was given"),
                        }
                    };
                    insert_at = Some(endsec);
                    r.expect(Kind::Semicolon, "';' after ENDSEC")?;
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

        let Gathered { instances, refs, max_id } = data;
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
        for &(target, offset) in &refs {
            if index.get(target).is_none() {
                let mut at = position(bytes, offset);
                let holder = instances.partition_point(|inst| inst.start <= offset).checked_sub(1);
                at.id = holder.map(|k| EntityId(instances[k].id));
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
            surface_cache: Default::default(),
            pinned: std::collections::BTreeSet::new(),
            pristine: std::collections::BTreeSet::new(),
        })
    }
}

/// Checks the text of one instance `#id = ...;` (for edits and added instances) and
/// returns its metadata (offsets relative to the text) and the ids it references.
pub(crate) fn scan_instance(text: &[u8]) -> Result<(Instance, Vec<u64>)> {
    let (inst, refs) = scan_instance_at(text)?;
    Ok((inst, refs.into_iter().map(|(id, _)| id).collect()))
}

/// [`scan_instance`] with each reference's byte offset (of its `#`) in `text`.
pub(crate) fn scan_instance_at(text: &[u8]) -> Result<(Instance, Vec<(u64, usize)>)> {
    let mut r = Reader { lx: Lexer::new(text, 0), current: None };
    let t = r.expect(Kind::Reference, "an instance id")?;
    let id = reference_id(&text[t.start..t.end])
        .ok_or_else(|| Error::Limit { at: r.at(t.start), what: "instance id does not fit 64 bits" })?;
    r.expect(Kind::Equals, "'='")?;
    let mut refs = Vec::new();
    let body = r.next()?;
    let (complex, name_len) = r.body(body, &mut refs)?;
    let semi = r.expect(Kind::Semicolon, "';'")?;
    let end = r.next()?;
    if end.kind != Kind::End {
        return Err(r.unexpected(end, "the end of the instance text"));
    }
    Ok((Instance { id, start: 0, end: semi.end, body: body.start as u32, name_len: name_len as u32, complex }, refs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Instances in the data sections of `doc`: id, span, body, name, complex.
    fn listing(doc: &Document) -> Vec<(u64, usize, usize, u32, u32, bool)> {
        doc.instances.iter().map(|i| (i.id, i.start, i.end, i.body, i.name_len, i.complex)).collect()
    }

    /// A data section of `n` instances in which every `k`-th holds a string or is
    /// followed by a comment that contains a line start `#` (where the parallel reading
    /// cuts): read from there, the comment holds a valid instance and ends in another
    /// comment, so a piece started there reads on without error. Complex instances and
    /// references backwards and forwards.
    fn data(n: usize, k: usize) -> String {
        let mut d = String::new();
        for i in 1..=n {
            let next = if i < n { i + 1 } else { 1 };
            match i % k {
                0 => d.push_str(&format!("#{i} = NAME('line\n#{} = FAKE(''x'');\n',#{next});\n", i + 7)),
                1 => d.push_str(&format!(
                    "#{i} = ( A(1.5,#{next}) B('b') );\n/* a comment\n#{} = FAKE();\n/* */\n",
                    i + 3
                )),
                _ => d.push_str(&format!("#{i} = CARTESIAN_POINT('',({i}.,-2.5E-1,#{next}));\n")),
            }
        }
        d
    }

    fn file(sections: &[String]) -> String {
        let mut f = String::from("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nENDSEC;\n");
        for s in sections {
            f.push_str("DATA;\n");
            f.push_str(s);
            f.push_str("ENDSEC;\n");
        }
        f.push_str("END-ISO-10303-21;\n");
        f
    }

    /// A parameter list's text from `seed` (a small linear congruential generator):
    /// references, numbers, strings, unset and derived values, enumerations, nested and
    /// typed lists, with no blank, a blank or a comment between tokens.
    fn parameter_text(seed: &mut u64, depth: usize, out: &mut String) {
        fn next(seed: &mut u64, n: u64) -> u64 {
            *seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (*seed >> 33) % n
        }
        const VALUES: [&str; 14] =
            ["#12", "#7", "#0", "1.5", "-2", "+3.", "1.E5", "2.5E-07", "'s'", "'it''s'", "$", "*", ".T.", "\"0F\""];
        const GAPS: [&str; 4] = ["", "", " ", "/* c */"];
        let items = next(seed, 5);
        for k in 0..items {
            if k > 0 {
                out.push_str(GAPS[next(seed, 4) as usize]);
                out.push(',');
                out.push_str(GAPS[next(seed, 4) as usize]);
            }
            match next(seed, 8) {
                0 if depth < 2 => {
                    out.push('(');
                    parameter_text(seed, depth + 1, out);
                    out.push(')');
                }
                1 if depth < 2 => {
                    out.push_str("B(");
                    parameter_text(seed, depth + 1, out);
                    out.push(')');
                }
                _ => out.push_str(VALUES[next(seed, VALUES.len() as u64) as usize]),
            }
        }
    }

    /// [`parameter_text`] of `seed` with `stray` (if any) put at its index.
    fn with_stray(seed: u64, stray: Option<(proptest::sample::Index, &str)>) -> String {
        let mut body = String::new();
        parameter_text(&mut seed.clone(), 0, &mut body);
        if let Some((at, piece)) = stray {
            let at = at.index(body.len() + 1);
            if body.is_char_boundary(at) {
                body.insert_str(at, piece);
            }
        }
        body
    }

    /// What `read` gives with the fast forms, and with tokens only.
    fn both_ways(read: impl Fn() -> String) -> (String, String) {
        let fast = read();
        TOKENS_ONLY.with(|c| c.set(true));
        let tokens = read();
        TOKENS_ONLY.with(|c| c.set(false));
        (fast, tokens)
    }

    proptest::proptest! {
        /// Parameters, commas and parentheses read without tokens (where nothing stands
        /// between them) give what the token reading gives: the same references at the same offsets,
        /// the same instance, or the same error at the same place. Well-formed lists,
        /// and the same with a stray piece put somewhere.
        #[test]
        fn fast_parameter_forms_read_as_tokens(
            seed in proptest::prelude::any::<u64>(),
            stray in proptest::option::of((proptest::prelude::any::<proptest::sample::Index>(), proptest::sample::select(vec![
                "#99999999999999999999999", "#", "1.E", "12AB", "-", ",", ")", "(", ",)", "#3#4", "1..2",
            ]))),
        ) {
            let text = format!("#1=A({});", with_stray(seed, stray));
            let (fast, tokens) = both_ways(|| format!("{:?}", scan_instance_at(text.as_bytes())));
            proptest::prop_assert_eq!(fast, tokens, "{}", text);
        }

        /// The views' parameter reading ([`param::parse_body`]) reads references,
        /// numbers, commas and parentheses without tokens where nothing stands between
        /// them, and gives what the token reading gives: the same values at the same
        /// offsets, or the same error offset. Well-formed lists, and the same with a
        /// stray piece put somewhere.
        #[test]
        fn fast_parameter_forms_parse_as_tokens(
            seed in proptest::prelude::any::<u64>(),
            stray in proptest::option::of((proptest::prelude::any::<proptest::sample::Index>(), proptest::sample::select(vec![
                "#99999999999999999999999", "#", "1.E", "12AB", "-", ",", ")", "(", ",)", "#3#4", "1..2", "()", "( )",
                "99999999999999999999", "-0", "@5", ".", ".T", "..", ".A.B.", ".1.",
            ]))),
        ) {
            let text = format!("A({})", with_stray(seed, stray));
            let (fast, tokens) = both_ways(|| format!("{:?}", param::parse_body(text.as_bytes(), 7)));
            proptest::prop_assert_eq!(fast, tokens, "{}", text);
        }

        /// Instance heads `#n = NAME(`, the `;` after an instance and the line break before
        /// the next read from their bytes give what the token reading gives: the same
        /// instances (offsets, names, kinds), or the same error at the same place, for
        /// the layouts writers use and for broken ones.
        #[test]
        fn fast_instance_heads_read_as_tokens(
            heads in proptest::collection::vec(proptest::sample::select(vec![
                "=A('x');", " = A('x');", "  =  A('x');", "\t= A('x');", " =\nA('x');", " = /* c */A('x');",
                " = (A('x') B());", "=(A()B());", " = !U('x');", " = A_2 ('x');", " = a_b('x');", " = A;",
                " A('x');", " = 5('x');", " == A('x');", " = A(#1);", " = A(.T.,#2,$);", "= ('x');", "=",
            ]), 1..6),
        ) {
            let data: String = heads
                .iter()
                .enumerate()
                .map(|(i, h)| format!("#{}{}{}", i + 1, h, ["\n", "\r\n", "", " ", "\n\n", "/* c */\n"][i % 6]))
                .collect();
            let text = file(&[data]);
            let (fast, tokens) = both_ways(|| format!("{:?}", Document::parse(text.as_bytes()).map(|d| listing(&d))));
            proptest::prop_assert_eq!(fast, tokens, "{}", text);
        }
    }

    /// Read in pieces on several threads (cut at line starts, some inside strings and
    /// comments, with the threshold lowered so that small texts are cut into many), the
    /// document is the one-thread reading's, and so is every error.
    #[test]
    fn parallel_reading_is_the_sequential_reading() {
        for (n, k) in [(20000, 7), (20000, 1), (5000, 2), (20, 3)] {
            let sections = [data(n, k)];
            let text = file(&sections);
            let (one, many) =
                (Document::parse_with(text.as_bytes(), usize::MAX), Document::parse_with(text.as_bytes(), 1));
            let (one, many) = (one.unwrap(), many.unwrap());
            assert_eq!(listing(&one), listing(&many), "{n} instances, every {k}th odd");
            assert_eq!(one.insert_at, many.insert_at);
            assert_eq!(one.max_id, many.max_id);
            assert_eq!(many.write(), text.as_bytes());
        }
        // Two data sections.
        let second: String = data(2000, 5).replace('#', "#10000");
        let text = file(&[data(3000, 4), second]);
        let (one, many) = (Document::parse_with(text.as_bytes(), usize::MAX), Document::parse_with(text.as_bytes(), 1));
        let (one, many) = (one.unwrap(), many.unwrap());
        assert_eq!(listing(&one), listing(&many));
        assert_eq!(one.insert_at, many.insert_at);
        // Errors anywhere: a bad token, a dangling reference, a duplicate id, a missing ';', a
        // comment left open.
        let good = data(3000, 6);
        for (what, bad) in [
            ("bad token", good.replacen("#2000 = CARTESIAN_POINT('',(", "#2000 = CARTESIAN_POINT('',(?", 1)),
            ("dangling", good.replacen(",#1503));", ",#99999));", 1)),
            ("duplicate", good.replacen("#2500 = CARTESIAN", "#2499 = CARTESIAN", 1)),
            ("missing ';'", good.replacen("(2800.,-2.5E-1,#2801));", "(2800.,-2.5E-1,#2801))", 1)),
            ("comment left open", good.replacen("#2900 = ", "/* #2900 = ", 1).replace("*/", "")),
        ] {
            assert!(bad != good, "{what}: the text did not change");
            let text = file(&[bad]);
            let err = |parallel_bytes| match Document::parse_with(text.as_bytes(), parallel_bytes) {
                Ok(_) => panic!("{what}: read without error"),
                Err(e) => e.to_string(),
            };
            let (one, many) = (err(usize::MAX), err(1));
            assert_eq!(one, many, "{what}");
        }
    }

    #[test]
    fn cut_points_are_line_starts_in_order() {
        let text = b"DATA;\n#1=A();\n#2=B();\n#3=C();\n#4=D();\n";
        let cuts = cut_points(text, 6, 4);
        assert!(!cuts.is_empty());
        assert!(cuts.windows(2).all(|w| w[0] < w[1]));
        assert!(cuts.iter().all(|&c| text[c] == b'#' && text[c - 1] == b'\n' && c > 6));
        assert!(cut_points(b"#1=A();#2=B();", 0, 4).is_empty());
    }
}
