//! Radial basis function interpolation of control-point displacements (paper §2.1.2,
//! eq. (3)–(5)), with every PyGeM kernel and the compactly supported Wendland family.

mod cg;
mod condition;
mod eval;
mod grid;
mod kernel;
mod multilevel;

pub use kernel::{Kernel, DEFAULT_K};
pub use multilevel::{CompactRbf, MultilevelRbf};

use faer::linalg::solvers::{Lblt, Solve};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Matrix4, Point3, Vector3};
use rayon::prelude::*;

use crate::deformation::{check_params, ParamWeights, PARALLEL_MIN_POINTS};
use crate::{Deformation, Error, LinearInParameters, Result};
use eval::Centres;
use grid::Grid;

/// Default limit on the interpolation miss at the control points, relative to the largest
/// control displacement.
///
/// After solving, the interpolant is evaluated at its own centres. A backward-stable solve
/// of a reasonably conditioned system misses them by about `ε·‖A‖·‖γ‖` (1e-16 to 1e-10 of
/// the displacements for the thin-plate spline on 10 to 10⁴ random centres). An
/// ill-conditioned one, such as PyGeM's Gaussian with radius 0.5 on 1000 random points in
/// the unit cube (condition estimate about 2·10²⁰; PyGeM misses its own control points by
/// 4.0), is refused with [`Error::SingularSystem`] or [`Error::IllConditioned`] and its
/// condition estimate, instead of returning numerical noise dressed as a shape.
pub const MAX_RESIDUAL: f64 = 1e-8;

/// Default limit on the 1-norm condition estimate of the interpolation system: at 10¹⁶ a
/// double-precision solve has no correct digit left in the worst case.
pub const MAX_CONDITION: f64 = 1e16;

/// From this many control points on, [`Solver::Auto`] solves compactly supported kernels
/// with the sparse factorisation (below it the dense one is as fast).
pub const SPARSE_MIN_CENTRES: usize = 1000;

/// From this many control points on, [`Solver::Auto`] solves compactly supported kernels
/// with conjugate gradients ([`Solver::Iterative`]) instead of the sparse Cholesky
/// factorisation, whose fill-in grows faster than the matrix in 3-D.
pub const ITERATIVE_MIN_CENTRES: usize = 8000;

/// Relative residual `‖Φγ − f‖ / ‖f‖` at which the conjugate gradients stop. Far below
/// [`MAX_RESIDUAL`], so that the interpolant passes through its centres as closely as with
/// a direct solve (the miss is still checked after solving).
pub const CG_TOL: f64 = 1e-12;

/// The parameters of an RBF: kernel, control points before and after the deformation.
#[derive(Debug, Clone, PartialEq)]
pub struct RbfParameters {
    /// The basis function.
    pub kernel: Kernel,
    /// Control points before the deformation.
    pub original: Vec<Point3<f64>>,
    /// Control points after the deformation (same count).
    pub deformed: Vec<Point3<f64>>,
}

/// How the interpolation system is solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Solver {
    /// Dense for global kernels; sparse for compact ones with at least
    /// [`SPARSE_MIN_CENTRES`] centres.
    #[default]
    Auto,
    /// Dense: the null-space method (four Householder reflections for the linear term and
    /// a faer Cholesky factorisation of the `(N−4)²` projected kernel matrix), or
    /// Bunch–Kaufman `LBLᵀ` (faer) of the whole symmetric `(N+4)²` system when the projected
    /// matrix is not definite.
    Dense,
    /// Sparse Cholesky (faer, AMD ordering) of the kernel block and a 4×4 Schur complement
    /// for the linear term; compact kernels only.
    Sparse,
    /// Conjugate gradients on the sparse kernel block, preconditioned by additive Schwarz
    /// over two staggered partitions of the centres into grid cells (each cell's block of
    /// Φ factored densely; Jacobi if a block does not factor), all right-hand sides in one
    /// pass over the matrix, and the same 4×4 Schur complement for the linear term;
    /// compact kernels only. No fill-in: memory is the matrix and the cells' factors.
    /// The condition estimate is the bound κ(M⁻¹Φ)·κ(M) from the CG coefficients'
    /// Lanczos estimate and the blocks' eigenvalue bounds. (With the environment
    /// variable `CADMORPH_CG_TRACE` set, the iteration count is printed to stderr;
    /// `CADMORPH_CG_BLOCK=0` selects the Jacobi preconditioner, `CADMORPH_CG_PARTS=1`
    /// one partition, for measurements.)
    Iterative,
}

/// Options for building an [`Rbf`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RbfOptions {
    /// Solver choice.
    pub solver: Solver,
    /// Largest accepted condition estimate (default [`MAX_CONDITION`]).
    pub max_condition: f64,
    /// Largest accepted miss at the control points, relative to the largest displacement
    /// (default [`MAX_RESIDUAL`]).
    pub max_residual: f64,
}

impl Default for RbfOptions {
    fn default() -> Self {
        RbfOptions { solver: Solver::Auto, max_condition: MAX_CONDITION, max_residual: MAX_RESIDUAL }
    }
}

/// The factorised interpolation system.
#[derive(Debug, Clone)]
enum System {
    /// Bunch–Kaufman `LBLᵀ` of the symmetric (indefinite) `(N+4)²` system.
    Dense(Lblt<f64>),
    /// The null-space method: `P = Q [R; 0]` (four Householder reflections), and a
    /// Cholesky factor of `±Z ᵀΦZ`, `Z` the last `N − 4` columns of `Q` (see
    /// [`Nullspace`]).
    Nullspace(Box<Nullspace>),
    Sparse {
        llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
        /// Φ⁻¹P (N×4).
        phi_inv_p: Mat<f64>,
        /// (PᵀΦ⁻¹P)⁻¹.
        schur_inv: Matrix4<f64>,
    },
    Iterative {
        /// Φ in the grid's sorted order.
        phi: cg::Csr,
        /// The preconditioner of its conjugate gradients.
        pre: cg::Precond,
        /// Φ⁻¹P (N×4).
        phi_inv_p: Mat<f64>,
        /// (PᵀΦ⁻¹P)⁻¹.
        schur_inv: Matrix4<f64>,
        /// Φ⁻¹f for the displacements at build time (solved with Φ⁻¹P in one CG run).
        first: Option<Mat<f64>>,
    },
}

/// RBF interpolation of control-point displacements (paper eq. (3)–(5)):
///
/// ```text
/// φ(x) = x + s(x) + Σᵢ γᵢ φ(‖x − x_Cᵢ‖),    s(x) = c + Q x,
/// φ(x_Cᵢ) = y_Cᵢ  (eq. 4),    Σᵢ γᵢ = 0,  Σᵢ γᵢ x_Cᵢ⁽ʲ⁾ = 0  (eq. 5)
/// ```
///
/// This is the interpolant PyGeM's `RBF` builds (it interpolates the deformed points
/// themselves, which differs by the identity in `Q`; [`Rbf::pygem_weights`] gives the
/// weights in its layout). The linear term uses centred and scaled coordinates internally,
/// which changes no value but keeps the system well conditioned for models far from the
/// origin or in millimetres.
///
/// Building solves the system once, densely (null-space method with a Cholesky factor, see
/// [`Solver::Dense`]) for global kernels, or with a
/// sparse matrix for compactly supported ones (sparse Cholesky from [`SPARSE_MIN_CENTRES`],
/// conjugate gradients from [`ITERATIVE_MIN_CENTRES`] centres, see [`Solver`]), and refuses a singular or ill-conditioned system
/// ([`Error::SingularSystem`], [`Error::IllConditioned`]) with its condition estimate.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Rbf, rbf::Kernel};
/// use cadmorph_morph::math::{Point3, Vector3};
/// let centres = [
///     Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0),
///     Point3::new(0.0, 0.0, 1.0), Point3::new(1.0, 1.0, 1.0),
/// ];
/// let mut moves = vec![Vector3::zeros(); 5];
/// moves[4] = Vector3::new(0.1, 0.2, 0.3);
/// let rbf = Rbf::try_new(&centres, &moves, Kernel::ThinPlate { radius: 0.5, k: 2 })?;
/// let p = rbf.deform_point(&centres[4]);
/// assert!((p - Point3::new(1.1, 1.2, 1.3)).norm() < 1e-13);
/// # Ok::<(), cadmorph_morph::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Rbf {
    kernel: Kernel,
    centres: Vec<Point3<f64>>,
    displacements: Vec<Vector3<f64>>,
    soa: Centres,
    /// Linear term per component c: `β[c] = [b₀, b₁, b₂, b₃]`, `s_c(x) = b₀ + Σₐ bₐ₊₁ (xₐ − shift_a)/scale`.
    beta: [[f64; 4]; 3],
    shift: Vector3<f64>,
    scale: f64,
    system: System,
    condition: f64,
    tree: Option<ImmutableKdTree<f64, 3>>,
    /// Cell grid of the centres (compact kernels), for assembly and bulk evaluation.
    grid: Option<Grid>,
}

impl Rbf {
    /// An RBF moving `centres[i]` by `displacements[i]`, with default [`RbfOptions`].
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] for unequal lists or fewer than 4 centres (the linear term
    /// has 4 unknowns); [`Error::InvalidParameter`] for a bad radius or a non-finite value;
    /// [`Error::SingularSystem`] (duplicate centres, all centres in one plane) and
    /// [`Error::IllConditioned`] with the condition estimate.
    pub fn try_new(centres: &[Point3<f64>], displacements: &[Vector3<f64>], kernel: Kernel) -> Result<Rbf> {
        Rbf::try_new_with(centres, displacements, kernel, RbfOptions::default())
    }

    /// The RBF described by `params` (displacements `deformed − original`).
    ///
    /// # Errors
    ///
    /// As [`Rbf::try_new`].
    pub fn from_parameters(params: &RbfParameters) -> Result<Rbf> {
        let d = crate::deformation::displacements(&params.original, &params.deformed)?;
        Rbf::try_new(&params.original, &d, params.kernel)
    }

    /// As [`Rbf::try_new`], with explicit options.
    ///
    /// # Errors
    ///
    /// As [`Rbf::try_new`]; also [`Error::InvalidParameter`] when [`Solver::Sparse`] is
    /// asked for a global kernel.
    pub fn try_new_with(
        centres: &[Point3<f64>],
        displacements: &[Vector3<f64>],
        kernel: Kernel,
        options: RbfOptions,
    ) -> Result<Rbf> {
        kernel.validate()?;
        let n = centres.len();
        if n != displacements.len() {
            return Err(Error::CountMismatch {
                line: 0,
                what: "displacements (one per control point)",
                expected: n,
                found: displacements.len(),
            });
        }
        if n < 4 {
            return Err(Error::CountMismatch {
                line: 0,
                what: "control points (the linear term needs at least 4)",
                expected: 4,
                found: n,
            });
        }
        for v in centres.iter().flat_map(|p| p.iter()).chain(displacements.iter().flat_map(|d| d.iter())) {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "control point",
                    value: *v,
                    reason: "must be finite",
                });
            }
        }
        let compact = kernel.support().is_some();
        let solver = match options.solver {
            Solver::Dense => Solver::Dense,
            Solver::Sparse | Solver::Iterative => {
                if !compact {
                    return Err(Error::InvalidParameter {
                        line: None,
                        name: "radius",
                        value: kernel.radius(),
                        reason: "the sparse solver needs a compactly supported kernel",
                    });
                }
                options.solver
            }
            Solver::Auto if compact && n >= ITERATIVE_MIN_CENTRES => Solver::Iterative,
            Solver::Auto if compact && n >= SPARSE_MIN_CENTRES => Solver::Sparse,
            Solver::Auto => Solver::Dense,
        };
        let shift = centres.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n as f64;
        let scale = centres.iter().map(|p| (p.coords - shift).amax()).fold(0.0, f64::max);
        let scale = if scale > 0.0 { scale } else { 1.0 };
        if let Some((first, second)) = coincident_pair(centres, 1e-12 * scale) {
            let p = centres[first];
            return Err(Error::CoincidentCentres { first, second, point: [p.x, p.y, p.z] });
        }
        if matches!(solver, Solver::Dense) {
            // The assembled (N+4)² system, the factor of the fallback and its scratch.
            crate::budget::check(&format!("dense RBF system of {n} centres"), &[n + 4, n + 4, 3], 8)?;
        }
        let tree = kernel.support().map(|_| {
            let pts: Vec<[f64; 3]> = centres.iter().map(|p| [p.x, p.y, p.z]).collect();
            ImmutableKdTree::new_from_slice(&pts)
        });
        let mut rbf = Rbf {
            kernel,
            centres: centres.to_vec(),
            displacements: displacements.to_vec(),
            soa: Centres {
                x: centres.iter().map(|p| p.x).collect(),
                y: centres.iter().map(|p| p.y).collect(),
                z: centres.iter().map(|p| p.z).collect(),
                g: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            },
            beta: [[0.0; 4]; 3],
            shift,
            scale,
            system: System::Dense(Mat::<f64>::identity(1, 1).lblt(Side::Lower)),
            condition: 1.0,
            tree,
            grid: kernel.support().map(|s| Grid::new(centres, s)),
        };
        let (system, condition) = match solver {
            Solver::Sparse => rbf.factor_sparse()?,
            Solver::Iterative => rbf.factor_iterative()?,
            _ => rbf.factor_dense()?,
        };
        if !condition.is_finite() {
            return Err(Error::SingularSystem { condition });
        }
        rbf.system = system;
        rbf.condition = condition;
        rbf.solve_weights()?;
        let residual = rbf.residual();
        if residual > options.max_residual || condition > options.max_condition {
            if condition >= 1.0 / f64::EPSILON && residual > options.max_residual {
                return Err(Error::SingularSystem { condition });
            }
            return Err(Error::IllConditioned { condition, residual, max_condition: options.max_condition });
        }
        Ok(rbf)
    }

    /// Largest miss of the interpolant at its centres, relative to the largest displacement.
    fn residual(&self) -> f64 {
        let scale = self.displacements.iter().map(|d| d.amax()).fold(0.0, f64::max);
        if scale == 0.0 {
            return 0.0;
        }
        let moved = self.deformed(&self.centres);
        let miss = moved
            .iter()
            .zip(&self.centres)
            .zip(&self.displacements)
            .map(|((m, c), d)| (m - c - d).amax())
            .fold(0.0, |a: f64, b| if b.is_nan() { f64::INFINITY } else { a.max(b) });
        miss / scale
    }

    /// The polynomial basis row `[1, (x − shift)/scale]`.
    fn poly_row(&self, p: &Point3<f64>) -> [f64; 4] {
        let q = (p.coords - self.shift) / self.scale;
        [1.0, q.x, q.y, q.z]
    }

    /// Dense factorisation: the null-space method when `ZᵀΦZ` is definite (kernels that
    /// are positive definite or conditionally definite of order ≤ 2, on distinct,
    /// non-coplanar centres: all of PyGeM's except `polyharmonic_spline` with even k ≥ 4),
    /// else Bunch–Kaufman on the whole system.
    fn factor_dense(&self) -> Result<(System, f64)> {
        match self.factor_nullspace() {
            Some(found) => Ok(found),
            None => self.factor_kkt(),
        }
    }

    /// The null-space method (Nocedal & Wright §16.2; for RBFs, e.g. Beatson, Light &
    /// Billings 2000): with `P = Q [R; 0]` and `Q = [Y Z]`, the system
    /// `[Φ P; Pᵀ 0] [γ; β] = [f; g]` becomes `γ = Y u₁ + Z u₂`, `Rᵀu₁ = g`,
    /// `(ZᵀΦZ) u₂ = Zᵀf − ZᵀΦY u₁`, `Rβ = Yᵀ(f − Φγ)`. `ZᵀΦZ` is positive definite for
    /// positive definite kernels and for conditionally positive definite ones of order ≤ 2
    /// (thin plate r² ln r, r³), negative definite for the conditionally negative definite
    /// ones of order 1 (multiquadric, r): a Cholesky factorisation of `±ZᵀΦZ`, `(N − 4)³/3` flops
    /// against `(N + 4)³/3` for `LBLᵀ` with its pivoting and `2(N + 4)³/3` for LU.
    /// `None` when neither sign factors (the caller falls back to `LBLᵀ`).
    fn factor_nullspace(&self) -> Option<(System, f64)> {
        let n = self.centres.len();
        if n <= 4 {
            return None;
        }
        let polys: Vec<[f64; 4]> = self.centres.iter().map(|p| self.poly_row(p)).collect();
        let house = Householder4::new(&polys)?;
        // The sign that makes ±ZᵀΦZ definite, by the kernel's theory; the other is tried
        // second (the factorisation overwrites the matrix, so a failed try costs a new
        // assembly).
        let first = match self.kernel {
            Kernel::MultiQuadratic { .. } | Kernel::Polyharmonic { k: 1, .. } => -1.0,
            _ => 1.0,
        };
        for sign in [first, -first] {
            let (mut data, norm1) = self.projected_matrix(&polys, &house);
            let b11 = Matrix4::from_fn(|i, j| data[j * n + i]);
            let b21 = Mat::from_fn(n - 4, 4, |i, j| data[j * n + 4 + i]);
            if sign < 0.0 {
                data.par_chunks_mut(n).skip(4).for_each(|col| col[4..].iter_mut().for_each(|v| *v = -*v));
            }
            // Cholesky in place, in the lower triangle of the trailing block (no second N²
            // copy: 4000 centres take 150 MB instead of 276).
            let par = faer::get_global_parallelism();
            let req =
                faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(n - 4, par, Default::default());
            // A scratch that cannot be had is a failed factorisation here, not an abort: the
            // caller's fallback (or its error) takes over.
            let Ok(mut mem) = faer::dyn_stack::MemBuffer::try_new(req) else {
                return None;
            };
            let factored = faer::linalg::cholesky::llt::factor::cholesky_in_place(
                faer::MatMut::from_column_major_slice_with_stride_mut(&mut data[4 * n + 4..], n - 4, n - 4, n),
                Default::default(),
                par,
                faer::dyn_stack::MemStack::new(&mut mem),
                Default::default(),
            );
            if factored.is_err() {
                continue;
            }
            let ns = Nullspace { house, b11, b21, factor: data, sign };
            let size = n + 4;
            let mut solve = |x: &mut [f64]| {
                let mut m = Mat::from_fn(size, 1, |i, _| x[i]);
                ns.solve_in_place(&mut m);
                for (i, v) in x.iter_mut().enumerate() {
                    *v = m[(i, 0)];
                }
            };
            // The system is symmetric: the transposed solve is the same solve.
            let mut solve_t = solve;
            let inv = condition::inverse_norm1(size, &mut solve, &mut solve_t);
            return Some((System::Nullspace(Box::new(ns)), norm1 * inv));
        }
        None
    }

    /// `QᵀΦQ` (N×N, column-major) and `‖[Φ P; Pᵀ 0]‖₁` for the condition estimate.
    fn projected_matrix(&self, polys: &[[f64; 4]], house: &Householder4) -> (Vec<f64>, f64) {
        let n = self.centres.len();
        let mut data = vec![0.0; n * n];
        data.par_chunks_mut(n).enumerate().for_each(|(j, col)| {
            eval::kernel_column(&self.kernel, &self.soa, self.centres[j], col);
        });
        let norm1_phi = data
            .par_chunks(n)
            .zip(polys.par_iter())
            .map(|(c, p)| c.iter().map(|v| v.abs()).sum::<f64>() + p.iter().map(|v| v.abs()).sum::<f64>())
            .reduce(|| 0.0, f64::max);
        let norm1_p = (0..4).map(|a| polys.iter().map(|p| p[a].abs()).sum::<f64>()).fold(0.0, f64::max);
        house.project_both_sides(&mut data, n);
        (data, norm1_phi.max(norm1_p))
    }

    /// Bunch–Kaufman `LBLᵀ` of the whole `(N + 4)²` system (the fallback of
    /// [`Rbf::factor_dense`]).
    fn factor_kkt(&self) -> Result<(System, f64)> {
        let n = self.centres.len();
        let size = n + 4;
        let kernel = self.kernel;
        let polys: Vec<[f64; 4]> = self.centres.iter().map(|p| self.poly_row(p)).collect();
        let mut data = vec![0.0; size * size];
        data.par_chunks_mut(size).enumerate().for_each(|(j, col)| {
            if j < n {
                eval::kernel_column(&kernel, &self.soa, self.centres[j], &mut col[..n]);
                col[n..].copy_from_slice(&polys[j]);
            } else {
                for i in 0..n {
                    col[i] = polys[i][j - n];
                }
            }
        });
        let norm1 = data.par_chunks(size).map(|c| c.iter().map(|v| v.abs()).sum::<f64>()).reduce(|| 0.0, f64::max);
        // The system is symmetric (indefinite with the polynomial block): Bunch–Kaufman
        // LBLᵀ reads the lower triangle and costs half of an LU.
        let lblt = faer::MatRef::from_column_major_slice(&data, size, size).lblt(Side::Lower);
        drop(data);
        let inv = condition::inverse_norm1(size, &mut |x: &mut [f64]| solve_vec(&lblt, x), &mut |x: &mut [f64]| {
            solve_vec(&lblt, x)
        });
        Ok((System::Dense(lblt), norm1 * inv))
    }

    fn factor_sparse(&self) -> Result<(System, f64)> {
        let n = self.centres.len();
        let tree = self.tree.as_ref().expect("compact kernels have a tree");
        let s = self.kernel.support().expect("compact kernel");
        let kernel = self.kernel;
        // Lower triangle of Φ (row ≥ column), found with the k-d tree.
        let columns: Vec<Vec<(usize, f64)>> = (0..n)
            .into_par_iter()
            .map(|j| {
                let c = self.centres[j];
                let mut col: Vec<(usize, f64)> = tree
                    .within_unsorted::<SquaredEuclidean>(&[c.x, c.y, c.z], s * s)
                    .into_iter()
                    .filter_map(|nb| {
                        let i = nb.item as usize;
                        (i >= j && nb.distance < s * s).then(|| (i, kernel.eval(nb.distance.sqrt())))
                    })
                    .collect();
                col.sort_unstable_by_key(|e| e.0);
                col
            })
            .collect();
        let mut norm1_cols = vec![0.0; n];
        let mut triplets = Vec::with_capacity(columns.iter().map(Vec::len).sum());
        for (j, col) in columns.iter().enumerate() {
            for &(i, v) in col {
                triplets.push(Triplet::new(i, j, v));
                norm1_cols[j] += v.abs();
                if i != j {
                    norm1_cols[i] += v.abs();
                }
            }
        }
        drop(columns);
        let norm1 = norm1_cols.into_iter().fold(0.0, f64::max);
        let phi = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|_| Error::SingularSystem { condition: f64::INFINITY })?;
        drop(triplets);
        // Φ is positive definite for distinct centres; a failed Cholesky means coincident ones.
        let llt = phi.sp_cholesky(Side::Lower).map_err(|_| Error::SingularSystem { condition: f64::INFINITY })?;
        drop(phi);
        let inv =
            condition::inverse_norm1(n, &mut |x: &mut [f64]| sparse_solve_vec(&llt, x), &mut |x: &mut [f64]| {
                sparse_solve_vec(&llt, x)
            });
        let cond_phi = norm1 * inv;
        let mut phi_inv_p = Mat::from_fn(n, 4, |i, a| self.poly_row(&self.centres[i])[a]);
        llt.solve_in_place(phi_inv_p.as_mut());
        let (schur_inv, cond_schur) = self.schur(&phi_inv_p)?;
        Ok((System::Sparse { llt, phi_inv_p, schur_inv }, cond_phi.max(cond_schur)))
    }

    fn factor_iterative(&self) -> Result<(System, f64)> {
        let n = self.centres.len();
        let grid = self.grid.as_ref().expect("compact kernels have a grid");
        let phi = assemble_csr(grid, self.kernel);
        let pre = block_preconditioner(grid, &phi);
        // One CG run for Φ⁻¹[f P]: columns 0..3 the displacements, 3..7 the polynomial basis.
        let mut b: Vec<[f64; cg::W]> = grid
            .perm
            .iter()
            .map(|&i| {
                let (d, r) = (self.displacements[i as usize], self.poly_row(&self.centres[i as usize]));
                [d.x, d.y, d.z, r[0], r[1], r[2], r[3], 0.0]
            })
            .collect();
        let info = cg::solve(&phi, &mut b, 7, CG_TOL, cg_max_iter(n), &pre);
        let cond_phi = info.condition;
        if std::env::var_os("CADMORPH_CG_TRACE").is_some() {
            eprintln!(
                "cg: n={n} nnz={} iterations={} converged={} cond={cond_phi:.3e}",
                phi.val.len(),
                info.iterations,
                info.converged
            );
        }
        if !info.converged || !cond_phi.is_finite() {
            if cond_phi.is_nan() || cond_phi >= 1.0 / f64::EPSILON {
                return Err(Error::SingularSystem { condition: cond_phi });
            }
            return Err(Error::IllConditioned {
                condition: cond_phi,
                residual: f64::INFINITY,
                max_condition: MAX_CONDITION,
            });
        }
        let mut phi_inv_p = Mat::<f64>::zeros(n, 4);
        let mut first = Mat::<f64>::zeros(n, 3);
        for (s, &i) in grid.perm.iter().enumerate() {
            for c in 0..3 {
                first[(i as usize, c)] = b[s][c];
            }
            for a in 0..4 {
                phi_inv_p[(i as usize, a)] = b[s][3 + a];
            }
        }
        let (schur_inv, cond_schur) = self.schur(&phi_inv_p)?;
        Ok((System::Iterative { phi, pre, phi_inv_p, schur_inv, first: Some(first) }, cond_phi.max(cond_schur)))
    }

    /// `(PᵀΦ⁻¹P)⁻¹` and the 1-norm condition of `PᵀΦ⁻¹P`.
    fn schur(&self, phi_inv_p: &Mat<f64>) -> Result<(Matrix4<f64>, f64)> {
        let mut schur = Matrix4::zeros();
        for (i, c) in self.centres.iter().enumerate() {
            let row = self.poly_row(c);
            for a in 0..4 {
                for b in 0..4 {
                    schur[(a, b)] += row[a] * phi_inv_p[(i, b)];
                }
            }
        }
        let schur_inv = schur.try_inverse().ok_or(Error::SingularSystem { condition: f64::INFINITY })?;
        let col_norm1 = |m: &Matrix4<f64>| -> f64 {
            (0..4).map(|j| m.column(j).iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max)
        };
        let cond_schur = col_norm1(&schur) * col_norm1(&schur_inv);
        Ok((schur_inv, if cond_schur.is_finite() { cond_schur } else { f64::INFINITY }))
    }

    /// `Φ⁻¹z` for the columns of `z` (original order) by conjugate gradients.
    fn cg_solve(&self, phi: &cg::Csr, pre: &cg::Precond, z: &mut Mat<f64>) {
        let grid = self.grid.as_ref().expect("compact kernels have a grid");
        let n = self.centres.len();
        for c0 in (0..z.ncols()).step_by(cg::W) {
            let m = (z.ncols() - c0).min(cg::W);
            let mut b: Vec<[f64; cg::W]> = grid
                .perm
                .iter()
                .map(|&i| std::array::from_fn(|c| if c < m { z[(i as usize, c0 + c)] } else { 0.0 }))
                .collect();
            cg::solve(phi, &mut b, m, CG_TOL, cg_max_iter(n), pre);
            for (s, &i) in grid.perm.iter().enumerate() {
                for c in 0..m {
                    z[(i as usize, c0 + c)] = b[s][c];
                }
            }
        }
    }

    /// Solve the KKT system `[Φ P; Pᵀ 0] [γ; β] = [f; h]` in place for the columns of `rhs`
    /// ((N+4) × m).
    fn solve_kkt(&self, rhs: &mut Mat<f64>) {
        self.solve_kkt_with(rhs, None);
    }

    /// As [`Rbf::solve_kkt`]; `known` is `Φ⁻¹f` when already solved.
    fn solve_kkt_with(&self, rhs: &mut Mat<f64>, known: Option<Mat<f64>>) {
        let n = self.centres.len();
        let m = rhs.ncols();
        let (z, phi_inv_p, schur_inv) = match &self.system {
            System::Dense(lblt) => return lblt.solve_in_place(rhs.as_mut()),
            System::Nullspace(ns) => return ns.solve_in_place(rhs),
            System::Sparse { llt, phi_inv_p, schur_inv } => {
                let mut z = Mat::from_fn(n, m, |i, j| rhs[(i, j)]);
                llt.solve_in_place(z.as_mut());
                (z, phi_inv_p, schur_inv)
            }
            System::Iterative { phi, pre, phi_inv_p, schur_inv, .. } => {
                let z = known.unwrap_or_else(|| {
                    let mut z = Mat::from_fn(n, m, |i, j| rhs[(i, j)]);
                    self.cg_solve(phi, pre, &mut z);
                    z
                });
                (z, phi_inv_p, schur_inv)
            }
        };
        let polys: Vec<[f64; 4]> = self.centres.iter().map(|c| self.poly_row(c)).collect();
        for col in 0..m {
            // β = S⁻¹ (Pᵀ Φ⁻¹ f − h)
            let mut t = nalgebra::Vector4::zeros();
            for (i, row) in polys.iter().enumerate() {
                for a in 0..4 {
                    t[a] += row[a] * z[(i, col)];
                }
            }
            for a in 0..4 {
                t[a] -= rhs[(n + a, col)];
            }
            let beta = schur_inv * t;
            for i in 0..n {
                let mut v = z[(i, col)];
                for a in 0..4 {
                    v -= phi_inv_p[(i, a)] * beta[a];
                }
                rhs[(i, col)] = v;
            }
            for a in 0..4 {
                rhs[(n + a, col)] = beta[a];
            }
        }
    }

    /// Solve for γ and β from the current displacements.
    fn solve_weights(&mut self) -> Result<()> {
        let n = self.centres.len();
        let mut rhs = Mat::from_fn(n + 4, 3, |i, c| if i < n { self.displacements[i][c] } else { 0.0 });
        let known = match &mut self.system {
            System::Iterative { first, .. } => first.take(),
            _ => None,
        };
        self.solve_kkt_with(&mut rhs, known);
        for c in 0..3 {
            for i in 0..n {
                let v = rhs[(i, c)];
                if !v.is_finite() {
                    return Err(Error::SingularSystem { condition: f64::INFINITY });
                }
                self.soa.g[c][i] = v;
            }
            for a in 0..4 {
                self.beta[c][a] = rhs[(n + a, c)];
            }
        }
        if let Some(grid) = &mut self.grid {
            grid.set_weights(&self.soa.g);
        }
        Ok(())
    }

    /// The kernel.
    pub fn kernel(&self) -> Kernel {
        self.kernel
    }
    /// The control points.
    pub fn centres(&self) -> &[Point3<f64>] {
        &self.centres
    }
    /// The control displacements.
    pub fn displacements(&self) -> &[Vector3<f64>] {
        &self.displacements
    }
    /// The 1-norm condition estimate of the solved system (of the kernel block and of
    /// the 4×4 Schur complement, the larger, for the sparse solver). For conjugate
    /// gradients it is the 2-norm estimate of the kernel block from the run's Lanczos
    /// coefficients; with the block preconditioner, the bound `κ(M⁻¹Φ)·κ(M)`, which lies
    /// above `κ(Φ)`.
    pub fn condition(&self) -> f64 {
        self.condition
    }
    /// Whether the system was solved with the sparse factorisation.
    pub fn is_sparse(&self) -> bool {
        matches!(self.system, System::Sparse { .. } | System::Iterative { .. })
    }
    /// Whether the system was solved with conjugate gradients ([`Solver::Iterative`]).
    pub fn is_iterative(&self) -> bool {
        matches!(self.system, System::Iterative { .. })
    }

    /// The parameters (control points before and after).
    pub fn parameters(&self) -> RbfParameters {
        RbfParameters {
            kernel: self.kernel,
            original: self.centres.clone(),
            deformed: self.centres.iter().zip(&self.displacements).map(|(c, d)| c + d).collect(),
        }
    }

    /// The weights in PyGeM's layout (`RBF.weights`, (N+4) × 3): rows `0..N` are γᵢ, row
    /// `N` the constant c, rows `N+1..N+4` the coefficients of x, y, z (PyGeM interpolates
    /// the deformed points, so its linear part is this crate's plus the identity).
    pub fn pygem_weights(&self) -> Vec<[f64; 3]> {
        let n = self.centres.len();
        let mut out = vec![[0.0; 3]; n + 4];
        for c in 0..3 {
            for i in 0..n {
                out[i][c] = self.soa.g[c][i];
            }
            let b = self.beta[c];
            // b₀ + Σ bₐ (xₐ − shiftₐ)/scale = (b₀ − Σ bₐ shiftₐ/scale) + Σ (bₐ/scale) xₐ
            out[n][c] = b[0] - (0..3).map(|a| b[a + 1] * self.shift[a] / self.scale).sum::<f64>();
            for a in 0..3 {
                out[n + 1 + a][c] = b[a + 1] / self.scale + if a == c { 1.0 } else { 0.0 };
            }
        }
        out
    }

    /// The linear term's displacement `s(p)`.
    #[inline]
    fn linear_term(&self, p: &Point3<f64>) -> Vector3<f64> {
        let r = self.poly_row(p);
        Vector3::from_fn(|c, _| {
            self.beta[c][0] + self.beta[c][1] * r[1] + self.beta[c][2] * r[2] + self.beta[c][3] * r[3]
        })
    }

    /// Indices and distances of the centres whose kernel may be nonzero at `p`.
    fn neighbours(&self, p: &Point3<f64>) -> Option<Vec<(usize, f64)>> {
        let tree = self.tree.as_ref()?;
        let s = self.kernel.support()?;
        Some(
            tree.within_unsorted::<SquaredEuclidean>(&[p.x, p.y, p.z], s * s)
                .into_iter()
                .filter(|nb| nb.distance < s * s)
                .map(|nb| (nb.item as usize, nb.distance.sqrt()))
                .collect(),
        )
    }

    /// Deform `points` on the calling thread.
    fn deform_serial(&self, points: &mut [Point3<f64>]) {
        let mut sums = vec![[0.0; 3]; points.len()];
        match &self.grid {
            Some(grid) => eval::grid_sums(&self.kernel, grid, points, &mut sums),
            None => eval::dense_sums(&self.kernel, &self.soa, points, &mut sums),
        }
        for (p, s) in points.iter_mut().zip(sums) {
            *p += self.linear_term(p) + Vector3::from(s);
        }
    }
}

/// The factorised dense system of the null-space method (see `Rbf::factor_nullspace`):
/// `B = QᵀΦQ` in blocks `B₁₁` (4×4), `B₂₁` ((N−4)×4) and the Cholesky factor `L` of
/// `sign · B₂₂`, which sits in the lower triangle of rows and columns 4.. of `factor` (the
/// N×N column-major array it was computed in).
#[derive(Debug, Clone)]
struct Nullspace {
    house: Householder4,
    b11: Matrix4<f64>,
    b21: Mat<f64>,
    factor: Vec<f64>,
    sign: f64,
}

impl Nullspace {
    /// `[γ; β] ← [Φ P; Pᵀ 0]⁻¹ [f; g]` for every column of `rhs` ((N+4) rows).
    fn solve_in_place(&self, rhs: &mut Mat<f64>) {
        let n = self.house.n;
        let m = rhs.ncols();
        let mut u1 = Vec::with_capacity(m);
        let mut qf = Vec::with_capacity(m);
        // Right-hand sides of the (N−4)² system, all columns in one Cholesky solve.
        let mut t = Mat::<f64>::zeros(n - 4, m);
        for col in 0..m {
            let mut f: Vec<f64> = (0..n).map(|i| rhs[(i, col)]).collect();
            self.house.apply_qt(&mut f);
            let g = nalgebra::Vector4::from_fn(|a, _| rhs[(n + a, col)]);
            let u = self.house.solve_rt(&g);
            for i in 0..n - 4 {
                let b = (0..4).map(|a| self.b21[(i, a)] * u[a]).sum::<f64>();
                t[(i, col)] = self.sign * (f[4 + i] - b);
            }
            u1.push(u);
            qf.push(f);
        }
        let l = faer::MatRef::from_column_major_slice_with_stride(&self.factor[4 * n + 4..], n - 4, n - 4, n);
        faer::linalg::cholesky::llt::solve::solve_in_place_with_conj(
            l,
            faer::Conj::No,
            t.as_mut(),
            faer::get_global_parallelism(),
            faer::dyn_stack::MemStack::new(&mut []),
        );
        for col in 0..m {
            let (u, mut f) = (u1[col], std::mem::take(&mut qf[col]));
            // Rβ = (Qᵀf)₁ − B₁₁u₁ − B₂₁ᵀu₂
            let mut top = nalgebra::Vector4::from_fn(|a, _| f[a]) - self.b11 * u;
            for a in 0..4 {
                top[a] -= (0..n - 4).map(|i| self.b21[(i, a)] * t[(i, col)]).sum::<f64>();
            }
            let beta = self.house.solve_r(&top);
            // γ = Q [u₁; u₂]
            f[..4].copy_from_slice(u.as_slice());
            for i in 0..n - 4 {
                f[4 + i] = t[(i, col)];
            }
            self.house.apply_q(&mut f);
            for (i, v) in f.iter().enumerate() {
                rhs[(i, col)] = *v;
            }
            for a in 0..4 {
                rhs[(n + a, col)] = beta[a];
            }
        }
    }
}

/// Householder QR of an N×4 matrix: `P = H₀H₁H₂H₃ [R; 0]`, `Hc = I − τc vc vcᵀ`, with
/// `vc` zero above row c.
#[derive(Debug, Clone)]
struct Householder4 {
    n: usize,
    v: [Vec<f64>; 4],
    tau: [f64; 4],
    r: Matrix4<f64>,
}

impl Householder4 {
    /// The QR factorisation of the rows `p`, or `None` when P has rank below 4 (all
    /// centres in one plane).
    fn new(p: &[[f64; 4]]) -> Option<Householder4> {
        let n = p.len();
        let mut a: Vec<Vec<f64>> = (0..4).map(|c| p.iter().map(|row| row[c]).collect()).collect();
        let mut v: [Vec<f64>; 4] = Default::default();
        let mut tau = [0.0; 4];
        let mut r = Matrix4::zeros();
        let scale = a.iter().map(|col| col.iter().fold(0.0, |m: f64, x| m.max(x.abs()))).fold(0.0, f64::max);
        for c in 0..4 {
            let x = &a[c][c..];
            let norm = x.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm.is_nan() || norm <= 1e-13 * scale * (n as f64).sqrt() {
                return None;
            }
            let alpha = if x[0] > 0.0 { -norm } else { norm };
            let mut vc = vec![0.0; n];
            vc[c..].copy_from_slice(x);
            vc[c] -= alpha;
            let vv = vc[c..].iter().map(|x| x * x).sum::<f64>();
            tau[c] = 2.0 / vv;
            for col in a.iter_mut().skip(c) {
                let d = tau[c] * vc[c..].iter().zip(&col[c..]).map(|(x, y)| x * y).sum::<f64>();
                for (y, x) in col[c..].iter_mut().zip(&vc[c..]) {
                    *y -= d * x;
                }
            }
            for (row, col) in a.iter().enumerate().take(4).skip(c) {
                r[(c, row)] = col[c];
            }
            v[c] = vc;
        }
        Some(Householder4 { n, v, tau, r })
    }

    /// `A ← QᵀAQ` for a symmetric N×N column-major `A` (both triangles kept), the four
    /// reflections at once in the compact WY form `Q = H₀H₁H₂H₃ = I − V T Vᵀ` (Schreiber &
    /// Van Loan): with `P = AV`, `S = Tᵀ(VᵀP)T` and `W = PT − ½VS`, `QᵀAQ = A − WVᵀ − VWᵀ`.
    /// Two passes over `A` (one read, one rank-8 update) instead of eight.
    fn project_both_sides(&self, a: &mut [f64], n: usize) {
        let v = &self.v;
        // T upper triangular: T₀..c,c = −τc T₀..c,₀..c (V₀..cᵀ vc), Tcc = τc.
        let mut t = Matrix4::zeros();
        for c in 0..4 {
            t[(c, c)] = self.tau[c];
            let vtv: Vec<f64> = (0..c).map(|k| v[k].iter().zip(&v[c]).map(|(x, y)| x * y).sum()).collect();
            for r in 0..c {
                t[(r, c)] = -self.tau[c] * (r..c).map(|k| t[(r, k)] * vtv[k]).sum::<f64>();
            }
        }
        // P = AV: row i of AV is column i of A (A symmetric) dotted with V's columns.
        let p: Vec<[f64; 4]> = a
            .par_chunks(n)
            .map(|col| {
                let mut row = [0.0; 4];
                for (k, vk) in v.iter().enumerate() {
                    row[k] = col.iter().zip(vk).map(|(x, y)| x * y).sum();
                }
                row
            })
            .collect();
        let m = Matrix4::from_fn(|r, c| (0..n).map(|i| v[r][i] * p[i][c]).sum::<f64>());
        let s = t.transpose() * m * t;
        let w: Vec<[f64; 4]> = (0..n)
            .map(|i| {
                let vi = nalgebra::RowVector4::new(v[0][i], v[1][i], v[2][i], v[3][i]);
                let pi = nalgebra::RowVector4::from(p[i]);
                let wi = pi * t - 0.5 * vi * s;
                [wi[0], wi[1], wi[2], wi[3]]
            })
            .collect();
        let vrows: Vec<[f64; 4]> = (0..n).map(|i| [v[0][i], v[1][i], v[2][i], v[3][i]]).collect();
        a.par_chunks_mut(n).enumerate().for_each(|(j, col)| {
            let (vj, wj) = (vrows[j], w[j]);
            for ((x, vi), wi) in col.iter_mut().zip(&vrows).zip(&w) {
                let mut d = 0.0;
                for k in 0..4 {
                    d += wi[k] * vj[k] + vi[k] * wj[k];
                }
                *x -= d;
            }
        });
    }

    /// `x ← Qᵀx = H₃H₂H₁H₀ x`.
    fn apply_qt(&self, x: &mut [f64]) {
        for c in 0..4 {
            self.reflect(c, x);
        }
    }

    /// `x ← Qx = H₀H₁H₂H₃ x`.
    fn apply_q(&self, x: &mut [f64]) {
        for c in (0..4).rev() {
            self.reflect(c, x);
        }
    }

    fn reflect(&self, c: usize, x: &mut [f64]) {
        let v = &self.v[c][c..];
        let d = self.tau[c] * v.iter().zip(&x[c..]).map(|(a, b)| a * b).sum::<f64>();
        for (y, a) in x[c..].iter_mut().zip(v) {
            *y -= d * a;
        }
    }

    /// `R⁻ᵀ g` (forward substitution).
    fn solve_rt(&self, g: &nalgebra::Vector4<f64>) -> nalgebra::Vector4<f64> {
        let mut u = nalgebra::Vector4::zeros();
        for i in 0..4 {
            let s = (0..i).map(|k| self.r[(k, i)] * u[k]).sum::<f64>();
            u[i] = (g[i] - s) / self.r[(i, i)];
        }
        u
    }

    /// `R⁻¹ b` (back substitution).
    fn solve_r(&self, b: &nalgebra::Vector4<f64>) -> nalgebra::Vector4<f64> {
        let mut x = nalgebra::Vector4::zeros();
        for i in (0..4).rev() {
            let s = (i + 1..4).map(|k| self.r[(i, k)] * x[k]).sum::<f64>();
            x[i] = (b[i] - s) / self.r[(i, i)];
        }
        x
    }
}

/// Φ of a compactly supported kernel in the grid's sorted order (neighbouring centres close
/// in memory), both triangles, rows assembled in parallel blocks.
fn assemble_csr(grid: &Grid, kernel: Kernel) -> cg::Csr {
    let n = grid.x.len();
    let s2 = kernel.support().expect("compact kernel").powi(2);
    const BLOCK: usize = 1024;
    let blocks: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let (mut lens, mut col, mut val) = (Vec::with_capacity(BLOCK), Vec::new(), Vec::new());
            for i in b * BLOCK..((b + 1) * BLOCK).min(n) {
                let before = col.len();
                let (x, y, z) = (grid.x[i], grid.y[i], grid.z[i]);
                grid.for_each_range([x, y, z], |r| {
                    for j in r {
                        let (u, v, w) = (x - grid.x[j], y - grid.y[j], z - grid.z[j]);
                        let r2 = u * u + v * v + w * w;
                        if r2 < s2 {
                            col.push(j as u32);
                            val.push(kernel.eval(r2.sqrt()));
                        }
                    }
                });
                lens.push(col.len() - before);
            }
            (lens, col, val)
        })
        .collect();
    let nnz = blocks.iter().map(|b| b.1.len()).sum();
    let mut phi =
        cg::Csr { row_ptr: Vec::with_capacity(n + 1), col: Vec::with_capacity(nnz), val: Vec::with_capacity(nnz) };
    phi.row_ptr.push(0);
    for (lens, col, val) in blocks {
        for l in lens {
            phi.row_ptr.push(phi.row_ptr.last().copied().unwrap_or(0) + l);
        }
        phi.col.extend_from_slice(&col);
        phi.val.extend_from_slice(&val);
    }
    phi
}

/// Centres per block of the block-Jacobi preconditioner ([`cg::BlockJacobi`]): the cube
/// of grid cells nearest this many centres (one cell, side = the support, for the usual
/// 20–100 neighbours), groups over twice this cut; the default of `CADMORPH_CG_BLOCK`
/// (0 turns the blocks off, for measurements). Measured on 50k centres with 107
/// neighbours each: one cell per block 124 iterations, 1.1–1.3 s; 2×2×2 cells 100
/// iterations, 2.1–2.3 s (`benches/pygem/README.md`).
const CG_BLOCK: usize = 60;

/// The block-Jacobi preconditioner over compact groups of the grid's cells, or Jacobi
/// when a block does not factor.
fn block_preconditioner(grid: &Grid, phi: &cg::Csr) -> cg::Precond {
    let target = std::env::var("CADMORPH_CG_BLOCK").ok().and_then(|v| v.parse().ok()).unwrap_or(CG_BLOCK);
    if target == 0 {
        return cg::Precond::Jacobi;
    }
    let parts = std::env::var("CADMORPH_CG_PARTS").ok().and_then(|v| v.parse().ok()).unwrap_or(2usize);
    let mut out = Vec::new();
    for p in 0..parts.clamp(1, 2) {
        let (order, bounds) = grid.blocks(target, p == 1);
        match cg::BlockJacobi::new(phi, order, bounds) {
            Some(b) => out.push(b),
            None => return cg::Precond::Jacobi,
        }
    }
    cg::Precond::Blocks(out)
}

/// Iteration limit of the conjugate gradients for `n` centres.
fn cg_max_iter(n: usize) -> usize {
    (3 * n).clamp(1000, 20_000)
}

/// `x ← A⁻¹x` with the dense `LBLᵀ` factors (A is symmetric, so also `A⁻ᵀx`).
fn solve_vec(lblt: &Lblt<f64>, x: &mut [f64]) {
    let mut m = Mat::from_fn(x.len(), 1, |i, _| x[i]);
    lblt.solve_in_place(m.as_mut());
    for (i, v) in x.iter_mut().enumerate() {
        *v = m[(i, 0)];
    }
}

/// `x ← Φ⁻¹x` with a sparse Cholesky factor.
fn sparse_solve_vec(llt: &faer::sparse::linalg::solvers::Llt<usize, f64>, x: &mut [f64]) {
    let mut m = Mat::from_fn(x.len(), 1, |i, _| x[i]);
    llt.solve_in_place(m.as_mut());
    for (i, v) in x.iter_mut().enumerate() {
        *v = m[(i, 0)];
    }
}

impl Deformation for Rbf {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        let mut d = self.linear_term(p);
        match self.neighbours(p) {
            Some(nbs) => {
                for (j, r) in nbs {
                    let f = self.kernel.eval(r);
                    d += f * Vector3::new(self.soa.g[0][j], self.soa.g[1][j], self.soa.g[2][j]);
                }
            }
            None => {
                for (j, c) in self.centres.iter().enumerate() {
                    let f = self.kernel.eval((p - c).norm());
                    d += f * Vector3::new(self.soa.g[0][j], self.soa.g[1][j], self.soa.g[2][j]);
                }
            }
        }
        p + d
    }

    fn deform(&self, points: &mut [Point3<f64>]) {
        // One point costs Nc kernel evaluations (global) or a tree query, so split finely.
        let chunk = if self.tree.is_some() { 256 } else { (1 << 16) / self.centres.len().max(1) }.clamp(16, 4096);
        if points.len() >= PARALLEL_MIN_POINTS.min(4 * chunk) {
            points.par_chunks_mut(chunk).for_each(|c| self.deform_serial(c));
        } else {
            self.deform_serial(points);
        }
    }

    /// `I + ∂s/∂x + Σᵢ γᵢ φ'(rᵢ) (x − x_Cᵢ)ᵀ / rᵢ`; `None` at a centre where the kernel has a
    /// corner (φ'(0) ≠ 0: `polyharmonic_spline` and `thin_plate_spline` with k = 1, `wendland_c0`).
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        let mut j = Matrix3::identity();
        for c in 0..3 {
            for a in 0..3 {
                j[(c, a)] += self.beta[c][a + 1] / self.scale;
            }
        }
        let nbs: Vec<(usize, f64)> = match self.neighbours(p) {
            Some(v) => v,
            None => self.centres.iter().enumerate().map(|(i, c)| (i, (p - c).norm())).collect(),
        };
        for (i, r) in nbs {
            if r == 0.0 {
                if self.kernel.smooth_at_centre() {
                    continue;
                }
                return None;
            }
            let u = (p - self.centres[i]) / r;
            let g = Vector3::new(self.soa.g[0][i], self.soa.g[1][i], self.soa.g[2][i]);
            j += self.kernel.deriv(r) * g * u.transpose();
        }
        Some(j)
    }
}

impl LinearInParameters for Rbf {
    /// `3 · Nc`: `[δx of all control points, δy, δz]`.
    fn n_params(&self) -> usize {
        3 * self.centres.len()
    }
    fn params(&self) -> Vec<f64> {
        (0..3).flat_map(|c| self.displacements.iter().map(move |d| d[c])).collect()
    }
    /// Re-solves with the stored factorisation: O(N²) dense, two triangular solves sparse.
    fn set_params(&mut self, theta: &[f64]) -> Result<()> {
        check_params(theta, self.n_params())?;
        let n = self.centres.len();
        for i in 0..n {
            self.displacements[i] = Vector3::new(theta[i], theta[n + i], theta[2 * n + i]);
        }
        self.solve_weights()
    }
    /// The cardinal weights at `p`: one solve with the stored factorisation per call.
    fn param_weights(&self, p: &Point3<f64>) -> ParamWeights {
        let n = self.centres.len();
        let mut rhs = Mat::<f64>::zeros(n + 4, 1);
        match self.neighbours(p) {
            Some(nbs) => {
                for (j, r) in nbs {
                    rhs[(j, 0)] = self.kernel.eval(r);
                }
            }
            None => {
                for (j, c) in self.centres.iter().enumerate() {
                    rhs[(j, 0)] = self.kernel.eval((p - c).norm());
                }
            }
        }
        let row = self.poly_row(p);
        for a in 0..4 {
            rhs[(n + a, 0)] = row[a];
        }
        // The system is symmetric, so Aᵀz = row(p) is the same solve.
        self.solve_kkt(&mut rhs);
        let weights = (0..n).map(|j| (j, rhs[(j, 0)])).filter(|&(_, w)| w != 0.0).collect();
        ParamWeights { n_nodes: n, weights, frame: Matrix3::identity() }
    }
}

/// The first pair of centres closer than `tol` (in the max norm), by a sweep over the
/// centres sorted along x: O(N log N) unless many centres share an x.
fn coincident_pair(centres: &[Point3<f64>], tol: f64) -> Option<(usize, usize)> {
    let mut order: Vec<usize> = (0..centres.len()).collect();
    order.sort_unstable_by(|&a, &b| centres[a].x.total_cmp(&centres[b].x));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if centres[b].x - centres[a].x > tol {
                break;
            }
            if (centres[b] - centres[a]).amax() <= tol {
                return Some((a.min(b), a.max(b)));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Solve `[Φ P; Pᵀ 0] x = b` with the given factorisation.
    fn solve(system: &System, b: &Mat<f64>) -> Mat<f64> {
        let mut x = b.clone();
        match system {
            System::Dense(lblt) => lblt.solve_in_place(x.as_mut()),
            System::Nullspace(ns) => ns.solve_in_place(&mut x),
            _ => unreachable!("dense systems only"),
        }
        x
    }

    #[test]
    fn nullspace_method_agrees_with_bunch_kaufman() {
        let mut state = 0x1234_5678_9ABC_DEF1u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let centres: Vec<Point3<f64>> = (0..150).map(|_| Point3::new(uniform(), uniform(), 3.0 * uniform())).collect();
        let moves: Vec<Vector3<f64>> = (0..150).map(|_| Vector3::new(uniform(), uniform(), uniform()) * 0.1).collect();
        // Positive definite, conditionally positive definite of order ≤ 2 (ZᵀΦZ positive
        // definite) and conditionally negative definite of order 1 (ZᵀΦZ negative definite).
        for kernel in [
            Kernel::ThinPlate { radius: 0.5, k: 2 },
            Kernel::Polyharmonic { radius: 1.0, k: 3 },
            Kernel::Polyharmonic { radius: 1.0, k: 1 },
            Kernel::MultiQuadratic { radius: 0.1 },
            Kernel::Gaussian { radius: 0.1 },
            Kernel::WendlandC2 { support: 0.8 },
        ] {
            let rbf = Rbf::try_new(&centres, &moves, kernel).unwrap();
            assert!(matches!(rbf.system, System::Nullspace(_)), "{kernel:?}: fell back");
            let (ns, cond_ns) = rbf.factor_nullspace().unwrap();
            let (kkt, cond_kkt) = rbf.factor_kkt().unwrap();
            let n = centres.len();
            let b = Mat::from_fn(n + 4, 2, |i, j| if i < n { uniform() - 0.5 } else { (j as f64) * uniform() });
            let (x, y) = (solve(&ns, &b), solve(&kkt, &b));
            let scale = (0..n + 4).map(|i| y[(i, 0)].abs().max(y[(i, 1)].abs())).fold(0.0, f64::max);
            for i in 0..n + 4 {
                for j in 0..2 {
                    let d = (x[(i, j)] - y[(i, j)]).abs();
                    assert!(d <= 1e-13 * cond_kkt * scale, "{kernel:?}: x[{i},{j}] {} vs {}", x[(i, j)], y[(i, j)]);
                }
            }
            // Both estimate the same condition number (estimates, so within a factor).
            assert!(cond_ns < 3.0 * cond_kkt && cond_kkt < 3.0 * cond_ns, "{kernel:?}: {cond_ns:e} vs {cond_kkt:e}");
        }
        // r⁴ ln r is conditionally definite of order 3 only: ZᵀΦZ is indefinite with a
        // linear term, so the build falls back to Bunch–Kaufman on the whole system.
        let rbf = Rbf::try_new(&centres, &moves, Kernel::Polyharmonic { radius: 1.0, k: 4 }).unwrap();
        assert!(matches!(rbf.system, System::Dense(_)));
        assert!(rbf.factor_nullspace().is_none());
    }
}
