//! Tokens of the ISO 10303-21 exchange structure (clause 5 of the standard).
//!
//! The lexer works on bytes and never allocates; numbers are only recognised here and
//! converted to `f64` when a typed view asks for them. Each token form is a short loop
//! over the bytes (clause 5.3's grammar has no backtracking beyond an exponent without
//! digits); combinator parsers cost a third of the reading time on large files.

/// The kinds of token.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// `NAME` or `!NAME` (user-defined).
    Keyword,
    /// `12`, `-3`.
    Integer,
    /// `1.`, `-2.5E-07`.
    Real,
    /// `'...'` (span includes the apostrophes).
    String,
    /// `"..."` (span includes the quotes).
    Binary,
    /// `.NAME.` (span includes the dots).
    Enumeration,
    /// `#123` (span includes the `#`).
    Reference,
    /// `$`.
    Unset,
    /// `*`.
    Derived,
    /// `(`.
    Open,
    /// `)`.
    Close,
    /// `,`.
    Comma,
    /// `;`.
    Semicolon,
    /// `=`.
    Equals,
    /// End of input.
    End,
}

/// A token: kind and byte span in the input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Token {
    pub kind: Kind,
    pub start: usize,
    pub end: usize,
}

/// Why the lexer stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LexError {
    /// A string or binary literal without its closing delimiter, starting at the offset.
    UnterminatedString(usize),
    /// A comment without `*/`, starting at the offset.
    UnterminatedComment(usize),
    /// A byte that starts no token, at the offset.
    Unexpected(usize),
}

/// A cursor over the input.
#[derive(Debug, Clone)]
pub(crate) struct Lexer<'a> {
    pub src: &'a [u8],
    pub pos: usize,
}

/// The end of the run of bytes from `i` that satisfy `f`.
#[inline]
fn run(s: &[u8], mut i: usize, f: impl Fn(u8) -> bool) -> usize {
    while i < s.len() && f(s[i]) {
        i += 1;
    }
    i
}

/// The end of the run of ASCII digits from `i`, eight bytes at a time where eight remain
/// (numbers and references are most of a file's bytes). A byte `b` is a digit when
/// `t = b ^ 0x30` is below 10; `((t & 0x7f) + 0x76) | t` has its high bit set exactly for
/// the others, with no carry between bytes (`0x7f + 0x76 < 0x100`).
#[inline]
fn digits_end(s: &[u8], mut i: usize) -> usize {
    const LOW: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    while let Some(chunk) = s.get(i..i + 8) {
        let mut word = [0u8; 8];
        word.copy_from_slice(chunk);
        let t = u64::from_le_bytes(word) ^ 0x3030_3030_3030_3030;
        let other = (((t & LOW) + 0x7676_7676_7676_7676) | t) & HIGH;
        if other != 0 {
            return i + (other.trailing_zeros() / 8) as usize;
        }
        i += 8;
    }
    run(s, i, |c| c.is_ascii_digit())
}

/// Bytes of a name after its first: `A-Z a-z 0-9 _`, as a table (one load per byte
/// where the range tests took several compares; names are most of an instance's header).
const NAME: [bool; 256] = {
    let mut t = [false; 256];
    let mut c = 0;
    while c < 256 {
        let b = c as u8;
        t[c] = b.is_ascii_alphanumeric() || b == b'_';
        c += 1;
    }
    t
};

#[inline(always)]
fn is_name(c: u8) -> bool {
    NAME[c as usize]
}

/// The end of the run of name bytes (`A-Z a-z 0-9 _`) from `i`, eight bytes at a time
/// where eight remain, like [`digits_end`] (entity names are most of an instance's
/// head, and a byte loop's exit is mispredicted at every name). Per byte, with `x` the
/// byte and each test leaving its high bit set for the bytes it excludes, no carry
/// crossing bytes (every sum stays below `0x100`):
/// - not a digit: `t = x ^ 0x30`, `((t & 0x7f) + 0x76) | t` (as in `digits_end`);
/// - not a letter: `u = (x | 0x20) ^ 0x60` (letters of either case to 1..=26) and
///   `a = u & 0x7f`: `(a + 0x65) | u | !(a + 0x7f)` (above 26, high bit, or zero);
/// - not `_`: `e = x ^ 0x5f` nonzero, `((e & 0x7f) + 0x7f) | e`.
#[inline]
fn name_end(s: &[u8], mut i: usize) -> usize {
    const LOW: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    const ONES: u64 = 0x0101_0101_0101_0101;
    while let Some(chunk) = s.get(i..i + 8) {
        let mut word = [0u8; 8];
        word.copy_from_slice(chunk);
        let x = u64::from_le_bytes(word);
        let t = x ^ (0x30 * ONES);
        let not_digit = ((t & LOW) + 0x76 * ONES) | t;
        let u = (x | (0x20 * ONES)) ^ (0x60 * ONES);
        let a = u & LOW;
        let not_letter = (a + 0x65 * ONES) | u | !(a + LOW);
        let e = x ^ (0x5f * ONES);
        let not_underscore = ((e & LOW) + LOW) | e;
        let other = not_digit & not_letter & not_underscore & HIGH;
        if other != 0 {
            return i + (other.trailing_zeros() / 8) as usize;
        }
        i += 8;
    }
    run(s, i, is_name)
}

/// `[!]letter{letter|digit|_}` (a keyword; `_` counts as a letter): the end, if one
/// starts at `i`.
#[inline]
pub(crate) fn keyword_end(s: &[u8], i: usize) -> Option<usize> {
    let i = if s.get(i) == Some(&b'!') { i + 1 } else { i };
    match s.get(i) {
        Some(&c) if c.is_ascii_alphabetic() || c == b'_' => Some(name_end(s, i + 1)),
        _ => None,
    }
}

/// `[+-]digits[.digits][E[+-]digits]` from `i`: the end and whether a `.` or an exponent
/// made it real. An `E` not followed by digits is not part of the number.
#[inline]
pub(crate) fn number_end(s: &[u8], i: usize) -> Option<(usize, bool)> {
    let digits = digits_end(s, if matches!(s.get(i), Some(b'+' | b'-')) { i + 1 } else { i });
    if digits == i || !s[digits - 1].is_ascii_digit() {
        return None;
    }
    let (mut end, mut real) = (digits, false);
    if s.get(end) == Some(&b'.') {
        end = digits_end(s, end + 1);
        real = true;
    }
    if matches!(s.get(end), Some(b'e' | b'E')) {
        let from = if matches!(s.get(end + 1), Some(b'+' | b'-')) { end + 2 } else { end + 1 };
        let to = digits_end(s, from);
        if to > from {
            end = to;
            real = true;
        }
    }
    Some((end, real))
}

/// `.NAME.` from `i` (at the first `.`): the end.
#[inline]
pub(crate) fn enumeration_end(s: &[u8], i: usize) -> Option<usize> {
    let name = name_end(s, i + 1);
    (name > i + 1 && s.get(name) == Some(&b'.')).then_some(name + 1)
}

/// `#digits` or `@digits` from `i` (at the `#` or `@`): the end.
#[inline]
pub(crate) fn reference_end(s: &[u8], i: usize) -> Option<usize> {
    let end = digits_end(s, i + 1);
    (end > i + 1).then_some(end)
}

impl<'a> Lexer<'a> {
    pub fn new(src: &'a [u8], pos: usize) -> Self {
        Self { src, pos }
    }

    /// Skips blanks, line breaks and comments.
    #[inline]
    pub fn skip_space(&mut self) -> Result<(), LexError> {
        let s = self.src;
        loop {
            while self.pos < s.len() && s[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            if s.len() - self.pos >= 2 && s[self.pos] == b'/' && s[self.pos + 1] == b'*' {
                let start = self.pos;
                let mut i = self.pos + 2;
                loop {
                    if i + 1 >= s.len() {
                        return Err(LexError::UnterminatedComment(start));
                    }
                    if s[i] == b'*' && s[i + 1] == b'/' {
                        break;
                    }
                    i += 1;
                }
                self.pos = i + 2;
                continue;
            }
            return Ok(());
        }
    }

    /// Whether the input continues with `text` after blanks and comments (consumes it if so).
    pub fn eat_literal(&mut self, text: &[u8]) -> Result<bool, LexError> {
        self.skip_space()?;
        if self.src[self.pos..].starts_with(text) {
            self.pos += text.len();
            Ok(true)
        } else {
            Ok(false)
        }
    }

    /// The next token.
    #[inline]
    pub fn next_token(&mut self) -> Result<Token, LexError> {
        self.skip_space()?;
        let s = self.src;
        let start = self.pos;
        let Some(&c) = s.get(start) else {
            return Ok(Token { kind: Kind::End, start, end: start });
        };
        let single = |kind| Token { kind, start, end: start + 1 };
        let tok = match c {
            b'(' => single(Kind::Open),
            b')' => single(Kind::Close),
            b',' => single(Kind::Comma),
            b';' => single(Kind::Semicolon),
            b'=' => single(Kind::Equals),
            b'$' => single(Kind::Unset),
            b'*' => single(Kind::Derived),
            b'\'' => {
                let mut i = start + 1;
                loop {
                    match s[i..].iter().position(|&b| b == b'\'') {
                        None => return Err(LexError::UnterminatedString(start)),
                        Some(k) => {
                            i += k;
                            if s.get(i + 1) == Some(&b'\'') {
                                i += 2;
                            } else {
                                break;
                            }
                        }
                    }
                }
                Token { kind: Kind::String, start, end: i + 1 }
            }
            b'"' => match s[start + 1..].iter().position(|&b| b == b'"') {
                None => return Err(LexError::UnterminatedString(start)),
                Some(k) => Token { kind: Kind::Binary, start, end: start + k + 2 },
            },
            b'#' | b'@' => match reference_end(s, start) {
                Some(end) => Token { kind: Kind::Reference, start, end },
                None => return Err(LexError::Unexpected(start)),
            },
            b'.' => match enumeration_end(s, start) {
                Some(end) => Token { kind: Kind::Enumeration, start, end },
                None => return Err(LexError::Unexpected(start)),
            },
            b'+' | b'-' | b'0'..=b'9' => match number_end(s, start) {
                Some((end, real)) => Token { kind: if real { Kind::Real } else { Kind::Integer }, start, end },
                None => return Err(LexError::Unexpected(start)),
            },
            _ => match keyword_end(s, start) {
                Some(end) => Token { kind: Kind::Keyword, start, end },
                None => return Err(LexError::Unexpected(start)),
            },
        };
        self.pos = tok.end;
        Ok(tok)
    }
}

/// Parses the digits of a reference token (`#123`) into an id; `None` when it overflows.
#[inline]
pub(crate) fn reference_id(tok: &[u8]) -> Option<u64> {
    let mut v: u64 = 0;
    for &c in &tok[1..] {
        v = v.checked_mul(10)?.checked_add(u64::from(c - b'0'))?;
    }
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eight-at-a-time digit run ends where the byte-at-a-time one does, for every
    /// byte value at every place in and after a run.
    #[test]
    fn digit_runs_end_where_the_bytes_say() {
        for len in 0..20 {
            for at in 0..=len {
                for b in 0..=255u8 {
                    let mut s = vec![b'7'; len];
                    if at < len {
                        s[at] = b;
                    }
                    s.extend_from_slice(b",1234567890");
                    for from in 0..=at.min(len) {
                        assert_eq!(digits_end(&s, from), run(&s, from, |c| c.is_ascii_digit()), "{s:?} from {from}");
                    }
                }
            }
        }
    }

    /// The eight-at-a-time name run ends where the byte-at-a-time one does, for every
    /// byte value at every place in and after a run.
    #[test]
    fn name_runs_end_where_the_bytes_say() {
        for len in 0..20 {
            for at in 0..=len {
                for b in 0..=255u8 {
                    let mut s: Vec<u8> = b"Az_9Zq0a_Z".iter().cycle().take(len).copied().collect();
                    if at < len {
                        s[at] = b;
                    }
                    s.extend_from_slice(b"(CARTESIAN_POINT_2");
                    for from in 0..=at.min(len) {
                        assert_eq!(name_end(&s, from), run(&s, from, is_name), "{s:?} from {from}");
                    }
                }
            }
        }
    }

    fn kinds(text: &str) -> Vec<Kind> {
        let mut lx = Lexer::new(text.as_bytes(), 0);
        let mut out = vec![];
        loop {
            let t = lx.next_token().unwrap();
            out.push(t.kind);
            if t.kind == Kind::End {
                return out;
            }
        }
    }

    #[test]
    fn tokens() {
        use Kind::*;
        assert_eq!(
            kinds("#12 = A_B( 'it''s', 1., -2, 3.5E-07, .T., $, *, \"0F\", (#1) ) ; /* c */"),
            vec![
                Reference,
                Equals,
                Keyword,
                Open,
                String,
                Comma,
                Real,
                Comma,
                Integer,
                Comma,
                Real,
                Comma,
                Enumeration,
                Comma,
                Unset,
                Comma,
                Derived,
                Comma,
                Binary,
                Comma,
                Open,
                Reference,
                Close,
                Close,
                Semicolon,
                End
            ]
        );
    }

    /// Each token form's edges: where a number, keyword, enumeration or reference ends,
    /// and what starts none.
    #[test]
    fn token_ends() {
        let first = |text: &str| Lexer::new(text.as_bytes(), 0).next_token().map(|t| (t.kind, t.end));
        use Kind::*;
        assert_eq!(first("12,"), Ok((Integer, 2)));
        assert_eq!(first("-12)"), Ok((Integer, 3)));
        assert_eq!(first("+7"), Ok((Integer, 2)));
        assert_eq!(first("1."), Ok((Real, 2)));
        assert_eq!(first("1.E5,"), Ok((Real, 4)));
        assert_eq!(first("-2.5e-07)"), Ok((Real, 8)));
        assert_eq!(first("3E+2"), Ok((Real, 4)));
        // An exponent without digits is not part of the number.
        assert_eq!(first("3E"), Ok((Integer, 1)));
        assert_eq!(first("3.5E+,"), Ok((Real, 3)));
        assert_eq!(first("-"), Err(LexError::Unexpected(0)));
        assert_eq!(first("+."), Err(LexError::Unexpected(0)));
        assert_eq!(first("ABC_1(x"), Ok((Keyword, 5)));
        assert_eq!(first("_A9 "), Ok((Keyword, 3)));
        assert_eq!(first("!USER_DEF("), Ok((Keyword, 9)));
        assert_eq!(first("!1"), Err(LexError::Unexpected(0)));
        assert_eq!(first(".T.,"), Ok((Enumeration, 3)));
        assert_eq!(first(".UNSPECIFIED."), Ok((Enumeration, 13)));
        assert_eq!(first(".."), Err(LexError::Unexpected(0)));
        assert_eq!(first(".T"), Err(LexError::Unexpected(0)));
        assert_eq!(first("#123)"), Ok((Reference, 4)));
        assert_eq!(first("@7"), Ok((Reference, 2)));
        assert_eq!(first("@"), Err(LexError::Unexpected(0)));
    }

    #[test]
    fn errors() {
        assert_eq!(Lexer::new(b"  'abc", 0).next_token(), Err(LexError::UnterminatedString(2)));
        assert_eq!(Lexer::new(b"/* abc", 0).next_token(), Err(LexError::UnterminatedComment(0)));
        assert_eq!(Lexer::new(b" ?", 0).next_token(), Err(LexError::Unexpected(1)));
        assert_eq!(Lexer::new(b"#", 0).next_token(), Err(LexError::Unexpected(0)));
        assert_eq!(reference_id(b"#99999999999999999999999"), None);
    }
}
