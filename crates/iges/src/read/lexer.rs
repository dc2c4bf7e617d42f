//! Free-format parameter tokens: integers, reals (`1.0D3`, `.5`, `-0.`), Hollerith
//! strings (`5HHello`, which may hold the delimiters), defaulted (empty) parameters,
//! custom parameter and record delimiters.
//!
//! The number grammar is a nom parser; the scan that splits a record into tokens is a
//! loop over bytes, since it decides on one byte at a time.

use nom::character::complete::{char, digit0, digit1, one_of};
use nom::combinator::opt;
use nom::{IResult, Parser};

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

/// Parses one number token (no blanks inside).
pub(crate) fn parse_number(s: &[u8]) -> Option<Raw> {
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

/// Splits `text[pos..]` into parameters up to the record delimiter `rd`.
///
/// Returns the tokens and the offset just after the record delimiter.
pub(crate) fn tokenize(text: &[u8], mut pos: usize, pd: u8, rd: u8, out: &mut Vec<Token>) -> Result<usize, LexError> {
    let len = text.len();
    loop {
        while pos < len && is_blank(text[pos]) && text[pos] != pd && text[pos] != rd {
            pos += 1;
        }
        if pos >= len {
            return Err(LexError::NoRecordEnd { offset: len });
        }
        let c = text[pos];
        if c == pd {
            out.push(Token { offset: pos as u32, raw: Raw::Default });
            pos += 1;
            continue;
        }
        if c == rd {
            out.push(Token { offset: pos as u32, raw: Raw::Default });
            return Ok(pos + 1);
        }
        let start = pos;
        let raw = if let Some((n, first)) = hollerith_at(text, pos) {
            if n > len - first {
                return Err(LexError::Hollerith { offset: start, length: n });
            }
            pos = first + n;
            Raw::Text { start: first as u32, len: n as u32 }
        } else {
            while pos < len && text[pos] != pd && text[pos] != rd && !is_blank(text[pos]) {
                pos += 1;
            }
            parse_number(&text[start..pos])
                .ok_or_else(|| LexError::Number { offset: start, found: crate::error::snippet(&text[start..pos]) })?
        };
        out.push(Token { offset: start as u32, raw });
        while pos < len && is_blank(text[pos]) && text[pos] != pd && text[pos] != rd {
            pos += 1;
        }
        if pos >= len {
            return Err(LexError::NoRecordEnd { offset: len });
        }
        if text[pos] == rd {
            return Ok(pos + 1);
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
        let mut out = Vec::new();
        tokenize(s.as_bytes(), 0, b',', b';', &mut out).unwrap();
        out.into_iter().map(|t| t.raw).collect()
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
        let mut out = Vec::new();
        tokenize(b"1/2.5/3HA/B!junk", 0, b'/', b'!', &mut out).unwrap();
        assert_eq!(out.len(), 3);
    }

    #[test]
    fn errors_name_the_offset() {
        let mut out = Vec::new();
        assert_eq!(tokenize(b"1,2", 0, b',', b';', &mut out), Err(LexError::NoRecordEnd { offset: 3 }));
        assert_eq!(tokenize(b"1,9Habc;", 0, b',', b';', &mut out), Err(LexError::Hollerith { offset: 2, length: 9 }));
        assert!(matches!(tokenize(b"1,x;", 0, b',', b';', &mut out), Err(LexError::Number { offset: 2, .. })));
        assert!(matches!(tokenize(b"1. 5;", 0, b',', b';', &mut out), Err(LexError::Delimiter { offset: 3, .. })));
    }
}
