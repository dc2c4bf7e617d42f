//! Writing: the unchanged document verbatim, edited documents with renumbered P lines,
//! and the text form of parameter values.

mod new;
mod orphans;

pub use new::DocumentBuilder;

use crate::document::{Document, PBlock, Value};
use crate::read::P_WIDTH;

/// The shortest IGES real constant that reads back to the same `f64` bits: always with a
/// decimal point, and an `E` exponent outside `1e-5 ≤ |x| < 1e15`.
///
/// ```
/// use cadmorph_iges::write::format_real;
/// assert_eq!(format_real(1.0), "1.");
/// assert_eq!(format_real(-0.25), "-0.25");
/// assert_eq!(format_real(1e-7), "1.E-7");
/// assert_eq!(format_real(0.1 + 0.2).parse::<f64>().unwrap(), 0.1 + 0.2);
/// ```
pub fn format_real(x: f64) -> String {
    let mut out = Vec::with_capacity(24);
    write_real(x, &mut out);
    String::from_utf8(out).expect("ASCII")
}

/// [`format_real`] appended to `out`, without allocating.
pub(crate) fn write_real(x: f64, out: &mut Vec<u8>) {
    cadmorph_brep::real::write_real(x, (1e-5, 1e15), out);
}

/// The text of one parameter value.
pub(crate) fn format_value(v: &Value, out: &mut Vec<u8>) {
    match v {
        Value::Default => {}
        Value::Integer(i) => out.extend_from_slice(itoa::Buffer::new().format(*i).as_bytes()),
        Value::Real(x) => write_real(*x, out),
        Value::Text(t) => {
            out.extend_from_slice(itoa::Buffer::new().format(t.len()).as_bytes());
            out.push(b'H');
            out.extend_from_slice(t);
        }
    }
}

/// A record laid out in lines: their text one after the other, and where each ends.
pub(crate) struct Layout {
    /// Every line's text, concatenated.
    pub text: Vec<u8>,
    /// The end of each line in `text`.
    pub ends: Vec<usize>,
}

impl Layout {
    /// The lines.
    pub fn lines(&self) -> impl Iterator<Item = &[u8]> {
        let starts = std::iter::once(0).chain(self.ends.iter().copied());
        starts.zip(&self.ends).map(|(a, &b)| &self.text[a..b])
    }
}

/// Lays a record out in lines of at most `width` columns: each value followed by the
/// parameter delimiter, the last by the record delimiter. Numbers never straddle lines;
/// strings longer than a line are split (Hollerith strings may continue on the next line).
pub(crate) fn layout(values: &[Value], pd: u8, rd: u8, width: usize) -> Layout {
    let mut text = Vec::with_capacity(values.len() * 20);
    let mut ends = Vec::new();
    lay_out(values, pd, rd, width, &mut text, |text, _| ends.push(text.len()));
    Layout { text, ends }
}

/// [`layout`] written straight into `out`: each line's text is appended, then
/// `end_line(out, start)` is called with the offset where that line's text starts, and
/// may append what closes the line (a P line's padding, pointer and sequence number).
/// Each value is formatted in place; only one that does not fit its line moves.
pub(crate) fn lay_out(
    values: &[Value],
    pd: u8,
    rd: u8,
    width: usize,
    out: &mut Vec<u8>,
    mut end_line: impl FnMut(&mut Vec<u8>, usize),
) {
    let mut start = out.len();
    let mut tok = Vec::new();
    for (k, v) in values.iter().enumerate() {
        let at = out.len();
        format_value(v, out);
        out.push(if k + 1 == values.len() { rd } else { pd });
        let len = out.len() - at;
        if at - start + len <= width {
            continue;
        }
        tok.clear();
        tok.extend_from_slice(&out[at..]);
        out.truncate(at);
        if len <= width && !matches!(v, Value::Text(_)) {
            // To the next line whole.
            end_line(out, start);
            start = out.len();
            out.extend_from_slice(&tok);
            continue;
        }
        // A long string: fill the line, continue on the next ones.
        let mut rest = &tok[..];
        loop {
            let room = width - (out.len() - start);
            let take = room.min(rest.len());
            out.extend_from_slice(&rest[..take]);
            rest = &rest[take..];
            if rest.is_empty() {
                break;
            }
            end_line(out, start);
            start = out.len();
        }
    }
    if values.is_empty() {
        out.push(rd);
    }
    end_line(out, start);
}

/// [`layout`] as one vector per line.
pub(crate) fn layout_record(values: &[Value], pd: u8, rd: u8, width: usize) -> Vec<Vec<u8>> {
    layout(values, pd, rd, width).lines().map(<[u8]>::to_vec).collect()
}

/// Appends `n` right-justified in `width` columns (`zero_padded`: with leading zeros).
pub(crate) fn put_number(out: &mut Vec<u8>, n: usize, width: usize, zero_padded: bool) {
    let mut b = itoa::Buffer::new();
    let s = b.format(n).as_bytes();
    out.extend(std::iter::repeat_n(if zero_padded { b'0' } else { b' ' }, width.saturating_sub(s.len())));
    out.extend_from_slice(s);
}

/// A sequence-number field (7 columns) in the file's style.
pub(crate) fn seq(n: usize, zero_padded: bool) -> String {
    if zero_padded {
        format!("{n:07}")
    } else {
        format!("{n:>7}")
    }
}

fn put_line(out: &mut Vec<u8>, body: &[u8], width: usize, tail: &[u8], eol: &[u8]) {
    out.extend_from_slice(body);
    out.resize(out.len() + width.saturating_sub(body.len()), b' ');
    out.extend_from_slice(tail);
    out.extend_from_slice(eol);
}

/// Replaces the 8-column field `k` of a D line by `value`, right-justified.
fn patch_field(line: &mut [u8], k: usize, value: i64) {
    let s = format!("{value:>8}");
    if s.len() == 8 {
        line[8 * k..8 * k + 8].copy_from_slice(s.as_bytes());
    }
}

/// Writes the document (see [`Document::write`]): entities the edits orphaned become
/// Null entities (see [`orphans`]).
pub(crate) fn write(doc: &Document) -> Vec<u8> {
    if !doc.edited {
        return doc.src.bytes.clone();
    }
    let orphans = doc.orphans();
    if orphans.is_empty() {
        return write_edited(doc);
    }
    let mut d = doc.clone();
    for k in orphans {
        let id = d.entities[k].id;
        // A one-value record cannot fail to lay out or read back.
        if d.set_values(id, vec![Value::Integer(0)], Some(0)).is_ok() {
            let dir = &mut d.entities[k].directory;
            (dir.structure, dir.line_font, dir.level, dir.view, dir.transform, dir.label_display, dir.color) =
                (0, 0, 0, 0, 0, 0, 0);
        }
    }
    write_edited(&d)
}

fn write_edited(doc: &Document) -> Vec<u8> {
    let layout = &doc.layout;
    let eol = doc.eol().to_vec();
    let mut out = Vec::with_capacity(doc.src.bytes.len() + 4096);
    // S and G lines verbatim.
    let head_end = doc.src.lines[layout.directory.start.min(layout.terminate)].start;
    let head_start = doc.src.lines.get(layout.start.start).map_or(0, |l| l.start);
    out.extend_from_slice(&doc.src.bytes[head_start..head_end]);

    // New P positions.
    let mut new_first = vec![0usize; doc.entities.len()];
    let mut new_count = vec![0usize; doc.entities.len()];
    let mut next = 0usize;
    for b in &doc.p_blocks {
        match b {
            PBlock::Entity(k) => {
                let e = &doc.entities[*k];
                new_first[*k] = next;
                new_count[*k] = e.new_lines.as_ref().map_or(e.p_count, Vec::len);
                next += new_count[*k];
            }
            PBlock::Loose(r) => next += r.len(),
        }
    }
    let p_total = next;

    // D section.
    for (k, e) in doc.entities.iter().enumerate() {
        if let Some(t) = e.template {
            // An appended copy: the lines of the entity it copies, with its own P
            // pointer, line count, type and form, and sequence numbers.
            let lt = layout.directory.start + 2 * t;
            for (half, li) in [(0, lt), (1, lt + 1)] {
                let mut line = doc.line_bytes(li).to_vec();
                if line.len() < 80 {
                    line.resize(80, b' ');
                }
                if half == 0 {
                    patch_field(&mut line, 0, i64::from(e.directory.entity_type));
                    patch_field(&mut line, 1, new_first[k] as i64 + 1);
                } else {
                    patch_field(&mut line, 0, i64::from(e.directory.entity_type));
                    patch_field(&mut line, 3, new_count[k] as i64);
                    patch_field(&mut line, 4, e.directory.form);
                }
                line[72] = b'D';
                line[73..80].copy_from_slice(seq(2 * k + 1 + half, doc.zero_padded).as_bytes());
                out.extend_from_slice(&line);
                out.extend_from_slice(&eol);
            }
            continue;
        }
        let la = layout.directory.start + 2 * k;
        let moved = new_first[k] != e.p_first || new_count[k] != e.p_count;
        if !moved && !e.directory_changed {
            out.extend_from_slice(doc.line_with_eol(la));
            out.extend_from_slice(doc.line_with_eol(la + 1));
            continue;
        }
        let mut a = doc.line_bytes(la).to_vec();
        let mut b = doc.line_bytes(la + 1).to_vec();
        patch_field(&mut a, 1, new_first[k] as i64 + 1);
        patch_field(&mut b, 3, new_count[k] as i64);
        if e.directory_changed {
            patch_field(&mut a, 0, i64::from(e.directory.entity_type));
            patch_field(&mut b, 0, i64::from(e.directory.entity_type));
            patch_field(&mut b, 4, e.directory.form);
            if e.directory.entity_type == 0 {
                // A Null entity (an orphan): its pointer fields no longer point anywhere.
                let d = &e.directory;
                for (k, v) in [
                    (2, d.structure),
                    (3, d.line_font),
                    (4, d.level),
                    (5, d.view),
                    (6, d.transform),
                    (7, d.label_display),
                ] {
                    patch_field(&mut a, k, v);
                }
                patch_field(&mut b, 2, d.color);
            }
        }
        out.extend_from_slice(&a);
        out.extend_from_slice(&doc.src.bytes[doc.src.lines[la].end..doc.src.lines[la].next]);
        out.extend_from_slice(&b);
        out.extend_from_slice(&doc.src.bytes[doc.src.lines[la + 1].end..doc.src.lines[la + 1].next]);
    }

    // P section.
    let p0 = layout.parameter.start;
    let mut n = 0usize;
    let copy_line = |out: &mut Vec<u8>, li: usize, n: usize| {
        let l = doc.src.lines[li];
        if li - p0 == n {
            out.extend_from_slice(&doc.src.bytes[l.start..l.next]);
        } else {
            let text = &doc.src.bytes[l.start..l.end];
            out.extend_from_slice(&text[..73]);
            out.extend_from_slice(seq(n + 1, doc.zero_padded).as_bytes());
            if text.len() > 80 {
                out.extend_from_slice(&text[80..]);
            }
            out.extend_from_slice(&doc.src.bytes[l.end..l.next]);
        }
    };
    for b in &doc.p_blocks {
        match b {
            PBlock::Loose(r) => {
                for li in r.clone() {
                    copy_line(&mut out, p0 + li, n);
                    n += 1;
                }
            }
            PBlock::Entity(k) => {
                let e = &doc.entities[*k];
                match &e.new_lines {
                    None => {
                        for li in e.p_first..e.p_first + e.p_count {
                            copy_line(&mut out, p0 + li, n);
                            n += 1;
                        }
                    }
                    Some(new) => {
                        let back = if e.template.is_some() {
                            let mut b = Vec::with_capacity(8);
                            put_number(&mut b, e.id.0 as usize, 8, doc.zero_padded);
                            b
                        } else {
                            doc.line_bytes(p0 + e.p_first)[64..72].to_vec()
                        };
                        for body in new {
                            let mut tail = back.clone();
                            tail.push(b'P');
                            tail.extend_from_slice(seq(n + 1, doc.zero_padded).as_bytes());
                            put_line(&mut out, body, P_WIDTH, &tail, &eol);
                            n += 1;
                        }
                    }
                }
            }
        }
    }

    // T record: patch the D and P counts.
    let t = layout.terminate;
    let old_p = layout.parameter.len();
    let d_total = 2 * doc.entities.len();
    if p_total == old_p && d_total == layout.directory.len() {
        out.extend_from_slice(doc.line_with_eol(t));
    } else {
        let mut line = doc.line_bytes(t).to_vec();
        let s = seq(p_total, doc.zero_padded);
        if line.len() >= 32 && line[24] == b'P' && s.len() == 7 {
            line[25..32].copy_from_slice(s.as_bytes());
        }
        let s = seq(d_total, doc.zero_padded);
        if line.len() >= 24 && line[16] == b'D' && s.len() == 7 {
            line[17..24].copy_from_slice(s.as_bytes());
        }
        out.extend_from_slice(&line);
        out.extend_from_slice(&doc.src.bytes[doc.src.lines[t].end..doc.src.lines[t].next]);
    }
    out.extend_from_slice(&doc.src.bytes[layout.trailer..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_round_trip() {
        for x in [0.0, -0.0, 1.0, -1.5, 1e-5, 9.99e-6, 1e15, 123456789.125, 1e300, -4.9e-324, 0.1 + 0.2] {
            let s = format_real(x);
            assert!(s.contains('.'), "{s}");
            let back = crate::read::lexer::parse_number(s.as_bytes());
            assert_eq!(back, Some(crate::read::lexer::Raw::Real(x)), "{s}");
        }
    }

    #[test]
    fn records_fill_lines() {
        let v: Vec<Value> = (0..40).map(|i| Value::Real(i as f64 * 0.125)).collect();
        let lines = layout_record(&v, b',', b';', 64);
        assert!(lines.iter().all(|l| l.len() <= 64));
        assert_eq!(*lines.last().unwrap().last().unwrap(), b';');
        let long = vec![Value::Integer(406), Value::Text(vec![b'x'; 150])];
        let lines = layout_record(&long, b',', b';', 64);
        assert_eq!(lines.iter().map(Vec::len).sum::<usize>(), 4 + 4 + 150 + 1);
    }
}
