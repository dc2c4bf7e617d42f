//! Typed parameters of a record, parsed on demand from an instance's text.

use super::lexer::{enumeration_end, number_end, reference_end, reference_id, Kind, Lexer, Token};
use crate::EntityId;

/// Deepest nesting of lists and typed parameters the reader accepts (real files use 4).
pub(crate) const MAX_DEPTH: usize = 64;

/// A parameter value (ISO 10303-21 §6.4).
#[derive(Debug, Clone, PartialEq)]
pub enum Value<'a> {
    /// An integer.
    Integer(i64),
    /// A real.
    Real(f64),
    /// A string, undecoded: the text between the apostrophes (see [`decode_string`]).
    String(&'a str),
    /// A binary `"..."`, its hex digits (first digit: unused bits).
    Binary(&'a str),
    /// An enumeration `.NAME.`, without the dots.
    Enumeration(&'a str),
    /// A reference `#n`.
    Reference(EntityId),
    /// `$`: no value.
    Unset,
    /// `*`: derived by the supertype.
    Derived,
    /// `( ... )`.
    List(Vec<Param<'a>>),
    /// A typed parameter `NAME( ... )`, e.g. `LENGTH_MEASURE(1.E-07)`.
    Typed(&'a str, Vec<Param<'a>>),
}

/// A parameter with its byte span in the instance text (`start..end`).
#[derive(Debug, Clone, PartialEq)]
pub struct Param<'a> {
    /// The value.
    pub value: Value<'a>,
    /// Offset of its first byte in the instance text.
    pub start: usize,
    /// Offset one past its last byte.
    pub end: usize,
}

impl<'a> Param<'a> {
    /// The number, for integers and reals.
    pub fn as_f64(&self) -> Option<f64> {
        match self.value {
            Value::Real(x) => Some(x),
            Value::Integer(i) => Some(i as f64),
            Value::Typed(_, ref inner) if inner.len() == 1 => inner[0].as_f64(),
            _ => None,
        }
    }
    /// The reference target.
    pub fn as_ref_id(&self) -> Option<EntityId> {
        match self.value {
            Value::Reference(id) => Some(id),
            _ => None,
        }
    }
    /// The items of a list.
    pub fn as_list(&self) -> Option<&[Param<'a>]> {
        match &self.value {
            Value::List(v) => Some(v),
            _ => None,
        }
    }
    /// The name of an enumeration.
    pub fn as_enum(&self) -> Option<&'a str> {
        match self.value {
            Value::Enumeration(e) => Some(e),
            _ => None,
        }
    }
    /// A logical/boolean `.T.`/`.F.` (`.U.` is `None`).
    pub fn as_bool(&self) -> Option<bool> {
        match self.as_enum()? {
            "T" => Some(true),
            "F" => Some(false),
            _ => None,
        }
    }
}

/// One record `NAME(params)`: a simple instance or one leaf of a complex instance.
#[derive(Debug, Clone, PartialEq)]
pub struct Record<'a> {
    /// The entity name.
    pub name: &'a str,
    /// Its parameters.
    pub params: Vec<Param<'a>>,
    /// Offset of the name in the instance text.
    pub start: usize,
}

/// The body of an instance.
#[derive(Debug, Clone, PartialEq)]
pub enum Body<'a> {
    /// `NAME(...)`.
    Simple(Record<'a>),
    /// `( A(...) B(...) ... )`, leaves in file order.
    Complex(Vec<Record<'a>>),
}

impl<'a> Body<'a> {
    /// The record of entity `name`: the simple record if it has that name, or that leaf.
    pub fn record(&self, name: &str) -> Option<&Record<'a>> {
        match self {
            Body::Simple(r) => (r.name == name).then_some(r),
            Body::Complex(v) => v.iter().find(|r| r.name == name),
        }
    }
    /// The simple record, or the first leaf.
    pub fn first(&self) -> Option<&Record<'a>> {
        match self {
            Body::Simple(r) => Some(r),
            Body::Complex(v) => v.first(),
        }
    }
}

struct P<'a> {
    lx: Lexer<'a>,
    base: usize,
    /// The items of the lists being read, innermost last: a list is gathered here and
    /// moved into a vector of its exact length when it closes (one allocation per list,
    /// where growing each list's vector item by item took several).
    stack: Vec<Param<'a>>,
}

/// A number token's value, correctly rounded as `str::parse` gives it, read from the
/// bytes (no UTF-8 check; `fast_float2` as the views' point reader uses it).
fn real(token: &[u8]) -> Option<f64> {
    fast_float2::parse(token).ok()
}

/// The value of a number token's bytes: an integer when it has neither `.` nor an
/// exponent and fits 64 bits, a real otherwise (integers beyond 64 bits read as reals).
/// `None` for bytes that are no number.
fn number_value(t: &[u8], is_real: bool) -> Option<Value<'static>> {
    let integer = if is_real { None } else { std::str::from_utf8(t).ok().and_then(|s| s.parse::<i64>().ok()) };
    Some(match integer {
        Some(i) => Value::Integer(i),
        None => Value::Real(real(t)?),
    })
}

fn str_of(src: &[u8], t: Token, trim: usize) -> &str {
    std::str::from_utf8(&src[t.start + trim..t.end - trim]).unwrap_or("")
}

impl<'a> P<'a> {
    #[inline(always)]
    fn next(&mut self) -> Result<Token, usize> {
        self.lx.next_token().map_err(|_| self.lx.pos + self.base)
    }

    fn params(&mut self, depth: usize) -> Result<Vec<Param<'a>>, usize> {
        // After `(`.
        let fast = super::fast_forms();
        if fast && self.lx.src.get(self.lx.pos) == Some(&b')') {
            self.lx.pos += 1;
            return Ok(Vec::new());
        }
        let from = self.stack.len();
        let mut first = true;
        loop {
            let p = match if fast { self.fast_value() } else { None } {
                Some(p) => p,
                None => {
                    let tok = self.next()?;
                    if first && tok.kind == Kind::Close {
                        return Ok(Vec::new());
                    }
                    self.param(tok, depth)?
                }
            };
            first = false;
            self.stack.push(p);
            // A comma or `)` right after the value, read without a token.
            match if fast { self.lx.src.get(self.lx.pos).copied() } else { None } {
                Some(b',') => {
                    self.lx.pos += 1;
                    continue;
                }
                Some(b')') => {
                    self.lx.pos += 1;
                    return Ok(self.stack.drain(from..).collect());
                }
                _ => {}
            }
            let tok = self.next()?;
            match tok.kind {
                Kind::Comma => {}
                Kind::Close => return Ok(self.stack.drain(from..).collect()),
                _ => return Err(tok.start + self.base),
            }
        }
    }

    /// A reference, number or enumeration that starts right at the cursor (no blank or comment
    /// before it), read from its bytes without a token: what [`param`](Self::param) reads
    /// of the same text. `None` for anything else, and for what `param` would refuse
    /// (then it reads it, and reports it).
    #[inline]
    fn fast_value(&mut self) -> Option<Param<'a>> {
        let (s, p) = (self.lx.src, self.lx.pos);
        let (value, end) = match *s.get(p)? {
            b'#' => {
                let e = reference_end(s, p)?;
                (Value::Reference(EntityId(reference_id(&s[p..e])?)), e)
            }
            b'+' | b'-' | b'0'..=b'9' => {
                let (e, is_real) = number_end(s, p)?;
                (number_value(&s[p..e], is_real)?, e)
            }
            b'.' => {
                let e = enumeration_end(s, p)?;
                (Value::Enumeration(str_of(s, Token { kind: Kind::Enumeration, start: p, end: e }, 1)), e)
            }
            _ => return None,
        };
        self.lx.pos = end;
        Some(Param { value, start: p + self.base, end: end + self.base })
    }

    fn param(&mut self, tok: Token, depth: usize) -> Result<Param<'a>, usize> {
        let src = self.lx.src;
        let at = tok.start + self.base;
        if depth > MAX_DEPTH {
            return Err(at);
        }
        let value = match tok.kind {
            Kind::Integer | Kind::Real => number_value(&src[tok.start..tok.end], tok.kind == Kind::Real).ok_or(at)?,
            Kind::String => Value::String(str_of(src, tok, 1)),
            Kind::Binary => Value::Binary(str_of(src, tok, 1)),
            Kind::Enumeration => Value::Enumeration(str_of(src, tok, 1)),
            Kind::Reference => Value::Reference(EntityId(reference_id(&src[tok.start..tok.end]).ok_or(at)?)),
            Kind::Unset => Value::Unset,
            Kind::Derived => Value::Derived,
            Kind::Open => Value::List(self.params(depth + 1)?),
            Kind::Keyword => {
                let name = str_of(src, tok, 0);
                let open = self.next()?;
                if open.kind != Kind::Open {
                    return Err(open.start + self.base);
                }
                Value::Typed(name, self.params(depth + 1)?)
            }
            _ => return Err(at),
        };
        Ok(Param { value, start: at, end: self.lx.pos + self.base })
    }

    fn record(&mut self, name: Token) -> Result<Record<'a>, usize> {
        let open = self.next()?;
        if open.kind != Kind::Open {
            return Err(open.start + self.base);
        }
        let params = self.params(1)?;
        Ok(Record { name: str_of(self.lx.src, name, 0), params, start: name.start + self.base })
    }

    fn body(&mut self) -> Result<Body<'a>, usize> {
        let tok = self.next()?;
        match tok.kind {
            Kind::Keyword => Ok(Body::Simple(self.record(tok)?)),
            Kind::Open => {
                let mut leaves = Vec::new();
                loop {
                    let t = self.next()?;
                    match t.kind {
                        Kind::Keyword => leaves.push(self.record(t)?),
                        Kind::Close => return Ok(Body::Complex(leaves)),
                        _ => return Err(t.start + self.base),
                    }
                }
            }
            _ => Err(tok.start + self.base),
        }
    }
}

/// Parses `NAME(...)` or `( A(...) B(...) )` at the start of `text`; offsets are
/// `base + ` their index in `text`. On failure returns the offset of the problem.
pub(crate) fn parse_body(text: &[u8], base: usize) -> Result<Body<'_>, usize> {
    parse_body_in(text, base, &mut Vec::new())
}

/// [`parse_body`] gathering the parameter lists on `stack`, which the caller keeps from
/// one record to the next: a stack made for each record grew item by item, and its
/// growth was a tenth of the time of reading small records. `stack` is left empty.
pub(crate) fn parse_body_in<'a>(text: &'a [u8], base: usize, stack: &mut Vec<Param<'a>>) -> Result<Body<'a>, usize> {
    let mut p = P { lx: Lexer::new(text, 0), base, stack: std::mem::take(stack) };
    let body = p.body();
    p.stack.clear();
    *stack = p.stack;
    body
}

/// Decodes a Part 21 string body: `''` → `'`, `\\` → `\`, `\S\c` (c + 128),
/// `\X\hh` (ISO 8859-1), `\X2\hhhh…\X0\` (UTF-16), `\X4\hhhhhhhh…\X0\` (UCS-4); page
/// directives `\P?\` are dropped; anything malformed is kept as written.
///
/// # Examples
///
/// ```
/// use cadmorph_step::decode_string;
/// assert_eq!(decode_string("it''s"), "it's");
/// assert_eq!(decode_string("\\X\\E9t\\X\\E9"), "été");
/// assert_eq!(decode_string("\\X2\\03A903C9\\X0\\"), "Ωω");
/// assert_eq!(decode_string("\\X4\\0001F600\\X0\\"), "😀");
/// ```
pub fn decode_string(raw: &str) -> String {
    let b = raw.as_bytes();
    let mut out = String::with_capacity(raw.len());
    let hex = |s: &[u8]| -> Option<u32> {
        let t = std::str::from_utf8(s).ok()?;
        u32::from_str_radix(t, 16).ok()
    };
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        if rest.starts_with(b"''") {
            out.push('\'');
            i += 2;
        } else if rest.starts_with(b"\\\\") {
            out.push('\\');
            i += 2;
        } else if rest.starts_with(b"\\X\\") && rest.len() >= 5 && hex(&rest[3..5]).is_some() {
            out.push(char::from_u32(hex(&rest[3..5]).unwrap_or(0)).unwrap_or('\u{FFFD}'));
            i += 5;
        } else if rest.starts_with(b"\\S\\") && rest.len() >= 4 && rest[3] < 128 {
            out.push(char::from_u32(u32::from(rest[3]) + 128).unwrap_or('\u{FFFD}'));
            i += 4;
        } else if rest.starts_with(b"\\P") && rest.len() >= 4 && rest[3] == b'\\' {
            i += 4;
        } else if (rest.starts_with(b"\\X2\\") || rest.starts_with(b"\\X4\\")) && rest.len() >= 4 {
            let width = if rest[2] == b'2' { 4 } else { 8 };
            let Some(end) = rest.windows(4).position(|w| w == b"\\X0\\") else {
                out.push('\\');
                i += 1;
                continue;
            };
            let digits = &rest[4..end];
            if !digits.len().is_multiple_of(width) || digits.chunks(width).any(|c| hex(c).is_none()) {
                out.push('\\');
                i += 1;
                continue;
            }
            let units: Vec<u32> = digits.chunks(width).filter_map(hex).collect();
            if width == 4 {
                let u16s: Vec<u16> = units.iter().map(|&u| u as u16).collect();
                out.extend(char::decode_utf16(u16s).map(|r| r.unwrap_or('\u{FFFD}')));
            } else {
                out.extend(units.iter().map(|&u| char::from_u32(u).unwrap_or('\u{FFFD}')));
            }
            i += end + 4;
        } else {
            let ch_len = raw[i..].chars().next().map_or(1, char::len_utf8);
            out.push_str(&raw[i..i + ch_len]);
            i += ch_len;
        }
    }
    out
}

/// Encodes a string for a Part 21 file: `'` doubled, `\` doubled, non-ASCII as `\X2\…\X0\`
/// (or `\X4\…\X0\` outside the BMP). The inverse of [`decode_string`].
///
/// # Examples
///
/// ```
/// use cadmorph_step::{decode_string, encode_string};
/// for s in ["plain", "it's", "back\\slash", "été Ωω 😀"] {
///     assert_eq!(decode_string(&encode_string(s)), s);
/// }
/// ```
pub fn encode_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\'' => out.push_str("''"),
            '\\' => out.push_str("\\\\"),
            ' '..='~' => out.push(c),
            _ => {
                let mut run = vec![c];
                while let Some(&n) = chars.peek() {
                    if (' '..='~').contains(&n) {
                        break;
                    }
                    run.push(n);
                    chars.next();
                }
                if run.iter().all(|c| (*c as u32) < 0x10000) {
                    out.push_str("\\X2\\");
                    for c in run {
                        out.push_str(&format!("{:04X}", c as u32));
                    }
                } else {
                    out.push_str("\\X4\\");
                    for c in run {
                        out.push_str(&format!("{:08X}", c as u32));
                    }
                }
                out.push_str("\\X0\\");
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simple_and_complex() {
        let b = parse_body(b"A('x',(1,2.),#3,$,*,.T.,M(4.))", 0).unwrap();
        let Body::Simple(r) = b else { panic!() };
        assert_eq!(r.name, "A");
        assert_eq!(r.params.len(), 7);
        assert_eq!(r.params[2].as_ref_id(), Some(EntityId(3)));
        assert_eq!(r.params[6].as_f64(), Some(4.0));
        let b = parse_body(b"( A() B(1) )", 10).unwrap();
        let Body::Complex(v) = b else { panic!() };
        assert_eq!((v[0].name, v[1].name, v[1].start), ("A", "B", 16));
    }

    proptest::proptest! {
        /// Number tokens read from bytes equal `str::parse`'s value bit for bit: every
        /// real form of ISO 10303-21 §6.3.2, long mantissas, extreme exponents, and
        /// integers beyond 64 bits (read as reals).
        #[test]
        fn numbers_read_as_str_parse_reads_them(
            sign in proptest::sample::select(vec!["", "-", "+"]),
            int in "[0-9]{1,25}",
            frac in proptest::option::of("[0-9]{0,25}"),
            exp in proptest::option::of(-330i32..330),
        ) {
            let mut t = format!("{sign}{int}");
            if let Some(f) = &frac {
                t.push('.');
                t.push_str(f);
            }
            if let Some(e) = exp {
                if frac.is_some() {
                    t.push_str(&format!("E{e}"));
                }
            }
            let body = format!("A({t})");
            let Body::Simple(r) = parse_body(body.as_bytes(), 0).unwrap() else { panic!() };
            let want: f64 = t.parse().unwrap();
            match r.params[0].value {
                Value::Real(x) => proptest::prop_assert_eq!(x.to_bits(), want.to_bits(), "{}", t),
                Value::Integer(i) => proptest::prop_assert_eq!(Ok(i), t.parse::<i64>(), "{}", t),
                ref v => proptest::prop_assert!(false, "{t}: {v:?}"),
            }
        }
    }

    #[test]
    fn deep_nesting_is_refused() {
        let text = format!("A({}{})", "(".repeat(100), ")".repeat(100));
        assert!(parse_body(text.as_bytes(), 0).is_err());
    }
}
