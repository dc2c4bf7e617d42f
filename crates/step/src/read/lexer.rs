//! Tokens of the ISO 10303-21 exchange structure (clause 5 of the standard).
//!
//! The lexer works on bytes and never allocates; numbers are recognised with nom and only
//! converted to `f64` when a typed view asks for them.

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while, take_while1};
use nom::character::complete::{digit0, digit1, one_of};
use nom::combinator::{opt, recognize};
use nom::{IResult, Parser};

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

fn keyword(i: &[u8]) -> IResult<&[u8], &[u8]> {
    recognize((
        opt(tag(&b"!"[..])),
        take_while1(|c: u8| c.is_ascii_alphabetic() || c == b'_'),
        take_while(|c: u8| c.is_ascii_alphanumeric() || c == b'_'),
    ))
    .parse(i)
}

/// `[+-]digits[.digits][E[+-]digits]`; returns whether a `.` or exponent made it real.
fn number(i: &[u8]) -> IResult<&[u8], (&[u8], bool)> {
    let (rest, (sign_digits, frac, exp)) = (
        recognize((opt(one_of("+-")), digit1)),
        opt(recognize((tag(&b"."[..]), digit0))),
        opt(recognize((one_of("eE"), opt(one_of("+-")), digit1))),
    )
        .parse(i)?;
    let len = i.len() - rest.len();
    let _ = sign_digits;
    Ok((rest, (&i[..len], frac.is_some() || exp.is_some())))
}

fn enumeration(i: &[u8]) -> IResult<&[u8], &[u8]> {
    recognize((tag(&b"."[..]), take_while1(|c: u8| c.is_ascii_alphanumeric() || c == b'_'), tag(&b"."[..]))).parse(i)
}

fn reference(i: &[u8]) -> IResult<&[u8], &[u8]> {
    recognize((alt((tag(&b"#"[..]), tag(&b"@"[..]))), digit1)).parse(i)
}

impl<'a> Lexer<'a> {
    pub fn new(src: &'a [u8], pos: usize) -> Self {
        Self { src, pos }
    }

    /// Skips blanks, line breaks and comments.
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
            b'#' | b'@' => match reference(&s[start..]) {
                Ok((rest, _)) => Token { kind: Kind::Reference, start, end: s.len() - rest.len() },
                Err(_) => return Err(LexError::Unexpected(start)),
            },
            b'.' => match enumeration(&s[start..]) {
                Ok((rest, _)) => Token { kind: Kind::Enumeration, start, end: s.len() - rest.len() },
                Err(_) => return Err(LexError::Unexpected(start)),
            },
            b'+' | b'-' | b'0'..=b'9' => match number(&s[start..]) {
                Ok((rest, (_, real))) => {
                    Token { kind: if real { Kind::Real } else { Kind::Integer }, start, end: s.len() - rest.len() }
                }
                Err(_) => return Err(LexError::Unexpected(start)),
            },
            _ => match keyword(&s[start..]) {
                Ok((rest, _)) => Token { kind: Kind::Keyword, start, end: s.len() - rest.len() },
                Err(_) => return Err(LexError::Unexpected(start)),
            },
        };
        self.pos = tok.end;
        Ok(tok)
    }
}

/// Parses the digits of a reference token (`#123`) into an id; `None` when it overflows.
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

    #[test]
    fn errors() {
        assert_eq!(Lexer::new(b"  'abc", 0).next_token(), Err(LexError::UnterminatedString(2)));
        assert_eq!(Lexer::new(b"/* abc", 0).next_token(), Err(LexError::UnterminatedComment(0)));
        assert_eq!(Lexer::new(b" ?", 0).next_token(), Err(LexError::Unexpected(1)));
        assert_eq!(Lexer::new(b"#", 0).next_token(), Err(LexError::Unexpected(0)));
        assert_eq!(reference_id(b"#99999999999999999999999"), None);
    }
}
