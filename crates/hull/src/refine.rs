//! Refinement along the length for laws that vary along it (the chine law, the
//! principal-dimension stretch): moving control points by a map that is not affine
//! differs from moving the surface by `O(h²)` in the knot spacing `h`, so spans are
//! bisected where the difference exceeds a tolerance.

use cadmorph_brep::CadDocument;
use cadmorph_model::Model;
use cadmorph_morph::Deformation;
use cadmorph_nurbs::{KnotVector, NurbsSurface, Surface};
use serde::Serialize;

use crate::{Error, Result};

/// What [`along_length`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Refined {
    /// Bisection rounds.
    pub rounds: usize,
    /// Control points of all faces before.
    pub control_points_before: usize,
    /// Control points of all faces after.
    pub control_points_after: usize,
    /// Largest distance between a B-spline face with its control points moved and the
    /// map applied to the points of its surface (sampled), after the refinement.
    pub max_deviation: f64,
}

/// The parametric direction along the length (the one x varies most in): `true` for u.
fn along_u(s: &NurbsSurface) -> bool {
    let (ud, vd) = s.domain();
    let (um, vm) = (0.5 * (ud.start() + ud.end()), 0.5 * (vd.start() + vd.end()));
    let du = (s.eval(*ud.end(), vm).x - s.eval(*ud.start(), vm).x).abs();
    let dv = (s.eval(um, *vd.end()).x - s.eval(um, *vd.start()).x).abs();
    du >= dv
}

/// Sample parameters of a knot vector's domain: every distinct knot and `per` points
/// inside each span.
fn samples(knots: &KnotVector, per: usize) -> Vec<f64> {
    let (k, _) = knots.distinct();
    let mut out = vec![k[0]];
    for w in k.windows(2) {
        for i in 1..=per {
            out.push(w[0] + (w[1] - w[0]) * i as f64 / (per + 1) as f64);
        }
        out.push(w[1]);
    }
    out
}

/// The distance between the surface with its control points moved by `law` and the law
/// applied to the surface's points, sampled, per knot span along the length: each span's
/// x range and largest distance.
fn deviation(s: &NurbsSurface, law: &dyn Deformation) -> Vec<((f64, f64), f64)> {
    let mut moved = s.clone();
    for q in moved.control_points_mut() {
        *q = law.deform_point(q);
    }
    let u = along_u(s);
    let (along, across) = if u { (s.u_knots(), s.v_knots()) } else { (s.v_knots(), s.u_knots()) };
    let (k, _) = along.distinct();
    let across = samples(across, 2);
    let per = 3;
    k.windows(2)
        .map(|w| {
            let mut worst: f64 = 0.0;
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..=per + 1 {
                let a = w[0] + (w[1] - w[0]) * i as f64 / (per + 1) as f64;
                for &b in &across {
                    let (uu, vv) = if u { (a, b) } else { (b, a) };
                    let p = s.eval(uu, vv);
                    lo = lo.min(p.x);
                    hi = hi.max(p.x);
                    worst = worst.max((moved.eval(uu, vv) - law.deform_point(&p)).norm());
                }
            }
            ((lo, hi), worst)
        })
        .collect()
}

/// Bisects the spans along the length whose x range meets one of `flagged`.
fn bisect(s: &mut NurbsSurface, flagged: &[(f64, f64)], eps: f64) -> Result<usize> {
    let u = along_u(s);
    let knots = if u { s.u_knots() } else { s.v_knots() };
    let (k, _) = knots.distinct();
    let spans = deviation_ranges(s, u, &k);
    let mids: Vec<f64> = k
        .windows(2)
        .zip(spans)
        .filter(|(_, (lo, hi))| flagged.iter().any(|f| f.0 <= hi + eps && f.1 >= lo - eps))
        .map(|(w, _)| 0.5 * (w[0] + w[1]))
        .collect();
    let r = if u { s.refine_u(&mids) } else { s.refine_v(&mids) };
    r.map_err(|e| Error::Invalid(format!("refining a face along the length: {e}")))?;
    Ok(mids.len())
}

/// The x range of each knot span along the length (sampled like [`deviation`]).
fn deviation_ranges(s: &NurbsSurface, u: bool, k: &[f64]) -> Vec<(f64, f64)> {
    let across = samples(if u { s.v_knots() } else { s.u_knots() }, 2);
    k.windows(2)
        .map(|w| {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..=4 {
                let a = w[0] + (w[1] - w[0]) * i as f64 / 4.0;
                for &b in &across {
                    let p = if u { s.eval(a, b) } else { s.eval(b, a) };
                    lo = lo.min(p.x);
                    hi = hi.max(p.x);
                }
            }
            (lo, hi)
        })
        .collect()
}

/// Refines the B-spline faces of `model` that `law` moves along the length, in the
/// model, until each face with its control points moved by `law` is within `tol` of
/// `law` applied to every point of it (sampled: three points inside each span along the
/// length, two inside each span across, and the knots). In every round each face's
/// spans are bisected where some face is further than `tol`, chosen by x range, so
/// faces sharing an edge with the same knots along it keep equal control points there
/// and the edge stays closed when the control points move. The geometry does not
/// change. `what` names the law in errors.
///
/// # Errors
///
/// [`Error::Invalid`] for a tolerance that is not positive, or when 20 rounds do not
/// reach it; the model's errors.
pub fn along_length<D: CadDocument>(
    model: &mut Model<D>,
    law: &dyn Deformation,
    tol: f64,
    what: &str,
) -> Result<Refined> {
    if tol.is_nan() || tol <= 0.0 {
        return Err(Error::Invalid(format!("{what}: the tolerance must be positive, not {tol}")));
    }
    let faces = model.patches().to_vec();
    let before: usize = faces.iter().map(|f| f.surface.control_points().len()).sum();
    let worst_of = |d: &[((f64, f64), f64)]| d.iter().map(|e| e.1).fold(0.0, f64::max);
    // The faces the law moves: any control point or surface sample displaced.
    let moves = |s: &NurbsSurface| {
        s.control_points().iter().any(|p| law.deform_point(p) != *p) || worst_of(&deviation(s, law)) > 0.0
    };
    let targets: Vec<usize> =
        (0..faces.len()).filter(|&i| !faces[i].kind.is_analytic() && moves(&faces[i].surface)).collect();
    let mut surfaces: Vec<NurbsSurface> = targets.iter().map(|&i| faces[i].surface.clone()).collect();
    let mut rounds = 0;
    let eps = 1e-9 * model.size();
    loop {
        let devs: Vec<_> = surfaces.iter().map(|s| deviation(s, law)).collect();
        let worst = devs.iter().map(|d| worst_of(d)).fold(0.0, f64::max);
        if worst <= tol {
            break;
        }
        if rounds == 20 {
            return Err(Error::Invalid(format!(
                "{what}: the faces are still {worst:.3e} from the law after {rounds} bisections along the length (tolerance {tol:.3e}); nothing written"
            )));
        }
        let flagged: Vec<(f64, f64)> = devs.iter().flatten().filter(|e| e.1 > tol).map(|e| e.0).collect();
        for s in &mut surfaces {
            bisect(s, &flagged, eps)?;
        }
        rounds += 1;
    }
    let worst = surfaces.iter().map(|s| worst_of(&deviation(s, law))).fold(0.0, f64::max);
    if rounds > 0 {
        for (&i, s) in targets.iter().zip(surfaces) {
            model.set_patch_surface(i, s)?;
        }
    }
    let after: usize = model.patches().iter().map(|f| f.surface.control_points().len()).sum();
    Ok(Refined { rounds, control_points_before: before, control_points_after: after, max_deviation: worst })
}
