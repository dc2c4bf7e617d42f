//! Refinement that keeps seams closed under a deformation (paper §3.1.2).
//!
//! Moving the control points of a patch with a map `M` gives the surface `S'`, which is
//! not `M ∘ S` unless `M` is affine: between the control points the morph bends space
//! in ways the coarse net cannot follow. Two patches that met exactly before the morph
//! then open up wherever `|M(S(u, v)) − S'(u, v)|` differs along their common edge.
//! Inserting knots leaves `S` unchanged and adds control points, so `S'` follows
//! `M ∘ S` more closely; where it follows within `tol` on every patch, every seam that
//! was closed stays closed within `2·tol`.

use cadmorph_morph::Deformation;
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{NurbsSurface, Surface};
use serde::Serialize;

/// Settings of [`refine_for`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineOptions {
    /// Largest allowed `|M(S(u, v)) − S'(u, v)|`, model units.
    pub tol: f64,
    /// Bisection rounds at most.
    pub max_rounds: usize,
    /// Stop before a patch would exceed this many control points.
    pub max_control_points: usize,
    /// Samples per knot span and direction (ends included) where the error is measured.
    pub samples_per_span: usize,
}

impl RefineOptions {
    /// Defaults for a tolerance: 24 rounds, 250 000 control points, 5 samples per span.
    pub fn new(tol: f64) -> Self {
        Self { tol, max_rounds: 24, max_control_points: 250_000, samples_per_span: 5 }
    }
}

/// What [`refine_for`] did to one patch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refinement {
    /// Control points before.
    pub control_points_before: usize,
    /// Control points after.
    pub control_points_after: usize,
    /// Knots inserted in u.
    pub u_knots_added: usize,
    /// Knots inserted in v.
    pub v_knots_added: usize,
    /// Largest sampled `|M(S) − S'|` after refinement.
    pub max_error: f64,
    /// Bisection rounds run.
    pub rounds: usize,
    /// Whether `max_error ≤ tol` was reached.
    pub converged: bool,
}

/// The patch with its control points moved by `d` (weights kept): `S'`.
pub fn deformed<D: Deformation + ?Sized>(s: &NurbsSurface, d: &D) -> NurbsSurface {
    let mut out = s.clone();
    d.deform(out.control_points_mut());
    out
}

/// Distinct knot values of the domain of each direction.
fn breaks(s: &NurbsSurface) -> (Vec<f64>, Vec<f64>) {
    let (ud, vd) = s.domain();
    let inside = |vals: Vec<f64>, a: f64, b: f64| vals.into_iter().filter(|&k| k >= a && k <= b).collect::<Vec<_>>();
    (inside(s.u_knots().distinct().0, *ud.start(), *ud.end()), inside(s.v_knots().distinct().0, *vd.start(), *vd.end()))
}

/// Largest `|M(S(u, v)) − S'(u, v)|` per knot cell `(i, j)` (u span i, v span j).
fn cell_errors<D: Deformation + ?Sized>(s: &NurbsSurface, moved: &NurbsSurface, d: &D, k: usize) -> Vec<Vec<f64>> {
    let (ub, vb) = breaks(s);
    let k = k.max(2);
    let lerp = |a: f64, b: f64, i: usize| a + (b - a) * i as f64 / (k - 1) as f64;
    ub.windows(2)
        .map(|uw| {
            vb.windows(2)
                .map(|vw| {
                    let mut worst: f64 = 0.0;
                    for i in 0..k {
                        for j in 0..k {
                            let (u, v) = (lerp(uw[0], uw[1], i), lerp(vw[0], vw[1], j));
                            let exact: Point3<f64> = d.deform_point(&s.eval(u, v));
                            let e = (exact - moved.eval(u, v)).norm();
                            worst = if e.is_nan() { f64::INFINITY } else { worst.max(e) };
                        }
                    }
                    worst
                })
                .collect()
        })
        .collect()
}

/// How much worse `S'` follows the bending of `M ∘ S` along u and along v in a cell:
/// the largest difference of the second differences `f(a) − 2 f(m) + f(b)` of the two
/// along iso-lines of the cell (three lines per direction). A cell is split in the
/// direction(s) where this is large: splitting the other way would not help (a morph
/// that kinks across u is not followed better by more v knots).
fn bending_mismatch<D: Deformation + ?Sized>(
    s: &NurbsSurface,
    moved: &NurbsSurface,
    d: &D,
    (u0, u1): (f64, f64),
    (v0, v1): (f64, f64),
) -> (f64, f64) {
    let err = |u: f64, v: f64| d.deform_point(&s.eval(u, v)) - moved.eval(u, v);
    let second =
        |a: (f64, f64), m: (f64, f64), b: (f64, f64)| (err(a.0, a.1) - err(m.0, m.1) * 2.0 + err(b.0, b.1)).norm();
    let (um, vm) = ((u0 + u1) / 2.0, (v0 + v1) / 2.0);
    let along_u = [v0, vm, v1].iter().map(|&v| second((u0, v), (um, v), (u1, v))).fold(0.0, f64::max);
    let along_v = [u0, um, u1].iter().map(|&u| second((u, v0), (u, vm), (u, v1))).fold(0.0, f64::max);
    (along_u, along_v)
}

/// Largest sampled `|M(S(u, v)) − S'(u, v)|` of a patch under `d` (the error that
/// [`refine_for`] drives below its tolerance).
pub fn morph_error<D: Deformation + ?Sized>(s: &NurbsSurface, d: &D, samples_per_span: usize) -> f64 {
    let moved = deformed(s, d);
    cell_errors(s, &moved, d, samples_per_span).into_iter().flatten().fold(0.0, f64::max)
}

/// Inserts knots into `s` (in place; its geometry does not change) until moving its
/// control points with `d` reproduces `d ∘ s` within `opts.tol` at every sample.
///
/// Each round measures the error on every knot cell and bisects the cells above the
/// tolerance, in the direction(s) along which `S'` misses the bending of `M ∘ S` most
/// (the second differences of the error along u and along v): that is where the morph
/// bends against the local control-point density. Knot lines run across the whole
/// patch, so one split serves a whole row of cells.
///
/// # Tolerance
///
/// Each bisection divides the local error by about 4, so reaching `tol` from an error
/// `e₀` takes about `log₄(e₀ / tol)` rounds, and the control points grow about
/// `√(e₀ / tol)`-fold per direction where the morph bends.
pub fn refine_for<D: Deformation + ?Sized>(s: &mut NurbsSurface, d: &D, opts: &RefineOptions) -> Refinement {
    let before = s.control_points().len();
    let (mut added_u, mut added_v) = (0, 0);
    let mut rounds = 0;
    loop {
        let moved = deformed(s, d);
        let errors = cell_errors(s, &moved, d, opts.samples_per_span);
        let max_error = errors.iter().flatten().copied().fold(0.0, f64::max);
        let done = max_error <= opts.tol;
        if done || rounds >= opts.max_rounds {
            return Refinement {
                control_points_before: before,
                control_points_after: s.control_points().len(),
                u_knots_added: added_u,
                v_knots_added: added_v,
                max_error,
                rounds,
                converged: done,
            };
        }
        let (ub, vb) = breaks(s);
        let mut split_u = vec![false; ub.len() - 1];
        let mut split_v = vec![false; vb.len() - 1];
        for (i, row) in errors.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if e <= opts.tol {
                    continue;
                }
                let (du, dv) = bending_mismatch(s, &moved, d, (ub[i], ub[i + 1]), (vb[j], vb[j + 1]));
                let worst = du.max(dv);
                if du >= 0.5 * worst || !worst.is_finite() {
                    split_u[i] = true;
                }
                if dv >= 0.5 * worst || !worst.is_finite() {
                    split_v[j] = true;
                }
            }
        }
        let xu: Vec<f64> = (0..split_u.len()).filter(|&i| split_u[i]).map(|i| (ub[i] + ub[i + 1]) / 2.0).collect();
        let xv: Vec<f64> = (0..split_v.len()).filter(|&j| split_v[j]).map(|j| (vb[j] + vb[j + 1]) / 2.0).collect();
        let grown = (s.n_u() + xu.len()) * (s.n_v() + xv.len());
        if grown > opts.max_control_points || (xu.is_empty() && xv.is_empty()) {
            return Refinement {
                control_points_before: before,
                control_points_after: s.control_points().len(),
                u_knots_added: added_u,
                v_knots_added: added_v,
                max_error,
                rounds,
                converged: false,
            };
        }
        s.refine_u(&xu).expect("midpoints of non-empty spans are new interior knots");
        s.refine_v(&xv).expect("midpoints of non-empty spans are new interior knots");
        added_u += xu.len();
        added_v += xv.len();
        rounds += 1;
    }
}

/// The PyGeM-style baseline: `n` knots per direction, evenly spaced over the domain
/// (values that are already knots are skipped). Returns the number of knots inserted.
pub fn refine_uniform(s: &mut NurbsSurface, n: usize) -> usize {
    let (ud, vd) = s.domain();
    let even = |a: f64, b: f64, knots: &cadmorph_nurbs::KnotVector| -> Vec<f64> {
        (1..=n).map(|i| a + (b - a) * i as f64 / (n + 1) as f64).filter(|&k| knots.multiplicity(k, 0.0) == 0).collect()
    };
    let xu = even(*ud.start(), *ud.end(), s.u_knots());
    let xv = even(*vd.start(), *vd.end(), s.v_knots());
    s.refine_u(&xu).expect("evenly spaced interior values");
    s.refine_v(&xv).expect("evenly spaced interior values");
    xu.len() + xv.len()
}
