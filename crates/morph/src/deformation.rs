//! The [`Deformation`] trait, composition ([`Then`]) and the parameter Jacobian of maps that
//! are linear in their parameters ([`LinearInParameters`]).

use nalgebra::{DMatrix, Matrix3, Point3};
use rayon::prelude::*;

/// Slices at least this long are deformed in parallel (rayon) by the default
/// [`Deformation::deform`]; shorter ones run on the calling thread, where spawning would cost
/// more than it saves.
pub const PARALLEL_MIN_POINTS: usize = 4096;

/// Number of points one rayon task handles in the parallel paths.
pub const PARALLEL_CHUNK: usize = 2048;

/// The hook of [`Deformation::deform_chunks`]: `(index of the chunk's first point, chunk) →
/// deform it?`, called from rayon's threads.
pub type ChunkHook<'a> = dyn Fn(usize, &mut [Point3<f64>]) -> bool + Sync + 'a;

/// The chunking of [`Deformation::deform_chunks`]: `before(start, chunk)` then, if it
/// returns `true`, `deform(chunk)`, on one chunk below [`PARALLEL_MIN_POINTS`] points, else
/// on [`PARALLEL_CHUNK`]-point chunks in parallel. For implementations of `deform_chunks`
/// that deform each chunk their own way (with set-up done once per call).
pub fn for_each_chunk(points: &mut [Point3<f64>], before: &ChunkHook<'_>, deform: impl Fn(&mut [Point3<f64>]) + Sync) {
    if points.len() >= PARALLEL_MIN_POINTS {
        points.par_chunks_mut(PARALLEL_CHUNK).enumerate().for_each(|(i, chunk)| {
            if before(i * PARALLEL_CHUNK, chunk) {
                deform(chunk);
            }
        });
    } else if before(0, points) {
        deform(points);
    }
}

/// The index of the first point of `points` with a non-finite coordinate: a branch-free
/// pass (`x · 0` is 0 exactly for finite `x`, NaN otherwise) that the compiler vectorises,
/// then a search only when it found one.
pub fn first_non_finite(points: &[Point3<f64>]) -> Option<usize> {
    let flat: &[f64] = bytemuck::cast_slice(points);
    let mut acc = [0.0f64; 8];
    let mut blocks = flat.chunks_exact(8);
    for b in &mut blocks {
        for k in 0..8 {
            acc[k] += b[k] * 0.0;
        }
    }
    for (k, v) in blocks.remainder().iter().enumerate() {
        acc[k] += v * 0.0;
    }
    if acc.iter().all(|a| *a == 0.0) {
        return None;
    }
    points.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
}

/// The default [`Deformation::deform_checked`]: each chunk of
/// [`Deformation::deform_chunks`] checked with [`first_non_finite`] just before it is
/// deformed, the chunks holding a non-finite point left as they are. For implementations
/// (and dispatchers) that override `deform_checked` for some cases only.
pub fn checked_by_chunks<D: Deformation + ?Sized>(d: &D, points: &mut [Point3<f64>]) -> Result<(), usize> {
    let first = std::sync::atomic::AtomicUsize::new(usize::MAX);
    d.deform_chunks(points, &|start, chunk| match first_non_finite(chunk) {
        Some(i) => {
            first.fetch_min(start + i, std::sync::atomic::Ordering::Relaxed);
            false
        }
        None => true,
    });
    match first.into_inner() {
        usize::MAX => Ok(()),
        i => Err(i),
    }
}

/// A map φ: ℝ³ → ℝ³ applied to points (control points, mesh nodes).
///
/// Building a deformation may fail (a singular RBF system, a malformed parameter file);
/// applying one never does.
///
/// Identities every implementation keeps:
/// - `d.deform(&mut pts)` leaves `pts[i] == d.deform_point(&old[i])` (to rounding, batched
///   versions may sum in another order);
/// - with zero displacements (FFD μ = 0, RBF/IDW deformed = original) φ is the identity;
/// - `a.then(b).deform_point(p) == b.deform_point(&a.deform_point(p))`.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Affine, Deformation};
/// use cadmorph_morph::math::{Point3, Vector3};
/// let shift = Affine::translation(Vector3::new(1.0, 0.0, 0.0));
/// let scale = Affine::scaling(Vector3::new(2.0, 2.0, 2.0));
/// let both = shift.then(scale); // first shift, then scale
/// assert_eq!(both.deform_point(&Point3::new(1.0, 1.0, 1.0)), Point3::new(4.0, 2.0, 2.0));
/// ```
pub trait Deformation: Sync {
    /// φ(p).
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64>;

    /// φ applied in place. The default maps each point with [`Deformation::deform_point`],
    /// in parallel once the slice holds [`PARALLEL_MIN_POINTS`] points or more.
    fn deform(&self, points: &mut [Point3<f64>]) {
        if points.len() >= PARALLEL_MIN_POINTS {
            points.par_chunks_mut(PARALLEL_CHUNK).for_each(|chunk| {
                for p in chunk {
                    *p = self.deform_point(p);
                }
            });
        } else {
            for p in points {
                *p = self.deform_point(p);
            }
        }
    }

    /// φ applied in place chunk by chunk, with `before(start, chunk)` called on each chunk
    /// (`start` is the index of its first point) just before the chunk is deformed: a chunk
    /// for which it returns `false` is not deformed. The chunks are those of
    /// [`Deformation::deform`] (one chunk below [`PARALLEL_MIN_POINTS`] points, else
    /// [`PARALLEL_CHUNK`]-point chunks in parallel), so a caller can fuse its own pass over
    /// the points (a copy in, a check for non-finite values) with the morph while each chunk
    /// is in cache. Implementations with per-call set-up (the FFD's power form) do it once.
    fn deform_chunks(&self, points: &mut [Point3<f64>], before: &ChunkHook<'_>) {
        for_each_chunk(points, before, |chunk| self.deform(chunk));
    }

    /// φ applied in place, reporting the first point with a non-finite coordinate (NaN or
    /// ±∞) as `Err(index)`. Such points are left as they are; of the others, the FFD
    /// deforms them all (its check is fused into its kernel, so costs nothing measurable),
    /// this default leaves the chunks of [`Deformation::deform_chunks`] that hold one
    /// unmoved (each chunk is checked just before it is deformed) and moves the rest.
    fn deform_checked(&self, points: &mut [Point3<f64>]) -> Result<(), usize> {
        checked_by_chunks(self, points)
    }

    /// The deformed copy of `points` (the copy twin of [`Deformation::deform`]).
    fn deformed(&self, points: &[Point3<f64>]) -> Vec<Point3<f64>> {
        let mut out = points.to_vec();
        self.deform(&mut out);
        out
    }

    /// ∂φ/∂x at `p` (row i, column j: ∂φᵢ/∂xⱼ) when it exists in closed form; `None` where
    /// φ is not differentiable at `p` (for instance an RBF with a kernel that has a corner at
    /// a centre) or the implementation does not know it.
    fn jacobian(&self, _p: &Point3<f64>) -> Option<Matrix3<f64>> {
        None
    }

    /// Composition: first `self`, then `next` (like [`Iterator::chain`], the receiver goes first).
    fn then<D: Deformation>(self, next: D) -> Then<Self, D>
    where
        Self: Sized,
    {
        Then { first: self, second: next }
    }
}

impl<D: Deformation + ?Sized> Deformation for &D {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        (**self).deform_point(p)
    }
    fn deform(&self, points: &mut [Point3<f64>]) {
        (**self).deform(points)
    }
    fn deform_chunks(&self, points: &mut [Point3<f64>], before: &ChunkHook<'_>) {
        (**self).deform_chunks(points, before)
    }
    fn deform_checked(&self, points: &mut [Point3<f64>]) -> Result<(), usize> {
        (**self).deform_checked(points)
    }
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        (**self).jacobian(p)
    }
}

impl<D: Deformation + ?Sized + Send> Deformation for Box<D> {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        (**self).deform_point(p)
    }
    fn deform(&self, points: &mut [Point3<f64>]) {
        (**self).deform(points)
    }
    fn deform_chunks(&self, points: &mut [Point3<f64>], before: &ChunkHook<'_>) {
        (**self).deform_chunks(points, before)
    }
    fn deform_checked(&self, points: &mut [Point3<f64>]) -> Result<(), usize> {
        (**self).deform_checked(points)
    }
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        (**self).jacobian(p)
    }
}

/// `first` followed by `second`; made by [`Deformation::then`].
///
/// The Jacobian follows the chain rule, `J(p) = J₂(φ₁(p)) · J₁(p)`, and is `None` when
/// either factor is.
#[derive(Debug, Clone)]
pub struct Then<A, B> {
    /// Applied first.
    pub first: A,
    /// Applied to the output of `first`.
    pub second: B,
}

impl<A: Deformation, B: Deformation> Deformation for Then<A, B> {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        self.second.deform_point(&self.first.deform_point(p))
    }
    fn deform(&self, points: &mut [Point3<f64>]) {
        // Keep each stage's batched (parallel, vectorised) implementation.
        self.first.deform(points);
        self.second.deform(points);
    }
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        let j1 = self.first.jacobian(p)?;
        let j2 = self.second.jacobian(&self.first.deform_point(p))?;
        Some(j2 * j1)
    }
}

/// ∂φ(p)/∂θ of a map that is linear in its parameters θ, in compact form.
///
/// The parameters come in three blocks of `n_nodes` (the x parameters of all nodes, then
/// the y, then the z ones: `θ[c · n_nodes + j]`), and
///
/// ```text
/// ∂φ(p)/∂θ[c·n + j] = w_j(p) · frame[:, c]
/// ```
///
/// where `(j, w_j)` are the `weights` (nodes not listed have weight 0).
/// For an FFD the nodes are the lattice points, `w` the Bernstein products and `frame`
/// the box axes scaled by the box lengths; for RBF and IDW the nodes are the control
/// points, `w` their cardinal weights and `frame` the identity.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamWeights {
    /// Number of nodes (a third of the number of parameters).
    pub n_nodes: usize,
    /// `(node, weight)` pairs.
    pub weights: Vec<(usize, f64)>,
    /// How a unit parameter of each component moves the point.
    pub frame: Matrix3<f64>,
}

impl ParamWeights {
    /// The dense 3 × 3n Jacobian `∂φ(p)/∂θ`.
    pub fn to_dense(&self) -> DMatrix<f64> {
        let n = self.n_nodes;
        let mut m = DMatrix::zeros(3, 3 * n);
        for &(j, w) in &self.weights {
            for c in 0..3 {
                for r in 0..3 {
                    m[(r, c * n + j)] += w * self.frame[(r, c)];
                }
            }
        }
        m
    }
}

/// A deformation that is linear in its parameters θ (FFD lattice displacements, RBF and IDW
/// control-point displacements), so that `∂φ(p)/∂θ` does not depend on θ: the Jacobian
/// that gradient-based shape optimisation needs.
///
/// Parameter layout: see [`ParamWeights`] (`θ[c · n_nodes + j]`, component-major).
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Ffd, LinearInParameters};
/// use cadmorph_morph::math::Point3;
/// let mut ffd = Ffd::unit([2, 2, 2]);
/// let p = Point3::new(0.3, 0.4, 0.5);
/// let jac = ffd.param_jacobian(&p);
/// // φ(p) = p + J θ exactly, for any θ:
/// let theta: Vec<f64> = (0..ffd.n_params()).map(|i| 0.01 * i as f64).collect();
/// ffd.set_params(&theta).unwrap();
/// let moved = p.coords + &jac * nalgebra::DVector::from_vec(theta);
/// assert!((ffd.deform_point(&p).coords - moved).norm() < 1e-14);
/// ```
pub trait LinearInParameters: Deformation {
    /// Number of parameters (three per node).
    fn n_params(&self) -> usize;

    /// The current parameters θ.
    fn params(&self) -> Vec<f64>;

    /// Replace the parameters θ (for RBF this re-solves with the stored factorisation).
    ///
    /// # Errors
    ///
    /// [`crate::Error::CountMismatch`] when `theta.len() != self.n_params()`,
    /// [`crate::Error::InvalidParameter`] for a non-finite value.
    fn set_params(&mut self, theta: &[f64]) -> crate::Result<()>;

    /// `∂φ(p)/∂θ` in compact form.
    fn param_weights(&self, p: &Point3<f64>) -> ParamWeights;

    /// The dense 3 × [`n_params`](LinearInParameters::n_params) Jacobian `∂φ(p)/∂θ`.
    fn param_jacobian(&self, p: &Point3<f64>) -> DMatrix<f64> {
        self.param_weights(p).to_dense()
    }
}

/// Checks a new parameter vector: length and finiteness.
pub(crate) fn check_params(theta: &[f64], expected: usize) -> crate::Result<()> {
    if theta.len() != expected {
        return Err(crate::Error::CountMismatch { line: 0, what: "parameters", expected, found: theta.len() });
    }
    if let Some(&v) = theta.iter().find(|v| !v.is_finite()) {
        return Err(crate::Error::InvalidParameter {
            line: None,
            name: "parameter",
            value: v,
            reason: "must be finite",
        });
    }
    Ok(())
}

/// The displacements `deformed − original` of parameter files' control points.
///
/// # Errors
///
/// [`Error::CountMismatch`](crate::Error::CountMismatch) when the two lists differ in length.
pub(crate) fn displacements(
    original: &[Point3<f64>],
    deformed: &[Point3<f64>],
) -> crate::Result<Vec<nalgebra::Vector3<f64>>> {
    if original.len() != deformed.len() {
        return Err(crate::Error::CountMismatch {
            line: 0,
            what: "deformed control points",
            expected: original.len(),
            found: deformed.len(),
        });
    }
    Ok(original.iter().zip(deformed).map(|(a, b)| b - a).collect())
}
