//! Multilevel interpolation with compactly supported radial basis functions (Floater &
//! Iske, "Multistep scattered data interpolation using compactly supported radial basis
//! functions", J. Comput. Appl. Math. 73 (1996); the same scheme is Wendland's
//! multiscale interpolation, "Scattered Data Approximation", Cambridge 2005).
//!
//! Level 0 is an ordinary [`Rbf`] (kernel and linear term) on a coarse set of centres
//! with a large support. Each next level interpolates what the levels before it miss, the
//! residual, with a *pure* kernel sum (no polynomial term, so that a local correction does
//! not leak a linear function over the whole domain) on a finer set of centres and a
//! smaller support:
//!
//! ```text
//! s₀ = Rbf interpolant of f on X₀,     rₖ = f − (s₀ + … + sₖ₋₁),
//! sₖ(x) = Σ_{c ∈ Xₖ} γ_c φ(‖x − c‖ / δₖ),    sₖ(c) = rₖ(c) for c ∈ Xₖ   (k ≥ 1),
//! φ(x) = x + s₀(x) + s₁(x) + … + s_L(x).
//! ```
//!
//! With the support `δₖ` a fixed multiple of the centre spacing of `Xₖ`, every level's
//! matrix has a bounded number of entries per row whatever the number of centres (Floater
//! & Iske's "stationary" choice), so it is sparse and well conditioned; its convergence
//! is what the caller measures (the residual after each level).

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::grid::Grid;
use super::{assemble_csr, cg, cg_max_iter, coincident_pair, eval, Kernel, Rbf, CG_TOL, MAX_CONDITION, MAX_RESIDUAL};
use crate::{Deformation, Error, Result};

/// Points per parallel task of the bulk evaluation.
const CHUNK: usize = 512;

/// A pure kernel sum `s(x) = Σᵢ γᵢ φ(‖x − cᵢ‖)` with a compactly supported, positive
/// definite kernel (the Wendland family), interpolating values `s(cᵢ) = fᵢ`: one level of
/// a [`MultilevelRbf`] (Floater & Iske 1996: the interpolant of one step, without the
/// polynomial part).
///
/// The system `Φγ = f` (Φ symmetric positive definite for distinct centres, Wendland
/// 1995) is solved by Jacobi-preconditioned conjugate gradients on the sparse matrix
/// assembled through the centre grid; the interpolant is checked at its centres
/// afterwards, like [`Rbf`].
///
/// As a [`Deformation`] it maps `x ↦ x + s(x)`; away from every centre (farther than the
/// support) it is the identity.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, rbf::{CompactRbf, Kernel}};
/// use cadmorph_morph::math::{Point3, Vector3};
/// let centres = [Point3::new(0.0, 0.0, 0.0), Point3::new(0.1, 0.0, 0.0), Point3::new(0.0, 0.1, 0.0)];
/// let values = [Vector3::new(0.0, 0.01, 0.0), Vector3::zeros(), Vector3::zeros()];
/// let s = CompactRbf::try_new(&centres, &values, Kernel::WendlandC2 { support: 0.3 })?;
/// assert!((s.deform_point(&centres[0]) - Point3::new(0.0, 0.01, 0.0)).norm() < 1e-12);
/// // Beyond the support nothing moves.
/// assert_eq!(s.deform_point(&Point3::new(1.0, 1.0, 1.0)), Point3::new(1.0, 1.0, 1.0));
/// # Ok::<(), cadmorph_morph::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct CompactRbf {
    kernel: Kernel,
    /// Centres sorted by cell, with their weights.
    grid: Grid,
    condition: f64,
    iterations: usize,
    /// Matrix entries (both triangles).
    nnz: usize,
}

impl CompactRbf {
    /// The kernel sum through `values[i]` at `centres[i]`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a kernel without compact support, a bad radius or a
    /// non-finite value; [`Error::CountMismatch`] for unequal lists or no centre;
    /// [`Error::CoincidentCentres`]; [`Error::IllConditioned`] when the conjugate
    /// gradients do not converge or the interpolant misses its centres by more than
    /// [`MAX_RESIDUAL`] of the largest value.
    pub fn try_new(centres: &[Point3<f64>], values: &[Vector3<f64>], kernel: Kernel) -> Result<CompactRbf> {
        kernel.validate()?;
        let Some(support) = kernel.support() else {
            return Err(Error::InvalidParameter {
                line: None,
                name: "radius",
                value: kernel.radius(),
                reason: "a multilevel level needs a compactly supported kernel",
            });
        };
        let n = centres.len();
        if n != values.len() || n == 0 {
            return Err(Error::CountMismatch {
                line: 0,
                what: "values (one per centre, at least one centre)",
                expected: n.max(1),
                found: values.len(),
            });
        }
        for v in centres.iter().flat_map(|p| p.iter()).chain(values.iter().flat_map(|d| d.iter())) {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "control point",
                    value: *v,
                    reason: "must be finite",
                });
            }
        }
        let scale = centres.iter().map(|p| p.coords.amax()).fold(0.0, f64::max).max(support);
        if let Some((first, second)) = coincident_pair(centres, 1e-12 * scale) {
            let p = centres[first];
            return Err(Error::CoincidentCentres { first, second, point: [p.x, p.y, p.z] });
        }
        let mut grid = Grid::new(centres, support);
        let phi = assemble_csr(&grid, kernel);
        let mut b: Vec<[f64; cg::W]> = grid
            .perm
            .iter()
            .map(|&i| {
                let d = values[i as usize];
                std::array::from_fn(|c| if c < 3 { d[c] } else { 0.0 })
            })
            .collect();
        let info = cg::solve(&phi, &mut b, 3, CG_TOL, cg_max_iter(n), &cg::Precond::Jacobi);
        if std::env::var_os("CADMORPH_CG_TRACE").is_some() {
            eprintln!(
                "cg (level): n={n} nnz={} iterations={} converged={} cond={:.3e}",
                phi.val.len(),
                info.iterations,
                info.converged,
                info.condition
            );
        }
        let fmax = values.iter().map(|d| d.amax()).fold(0.0, f64::max);
        if fmax > 0.0 && (!info.converged || !info.condition.is_finite()) {
            return Err(Error::IllConditioned {
                condition: info.condition,
                residual: f64::INFINITY,
                max_condition: MAX_CONDITION,
            });
        }
        for c in 0..3 {
            for (s, row) in b.iter().enumerate() {
                grid.g[c][s] = row[c];
            }
        }
        let level =
            CompactRbf { kernel, grid, condition: info.condition, iterations: info.iterations, nnz: phi.val.len() };
        if fmax > 0.0 {
            let mut at = vec![Vector3::zeros(); n];
            level.accumulate(centres, &mut at);
            let miss = at.iter().zip(values).map(|(a, f)| (a - f).amax()).fold(0.0, f64::max) / fmax;
            if miss.is_nan() || miss > MAX_RESIDUAL {
                return Err(Error::IllConditioned {
                    condition: info.condition,
                    residual: miss,
                    max_condition: MAX_CONDITION,
                });
            }
        }
        Ok(level)
    }

    /// The kernel.
    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// Number of centres.
    pub fn n_centres(&self) -> usize {
        self.grid.x.len()
    }

    /// Lanczos estimate of the spectral condition number of the Jacobi-scaled Φ (from the
    /// conjugate gradients; 1 when all values were zero).
    pub fn condition(&self) -> f64 {
        self.condition
    }

    /// Conjugate-gradient iterations of the solve.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Stored entries of Φ (both triangles): `nnz / n_centres` is the mean number of
    /// centres within the support of a centre.
    pub fn nnz(&self) -> usize {
        self.nnz
    }

    /// `out[i] += s(points[i])`, in parallel (the residual update and the bulk
    /// evaluation of [`MultilevelRbf`]).
    ///
    /// # Panics
    ///
    /// If `out` and `points` differ in length.
    pub fn accumulate(&self, points: &[Point3<f64>], out: &mut [Vector3<f64>]) {
        assert_eq!(points.len(), out.len(), "one output per point");
        let job = |(ps, os): (&[Point3<f64>], &mut [Vector3<f64>])| {
            let mut sums = vec![[0.0; 3]; ps.len()];
            eval::grid_sums(&self.kernel, &self.grid, ps, &mut sums);
            for (o, s) in os.iter_mut().zip(&sums) {
                *o += Vector3::new(s[0], s[1], s[2]);
            }
        };
        if points.len() >= 4 * CHUNK {
            points.par_chunks(CHUNK).zip(out.par_chunks_mut(CHUNK)).for_each(job);
        } else {
            job((points, out));
        }
    }

    /// `∂s/∂x` at `p`: `Σᵢ γᵢ φ'(rᵢ) (x − cᵢ)ᵀ / rᵢ`.
    fn gradient(&self, p: &Point3<f64>) -> Matrix3<f64> {
        let g = &self.grid;
        let mut j = Matrix3::zeros();
        g.for_each_range([p.x, p.y, p.z], |r| {
            for i in r {
                let d = Vector3::new(p.x - g.x[i], p.y - g.y[i], p.z - g.z[i]);
                let rr = d.norm();
                if rr > 0.0 {
                    let w = Vector3::new(g.g[0][i], g.g[1][i], g.g[2][i]);
                    j += self.kernel.deriv(rr) / rr * w * d.transpose();
                }
            }
        });
        j
    }
}

impl Deformation for CompactRbf {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        let mut d = [Vector3::zeros()];
        self.accumulate(std::slice::from_ref(p), &mut d);
        p + d[0]
    }

    fn deform(&self, points: &mut [Point3<f64>]) {
        let mut d = vec![Vector3::zeros(); points.len()];
        self.accumulate(points, &mut d);
        points.par_iter_mut().zip(&d).for_each(|(p, d)| *p += d);
    }

    /// `I + ∂s/∂x` (the Wendland kernels C² and C⁴ are smooth at their centres; C⁰ has a
    /// corner there, where its one-sided term is left out).
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        Some(Matrix3::identity() + self.gradient(p))
    }
}

/// A multilevel RBF: a base [`Rbf`] (level 0) plus [`CompactRbf`] corrections, each
/// interpolating the residual of the levels before it (Floater & Iske, "Multistep
/// scattered data interpolation using compactly supported radial basis functions",
/// J. Comput. Appl. Math. 73 (1996); Wendland's multiscale interpolation):
///
/// ```text
/// s₀ = Rbf interpolant of f on X₀,     rₖ = f − (s₀ + … + sₖ₋₁),
/// sₖ(x) = Σ_{c ∈ Xₖ} γ_c φ(‖x − c‖ / δₖ),    sₖ(c) = rₖ(c) for c ∈ Xₖ   (k ≥ 1),
/// φ(x) = x + s₀(x) + s₁(x) + … + s_L(x).
/// ```
///
/// The corrections have no polynomial term, so that a local correction does not leak a
/// linear function over the whole domain. With the support `δₖ` a fixed multiple of the
/// centre spacing of `Xₖ`, every level's matrix has a bounded number of entries per row
/// (Floater & Iske's stationary choice). The caller picks the centre sets and measures
/// the residual after each level (the mesh crate's `BoundaryMorph::multilevel`).
///
/// It is a [`Deformation`]: `φ(x) = x + s₀(x) + Σₖ sₖ(x)`, every level evaluated at the
/// original `x`. With no correction level it is exactly its base `Rbf`.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Rbf, rbf::{CompactRbf, Kernel, MultilevelRbf}};
/// use cadmorph_morph::math::{Point3, Vector3};
/// // Level 0 on four corners of a tetrahedron, moved rigidly: the linear term is exact.
/// let c0 = [
///     Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
///     Point3::new(0.0, 1.0, 0.0), Point3::new(0.0, 0.0, 1.0),
/// ];
/// let t = Vector3::new(0.1, 0.0, 0.0);
/// let base = Rbf::try_new(&c0, &[t; 4], Kernel::WendlandC2 { support: 2.0 })?;
/// let mut ml = MultilevelRbf::new(base);
/// // Level 1 lifts the point (0.5, 0.5, 0.5) by 0.01 in y, locally.
/// let c1 = [Point3::new(0.5, 0.5, 0.5)];
/// ml.push(CompactRbf::try_new(&c1, &[Vector3::new(0.0, 0.01, 0.0)], Kernel::WendlandC2 { support: 0.2 })?);
/// assert!((ml.deform_point(&c1[0]) - Point3::new(0.6, 0.51, 0.5)).norm() < 1e-12);
/// assert!((ml.deform_point(&c0[1]) - (c0[1] + t)).norm() < 1e-12);
/// # Ok::<(), cadmorph_morph::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct MultilevelRbf {
    base: Rbf,
    levels: Vec<CompactRbf>,
}

impl MultilevelRbf {
    /// The multilevel interpolant with level 0 `base` and no correction yet.
    pub fn new(base: Rbf) -> MultilevelRbf {
        MultilevelRbf { base, levels: Vec::new() }
    }

    /// Add a correction level (it should interpolate the residual of the levels so far).
    pub fn push(&mut self, level: CompactRbf) {
        self.levels.push(level);
    }

    /// Level 0.
    pub fn base(&self) -> &Rbf {
        &self.base
    }

    /// The correction levels 1, 2, ….
    pub fn levels(&self) -> &[CompactRbf] {
        &self.levels
    }

    /// Centres of all levels together.
    pub fn n_centres(&self) -> usize {
        self.base.centres().len() + self.levels.iter().map(CompactRbf::n_centres).sum::<usize>()
    }

    /// `out[i] = φ(points[i]) − points[i]`, all levels, in parallel.
    ///
    /// # Panics
    ///
    /// If `out` and `points` differ in length.
    pub fn displacements(&self, points: &[Point3<f64>], out: &mut [Vector3<f64>]) {
        assert_eq!(points.len(), out.len(), "one output per point");
        let moved = self.base.deformed(points);
        out.par_iter_mut().zip(moved.par_iter().zip(points)).for_each(|(o, (m, p))| *o = m - p);
        for level in &self.levels {
            level.accumulate(points, out);
        }
    }
}

impl Deformation for MultilevelRbf {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        if self.levels.is_empty() {
            return self.base.deform_point(p);
        }
        let mut q = [*p];
        self.deform(&mut q);
        q[0]
    }

    /// The corrections at the original points, then the base in place (so that with no
    /// correction level this is the base's own `deform`, bit for bit).
    fn deform(&self, points: &mut [Point3<f64>]) {
        if self.levels.is_empty() {
            return self.base.deform(points);
        }
        let mut d = vec![Vector3::zeros(); points.len()];
        for level in &self.levels {
            level.accumulate(points, &mut d);
        }
        self.base.deform(points);
        points.par_iter_mut().zip(&d).for_each(|(p, d)| *p += d);
    }

    /// The base's Jacobian plus every level's gradient; `None` where the base has none.
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        let mut j = self.base.jacobian(p)?;
        for level in &self.levels {
            j += level.gradient(p);
        }
        Some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Interpolation holds at every centre, and the Jacobian matches central differences.
    #[test]
    fn compact_level_interpolates_and_differentiates() {
        let mut st = 0x9E37_79B9_7F4A_7C15u64;
        let centres: Vec<Point3<f64>> =
            (0..3000).map(|_| Point3::new(uniform(&mut st), uniform(&mut st), uniform(&mut st))).collect();
        let values: Vec<Vector3<f64>> =
            centres.iter().map(|p| Vector3::new(p.y.sin(), p.x * p.z, 0.0) * 0.01).collect();
        let s = CompactRbf::try_new(&centres, &values, Kernel::WendlandC2 { support: 0.15 }).unwrap();
        assert!(s.nnz() > 3000 && s.nnz() < 3000 * 60, "{}", s.nnz());
        let mut at = vec![Vector3::zeros(); centres.len()];
        s.accumulate(&centres, &mut at);
        for (a, f) in at.iter().zip(&values) {
            // The CG stops at 1e-12 relative residual; the check in try_new is MAX_RESIDUAL.
            assert!((a - f).amax() <= 1e-8 * 0.01, "{a} vs {f}");
        }
        let p = Point3::new(0.43, 0.51, 0.37);
        let j = s.jacobian(&p).unwrap();
        let h = 1e-5;
        for a in 0..3 {
            let mut e = Vector3::zeros();
            e[a] = h;
            let fd = (s.deform_point(&(p + e)) - s.deform_point(&(p - e))) / (2.0 * h);
            for c in 0..3 {
                assert!((j[(c, a)] - fd[c]).abs() < 1e-6, "J[{c},{a}] {} vs {}", j[(c, a)], fd[c]);
            }
        }
    }

    #[test]
    fn compact_level_refuses_global_kernel_and_coincident_centres() {
        let c = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
        let v = [Vector3::zeros(); 2];
        assert!(matches!(
            CompactRbf::try_new(&c, &v, Kernel::Gaussian { radius: 1.0 }),
            Err(Error::InvalidParameter { .. })
        ));
        let c = [Point3::origin(), Point3::origin()];
        assert!(matches!(
            CompactRbf::try_new(&c, &v, Kernel::WendlandC2 { support: 1.0 }),
            Err(Error::CoincidentCentres { .. })
        ));
    }

    /// With no correction level the multilevel interpolant is its base, bit for bit.
    #[test]
    fn one_level_is_the_base() {
        let mut st = 0x1234_5678_9ABC_DEF1u64;
        let centres: Vec<Point3<f64>> =
            (0..200).map(|_| Point3::new(uniform(&mut st), uniform(&mut st), uniform(&mut st))).collect();
        let moves: Vec<Vector3<f64>> =
            (0..200).map(|_| Vector3::new(uniform(&mut st), uniform(&mut st), uniform(&mut st)) * 0.05).collect();
        let base = Rbf::try_new(&centres, &moves, Kernel::WendlandC2 { support: 0.5 }).unwrap();
        let ml = MultilevelRbf::new(base.clone());
        let pts: Vec<Point3<f64>> =
            (0..5000).map(|_| Point3::new(uniform(&mut st), uniform(&mut st), uniform(&mut st))).collect();
        assert_eq!(ml.deformed(&pts), base.deformed(&pts));
        assert_eq!(ml.deform_point(&pts[7]), base.deform_point(&pts[7]));
        assert_eq!(ml.n_centres(), 200);
    }
}
