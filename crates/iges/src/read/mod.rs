//! Reading: lines and sections, the Global section, directory entries, parameter records.

pub(crate) mod lexer;
pub(crate) mod tokens;

use std::sync::Arc;

use crate::document::{Directory, Document, Entity, EntityId, Layout, Line, PBlock, RecordText, Source, Status};
use crate::error::{snippet, Error, Position, Result, Warning};
use crate::global::Global;
use lexer::{hollerith_at, tokenize, LexError, Raw, Token};

/// Width of the data field of a P line (columns 1–64).
pub(crate) const P_WIDTH: usize = 64;
/// Width of the data field of an S or G line (columns 1–72).
pub(crate) const G_WIDTH: usize = 72;

fn pos(section: char, line: usize, column: usize, entity: Option<u32>) -> Position {
    Position { section, line, column, entity }
}

/// The input's lines, and which of them [`sections`] must still look at.
struct Split {
    lines: Vec<Line>,
    /// Indices, ascending, of every line but those the split confirmed while it had them
    /// in the cache: an 80-column line whose columns 73–80 hold the section letter of the
    /// line before it (other than T) and that line's sequence number plus one. Such a
    /// line continues its section exactly as the line before did, so [`sections`] has
    /// nothing to check in it.
    unchecked: Vec<usize>,
}

/// Files from this size on (LF-terminated) are split in two halves on two threads.
const PARALLEL_SPLIT: usize = 1 << 20;

/// Splits the input into lines (LF, CRLF or CR), or into 80-byte records if it has no
/// line terminators at all.
fn split_lines(src: &[u8]) -> Split {
    // LF only, the common case: large files in two halves cut after a line feed. Any
    // carriage return sends the file to the general splitter below.
    let mid = src.len() / 2;
    let cut = memchr::memchr(b'\n', &src[mid..]).map(|k| mid + k + 1);
    let lf = match cut.filter(|&c| src.len() >= PARALLEL_SPLIT && c < src.len() && rayon::current_num_threads() > 1) {
        Some(cut) => match rayon::join(|| split_lf(src, 0, cut), || split_lf(src, cut, src.len())) {
            (Some(mut a), Some(b)) => {
                let n = a.lines.len();
                a.lines.extend_from_slice(&b.lines);
                a.unchecked.extend(b.unchecked.iter().map(|k| k + n));
                Some(a)
            }
            _ => None,
        },
        None => split_lf(src, 0, src.len()),
    };
    // Unless the input has no line terminator at all (one "line" of more than 80 bytes:
    // 80-byte records without line feeds).
    if let Some(split) = lf.filter(|s| !matches!(s.lines[..], [only] if only.end == only.next && src.len() > 80)) {
        return split;
    }
    let mut lines = Vec::with_capacity(src.len() / 80 + 1);
    if memchr::memchr2(b'\r', b'\n', src).is_none() && src.len() > 80 {
        let mut s = 0;
        while s < src.len() {
            let e = (s + 80).min(src.len());
            lines.push(Line { start: s, end: e, next: e });
            s = e;
        }
        return Split { unchecked: unchecked_lines(src, &lines), lines };
    }
    let mut s = 0;
    let mut i = 0;
    while i < src.len() {
        match src[i] {
            b'\n' => {
                let end = if i > s && src[i - 1] == b'\r' { i - 1 } else { i };
                lines.push(Line { start: s, end, next: i + 1 });
                s = i + 1;
            }
            b'\r' if src.get(i + 1) != Some(&b'\n') => {
                lines.push(Line { start: s, end: i, next: i + 1 });
                s = i + 1;
            }
            _ => {}
        }
        i += 1;
    }
    if s < src.len() {
        lines.push(Line { start: s, end: src.len(), next: src.len() });
    }
    Split { unchecked: unchecked_lines(src, &lines), lines }
}

/// [`Split::unchecked`] of lines found by other means than [`split_lf`].
fn unchecked_lines(src: &[u8], lines: &[Line]) -> Vec<usize> {
    let mut before = None;
    (0..lines.len()).filter(|&k| !continues(&mut before, &src[lines[k].start..lines[k].end])).collect()
}

/// Whether line `text` continues the line before it as [`Split::unchecked`] says (an
/// 80-column line with the letter of the line before, other than T, numbered one after
/// it). `before` holds the line before's letter and number, if it had both, and is set
/// to this line's.
fn continues(before: &mut Option<(u8, usize)>, text: &[u8]) -> bool {
    let Some(&tail) = text.get(72..80).and_then(|t| t.first_chunk::<8>()).filter(|_| text.len() == 80) else {
        *before = None;
        return false;
    };
    let seq = seven_digits(tail);
    let follows =
        matches!((*before, seq), (Some((letter, n)), Some(m)) if letter == tail[0] && letter != b'T' && m == n + 1);
    *before = seq.map(|m| (tail[0], m));
    follows
}

/// The LF-terminated lines of `src[from..to]` (`from` at a line's start, `to` after a
/// line feed or at the input's end), or `None` if that text holds a carriage return.
/// Lines of 80 columns are taken at a glance (the 80 bytes checked to hold no line feed
/// or carriage return, 8 at a time) and their section letter and sequence number
/// compared with the line before's (see [`Split::unchecked`]); others are found with
/// memchr. The first line is always unchecked.
fn split_lf(src: &[u8], from: usize, to: usize) -> Option<Split> {
    let src = &src[..to];
    let mut lines = Vec::with_capacity((to - from) / 81 + 1);
    let mut unchecked = Vec::new();
    let mut before = None;
    let mut s = from;
    while s < src.len() {
        if let Some(line) = src.get(s..s + 81).and_then(|l| l.first_chunk::<81>()) {
            if line[80] == b'\n' && !has_line_end(line) {
                if !continues(&mut before, &line[..80]) {
                    unchecked.push(lines.len());
                }
                lines.push(Line { start: s, end: s + 80, next: s + 81 });
                s += 81;
                continue;
            }
        }
        let k = memchr::memchr(b'\n', &src[s..]).unwrap_or(src.len() - s);
        if memchr::memchr(b'\r', &src[s..s + k]).is_some() {
            return None;
        }
        if !continues(&mut before, &src[s..s + k]) {
            unchecked.push(lines.len());
        }
        lines.push(Line { start: s, end: s + k, next: (s + k + 1).min(src.len()) });
        s += k + 1;
    }
    Some(Split { lines, unchecked })
}

/// Whether the first 80 bytes of `line` hold a line feed or a carriage return.
fn has_line_end(line: &[u8; 81]) -> bool {
    let mut any = 0u64;
    for c in line[..80].chunks_exact(8) {
        let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        // High bit of each zero byte (exact: no borrow between bytes).
        for x in [w ^ 0x0A0A_0A0A_0A0A_0A0A, w ^ 0x0D0D_0D0D_0D0D_0D0D] {
            any |= !(((x & 0x7F7F_7F7F_7F7F_7F7F) + 0x7F7F_7F7F_7F7F_7F7F) | x) & 0x8080_8080_8080_8080;
        }
    }
    any != 0
}

fn is_blank_line(b: &[u8]) -> bool {
    b.iter().all(|&c| c == b' ' || c == b'\t' || c == 0x1a)
}

/// A sequence number field (digits, maybe zero-padded).
fn sequence_number(field: &[u8]) -> Option<usize> {
    if field.is_empty() || field.len() > 7 || !field.iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some(field.iter().fold(0usize, |n, &d| n * 10 + usize::from(d - b'0')))
}

/// The number in columns 74–80 of a line whose columns 73–80 are `field`, if those seven
/// columns are digits after any leading blanks (the forms writers use, zero-padded or
/// not); `None` for anything else, which [`sequence_number`] then decides. Eight bytes
/// at once (SWAR), as the tokenizer reads digits.
fn seven_digits(field: [u8; 8]) -> Option<usize> {
    const LOW7: u64 = 0x7F7F_7F7F_7F7F_7F7F;
    let x = u64::from_le_bytes(field);
    let t = x ^ 0x2020_2020_2020_2020;
    // 0x80 in each byte of `t` that is zero, i.e. each blank of `x` (exact: no borrows).
    let z = !(((t & LOW7).wrapping_add(LOW7)) | t | LOW7);
    // 0xFF over the blanks of columns 74–80 (byte 0, column 73, is the section letter).
    let blanks = ((z >> 7) * 0xFF) & !0xFF;
    let lead = blanks >> 8;
    // Blanks must lead (a run from column 74), and a digit must follow them.
    if lead & lead.wrapping_add(1) != 0 || lead == 0x00FF_FFFF_FFFF_FFFF {
        return None;
    }
    // Blanks become '0' (0x20 | 0x10), the letter too; then every byte must be a digit.
    let v = ((x | (blanks & 0x1010_1010_1010_1010)) & !0xFF) | 0x30;
    let d = v ^ 0x3030_3030_3030_3030;
    let nd = (d.wrapping_add(0x7676_7676_7676_7676) | d) & 0x8080_8080_8080_8080;
    (nd == 0).then(|| lexer::eight_digit_value(d) as usize)
}

/// Finds the sections; checks letters, order and sequence numbers.
fn sections(src: &[u8], lines: &[Line], unchecked: &[usize]) -> Result<Layout> {
    const ORDER: [u8; 5] = [b'S', b'G', b'D', b'P', b'T'];
    let mut first = [usize::MAX; 5];
    let mut last = [0usize; 5];
    let mut current = 0usize;
    let mut terminate = None;
    // Lines the split confirmed are skipped: each continues the section of the line
    // before it, so only the section's end moves.
    let mut done = 0;
    for &k in unchecked.iter().chain(std::iter::once(&lines.len())) {
        if k > done {
            last[current] = k;
        }
        done = k + 1;
        let Some(l) = lines.get(k) else { break };
        let text = &src[l.start..l.end];
        if terminate.is_some() {
            if is_blank_line(text) {
                continue;
            }
            return Err(Error::Section {
                at: pos('T', k + 1, 1, None),
                expected: "nothing after the Terminate record",
                found: snippet(text),
            });
        }
        if text.len() < 73 {
            if is_blank_line(text) && k + 1 == lines.len() {
                continue;
            }
            let section = if current == 0 && first[0] == usize::MAX { '?' } else { ORDER[current] as char };
            return Err(Error::Section {
                at: pos(section, k + 1, text.len() + 1, None),
                expected: "a record with its section letter in column 73",
                found: format!("a line of {} characters", text.len()),
            });
        }
        let letter = text[72];
        let Some(s) = ORDER.iter().position(|&c| c == letter) else {
            let (expected, section) = match letter {
                b'B' | b'C' | b'F' => ("the fixed ASCII form (binary and compressed IGES are not supported)", '?'),
                _ => ("S, G, D, P or T in column 73", if k == 0 { '?' } else { ORDER[current] as char }),
            };
            return Err(Error::Section {
                at: pos(section, k + 1, 73, None),
                expected,
                found: (letter as char).to_string(),
            });
        };
        if s < current {
            return Err(Error::Section {
                at: pos(letter as char, k + 1, 73, None),
                expected: "sections in the order S, G, D, P, T",
                found: format!("{} after {}", letter as char, ORDER[current] as char),
            });
        }
        current = s;
        if first[s] == usize::MAX {
            first[s] = k;
        }
        last[s] = k + 1;
        // Columns 74–80: the line's number within its section. A line out of place (two P
        // lines swapped) would otherwise be read as other geometry; a blank field is
        // taken as correct (some writers leave it out).
        let expected = k - first[s] + 1;
        let seq = trim(&text[73..text.len().min(80)]);
        if !seq.is_empty() && sequence_number(seq) != Some(expected) {
            return Err(Error::Sequence {
                at: pos(letter as char, k + 1, 74, None),
                expected,
                found: String::from_utf8_lossy(seq).into_owned(),
            });
        }
        if s == 4 {
            terminate = Some(k);
        }
    }
    let Some(terminate) = terminate else {
        let line = lines.len();
        return Err(Error::Truncated {
            at: pos(ORDER[current] as char, line, 1, None),
            what: "no Terminate (T) record",
        });
    };
    // Empty sections sit where the next one starts.
    let range = |s: usize| {
        if first[s] == usize::MAX {
            let at = (s + 1..5).map(|t| first[t]).find(|&f| f != usize::MAX).unwrap_or(terminate);
            at..at
        } else {
            first[s]..last[s]
        }
    };
    let layout = Layout {
        start: range(0),
        global: range(1),
        directory: range(2),
        parameter: range(3),
        terminate,
        trailer: lines[terminate].next,
    };
    if layout.global.is_empty() {
        return Err(Error::Truncated { at: pos('G', layout.global.start + 1, 1, None), what: "no Global (G) section" });
    }
    Ok(layout)
}

fn lex_position(err: &LexError, map: &dyn Fn(usize) -> Position) -> Error {
    match err {
        LexError::Number { offset, found } => {
            Error::Syntax { at: map(*offset), expected: "a number or a Hollerith string", found: found.clone() }
        }
        LexError::Hollerith { offset, length } => {
            Error::Hollerith { at: map(*offset), length: *length, within: "record" }
        }
        LexError::Delimiter { offset, found } => {
            Error::Syntax { at: map(*offset), expected: "a parameter or record delimiter", found: found.clone() }
        }
        LexError::NoRecordEnd { offset } => {
            Error::Truncated { at: map(*offset), what: "the record ends without its record delimiter" }
        }
    }
}

/// Parses the Global section text (columns 1–72 of its lines, concatenated).
/// The Global section, and the warnings its reading gave.
///
/// A Hollerith string whose count runs past the end of the section (one Rhino export
/// writes the last string's count too large) is read as OCCT's reader reads it: the string
/// takes the rest of the section, and a [`Warning`] names the count's position.
fn global(src: &[u8], lines: &[Line], layout: &Layout) -> Result<(Global, Vec<Warning>)> {
    let mut text = Vec::with_capacity(layout.global.len() * G_WIDTH);
    for l in &lines[layout.global.clone()] {
        text.extend_from_slice(&src[l.start..l.start + G_WIDTH]);
    }
    let g0 = layout.global.start;
    let map = |off: usize| pos('G', g0 + off / G_WIDTH + 1, off % G_WIDTH + 1, None);
    let mut tokens = Vec::new();
    let mut warnings = Vec::new();
    // Parameters 1 and 2 name the delimiters, so they are read before the others.
    let mut i = 0;
    while i < text.len() && text[i] == b' ' {
        i += 1;
    }
    let mut delimiter = |i: &mut usize, pd: Option<u8>, default: u8| -> Result<u8> {
        if let Some((n, first)) = hollerith_at(&text, *i) {
            if n != 1 || first >= text.len() {
                return Err(Error::Syntax {
                    at: map(*i),
                    expected: "a one-character Hollerith delimiter (1Hx)",
                    found: snippet(&text[*i..]),
                });
            }
            tokens.push(Token { offset: *i as u32, raw: Raw::Text { start: first as u32, len: 1 } });
            *i = first + 1;
            Ok(text[first])
        } else {
            // Defaulted: the next character must be the parameter delimiter.
            let pd = pd.unwrap_or(b',');
            if text.get(*i) != Some(&pd) {
                return Err(Error::Syntax {
                    at: map(*i),
                    expected: "a delimiter given as 1Hx or defaulted",
                    found: snippet(&text[(*i).min(text.len())..]),
                });
            }
            tokens.push(Token { offset: *i as u32, raw: Raw::Default });
            Ok(default)
        }
    };
    let pd = delimiter(&mut i, None, b',')?;
    if text.get(i) != Some(&pd) {
        return Err(Error::Syntax {
            at: map(i),
            expected: "the parameter delimiter after parameter 1",
            found: snippet(&text[i.min(text.len())..]),
        });
    }
    i += 1;
    let rd = delimiter(&mut i, Some(pd), b';')?;
    match text.get(i) {
        Some(&c) if c == rd => {}
        Some(&c) if c == pd => match tokenize(&text, i + 1, pd, rd, &mut tokens) {
            Ok(_) => {}
            Err(LexError::Hollerith { offset, length }) => {
                let (_, first) = hollerith_at(&text, offset).expect("the lexer saw a count here");
                let kept = text.len() - first;
                tokens.push(Token { offset: offset as u32, raw: Raw::Text { start: first as u32, len: kept as u32 } });
                warnings.push(Warning {
                    at: map(offset),
                    message: format!(
                        "Hollerith count {length} runs past the end of the global section; \
                             the string was read to the end of the section ({kept} characters), as OCCT reads it"
                    ),
                });
            }
            Err(e) => return Err(lex_position(&e, &map)),
        },
        _ => {
            return Err(Error::Syntax {
                at: map(i),
                expected: "a delimiter after parameter 2",
                found: snippet(&text[i.min(text.len())..]),
            })
        }
    }
    Ok((Global { text, tokens, parameter_delimiter: pd, record_delimiter: rd }, warnings))
}

/// Reads an 8-column integer field; blanks are 0.
fn field(line: &[u8], k: usize, at: Position) -> Result<i64> {
    let f = &line[8 * k..8 * k + 8];
    let t = trim(f);
    if t.is_empty() {
        return Ok(0);
    }
    match lexer::parse_number(t) {
        Some(Raw::Integer(n)) => Ok(n),
        _ => Err(Error::Syntax { at, expected: "an integer field", found: snippet(f) }),
    }
}

fn trim(b: &[u8]) -> &[u8] {
    let s = b.iter().position(|&c| c != b' ').unwrap_or(b.len());
    let e = b.iter().rposition(|&c| c != b' ').map_or(s, |e| e + 1);
    &b[s..e]
}

fn status(f: &[u8], at: Position) -> Result<Status> {
    let mut v = [0u8; 4];
    for (k, pair) in f.chunks(2).enumerate() {
        let mut n = 0u8;
        for &c in pair {
            n = match c {
                b' ' => n * 10,
                b'0'..=b'9' => n * 10 + (c - b'0'),
                _ => {
                    return Err(Error::Syntax { at, expected: "an 8-digit status number", found: snippet(f) });
                }
            };
        }
        v[k] = n;
    }
    Ok(Status { blank: v[0], subordinate: v[1], entity_use: v[2], hierarchy: v[3] })
}

fn directory(a: &[u8], b: &[u8], line: usize, entries: usize) -> Result<Directory> {
    let at = |l: usize, k: usize| pos('D', l, 8 * k + 1, Some((2 * entries + 1) as u32));
    let ty = field(a, 0, at(line, 0))?;
    let entity_type = u32::try_from(ty).map_err(|_| Error::Syntax {
        at: at(line, 0),
        expected: "a non-negative entity type",
        found: ty.to_string(),
    })?;
    let ty2 = field(b, 0, at(line + 1, 0))?;
    if ty2 != ty && !trim(&b[0..8]).is_empty() {
        return Err(Error::Mismatch {
            at: at(line + 1, 0),
            expected: format!("entity type {ty} (field 1)"),
            found: format!("entity type {ty2} (field 11)"),
        });
    }
    Ok(Directory {
        entity_type,
        parameter_data: field(a, 1, at(line, 1))?,
        structure: field(a, 2, at(line, 2))?,
        line_font: field(a, 3, at(line, 3))?,
        level: field(a, 4, at(line, 4))?,
        view: field(a, 5, at(line, 5))?,
        transform: field(a, 6, at(line, 6))?,
        label_display: field(a, 7, at(line, 7))?,
        status: status(&a[64..72], at(line, 8))?,
        line_weight: field(b, 1, at(line + 1, 1))?,
        color: field(b, 2, at(line + 1, 2))?,
        parameter_lines: field(b, 3, at(line + 1, 3))?,
        form: field(b, 4, at(line + 1, 4))?,
        label: String::from_utf8_lossy(trim(&b[56..64])).into_owned(),
        subscript: field(b, 8, at(line + 1, 8))?,
    })
}

/// Reads the whole document, taking ownership of the bytes (kept for writing).
pub(crate) fn parse(source: Vec<u8>) -> Result<Document> {
    let Split { lines, unchecked } = split_lines(&source);
    let src = Arc::new(Source { bytes: source, lines });
    let (bytes, lines) = (&src.bytes[..], &src.lines[..]);
    let layout = sections(bytes, lines, &unchecked)?;
    drop(unchecked);
    let global = global(bytes, lines, &layout)?;
    let (pd, rd) = (global.0.parameter_delimiter, global.0.record_delimiter);

    let d = layout.directory.clone();
    if d.len() % 2 == 1 {
        return Err(Error::Truncated {
            at: pos('D', d.end, 1, None),
            what: "the D section has an odd number of lines (each entry has two)",
        });
    }
    let n = d.len() / 2;
    let n_p = layout.parameter.len();
    let p0 = layout.parameter.start;
    // Each entry and its record are read on their own, in parallel; the first error in
    // directory order is reported, as a sequential read would.
    let read_entity = |k: usize| -> Result<Entity> {
        let la = d.start + 2 * k;
        let a = &bytes[lines[la].start..lines[la].end];
        let b = &bytes[lines[la + 1].start..lines[la + 1].end];
        let dir = directory(a, b, la + 1, k)?;
        let id = EntityId::from_index(k);
        let (first, count) = (dir.parameter_data, dir.parameter_lines);
        let fits = first >= 1 && count >= 1 && first.checked_add(count).is_some_and(|e| e - 1 <= n_p as i64);
        if !fits {
            return Err(Error::ParamRange {
                at: pos('D', la + 1, 9, Some(id.0)),
                first,
                count,
                available: n_p,
                detail: "",
            });
        }
        let (p_first, p_count) = ((first - 1) as usize, count as usize);
        let range = p0 + p_first..p0 + p_first + p_count;
        let rec = lexer::RecordLines { bytes, lines: &lines[range.clone()], width: P_WIDTH };
        // Columns 65–72 of the first line point back to the entry.
        let first_line = &bytes[lines[p0 + p_first].start..lines[p0 + p_first].end];
        let back = trim(&first_line[64..72]);
        if !back.is_empty() && lexer::parse_number(back) != Some(Raw::Integer(i64::from(id.0))) {
            return Err(Error::Mismatch {
                at: pos('P', p0 + p_first + 1, 65, Some(id.0)),
                expected: format!("a record of DE {}", id.0),
                found: format!("a record of DE {}", String::from_utf8_lossy(back)),
            });
        }
        let p_line = p0 + p_first + 1;
        let map = |off: usize| pos('P', p_line + off / P_WIDTH, off % P_WIDTH + 1, Some(id.0));
        let lexer::Record { tokens, text, strings } =
            lexer::tokenize_record(&rec, pd, rd).map_err(|e| lex_position(&e, &map))?;
        if tokens.first() != Some(Raw::Integer(i64::from(dir.entity_type))) {
            return Err(Error::Mismatch {
                at: map(0),
                expected: format!("entity type {} first", dir.entity_type),
                found: snippet(&first_line[..16]),
            });
        }
        // Long records keep no copy of their text: it is built from the input if asked for.
        let text = match text {
            Some(t) => RecordText::owned(t),
            None => RecordText::lazy(Arc::clone(&src), range),
        };
        Ok(Entity {
            id,
            directory: dir,
            text,
            tokens,
            strings,
            delimiters: (pd, rd),
            p_first,
            p_count,
            p_line,
            d_line: la + 1,
            new_lines: None,
            directory_changed: false,
            template: None,
        })
    };
    let entities: Vec<Entity> = {
        use rayon::prelude::*;
        let read: Vec<Result<Entity>> = (0..n).into_par_iter().map(read_entity).collect();
        read.into_iter().collect::<Result<_>>()?
    };
    // Directory pointers that must name an entry.
    for e in &entities {
        let dir = &e.directory;
        let checks = [
            (dir.transform, 49, true),
            (dir.view, 41, true),
            (dir.label_display, 57, true),
            (-dir.structure, 17, false),
            (-dir.line_font, 25, false),
            (-dir.level, 33, false),
        ];
        for (target, column, positive_is_pointer) in checks {
            let is_pointer = if positive_is_pointer { target != 0 } else { target > 0 };
            if is_pointer && !(target > 0 && target % 2 == 1 && ((target - 1) / 2) < n as i64) {
                return Err(Error::DanglingPointer { at: e.directory_position(column), target, entries: n });
            }
        }
        if dir.color < 0 && !(-dir.color % 2 == 1 && ((-dir.color - 1) / 2) < n as i64) {
            return Err(Error::DanglingPointer {
                at: pos('D', e.d_line + 1, 17, Some(e.id.0)),
                target: dir.color,
                entries: n,
            });
        }
        if dir.transform > 0 && entities[((dir.transform - 1) / 2) as usize].entity_type() != 124 {
            return Err(Error::Mismatch {
                at: e.directory_position(49),
                expected: "a pointer to a transformation matrix (124)".into(),
                found: format!("type {}", entities[((dir.transform - 1) / 2) as usize].entity_type()),
            });
        }
    }
    // The P section in line order: entity records and any lines nobody points to.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&k| entities[k].p_first);
    let mut p_blocks = Vec::with_capacity(n);
    let mut next = 0usize;
    for &k in &order {
        let e = &entities[k];
        if e.p_first < next {
            return Err(Error::ParamRange {
                at: pos('D', e.d_line, 9, Some(e.id.0)),
                first: e.p_first as i64 + 1,
                count: e.p_count as i64,
                available: n_p,
                detail: " (overlaps another entity's lines)",
            });
        }
        if e.p_first > next {
            p_blocks.push(PBlock::Loose(next..e.p_first));
        }
        p_blocks.push(PBlock::Entity(k));
        next = e.p_first + e.p_count;
    }
    if next < n_p {
        p_blocks.push(PBlock::Loose(next..n_p));
    }
    let zero_padded = lines.first().is_some_and(|l| bytes.get(l.start + 73) == Some(&b'0'));
    let (global, warnings) = global;
    let doc = Document { src, layout, global, entities, p_blocks, edited: false, zero_padded, warnings };
    doc.check_terminate()?;
    Ok(doc)
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The eight-byte sequence-number reader agrees with the general one wherever it
        /// answers (and answers on the usual forms).
        #[test]
        fn seven_digits_agrees_with_sequence_number(
            cols in proptest::collection::vec(proptest::sample::select(vec![b' ', b'0', b'1', b'5', b'9', b'P', b'/', b':', 0x7F, 0xB0]), 8),
        ) {
            let f: [u8; 8] = cols.try_into().unwrap();
            if let Some(n) = seven_digits(f) {
                proptest::prop_assert_eq!(Some(n), sequence_number(trim(&f[1..])));
            }
        }

        #[test]
        fn seven_digits_reads_both_paddings(n in 1usize..10_000_000, letter in proptest::sample::select(vec![b'S', b'G', b'D', b'P', b'T'])) {
            for text in [format!("{n:07}"), format!("{n:>7}")] {
                let mut f = [letter; 8];
                f[1..].copy_from_slice(text.as_bytes());
                proptest::prop_assert_eq!(seven_digits(f), Some(n));
            }
        }
    }

    /// The splitter as it was before the split checked sequence numbers and ran on two
    /// threads: the reference for [`split_lines`].
    fn reference_split(src: &[u8]) -> Vec<(usize, usize, usize)> {
        let mut out = Vec::new();
        let has_cr = src.contains(&b'\r');
        if !has_cr && !src.contains(&b'\n') && src.len() > 80 {
            for s in (0..src.len()).step_by(80) {
                let e = (s + 80).min(src.len());
                out.push((s, e, e));
            }
            return out;
        }
        let mut s = 0;
        for i in 0..src.len() {
            if src[i] == b'\n' {
                let end = if has_cr && i > s && src[i - 1] == b'\r' { i - 1 } else { i };
                out.push((s, end, i + 1));
                s = i + 1;
            } else if has_cr && src[i] == b'\r' && src.get(i + 1) != Some(&b'\n') {
                out.push((s, i, i + 1));
                s = i + 1;
            }
        }
        if s < src.len() {
            out.push((s, src.len(), src.len()));
        }
        out
    }

    /// A line of a file for the split tests: an 80-column line of section `letter`
    /// numbered `n` (zero-padded or blank-padded), or something else.
    fn test_line(kind: u8, letter: u8, n: usize) -> Vec<u8> {
        let mut l = vec![b'x'; 72];
        l.push(letter);
        match kind {
            0 => l.extend_from_slice(format!("{n:07}").as_bytes()),
            1 => l.extend_from_slice(format!("{n:>7}").as_bytes()),
            2 => l.extend_from_slice(format!("{:07}", n + 1).as_bytes()),
            3 => l.extend_from_slice(b"       "),
            4 => l.truncate(30),
            5 => l.extend_from_slice(format!("{n:07}  ").as_bytes()),
            _ => l.extend_from_slice(format!("{n:<7}").as_bytes()),
        }
        l.push(b'\n');
        l
    }

    /// Lines of sections S, G, D, P (`p_lines` of them), T, mostly well numbered, some
    /// not; with a line end changed to CRLF or CR where asked.
    fn test_file(kinds: &[(u8, u8)], p_lines: usize, cr: Option<(usize, bool)>) -> Vec<u8> {
        let mut src = Vec::new();
        let mut k = 0;
        for (section, letter) in [b'S', b'G', b'D', b'P', b'T'].iter().enumerate() {
            let count = if section == 3 { p_lines } else { 2 };
            for n in 1..=count {
                let (kind, odd) = kinds[k % kinds.len()];
                k += 1;
                let l = if odd == 1 { b'P' } else { *letter };
                src.extend(test_line(kind, l, n));
            }
        }
        if let Some((at, crlf)) = cr {
            let at = at % src.len();
            if let Some(k) = src[at..].iter().position(|&c| c == b'\n') {
                if crlf {
                    src.insert(at + k, b'\r');
                } else {
                    src[at + k] = b'\r';
                }
            }
        }
        src
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
        /// The split gives the lines the plain splitter gives, and the layout (or the
        /// error) [`sections`] finds from its unchecked lines is the one it finds
        /// looking at every line.
        #[test]
        fn split_and_sections_agree_with_the_plain_reading(
            kinds in proptest::collection::vec((proptest::prop_oneof![8 => proptest::prelude::Just(0u8), 1 => 0u8..7], proptest::prop_oneof![20 => proptest::prelude::Just(0u8), 1 => proptest::prelude::Just(1u8)]), 1..40),
            // Over 1 MiB (14 000 lines) the split runs on two threads.
            p_lines in proptest::prop_oneof![3 => 1usize..120, 1 => proptest::prelude::Just(14_000usize)],
            cr in proptest::option::of((0usize..2_000_000, proptest::bool::ANY)),
        ) {
            let src = test_file(&kinds, p_lines, cr);
            let split = split_lines(&src);
            let got: Vec<_> = split.lines.iter().map(|l| (l.start, l.end, l.next)).collect();
            proptest::prop_assert_eq!(&got, &reference_split(&src));
            proptest::prop_assert!(split.unchecked.windows(2).all(|w| w[0] < w[1]));
            let all: Vec<usize> = (0..split.lines.len()).collect();
            let fast = sections(&src, &split.lines, &split.unchecked);
            let slow = sections(&src, &split.lines, &all);
            proptest::prop_assert_eq!(format!("{fast:?}"), format!("{slow:?}"));
        }
    }

    #[test]
    fn line_endings() {
        let l = split_lines(b"a\r\nb\nc\rd").lines;
        let spans: Vec<_> = l.iter().map(|l| (l.start, l.end, l.next)).collect();
        assert_eq!(spans, vec![(0, 1, 3), (3, 4, 5), (5, 6, 7), (7, 8, 8)]);
    }

    #[test]
    fn eighty_column_lines_and_others() {
        // 80-column lines (taken at a glance), a short one, a long one, a line feed
        // inside what would be an 80-column line, no final line feed.
        let mut src = Vec::new();
        let mut want = Vec::new();
        for len in [80usize, 80, 12, 95, 80, 30, 49, 80, 0, 80, 7] {
            let s = src.len();
            src.extend(std::iter::repeat_n(b'x', len));
            want.push((s, s + len, s + len + 1));
            src.push(b'\n');
        }
        src.extend_from_slice(b"tail");
        want.push((src.len() - 4, src.len(), src.len()));
        let got: Vec<_> = split_lines(&src).lines.iter().map(|l| (l.start, l.end, l.next)).collect();
        assert_eq!(got, want);
    }
}
