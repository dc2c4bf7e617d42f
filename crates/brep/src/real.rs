//! Real numbers as text the way IGES (5.3 §2.2.2.3, real constants) and STEP
//! (ISO 10303-21 §6.4.3, real tokens) both want them: the shortest digits that read back
//! to the same `f64`, always with a decimal point, and an `E` exponent outside a range
//! of magnitudes each format's writer chooses.
//!
//! The shortest digits come from `zmij` (dtolnay's port of Victor Zverovich's Żmij, a
//! Schubfach variant; the crate serde_json formats with): several times faster than
//! `core::fmt`'s and about twice as fast as `ryu`'s, which it replaced (15 against 30 ns
//! per 17-digit real on the project VM), and written into the caller's buffer without
//! allocating. Which text follows from the digits is the same as `format!("{x:?}")` or
//! `format!("{x}")` laid out as below (tested against both).

/// Appends `x` to `out`: in plain decimal notation when `x == 0` or
/// `decimal.0 ≤ |x| < decimal.1` (`1.`, `-0.25`, `123.5`), otherwise as a mantissa with
/// one digit before the point and an exponent (`1.E-7`, `6.02E23`). `x` must be finite.
///
/// ```
/// use cadmorph_brep::real::write_real;
/// let text = |x: f64| {
///     let mut out = Vec::new();
///     write_real(x, (1e-5, 1e15), &mut out);
///     String::from_utf8(out).unwrap()
/// };
/// assert_eq!(text(1.0), "1.");
/// assert_eq!(text(-0.25), "-0.25");
/// assert_eq!(text(1e-7), "1.E-7");
/// assert_eq!(text(6.02e23), "6.02E23");
/// assert_eq!(text(0.1 + 0.2).parse::<f64>().unwrap(), 0.1 + 0.2);
/// ```
pub fn write_real(x: f64, decimal: (f64, f64), out: &mut Vec<u8>) {
    debug_assert!(x.is_finite());
    let mut buf = zmij::Buffer::new();
    let s = buf.format_finite(x).as_bytes();
    let a = x.abs();
    // zmij writes plain decimals for 1e-5 ≤ |x| < 1e16 (`123.0`, `0.25`, `0.00001`),
    // never with trailing zeros but the `.0` of an integer: inside that, copy.
    if a >= decimal.0 && a < decimal.1 && decimal.0 >= 1e-5 && decimal.1 <= 1e16 {
        match s.strip_suffix(b".0") {
            Some(int) => {
                out.extend_from_slice(int);
                out.push(b'.');
            }
            None => out.extend_from_slice(s),
        }
        return;
    }
    // zmij writes `[-]digits[.digits][e(-|+)exp]` or `[-]0.000digits`: take the significant
    // digits and the decimal exponent of the first one.
    let (neg, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    let (mant, exp) = match s.iter().position(|&c| c == b'e') {
        Some(i) => (&s[..i], parse_exp(&s[i + 1..])),
        None => (s, 0),
    };
    let mut digits = [0u8; 24];
    let mut n = 0;
    let mut point = None;
    let mut lead = 0i32; // zeros between the point and the first significant digit
    for &c in mant {
        if c == b'.' {
            point = Some(n);
        } else if n == 0 && c == b'0' {
            if point.is_some() {
                lead += 1;
            }
        } else {
            digits[n] = c;
            n += 1;
        }
    }
    // Trailing zeros of the integer part count as exponent, not digits.
    let int_len = point.unwrap_or(n) as i32;
    while n > 1 && digits[n - 1] == b'0' {
        n -= 1;
    }
    if neg {
        out.push(b'-');
    }
    if n == 0 || x == 0.0 {
        out.extend_from_slice(b"0.");
        return;
    }
    // x = 0.d1 d2 ... × 10^e10, i.e. d1.d2... × 10^(e10 - 1).
    let e10 = if point.is_some() && int_len == 0 { exp - lead } else { exp + int_len };
    if a >= decimal.0 && a < decimal.1 {
        if e10 <= 0 {
            out.extend_from_slice(b"0.");
            out.extend(std::iter::repeat_n(b'0', (-e10) as usize));
            out.extend_from_slice(&digits[..n]);
        } else {
            let e = e10 as usize;
            if n <= e {
                out.extend_from_slice(&digits[..n]);
                out.extend(std::iter::repeat_n(b'0', e - n));
                out.push(b'.');
            } else {
                out.extend_from_slice(&digits[..e]);
                out.push(b'.');
                out.extend_from_slice(&digits[e..n]);
            }
        }
    } else {
        out.push(digits[0]);
        out.push(b'.');
        out.extend_from_slice(&digits[1..n]);
        out.push(b'E');
        let mut ib = itoa::Buffer::new();
        out.extend_from_slice(ib.format(e10 - 1).as_bytes());
    }
}

fn parse_exp(s: &[u8]) -> i32 {
    let (neg, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, s),
    };
    let v = s.iter().fold(0i32, |v, &c| v * 10 + i32::from(c - b'0'));
    if neg {
        -v
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The layout of `core::fmt`'s shortest digits, as the writers did before.
    fn reference(x: f64, decimal: (f64, f64)) -> String {
        let a = x.abs();
        if a == 0.0 || (decimal.0..decimal.1).contains(&a) {
            let s = format!("{x}");
            let mut s = if s.contains('.') { s.trim_end_matches('0').to_owned() } else { s };
            if !s.contains('.') {
                s.push('.');
            }
            s
        } else {
            let s = format!("{x:e}");
            let (m, e) = s.split_once('e').unwrap();
            let dot = if m.contains('.') { "" } else { "." };
            format!("{m}{dot}E{e}")
        }
    }

    fn text(x: f64, decimal: (f64, f64)) -> String {
        let mut out = Vec::new();
        write_real(x, decimal, &mut out);
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn edges_of_the_ranges_and_of_the_digits() {
        for d in [(1e-5, 1e15), (1e-4, 1e16)] {
            for x in [
                0.0,
                -0.0,
                1.0,
                -1.0,
                10.0,
                100.0,
                1e14,
                1e15,
                9.99e14,
                1e16,
                1.5e16,
                123456789012345680.0,
                1e-4,
                9.99e-5,
                1e-5,
                9.9e-6,
                1e-7,
                0.1,
                0.3,
                1.0 / 3.0,
                2.5e-300,
                f64::MAX,
                f64::MIN_POSITIVE,
                5e-324,
                12345.678,
                1e21,
                1e22,
                6.02e23,
            ] {
                assert_eq!(text(x, d), reference(x, d), "{x:e} with {d:?}");
                assert_eq!(text(x, d).parse::<f64>().unwrap().to_bits(), x.to_bits(), "{x:e}");
            }
        }
    }

    /// The same value, length and layout as `core::fmt`'s text. The last digit may
    /// differ where the exact value lies half-way between two shortest candidates:
    /// zmij (as ryu) rounds such ties to even, `core::fmt` up (`-1921938935185794.25` is
    /// `…794.2` in one and `…794.3` in the other; both read back to the same bits).
    fn agrees(x: f64, d: (f64, f64)) -> Result<(), TestCaseError> {
        let (a, b) = (text(x, d), reference(x, d));
        prop_assert_eq!(a.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{}", a);
        prop_assert_eq!(a.len(), b.len(), "{} vs {}", a, b);
        let shape = |s: &str| s.bytes().map(|c| if c.is_ascii_digit() { b'9' } else { c }).collect::<Vec<_>>();
        prop_assert_eq!(shape(&a), shape(&b), "{} vs {}", a, b);
        Ok(())
    }

    proptest! {
        #[test]
        fn same_text_as_core_fmt(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            for d in [(1e-5, 1e15), (1e-4, 1e16)] {
                agrees(x, d)?;
            }
        }

        #[test]
        fn same_text_for_everyday_magnitudes(m in -1e6f64..1e6, e in -12i32..12) {
            let x = m * 10f64.powi(e);
            for d in [(1e-5, 1e15), (1e-4, 1e16)] {
                agrees(x, d)?;
            }
        }
    }
}
