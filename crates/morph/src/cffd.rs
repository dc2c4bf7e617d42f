//! Constrained FFD on point sets, as PyGeM's `CFFD`, `BFFD` and `VFFD` define it
//! (mathLab/PyGeM `pygem/cffd.py`, `bffd.py`, `vffd.py`), and its exact-nearest variant.
//!
//! A [`PointFunction`] `F(x)` of the deformed points is to take the value `c`. PyGeM's
//! `adjust_control_points` ([`pygem_adjust`]) corrects the lattice displacements one
//! axis at a time: with `Δ = c − F(φ(x))` at the start and `h[k, a]` the k-th row of the
//! axis mask normalised to sum 1 (PyGeM's `hyper_param`), for axis `a = x, y, z` it
//! moves only the free `μ_a` by the minimum-norm step `Aᵀ (A Aᵀ)⁻¹ (F + h[:, a] Δ − F)`,
//! where `A = ∂F/∂μ_a` over the constraints that depend on axis `a`. PyGeM finds `A` by
//! least squares on random samples; here it is the exact Jacobian, which is the same map
//! for functions affine in each axis's coordinates (linear maps, the barycentre, the
//! volume of a closed triangulation), so the results agree to rounding.
//!
//! [`nearest`] instead finds the displacements nearest to the user's (all axes at once)
//! with `F(φ(x)) = c` exactly, by Newton on the multipliers
//! ([`crate::constrained::nearest_nonlinear`]).

use nalgebra::{DMatrix, DVector, Point3};

use crate::constrained::{nearest_linear, nearest_nonlinear, Constrained, NewtonOptions};
use crate::{Deformation, Error, Ffd, LinearInParameters, Result};

/// A vector function of a point set whose value a constrained FFD fixes.
pub trait PointFunction: Sync {
    /// Number of values.
    fn len(&self) -> usize;
    /// Whether it has no values.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// `F(points)`.
    fn value(&self, points: &[Point3<f64>]) -> DVector<f64>;
    /// `∂F/∂x`: values × `3 · points` (x, y, z of each point in turn).
    fn jacobian(&self, points: &[Point3<f64>]) -> DMatrix<f64>;
    /// For each value, the coordinate axes it depends on (PyGeM's `fun_mask`).
    fn axes(&self) -> Vec<[bool; 3]>;
}

/// `F(x) = A · x.ravel()`: PyGeM's CFFD test constraint (`fun_mask` all true).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearFunction {
    /// `A`: values × `3 · points`.
    pub matrix: DMatrix<f64>,
}

impl PointFunction for LinearFunction {
    fn len(&self) -> usize {
        self.matrix.nrows()
    }
    fn value(&self, points: &[Point3<f64>]) -> DVector<f64> {
        let x = DVector::from_iterator(3 * points.len(), points.iter().flat_map(|p| [p.x, p.y, p.z]));
        &self.matrix * x
    }
    fn jacobian(&self, _points: &[Point3<f64>]) -> DMatrix<f64> {
        self.matrix.clone()
    }
    fn axes(&self) -> Vec<[bool; 3]> {
        vec![[true; 3]; self.len()]
    }
}

/// The mean of the points (PyGeM's BFFD): three values, each depending on its own axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Barycentre;

impl PointFunction for Barycentre {
    fn len(&self) -> usize {
        3
    }
    fn value(&self, points: &[Point3<f64>]) -> DVector<f64> {
        let n = points.len().max(1) as f64;
        let s = points.iter().fold(nalgebra::Vector3::zeros(), |a, p| a + p.coords);
        DVector::from_column_slice((s / n).as_slice())
    }
    fn jacobian(&self, points: &[Point3<f64>]) -> DMatrix<f64> {
        let n = points.len().max(1) as f64;
        let mut j = DMatrix::zeros(3, 3 * points.len());
        for p in 0..points.len() {
            for r in 0..3 {
                j[(r, 3 * p + r)] = 1.0 / n;
            }
        }
        j
    }
    fn axes(&self) -> Vec<[bool; 3]> {
        vec![[true, false, false], [false, true, false], [false, false, true]]
    }
}

/// PyGeM's VFFD volume of a closed triangulation: `Σ det[x_a; x_b; x_c]` over the
/// triangles, which is **six times** the enclosed volume (PyGeM's `_volume`, kept as it
/// is so that targets read the same).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TriangleVolume {
    /// Vertex indices of each triangle.
    pub triangles: Vec<[usize; 3]>,
}

impl TriangleVolume {
    /// The function, checking the indices against the number of points.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when an index is not below `n_points`.
    pub fn try_new(triangles: Vec<[usize; 3]>, n_points: usize) -> Result<Self> {
        if let Some(&bad) = triangles.iter().flatten().find(|&&i| i >= n_points) {
            return Err(Error::CountMismatch {
                line: 0,
                what: "triangle vertex index below the point count",
                expected: n_points,
                found: bad,
            });
        }
        Ok(TriangleVolume { triangles })
    }
}

impl PointFunction for TriangleVolume {
    fn len(&self) -> usize {
        1
    }
    fn value(&self, points: &[Point3<f64>]) -> DVector<f64> {
        let v: f64 = self
            .triangles
            .iter()
            .map(|t| points[t[0]].coords.dot(&points[t[1]].coords.cross(&points[t[2]].coords)))
            .sum();
        DVector::from_vec(vec![v])
    }
    fn jacobian(&self, points: &[Point3<f64>]) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(1, 3 * points.len());
        for t in &self.triangles {
            let (a, b, c) = (points[t[0]].coords, points[t[1]].coords, points[t[2]].coords);
            for (i, g) in [(t[0], b.cross(&c)), (t[1], c.cross(&a)), (t[2], a.cross(&b))] {
                for r in 0..3 {
                    j[(0, 3 * i + r)] += g[r];
                }
            }
        }
        j
    }
    fn axes(&self) -> Vec<[bool; 3]> {
        vec![[true; 3]]
    }
}

/// `∂F(φ(points))/∂θ`: values × [`Ffd::n_params`], at the current displacements.
pub fn param_jacobian(
    ffd: &Ffd,
    points: &[Point3<f64>],
    deformed: &[Point3<f64>],
    f: &dyn PointFunction,
) -> DMatrix<f64> {
    let jf = f.jacobian(deformed);
    let mut a = DMatrix::zeros(f.len(), ffd.n_params());
    for (p, x) in points.iter().enumerate() {
        let pw = ffd.param_weights(x);
        let n = pw.n_nodes;
        for &(j, w) in &pw.weights {
            for c in 0..3 {
                for r in 0..3 {
                    let coef = w * pw.frame[(r, c)];
                    if coef != 0.0 {
                        for k in 0..f.len() {
                            a[(k, c * n + j)] += jf[(k, 3 * p + r)] * coef;
                        }
                    }
                }
            }
        }
    }
    a
}

fn deformed(ffd: &Ffd, points: &[Point3<f64>]) -> Vec<Point3<f64>> {
    let mut out = points.to_vec();
    ffd.deform(&mut out);
    out
}

fn check(ffd: &Ffd, f: &dyn PointFunction, target: &[f64], free: Option<&[bool]>) -> Result<()> {
    if target.len() != f.len() {
        return Err(Error::CountMismatch {
            line: 0,
            what: "constraint values",
            expected: f.len(),
            found: target.len(),
        });
    }
    if let Some(m) = free {
        if m.len() != ffd.n_params() {
            return Err(Error::CountMismatch {
                line: 0,
                what: "mask entries",
                expected: ffd.n_params(),
                found: m.len(),
            });
        }
    }
    Ok(())
}

/// PyGeM's `CFFD.adjust_control_points(points)`: corrects `ffd`'s displacements axis by
/// axis so that `f(φ(points)) = target` (see the module docs). `free` (in
/// [`LinearInParameters`] layout; `None`: all free) is PyGeM's `ffd_mask`.
///
/// # Errors
///
/// [`Error::CountMismatch`] for mismatched sizes; [`Error::Infeasible`] when an axis's
/// free displacements cannot change the values that depend on it (all fixed, or `A Aᵀ`
/// singular, where PyGeM's `np.linalg.inv` fails).
pub fn pygem_adjust(
    ffd: &mut Ffd,
    points: &[Point3<f64>],
    f: &dyn PointFunction,
    target: &[f64],
    free: Option<&[bool]>,
) -> Result<()> {
    check(ffd, f, target, free)?;
    let n = ffd.n_params() / 3;
    let axes = f.axes();
    let hyper: Vec<[f64; 3]> = axes
        .iter()
        .map(|a| {
            let s = a.iter().filter(|&&b| b).count().max(1) as f64;
            a.map(|b| if b { 1.0 / s } else { 0.0 })
        })
        .collect();
    let start = f.value(&deformed(ffd, points));
    let diff: Vec<f64> = (0..f.len()).map(|k| target[k] - start[k]).collect();
    for axis in 0..3 {
        let cols: Vec<usize> = (axis * n..(axis + 1) * n).filter(|&i| free.is_none_or(|m| m[i])).collect();
        let rows: Vec<usize> = (0..f.len()).filter(|&k| axes[k][axis]).collect();
        if rows.is_empty() {
            continue;
        }
        let now = deformed(ffd, points);
        let full = param_jacobian(ffd, points, &now, f);
        let a = DMatrix::from_fn(rows.len(), cols.len(), |r, c| full[(rows[r], cols[c])]);
        let mut theta = ffd.params();
        let sub: Vec<f64> = cols.iter().map(|&i| theta[i]).collect();
        let a_sub = &a * DVector::from_column_slice(&sub);
        let b = DVector::from_fn(rows.len(), |r, _| a_sub[r] + hyper[rows[r]][axis] * diff[rows[r]]);
        let solved = nearest_linear(&sub, &a, &b, &vec![1.0; cols.len()]).map_err(|e| match e {
            Error::Infeasible(why) => Error::Infeasible(format!("axis {}: {why}", ["x", "y", "z"][axis])),
            other => other,
        })?;
        for (k, &i) in cols.iter().enumerate() {
            theta[i] = solved[k];
        }
        ffd.set_params(&theta)?;
    }
    Ok(())
}

/// The displacements nearest to `ffd`'s (metric `diag(metric)`, `0` = fixed, in
/// [`LinearInParameters`] layout) with `f(φ(points)) = target` exactly, set on `ffd`.
/// `tol` is relative to `max(|target|, 1)` per value.
///
/// # Errors
///
/// As [`pygem_adjust`], and [`Error::Infeasible`] when Newton does not converge.
pub fn nearest(
    ffd: &mut Ffd,
    points: &[Point3<f64>],
    f: &dyn PointFunction,
    target: &[f64],
    metric: &[f64],
    opts: NewtonOptions,
) -> Result<Constrained> {
    check(ffd, f, target, None)?;
    let scale: Vec<f64> = target.iter().map(|t| t.abs().max(1.0)).collect();
    let mut work = ffd.clone();
    let out = nearest_nonlinear(&ffd.params(), metric, &scale, opts, |theta| {
        work.set_params(theta)?;
        let now = deformed(&work, points);
        let v = f.value(&now) - DVector::from_column_slice(target);
        Ok((v, param_jacobian(&work, points, &now, f)))
    })?;
    ffd.set_params(&out.theta)?;
    Ok(out)
}
