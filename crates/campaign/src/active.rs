//! Active subspaces from a results table with one scalar output per variant,
//! gradient-free (Constantine, Active Subspaces: Emerging Ideas for Dimension Reduction
//! in Parameter Studies, SIAM 2015, §1.3 and Algorithms 1.2 and 1.3): a global quadratic
//! model or local linear models give the gradients, and the eigenvectors of
//!
//! ```text
//! C = E[∇f ∇fᵀ]
//! ```
//!
//! with the largest eigenvalues are the directions along which the output varies most.
//! Inputs are first mapped to `[-1, 1]` from the parameters' bounds, so directions
//! weigh parameters by their ranges, not their units.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::Serialize;

use crate::error::{Error, Result};

/// How the gradients are estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fit {
    /// One least-squares quadratic `f ≈ c + bᵀz + ½ zᵀAz` over all points; with `z`
    /// uniform on `[-1, 1]^m`, `C = bbᵀ + A²/3` in closed form (Algorithm 1.3 with the
    /// expectation taken exactly).
    Quadratic,
    /// A least-squares linear model on the `neighbours` nearest points of each point; `C`
    /// is the mean of the outer products of those slopes (Algorithm 1.2).
    LocalLinear {
        /// Points in each local fit (at least `m + 1`).
        neighbours: usize,
    },
}

/// The estimated active subspace.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ActiveSubspace {
    /// Parameter names.
    pub names: Vec<String>,
    /// Eigenvalues of `C`, largest first.
    pub eigenvalues: Vec<f64>,
    /// The matching unit eigenvectors (normalised coordinates), each as weights by
    /// parameter; the sign is chosen so that the largest weight is positive.
    pub directions: Vec<Vec<f64>>,
}

fn normalise(x: &[Vec<f64>], bounds: &[(f64, f64)]) -> Vec<Vec<f64>> {
    x.iter().map(|r| r.iter().zip(bounds).map(|(v, (lo, hi))| 2.0 * (v - lo) / (hi - lo) - 1.0).collect()).collect()
}

/// Least-squares solution of `a c ≈ f` (SVD), or why not.
fn least_squares(a: DMatrix<f64>, f: DVector<f64>) -> Result<DVector<f64>> {
    let cols = a.ncols();
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    let rank = svd.singular_values.iter().filter(|&&s| s > 1e-10 * smax).count();
    if rank < cols {
        return Err(Error::Fit(format!(
            "the fit is rank deficient: rank {rank} of {cols} (too few or degenerate points)"
        )));
    }
    svd.solve(&f, 1e-12 * smax).map_err(|e| Error::Fit(e.to_string()))
}

fn quadratic_c(z: &[Vec<f64>], f: &[f64]) -> Result<DMatrix<f64>> {
    let m = z[0].len();
    let p = 1 + m + m * (m + 1) / 2;
    if z.len() < p {
        return Err(Error::Fit(format!("a quadratic in {m} parameters needs at least {p} points, found {}", z.len())));
    }
    let a = DMatrix::from_fn(z.len(), p, |r, c| {
        let zr = &z[r];
        if c == 0 {
            return 1.0;
        }
        if c <= m {
            return zr[c - 1];
        }
        let mut k = m + 1;
        for i in 0..m {
            for j in i..m {
                if k == c {
                    return zr[i] * zr[j];
                }
                k += 1;
            }
        }
        unreachable!("column {c} of {p}")
    });
    let coef = least_squares(a, DVector::from_column_slice(f))?;
    let b = DVector::from_fn(m, |i, _| coef[1 + i]);
    let mut hess = DMatrix::zeros(m, m);
    let mut k = m + 1;
    for i in 0..m {
        for j in i..m {
            if i == j {
                hess[(i, i)] = 2.0 * coef[k];
            } else {
                hess[(i, j)] = coef[k];
                hess[(j, i)] = coef[k];
            }
            k += 1;
        }
    }
    Ok(&b * b.transpose() + &hess * &hess / 3.0)
}

fn local_linear_c(z: &[Vec<f64>], f: &[f64], neighbours: usize) -> Result<DMatrix<f64>> {
    let m = z[0].len();
    if neighbours < m + 1 || neighbours > z.len() {
        return Err(Error::Fit(format!(
            "local linear fits in {m} parameters need between {} and {} neighbours, asked {neighbours}",
            m + 1,
            z.len()
        )));
    }
    let mut c = DMatrix::zeros(m, m);
    for zi in z {
        let mut order: Vec<(f64, usize)> =
            z.iter().enumerate().map(|(k, zk)| (zk.iter().zip(zi).map(|(a, b)| (a - b) * (a - b)).sum(), k)).collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let near: Vec<usize> = order[..neighbours].iter().map(|&(_, k)| k).collect();
        let a = DMatrix::from_fn(neighbours, m + 1, |r, col| if col == 0 { 1.0 } else { z[near[r]][col - 1] });
        let rhs = DVector::from_iterator(neighbours, near.iter().map(|&k| f[k]));
        let coef = least_squares(a, rhs)?;
        let g = DVector::from_fn(m, |i, _| coef[1 + i]);
        c += &g * g.transpose();
    }
    Ok(c / z.len() as f64)
}

/// The active subspace of `f` sampled at `x` (one row of parameter values per sample),
/// the parameters named `names` with `bounds` `(lo, hi)`.
///
/// # Errors
///
/// [`Error::Fit`] for mismatched sizes, too few points or a degenerate fit.
pub fn active_subspace(
    names: &[String],
    bounds: &[(f64, f64)],
    x: &[Vec<f64>],
    f: &[f64],
    fit: Fit,
) -> Result<ActiveSubspace> {
    let m = names.len();
    if m == 0 || bounds.len() != m || x.len() != f.len() || x.iter().any(|r| r.len() != m) || x.is_empty() {
        return Err(Error::Fit(format!("expected {} samples of {m} parameters and one output each", f.len())));
    }
    if bounds.iter().any(|(lo, hi)| lo.partial_cmp(hi) != Some(std::cmp::Ordering::Less)) {
        return Err(Error::Fit("every parameter needs a range lo < hi".into()));
    }
    let z = normalise(x, bounds);
    let c = match fit {
        Fit::Quadratic => quadratic_c(&z, f)?,
        Fit::LocalLinear { neighbours } => local_linear_c(&z, f, neighbours)?,
    };
    let eig = SymmetricEigen::new(c);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let directions = order
        .iter()
        .map(|&k| {
            let v: Vec<f64> = eig.eigenvectors.column(k).iter().copied().collect();
            let big = v.iter().copied().fold(0.0f64, |a, b| if b.abs() > a.abs() { b } else { a });
            if big < 0.0 {
                v.iter().map(|x| -x).collect()
            } else {
                v
            }
        })
        .collect();
    Ok(ActiveSubspace {
        names: names.to_vec(),
        eigenvalues: order.iter().map(|&k| eig.eigenvalues[k]).collect(),
        directions,
    })
}
