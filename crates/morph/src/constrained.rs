//! Constrained morphs: the parameters nearest to the user's that meet constraints.
//!
//! Given the user's parameters θᵤ (FFD lattice displacements, in [`LinearInParameters`](crate::LinearInParameters)
//! layout) and a diagonal metric `M` (`M_ii = 0`: parameter `i` is fixed; `M = I`: plain
//! least squares), the constrained parameters solve
//!
//! ```text
//! min ½ (θ − θᵤ)ᵀ M⁻¹ (θ − θᵤ)   subject to   c(θ) = 0
//! ```
//!
//! * linear constraints `A θ = b` ([`nearest_linear`]): `θ = θᵤ + M Aᵀ λ`,
//!   `(A M Aᵀ) λ = b − A θᵤ` (weighted minimum-norm correction);
//! * nonlinear constraints ([`nearest_nonlinear`], enclosed volume, barycentre): Newton on
//!   the multipliers (SQP with the constraint linearised at the current iterate):
//!   `θₙ₊₁ = θᵤ + M Jₙᵀ λ`, `(Jₙ M Jₙᵀ) λ = −c(θₙ) − Jₙ (θᵤ − θₙ)`.
//!
//! Point-set constraints (PyGeM's CFFD, BFFD, VFFD) are in [`crate::cffd`].

use nalgebra::{DMatrix, DVector};

use crate::{Error, Result};

/// Relative size of a singular value below which `A M Aᵀ` counts as singular.
const RANK_TOL: f64 = 1e-12;

/// Solves `(A M Aᵀ) λ = r`, or explains why the constraints cannot be met.
fn multipliers(a: &DMatrix<f64>, metric: &[f64], r: &DVector<f64>, what: &str) -> Result<DVector<f64>> {
    let mut am = a.clone();
    for (j, &m) in metric.iter().enumerate() {
        am.column_mut(j).scale_mut(m);
    }
    let g = &am * a.transpose();
    if a.nrows() == 0 {
        return Ok(DVector::zeros(0));
    }
    if metric.iter().all(|&m| m == 0.0) {
        return Err(Error::Infeasible(format!(
            "every displacement is fixed: no free lattice point can change the {what}"
        )));
    }
    let svd = g.clone().svd(true, true);
    let smax = svd.singular_values.max();
    if smax == 0.0 || !smax.is_finite() {
        return Err(Error::Infeasible(format!("no free lattice displacement changes the {what}")));
    }
    let smin = svd.singular_values.min();
    if smin <= RANK_TOL * smax {
        return Err(Error::Infeasible(format!(
            "the free lattice displacements cannot change the {what} independently (constraint matrix of rank below {}; singular values {:.3e} .. {:.3e})",
            a.nrows(),
            smin,
            smax
        )));
    }
    svd.solve(r, 0.0).map_err(|e| Error::Infeasible(e.to_string()))
}

fn check_metric(n: usize, metric: &[f64]) -> Result<()> {
    if metric.len() != n {
        return Err(Error::CountMismatch { line: 0, what: "metric entries", expected: n, found: metric.len() });
    }
    if let Some(&m) = metric.iter().find(|m| !(m.is_finite() && **m >= 0.0)) {
        return Err(Error::InvalidParameter {
            line: None,
            name: "metric",
            value: m,
            reason: "must be finite and non-negative",
        });
    }
    Ok(())
}

/// The parameters nearest to `theta` in the metric `M = diag(metric)` with `A θ = b`.
///
/// # Errors
///
/// [`Error::CountMismatch`] for mismatched sizes, [`Error::Infeasible`] when the free
/// parameters cannot meet the constraints (all fixed, dependent rows).
///
/// # Examples
///
/// ```
/// use cadmorph_morph::constrained::nearest_linear;
/// use nalgebra::{DMatrix, DVector};
/// // Keep θ0 + θ1 = 1, θ2 fixed: the nearest point to (0, 0, 5).
/// let a = DMatrix::from_row_slice(1, 3, &[1.0, 1.0, 1.0]);
/// let th = nearest_linear(&[0.0, 0.0, 5.0], &a, &DVector::from_vec(vec![6.0]), &[1.0, 1.0, 0.0]).unwrap();
/// assert_eq!(th, vec![0.5, 0.5, 5.0]);
/// ```
pub fn nearest_linear(theta: &[f64], a: &DMatrix<f64>, b: &DVector<f64>, metric: &[f64]) -> Result<Vec<f64>> {
    let n = theta.len();
    check_metric(n, metric)?;
    if a.ncols() != n {
        return Err(Error::CountMismatch { line: 0, what: "constraint columns", expected: n, found: a.ncols() });
    }
    if b.len() != a.nrows() {
        return Err(Error::CountMismatch { line: 0, what: "constraint values", expected: a.nrows(), found: b.len() });
    }
    let t = DVector::from_column_slice(theta);
    let r = b - a * &t;
    let lambda = multipliers(a, metric, &r, "constrained quantities")?;
    let step = a.transpose() * lambda;
    Ok((0..n).map(|i| theta[i] + metric[i] * step[i]).collect())
}

/// Settings of [`nearest_nonlinear`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Stop when every `|c_i(θ)| ≤ tol_i` (absolute, per constraint; see `scale`).
    pub tol: f64,
    /// Iteration limit.
    pub max_iter: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions { tol: 1e-13, max_iter: 30 }
    }
}

/// What [`nearest_nonlinear`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Constrained {
    /// The constrained parameters.
    pub theta: Vec<f64>,
    /// Newton iterations taken.
    pub iterations: usize,
    /// `max_i |c_i(θ)| / scale_i` at the end.
    pub residual: f64,
}

/// The parameters nearest to `theta` (metric `diag(metric)`) with `c(θ) = 0`, by Newton
/// on the multipliers. `constraint(θ)` returns `c(θ)` and its Jacobian `∂c/∂θ`
/// (constraints × parameters); `scale[i]` is the size of constraint `i` that the
/// tolerance is relative to (a volume, a length times a volume).
///
/// # Errors
///
/// [`Error::Infeasible`] when the free parameters cannot change the constraints, or the
/// iteration does not reach `tol` (a change out of the lattice's reach); the callback's
/// errors.
pub fn nearest_nonlinear(
    theta: &[f64],
    metric: &[f64],
    scale: &[f64],
    opts: NewtonOptions,
    mut constraint: impl FnMut(&[f64]) -> Result<(DVector<f64>, DMatrix<f64>)>,
) -> Result<Constrained> {
    let n = theta.len();
    check_metric(n, metric)?;
    let user = DVector::from_column_slice(theta);
    let mut current = user.clone();
    let mut best = f64::INFINITY;
    for it in 0..=opts.max_iter {
        let (c, j) = constraint(current.as_slice())?;
        if j.ncols() != n || j.nrows() != c.len() || scale.len() != c.len() {
            return Err(Error::CountMismatch {
                line: 0,
                what: "constraint Jacobian columns",
                expected: n,
                found: j.ncols(),
            });
        }
        let residual = c.iter().zip(scale).map(|(ci, s)| ci.abs() / s).fold(0.0, f64::max);
        if !residual.is_finite() {
            return Err(Error::Infeasible(format!("the constraint is not finite after {it} Newton steps")));
        }
        if residual <= opts.tol {
            return Ok(Constrained { theta: current.as_slice().to_vec(), iterations: it, residual });
        }
        if it == opts.max_iter {
            return Err(Error::Infeasible(format!(
                "Newton on the multipliers did not converge in {} steps (relative residual {residual:.3e}, best {best:.3e}): the asked change is out of the free lattice displacements' reach",
                opts.max_iter
            )));
        }
        best = best.min(residual);
        let r = -&c - &j * (&user - &current);
        let lambda = multipliers(&j, metric, &r, "constrained quantities")?;
        let step = j.transpose() * lambda;
        for i in 0..n {
            current[i] = user[i] + metric[i] * step[i];
        }
    }
    unreachable!("the loop returns at it == max_iter")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_solution_is_the_weighted_projection() {
        // min (θ0² + θ1²/4) with θ0 + θ1 = 1 (metric 1, 4): θ = (1/5, 4/5).
        let a = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
        let th = nearest_linear(&[0.0, 0.0], &a, &DVector::from_vec(vec![1.0]), &[1.0, 4.0]).unwrap();
        assert!((th[0] - 0.2).abs() < 1e-15 && (th[1] - 0.8).abs() < 1e-15);
    }

    #[test]
    fn all_fixed_and_dependent_rows_are_refused() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 2.0, 2.0]);
        let b = DVector::from_vec(vec![1.0, 3.0]);
        let e = nearest_linear(&[0.0, 0.0], &a, &b, &[0.0, 0.0]).unwrap_err();
        assert!(e.to_string().contains("every displacement is fixed"), "{e}");
        let e = nearest_linear(&[0.0, 0.0], &a, &b, &[1.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("rank"), "{e}");
    }

    #[test]
    fn nonlinear_finds_the_nearest_point_on_a_sphere() {
        // Nearest point to (3, 4) on the circle |θ| = 1 is (0.6, 0.8).
        let out = nearest_nonlinear(&[3.0, 4.0], &[1.0, 1.0], &[1.0], NewtonOptions::default(), |t| {
            Ok((
                DVector::from_vec(vec![t[0] * t[0] + t[1] * t[1] - 1.0]),
                DMatrix::from_row_slice(1, 2, &[2.0 * t[0], 2.0 * t[1]]),
            ))
        })
        .unwrap();
        assert!((out.theta[0] - 0.6).abs() < 1e-12 && (out.theta[1] - 0.8).abs() < 1e-12, "{out:?}");
    }

    #[test]
    fn unreachable_targets_fail() {
        // θ0² = −1 has no solution.
        let e = nearest_nonlinear(&[1.0], &[1.0], &[1.0], NewtonOptions::default(), |t| {
            Ok((DVector::from_vec(vec![t[0] * t[0] + 1.0]), DMatrix::from_row_slice(1, 1, &[2.0 * t[0]])))
        })
        .unwrap_err();
        assert!(matches!(e, Error::Infeasible(_)), "{e}");
    }
}
