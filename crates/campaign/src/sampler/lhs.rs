//! Latin hypercube sampling (McKay, Beckman & Conover 1979, "A comparison of three
//! methods for selecting values of input variables in the analysis of output from a
//! computer code", Technometrics 21(2)): each coordinate's `n` strata `[k/n, (k+1)/n)`
//! hold exactly one point, at a uniform position inside it.

use super::{Criterion, Stream};

/// One Latin hypercube design of `n` points in `[0, 1)^d`.
fn one_design(n: usize, d: usize, s: &mut Stream) -> Vec<Vec<f64>> {
    let mut rows = vec![vec![0.0; d]; n];
    for j in 0..d {
        let perm = s.permutation(n);
        for (i, row) in rows.iter_mut().enumerate() {
            let u = s.uniform();
            // (k + u) / n may round up to (k + 1) / n: keep it inside its stratum.
            let (v, top) = ((perm[i] as f64 + u) / n as f64, (perm[i] + 1) as f64 / n as f64);
            row[j] = if v < top { v } else { f64::from_bits(top.to_bits() - 1) };
        }
    }
    rows
}

/// Smallest Euclidean distance between two points (Morris & Mitchell's maximin
/// criterion, to be maximised).
pub fn min_distance(rows: &[Vec<f64>]) -> f64 {
    let mut best = f64::INFINITY;
    for a in 0..rows.len() {
        for b in a + 1..rows.len() {
            let d2: f64 = rows[a].iter().zip(&rows[b]).map(|(x, y)| (x - y) * (x - y)).sum();
            best = best.min(d2);
        }
    }
    best.sqrt()
}

/// Largest absolute Pearson correlation between two coordinates (to be minimised).
pub fn max_correlation(rows: &[Vec<f64>]) -> f64 {
    let n = rows.len() as f64;
    let d = rows.first().map_or(0, Vec::len);
    let mean: Vec<f64> = (0..d).map(|j| rows.iter().map(|r| r[j]).sum::<f64>() / n).collect();
    let mut worst = 0.0f64;
    for a in 0..d {
        for b in a + 1..d {
            let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
            for r in rows {
                let (x, y) = (r[a] - mean[a], r[b] - mean[b]);
                sab += x * y;
                saa += x * x;
                sbb += y * y;
            }
            worst = worst.max((sab / (saa * sbb).sqrt()).abs());
        }
    }
    worst
}

/// `n` points of `[0, 1)^d` forming a Latin hypercube, from `seed`. With a criterion,
/// `candidates` designs are drawn and the best by it is kept (the first on ties).
pub fn latin_hypercube(n: usize, d: usize, seed: u64, criterion: Criterion, candidates: usize) -> Vec<Vec<f64>> {
    let mut s = Stream::new(seed);
    let draws = if criterion == Criterion::None { 1 } else { candidates.max(1) };
    let mut best: Option<(f64, Vec<Vec<f64>>)> = None;
    for _ in 0..draws {
        let rows = one_design(n, d, &mut s);
        let score = match criterion {
            Criterion::None => 0.0,
            Criterion::Maximin => -min_distance(&rows),
            Criterion::Correlation => max_correlation(&rows),
        };
        if best.as_ref().is_none_or(|(b, _)| score < *b) {
            best = Some((score, rows));
        }
    }
    best.map(|(_, r)| r).unwrap_or_default()
}
