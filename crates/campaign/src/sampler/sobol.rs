//! Sobol' points (Sobol' 1967) with the direction numbers of Joe & Kuo 2008 ("Constructing
//! Sobol sequences with better two-dimensional projections", SIAM J. Sci. Comput. 30,
//! file `new-joe-kuo-6.21201`), in the Gray-code order of Antonov & Saleev (1979) that
//! Joe and Kuo's own generator uses, optionally Owen-scrambled.
//!
//! The sequence comes from the `sobol` crate (1.0.2, which ships the Joe–Kuo tables and
//! builds the direction numbers with the recurrence of Bratley & Fox 1988); it is checked
//! against an independent construction from the published table in the tests. Scrambling
//! is the nested uniform (Owen 1995) scramble in the hash-based form of Burley 2020
//! ("Practical hash-based Owen scrambling", JCGT 9(4)): bit-reverse, a Laine–Karras
//! permutation seeded per dimension, reverse back; a digit's flip depends only on the
//! digits above it, so every elementary interval keeps its count (the net property).
//!
//! Crates checked: `sobol_burley` (0.5; Owen-scrambled too, but `f32` output, at most
//! 2¹⁶ points and 256 dimensions, and no unscrambled sequence to check against Joe–Kuo)
//! and `sobol` (1.0.2; unscrambled only, `f64`, up to 21 201 dimensions). `sobol` is used
//! for the sequence and the scramble is done here.

use ::sobol::params::JoeKuoD6;
use ::sobol::Sobol;

use super::Stream;

/// Dimensions available (the Joe–Kuo table loaded: `new-joe-kuo-6.1000`).
pub const MAX_DIMS: usize = 1000;

/// Burley 2020's Laine–Karras permutation: each output bit depends on the bits below it
/// only (adding a seed and xoring in products with even constants carry upwards).
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen's nested uniform scramble of the 32-digit binary fraction `x` (Burley 2020).
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The first `n` points of the `d`-dimensional Sobol' sequence as 32-bit binary
/// fractions (`x / 2³²`), unscrambled.
pub fn integer_points(n: usize, d: usize) -> Vec<Vec<u32>> {
    if d == 0 {
        return vec![Vec::new(); n];
    }
    let params = JoeKuoD6::standard();
    // 32 digits: exact in f64, and 2^32 − 1 points.
    let seq = Sobol::<f64>::new_with_resolution(d, &params, Some(32));
    seq.take(n).map(|p| p.iter().map(|&x| (x * 4_294_967_296.0) as u32).collect()).collect()
}

/// The first `n` points of `[0, 1)^d`: Sobol' points, Owen-scrambled with one seed per
/// dimension drawn from `scramble_seed` when given.
pub fn points(n: usize, d: usize, scramble_seed: Option<u64>) -> Vec<Vec<f64>> {
    let seeds: Vec<u32> = match scramble_seed {
        Some(s) => {
            let mut st = Stream::new(s);
            (0..d).map(|_| st.word()).collect()
        }
        None => Vec::new(),
    };
    integer_points(n, d)
        .into_iter()
        .map(|p| {
            p.iter()
                .enumerate()
                .map(|(j, &x)| {
                    let x = if seeds.is_empty() { x } else { owen_scramble(x, seeds[j]) };
                    x as f64 / 4_294_967_296.0
                })
                .collect()
        })
        .collect()
}
