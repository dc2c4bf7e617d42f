//! Conjugate gradients on the sparse symmetric positive definite kernel block Φ of a
//! compactly supported RBF, for up to [`W`] right-hand sides at once (one pass over the
//! matrix serves all of them), with a Jacobi or a block-Jacobi preconditioner
//! ([`BlockJacobi`], Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., §12.1;
//! Golub & Van Loan §11.5) and a Lanczos estimate of the spectral condition number from
//! the CG coefficients (Golub & Van Loan §11.5.4).
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
        y.par_chunks_mut(ROWS)
            .enumerate()
            .map(|(chunk, ys)| crate::simd::dispatch(RowsMulDot { a: self, x, ys, first: chunk * ROWS }))
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
/// `W` accumulators stay in registers. (AVX-512: one FMA per row entry.)
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

/// The preconditioner `M` of a CG run.
#[derive(Debug, Clone)]
pub(crate) enum Precond {
    /// `M = diag Φ` (does nothing for a Wendland kernel, whose diagonal is constant; kept
    /// for the small systems of the multilevel fit).
    Jacobi,
    /// Additive Schwarz over one or more partitions into spatially compact groups of
    /// centres: `M⁻¹ = Σₚ Mₚ⁻¹`, each `Mₚ` the diagonal blocks of Φ over partition `p`
    /// ([`BlockJacobi`]). Two partitions staggered by half a block catch the close pairs
    /// of centres that one partition cuts apart.
    Blocks(Vec<BlockJacobi>),
}

/// Block-Jacobi preconditioner: `M = blockdiag(Φ[B₁,B₁], …, Φ[Bₖ,Bₖ])` over groups `Bₖ` of
/// centres that lie close together (a few cells of the grid), each block held as its
/// dense Cholesky factor.
///
/// Why it works for compactly supported kernels: a block holds the strong near-field
/// couplings of its centres, so `M⁻¹Φ` keeps only the couplings between neighbouring
/// blocks. On the benchmark case (50k centres, 107 neighbours each) it cuts the
/// iterations from ~1500 to the figure in `benches/pygem/README.md`. Each block is a
/// principal submatrix of a symmetric positive definite matrix, so its factorisation
/// exists; a block whose pivots fail in floating point makes [`BlockJacobi::new`] return
/// `None` and the caller falls back to [`Precond::Jacobi`].
#[derive(Debug, Clone)]
pub(crate) struct BlockJacobi {
    /// Block position → row of Φ.
    order: Vec<u32>,
    /// Row of Φ → block position.
    inv: Vec<u32>,
    /// Block `k` is positions `bounds[k]..bounds[k + 1]`.
    bounds: Vec<usize>,
    /// Each block's lower Cholesky factor, packed by rows (row `i` is `i + 1` values).
    factors: Vec<Vec<f64>>,
    /// Upper bound of the largest eigenvalue of `M` (Gershgorin, over the blocks).
    largest: f64,
    /// Estimate of the smallest eigenvalue of `M` (inverse iteration, over the blocks).
    smallest: f64,
}

/// Offset of row `i` in a packed lower triangle.
#[inline(always)]
fn packed(i: usize) -> usize {
    i * (i + 1) / 2
}

impl BlockJacobi {
    /// Factors the diagonal blocks of `a` over the groups `order[bounds[k]..bounds[k + 1]]`
    /// (`order` a permutation of the rows); `None` when a block is not numerically
    /// positive definite.
    pub fn new(a: &Csr, order: Vec<u32>, bounds: Vec<usize>) -> Option<BlockJacobi> {
        let n = a.n();
        debug_assert_eq!(order.len(), n);
        let mut inv = vec![0u32; n];
        for (k, &i) in order.iter().enumerate() {
            inv[i as usize] = k as u32;
        }
        let blocks: Option<Vec<(Vec<f64>, f64, f64)>> = (0..bounds.len() - 1)
            .into_par_iter()
            .map(|b| {
                let (lo, hi) = (bounds[b], bounds[b + 1]);
                let bs = hi - lo;
                let mut l = vec![0.0; packed(bs)];
                let mut gershgorin: f64 = 0.0;
                for k in 0..bs {
                    let i = order[lo + k] as usize;
                    let r = a.row_ptr[i]..a.row_ptr[i + 1];
                    let mut row_sum = 0.0;
                    for (&j, &v) in a.col[r.clone()].iter().zip(&a.val[r]) {
                        let p = inv[j as usize] as usize;
                        if (lo..hi).contains(&p) {
                            row_sum += v.abs();
                            if p - lo <= k {
                                l[packed(k) + p - lo] += v;
                            }
                        }
                    }
                    gershgorin = gershgorin.max(row_sum);
                }
                cholesky_packed(&mut l, bs)?;
                let lowest = smallest_eigenvalue(&l, bs);
                Some((l, gershgorin, lowest))
            })
            .collect();
        let blocks = blocks?;
        let largest = blocks.iter().map(|b| b.1).fold(0.0, f64::max);
        let smallest = blocks.iter().map(|b| b.2).fold(f64::INFINITY, f64::min);
        let factors = blocks.into_iter().map(|b| b.0).collect();
        Some(BlockJacobi { order, inv, bounds, factors, largest, smallest })
    }

    /// `z = M⁻¹ r`, or `z += M⁻¹ r` when `add`; `scratch` is resized to the rows of `r`.
    fn apply(&self, r: &[[f64; W]], z: &mut [[f64; W]], scratch: &mut Vec<[f64; W]>, add: bool) {
        scratch.resize(r.len(), [0.0; W]);
        scratch.par_iter_mut().zip(self.order.par_iter()).for_each(|(s, &i)| *s = r[i as usize]);
        let mut pieces = Vec::with_capacity(self.factors.len());
        let mut rest: &mut [[f64; W]] = scratch;
        for (w, f) in self.bounds.windows(2).zip(&self.factors) {
            let (head, tail) = rest.split_at_mut(w[1] - w[0]);
            pieces.push((head, f));
            rest = tail;
        }
        pieces.into_par_iter().for_each(|(y, l)| solve_packed(l, y));
        if add {
            z.par_iter_mut().zip(self.inv.par_iter()).for_each(|(zi, &k)| {
                let s = &scratch[k as usize];
                for c in 0..W {
                    zi[c] += s[c];
                }
            });
        } else {
            z.par_iter_mut().zip(self.inv.par_iter()).for_each(|(zi, &k)| *zi = scratch[k as usize]);
        }
    }
}

/// In-place Cholesky `A = L Lᵀ` of a packed lower triangle (Cholesky–Banachiewicz, row by
/// row: Golub & Van Loan Alg. 4.2.1 in its row form); `None` at a non-positive pivot.
fn cholesky_packed(l: &mut [f64], n: usize) -> Option<()> {
    for i in 0..n {
        let oi = packed(i);
        for j in 0..=i {
            let oj = packed(j);
            let (head, row_i) = l.split_at_mut(oi);
            // Row j is in `head` for j < i, else it is row i itself.
            let dot: f64 = if j < i {
                head[oj..oj + j].iter().zip(&row_i[..j]).map(|(a, b)| a * b).sum()
            } else {
                row_i[..j].iter().map(|a| a * a).sum()
            };
            let s = row_i[j] - dot;
            if j == i {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                row_i[j] = s.sqrt();
            } else {
                row_i[j] = s / head[oj + j];
            }
        }
    }
    Some(())
}

/// `y ← (L Lᵀ)⁻¹ y` for the `W` columns of `y`, `L` packed by rows, in the widest SIMD
/// instruction set pulp finds ([`PackedSolve`]).
fn solve_packed(l: &[f64], y: &mut [[f64; W]]) {
    crate::simd::dispatch(PackedSolve { l, y });
}

/// The two triangular solves of [`solve_packed`]: each stored entry of `L` is broadcast
/// into one fused multiply-add per SIMD vector of the `W` columns (as [`RowsMulDot`]).
struct PackedSolve<'a> {
    l: &'a [f64],
    y: &'a mut [[f64; W]],
}

impl pulp::WithSimd for PackedSolve<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let PackedSolve { l, y } = self;
        let n = y.len();
        // L v = y, row by row: v_i = (y_i − Σ_{k<i} L_ik v_k) / L_ii.
        for i in 0..n {
            let row = &l[packed(i)..packed(i) + i + 1];
            let (done, rest) = y.split_at_mut(i);
            let mut acc = rest[0];
            {
                let (acc_v, acc_tail) = S::as_mut_simd_f64s(&mut acc);
                for (&v, yk) in row[..i].iter().zip(done.iter()) {
                    let (y_v, y_tail) = S::as_simd_f64s(yk);
                    let vs = simd.splat_f64s(-v);
                    for (a, &b) in acc_v.iter_mut().zip(y_v) {
                        *a = simd.mul_add_e_f64s(vs, b, *a);
                    }
                    for (a, &b) in acc_tail.iter_mut().zip(y_tail) {
                        *a -= v * b;
                    }
                }
            }
            let d = 1.0 / row[i];
            rest[0] = acc.map(|a| a * d);
        }
        // Lᵀ x = v, last row first, each solved x_i sent back along row i of L.
        for i in (0..n).rev() {
            let row = &l[packed(i)..packed(i) + i + 1];
            let (before, rest) = y.split_at_mut(i);
            let d = 1.0 / row[i];
            let xi = rest[0].map(|a| a * d);
            rest[0] = xi;
            let (x_v, x_tail) = S::as_simd_f64s(&xi);
            for (&v, yk) in row[..i].iter().zip(before.iter_mut()) {
                let vs = simd.splat_f64s(-v);
                let (y_v, y_tail) = S::as_mut_simd_f64s(yk);
                for (a, &b) in y_v.iter_mut().zip(x_v) {
                    *a = simd.mul_add_e_f64s(vs, b, *a);
                }
                for (a, &b) in y_tail.iter_mut().zip(x_tail) {
                    *a -= v * b;
                }
            }
        }
    }
}

/// Smallest eigenvalue of `L Lᵀ` by inverse iteration (Rayleigh quotient after a few
/// steps from a fixed start; an estimate from above).
fn smallest_eigenvalue(l: &[f64], n: usize) -> f64 {
    if n == 0 {
        return f64::INFINITY;
    }
    // One column of the W-wide solver carries the iterate.
    let mut y: Vec<[f64; W]> =
        (0..n).map(|i| std::array::from_fn(|c| if c == 0 { 1.0 + (i % 7) as f64 * 0.1 } else { 0.0 })).collect();
    let mut rayleigh = f64::INFINITY;
    for _ in 0..12 {
        let norm = y.iter().map(|v| v[0] * v[0]).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return 0.0;
        }
        for v in y.iter_mut() {
            v[0] /= norm;
        }
        let before: Vec<f64> = y.iter().map(|v| v[0]).collect();
        solve_packed(l, &mut y);
        // ‖x‖ = 1, y = A⁻¹x: xᵀA⁻¹x approximates 1/λmin.
        let q: f64 = before.iter().zip(&y).map(|(a, b)| a * b[0]).sum();
        rayleigh = if q > 0.0 { 1.0 / q } else { 0.0 };
    }
    rayleigh
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
/// `‖rᶜ‖ ≤ tol ‖bᶜ‖`, in place (on return `b` holds the solutions), preconditioned by
/// `pre`. The reported condition is the Lanczos estimate of κ₂(M⁻¹A), times the estimate
/// of κ₂(M) for block Jacobi (κ(A) ≤ κ(M⁻¹A)·κ(M) for symmetric positive definite A, M).
pub(crate) fn solve(a: &Csr, b: &mut [[f64; W]], m: usize, tol: f64, max_iter: usize, pre: &Precond) -> CgInfo {
    let n = a.n();
    // Jacobi: solve D^-1/2 A D^-1/2 y = D^-1/2 b, x = D^-1/2 y, with the scaling folded
    // into the vectors.
    let d = a.diag();
    if d.iter().any(|&v| !(v > 0.0 && v.is_finite())) {
        return CgInfo { iterations: 0, converged: false, condition: f64::INFINITY };
    }
    let dinv: Vec<f64> = d.iter().map(|v| 1.0 / v).collect();
    // The block partitions; none for Jacobi, whose z = D⁻¹r is fused into the update.
    let parts: &[BlockJacobi] = match pre {
        Precond::Jacobi => &[],
        Precond::Blocks(parts) => parts,
    };
    let mut scratch = Vec::new();
    let mut apply_blocks = |r: &[[f64; W]], z: &mut [[f64; W]]| {
        for (k, part) in parts.iter().enumerate() {
            part.apply(r, z, &mut scratch, k > 0);
        }
    };
    let mut x = vec![[0.0; W]; n];
    let mut r = b.to_vec();
    let mut z: Vec<[f64; W]> = r.iter().zip(&dinv).map(|(ri, &s)| ri.map(|v| v * s)).collect();
    if !parts.is_empty() {
        apply_blocks(&r, &mut z);
    }
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
        let (mut rz_new, rr) = x
            .par_chunks_mut(ROWS)
            .zip(r.par_chunks_mut(ROWS))
            .zip(z.par_chunks_mut(ROWS))
            .enumerate()
            .map(|(chunk, ((xs, rs), zs))| {
                let (mut s, mut t) = ([0.0; W], [0.0; W]);
                let jacobi = parts.is_empty();
                for (k, ((xi, ri), zi)) in xs.iter_mut().zip(rs.iter_mut()).zip(zs.iter_mut()).enumerate() {
                    let i = chunk * ROWS + k;
                    let (pi, qi) = (&p[i], &q[i]);
                    for c in 0..W {
                        xi[c] += alpha[c] * pi[c];
                        ri[c] -= alpha[c] * qi[c];
                        t[c] += ri[c] * ri[c];
                    }
                    if jacobi {
                        let di = dinv[i];
                        for c in 0..W {
                            zi[c] = ri[c] * di;
                            s[c] += ri[c] * zi[c];
                        }
                    }
                }
                (s, t)
            })
            .reduce(|| ([0.0; W], [0.0; W]), |a, b| (add(a.0, b.0), add(a.1, b.1)));
        if !parts.is_empty() {
            apply_blocks(&r, &mut z);
            rz_new = dots(&r, &z);
        }
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
    if !parts.is_empty() {
        // M⁻¹ = Σₚ Mₚ⁻¹: λmax(M⁻¹) ≤ Σₚ 1/λmin(Mₚ) and λmin(M⁻¹) ≥ Σₚ 1/λmax(Mₚ).
        let inv_hi: f64 = parts.iter().map(|p| 1.0 / p.smallest).sum();
        let inv_lo: f64 = parts.iter().map(|p| 1.0 / p.largest).sum();
        let k = inv_hi / inv_lo;
        condition *= if k.is_finite() && k > 0.0 { k } else { f64::INFINITY };
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

    /// The dispatched SIMD product, in each instruction set this CPU has,
    /// against the scalar loop, on a random sparse symmetric pattern: the same numbers
    /// up to the rounding of fused multiply-adds.
    #[test]
    fn simd_product_matches_scalar() {
        let n: usize = 3000;
        let (mut row_ptr, mut col, mut val) = (vec![0], vec![], vec![]);
        let mut next = lcg(12345);
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
        let mut y2 = vec![[0.0; W]; n];
        let d2 = a.mul_dot_scalar(&x, &mut y2);
        crate::simd::for_each_isa(|isa| {
            let mut y1 = vec![[0.0; W]; n];
            let d1 = a.mul_dot(&x, &mut y1);
            for i in 0..n {
                for c in 0..W {
                    assert!((y1[i][c] - y2[i][c]).abs() <= 1e-13, "{isa}: row {i} column {c}");
                }
            }
            for c in 0..W {
                assert!((d1[c] - d2[c]).abs() <= 1e-10 * d2[c].abs().max(1.0), "{isa}");
            }
        });
    }

    /// Pseudo-random numbers in [0, 1) for the tests (a 64-bit LCG).
    fn lcg(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn packed_cholesky_solves_a_symmetric_positive_definite_system() {
        let n = 37;
        let mut next = lcg(3);
        let b: Vec<f64> = (0..n * n).map(|_| next() - 0.5).collect();
        // A = B Bᵀ + I.
        let a = |i: usize, j: usize| -> f64 {
            (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
        };
        let mut l = vec![0.0; packed(n)];
        for i in 0..n {
            for j in 0..=i {
                l[packed(i) + j] = a(i, j);
            }
        }
        cholesky_packed(&mut l, n).expect("positive definite");
        let rhs: Vec<[f64; W]> = (0..n).map(|_| std::array::from_fn(|_| next() - 0.5)).collect();
        crate::simd::for_each_isa(|isa| {
            let mut x = rhs.clone();
            solve_packed(&l, &mut x);
            for i in 0..n {
                for c in 0..W {
                    let ax: f64 = (0..n).map(|j| a(i, j) * x[j][c]).sum();
                    assert!((ax - rhs[i][c]).abs() < 1e-12, "{isa}: row {i} column {c}: {ax} vs {}", rhs[i][c]);
                }
            }
        });
        // The smallest eigenvalue of A is at least 1 (B Bᵀ ⪰ 0), and the estimate sees it.
        let lo = smallest_eigenvalue(&l, n);
        assert!((1.0 - 1e-9..50.0).contains(&lo), "{lo}");
        // An indefinite matrix is refused.
        let mut bad = vec![1.0, 2.0, 1.0];
        assert!(cholesky_packed(&mut bad, 2).is_none());
    }

    /// A Wendland C² kernel matrix on random centres, in the grid's order.
    fn wendland(n: usize, support: f64, seed: u64) -> (super::super::grid::Grid, Csr) {
        let mut next = lcg(seed);
        let centres: Vec<nalgebra::Point3<f64>> =
            (0..n).map(|_| nalgebra::Point3::new(next(), next(), next())).collect();
        let grid = super::super::grid::Grid::new(&centres, support);
        let kernel = super::super::Kernel::WendlandC2 { support };
        let a = super::super::assemble_csr(&grid, kernel);
        (grid, a)
    }

    #[test]
    fn partitions_cover_every_row_once() {
        let (grid, _) = wendland(3000, 0.15, 5);
        for (target, (order, bounds)) in
            [(60, grid.blocks(60, false)), (60, grid.blocks(60, true)), (7, grid.blocks(7, false))]
        {
            let mut seen = vec![false; 3000];
            for &i in &order {
                assert!(!std::mem::replace(&mut seen[i as usize], true), "row {i} twice");
            }
            assert!(seen.iter().all(|&s| s));
            assert_eq!((bounds[0], *bounds.last().unwrap()), (0, 3000));
            assert!(bounds.windows(2).all(|w| w[0] < w[1] && w[1] - w[0] <= 2 * target), "target {target}");
        }
    }

    /// Block-Jacobi (two staggered partitions) against Jacobi on the same Wendland
    /// system: the same solution, far fewer iterations, and a condition bound not below
    /// the Jacobi run's Lanczos estimate of κ₂(Φ) (which approaches it from below).
    #[test]
    fn staggered_blocks_solve_as_jacobi_in_fewer_iterations() {
        let n = 1500;
        let (grid, a) = wendland(n, 0.25, 11);
        let mut next = lcg(12);
        let b: Vec<[f64; W]> =
            (0..n).map(|_| std::array::from_fn(|c| if c < 5 { next() - 0.5 } else { 0.0 })).collect();
        let parts: Vec<BlockJacobi> = [grid.blocks(60, false), grid.blocks(60, true)]
            .into_iter()
            .map(|(order, bounds)| BlockJacobi::new(&a, order, bounds).expect("blocks factor"))
            .collect();
        let (mut xj, mut xb) = (b.clone(), b.clone());
        let jacobi = solve(&a, &mut xj, 5, 1e-12, 20_000, &Precond::Jacobi);
        let blocks = solve(&a, &mut xb, 5, 1e-12, 20_000, &Precond::Blocks(parts));
        assert!(jacobi.converged && blocks.converged);
        assert!(3 * blocks.iterations < jacobi.iterations, "{} vs {}", blocks.iterations, jacobi.iterations);
        assert!(blocks.condition >= 0.5 * jacobi.condition, "{:e} vs {:e}", blocks.condition, jacobi.condition);
        let scale = xj.iter().flat_map(|v| v.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        let mut ax = vec![[0.0; W]; n];
        a.mul_dot(&xb, &mut ax);
        for i in 0..n {
            for c in 0..5 {
                assert!((xb[i][c] - xj[i][c]).abs() <= 1e-8 * scale, "row {i} column {c}");
                assert!((ax[i][c] - b[i][c]).abs() <= 1e-9, "residual row {i} column {c}");
            }
        }
    }

    #[test]
    fn a_block_that_does_not_factor_is_refused() {
        // [[1, 2], [2, 1]] is indefinite: as one block it has no Cholesky factor.
        let a = Csr { row_ptr: vec![0, 2, 4], col: vec![0, 1, 0, 1], val: vec![1.0, 2.0, 2.0, 1.0] };
        assert!(BlockJacobi::new(&a, vec![0, 1], vec![0, 2]).is_none());
        assert!(BlockJacobi::new(&a, vec![1, 0], vec![0, 1, 2]).is_some());
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
        let info = solve(&a, &mut b, 3, 1e-14, 1000, &Precond::Jacobi);
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
