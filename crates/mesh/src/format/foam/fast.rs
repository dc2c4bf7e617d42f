//! The fast path of the large ASCII lists of a `polyMesh` (`points`, `faces`, `owner`,
//! `neighbour`): the list body is cut at record boundaries into pieces; a first parallel
//! pass counts each piece's records, and a second parses them on bytes, without the
//! general tokenizer, straight into their place in the output (no per-piece buffers to
//! join: for a 10⁶-cell mesh those copies, and the fresh pages they take, cost as much
//! as the parse).
//!
//! The fast path takes only the plain layout OpenFOAM writes (one record after another,
//! separated by white space; unsigned labels; no comments inside the list). Anything
//! else — a comment, a sign, a record that does not close where it should, a count that
//! does not match — makes it return `None`, and the caller parses the file again with the
//! general lexer ([`super::file`]), which gives the same values and, for a bad file, the
//! error with its line. So the fast path changes speed, never results.
//!
//! Pieces are cut only where a record must start: at the start of a line that begins a
//! one-line record (`4(` for a face, `(` for a point). Inside OpenFOAM's multi-line form of a
//! long face (`12\n(\n3\n…\n)`) no line has that shape, so a cut never falls inside a
//! record. Written by hand because no crate parses these lists; `memchr` finds the
//! lines.

use std::ops::Range;

use nalgebra::Point3;
use rayon::prelude::*;

/// Bodies smaller than this are parsed in one piece (small in tests, so that their short
/// lists are cut into many pieces).
const MIN_PIECE: usize = if cfg!(test) { 64 } else { 1 << 20 };

#[inline]
pub(super) fn is_ws(c: u8) -> bool {
    matches!(c, b' ' | b'\n' | b'\t' | b'\r' | b'\x0b' | b'\x0c')
}

/// A cursor over `b[..end]`.
pub(super) struct Scan<'a> {
    pub(super) b: &'a [u8],
    pub(super) pos: usize,
    pub(super) end: usize,
}

impl Scan<'_> {
    #[inline]
    pub(super) fn ws(&mut self) {
        while self.pos < self.end && is_ws(self.b[self.pos]) {
            self.pos += 1;
        }
    }

    #[inline]
    pub(super) fn peek(&self) -> Option<u8> {
        (self.pos < self.end).then(|| self.b[self.pos])
    }

    /// An unsigned decimal label of 1 to 18 digits, not followed by a digit.
    #[inline]
    pub(super) fn uint(&mut self) -> Option<usize> {
        if self.pos + 8 <= self.end {
            if let Some(w) = self.b.get(self.pos..self.pos + 8) {
                let w = u64::from_le_bytes([w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]]);
                if let Some((v, len)) = swar_digits(w) {
                    self.pos += len;
                    return Some(v as usize);
                }
            }
        }
        self.uint_loop()
    }

    /// [`Scan::uint`] a digit at a time (near the end, or for 8 digits or more).
    fn uint_loop(&mut self) -> Option<usize> {
        let start = self.pos;
        let mut v: u64 = 0;
        while self.pos < self.end {
            let d = self.b[self.pos].wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            v = v * 10 + d as u64;
            self.pos += 1;
        }
        let len = self.pos - start;
        (1..=18).contains(&len).then_some(v as usize)
    }

    /// [`Scan::uint`] of a label below 2³².
    #[inline]
    pub(super) fn label(&mut self) -> Option<u32> {
        u32::try_from(self.uint()?).ok()
    }

    #[inline]
    pub(super) fn punct(&mut self, c: u8) -> Option<()> {
        (self.peek() == Some(c)).then(|| self.pos += 1)
    }

    /// A point record `(x y z)` at the cursor (white space allowed inside).
    #[inline]
    pub(super) fn point(&mut self) -> Option<Point3<f64>> {
        self.punct(b'(')?;
        let mut c = [0.0; 3];
        for v in &mut c {
            self.ws();
            *v = self.real()?;
        }
        self.ws();
        self.punct(b')')?;
        Some(Point3::new(c[0], c[1], c[2]))
    }

    /// A number token (up to white space or `)`), parsed as [`real`] does.
    pub(super) fn real(&mut self) -> Option<f64> {
        // The common case in one pass: `fast-float2` reads the longest number at the
        // cursor; when white space, `)` or the end follows and the value is finite, that
        // number is the whole token, of [`real`]'s alphabet, and `real` reads it the same
        // way. Anything else (`nan`, `inf`, `1x`) goes through `real`.
        if let Ok((v, len)) = fast_float2::parse_partial::<f64, _>(&self.b[self.pos..self.end]) {
            let next = self.pos + len;
            if len > 0 && v.is_finite() && (next == self.end || is_ws(self.b[next]) || self.b[next] == b')') {
                self.pos = next;
                return Some(v);
            }
        }
        let start = self.pos;
        while self.pos < self.end && !is_ws(self.b[self.pos]) && self.b[self.pos] != b')' {
            self.pos += 1;
        }
        real(&self.b[start..self.pos])
    }
}

/// The run of 1 to 7 decimal digits that starts the 8 bytes `w` (little-endian: the
/// first byte lowest) and is followed by a non-digit among them: its value and length.
/// `None` when `w` starts with a non-digit or holds 8 digits.
#[inline]
fn swar_digits(w: u64) -> Option<(u64, usize)> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    // A byte is a digit when its high nibble is 3 and adding 6 keeps it so (0x30–0x39). A
    // carry out of a byte ≥ 0xFA can only spoil the bytes after that non-digit.
    let hi = 0xF0 * ONES;
    let non_digit = ((w & hi) ^ (0x30 * ONES)) | ((w.wrapping_add(0x06 * ONES) & hi) ^ (0x30 * ONES));
    let len = (non_digit.trailing_zeros() / 8) as usize;
    if len == 0 || len == 8 {
        return None;
    }
    // The digits moved to the top bytes, zeros (leading zero digits) below: then pairs,
    // quads and the eight-digit value, each step a multiply and a shift.
    let v = (w & (0x0F * ONES)) << (8 * (8 - len));
    let v = ((v & (0x0F * ONES)).wrapping_mul(2561) >> 8) & 0x00FF_00FF_00FF_00FF;
    let v = (v.wrapping_mul(6_553_601) >> 16) & 0x0000_FFFF_0000_FFFF;
    Some((v.wrapping_mul(42_949_672_960_001) >> 32, len))
}

/// A number as Rust's `str::parse::<f64>` reads it (the general lexer's reading): tokens
/// of digits, signs, `.` and exponents through `fast-float2` (the same correctly rounded
/// Eisel–Lemire algorithm, on bytes, about twice as fast here), anything else (`nan`,
/// `inf`) through `str::parse`. `None` where `str::parse` fails.
pub(crate) fn real(token: &[u8]) -> Option<f64> {
    if token.iter().all(|c| matches!(c, b'0'..=b'9' | b'+' | b'-' | b'.' | b'e' | b'E')) {
        // Both accept and refuse the same tokens of this alphabet (tested).
        fast_float2::parse(token).ok()
    } else {
        std::str::from_utf8(token).ok()?.parse().ok()
    }
}

/// How a piece ended.
enum End {
    /// It reached the end of its range between two records.
    Range,
    /// It met the `)` closing the list, at this offset.
    Close(usize),
}

/// Cut `b[start..]` into pieces at offsets after a `\n` where `starts_record` holds,
/// about `4 × threads` of them (fewer when the body is small).
fn pieces(b: &[u8], start: usize, starts_record: impl Fn(&[u8]) -> bool) -> Vec<Range<usize>> {
    let len = b.len() - start;
    let parts = (len / MIN_PIECE).clamp(1, 4 * rayon::current_num_threads());
    let mut cuts = vec![start];
    for k in 1..parts {
        let mut at = start + k * len / parts;
        if at <= *cuts.last().unwrap_or(&start) {
            continue;
        }
        // The first line start at or after `at` that begins a record, looking ahead at most
        // one piece.
        let limit = (at + len / parts).min(b.len());
        while at < limit {
            let Some(nl) = memchr::memchr(b'\n', &b[at..limit]) else { break };
            let line = at + nl + 1;
            if starts_record(&b[line..]) {
                cuts.push(line);
                break;
            }
            at = line;
        }
    }
    cuts.push(b.len());
    cuts.windows(2).map(|w| w[0]..w[1]).collect()
}

/// The offset of the list's `)` when every piece but the last ended at its range and
/// the last at the `)`.
fn closing(ends: Vec<Option<End>>) -> Option<usize> {
    let last = ends.len().checked_sub(1)?;
    let mut close = None;
    for (k, e) in ends.into_iter().enumerate() {
        match (e?, k == last) {
            (End::Range, false) => {}
            (End::Close(at), true) => close = Some(at),
            _ => return None,
        }
    }
    close
}

/// How the scan of a piece ends after its last record: at the end of its range, or at
/// the `)` closing the list.
fn piece_end(s: &mut Scan<'_>) -> Option<End> {
    s.ws();
    match s.peek() {
        None => Some(End::Range),
        Some(b')') => Some(End::Close(s.pos)),
        Some(_) => None,
    }
}

/// `out` cut into consecutive slices of the lengths `lens`.
fn split_lengths<'a, T>(mut out: &'a mut [T], lens: &[usize]) -> Vec<&'a mut [T]> {
    let mut v = Vec::with_capacity(lens.len());
    for &l in lens {
        let (a, rest) = std::mem::take(&mut out).split_at_mut(l);
        v.push(a);
        out = rest;
    }
    v
}

/// How many bytes of `b` satisfy `pred`, counted in blocks of up to 255 one-byte lanes (a
/// form the compiler vectorises).
#[inline]
fn count_bytes(b: &[u8], pred: impl Fn(u8, u8) -> bool) -> usize {
    // `pred(previous, byte)`; the first byte's previous is a space.
    let mut n = usize::from(b.first().is_some_and(|&c| pred(b' ', c)));
    for (prev, next) in b.chunks(255).zip(b[1.min(b.len())..].chunks(255)) {
        n += prev.iter().zip(next).fold(0u8, |a, (&p, &c)| a.wrapping_add(u8::from(pred(p, c)))) as usize;
    }
    n
}

#[inline]
fn digit(c: u8) -> bool {
    c.wrapping_sub(b'0') < 10
}

/// Runs of decimal digits in `b`.
fn count_numbers(b: &[u8]) -> usize {
    count_bytes(b, |p, c| digit(c) & !digit(p))
}

/// Exactly `n` unsigned labels from `b[start..]` up to the list's `)`: the labels and the
/// offset of that `)`.
pub(crate) fn labels(b: &[u8], start: usize, n: usize) -> Option<(Vec<u32>, usize)> {
    let close = start + memchr::memchr(b')', &b[start..])?;
    let body = &b[..close];
    // A label list has one label per line.
    let ranges = pieces(body, start, |line| line.first().is_some_and(u8::is_ascii_digit));
    let counts: Vec<usize> = ranges.par_iter().map(|r| count_numbers(&body[r.clone()])).collect();
    if counts.iter().sum::<usize>() != n {
        return None;
    }
    let mut out = vec![0u32; n];
    let ends: Vec<Option<End>> = ranges
        .into_par_iter()
        .zip(split_lengths(&mut out, &counts))
        .map(|(r, slot)| {
            let mut s = Scan { b: body, pos: r.start, end: r.end };
            for v in slot.iter_mut() {
                s.ws();
                *v = s.label()?;
            }
            s.ws();
            (s.pos == s.end).then_some(if s.end == close { End::Close(close) } else { End::Range })
        })
        .collect();
    closing(ends)?;
    Some((out, close))
}

/// Whether `line` begins a one-line face record `k(`.
pub(super) fn starts_face(line: &[u8]) -> bool {
    let digits = line.iter().take(19).take_while(|c| c.is_ascii_digit()).count();
    digits > 0 && line.get(digits) == Some(&b'(')
}

/// Faces and labels in a piece of a face list: one `(` per face and, among the runs of
/// digits, one size per face and its labels. A piece that holds anything else is caught
/// by the parse that follows (its faces must then fill exactly these counts).
fn count_faces(b: &[u8]) -> Option<(usize, usize)> {
    let faces = count_bytes(b, |_, c| c == b'(');
    Some((faces, count_numbers(b).checked_sub(faces)?))
}

/// Exactly `n` faces `k(a b …)` from `b[start..]` up to the list's `)`: CSR offsets
/// (`n + 1`), the flat point labels, and the offset of that `)`.
pub(crate) fn faces(b: &[u8], start: usize, n: usize) -> Option<(Vec<usize>, Vec<u32>, usize)> {
    let ranges = pieces(b, start, starts_face);
    let counts: Vec<Option<(usize, usize)>> = ranges.par_iter().map(|r| count_faces(&b[r.clone()])).collect();
    let counts: Vec<(usize, usize)> = counts.into_iter().collect::<Option<_>>()?;
    let (n_faces, n_labels) = counts.iter().fold((0usize, 0usize), |a, c| (a.0 + c.0, a.1.saturating_add(c.1)));
    // Each face has at least its size and a `(` in the file.
    if n_faces != n || n_labels > b.len() {
        return None;
    }
    // offsets[0] = 0, then each face's size, summed in place below.
    let mut offsets = vec![0usize; n + 1];
    let mut labels = vec![0u32; n_labels];
    let face_lens: Vec<usize> = counts.iter().map(|c| c.0).collect();
    let label_lens: Vec<usize> = counts.iter().map(|c| c.1).collect();
    let ends: Vec<Option<End>> = ranges
        .into_par_iter()
        .zip(split_lengths(&mut offsets[1..], &face_lens))
        .zip(split_lengths(&mut labels, &label_lens))
        .map(|((r, sizes), slot)| {
            let mut s = Scan { b, pos: r.start, end: r.end };
            let mut at = 0usize;
            for size in sizes.iter_mut() {
                s.ws();
                let k = s.uint()?;
                s.ws();
                s.punct(b'(')?;
                *size = k;
                for v in slot.get_mut(at..at.checked_add(k)?)? {
                    s.ws();
                    *v = s.label()?;
                }
                at += k;
                s.ws();
                s.punct(b')')?;
            }
            if at != slot.len() {
                return None;
            }
            piece_end(&mut s)
        })
        .collect();
    let close = closing(ends)?;
    for i in 1..=n {
        offsets[i] += offsets[i - 1];
    }
    Some((offsets, labels, close))
}

/// A point record's byte range in the file, and its point.
pub(crate) type PointRecord = (Range<usize>, Point3<f64>);

/// Exactly `n` points `(x y z)` from `b[start..]` up to the list's `)`: each record's byte
/// range with its point, and the offset of that `)`.
pub(crate) fn points(b: &[u8], start: usize, n: usize) -> Option<(Vec<PointRecord>, usize)> {
    let ranges = pieces(b, start, |line| line.first() == Some(&b'('));
    let counts: Vec<usize> = ranges.par_iter().map(|r| memchr::memchr_iter(b'(', &b[r.clone()]).count()).collect();
    if counts.iter().sum::<usize>() != n {
        return None;
    }
    // Filled in parallel: the fresh pages are faulted in by both threads.
    let mut out = Vec::with_capacity(n);
    out.par_extend(rayon::iter::repeat_n((0..0, Point3::origin()), n));
    let ends: Vec<Option<End>> = ranges
        .into_par_iter()
        .zip(split_lengths(&mut out, &counts))
        .map(|(r, slot)| {
            let mut s = Scan { b, pos: r.start, end: r.end };
            for rec in slot.iter_mut() {
                s.ws();
                let at = s.pos;
                let p = s.point()?;
                *rec = (at..s.pos, p);
            }
            piece_end(&mut s)
        })
        .collect();
    let close = closing(ends)?;
    Some((out, close))
}

#[cfg(test)]
pub(super) mod tests {
    use proptest::prelude::*;

    use super::super::file::{self, Lexer};
    use super::*;

    const HEAD: &str = "FoamFile { version 2.0; format ascii; class faceList; object faces; }\n";

    /// A face list as OpenFOAM writes it: faces under 10 points on one line, longer ones
    /// in the multi-line form.
    pub(in super::super) fn face_text(faces: &[Vec<usize>], footer: &str) -> String {
        let mut s = format!("{HEAD}\n\n{}\n(\n", faces.len());
        for f in faces {
            if f.len() < 10 {
                let labels: Vec<String> = f.iter().map(|v| v.to_string()).collect();
                s += &format!("{}({})\n", f.len(), labels.join(" "));
            } else {
                s += &format!("{}\n(\n", f.len());
                for v in f {
                    s += &format!("{v}\n");
                }
                s += ")\n";
            }
        }
        s + ")\n" + footer
    }

    fn slow_faces(text: &str) -> (Vec<usize>, Vec<u32>) {
        let (_, off, flat) = file::face_list(text.as_bytes()).unwrap();
        (off, flat.into_iter().map(|v| v as u32).collect())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The fast face reader gives what the general lexer gives, also for lists long
        /// enough to be cut into pieces, with multi-line faces among them.
        #[test]
        fn faces_equal_the_lexer(
            faces in prop::collection::vec(prop::collection::vec(0usize..10_000_000, 3..14), 1..400),
            repeat in 1usize..4,
        ) {
            let all: Vec<Vec<usize>> = faces.iter().cycle().take(faces.len() * repeat).cloned().collect();
            let text = face_text(&all, "\n\n// ******************** //\n");
            let fast = file::face_list_fast(text.as_bytes()).map(|(_, o, p)| (o, p));
            prop_assert_eq!(fast, Some(slow_faces(&text)));
        }

        /// The eight-byte digit reader agrees with a digit-at-a-time loop, for any bytes
        /// (digits, white space, `)` and arbitrary ones mixed).
        #[test]
        fn swar_equals_the_loop(w in prop::collection::vec(prop_oneof![b'0'..=b'9', Just(b' '), Just(b')'), any::<u8>()], 8)) {
            let len = w.iter().take_while(|c| c.is_ascii_digit()).count();
            let want = (1..8).contains(&len).then(|| (w[..len].iter().fold(0u64, |v, &c| v * 10 + u64::from(c - b'0')), len));
            let word = u64::from_le_bytes([w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]]);
            prop_assert_eq!(swar_digits(word), want);
        }

        /// Digit runs are counted as a byte-wise scan counts them.
        #[test]
        fn count_numbers_equals_the_scan(b in prop::collection::vec(prop_oneof![b'0'..=b'9', Just(b'\n'), any::<u8>()], 0..200)) {
            let mut want = 0;
            let mut prev = false;
            for &c in &b {
                want += usize::from(c.is_ascii_digit() && !prev);
                prev = c.is_ascii_digit();
            }
            prop_assert_eq!(count_numbers(&b), want);
        }

        /// Labels: one per line, as owner and neighbour files hold them.
        #[test]
        fn labels_equal_the_lexer(labels in prop::collection::vec(0usize..100_000_000, 0..3000), repeat in 1usize..4) {
            let all: Vec<usize> = labels.iter().cycle().take(labels.len() * repeat).copied().collect();
            let mut text = format!("FoamFile {{ format ascii; class labelList; }}\n{}\n(\n", all.len());
            for v in &all {
                text += &format!("{v}\n");
            }
            text += ")\n// end\n";
            let (_, slow) = file::label_list(text.as_bytes()).unwrap();
            let fast = file::label_list_fast(text.as_bytes()).map(|(_, v)| v);
            prop_assert_eq!(fast, Some(slow.into_iter().map(|v| v as u32).collect::<Vec<_>>()));
        }

        /// Points: each coordinate read to the same bits as `str::parse` reads it.
        #[test]
        fn points_equal_the_lexer(coords in prop::collection::vec(prop::num::f64::NORMAL | prop::num::f64::ZERO, 3..900), repeat in 1usize..4) {
            let mut text = String::from("FoamFile { format ascii; class vectorField; }\n");
            let n = coords.len() / 3 * repeat;
            text += &format!("{n}\n(\n");
            for (k, c) in coords.chunks_exact(3).cycle().take(n).enumerate() {
                // Several writers' spellings: shortest, fixed 17 digits, exponent.
                match k % 3 {
                    0 => text += &format!("({} {} {})\n", c[0], c[1], c[2]),
                    1 => text += &format!("({:.17} {:e} {:E})\n", c[0], c[1], c[2]),
                    _ => text += &format!("({:+e} {:.3} {})\n", c[0], c[1], c[2]),
                }
            }
            text += ")\n";
            let b = text.as_bytes();
            let mut lx = Lexer::new(b);
            file::read_header(&mut lx).unwrap();
            let n_read = lx.count(b.len()).unwrap();
            lx.expect(b'(', "").unwrap();
            let (recs, close) = points(b, lx.pos, n_read).unwrap();
            prop_assert_eq!(&b[close..close + 1], b")");
            for (r, p) in &recs {
                let inner = std::str::from_utf8(&b[r.start + 1..r.end - 1]).unwrap();
                let want: Vec<f64> = inner.split_whitespace().map(|t| t.parse().unwrap()).collect();
                prop_assert_eq!(p.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), want.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
            }
        }

        /// `real` accepts and refuses what `str::parse::<f64>` does, with the same bits.
        #[test]
        fn real_is_str_parse(t in "[0-9+.eE-]{1,30}|[-+]?(inf|nan|infinity|NaN)") {
            let want = t.parse::<f64>().ok();
            let got = real(t.as_bytes());
            prop_assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits));
        }
    }

    /// A list the fast path does not take (a comment inside, a signed label, a face that
    /// does not close) goes back to the lexer: same result, or its error.
    #[test]
    fn unusual_lists_fall_back() {
        let text = face_text(&[vec![0, 1, 2], vec![2, 3, 4, 5]], "");
        let with_comment = text.replacen("3(0 1 2)", "3(0 1 2) // first", 1);
        assert!(file::face_list_fast(with_comment.as_bytes()).is_none());
        assert_eq!(slow_faces(&with_comment), slow_faces(&text));
        let unclosed = text.replacen("3(0 1 2)", "3(0 1 2 7)", 1);
        assert!(file::face_list_fast(unclosed.as_bytes()).is_none());
        assert!(file::face_list(unclosed.as_bytes()).is_err());
        let labels = "FoamFile { format ascii; }\n3\n(\n0\n-1\n2\n)\n";
        assert!(file::label_list_fast(labels.as_bytes()).is_none());
        let short = "FoamFile { format ascii; }\n4\n(\n0\n1\n2\n)\n";
        assert!(file::label_list_fast(short.as_bytes()).is_none());
    }
}
