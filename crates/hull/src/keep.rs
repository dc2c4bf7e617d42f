//! FFD of a closed CAD model that keeps its enclosed volume and/or its barycentre (the
//! paper's closing remarks: fixed-volume FFD), with the lattice displacements nearest to
//! the user's.
//!
//! The model's morph moves every face control point once, `P_k(μ) = P_k + J_k μ` with
//! `J_k = ∂φ(P_k)/∂μ` ([`LinearInParameters::param_weights`]), so the volume `V(μ)` and
//! moments `M(μ)` of the morphed faces are exact polynomials of `μ` that
//! [`crate::volume`] evaluates exactly, with gradients
//! `∂V/∂μ = Σ_k (∫ R_k n dA)ᵀ J_k`, `∂M_a/∂μ = Σ_k (∫ x_a R_k n dA)ᵀ J_k`. The
//! constraints `V(μ) = V₀` and `M(μ) − c₀ V(μ) = 0` are met by Newton on the multipliers
//! ([`cadmorph_morph::constrained::nearest_nonlinear`]) to `1e-13` relative.
//!
//! Trimmed planar faces (a transom, a deck) keep their share only if the lattice leaves
//! them and their bounding curves alone; a morph that would move one is refused
//! ([`Error::MovesTrimmedFace`]).

use cadmorph_brep::{BoundCurve, Face};
use cadmorph_morph::constrained::{nearest_nonlinear, NewtonOptions};
use cadmorph_morph::{Deformation, Ffd, LinearInParameters};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::volume::{bounds_by_face, enclosed, natural_gradients, natural_moments, FaceMethod, Moments};
use crate::{Error, Result};

/// What to keep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Keep {
    /// The enclosed volume.
    pub volume: bool,
    /// The centroid of the enclosed volume.
    pub barycentre: bool,
    /// With `volume`: the volume to reach, as a multiple of the present one (`1`: keep
    /// it; `0` counts as `1`).
    pub volume_factor: f64,
}

/// What [`keep`] did.
#[derive(Debug, Clone, Serialize)]
pub struct KeepReport {
    /// Volume and moments before the morph.
    pub before: Moments,
    /// Volume and moments the user's displacements would give.
    pub unconstrained: Moments,
    /// Volume and moments of the constrained morph (computed from the moved faces).
    pub after: Moments,
    /// `|μ − μ_user|` (Euclidean, in box-length units).
    pub change: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// One face's share as a function of the lattice displacements.
struct Moving {
    face: usize,
    sign: f64,
    /// `J_k` of every control point, as (node, weight) pairs and the frame.
    weights: Vec<cadmorph_morph::ParamWeights>,
}

/// The lattice displacements nearest to `ffd`'s that keep what `what` asks, given the
/// faces and bounding curves of a closed model (the model's
/// [`patches`](cadmorph_model::Model::patches) and
/// [`bound_curves`](cadmorph_model::Model::bound_curves), `size` its
/// [`size`](cadmorph_model::Model::size)). `free` (in [`LinearInParameters`] layout,
/// `None`: all) says which displacements may change. Returns the constrained FFD.
///
/// # Errors
///
/// Those of [`enclosed`]; [`Error::MovesTrimmedFace`]; [`Error::Constraint`] with
/// [`cadmorph_morph::Error::Infeasible`] when the free lattice points cannot keep the
/// quantities (all fixed, none inside a moving face, a change out of reach).
pub fn keep(
    faces: &[Face],
    bounds: &[BoundCurve],
    size: f64,
    ffd: &Ffd,
    what: Keep,
    free: Option<&[bool]>,
) -> Result<(Ffd, KeepReport)> {
    let base = enclosed(faces, bounds, size)?;
    let by_face = bounds_by_face(faces.len(), bounds);
    let mut fixed = Moments::ZERO;
    let mut moving = Vec::new();
    for (i, face) in faces.iter().enumerate() {
        let inside = |p: &nalgebra::Point3<f64>| !ffd.param_weights(p).weights.is_empty();
        match base.methods[i] {
            // Trimmed faces keep their share only while the FFD leaves them alone.
            FaceMethod::Planar | FaceMethod::Trimmed | FaceMethod::Rectangle(_) | FaceMethod::Reseamed { .. } => {
                let touched = face.surface.control_points().iter().any(inside)
                    || by_face[i].iter().any(|b| b.curve.control_points().iter().any(inside));
                if touched {
                    return Err(Error::MovesTrimmedFace { face: face.entity });
                }
                fixed.volume += base.faces[i].volume;
                for k in 0..3 {
                    fixed.moment[k] += base.faces[i].moment[k];
                }
            }
            FaceMethod::Natural => {
                let weights: Vec<_> = face.surface.control_points().iter().map(|p| ffd.param_weights(p)).collect();
                if weights.iter().all(|w| w.weights.is_empty()) {
                    fixed.volume += base.faces[i].volume;
                    for k in 0..3 {
                        fixed.moment[k] += base.faces[i].moment[k];
                    }
                } else {
                    moving.push(Moving { face: i, sign: base.signs[i], weights });
                }
            }
        }
    }
    let n = ffd.n_params();
    let metric: Vec<f64> = match free {
        Some(m) if m.len() != n => {
            return Err(Error::Invalid(format!("the mask has {} entries, the lattice {n} displacements", m.len())));
        }
        Some(m) => m.iter().map(|&f| if f { 1.0 } else { 0.0 }).collect(),
        None => vec![1.0; n],
    };
    let factor = if what.volume_factor == 0.0 { 1.0 } else { what.volume_factor };
    if !(factor.is_finite() && factor > 0.0) {
        return Err(Error::Invalid(format!("the volume factor must be positive and finite, not {factor}")));
    }
    let v0 = base.total.volume * factor;
    let c0 = base.total.centroid();
    let mut rows = Vec::new();
    if what.volume {
        rows.push(None);
    }
    if what.barycentre {
        rows.extend([Some(0), Some(1), Some(2)]);
    }
    if rows.is_empty() {
        return Err(Error::Invalid("nothing to keep: ask for the volume, the barycentre or both".into()));
    }
    let scale: Vec<f64> = rows.iter().map(|r| if r.is_some() { v0 * size } else { v0 }).collect();
    let mut work = ffd.clone();
    // Volume, moments and their gradients at displacements θ.
    let mut eval = |theta: &[f64], grads: bool| -> Result<(Moments, [DVector<f64>; 4])> {
        work.set_params(theta)?;
        let mut total = fixed;
        let mut g = [DVector::zeros(n), DVector::zeros(n), DVector::zeros(n), DVector::zeros(n)];
        for mv in &moving {
            let mut s = faces[mv.face].surface.clone();
            for q in s.control_points_mut() {
                *q = work.deform_point(q);
            }
            let m = natural_moments(&s, mv.sign);
            total.volume += m.volume;
            for k in 0..3 {
                total.moment[k] += m.moment[k];
            }
            if grads {
                let gk = natural_gradients(&s, mv.sign);
                for (w, gj) in mv.weights.iter().zip(&gk) {
                    for &(node, wt) in &w.weights {
                        for c in 0..3 {
                            let col = w.frame.column(c);
                            for (a, ga) in gj.iter().enumerate() {
                                g[a][c * w.n_nodes + node] += wt * ga.dot(&col);
                            }
                        }
                    }
                }
            }
        }
        Ok((total, g))
    };
    let user = ffd.params();
    let (unconstrained, _) = eval(&user, false)?;
    let out = nearest_nonlinear(&user, &metric, &scale, NewtonOptions::default(), |theta| {
        let (m, g) = eval(theta, true).map_err(|e| match e {
            Error::Constraint(c) => c,
            other => cadmorph_morph::Error::Infeasible(other.to_string()),
        })?;
        let mut c = DVector::zeros(rows.len());
        let mut j = DMatrix::zeros(rows.len(), n);
        for (r, row) in rows.iter().enumerate() {
            match row {
                None => {
                    c[r] = m.volume - v0;
                    j.row_mut(r).copy_from(&g[0].transpose());
                }
                Some(a) => {
                    c[r] = m.moment[*a] - c0[*a] * m.volume;
                    j.row_mut(r).copy_from(&(&g[a + 1] - &g[0] * c0[*a]).transpose());
                }
            }
        }
        Ok((c, j))
    })?;
    let (after, _) = eval(&out.theta, false)?;
    let mut result = ffd.clone();
    result.set_params(&out.theta)?;
    // A constraint met only by folding the lattice is out of reach: the morph would
    // turn faces inside out.
    for mv in &moving {
        for (k, p) in faces[mv.face].surface.control_points().iter().enumerate() {
            if let Some(j) = result.jacobian(p) {
                let det = j.determinant();
                if det.is_nan() || det <= 0.0 {
                    return Err(cadmorph_morph::Error::Infeasible(format!(
                        "the constrained lattice folds (Jacobian determinant {det:.3e} at control point {k} of face {}): the asked volume or barycentre is out of the free lattice points' reach",
                        faces[mv.face].entity
                    ))
                    .into());
                }
            }
        }
    }
    let change = out.theta.iter().zip(&user).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
    Ok((result, KeepReport { before: base.total, unconstrained, after, change, iterations: out.iterations }))
}
