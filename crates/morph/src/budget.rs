//! The memory budget: the most memory one allocation of a deformation (or of a caller
//! that sizes its work by the same rule, such as seam refinement) may ask for.
//!
//! Sizes that come from input (a lattice of `L×M×N` nodes, `N` RBF centres, a number of
//! knots to insert) are multiplied out in `u128`, so they cannot wrap, and compared with
//! the budget before anything is allocated. A request over the budget is refused with
//! [`crate::Error::TooLarge`], which names the parameter and the bytes it
//! would need, instead of aborting the process on a failed allocation.
//!
//! The budget is process-wide (like rayon's global pool): programs set it once at start-up
//! with [`set_limit`] (the `cadmorph` CLI's `--max-memory`). Until then it is half of the
//! machine's physical memory (`MemTotal` of `/proc/meminfo`), or 8 GiB where that cannot
//! be read.
//!
//! ```
//! use cadmorph_morph::{budget, Error};
//! // 2^32 × 2^32 × 2 lattice nodes of three f64 each: the product does not wrap.
//! let e = budget::check("FFD lattice", &[1 << 32, 1 << 32, 2, 3], 8).unwrap_err();
//! assert!(matches!(e, Error::TooLarge { .. }));
//! assert!(e.to_string().contains("FFD lattice"));
//! budget::check("FFD lattice", &[3, 3, 3, 3], 8)?;
//! # Ok::<(), Error>(())
//! ```

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

use crate::{Error, Result};

/// 0 means "not set": use [`default_limit`].
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// Half of the physical memory, read once; 8 GiB where `/proc/meminfo` is not available.
pub fn default_limit() -> u64 {
    static DEFAULT: OnceLock<u64> = OnceLock::new();
    *DEFAULT.get_or_init(|| {
        std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| {
                let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
                let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
                Some(kib.saturating_mul(1024) / 2)
            })
            .filter(|&b| b > 0)
            .unwrap_or(8 << 30)
    })
}

/// The budget in force, in bytes.
pub fn limit() -> u64 {
    match LIMIT.load(Ordering::Relaxed) {
        0 => default_limit(),
        n => n,
    }
}

/// Set the process-wide budget in bytes (0 restores the default).
pub fn set_limit(bytes: u64) {
    LIMIT.store(bytes, Ordering::Relaxed);
}

/// The product of `counts` times `elem_bytes`, or `None` when it exceeds `u128`.
pub fn bytes_of(counts: &[usize], elem_bytes: usize) -> Option<u128> {
    counts.iter().try_fold(elem_bytes as u128, |acc, &c| acc.checked_mul(c as u128))
}

/// Check that `counts` elements (their product) of `elem_bytes` each fit the budget.
///
/// # Errors
///
/// [`Error::TooLarge`] naming `what`, the bytes needed (saturated at `u128::MAX` when the
/// product itself overflows) and the budget.
pub fn check(what: &str, counts: &[usize], elem_bytes: usize) -> Result<()> {
    let needed = bytes_of(counts, elem_bytes).unwrap_or(u128::MAX);
    let limit = limit();
    if needed > limit as u128 || needed > isize::MAX as u128 {
        return Err(Error::TooLarge { what: what.to_string(), needed, limit });
    }
    Ok(())
}

/// A byte count in words a person reads (`3.2 GB`, `12 PB`, `> 3e38 bytes`).
pub fn human_bytes(b: u128) -> String {
    const UNITS: [&str; 7] = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    if b == u128::MAX {
        return "more than 2^128 bytes".to_string();
    }
    let mut v = b as f64;
    let mut unit = 0;
    while v >= 1000.0 && unit + 1 < UNITS.len() {
        v /= 1000.0;
        unit += 1;
    }
    if unit + 1 == UNITS.len() && v >= 1000.0 {
        return format!("{:.1e} bytes", b as f64);
    }
    if unit == 0 {
        format!("{b} bytes")
    } else {
        format!("{v:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_do_not_wrap() {
        assert_eq!(bytes_of(&[1 << 32, 1 << 32, 2], 24), Some((1u128 << 65) * 24));
        assert_eq!(bytes_of(&[usize::MAX, usize::MAX, usize::MAX], 8), None);
        assert!(check("x", &[usize::MAX, usize::MAX, usize::MAX], 8).is_err());
    }

    #[test]
    fn human_readable() {
        assert_eq!(human_bytes(512), "512 bytes");
        assert_eq!(human_bytes(3_200_000_000), "3.2 GB");
        assert_eq!(human_bytes(24 * 1_000_000_000_000_000), "24.0 PB");
        assert!(human_bytes(u128::MAX).contains("2^128"));
    }

    #[test]
    fn default_is_positive() {
        assert!(default_limit() > 0);
    }
}
