//! Refinement that keeps seams closed under a deformation (paper §3.1.2).
//!
//! Moving the control points of a patch with a map `M` gives the surface `S'`, which is
//! not `M ∘ S` unless `M` is affine: between the control points the morph bends space
//! in ways the coarse net cannot follow. Two patches that met exactly before the morph
//! then open up wherever `|M(S(u, v)) − S'(u, v)|` differs along their common edge.
//! Inserting knots leaves `S` unchanged and adds control points, so `S'` follows
//! `M ∘ S` more closely; where it follows within `tol` on every patch, every seam that
//! was closed stays closed within `2·tol`.

use crate::{Error, Result};
use cadmorph_morph::Deformation;
use cadmorph_nurbs::math::{Matrix3, Point3, Vector3};
use cadmorph_nurbs::{NurbsSurface, Side, Surface};
use serde::Serialize;

/// Where [`refine_for`] asks `S'` to follow `M ∘ S`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// On the four boundaries, in position and in normal direction: what keeps seams
    /// closed (C0) and smooth (G1) at the least cost, since knots near an edge fix it
    /// without refining the interior.
    Boundaries,
    /// Everywhere on the patch, in position: the whole surface follows the morph.
    Everywhere,
}

/// Settings of [`refine_for`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineOptions {
    /// Largest allowed `|M(S(u, v)) − S'(u, v)|`, model units.
    pub tol: f64,
    /// Largest allowed angle, degrees, between the normal of `S'` and the normal of
    /// `M ∘ S` on the boundaries (with [`Scope::Boundaries`]); seams stay G1 within
    /// twice this.
    pub angle_tol_deg: f64,
    /// Where the tolerances apply.
    pub scope: Scope,
    /// Bisection rounds at most.
    pub max_rounds: usize,
    /// Stop before a patch would exceed this many control points.
    pub max_control_points: usize,
    /// Samples per knot span and direction (ends included) where the error is measured.
    pub samples_per_span: usize,
}

impl RefineOptions {
    /// Defaults for a tolerance: boundaries only, normals within 0.005° (seams G1
    /// within 0.01°), 24 rounds, 250 000 control points, 5 samples per span.
    pub fn new(tol: f64) -> Self {
        Self {
            tol,
            angle_tol_deg: 0.005,
            scope: Scope::Boundaries,
            max_rounds: 24,
            max_control_points: 250_000,
            samples_per_span: 5,
        }
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
    /// Largest sampled `|M(S) − S'|` after refinement (on the boundaries with
    /// [`Scope::Boundaries`]).
    pub max_error: f64,
    /// Largest sampled normal angle between `S'` and `M ∘ S` on the boundaries, degrees
    /// (0 with [`Scope::Everywhere`], which does not measure it).
    pub max_angle_deg: f64,
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
        let (ub, vb) = breaks(s);
        let mut split_u = vec![false; ub.len() - 1];
        let mut split_v = vec![false; vb.len() - 1];
        let (max_error, max_angle_deg) = match opts.scope {
            Scope::Everywhere => (mark_everywhere(s, &moved, d, opts, (&ub, &vb), (&mut split_u, &mut split_v)), 0.0),
            Scope::Boundaries => mark_boundaries(s, &moved, d, opts, (&ub, &vb), (&mut split_u, &mut split_v)),
        };
        let done = max_error <= opts.tol && max_angle_deg <= opts.angle_tol_deg;
        let xu: Vec<f64> = (0..split_u.len()).filter(|&i| split_u[i]).map(|i| (ub[i] + ub[i + 1]) / 2.0).collect();
        let xv: Vec<f64> = (0..split_v.len()).filter(|&j| split_v[j]).map(|j| (vb[j] + vb[j + 1]) / 2.0).collect();
        let grown = (s.n_u() + xu.len()) * (s.n_v() + xv.len());
        if done || rounds >= opts.max_rounds || grown > opts.max_control_points || (xu.is_empty() && xv.is_empty()) {
            return Refinement {
                control_points_before: before,
                control_points_after: s.control_points().len(),
                u_knots_added: added_u,
                v_knots_added: added_v,
                max_error,
                max_angle_deg,
                rounds,
                converged: done,
            };
        }
        s.refine_u(&xu).expect("midpoints of non-empty spans are new interior knots");
        s.refine_v(&xv).expect("midpoints of non-empty spans are new interior knots");
        added_u += xu.len();
        added_v += xv.len();
        rounds += 1;
    }
}

/// Marks `i` and its neighbours within the cubic support (one span each side).
fn mark(split: &mut [bool], i: usize) {
    for k in i.saturating_sub(1)..=(i + 1).min(split.len() - 1) {
        split[k] = true;
    }
}

type Marks<'a> = (&'a mut [bool], &'a mut [bool]);

/// [`Scope::Everywhere`]: bisects cells whose error exceeds `tol`, in the direction(s)
/// of [`bending_mismatch`], with their neighbours (a cell's control points belong to
/// the neighbouring spans too, so splitting it alone converges only linearly).
fn mark_everywhere<D: Deformation + ?Sized>(
    s: &NurbsSurface,
    moved: &NurbsSurface,
    d: &D,
    opts: &RefineOptions,
    (ub, vb): (&[f64], &[f64]),
    (split_u, split_v): Marks,
) -> f64 {
    let errors = cell_errors(s, moved, d, opts.samples_per_span);
    let max_error = errors.iter().flatten().copied().fold(0.0, f64::max);
    for (i, row) in errors.iter().enumerate() {
        for (j, &e) in row.iter().enumerate() {
            if e <= opts.tol {
                continue;
            }
            let (du, dv) = bending_mismatch(s, moved, d, (ub[i], ub[i + 1]), (vb[j], vb[j + 1]));
            let worst = du.max(dv);
            if du >= 0.5 * worst || !worst.is_finite() {
                mark(split_u, i);
            }
            if dv >= 0.5 * worst || !worst.is_finite() {
                mark(split_v, j);
            }
        }
    }
    max_error
}

/// The unit normal where it is well conditioned (the partials at least 1e-3 rad from
/// parallel); near collapsed edges and tangent partials its direction is noise.
pub(crate) fn well_defined_normal(s: &NurbsSurface, u: f64, v: f64) -> Option<Vector3<f64>> {
    let e = s.eval_d1(u, v);
    let n = e.du.cross(&e.dv);
    let sine = n.norm() / (e.du.norm() * e.dv.norm());
    (sine > 1e-3).then(|| n.normalize())
}

/// The normal of `M ∘ S` at `(u, v)`: `(J S_u) × (J S_v)` with `J = ∂M/∂x` at `S(u, v)`
/// (central differences where the deformation has no closed-form Jacobian).
pub(crate) fn exact_normal<D: Deformation + ?Sized>(
    s: &NurbsSurface,
    d: &D,
    u: f64,
    v: f64,
    h: f64,
) -> Option<Vector3<f64>> {
    let e = s.eval_d1(u, v);
    let j = d.jacobian(&e.point).unwrap_or_else(|| {
        let mut j = Matrix3::zeros();
        for k in 0..3 {
            let mut dx = Vector3::zeros();
            dx[k] = h;
            let col = (d.deform_point(&(e.point + dx)) - d.deform_point(&(e.point - dx))) / (2.0 * h);
            j.set_column(k, &col);
        }
        j
    });
    let n = (j * e.du).cross(&(j * e.dv));
    let len = n.norm();
    (len > 0.0 && len.is_finite()).then(|| n / len)
}

/// Which directions of `moved` (the control points of `s` moved by `d`) fall short of
/// `M ∘ S` in their first derivative at `(u, v)`: `(u, v)` flags, set for the direction
/// whose relative error `|S'_x − J S_x| / |J S_x|` is the larger one or at least half of
/// it. A normal that strays from the exact morph's strays because of these; bisecting
/// only them keeps refinement from growing a patch in the direction that is already
/// right (a ruled side face bent across, not along, its edge).
pub(crate) fn short_directions<D: Deformation + ?Sized>(
    s: &NurbsSurface,
    moved: &NurbsSurface,
    d: &D,
    u: f64,
    v: f64,
    h: f64,
) -> (bool, bool) {
    let e = s.eval_d1(u, v);
    let j = d.jacobian(&e.point).unwrap_or_else(|| {
        let mut j = Matrix3::zeros();
        for k in 0..3 {
            let mut dx = Vector3::zeros();
            dx[k] = h;
            let col = (d.deform_point(&(e.point + dx)) - d.deform_point(&(e.point - dx))) / (2.0 * h);
            j.set_column(k, &col);
        }
        j
    });
    let m = moved.eval_d1(u, v);
    let rel = |got: Vector3<f64>, want: Vector3<f64>| {
        let n = want.norm();
        if n > 0.0 {
            (got - want).norm() / n
        } else {
            0.0
        }
    };
    let (eu, ev) = (rel(m.du, j * e.du), rel(m.dv, j * e.dv));
    let top = eu.max(ev);
    if !(top.is_finite()) || top == 0.0 {
        return (true, true);
    }
    (eu >= 0.5 * top, ev >= 0.5 * top)
}

/// [`Scope::Boundaries`]: along each side, a span whose boundary points miss `M ∘ S` by
/// more than `tol` is bisected along the edge (the boundary curve of `S'` depends only
/// on the boundary row and the knots along the edge); where the normals differ by more
/// than `angle_tol_deg`, the span next to the edge across it is bisected, which halves
/// the leg from the boundary row to the next row and with it the normal error.
/// Returns the largest position error and normal angle found.
fn mark_boundaries<D: Deformation + ?Sized>(
    s: &NurbsSurface,
    moved: &NurbsSurface,
    d: &D,
    opts: &RefineOptions,
    (ub, vb): (&[f64], &[f64]),
    (split_u, split_v): Marks,
) -> (f64, f64) {
    let k = opts.samples_per_span.max(2);
    let h = 1e-7 * s.bounding_box().diagonal().max(f64::MIN_POSITIVE);
    let (mut max_error, mut max_angle): (f64, f64) = (0.0, 0.0);
    for side in Side::ALL {
        // Spans along the edge, and the fixed parameter with the cross span next to it.
        let (along, fixed, cross_span, along_is_u) = match side {
            Side::UMin => (vb, ub[0], 0, false),
            Side::UMax => (vb, ub[ub.len() - 1], ub.len() - 2, false),
            Side::VMin => (ub, vb[0], 0, true),
            Side::VMax => (ub, vb[vb.len() - 1], vb.len() - 2, true),
        };
        for (i, w) in along.windows(2).enumerate() {
            let (mut pos, mut ang): (f64, f64) = (0.0, 0.0);
            for n in 0..k {
                let t = w[0] + (w[1] - w[0]) * n as f64 / (k - 1) as f64;
                let (u, v) = if along_is_u { (t, fixed) } else { (fixed, t) };
                let exact: Point3<f64> = d.deform_point(&s.eval(u, v));
                let e = (exact - moved.eval(u, v)).norm();
                pos = if e.is_nan() { f64::INFINITY } else { pos.max(e) };
                if let (Some(a), Some(b)) = (well_defined_normal(moved, u, v), exact_normal(s, d, u, v, h)) {
                    ang = ang.max(a.cross(&b).norm().atan2(a.dot(&b)).to_degrees());
                }
            }
            max_error = max_error.max(pos);
            max_angle = max_angle.max(ang);
            let (split_along, split_cross) =
                if along_is_u { (&mut *split_u, &mut *split_v) } else { (&mut *split_v, &mut *split_u) };
            if pos > opts.tol {
                mark(split_along, i);
            }
            if ang > opts.angle_tol_deg {
                split_cross[cross_span] = true;
            }
        }
    }
    (max_error, max_angle)
}

/// The PyGeM-style baseline: `n` knots per direction, evenly spaced over the domain
/// (values that are already knots are skipped). Returns the number of knots inserted.
///
/// The values are `a·(1 − t) + b·t`, which stays finite on any finite domain (the plain
/// `a + (b − a)·t` overflows on spans near `f64::MAX`), and the refined net is sized
/// against the memory budget ([`cadmorph_morph::budget`]) before anything is allocated.
///
/// # Errors
///
/// [`Error::TooLarge`] when the refined net would exceed the budget; [`Error::Nurbs`]
/// when the domain is too narrow for `n` distinct values.
pub fn refine_uniform(s: &mut NurbsSurface, n: usize) -> Result<usize> {
    let (ud, vd) = s.domain();
    let (nu, nv) = (s.n_u(), s.n_v());
    let grown = |a: usize| a.saturating_add(n);
    // Four f64 per control point (x, y, z, w), twice over while the rows are rebuilt.
    cadmorph_morph::budget::check(
        &format!("uniform refinement by {n} knots per direction ({}x{} control points)", grown(nu), grown(nv)),
        &[grown(nu), grown(nv), 4, 2],
        std::mem::size_of::<f64>(),
    )
    .map_err(|e| match e {
        cadmorph_morph::Error::TooLarge { what, needed, limit } => Error::TooLarge { what, needed, limit },
        other => unreachable!("budget::check only refuses sizes: {other}"),
    })?;
    let even = |a: f64, b: f64, knots: &cadmorph_nurbs::KnotVector| -> Vec<f64> {
        let mut out: Vec<f64> = (1..=n)
            .map(|i| {
                let t = i as f64 / (n + 1) as f64;
                a * (1.0 - t) + b * t
            })
            .filter(|&k| k > a && k < b && knots.multiplicity(k, 0.0) == 0)
            .collect();
        out.dedup();
        out
    };
    let xu = even(*ud.start(), *ud.end(), s.u_knots());
    let xv = even(*vd.start(), *vd.end(), s.v_knots());
    s.refine_u(&xu)?;
    s.refine_v(&xv)?;
    Ok(xu.len() + xv.len())
}
