//! Seeded inputs shared by the benches.
#![allow(dead_code)]

use cadmorph_morph::math::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

/// `n` points uniform in `[lo, hi]³` (XorShift seeded with `seed`).
pub fn points(n: usize, lo: f64, hi: f64, seed: u64) -> Vec<Point3<f64>> {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    (0..n).map(|_| Point3::new(rng.gen_range(lo..hi), rng.gen_range(lo..hi), rng.gen_range(lo..hi))).collect()
}

/// `n` displacements uniform in `[-a, a]³`.
pub fn moves(n: usize, a: f64, seed: u64) -> Vec<Vector3<f64>> {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    (0..n).map(|_| Vector3::new(rng.gen_range(-a..a), rng.gen_range(-a..a), rng.gen_range(-a..a))).collect()
}
