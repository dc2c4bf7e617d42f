//! The OpenFOAM file container (OpenFOAM User Guide §4.2 "Basic input/output file
//! format"): an optional banner comment, the `FoamFile { version; format; class; arch;
//! location; object; }` header dictionary, then the data. Lists are `N ( … )`; in
//! `format binary` files the parentheses enclose `N` raw little-endian values (labels of
//! the width `arch` gives, 32 bits by default, and 64-bit scalars).

use crate::{Error, Result};

/// A token of an OpenFOAM text stream, with its byte range.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Tok<'a> {
    /// `(`, `)`, `{`, `}`, `;`, `[`, `]`.
    Punct(u8),
    /// A word, number or quoted string (quotes removed).
    Word(&'a str),
}

/// A cursor over the bytes of an OpenFOAM file.
pub(crate) struct Lexer<'a> {
    pub bytes: &'a [u8],
    pub pos: usize,
}

/// The 1-based line of byte `offset`.
pub(crate) fn line_of(bytes: &[u8], offset: usize) -> usize {
    1 + bytes[..offset.min(bytes.len())].iter().filter(|&&b| b == b'\n').count()
}

impl<'a> Lexer<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Lexer { bytes, pos: 0 }
    }

    /// A syntax error at the current position.
    pub fn error(&self, expected: &'static str) -> Error {
        let end = (self.pos + 40).min(self.bytes.len());
        let found = String::from_utf8_lossy(&self.bytes[self.pos.min(end)..end]).into_owned();
        let found = if found.is_empty() { "end of file".to_string() } else { found };
        Error::syntax(line_of(self.bytes, self.pos), expected, &found)
    }

    /// Skip white space and `//`, `/* */` comments.
    pub fn skip_ws(&mut self) {
        let b = self.bytes;
        loop {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            if self.pos + 1 < b.len() && b[self.pos] == b'/' && b[self.pos + 1] == b'/' {
                while self.pos < b.len() && b[self.pos] != b'\n' {
                    self.pos += 1;
                }
            } else if self.pos + 1 < b.len() && b[self.pos] == b'/' && b[self.pos + 1] == b'*' {
                self.pos += 2;
                while self.pos + 1 < b.len() && !(b[self.pos] == b'*' && b[self.pos + 1] == b'/') {
                    self.pos += 1;
                }
                self.pos = (self.pos + 2).min(b.len());
            } else {
                return;
            }
        }
    }

    /// The next token, or `None` at the end.
    pub fn next(&mut self) -> Option<Tok<'a>> {
        self.skip_ws();
        let b = self.bytes;
        if self.pos >= b.len() {
            return None;
        }
        let c = b[self.pos];
        if b"(){};[]".contains(&c) {
            self.pos += 1;
            return Some(Tok::Punct(c));
        }
        if c == b'"' {
            let start = self.pos + 1;
            let mut i = start;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            let end = i.min(b.len());
            self.pos = (end + 1).min(b.len());
            return Some(Tok::Word(std::str::from_utf8(&b[start..end]).unwrap_or("")));
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() && !b"(){};[]\"".contains(&b[self.pos]) {
            if self.pos + 1 < b.len() && b[self.pos] == b'/' && (b[self.pos + 1] == b'/' || b[self.pos + 1] == b'*') {
                break;
            }
            self.pos += 1;
        }
        Some(Tok::Word(std::str::from_utf8(&b[start..self.pos]).unwrap_or("")))
    }

    /// Expect the punctuation `c`.
    pub fn expect(&mut self, c: u8, what: &'static str) -> Result<()> {
        let save = self.pos;
        match self.next() {
            Some(Tok::Punct(p)) if p == c => Ok(()),
            _ => {
                self.pos = save;
                self.skip_ws();
                Err(self.error(what))
            }
        }
    }

    /// Expect a non-negative integer (a list size), at most `max`.
    pub fn count(&mut self, max: usize) -> Result<usize> {
        self.skip_ws();
        let save = self.pos;
        match self.next() {
            Some(Tok::Word(w)) => match w.parse::<usize>() {
                Ok(n) if n <= max => Ok(n),
                _ => {
                    self.pos = save;
                    Err(self.error("a list size no larger than the file can hold"))
                }
            },
            _ => {
                self.pos = save;
                Err(self.error("a list size"))
            }
        }
    }
}

/// The `FoamFile` header.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Header {
    /// `format`: `true` for `binary`.
    pub binary: bool,
    /// `class` (`vectorField`, `faceList`, `faceCompactList`, `labelList`, `polyBoundaryMesh`…).
    pub class: String,
    /// `object`.
    pub object: String,
    /// Label width in bytes (4 unless `arch` says `label=64`).
    pub label_bytes: usize,
    /// Scalar width in bytes (8 unless `arch` says `scalar=32`).
    pub scalar_bytes: usize,
    /// The header's `note`, if any (owner files give the cell count there).
    pub note: String,
}

/// Read the header dictionary; on return the lexer stands after its closing brace.
pub(crate) fn read_header(lx: &mut Lexer<'_>) -> Result<Header> {
    let mut h = Header { label_bytes: 4, scalar_bytes: 8, ..Default::default() };
    match lx.next() {
        Some(Tok::Word("FoamFile")) => {}
        _ => {
            lx.pos = 0;
            lx.skip_ws();
            return Err(lx.error("a `FoamFile` header"));
        }
    }
    lx.expect(b'{', "`{` opening the FoamFile header")?;
    loop {
        let key = match lx.next() {
            Some(Tok::Punct(b'}')) => break,
            Some(Tok::Word(k)) => k,
            _ => return Err(lx.error("a header entry or `}`")),
        };
        let mut value = String::new();
        loop {
            match lx.next() {
                Some(Tok::Punct(b';')) => break,
                Some(Tok::Word(w)) => {
                    if !value.is_empty() {
                        value.push(' ');
                    }
                    value.push_str(w);
                }
                _ => return Err(lx.error("`;` ending the header entry")),
            }
        }
        match key {
            "format" => h.binary = value == "binary",
            "class" => h.class = value,
            "object" => h.object = value,
            "note" => h.note = value,
            "arch" => {
                if value.contains("label=64") {
                    h.label_bytes = 8;
                }
                if value.contains("scalar=32") {
                    h.scalar_bytes = 4;
                }
            }
            _ => {}
        }
    }
    Ok(h)
}

/// Read `N ( labels )`, ASCII or binary.
pub(crate) fn read_labels(lx: &mut Lexer<'_>, h: &Header) -> Result<Vec<i64>> {
    let n = lx.count(lx.bytes.len())?;
    lx.expect(b'(', "`(` opening the list")?;
    let mut out = Vec::with_capacity(n);
    if h.binary {
        let len = n * h.label_bytes;
        let start = lx.pos;
        if start + len > lx.bytes.len() {
            return Err(Error::Binary {
                offset: start,
                what: format!("{n} labels of {} bytes, but the file ends at byte {}", h.label_bytes, lx.bytes.len()),
            });
        }
        for c in lx.bytes[start..start + len].chunks_exact(h.label_bytes) {
            out.push(if h.label_bytes == 4 {
                i32::from_le_bytes([c[0], c[1], c[2], c[3]]) as i64
            } else {
                i64::from_le_bytes(c.try_into().unwrap_or([0; 8]))
            });
        }
        lx.pos = start + len;
    } else {
        for _ in 0..n {
            lx.skip_ws();
            let save = lx.pos;
            match lx.next() {
                Some(Tok::Word(w)) => match w.parse::<i64>() {
                    Ok(v) => out.push(v),
                    Err(_) => {
                        lx.pos = save;
                        return Err(lx.error("a label"));
                    }
                },
                _ => {
                    lx.pos = save;
                    return Err(lx.error("a label"));
                }
            }
        }
    }
    lx.expect(b')', "`)` closing the list (is the size right?)")?;
    Ok(out)
}

/// Read the data part of a `labelList` file.
pub(crate) fn label_list(bytes: &[u8]) -> Result<(Header, Vec<i64>)> {
    let mut lx = Lexer::new(bytes);
    let h = read_header(&mut lx)?;
    let v = read_labels(&mut lx, &h)?;
    Ok((h, v))
}

/// A `labelList` file through the fast path ([`super::fast::labels`] for ASCII, a direct
/// read for binary): `None` when it is not a plain list of labels from 0 to 2³² − 1 (then
/// [`label_list`] reads it, or names what is wrong).
pub(crate) fn label_list_fast(bytes: &[u8]) -> Option<(Header, Vec<u32>)> {
    let mut lx = Lexer::new(bytes);
    let h = read_header(&mut lx).ok()?;
    let v = fast_labels(&mut lx, &h)?;
    Some((h, v))
}

/// One list of labels from 0 to 2³² − 1 at the lexer, ASCII or binary, through the fast
/// path; the lexer stands after its `)`.
fn fast_labels(lx: &mut Lexer<'_>, h: &Header) -> Option<Vec<u32>> {
    let n = lx.count(lx.bytes.len()).ok()?;
    lx.expect(b'(', "").ok()?;
    let v = if h.binary {
        let w = h.label_bytes;
        let body = lx.bytes.get(lx.pos..lx.pos.checked_add(n.checked_mul(w)?)?)?;
        lx.pos += body.len();
        if w == 4 {
            let v: Vec<u32> = body.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
            // Negative 32-bit labels have the top bit set.
            if v.iter().any(|&x| x > i32::MAX as u32) {
                return None;
            }
            v
        } else {
            body.chunks_exact(8)
                .map(|c| u32::try_from(i64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]])).ok())
                .collect::<Option<_>>()?
        }
    } else {
        let (v, close) = super::fast::labels(lx.bytes, lx.pos, n)?;
        lx.pos = close;
        v
    };
    lx.expect(b')', "").ok()?;
    Some(v)
}

/// A `faceList` file through the fast path ([`super::fast::faces`]; a `faceCompactList`
/// or binary file as its two label lists): CSR offsets and point labels, or `None` when
/// it is not a plain face list (then [`face_list`] reads it, or names what is wrong).
pub(crate) fn face_list_fast(bytes: &[u8]) -> Option<(Header, Vec<usize>, Vec<u32>)> {
    let mut lx = Lexer::new(bytes);
    let h = read_header(&mut lx).ok()?;
    if h.binary || h.class == "faceCompactList" {
        let offsets = fast_labels(&mut lx, &h)?;
        let points = fast_labels(&mut lx, &h)?;
        let spans = offsets.first() == Some(&0) && offsets.last().map(|&o| o as usize) == Some(points.len());
        let offsets: Vec<usize> = offsets.into_iter().map(|o| o as usize).collect();
        return (spans && offsets.windows(2).all(|w| w[0] <= w[1])).then_some((h, offsets, points));
    }
    let n = lx.count(bytes.len()).ok()?;
    lx.expect(b'(', "").ok()?;
    let (offsets, points, close) = super::fast::faces(bytes, lx.pos, n)?;
    lx.pos = close;
    lx.expect(b')', "").ok()?;
    Some((h, offsets, points))
}

/// Read a `faceList` (`N ( n(a b c) … )`) or `faceCompactList` (offsets list, then the
/// flat point list) file: the CSR offsets and the point labels.
pub(crate) fn face_list(bytes: &[u8]) -> Result<(Header, Vec<usize>, Vec<i64>)> {
    let mut lx = Lexer::new(bytes);
    let h = read_header(&mut lx)?;
    if h.class == "faceCompactList" || h.binary {
        let offsets = read_labels(&mut lx, &h)?;
        let flat = read_labels(&mut lx, &h)?;
        let mut off = Vec::with_capacity(offsets.len());
        for (i, &o) in offsets.iter().enumerate() {
            if o < 0 || o as usize > flat.len() || (i > 0 && o < offsets[i - 1]) {
                return Err(Error::Topology(format!(
                    "faces: offset {i} is {o}, outside 0..={} or decreasing",
                    flat.len()
                )));
            }
            off.push(o as usize);
        }
        if off.first().copied().unwrap_or(0) != 0 || off.last().copied().unwrap_or(0) != flat.len() {
            return Err(Error::Topology("faces: compact offsets do not span the point list".into()));
        }
        return Ok((h, off, flat));
    }
    let n = lx.count(bytes.len())?;
    lx.expect(b'(', "`(` opening the face list")?;
    let mut off = Vec::with_capacity(n + 1);
    let mut flat = Vec::with_capacity(4 * n);
    off.push(0);
    for _ in 0..n {
        let k = lx.count(bytes.len())?;
        lx.expect(b'(', "`(` opening a face")?;
        for _ in 0..k {
            lx.skip_ws();
            let save = lx.pos;
            match lx.next() {
                Some(Tok::Word(w)) if w.parse::<i64>().is_ok() => flat.push(w.parse::<i64>().unwrap_or(0)),
                _ => {
                    lx.pos = save;
                    return Err(lx.error("a point label"));
                }
            }
        }
        lx.expect(b')', "`)` closing a face (is its size right?)")?;
        off.push(flat.len());
    }
    lx.expect(b')', "`)` closing the face list (is the size right?)")?;
    Ok((h, off, flat))
}

/// Gunzip `bytes` when `gz` is set.
pub(crate) fn maybe_gunzip(bytes: Vec<u8>, gz: bool) -> Result<Vec<u8>> {
    if !gz {
        return Ok(bytes);
    }
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(&bytes[..])
        .read_to_end(&mut out)
        .map_err(|e| Error::Binary { offset: 0, what: format!("gzip: {e}") })?;
    Ok(out)
}

/// Gzip `bytes`.
pub(crate) fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    // Writing into a Vec cannot fail.
    let _ = e.write_all(bytes);
    e.finish().unwrap_or_default()
}
