//! Conjugate gradients on the sparse symmetric positive definite kernel block Φ of a
//! compactly supported RBF, for up to [`W`] right-hand sides at once (one pass over the
//! matrix serves all of them), with a Jacobi preconditioner and a Lanczos estimate of the
//! spectral condition number from the CG coefficients.
//!
//! (No `mul_add` outside the `pulp` dispatch of the matrix–vector product: the baseline
//! target has no FMA instruction and `mul_add` becomes a library call.)

use rayon::prelude::*;

/// Right-hand sides solved together.
pub(crate) const W: usize = 8;

/// Rows per parallel task.
const ROWS: usize = 2048;

/// A symmetric matrix in compressed sparse row form (both triangles stored).
#[derive(Debug, Clone)]
pub(crate) struct Csr {
    pub row_ptr: Vec<usize>,
    pub col: Vec<u32>,
    pub val: Vec<f64>,
}

impl Csr {
    pub fn n(&self) -> usize {
        self.row_ptr.len() - 1
    }

    fn diag(&self) -> Vec<f64> {
        (0..self.n())
            .map(|i| {
                let r = self.row_ptr[i]..self.row_ptr[i + 1];
                self.col[r.clone()].iter().zip(&self.val[r]).filter(|(&j, _)| j as usize == i).map(|(_, v)| *v).sum()
            })
            .collect()
    }

    /// `y = A x` and the per-column dots `xᵀ y`, rows in parallel, each block of rows
    /// in the widest SIMD instruction set pulp finds on the CPU ([`RowsMulDot`]).
    fn mul_dot(&self, x: &[[f64; W]], y: &mut [[f64; W]]) -> [f64; W] {
        let arch = pulp::Arch::new();
        y.par_chunks_mut(ROWS)
            .enumerate()
            .map(|(chunk, ys)| arch.dispatch(RowsMulDot { a: self, x, ys, first: chunk * ROWS }))
            .reduce(|| [0.0; W], add)
    }

    /// [`mul_dot`](Self::mul_dot) in plain scalar code (the reference the SIMD path is
    /// tested against).
    #[cfg(test)]
    fn mul_dot_scalar(&self, x: &[[f64; W]], y: &mut [[f64; W]]) -> [f64; W] {
        use pulp::WithSimd;
        RowsMulDot { a: self, x, ys: y, first: 0 }.with_simd(pulp::Scalar::new())
    }
}

/// Rows `first..first + ys.len()` of `y = A x`, and their share of `xᵀ y`.
///
/// For each stored entry `v = A[i, j]` the `W` columns of row `j` of `x` are loaded as
/// `W / lanes` vectors and `v` is broadcast into one fused multiply-add per vector (two
/// AVX2 instructions for `W = 8`), instead of `W` scalar multiplies and adds; the row's
/// `W` accumulators stay in registers. (pulp 0.21 reaches AVX-512 only with its nightly
/// `nightly-x86-v4` feature, so on stable Rust the widest path is AVX2.)
struct RowsMulDot<'a> {
    a: &'a Csr,
    x: &'a [[f64; W]],
    ys: &'a mut [[f64; W]],
    first: usize,
}

impl pulp::WithSimd for RowsMulDot<'_> {
    type Output = [f64; W];

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> [f64; W] {
        let RowsMulDot { a, x, ys, first } = self;
        let mut dot = [0.0; W];
        for (k, yi) in ys.iter_mut().enumerate() {
            let i = first + k;
            let r = a.row_ptr[i]..a.row_ptr[i + 1];
            let mut acc = [0.0; W];
            {
                let (acc_v, acc_tail) = S::as_mut_simd_f64s(&mut acc);
                for (&j, &v) in a.col[r.clone()].iter().zip(&a.val[r]) {
                    let xj = &x[j as usize];
                    let (x_v, x_tail) = S::as_simd_f64s(xj);
                    let vs = simd.splat_f64s(v);
                    for (a, &b) in acc_v.iter_mut().zip(x_v) {
                        *a = simd.mul_add_e_f64s(vs, b, *a);
                    }
                    for (a, &b) in acc_tail.iter_mut().zip(x_tail) {
                        *a += v * b;
                    }
                }
            }
            for c in 0..W {
                dot[c] += x[i][c] * acc[c];
            }
            *yi = acc;
        }
        dot
    }
}

fn add(a: [f64; W], b: [f64; W]) -> [f64; W] {
    std::array::from_fn(|c| a[c] + b[c])
}

/// What a CG run did.
#[derive(Debug, Clone)]
pub(crate) struct CgInfo {
    /// Iterations until the last column converged (or the limit).
    pub iterations: usize,
    /// Whether every column reached the tolerance.
    pub converged: bool,
    /// Lanczos estimate of κ₂ of the (Jacobi-scaled) matrix, the largest over the columns.
    pub condition: f64,
}

/// Solves `A xᶜ = bᶜ` for the columns `c < m` of `b` (row-major, `W` columns per row) to
/// `‖rᶜ‖ ≤ tol ‖bᶜ‖`, in place (on return `b` holds the solutions).
pub(crate) fn solve(a: &Csr, b: &mut [[f64; W]], m: usize, tol: f64, max_iter: usize) -> CgInfo {
    let n = a.n();
    // Jacobi: solve D^-1/2 A D^-1/2 y = D^-1/2 b, x = D^-1/2 y, with the scaling folded
    // into the vectors.
    let d = a.diag();
    if d.iter().any(|&v| !(v > 0.0 && v.is_finite())) {
        return CgInfo { iterations: 0, converged: false, condition: f64::INFINITY };
    }
    let dinv: Vec<f64> = d.iter().map(|v| 1.0 / v).collect();
    let mut x = vec![[0.0; W]; n];
    let mut r = b.to_vec();
    let mut z: Vec<[f64; W]> = r.iter().zip(&dinv).map(|(ri, &s)| ri.map(|v| v * s)).collect();
    let mut p = z.clone();
    let mut q = vec![[0.0; W]; n];
    let dots = |u: &[[f64; W]], v: &[[f64; W]]| -> [f64; W] {
        u.par_chunks(ROWS)
            .zip(v.par_chunks(ROWS))
            .map(|(a, b)| {
                let mut s = [0.0; W];
                for (ai, bi) in a.iter().zip(b) {
                    for c in 0..W {
                        s[c] += ai[c] * bi[c];
                    }
                }
                s
            })
            .reduce(|| [0.0; W], add)
    };
    let bnorm = dots(b, b).map(f64::sqrt);
    let mut rz = dots(&r, &z);
    let mut active: [bool; W] = std::array::from_fn(|c| c < m && bnorm[c] > 0.0);
    // Lanczos tridiagonal per column: diagonal 1/αₖ + βₖ₋₁/αₖ₋₁, off-diagonal √βₖ/αₖ.
    let mut alphas: Vec<[f64; W]> = Vec::new();
    let mut betas: Vec<[f64; W]> = Vec::new();
    let mut iterations = 0;
    while active.iter().any(|&a| a) && iterations < max_iter {
        iterations += 1;
        let pq = a.mul_dot(&p, &mut q);
        let alpha: [f64; W] = std::array::from_fn(|c| if active[c] { rz[c] / pq[c] } else { 0.0 });
        if alpha.iter().any(|v| !v.is_finite()) {
            return CgInfo { iterations, converged: false, condition: f64::INFINITY };
        }
        let (rz_new, rr) = x
            .par_chunks_mut(ROWS)
            .zip(r.par_chunks_mut(ROWS))
            .zip(z.par_chunks_mut(ROWS))
            .enumerate()
            .map(|(chunk, ((xs, rs), zs))| {
                let (mut s, mut t) = ([0.0; W], [0.0; W]);
                for (k, ((xi, ri), zi)) in xs.iter_mut().zip(rs.iter_mut()).zip(zs.iter_mut()).enumerate() {
                    let i = chunk * ROWS + k;
                    let (pi, qi, di) = (&p[i], &q[i], dinv[i]);
                    for c in 0..W {
                        xi[c] += alpha[c] * pi[c];
                        ri[c] -= alpha[c] * qi[c];
                        zi[c] = ri[c] * di;
                        s[c] += ri[c] * zi[c];
                        t[c] += ri[c] * ri[c];
                    }
                }
                (s, t)
            })
            .reduce(|| ([0.0; W], [0.0; W]), |a, b| (add(a.0, b.0), add(a.1, b.1)));
        let beta: [f64; W] = std::array::from_fn(|c| if active[c] { rz_new[c] / rz[c] } else { 0.0 });
        alphas.push(alpha);
        betas.push(beta);
        for c in 0..W {
            if active[c] && rr[c].sqrt() <= tol * bnorm[c] {
                active[c] = false;
            }
        }
        rz = rz_new;
        p.par_chunks_mut(ROWS).zip(z.par_chunks(ROWS)).for_each(|(ps, zs)| {
            for (pi, zi) in ps.iter_mut().zip(zs) {
                for c in 0..W {
                    pi[c] = beta[c] * pi[c] + zi[c];
                }
            }
        });
    }
    let converged = !active.iter().any(|&a| a);
    let mut condition: f64 = 1.0;
    for c in 0..m {
        let (mut diag, mut off) = (Vec::new(), Vec::new());
        for k in 0..alphas.len() {
            let a = alphas[k][c];
            if a == 0.0 {
                break;
            }
            let prev = if k > 0 { betas[k - 1][c] / alphas[k - 1][c] } else { 0.0 };
            diag.push(1.0 / a + prev);
            if k > 0 {
                off.push(betas[k - 1][c].sqrt() / alphas[k - 1][c]);
            }
        }
        if !diag.is_empty() {
            let (lo, hi) = extreme_eigenvalues(&diag, &off);
            let k = if lo > 0.0 { hi / lo } else { f64::INFINITY };
            condition = condition.max(k);
        }
    }
    b.copy_from_slice(&x);
    CgInfo { iterations, converged, condition }
}

/// Smallest and largest eigenvalue of the symmetric tridiagonal matrix (diagonal `d`,
/// off-diagonal `e`), by Sturm-sequence bisection.
fn extreme_eigenvalues(d: &[f64], e: &[f64]) -> (f64, f64) {
    let n = d.len();
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for i in 0..n {
        let r = if i > 0 { e[i - 1].abs() } else { 0.0 } + if i + 1 < n { e[i].abs() } else { 0.0 };
        lo = lo.min(d[i] - r);
        hi = hi.max(d[i] + r);
    }
    // Number of eigenvalues below x.
    let count = |x: f64| -> usize {
        let mut c = 0;
        let mut q = 1.0;
        for i in 0..n {
            let e2 = if i > 0 { e[i - 1] * e[i - 1] } else { 0.0 };
            q = d[i] - x - if i > 0 { e2 / q } else { 0.0 };
            if q == 0.0 {
                q = -f64::EPSILON * (d[i].abs() + x.abs()).max(f64::MIN_POSITIVE);
            }
            if q < 0.0 {
                c += 1;
            }
        }
        c
    };
    let bisect = |k: usize| -> f64 {
        // The (k+1)-th smallest eigenvalue.
        let (mut a, mut b) = (lo, hi);
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                break;
            }
            if count(mid) > k {
                b = mid;
            } else {
                a = mid;
            }
        }
        0.5 * (a + b)
    };
    (bisect(0), bisect(n - 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tridiagonal_extremes() {
        // 1-D Laplacian tridiag(−1, 2, −1), n = 10: eigenvalues 2 − 2cos(kπ/11).
        let n = 10;
        let (lo, hi) = extreme_eigenvalues(&vec![2.0; n], &vec![-1.0; n - 1]);
        let pi = std::f64::consts::PI;
        assert!((lo - (2.0 - 2.0 * (pi / 11.0).cos())).abs() < 1e-12);
        assert!((hi - (2.0 - 2.0 * (10.0 * pi / 11.0).cos())).abs() < 1e-12);
    }

    /// The dispatched SIMD product (AVX2 or scalar, whatever this CPU has)
    /// against the scalar loop, on a random sparse symmetric pattern: the same numbers
    /// up to the rounding of fused multiply-adds.
    #[test]
    fn simd_product_matches_scalar() {
        let n: usize = 3000;
        let (mut row_ptr, mut col, mut val) = (vec![0], vec![], vec![]);
        let mut seed: u64 = 12345;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..n {
            for j in i.saturating_sub(40)..(i + 41).min(n) {
                if (i * 7 + j * 13) % 3 != 0 || i == j {
                    col.push(j as u32);
                    val.push(next() - 0.5);
                }
            }
            row_ptr.push(col.len());
        }
        let a = Csr { row_ptr, col, val };
        let x: Vec<[f64; W]> = (0..n).map(|_| std::array::from_fn(|_| next() - 0.5)).collect();
        let (mut y1, mut y2) = (vec![[0.0; W]; n], vec![[0.0; W]; n]);
        let d1 = a.mul_dot(&x, &mut y1);
        let d2 = a.mul_dot_scalar(&x, &mut y2);
        for i in 0..n {
            for c in 0..W {
                assert!((y1[i][c] - y2[i][c]).abs() <= 1e-13, "row {i} column {c}");
            }
        }
        for c in 0..W {
            assert!((d1[c] - d2[c]).abs() <= 1e-10 * d2[c].abs().max(1.0));
        }
    }

    #[test]
    fn solves_laplacian_columns() {
        // tridiag(−1, 3, −1), 500 rows, three right-hand sides.
        let n: usize = 500;
        let (mut row_ptr, mut col, mut val) = (vec![0], vec![], vec![]);
        for i in 0..n {
            for j in i.saturating_sub(1)..(i + 2).min(n) {
                col.push(j as u32);
                val.push(if i == j { 3.0 } else { -1.0 });
            }
            row_ptr.push(col.len());
        }
        let a = Csr { row_ptr, col, val };
        let mut b: Vec<[f64; W]> = (0..n).map(|i| std::array::from_fn(|c| ((i * (c + 1)) % 7) as f64)).collect();
        let b0 = b.clone();
        let info = solve(&a, &mut b, 3, 1e-14, 1000);
        assert!(info.converged);
        assert!(info.condition > 1.0 && info.condition < 5.01, "{}", info.condition);
        let mut ax = vec![[0.0; W]; n];
        a.mul_dot(&b, &mut ax);
        for i in 0..n {
            for c in 0..3 {
                assert!((ax[i][c] - b0[i][c]).abs() < 1e-12);
            }
        }
    }
}
