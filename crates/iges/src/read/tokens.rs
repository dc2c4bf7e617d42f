//! A record's parameters as read, stored as two arrays: a kind byte and an 8-byte
//! payload per parameter (9 bytes where the [`Raw`] enum takes 16). The bulk of a file
//! is the reals of B-spline nets: this halves the memory the tokenizer writes and the
//! conversion to NURBS reads, and lets a run of reals be read as plain `f64` bits.

use super::lexer::{Raw, Sink};

/// Kind bytes.
const DEFAULT: u8 = 0;
const INTEGER: u8 = 1;
const REAL: u8 = 2;
const TEXT: u8 = 3;

/// The parameters of one record, in order (see the module docs). Reads back exactly the
/// [`Raw`] values pushed.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Tokens {
    kinds: Vec<u8>,
    /// Integers as `i64` bits, reals as `f64` bits, strings as `start << 32 | len`.
    bits: Vec<u64>,
}

impl Tokens {
    /// Room for `n` parameters.
    pub fn with_capacity(n: usize) -> Self {
        Tokens { kinds: Vec::with_capacity(n), bits: Vec::with_capacity(n) }
    }

    /// Appends one parameter.
    #[inline]
    pub fn push(&mut self, raw: Raw) {
        let (kind, bits) = match raw {
            Raw::Default => (DEFAULT, 0),
            Raw::Integer(i) => (INTEGER, i as u64),
            Raw::Real(x) => (REAL, x.to_bits()),
            Raw::Text { start, len } => (TEXT, (u64::from(start) << 32) | u64::from(len)),
        };
        self.kinds.push(kind);
        self.bits.push(bits);
    }

    /// The number of parameters.
    pub fn len(&self) -> usize {
        self.kinds.len()
    }

    /// Parameter `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Option<Raw> {
        let kind = *self.kinds.get(i)?;
        let bits = self.bits[i];
        Some(match kind {
            INTEGER => Raw::Integer(bits as i64),
            REAL => Raw::Real(f64::from_bits(bits)),
            TEXT => Raw::Text { start: (bits >> 32) as u32, len: bits as u32 },
            _ => Raw::Default,
        })
    }

    /// The first parameter.
    pub fn first(&self) -> Option<Raw> {
        self.get(0)
    }

    /// Every parameter, in order.
    pub fn iter(&self) -> impl Iterator<Item = Raw> + '_ {
        (0..self.len()).map(|i| self.get(i).expect("in range"))
    }

    /// Room for `n` more parameters.
    pub fn reserve(&mut self, n: usize) {
        self.kinds.reserve(n);
        self.bits.reserve(n);
    }

    /// Appends `other`'s parameters.
    pub fn append(&mut self, other: &Tokens) {
        self.kinds.extend_from_slice(&other.kinds);
        self.bits.extend_from_slice(&other.bits);
    }

    /// Whether a parameter is a string.
    pub fn has_text(&self) -> bool {
        self.kinds.contains(&TEXT)
    }

    /// The first string among parameters `range`, if any.
    pub fn text_in(&self, range: std::ops::Range<usize>) -> Option<usize> {
        let start = range.start;
        self.kinds[range].iter().position(|&k| k == TEXT).map(|k| start + k)
    }

    /// Parameters `range` as numbers (see [`Reals::get`]).
    pub fn reals(&self, range: std::ops::Range<usize>) -> Reals<'_> {
        Reals { kinds: &self.kinds[range.clone()], bits: &self.bits[range] }
    }
}

impl Sink for Tokens {
    #[inline]
    fn put(&mut self, _offset: usize, raw: Raw) {
        self.push(raw);
    }
}

/// A run of parameters read as numbers.
#[derive(Clone, Copy)]
pub(crate) struct Reals<'a> {
    kinds: &'a [u8],
    bits: &'a [u64],
}

impl Reals<'_> {
    /// Parameter `k` of the run as a real: a real as it is, an integer converted, a
    /// default (or a string, which callers refuse first) as 0.
    #[inline]
    pub fn get(&self, k: usize) -> f64 {
        match self.kinds[k] {
            REAL => f64::from_bits(self.bits[k]),
            INTEGER => self.bits[k] as i64 as f64,
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::Strategy as _;

    proptest::proptest! {
        /// Every value reads back as pushed, bit for bit (NaN payloads, signed zeros and
        /// extreme integers included), and as a number where it is one.
        #[test]
        fn values_read_back_as_pushed(
            values in proptest::collection::vec(proptest::prop_oneof![
                proptest::prelude::Just(Raw::Default),
                proptest::prelude::any::<i64>().prop_map(Raw::Integer),
                proptest::prelude::any::<u64>().prop_map(|b| Raw::Real(f64::from_bits(b))),
                (proptest::prelude::any::<u32>(), proptest::prelude::any::<u32>()).prop_map(|(start, len)| Raw::Text { start, len }),
            ], 0..40),
        ) {
            let mut t = Tokens::default();
            for v in &values {
                t.push(*v);
            }
            proptest::prop_assert_eq!(t.len(), values.len());
            let back: Vec<Raw> = t.iter().collect();
            for (a, b) in back.iter().zip(&values) {
                match (a, b) {
                    (Raw::Real(x), Raw::Real(y)) => proptest::prop_assert_eq!(x.to_bits(), y.to_bits()),
                    _ => proptest::prop_assert_eq!(a, b),
                }
            }
            let reals = t.reals(0..t.len());
            for (k, v) in values.iter().enumerate() {
                let want = match *v {
                    Raw::Real(x) => x,
                    Raw::Integer(i) => i as f64,
                    _ => 0.0,
                };
                proptest::prop_assert_eq!(reals.get(k).to_bits(), want.to_bits());
            }
            let first_text = values.iter().position(|v| matches!(v, Raw::Text { .. }));
            proptest::prop_assert_eq!(t.text_in(0..t.len()), first_text);
            proptest::prop_assert_eq!(t.has_text(), first_text.is_some());
        }
    }
}
