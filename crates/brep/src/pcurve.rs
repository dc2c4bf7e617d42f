//! Parameter-space curves: a model-space curve lying on a surface, as a curve in the
//! surface's `(u, v)` (STEP `PCURVE`, ISO 10303-42 §4.4.43; IGES 142 `BPTR`, §4.32).
//!
//! A reader measures a face (area, volume, inside/outside) in its surface's parameters,
//! so the parameter curves decide how exactly it is read. A writer that leaves them out
//! makes the reader project the model-space curves itself, which OCCT does to its
//! approximation tolerance (about 1e-4 of a face's area on a cylinder's trim). Here they
//! are fitted to the projection of the curve onto the surface within a tolerance in
//! `(u, v)` ([`cadmorph_nurbs::fit_curve`], cubic, with the curve's own parameter, so
//! a pcurve and its model-space curve agree point by point).

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{fit_curve, Curve, NurbsCurve, NurbsSurface, Projection, Side, Surface};

/// How a surface closes on itself: the period in `u` and in `v`, where it does
/// (its `UMin` and `UMax` sides coincide within the tolerance, or `VMin` and `VMax`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Periods {
    /// The `u` period.
    pub u: Option<f64>,
    /// The `v` period.
    pub v: Option<f64>,
}

impl Periods {
    /// The periods of `s`, sides compared at nine points within `tol`.
    pub fn of(s: &NurbsSurface, tol: f64) -> Self {
        let closed = |lo: Side, hi: Side| {
            let (a, b) = (s.boundary(lo), s.boundary(hi));
            let (da, db) = (a.domain(), b.domain());
            (0..=8).all(|k| {
                let f = k as f64 / 8.0;
                let pa = a.eval(da.start() + f * (da.end() - da.start()));
                let pb = b.eval(db.start() + f * (db.end() - db.start()));
                (pa - pb).norm() <= tol
            })
        };
        let (du, dv) = s.domain();
        Self {
            u: closed(Side::UMin, Side::UMax).then(|| du.end() - du.start()),
            v: closed(Side::VMin, Side::VMax).then(|| dv.end() - dv.start()),
        }
    }

    /// `(u, v)` moved by whole periods to lie nearest `near`.
    pub fn unwrap(&self, (u, v): (f64, f64), near: (f64, f64)) -> (f64, f64) {
        let shift = |x: f64, x0: f64, p: Option<f64>| p.map_or(x, |p| x + p * ((x0 - x) / p).round());
        (shift(u, near.0, self.u), shift(v, near.1, self.v))
    }
}

/// The parameter curve of `c` (which lies on `s`, within the projection's reach) as a
/// planar curve `(u, v, 0)` over `c`'s domain, and its `(u, v)` at the end the walk
/// finishes.
///
/// The curve is walked from its start (from its end when `backwards`) in small steps,
/// each projected from the step before (so it stays on one sheet of a closed surface:
/// a curve on the seam of a cylinder takes the side `start` is on), beginning next to
/// `start` when given. Then it is fitted within `tol` in `(u, v)`.
///
/// # Errors
///
/// The fit's error when 4096 poles do not reach `tol` (the curve is not on the surface,
/// or crosses a pole where `(u, v)` is not continuous).
pub fn pcurve(
    s: &NurbsSurface,
    c: &NurbsCurve,
    backwards: bool,
    start: Option<(f64, f64)>,
    periods: Periods,
    tol: f64,
    size: f64,
) -> cadmorph_nurbs::Result<(NurbsCurve, (f64, f64))> {
    let d = c.domain();
    let (t0, t1) = (*d.start(), *d.end());
    let ptol = 1e-12 * size.max(f64::MIN_POSITIVE);
    let accept = 1e-3 * size.max(f64::MIN_POSITIVE);
    // The walk: a table of (t, unwrapped (u, v)) in the order walked.
    let n = (8 * c.control_points().len()).clamp(64, 4096);
    let mut table: Vec<(f64, (f64, f64))> = Vec::with_capacity(n + 1);
    let mut near = start;
    for k in 0..=n {
        let f = k as f64 / n as f64;
        let t = if backwards { t1 - f * (t1 - t0) } else { t0 + f * (t1 - t0) };
        let seed = near.map(|q| wrap(q, s));
        let pr = across_seam(s, &c.eval(t), s.project_near(&c.eval(t), seed, ptol, accept), periods, ptol);
        let uv = match near {
            Some(q) => periods.unwrap((pr.u, pr.v), q),
            None => (pr.u, pr.v),
        };
        table.push((t, uv));
        near = Some(uv);
    }
    // At a pole (a sphere's, a cone's apex) one coordinate is free: it takes the value
    // of the nearest sample where it is not, the limit along the curve.
    let poles: Vec<(bool, bool)> = table.iter().map(|&(_, q)| degenerate(s, wrap(q, s))).collect();
    for k in 0..2 {
        let free = |i: usize| if k == 0 { poles[i].0 } else { poles[i].1 };
        for i in 0..table.len() {
            if !free(i) {
                continue;
            }
            let before = (0..i).rev().find(|&j| !free(j));
            let after = (i + 1..table.len()).find(|&j| !free(j));
            let from = match (before, after) {
                (Some(a), Some(b)) => Some(if i - a <= b - i { a } else { b }),
                (a, b) => a.or(b),
            };
            if let Some(j) = from {
                let x = if k == 0 { table[j].1 .0 } else { table[j].1 .1 };
                if k == 0 {
                    table[i].1 .0 = x;
                } else {
                    table[i].1 .1 = x;
                }
            }
        }
    }
    let mut poles = poles;
    if backwards {
        table.reverse();
        poles.reverse();
    }
    let end = if backwards { table[0].1 } else { table[n].1 };
    // Any parameter: projected from the nearest walked point, kept on its sheet.
    let at = |t: f64| -> Point3<f64> {
        let k = (((t - t0) / (t1 - t0) * n as f64).round().max(0.0) as usize).min(n);
        let q = table[k].1;
        let pr = across_seam(s, &c.eval(t), s.project_from(&c.eval(t), wrap(q, s), ptol), periods, ptol);
        let (mut u, mut v) = periods.unwrap((pr.u, pr.v), q);
        // Only where the walk met a pole (a derivative evaluation per fit point otherwise).
        let (free_u, free_v) = if poles[k] != (false, false) { degenerate(s, (pr.u, pr.v)) } else { (false, false) };
        if free_u {
            u = q.0;
        }
        if free_v {
            v = q.1;
        }
        Point3::new(u, v, 0.0)
    };
    let (knots, _) = c.knots().distinct();
    let (curve, _) = fit_curve(at, (t0, t1), &knots, 3, tol, 4096)?;
    Ok((curve, end))
}

/// Whether `u`, and whether `v`, is free at `(u, v)` of `s`: a pole or an apex, where
/// the partial derivative in it vanishes (`|S_u| ≤ 1e-8 |S_v|`, or the converse).
fn degenerate(s: &NurbsSurface, (u, v): (f64, f64)) -> (bool, bool) {
    let d = s.derivs(u, v, 1);
    let (su, sv) = (d[(1, 0)].norm(), d[(0, 1)].norm());
    (su <= 1e-8 * sv, sv <= 1e-8 * su)
}

/// A projection `pr` of `p` that stopped on the domain's edge in a closed direction (a
/// local search from one side of the seam, with the closest point just across it) tried
/// again from the other side; the closer of the two.
fn across_seam(s: &NurbsSurface, p: &Point3<f64>, pr: Projection, periods: Periods, tol: f64) -> Projection {
    if pr.distance_sq <= tol * tol {
        return pr;
    }
    let (du, dv) = s.domain();
    let other = |x: f64, lo: f64, hi: f64, period: Option<f64>| match period {
        Some(_) if x <= lo => Some(hi),
        Some(_) if x >= hi => Some(lo),
        _ => None,
    };
    let seeds = [
        other(pr.u, *du.start(), *du.end(), periods.u).map(|u| (u, pr.v)),
        other(pr.v, *dv.start(), *dv.end(), periods.v).map(|v| (pr.u, v)),
    ];
    seeds.into_iter().flatten().map(|seed| s.project_from(p, seed, tol)).fold(pr, |best, q| {
        if q.distance_sq < best.distance_sq {
            q
        } else {
            best
        }
    })
}

/// `q` moved by whole periods into the surface's domain (where a projection starts).
pub fn wrap(q: (f64, f64), s: &NurbsSurface) -> (f64, f64) {
    let (du, dv) = s.domain();
    let into = |x: f64, lo: f64, hi: f64| {
        let p = hi - lo;
        if p > 0.0 && (x < lo - 1e-12 * p || x > hi + 1e-12 * p) {
            lo + (x - lo).rem_euclid(p)
        } else {
            x
        }
    };
    (into(q.0, *du.start(), *du.end()), into(q.1, *dv.start(), *dv.end()))
}

/// The points of a chain of curves lying on `s` in `(u, v)`: each curve sampled at
/// `2 n` points (`n` its control points, 16 to 256), each projected from the one before
/// (so the walk stays on one sheet of a closed surface) and unwrapped across its seam;
/// `size` is the model's size. The last point of each curve is left out (the next
/// curve starts there).
pub fn uv_polyline(s: &NurbsSurface, curves: &[NurbsCurve], size: f64) -> Vec<(f64, f64)> {
    let tol = 1e-12 * size.max(f64::MIN_POSITIVE);
    let periods = Periods::of(s, 1e-7 * size);
    let mut uv: Vec<(f64, f64)> = Vec::new();
    let mut near = None;
    for c in curves {
        let d = c.domain();
        let n = (2 * c.control_points().len()).clamp(16, 256);
        for k in 0..n {
            let t = d.start() + (d.end() - d.start()) * k as f64 / n as f64;
            let pr = s.project_near(&c.eval(t), near, tol, 1e-3 * size);
            near = Some((pr.u, pr.v));
            let q = uv.last().map_or((pr.u, pr.v), |&last| periods.unwrap((pr.u, pr.v), last));
            uv.push(q);
        }
    }
    uv
}

/// The signed area of a closed polyline (the shoelace formula): positive when it runs
/// counterclockwise.
pub fn signed_area(uv: &[(f64, f64)]) -> f64 {
    let n = uv.len();
    (0..n)
        .map(|k| {
            let (a, b) = (uv[k], uv[(k + 1) % n]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_on_a_bilinear_plane_is_a_line_in_uv() {
        let s = NurbsSurface::bilinear([[0., 0., 0.], [2., 0., 0.], [0., 1., 0.], [2., 1., 0.]]);
        let c = NurbsCurve::try_new(
            1,
            cadmorph_nurbs::KnotVector::try_new(vec![0., 0., 1., 1.]).unwrap(),
            vec![Point3::new(0.5, 0.25, 0.), Point3::new(1.5, 0.75, 0.)],
            None,
        )
        .unwrap();
        let p = Periods::of(&s, 1e-9);
        assert_eq!(p, Periods { u: None, v: None });
        let (pc, end) = pcurve(&s, &c, false, None, p, 1e-12, 2.0).unwrap();
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            let q = pc.eval(t);
            assert!((q - Point3::new(0.25 + 0.5 * t, 0.25 + 0.5 * t, 0.)).norm() < 1e-11, "{t}: {q}");
        }
        assert!((end.0 - 0.75).abs() < 1e-12 && (end.1 - 0.75).abs() < 1e-12);
    }
}
