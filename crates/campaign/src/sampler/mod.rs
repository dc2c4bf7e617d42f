//! Samplers of the design space (issue 16, Deliver 2), all seeded and reproducible.
//!
//! Random draws come from ChaCha8 (`rand_chacha`, whose stream for a seed is fixed by the
//! ChaCha specification, RFC 8439's block function with 8 rounds) through [`Stream`], which
//! turns its 64-bit words into uniforms and indices itself: a plan depends on the seed and
//! on this crate only, not on the distribution code of a `rand` release.

pub mod factorial;
pub mod lhs;
pub mod oat;
pub mod random;
pub mod sobol;

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::space::Parameter;

/// How the values of LHS designs are chosen among candidates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Criterion {
    /// The first design drawn.
    None,
    /// The candidate with the largest smallest distance between two points (Morris &
    /// Mitchell 1995, "Exploratory designs for computational experiments", the maximin
    /// criterion; as pyDOE's `lhs(criterion="maximin")`).
    Maximin,
    /// The candidate with the smallest largest absolute correlation between two columns
    /// (as pyDOE's `lhs(criterion="correlation")`; Iman & Conover 1982 reduce the same
    /// quantity).
    Correlation,
}

/// A sampling plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Every combination of the levels ([`factorial`]).
    FullFactorial {
        /// Levels of each range parameter (sets use their values).
        levels: usize,
    },
    /// The base point, then each parameter through its levels with the others at base
    /// ([`oat`]).
    OneAtATime {
        /// Levels of each range parameter (sets use their values).
        levels: usize,
    },
    /// Independent uniform points ([`random`]).
    Random {
        /// Points.
        n: usize,
    },
    /// Latin hypercube ([`lhs`]).
    Lhs {
        /// Points.
        n: usize,
        /// Choice among candidate designs.
        criterion: Criterion,
        /// Candidate designs drawn when a criterion is given.
        candidates: usize,
    },
    /// Sobol' points, Joe–Kuo direction numbers, optionally Owen-scrambled ([`sobol`]).
    Sobol {
        /// Points.
        n: usize,
        /// Owen scrambling (seeded).
        scramble: bool,
    },
}

/// Uniforms and indices from ChaCha8 with a fixed seed.
pub struct Stream(ChaCha8Rng);

impl Stream {
    /// The stream of `seed`.
    pub fn new(seed: u64) -> Self {
        Stream(ChaCha8Rng::seed_from_u64(seed))
    }
    /// A uniform in `[0, 1)`: the top 53 bits of the next word.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// A uniform index in `0..n` (Lemire's multiply-shift with rejection, unbiased).
    pub fn below(&mut self, n: usize) -> usize {
        let n = n as u64;
        let threshold = n.wrapping_neg() % n;
        loop {
            let m = (self.0.next_u64() as u128) * (n as u128);
            if (m as u64) >= threshold {
                return (m >> 64) as usize;
            }
        }
    }
    /// The next raw 32-bit word.
    pub fn word(&mut self) -> u32 {
        self.0.next_u32()
    }
    /// A random permutation of `0..n` (Fisher–Yates, Knuth vol. 2 §3.4.2 algorithm P).
    pub fn permutation(&mut self, n: usize) -> Vec<usize> {
        let mut p: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = self.below(i + 1);
            p.swap(i, j);
        }
        p
    }
}

/// The points of `method` for `params`: one row of parameter values per variant.
pub fn plan(method: &Method, params: &[Parameter], seed: u64) -> Vec<Vec<f64>> {
    let d = params.len();
    let to_values = |unit: Vec<Vec<f64>>| -> Vec<Vec<f64>> {
        unit.into_iter().map(|u| u.iter().zip(params).map(|(&t, p)| p.values.at(t)).collect()).collect()
    };
    match *method {
        Method::FullFactorial { levels } => factorial::full_factorial(params, levels),
        Method::OneAtATime { levels } => oat::one_at_a_time(params, levels),
        Method::Random { n } => to_values(random::uniform(n, d, seed)),
        Method::Lhs { n, criterion, candidates } => to_values(lhs::latin_hypercube(n, d, seed, criterion, candidates)),
        Method::Sobol { n, scramble } => to_values(sobol::points(n, d, scramble.then_some(seed))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_is_uniform_and_reproducible() {
        let (mut a, mut b) = (Stream::new(7), Stream::new(7));
        let xs: Vec<f64> = (0..10_000).map(|_| a.uniform()).collect();
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
        assert_eq!(xs, (0..10_000).map(|_| b.uniform()).collect::<Vec<_>>());
        // Mean of U(0,1) is 1/2 with standard error 1/sqrt(12 n) ≈ 0.0029: 5 sigma.
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        assert!((mean - 0.5).abs() < 0.015, "{mean}");
        let mut counts = [0usize; 3];
        for _ in 0..3000 {
            counts[a.below(3)] += 1;
        }
        assert!(counts.iter().all(|&c| (850..1150).contains(&c)), "{counts:?}");
        let mut p = a.permutation(50);
        p.sort_unstable();
        assert_eq!(p, (0..50).collect::<Vec<_>>());
    }
}
