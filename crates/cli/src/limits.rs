//! Limits given on the command line: the memory budget (`--max-memory`), tolerances that
//! a run can reach, and the control-point budget of refinement.

use anyhow::{bail, Result};

/// A size in bytes from `8G`, `512M`, `64k`, `2GiB` or a plain number of bytes (decimal
/// units are powers of 1000, `Ki`/`Mi`/`Gi`/`Ti` powers of 1024).
pub fn parse_memory(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let value: f64 = num.parse().map_err(|_| format!("{s:?} is not a size (examples: 8G, 512M, 2GiB, 1000000)"))?;
    let scale: f64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "m" | "mb" => 1e6,
        "g" | "gb" => 1e9,
        "t" | "tb" => 1e12,
        "ki" | "kib" => 1024.0,
        "mi" | "mib" => 1024f64.powi(2),
        "gi" | "gib" => 1024f64.powi(3),
        "ti" | "tib" => 1024f64.powi(4),
        other => return Err(format!("unknown size unit {other:?} (use k, M, G, T or Ki, Mi, Gi, Ti)")),
    };
    let bytes = value * scale;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("{s:?} is not a usable memory size"));
    }
    Ok(bytes as u64)
}

/// A tolerance must be a positive finite number: clap value parser.
pub fn positive(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|_| format!("{s:?} is not a number"))?;
    if !v.is_finite() || v <= 0.0 {
        return Err(format!("{s} is not a positive finite number"));
    }
    Ok(v)
}

/// A gap tolerance that `f64` can resolve at the model's size: at least 16 units in the
/// last place of the largest coordinate, or refinement could never reach it.
pub fn check_gap_tolerance(flag: &str, tol: f64, model_size: f64, unit: &str) -> Result<()> {
    let floor = 16.0 * f64::EPSILON * model_size;
    if tol < floor {
        bail!(
            "{flag} {tol:e} is below what double precision resolves on this model (size {model_size:.6e} {unit}: \
             at least {floor:.1e})"
        );
    }
    Ok(())
}

/// An angle tolerance in degrees: positive and below 90°.
pub fn check_angle_tolerance(flag: &str, deg: f64) -> Result<()> {
    if !(deg > 1e-12 && deg < 90.0) {
        bail!("{flag} {deg} must be above 1e-12 and below 90 degrees");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_memory("8G"), Ok(8_000_000_000));
        assert_eq!(parse_memory("2GiB"), Ok(2 << 30));
        assert_eq!(parse_memory("512M"), Ok(512_000_000));
        assert_eq!(parse_memory("1000"), Ok(1000));
        assert!(parse_memory("lots").is_err());
        assert!(parse_memory("3X").is_err());
        assert!(parse_memory("0").is_err());
    }

    #[test]
    fn tolerances() {
        for bad in ["nan", "inf", "-inf", "0", "-1e-5", "x"] {
            assert!(positive(bad).is_err(), "{bad}");
        }
        assert_eq!(positive("1.45e-5"), Ok(1.45e-5));
        assert!(check_gap_tolerance("--refine-tol", 1e-20, 145.0, "metres").is_err());
        assert!(check_gap_tolerance("--refine-tol", 1.45e-5, 145.0, "metres").is_ok());
        assert!(check_angle_tolerance("--angle-tol", 0.01).is_ok());
        assert!(check_angle_tolerance("--angle-tol", 90.0).is_err());
    }
}
