//! Free-format parameter tokens: integers, reals (`1.0D3`, `.5`, `-0.`), Hollerith
//! strings (`5HHello`, which may hold the delimiters), defaulted (empty) parameters,
//! custom parameter and record delimiters.
//!
//! The number grammar is a nom parser; the scan that splits a record into tokens is a
//! loop over bytes, since it decides on one byte at a time.

use nom::character::complete::{char, digit0, digit1, one_of};
use nom::combinator::opt;
use nom::{IResult, Parser};

use super::tokens::Tokens;
use crate::document::Line;

/// One parameter value as stored: strings as byte ranges into the record text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Raw {
    /// An empty parameter.
    Default,
    /// An integer (no decimal point, no exponent).
    Integer(i64),
    /// A real.
    Real(f64),
    /// A Hollerith string: `start..start+len` of the record text.
    Text { start: u32, len: u32 },
}

/// A token: its value and where its text starts in the record (for error positions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Token {
    pub offset: u32,
    pub raw: Raw,
}

/// Where tokens go: with their offsets (Global section, error positions) or without
/// (parameter records, where offsets are recomputed only to report an error).
pub(crate) trait Sink {
    /// Appends a token that starts at `offset`.
    fn put(&mut self, offset: usize, raw: Raw);
}

impl Sink for Vec<Token> {
    #[inline]
    fn put(&mut self, offset: usize, raw: Raw) {
        self.push(Token { offset: offset as u32, raw });
    }
}

impl Sink for Vec<Raw> {
    #[inline]
    fn put(&mut self, _offset: usize, raw: Raw) {
        self.push(raw);
    }
}

/// The offsets of the parameters of a record (as far as it reads).
pub(crate) fn offsets(text: &[u8], pd: u8, rd: u8) -> Vec<usize> {
    let mut out: Vec<Token> = Vec::new();
    let _ = tokenize(text, 0, pd, rd, &mut out);
    out.into_iter().map(|t| t.offset as usize).collect()
}

/// What went wrong, at which byte offset of the record text.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum LexError {
    /// A parameter that is neither a number nor a Hollerith string.
    Number { offset: usize, found: String },
    /// A Hollerith string longer than the text left.
    Hollerith { offset: usize, length: usize },
    /// Text after a value that is not a delimiter.
    Delimiter { offset: usize, found: String },
    /// The text ends before the record delimiter.
    NoRecordEnd { offset: usize },
}

/// Shape of a number: has a decimal point, has an exponent.
fn number(i: &[u8]) -> IResult<&[u8], (usize, bool, bool)> {
    let (i, _) = opt(one_of("+-")).parse(i)?;
    let (i, int) = digit0(i)?;
    let (i, frac) = opt((char('.'), digit0)).parse(i)?;
    let (i, exp) = opt((one_of("EeDd"), opt(one_of("+-")), digit1)).parse(i)?;
    let digits = int.len() + frac.map_or(0, |(_, d): (char, &[u8])| d.len());
    Ok((i, (digits, frac.is_some(), exp.is_some())))
}

/// Exact powers of ten up to 10²² (all representable in an f64).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// Parses one number token (no blanks inside).
///
/// The common forms go through the tokenizer's one-pass [`scan`]; the rest (long
/// mantissas, large exponents) through the full grammar and `str::parse`.
pub(crate) fn parse_number(s: &[u8]) -> Option<Raw> {
    if let Scan::Value(raw, end) = scan(s, 0) {
        if end == s.len() {
            return Some(raw);
        }
    }
    let (rest, (digits, dot, exp)) = number(s).ok()?;
    if !rest.is_empty() || digits == 0 {
        return None;
    }
    if !dot && !exp {
        // Checked: an integer too large for i64 is read as a real.
        if let Some(n) = std::str::from_utf8(s).ok().and_then(|t| t.parse::<i64>().ok()) {
            return Some(Raw::Integer(n));
        }
    }
    let parsed = if s.iter().any(|&b| b == b'D' || b == b'd') {
        let t: Vec<u8> = s.iter().map(|&b| if b == b'D' || b == b'd' { b'E' } else { b }).collect();
        std::str::from_utf8(&t).ok()?.parse::<f64>().ok()
    } else {
        std::str::from_utf8(s).ok()?.parse::<f64>().ok()
    };
    parsed.map(Raw::Real)
}

fn is_blank(b: u8) -> bool {
    b == b' ' || b == b'\t'
}

/// If a Hollerith string starts at `pos` (digits then `H`), its declared length and the
/// offset of its first character.
pub(crate) fn hollerith_at(text: &[u8], pos: usize) -> Option<(usize, usize)> {
    let mut k = pos;
    let mut n: usize = 0;
    while k < text.len() && text[k].is_ascii_digit() {
        n = n.saturating_mul(10).saturating_add(usize::from(text[k] - b'0'));
        k += 1;
    }
    (k > pos && k < text.len() && (text[k] == b'H' || text[k] == b'h')).then_some((n, k + 1))
}

/// What a one-pass scan found at the start of a parameter.
enum Scan {
    /// A number ending at the offset.
    Value(Raw, usize),
    /// A Hollerith string: declared length and offset of its first character.
    Hollerith(usize, usize),
    /// Anything else: the full grammar decides.
    Slow,
}

/// The value of 8 digits (each byte 0–9) read little-endian, the first byte most
/// significant (SWAR: pairs, then quads, then all).
#[inline(always)]
pub(crate) fn eight_digit_value(v: u64) -> u64 {
    let v = (v & 0x0F0F_0F0F_0F0F_0F0F).wrapping_mul(2561) >> 8;
    let v = (v & 0x00FF_00FF_00FF_00FF).wrapping_mul(6_553_601) >> 16;
    (v & 0x0000_FFFF_0000_FFFF).wrapping_mul(42_949_672_960_001) >> 32
}

/// Powers of ten as integers, for appending a run of up to 8 digits.
const POW10_U64: [u64; 9] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000, 100_000_000];

/// Accumulates the digits from `i` into `m`; returns the end. Eight bytes are read at a
/// time: the run of leading digits among them is found from a mask (no per-digit
/// branch) and its value added in one SWAR step. The arithmetic wraps past 19 digits;
/// callers count the digits from the offsets and reject such runs.
#[inline(always)]
fn digits(text: &[u8], mut i: usize, m: &mut u64) -> usize {
    while let Some(chunk) = text.get(i..).and_then(|t| t.first_chunk::<8>()) {
        // Digits become 0–9; any other byte has its high bit set in `nd`.
        let x = u64::from_le_bytes(*chunk) ^ 0x3030_3030_3030_3030;
        let nd = (x.wrapping_add(0x7676_7676_7676_7676) | x) & 0x8080_8080_8080_8080;
        let n = (nd.trailing_zeros() / 8) as usize;
        if n == 0 {
            return i;
        }
        // The first n bytes moved to the top: leading zeros below them.
        *m = m.wrapping_mul(POW10_U64[n]).wrapping_add(eight_digit_value(x << (8 * (8 - n))));
        i += n;
        if n < 8 {
            return i;
        }
        // A run of 8: mantissas of 9 or 10 digits end within a few more bytes.
        let end = i + 3;
        while i < end && i < text.len() && text[i].is_ascii_digit() {
            *m = m.wrapping_mul(10).wrapping_add(u64::from(text[i] - b'0'));
            i += 1;
        }
        if i < end {
            return i;
        }
    }
    while i < text.len() && text[i].is_ascii_digit() {
        *m = m.wrapping_mul(10).wrapping_add(u64::from(text[i] - b'0'));
        i += 1;
    }
    i
}

/// One pass over a parameter: an integer, a real whose digits make an integer of at most
/// 2⁵³ with a decimal exponent within ±22 (Clinger's fast path: `m · 10^e` or `m / 10^e`
/// with both exact is the correctly rounded value, so the result equals `str::parse`'s),
/// or the count of a Hollerith string. The one number scanner of the crate: the
/// tokenizer (sequential and chunked) and [`parse_number`] both use it.
#[inline(always)]
fn scan(text: &[u8], start: usize) -> Scan {
    let len = text.len();
    let mut i = start;
    let first = text.get(i).copied();
    let neg = first == Some(b'-');
    if neg || first == Some(b'+') {
        i += 1;
    }
    let signed = i > start;
    let mut m: u64 = 0;
    let d0 = i;
    // The integer part has a digit or two in most reals: byte by byte until 3 digits.
    while i < d0 + 3 && i < len && text[i].is_ascii_digit() {
        m = m * 10 + u64::from(text[i] - b'0');
        i += 1;
    }
    if i == d0 + 3 {
        i = digits(text, i, &mut m);
    }
    let integer_end = i;
    let int_digits = i - d0;
    // The byte after the digits (0 at the end); `| 0x20` folds the letters' cases.
    let mut c = text.get(i).copied().unwrap_or(0);
    if c | 0x20 == b'h' {
        if int_digits > 0 && int_digits <= 19 && !signed {
            return Scan::Hollerith(m as usize, i + 1);
        }
        return Scan::Slow;
    }
    let mut real = false;
    let mut frac = 0;
    if c == b'.' {
        real = true;
        let f0 = i + 1;
        i = digits(text, f0, &mut m);
        frac = i - f0;
        c = text.get(i).copied().unwrap_or(0);
    }
    let count = int_digits + frac;
    if count == 0 || count > 19 {
        return Scan::Slow;
    }
    let mut scale = -(frac as i32);
    if c | 0x20 == b'e' || c | 0x20 == b'd' {
        real = true;
        i += 1;
        let eneg = match text.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let e0 = i;
        let mut e: i32 = 0;
        while i < len && text[i].is_ascii_digit() && i - e0 < 4 {
            e = e * 10 + i32::from(text[i] - b'0');
            i += 1;
        }
        if i == e0 {
            return Scan::Slow;
        }
        scale += if eneg { -e } else { e };
    }
    if !real {
        if count > 18 {
            return Scan::Slow;
        }
        let v = m as i64;
        return Scan::Value(Raw::Integer(if neg { -v } else { v }), integer_end);
    }
    if m > (1u64 << 53) {
        return Scan::Slow;
    }
    let x = m as f64;
    let v = match scale {
        0 => x,
        1..=22 => x * POW10[scale as usize],
        -22..=-1 => x / POW10[(-scale) as usize],
        _ => return Scan::Slow,
    };
    Scan::Value(Raw::Real(if neg { -v } else { v }), i)
}

/// The first offset at or after `pos` that is not a blank (or the text's end): runs of
/// eight spaces at a glance, then byte by byte.
#[inline(always)]
fn skip_blanks(text: &[u8], mut pos: usize) -> usize {
    while let Some(chunk) = text.get(pos..).and_then(|t| t.first_chunk::<8>()) {
        if u64::from_le_bytes(*chunk) != 0x2020_2020_2020_2020 {
            break;
        }
        pos += 8;
    }
    while pos < text.len() && is_blank(text[pos]) {
        pos += 1;
    }
    pos
}

/// Whether `c` can be part of a number or Hollerith count (then it cannot be a delimiter
/// for the one-pass scan).
fn numeric(c: u8) -> bool {
    matches!(c, b'0'..=b'9' | b'+' | b'-' | b'.' | b'E' | b'e' | b'D' | b'd' | b'H' | b'h')
}

/// Splits `text[pos..]` into parameters up to the record delimiter `rd`.
///
/// Returns the tokens and the offset just after the record delimiter.
pub(crate) fn tokenize<S: Sink>(text: &[u8], pos: usize, pd: u8, rd: u8, out: &mut S) -> Result<usize, LexError> {
    match tokenize_until(text, pos, pd, rd, usize::MAX, out)? {
        Stop::End(p) | Stop::At(p) => Ok(p),
    }
}

/// Where [`tokenize_until`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// After the record delimiter, at this offset.
    End(usize),
    /// At the start of a parameter at or after the stop offset.
    At(usize),
}

/// Records of at least two of these (bytes) are split into chunks tokenized in parallel
/// (with the records themselves read in parallel, chunks of this size keep both cores
/// busy on files of a few large surfaces; the chunks' tokens are copied into one vector,
/// which smaller records do not repay).
const CHUNK: usize = 1 << 18;

/// Lines copied at a time into the window a long record is tokenized through (a few KiB,
/// so the copy stays in the L1 cache and the record's text is never built whole).
const WINDOW: usize = 64;

/// A record as lines of the input: the data field of line `j` (its first `width` bytes,
/// fewer only for a last, short line) holds the record text from offset `j * width`.
#[derive(Clone, Copy)]
pub(crate) struct RecordLines<'a> {
    pub bytes: &'a [u8],
    pub lines: &'a [Line],
    pub width: usize,
}

impl RecordLines<'_> {
    fn field(&self, j: usize) -> &[u8] {
        let l = self.lines[j];
        &self.bytes[l.start..(l.start + self.width).min(l.end)]
    }

    /// The fields of lines `range`, concatenated into `buf`.
    fn copy(&self, range: std::ops::Range<usize>, buf: &mut Vec<u8>) {
        buf.clear();
        for j in range {
            let f = self.field(j);
            // P lines: 64 bytes, copied inline rather than by a call per line.
            match f.first_chunk::<64>() {
                Some(c) if f.len() == 64 => buf.extend_from_slice(c),
                _ => buf.extend_from_slice(f),
            }
        }
    }

    /// The whole record text.
    pub fn text(&self) -> Vec<u8> {
        let mut text = Vec::with_capacity(self.lines.len() * self.width);
        self.copy(0..self.lines.len(), &mut text);
        text
    }

    /// The first offset at or after `q` that is not a blank (or the text's end).
    fn skip_blanks(&self, mut q: usize) -> usize {
        while q / self.width < self.lines.len()
            && self.field(q / self.width).get(q % self.width).is_some_and(|&c| is_blank(c))
        {
            q += 1;
        }
        q
    }
}

/// A sink that moves string offsets from a window to the whole record, and notes
/// whether there were any.
struct Shifted<'a> {
    out: &'a mut Tokens,
    base: usize,
    strings: &'a mut bool,
}

impl Sink for Shifted<'_> {
    #[inline]
    fn put(&mut self, _offset: usize, raw: Raw) {
        self.out.push(match raw {
            Raw::Text { start, len } => {
                *self.strings = true;
                Raw::Text { start: (start as usize + self.base) as u32, len }
            }
            r => r,
        });
    }
}

/// [`tokenize_until`] on a record given as lines, from offset `from`, through windows of
/// [`WINDOW`] lines: each window is tokenized up to the start of its last line, so every
/// parameter read from it ends within it in a well-formed record, and the tokens are
/// those the whole text gives. `None` when a window cannot decide (a parameter running
/// past its end, or any error): then only the whole text can. `strings` is set if a
/// string was read.
#[allow(clippy::too_many_arguments)]
fn tokenize_window(
    rec: &RecordLines,
    from: usize,
    stop: usize,
    pd: u8,
    rd: u8,
    buf: &mut Vec<u8>,
    out: &mut Tokens,
    strings: &mut bool,
) -> Option<Stop> {
    let (n, w) = (rec.lines.len(), rec.width);
    let mut p = from;
    loop {
        let a = p / w;
        if a >= n {
            return None;
        }
        let b = (a + WINDOW).min(n);
        rec.copy(a..b, buf);
        let base = a * w;
        let local = if b == n { stop.saturating_sub(base) } else { stop.min((b - 1) * w) - base };
        match tokenize_until(buf, p - base, pd, rd, local, &mut Shifted { out, base, strings }) {
            Ok(Stop::End(e)) => return Some(Stop::End(base + e)),
            Ok(Stop::At(q)) if base + q >= stop => return Some(Stop::At(base + q)),
            Ok(Stop::At(q)) => p = base + q,
            Err(_) => return None,
        }
    }
}

/// The tokens of a whole record given as lines, and its text if it had to be built
/// (short records, and records a window cannot read: long strings, numbers across a
/// window's end, errors, whose positions are then those of the whole text).
///
/// Long records are read in parallel: the lines are cut into chunks, each tokenized as
/// if a parameter started at its first line; a cut is accepted only if the chunk before
/// it, read on, starts a parameter at exactly the same place (so a cut inside a string
/// or number, or just before a delimiter, is detected). Otherwise the record is read in
/// one piece, so the result is always the sequential one. With one thread the record is
/// read in one piece (the copy of the chunks' tokens would buy nothing).
pub(crate) fn tokenize_record(rec: &RecordLines, pd: u8, rd: u8) -> Result<Record, LexError> {
    // One chunk per thread at most (each chunk after the first is copied into the first's
    // vector), and none under CHUNK.
    let threads = rayon::current_num_threads();
    let chunk = if threads > 1 { CHUNK.max(rec.lines.len() * rec.width / threads) } else { usize::MAX };
    chunked(rec, pd, rd, chunk).map(|(r, _)| r)
}

/// [`tokenize_record`] on the calling thread only, as it reads with one thread (no
/// parallel cut, whatever the thread pool): for timing the tokenizer alone.
#[cfg(feature = "bench-internals")]
pub(crate) fn tokenize_record_one_thread(rec: &RecordLines, pd: u8, rd: u8) -> Result<Record, LexError> {
    chunked(rec, pd, rd, usize::MAX).map(|(r, _)| r)
}

/// A record as read.
pub(crate) struct Record {
    pub tokens: Tokens,
    /// Its text, if it had to be built.
    pub text: Option<Vec<u8>>,
    /// Whether a parameter is a string.
    pub strings: bool,
}

/// [`tokenize_record`], and whether the parallel cut was used.
fn chunked(rec: &RecordLines, pd: u8, rd: u8, chunk: usize) -> Result<(Record, bool), LexError> {
    let (n_lines, w) = (rec.lines.len(), rec.width);
    let whole = |capacity: usize| -> Result<(Record, bool), LexError> {
        let text = rec.text();
        let mut out = Tokens::with_capacity(capacity);
        tokenize(&text, 0, pd, rd, &mut out)?;
        let strings = out.has_text();
        Ok((Record { tokens: out, text: Some(text), strings }, false))
    };
    if n_lines <= WINDOW {
        return whole(n_lines * w / 8 + 16);
    }
    let len = n_lines * w;
    let n = len / chunk;
    let fast = !numeric(pd) && !numeric(rd) && !is_blank(pd) && !is_blank(rd);
    if n >= 2 && fast {
        let cuts: Vec<usize> = (0..=n).map(|k| if k == n { n_lines } else { k * chunk / w }).collect();
        use rayon::prelude::*;
        let parts: Vec<Option<(Tokens, Stop, bool)>> = (0..n)
            .into_par_iter()
            .map(|k| {
                // The first chunk's vector receives the others' tokens (only they are
                // copied), so it is sized for the whole record.
                let lines = if k == 0 { n_lines } else { cuts[k + 1] - cuts[k] };
                let mut out = Tokens::with_capacity(lines * w / 8 + 16);
                let mut buf = Vec::with_capacity(WINDOW * w);
                let stop = if k + 1 == n { usize::MAX } else { cuts[k + 1] * w };
                let mut strings = false;
                tokenize_window(rec, cuts[k] * w, stop, pd, rd, &mut buf, &mut out, &mut strings)
                    .map(|s| (out, s, strings))
            })
            .collect();
        let total: usize = parts.iter().flatten().map(|p| p.0.len()).sum();
        let mut tokens = Tokens::default();
        let mut strings = false;
        let mut ok = true;
        for (k, part) in parts.into_iter().enumerate() {
            let Some((toks, stop, s)) = part else {
                ok = false;
                break;
            };
            let expected = if k + 1 == n {
                matches!(stop, Stop::End(_))
            } else {
                stop == Stop::At(rec.skip_blanks(cuts[k + 1] * w))
            };
            if !expected {
                ok = false;
                break;
            }
            strings |= s;
            if k == 0 {
                tokens = toks;
                tokens.reserve(total - tokens.len());
            } else {
                tokens.append(&toks);
            }
        }
        if ok {
            return Ok((Record { tokens, text: None, strings }, true));
        }
    }
    let mut out = Tokens::with_capacity(len / 8 + 16);
    let mut buf = Vec::with_capacity(WINDOW * w);
    let mut strings = false;
    if let Some(Stop::End(_)) = tokenize_window(rec, 0, usize::MAX, pd, rd, &mut buf, &mut out, &mut strings) {
        return Ok((Record { tokens: out, text: None, strings }, false));
    }
    whole(len / 8 + 16)
}

/// [`tokenize`], stopping at the first parameter that starts at or after `stop`.
pub(crate) fn tokenize_until<S: Sink>(
    text: &[u8],
    mut pos: usize,
    pd: u8,
    rd: u8,
    stop: usize,
    out: &mut S,
) -> Result<Stop, LexError> {
    let len = text.len();
    let fast = !numeric(pd) && !numeric(rd) && !is_blank(pd) && !is_blank(rd);
    loop {
        if fast {
            // The bulk of a record: a number directly followed by the parameter
            // delimiter. Anything else (blanks, defaults, strings, the record end, long
            // numbers) leaves this loop for the general steps below, which see the same
            // text as if this loop had not run.
            while pos < stop {
                let Scan::Value(raw, end) = scan(text, pos) else {
                    // Blanks before a parameter (the padding at the end of each P line's
                    // data field): skipped eight at a time, then the scan goes on.
                    let q = skip_blanks(text, pos);
                    if q > pos && q < len {
                        pos = q;
                        continue;
                    }
                    break;
                };
                if text.get(end) != Some(&pd) {
                    break;
                }
                out.put(pos, raw);
                pos = end + 1;
            }
        }
        while pos < len && is_blank(text[pos]) && text[pos] != pd && text[pos] != rd {
            pos += 1;
        }
        if pos >= stop {
            return Ok(Stop::At(pos));
        }
        if pos >= len {
            return Err(LexError::NoRecordEnd { offset: len });
        }
        let c = text[pos];
        if c == pd {
            out.put(pos, Raw::Default);
            pos += 1;
            continue;
        }
        if c == rd {
            out.put(pos, Raw::Default);
            return Ok(Stop::End(pos + 1));
        }
        let start = pos;
        let scanned = if fast { scan(text, pos) } else { Scan::Slow };
        let raw = match scanned {
            Scan::Value(raw, end) if end < len && (text[end] == pd || text[end] == rd || is_blank(text[end])) => {
                pos = end;
                raw
            }
            Scan::Hollerith(n, first) => {
                if n > len - first {
                    return Err(LexError::Hollerith { offset: start, length: n });
                }
                pos = first + n;
                Raw::Text { start: first as u32, len: n as u32 }
            }
            _ => {
                if let Some((n, first)) = hollerith_at(text, pos) {
                    if n > len - first {
                        return Err(LexError::Hollerith { offset: start, length: n });
                    }
                    pos = first + n;
                    Raw::Text { start: first as u32, len: n as u32 }
                } else {
                    while pos < len && text[pos] != pd && text[pos] != rd && !is_blank(text[pos]) {
                        pos += 1;
                    }
                    parse_number(&text[start..pos]).ok_or_else(|| LexError::Number {
                        offset: start,
                        found: crate::error::snippet(&text[start..pos]),
                    })?
                }
            }
        };
        out.put(start, raw);
        while pos < len && is_blank(text[pos]) && text[pos] != pd && text[pos] != rd {
            pos += 1;
        }
        if pos >= len {
            return Err(LexError::NoRecordEnd { offset: len });
        }
        if text[pos] == rd {
            return Ok(Stop::End(pos + 1));
        }
        if text[pos] != pd {
            let end = (pos + 20).min(len);
            return Err(LexError::Delimiter { offset: pos, found: crate::error::snippet(&text[pos..end]) });
        }
        pos += 1;
        // A parameter delimiter directly followed by the record delimiter: one more,
        // defaulted parameter (e.g. the Global section's `,;`).
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(s: &str) -> Vec<Raw> {
        let mut out: Vec<Token> = Vec::new();
        tokenize(s.as_bytes(), 0, b',', b';', &mut out).unwrap();
        out.into_iter().map(|t| t.raw).collect()
    }

    #[test]
    fn fast_path_agrees_with_the_full_parser() {
        let cases = [
            "0.",
            "-0.",
            "1.",
            ".5",
            "0.1",
            "-12.75",
            "1E-07",
            "1.5D3",
            "0.333333333",
            "9.009009009E-02",
            "123456789012345.",
            "1.234567890123456",
            "6.283185307",
            "-1.1626228E-16",
            "4.440892099E-15",
            "1e22",
            "1e23",
            "17.",
            "000.000100",
            "+3.",
            "1.D0",
            "12345678901234567",
        ];
        for c in cases {
            let full: f64 = c.replace(['D', 'd'], "E").parse().unwrap();
            match parse_number(c.as_bytes()) {
                Some(Raw::Real(x)) => assert_eq!(x.to_bits(), full.to_bits(), "{c}"),
                Some(Raw::Integer(i)) => assert_eq!(i as f64, full, "{c}"),
                other => panic!("{c}: {other:?}"),
            }
        }
    }

    proptest::proptest! {
        /// Every shortest representation and every 9-digit rounding of a random f64 reads
        /// back exactly as `str::parse` reads it.
        #[test]
        fn fast_path_is_exact(x in proptest::num::f64::NORMAL, digits in 1usize..17) {
            for s in [format!("{x:?}"), format!("{x:.*e}", digits), format!("{:.*}", digits, x % 1e6)] {
                let full: f64 = s.parse().unwrap();
                let got = match parse_number(s.as_bytes()) {
                    Some(Raw::Real(v)) => v,
                    Some(Raw::Integer(i)) => i as f64,
                    other => panic!("{s}: {other:?}"),
                };
                proptest::prop_assert_eq!(got.to_bits(), full.to_bits(), "{}", s);
            }
        }
    }

    /// Chunk size of the chunking test (small, so records stay small).
    const TEST_CHUNK: usize = 1 << 14;

    /// A text cut into 64-byte lines.
    fn lines_of(text: &[u8]) -> Vec<Line> {
        (0..text.len().div_ceil(64))
            .map(|j| Line { start: 64 * j, end: (64 * j + 64).min(text.len()), next: (64 * j + 64).min(text.len()) })
            .collect()
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config { cases: 64, ..Default::default() })]
        /// Long records read in parallel chunks give exactly the sequential tokens, also
        /// when cuts fall inside strings or before delimiters.
        #[test]
        fn chunked_records_equal_sequential(seed in 0u64..1000, strings in 0usize..4) {
            let mut rec = String::new();
            let mut line = String::from("128,");
            let mut k = seed;
            while rec.len() < 3 * TEST_CHUNK {
                k = k.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let tok = match (k >> 60) as usize % (4 + strings) {
                    0 => format!("{}", (k >> 20) % 1000),
                    1 => format!("{:?}", (k >> 11) as f64 / (1u64 << 53) as f64),
                    2 => String::new(),
                    3 => format!("{:.3E}", (k >> 30) as f64),
                    _ => { let n = (k >> 40) as usize % 150; format!("{n}H{}", ",".repeat(n)) }
                };
                let piece = format!("{tok},");
                if line.len() + piece.len() > 64 && !tok.contains('H') {
                    rec.push_str(&format!("{line:64}"));
                    line.clear();
                }
                line.push_str(&piece);
            }
            line.push_str("0;");
            rec.push_str(&format!("{line:64}"));
            let mut seq: Vec<Raw> = Vec::new();
            tokenize(rec.as_bytes(), 0, b',', b';', &mut seq).unwrap();
            let lines = lines_of(rec.as_bytes());
            let lines = RecordLines { bytes: rec.as_bytes(), lines: &lines, width: 64 };
            let has_strings = seq.iter().any(|t| matches!(t, Raw::Text { .. }));
            let (par, parallel) = chunked(&lines, b',', b';', TEST_CHUNK).unwrap();
            proptest::prop_assert!(seq == par.tokens.iter().collect::<Vec<Raw>>());
            proptest::prop_assert_eq!(par.strings, has_strings);
            // Through windows on one thread: the same tokens.
            let (windowed, _) = chunked(&lines, b',', b';', usize::MAX).unwrap();
            proptest::prop_assert!(seq == windowed.tokens.iter().collect::<Vec<Raw>>());
            proptest::prop_assert_eq!(windowed.strings, has_strings);
            if strings == 0 {
                // Without strings every cut falls on a line start before a parameter.
                proptest::prop_assert!(parallel);
            }
        }

        /// The one-pass scan of a record gives what `str::parse` gives for each number.
        #[test]
        fn records_scan_exactly(xs in proptest::collection::vec(proptest::num::f64::NORMAL, 1..20), digits in 1usize..18) {
            let texts: Vec<String> = xs.iter().enumerate().map(|(k, x)| match k % 3 {
                0 => format!("{x:?}"),
                1 => format!("{x:.*E}", digits),
                _ => format!("{}", (x % 1e6).round() as i64),
            }).collect();
            let record = format!("128,{}  ;", texts.join(" ,"));
            let mut out: Vec<Token> = Vec::new();
            tokenize(record.as_bytes(), 0, b',', b';', &mut out).unwrap();
            proptest::prop_assert_eq!(out.len(), texts.len() + 1);
            for (t, s) in out[1..].iter().zip(&texts) {
                let full: f64 = s.parse().unwrap();
                let got = match t.raw {
                    Raw::Real(v) => v,
                    Raw::Integer(i) => i as f64,
                    other => panic!("{s}: {other:?}"),
                };
                proptest::prop_assert_eq!(got.to_bits(), full.to_bits(), "{}", s);
            }
        }
    }

    #[test]
    fn numbers_of_every_form() {
        assert_eq!(parse_number(b"1.0D3"), Some(Raw::Real(1000.0)));
        assert_eq!(parse_number(b".5"), Some(Raw::Real(0.5)));
        assert_eq!(parse_number(b"-0."), Some(Raw::Real(-0.0)));
        assert_eq!(parse_number(b"1E-07"), Some(Raw::Real(1e-7)));
        assert_eq!(parse_number(b"+12"), Some(Raw::Integer(12)));
        assert_eq!(parse_number(b"-3"), Some(Raw::Integer(-3)));
        assert_eq!(parse_number(b"99999999999999999999"), Some(Raw::Real(1e20)));
        // Past 19 digits the one-pass scan's sum wraps; the full parser decides.
        for long in ["123456789012345678901234567890", "0.1234567890123456789012345", "-98765432109876543210.5e-3"] {
            let want: f64 = long.parse().unwrap();
            assert_eq!(parse_number(long.as_bytes()), Some(Raw::Real(want)), "{long}");
        }
        assert_eq!(parse_number(b"1234567890123456789"), Some(Raw::Integer(1_234_567_890_123_456_789)));
        assert_eq!(parse_number(b"2.5d-1"), Some(Raw::Real(0.25)));
        assert_eq!(parse_number(b"2.5e+1"), Some(Raw::Real(25.0)));
        // Exponents beyond the exact powers: the full parser.
        assert_eq!(parse_number(b"1.5E-30"), Some(Raw::Real(1.5e-30)));
        assert_eq!(parse_number(b"1.5E30"), Some(Raw::Real(1.5e30)));
        assert_eq!(parse_number(b"15E-23"), Some(Raw::Real(15e-23)));
        for bad in [&b"inf"[..], b"NaN", b".", b"1.2.3", b"E5", b"1E", b"--1", b"0x10"] {
            assert_eq!(parse_number(bad), None, "{}", String::from_utf8_lossy(bad));
        }
    }

    #[test]
    fn defaults_strings_and_delimiters() {
        let v = values("128,,3H,;a, 2 ,;");
        assert_eq!(v.len(), 5);
        assert_eq!(v[0], Raw::Integer(128));
        assert_eq!(v[1], Raw::Default);
        assert_eq!(v[2], Raw::Text { start: 7, len: 3 });
        assert_eq!(v[3], Raw::Integer(2));
        assert_eq!(v[4], Raw::Default);
        let mut out: Vec<Token> = Vec::new();
        tokenize(b"1/2.5/3HA/B!junk", 0, b'/', b'!', &mut out).unwrap();
        assert_eq!(out.len(), 3);
        // Lower-case h, and counts too long for the one-pass scan.
        assert_eq!(values("2hab,;")[0], Raw::Text { start: 2, len: 2 });
        let mut out: Vec<Token> = Vec::new();
        assert!(matches!(
            tokenize(b"99999999999999999999Hx;", 0, b',', b';', &mut out),
            Err(LexError::Hollerith { offset: 0, .. })
        ));
    }

    #[test]
    fn errors_name_the_offset() {
        let mut out: Vec<Token> = Vec::new();
        assert_eq!(tokenize(b"1,2", 0, b',', b';', &mut out), Err(LexError::NoRecordEnd { offset: 3 }));
        assert_eq!(tokenize(b"1,9Habc;", 0, b',', b';', &mut out), Err(LexError::Hollerith { offset: 2, length: 9 }));
        assert!(matches!(tokenize(b"1,x;", 0, b',', b';', &mut out), Err(LexError::Number { offset: 2, .. })));
        assert!(matches!(tokenize(b"1. 5;", 0, b',', b';', &mut out), Err(LexError::Delimiter { offset: 3, .. })));
    }
}
