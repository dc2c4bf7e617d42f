//! Text helpers shared by the readers and writers: line splitting that keeps every byte,
//! number parsing with the line of a failure, and the number formats of the writers
//! (C `%g`, Python `'{:.16E}'`, Python `str`).

use crate::{Error, Result};

/// The lines of `text` as byte ranges, each including its line terminator, so that
/// concatenating them gives `text` back exactly.
pub(crate) fn line_ranges(text: &str) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, b) in text.bytes().enumerate() {
        if b == b'\n' {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    if start < text.len() {
        out.push(start..text.len());
    }
    out
}

/// A line without its terminator (`\n` or `\r\n`).
pub(crate) fn trim_eol(line: &str) -> &str {
    line.strip_suffix('\n').map(|l| l.strip_suffix('\r').unwrap_or(l)).unwrap_or(line)
}

/// Parse a float, accepting Fortran `D` exponents (`1.0D+00`); the error names `line`.
pub(crate) fn parse_f64(tok: &str, line: usize) -> Result<f64> {
    let t = tok.trim();
    let v = match t.parse::<f64>() {
        Ok(v) => v,
        Err(_) => t.replace(['D', 'd'], "E").parse::<f64>().map_err(|_| Error::syntax(line, "a number", tok))?,
    };
    Ok(v)
}

/// Parse an integer; the error names `line`.
pub(crate) fn parse_i64(tok: &str, line: usize) -> Result<i64> {
    tok.trim().parse::<i64>().map_err(|_| Error::syntax(line, "an integer", tok))
}

/// Check that every coordinate is finite.
pub(crate) fn check_finite(points: &[nalgebra::Point3<f64>]) -> Result<()> {
    // A parallel scan; the search for the first bad point only when there is one.
    use rayon::prelude::*;
    if points.par_iter().with_min_len(1 << 14).all(|p| p.iter().all(|v| v.is_finite())) {
        return Ok(());
    }
    for (i, p) in points.iter().enumerate() {
        for &v in p.iter() {
            if !v.is_finite() {
                return Err(Error::NonFinite { index: i, value: v });
            }
        }
    }
    Ok(())
}

/// Python's `'{:.{prec}E}'.format(x)` (also C's `%.{prec}E`): `2.2000000000000002E+00`.
pub(crate) fn py_exp(x: f64, prec: usize) -> String {
    let s = format!("{x:.prec$E}");
    let (m, e) = s.split_once('E').unwrap_or((&s, "0"));
    let e: i32 = e.parse().unwrap_or(0);
    let sign = if e < 0 { '-' } else { '+' };
    format!("{m}E{sign}{:02}", e.abs())
}

/// C's `%.{prec}g` (the format VTK's writers use for floats, with `prec` 6 or 11/17):
/// `prec` significant digits, trailing zeros removed, scientific notation when the
/// exponent is below −4 or at least `prec`; `-0` keeps its sign.
pub(crate) fn c_g(x: f64, prec: usize) -> String {
    if x == 0.0 {
        return if x.is_sign_negative() { "-0".into() } else { "0".into() };
    }
    if !x.is_finite() {
        return if x.is_nan() {
            "nan".into()
        } else if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    let p = prec.max(1);
    let sci = format!("{:.*e}", p - 1, x);
    let (m, e) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = e.parse().unwrap_or(0);
    if exp < -4 || exp >= p as i32 {
        let m = strip_zeros(m);
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{m}e{sign}{:02}", exp.abs())
    } else {
        let decimals = (p as i32 - 1 - exp).max(0) as usize;
        strip_zeros(&format!("{x:.decimals$}")).to_string()
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// Python's `str` of a float (PyGeM writes every number this way).
pub(crate) fn py_str(x: f64) -> String {
    cadmorph_morph::prm::float_str(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c_g_matches_printf() {
        // Values and expected strings from C printf("%g") (glibc).
        assert_eq!(c_g(-40.2, 6), "-40.2");
        assert_eq!(c_g(0.777718123, 6), "0.777718");
        assert_eq!(c_g(1.0e-5, 6), "1e-05");
        assert_eq!(c_g(123456789.0, 6), "1.23457e+08");
        assert_eq!(c_g(-0.0, 6), "-0");
        assert_eq!(c_g(100000.0, 6), "100000");
        assert_eq!(c_g(0.0001, 6), "0.0001");
        assert_eq!(c_g(9.9999999, 6), "10");
    }

    #[test]
    fn py_exp_matches_python() {
        // Python: '{:.16E}'.format(2.2) == '2.2000000000000002E+00'
        assert_eq!(py_exp(2.2, 16), "2.2000000000000002E+00");
        assert_eq!(py_exp(-1.2, 16), "-1.2000000000000000E+00");
        assert_eq!(py_exp(0.0, 16), "0.0000000000000000E+00");
        assert_eq!(py_exp(1e-120, 3), "1.000E-120");
    }

    #[test]
    fn lines_keep_every_byte() {
        let t = "a\r\nb\n\nc";
        let r = line_ranges(t);
        assert_eq!(r.iter().map(|r| &t[r.clone()]).collect::<String>(), t);
        assert_eq!(r.len(), 4);
        assert_eq!(trim_eol(&t[r[0].clone()]), "a");
    }
}
