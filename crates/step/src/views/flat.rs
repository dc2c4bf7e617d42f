//! Flat records read from their bytes: `NAME('...', p₁, …, p_N)` whose parameters after
//! the name string are references, `$`, `*`, enumerations, numbers or lists (kept as
//! their byte span, read further only when asked, by [`ref_list`]). Most topology and
//! placement records have that shape (`VERTEX_POINT`, `EDGE_CURVE`, `ORIENTED_EDGE`,
//! `FACE_BOUND`, `EDGE_LOOP`, `ADVANCED_FACE`, `CLOSED_SHELL`, `SURFACE_CURVE`, `LINE`,
//! `VECTOR`, `PLANE`, `AXIS2_PLACEMENT_3D`), and reading one this way allocates nothing,
//! where the general reader builds its parameter tree (a small file's faces read a few
//! hundred of them).
//!
//! Only a record of exactly the asked name and arity, written with blanks at most
//! between its tokens, is read; anything else (a typed parameter, a comment, a string
//! inside a list, another name or arity, a number too long for 64 bits) gives `None`,
//! and the caller reads the record with the general reader, which also reports its
//! errors. What is read equals what the general reader gives for every record of a
//! document (which its parse checked; a list is only skipped by its parentheses here):
//! property test below.

use crate::read::lexer::{enumeration_end, number_end, reference_end, reference_id};
use crate::EntityId;

/// One parameter of a flat record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Flat {
    /// `#n`.
    Ref(EntityId),
    /// `$`.
    Unset,
    /// `*`.
    Derived,
    /// `.T.` or `.F.`.
    Bool(bool),
    /// Another enumeration.
    Enum,
    /// A list: the byte span of its text in the record's text, parentheses included.
    List(usize, usize),
    /// An integer or real, as [`Param::as_f64`](crate::Param::as_f64) gives it.
    Number(f64),
}

/// The end of the blanks (space, tab, line breaks) from `i`.
pub(crate) fn blanks(t: &[u8], mut i: usize) -> usize {
    while i < t.len() && matches!(t[i], b' ' | b'\n' | b'\r' | b'\t') {
        i += 1;
    }
    i
}

/// The `N` parameters after the name string of the record `keyword(...)` that starts at
/// `body` in `text` (an instance's text and its body offset); `None` when the record has
/// another shape (see the module docs).
pub(crate) fn flat<const N: usize>(text: &[u8], body: usize, keyword: &[u8]) -> Option<[Flat; N]> {
    flat_after(text, body, keyword, 1)
}

/// [`flat`] of a record that starts with `strings` strings (0 for `REPRESENTATION_MAP`,
/// 2 for `ITEM_DEFINED_TRANSFORMATION`'s name and description).
pub(crate) fn flat_after<const N: usize>(
    text: &[u8],
    body: usize,
    keyword: &[u8],
    strings: usize,
) -> Option<[Flat; N]> {
    let t = text.get(body..)?.strip_prefix(keyword)?;
    let mut i = blanks(t, 0);
    if t.get(i)? != &b'(' {
        return None;
    }
    i += 1;
    for n in 0..strings {
        i = blanks(t, i);
        if n > 0 {
            if t.get(i)? != &b',' {
                return None;
            }
            i = blanks(t, i + 1);
        }
        i = plain_string_end(t, i)?;
    }
    let mut out = [Flat::Unset; N];
    for (n, slot) in out.iter_mut().enumerate() {
        i = blanks(t, i);
        if n + strings > 0 {
            if t.get(i)? != &b',' {
                return None;
            }
            i = blanks(t, i + 1);
        }
        let (value, end) = match *t.get(i)? {
            b'#' => {
                let e = reference_end(t, i)?;
                (Flat::Ref(EntityId(reference_id(&t[i..e])?)), e)
            }
            b'$' => (Flat::Unset, i + 1),
            b'*' => (Flat::Derived, i + 1),
            b'.' => {
                let e = enumeration_end(t, i)?;
                match &t[i..e] {
                    b".T." => (Flat::Bool(true), e),
                    b".F." => (Flat::Bool(false), e),
                    _ => (Flat::Enum, e),
                }
            }
            b'(' => {
                let e = list_end(t, i)?;
                let at = text.len() - t.len();
                (Flat::List(at + i, at + e), e)
            }
            b'+' | b'-' | b'0'..=b'9' => {
                let (e, _) = number_end(t, i)?;
                (Flat::Number(fast_float2::parse(&t[i..e]).ok()?), e)
            }
            _ => return None,
        };
        *slot = value;
        i = end;
    }
    i = blanks(t, i);
    (t.get(i)? == &b')').then_some(out)
}

/// The end of the string that opens at `i` (after its closing `'`), for a string with no
/// doubled apostrophe; `None` otherwise.
pub(crate) fn plain_string_end(t: &[u8], i: usize) -> Option<usize> {
    if t.get(i)? != &b'\'' {
        return None;
    }
    let end = t[i + 1..].iter().position(|&b| b == b'\'')? + i + 2;
    (t.get(end) != Some(&b'\'')).then_some(end)
}

/// The end of the list that opens at `i` (after its `)`): `None` when it holds a string,
/// a binary or a comment (left to the general reader) or does not close.
fn list_end(t: &[u8], mut i: usize) -> Option<usize> {
    let mut depth = 0usize;
    loop {
        match *t.get(i)? {
            b'(' => depth += 1,
            b')' => {
                depth -= 1;
                if depth == 0 {
                    return Some(i + 1);
                }
            }
            b'\'' | b'"' | b'/' => return None,
            _ => {}
        }
        i += 1;
    }
}

/// The references of the list `text[span.0..span.1]` (a [`Flat::List`]) when it holds
/// references only, with blanks at most between its tokens; `None` otherwise (the caller
/// then reads the record with the general reader).
pub(crate) fn ref_list(text: &[u8], (start, end): (usize, usize)) -> Option<Vec<EntityId>> {
    let t = text.get(start..end)?;
    let mut i = blanks(t, 1);
    let mut out = Vec::with_capacity(t.len() / 4);
    if t.get(i)? == &b')' {
        return (i + 1 == t.len()).then_some(out);
    }
    loop {
        if t.get(i)? != &b'#' {
            return None;
        }
        let e = reference_end(t, i)?;
        out.push(EntityId(reference_id(&t[i..e])?));
        i = blanks(t, e);
        match *t.get(i)? {
            b',' => i = blanks(t, i + 1),
            b')' => return (i + 1 == t.len()).then_some(out),
            _ => return None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::param::{parse_body, Body, Param, Value};
    use proptest::prelude::*;

    /// What the general reader gives for parameter `p` of a flat record, as a [`Flat`].
    fn general(p: &Param<'_>) -> Option<Flat> {
        Some(match &p.value {
            Value::Reference(id) => Flat::Ref(*id),
            Value::Unset => Flat::Unset,
            Value::Derived => Flat::Derived,
            Value::Enumeration("T") => Flat::Bool(true),
            Value::Enumeration("F") => Flat::Bool(false),
            Value::Enumeration(_) => Flat::Enum,
            Value::Integer(i) => Flat::Number(*i as f64),
            Value::Real(x) => Flat::Number(*x),
            Value::List(_) => Flat::List(p.start, p.end),
            _ => return None,
        })
    }

    fn piece() -> impl Strategy<Value = &'static str> {
        prop_oneof![
            4 => proptest::sample::select(vec![
                "#12", "#0", "#7", "$", "*", ".T.", ".F.", ".U.", "1.", "-2.5E-3", "7", "+0.5", "(#1,#2)", "( #3 )", "()",
                "(#4,\n#5)",
            ]),
            1 => proptest::sample::select(vec![
                "#99999999999999999999999", ".T", "99999999999999999999", "A(1.)", "'s'", "#", "1.E", "@3", "/* c */#4",
                "((#1),#2)", "(1.,2.)", "('a',#1)", "(/*c*/#1)", "(#1 #2)", "(#1,)", "(,#1)", "(#1,*)",
            ]),
        ]
    }

    fn gap() -> impl Strategy<Value = &'static str> {
        prop_oneof![8 => proptest::sample::select(vec!["", "", " ", "\n", "  "]), 1 => Just(",")]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1024))]

        /// Whenever the flat reading gives parameters for a record the general reader
        /// reads, the general reader gives a simple record of that name with the leading
        /// strings and the same parameters.
        #[test]
        fn flat_records_read_as_the_general_reader(
            params in proptest::collection::vec(piece(), 0..5),
            gaps in proptest::collection::vec(gap(), 12),
            name in proptest::sample::select(vec!["LINE", "LINE", "LINE", "LINEX", "LINE "]),
            strings in proptest::sample::select(vec![
                vec![], vec!["''"], vec!["''"], vec!["'a b'"], vec!["'it''s'"], vec!["'"], vec!["''", "'d'"],
            ]),
            other_arity in proptest::bool::weighted(0.2),
        ) {
            let n = if other_arity { (params.len() + 1) % 5 } else { params.len() };
            let mut text = format!("{name}({}{}", gaps[0], strings.join(","));
            for (k, p) in params.iter().enumerate() {
                let comma = if k == 0 && strings.is_empty() { "" } else { "," };
                text.push_str(&format!("{}{comma}{}{}", gaps[(2 * k + 1) % 12], gaps[(2 * k + 2) % 12], p));
            }
            text.push_str(gaps[11]);
            text.push(')');
            let (t, m) = (text.as_bytes(), strings.len());
            let read = match n {
                0 => flat_after::<0>(t, 0, b"LINE", m).map(|a| a.to_vec()),
                1 => flat_after::<1>(t, 0, b"LINE", m).map(|a| a.to_vec()),
                2 => flat_after::<2>(t, 0, b"LINE", m).map(|a| a.to_vec()),
                3 => flat_after::<3>(t, 0, b"LINE", m).map(|a| a.to_vec()),
                _ => flat_after::<4>(t, 0, b"LINE", m).map(|a| a.to_vec()),
            };
            // Only records the general reader reads count: a document's records were all
            // checked by its parse (a list is skipped by its parentheses, not checked).
            let body = parse_body(text.as_bytes(), 0);
            if let (Some(read), Ok(body)) = (read, body) {
                let Body::Simple(r) = body else {
                    return Err(TestCaseError::fail(format!("{text}: flat {read:?}, general {body:?}")));
                };
                prop_assert_eq!(r.name, "LINE", "{}", text);
                prop_assert_eq!(r.params.len(), read.len() + m, "{}", text);
                for p in &r.params[..m] {
                    prop_assert!(matches!(p.value, Value::String(_)), "{}", text);
                }
                for (p, f) in r.params[m..].iter().zip(&read) {
                    prop_assert_eq!(general(p), Some(*f), "{}", text);
                    // A list of references reads as the general reader's items.
                    if let (Flat::List(a, b), Value::List(items)) = (f, &p.value) {
                        if let Some(ids) = ref_list(text.as_bytes(), (*a, *b)) {
                            let general: Vec<_> = items.iter().map(|q| q.as_ref_id()).collect();
                            prop_assert_eq!(general, ids.into_iter().map(Some).collect::<Vec<_>>(), "{}", text);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_usual_layouts_are_read() {
        let t = b"AXIS2_PLACEMENT_3D('',#12,#13,$)";
        assert_eq!(
            flat::<3>(t, 0, b"AXIS2_PLACEMENT_3D"),
            Some([Flat::Ref(EntityId(12)), Flat::Ref(EntityId(13)), Flat::Unset])
        );
        let t = b"#5 = ORIENTED_EDGE ( 'NONE', *, *, #40, .F. ) ;";
        assert_eq!(
            flat::<4>(t, 5, b"ORIENTED_EDGE"),
            Some([Flat::Derived, Flat::Derived, Flat::Ref(EntityId(40)), Flat::Bool(false)])
        );
        assert_eq!(flat::<2>(b"VECTOR('',#3,1)", 0, b"VECTOR"), Some([Flat::Ref(EntityId(3)), Flat::Number(1.0)]));
        // Another arity, a list, a comment, another name: left to the general reader.
        assert_eq!(flat::<1>(b"VECTOR('',#3,1)", 0, b"VECTOR"), None);
        let t = b"EDGE_LOOP('',( #3,#4 ))";
        let Some([Flat::List(a, b)]) = flat::<1>(t, 0, b"EDGE_LOOP") else { panic!("a list") };
        assert_eq!(ref_list(t, (a, b)), Some(vec![EntityId(3), EntityId(4)]));
        assert_eq!(flat::<1>(b"A('',('x'))", 0, b"A"), None);
        assert_eq!(flat::<1>(b"PLANE('',/**/#3)", 0, b"PLANE"), None);
        assert_eq!(flat::<1>(b"PLANES('',#3)", 0, b"PLANE"), None);
        let t = b"REPRESENTATION_MAP(#4,#5)";
        assert_eq!(
            flat_after::<2>(t, 0, b"REPRESENTATION_MAP", 0),
            Some([Flat::Ref(EntityId(4)), Flat::Ref(EntityId(5))])
        );
        let t = b"ITEM_DEFINED_TRANSFORMATION('','',#6,#7)";
        assert_eq!(
            flat_after::<2>(t, 0, b"ITEM_DEFINED_TRANSFORMATION", 2),
            Some([Flat::Ref(EntityId(6)), Flat::Ref(EntityId(7))])
        );
    }
}
