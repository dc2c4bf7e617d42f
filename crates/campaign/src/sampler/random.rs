//! Independent uniform points in the unit cube (plain Monte Carlo).

use super::Stream;

/// `n` points of `[0, 1)^d`, each coordinate a uniform from the seeded stream, row by row.
pub fn uniform(n: usize, d: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut s = Stream::new(seed);
    (0..n).map(|_| (0..d).map(|_| s.uniform()).collect()).collect()
}
