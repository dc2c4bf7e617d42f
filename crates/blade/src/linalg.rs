//! Small linear-algebra helpers: a banded LU for B-spline collocation matrices, dense
//! solves and least squares (nalgebra), the B-spline basis row of one parameter.

use cadmorph_nurbs::{basis_funs, KnotVector};
use nalgebra::{DMatrix, DVector};

use crate::{Error, Result};

/// The non-zero basis functions of degree `p` at `t`: the first column they start at and
/// their `p + 1` values (Piegl & Tiller A2.1 + A2.2).
pub(crate) fn basis_row(knots: &KnotVector, p: usize, t: f64) -> (usize, Vec<f64>) {
    let span = knots.find_span(p, t);
    (span - p, basis_funs(knots, p, t))
}

/// LU factors of a band matrix with half-bandwidth `w` (non-zeros only where
/// `|i − j| ≤ w`), computed without pivoting.
///
/// B-spline collocation matrices whose parameters satisfy the Schoenberg–Whitney
/// conditions are totally positive, so Gaussian elimination without pivoting is stable
/// for them (de Boor, *A Practical Guide to Splines*, ch. XIII); the factorisation costs
/// `O(n w²)` instead of the dense `O(n³)`.
#[derive(Debug, Clone)]
pub(crate) struct BandLu {
    n: usize,
    w: usize,
    /// Row-major band: entry `(i, j)` at `i * (2w + 1) + (j + w − i)`.
    band: Vec<f64>,
}

impl BandLu {
    /// Factors the matrix whose row `i` is `rows[i] = (first column, values)`.
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] for a zero pivot or a row outside the band.
    pub(crate) fn factor(rows: &[(usize, Vec<f64>)], w: usize, what: &'static str) -> Result<Self> {
        let n = rows.len();
        let width = 2 * w + 1;
        let mut band = vec![0.0; n * width];
        for (i, (start, vals)) in rows.iter().enumerate() {
            for (k, v) in vals.iter().enumerate() {
                let j = start + k;
                if *v == 0.0 {
                    continue;
                }
                if j >= n || j + w < i || j > i + w {
                    return Err(Error::Singular { what, n });
                }
                band[i * width + (j + w - i)] = *v;
            }
        }
        let at = |i: usize, j: usize| i * width + (j + w - i);
        for k in 0..n {
            let piv = band[at(k, k)];
            if piv.abs() < 1e-300 || !piv.is_finite() {
                return Err(Error::Singular { what, n });
            }
            for i in k + 1..(k + w + 1).min(n) {
                let f = band[at(i, k)] / piv;
                if f == 0.0 {
                    continue;
                }
                band[at(i, k)] = f;
                for j in k + 1..(k + w + 1).min(n) {
                    band[at(i, j)] -= f * band[at(k, j)];
                }
            }
        }
        Ok(Self { n, w, band })
    }

    /// Solves `A x = b` in place.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let (n, w) = (self.n, self.w);
        let width = 2 * w + 1;
        let at = |i: usize, j: usize| i * width + (j + w - i);
        for i in 0..n {
            let lo = i.saturating_sub(w);
            let mut s = b[i];
            for j in lo..i {
                s -= self.band[at(i, j)] * b[j];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let hi = (i + w + 1).min(n);
            let mut s = b[i];
            for j in i + 1..hi {
                s -= self.band[at(i, j)] * b[j];
            }
            b[i] = s / self.band[at(i, i)];
        }
    }
}

/// Solves the dense square system `a x = b` (LU with partial pivoting, as LAPACK `gesv`
/// that `numpy.linalg.solve` calls).
///
/// # Errors
///
/// [`Error::Singular`] when `a` is singular.
pub(crate) fn solve_dense(a: DMatrix<f64>, b: &DVector<f64>, what: &'static str) -> Result<DVector<f64>> {
    let n = a.nrows();
    a.lu().solve(b).filter(|x| x.iter().all(|v| v.is_finite())).ok_or(Error::Singular { what, n })
}

/// The least-squares solution of `a x ≈ b` for a full-column-rank `a` (QR), the unique
/// minimiser that `numpy.linalg.lstsq` also returns for such a matrix.
///
/// # Errors
///
/// [`Error::Singular`] when `a` is rank deficient.
pub(crate) fn least_squares(a: &DMatrix<f64>, b: &DVector<f64>, what: &'static str) -> Result<DVector<f64>> {
    let n = a.ncols();
    if a.nrows() < n {
        return Err(Error::Singular { what, n });
    }
    let qr = a.clone().qr();
    let r = qr.r();
    let qtb = qr.q().transpose() * b;
    let scale = r.diagonal().amax();
    if r.diagonal().iter().any(|d| d.abs() <= 1e-14 * scale) {
        return Err(Error::Singular { what, n });
    }
    r.solve_upper_triangular(&qtb.rows(0, n).into_owned()).ok_or(Error::Singular { what, n })
}
