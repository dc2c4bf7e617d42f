//! Point projection (closest point) onto curves and surfaces.
//!
//! Both projections follow Piegl & Tiller, *The NURBS Book*, §6.1: a coarse sampling of
//! the parameter domain (a few samples per knot span, more for higher degrees) finds
//! start values near every local minimum of the distance, then Newton iteration on
//!
//! ```text
//! curve:    f(t)    = C'(t) · (C(t) − P) = 0                         (6.3)
//! surface:  f(u, v) = S_u · (S − P) = 0,   g(u, v) = S_v · (S − P) = 0  (6.5)–(6.7)
//! ```
//!
//! refines the best few starts. Two things are added to the book's iteration so it
//! cannot diverge or leave the domain:
//!
//! - **Descent safeguard.** A step that does not reduce the distance is halved until it
//!   does (a backtracking line search); where the Newton matrix is not positive
//!   definite (far from the surface, on the concave side) the Gauss–Newton matrix
//!   `JᵀJ` is used instead.
//! - **Domain edges.** Parameters are clamped to the domain. A parameter that sits on its
//!   bound while the distance gradient points outward is held fixed (an active-set
//!   Newton method), so the iteration continues as 1D Newton along the boundary curve
//!   and converges to the closest point on the edge, or stops at a corner.
//!
//! # Convergence
//!
//! The iteration stops when the point lies within `tol` of the surface (point
//! coincidence, the book's ε₁), when the last Newton step moved the point by at most
//! `tol` in model space, or the parameters by at most `1e-14` of the domain width (the
//! parametric tolerance), or when no step reduces the distance any more. Newton
//! converges quadratically, so after a step of length `≤ tol` the remaining error is of
//! order `tol²/ρ` (ρ the radius of curvature): much smaller than `tol`.

use nalgebra::{Point3, Vector3};

use crate::{Curve, KnotVector, NurbsCurve, NurbsSurface, Surface};

/// Newton iterations per start value.
const MAX_ITERATIONS: usize = 64;
/// Step halvings before a Newton step is given up.
const MAX_HALVINGS: usize = 40;
/// Start values refined by Newton (the best local minima of the sampled distance).
const MAX_STARTS: usize = 4;
/// Parametric step, relative to the domain width, below which Newton stops.
const PARAM_STEP: f64 = 1e-14;
/// Upper bound of samples per direction (long knot vectors get fewer per span).
const MAX_SAMPLES: usize = 256;

/// The closest point of a curve to a given point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveProjection {
    /// Parameter of the closest point.
    pub t: f64,
    /// The closest point `C(t)`.
    pub point: Point3<f64>,
    /// Squared distance from the given point to `point`.
    pub distance_sq: f64,
}

/// The closest point of a surface to a given point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// u parameter of the closest point.
    pub u: f64,
    /// v parameter of the closest point.
    pub v: f64,
    /// The closest point `S(u, v)`.
    pub point: Point3<f64>,
    /// Squared distance from the given point to `point`.
    pub distance_sq: f64,
}

/// Closest point on a curve, to within `tol` (model units).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{CurveProject, KnotVector, NurbsCurve};
/// use nalgebra::Point3;
/// // Quarter circle of radius 1; the point (2, 2, 0) projects to (√½, √½, 0).
/// let w = std::f64::consts::FRAC_1_SQRT_2;
/// let arc = NurbsCurve::new(
///     2,
///     KnotVector::try_new(vec![0., 0., 0., 1., 1., 1.]).unwrap(),
///     vec![Point3::new(1., 0., 0.), Point3::new(1., 1., 0.), Point3::new(0., 1., 0.)],
///     Some(vec![1.0, w, 1.0]),
/// );
/// let pr = arc.project(&Point3::new(2.0, 2.0, 0.0), 1e-12);
/// assert!((pr.t - 0.5).abs() < 1e-12);
/// assert!((pr.distance_sq.sqrt() - (8f64.sqrt() - 1.0)).abs() < 1e-12);
/// ```
pub trait CurveProject: Curve {
    /// The closest point of the curve to `p`.
    ///
    /// # Tolerance
    ///
    /// `tol` is the accuracy in model units of the returned point; see the
    /// source comments at the top of `project.rs` for the stopping rules. The cost is one sampling pass
    /// (`O(spans · degree)` evaluations) plus a few Newton steps per start value.
    fn project(&self, p: &Point3<f64>, tol: f64) -> CurveProjection;
}

/// Closest point on a surface, to within `tol` (model units).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{NurbsSurface, SurfaceProject};
/// use nalgebra::Point3;
/// let plane = NurbsSurface::bilinear([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
/// let inside = plane.project(&Point3::new(0.25, 0.5, 3.0), 1e-12);
/// assert!((inside.u - 0.25).abs() < 1e-12 && (inside.v - 0.5).abs() < 1e-12);
/// assert!((inside.distance_sq - 9.0).abs() < 1e-10);
/// // Beyond the edge u = 1: the closest point is on that edge.
/// let outside = plane.project(&Point3::new(2.0, 0.5, 1.0), 1e-12);
/// assert_eq!(outside.u, 1.0);
/// assert!((outside.v - 0.5).abs() < 1e-12);
/// ```
pub trait SurfaceProject: Surface {
    /// The closest point of the surface to `p`.
    ///
    /// # Tolerance
    ///
    /// `tol` is the accuracy in model units of the returned point; see the
    /// source comments at the top of `project.rs` for the stopping rules. The cost is one sampling pass
    /// (`O(spans_u · spans_v · p · q)` evaluations, at most 256² points) plus a few
    /// Newton steps per start value.
    fn project(&self, p: &Point3<f64>, tol: f64) -> Projection;
}

impl<C: CurveProject + ?Sized> CurveProject for &C {
    fn project(&self, p: &Point3<f64>, tol: f64) -> CurveProjection {
        (**self).project(p, tol)
    }
}

impl<C: CurveProject + ?Sized> CurveProject for Box<C> {
    fn project(&self, p: &Point3<f64>, tol: f64) -> CurveProjection {
        (**self).project(p, tol)
    }
}

impl<S: SurfaceProject + ?Sized> SurfaceProject for &S {
    fn project(&self, p: &Point3<f64>, tol: f64) -> Projection {
        (**self).project(p, tol)
    }
}

impl<S: SurfaceProject + ?Sized> SurfaceProject for Box<S> {
    fn project(&self, p: &Point3<f64>, tol: f64) -> Projection {
        (**self).project(p, tol)
    }
}

impl CurveProject for NurbsCurve {
    fn project(&self, p: &Point3<f64>, tol: f64) -> CurveProjection {
        let d = self.domain();
        let ts = span_samples(self.knots(), self.degree(), (*d.start(), *d.end()));
        project_curve(self, &ts, p, tol)
    }
}

/// A curve with its sample table kept for many projections onto it: the same answers
/// as [`CurveProject::project`], bit for bit, without evaluating the samples again for
/// every point (boundary pairing projects dozens of points onto each candidate curve).
#[derive(Debug, Clone)]
pub struct CurveProjector<'a> {
    curve: &'a NurbsCurve,
    ts: Vec<f64>,
    points: Vec<Point3<f64>>,
}

impl<'a> CurveProjector<'a> {
    /// The sample table of `curve` (the one [`CurveProject::project`] makes).
    pub fn new(curve: &'a NurbsCurve) -> Self {
        let d = curve.domain();
        let ts = span_samples(curve.knots(), curve.degree(), (*d.start(), *d.end()));
        let points = ts.iter().map(|&t| curve.eval(t)).collect();
        Self { curve, ts, points }
    }

    /// The closest point of the curve to `p`, as [`CurveProject::project`] finds it.
    pub fn project(&self, p: &Point3<f64>, tol: f64) -> CurveProjection {
        let d = self.points.iter().map(|q| (q - p).norm_squared()).collect();
        project_curve_from(self.curve, &self.ts, d, p, tol)
    }
}

impl SurfaceProject for NurbsSurface {
    fn project(&self, p: &Point3<f64>, tol: f64) -> Projection {
        let (du, dv) = self.domain();
        let us = span_samples(self.u_knots(), self.u_degree(), (*du.start(), *du.end()));
        let vs = span_samples(self.v_knots(), self.v_degree(), (*dv.start(), *dv.end()));
        project_surface(self, &us, &vs, p, tol)
    }
}

/// Sample parameters: `degree + 2` per non-empty knot span of the domain `[a, b]`
/// (fewer when there are many spans, at least 2), both ends included.
pub(crate) fn span_samples(knots: &KnotVector, degree: usize, (a, b): (f64, f64)) -> Vec<f64> {
    let (values, _) = knots.distinct();
    let mut breaks: Vec<f64> = values.into_iter().filter(|&k| k > a && k < b).collect();
    breaks.insert(0, a);
    breaks.push(b);
    let spans = breaks.len() - 1;
    let per_span = (degree + 2).min((MAX_SAMPLES / spans).max(2));
    let mut out = Vec::with_capacity(spans * per_span + 1);
    for w in breaks.windows(2) {
        out.extend((0..per_span).map(|i| w[0] + (w[1] - w[0]) * i as f64 / per_span as f64));
    }
    out.push(b);
    out
}

/// Indices of the `MAX_STARTS` smallest local minima of `d` (a sequence or a grid
/// given by its neighbour function), best first.
fn best_minima(d: &[f64], is_local_min: impl Fn(usize) -> bool) -> Vec<usize> {
    let mut minima: Vec<usize> = (0..d.len()).filter(|&i| is_local_min(i)).collect();
    minima.sort_by(|&i, &j| d[i].total_cmp(&d[j]));
    minima.truncate(MAX_STARTS);
    if minima.is_empty() {
        // All NaN: start from the first sample.
        minima.push(0);
    }
    minima
}

/// Projection onto any curve from the sample parameters `ts` (sorted, covering the domain).
fn project_curve<C: Curve + ?Sized>(c: &C, ts: &[f64], p: &Point3<f64>, tol: f64) -> CurveProjection {
    let d: Vec<f64> = ts.iter().map(|&t| (c.eval(t) - p).norm_squared()).collect();
    project_curve_from(c, ts, d, p, tol)
}

/// [`project_curve`] given the squared distances `d` of `p` to the samples.
fn project_curve_from<C: Curve + ?Sized>(c: &C, ts: &[f64], d: Vec<f64>, p: &Point3<f64>, tol: f64) -> CurveProjection {
    let n = d.len();
    let starts = best_minima(&d, |i| (i == 0 || d[i] <= d[i - 1]) && (i + 1 == n || d[i] <= d[i + 1]));
    let domain = (ts[0], ts[n - 1]);
    starts
        .into_iter()
        .map(|i| newton_curve(c, p, ts[i], domain, tol))
        .min_by(|a, b| a.distance_sq.total_cmp(&b.distance_sq))
        .expect("at least one start")
}

/// Safeguarded Newton iteration on `C'·(C − P) = 0` (Piegl & Tiller (6.3)), clamped to
/// `[a, b]`.
fn newton_curve<C: Curve + ?Sized>(c: &C, p: &Point3<f64>, t0: f64, (a, b): (f64, f64), tol: f64) -> CurveProjection {
    let ptol = PARAM_STEP * (b - a);
    let mut t = t0;
    let mut d = c.derivs(t, 2);
    let mut r = d[0] - p.coords;
    let mut dsq = r.norm_squared();
    for _ in 0..MAX_ITERATIONS {
        if dsq <= tol * tol {
            break;
        }
        let g = r.dot(&d[1]);
        let speed_sq = d[1].norm_squared();
        let mut h = speed_sq + r.dot(&d[2]);
        if h.is_nan() || h <= 0.0 {
            // Not locally convex: Gauss–Newton.
            h = speed_sq;
        }
        if h.is_nan() || h <= 0.0 || g == 0.0 {
            break;
        }
        let mut step = -g / h;
        if (t <= a && step < 0.0) || (t >= b && step > 0.0) {
            // The distance decreases out of the domain: the end is the closest point.
            break;
        }
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let tn = (t + step).clamp(a, b);
            let dsq_n = (c.eval(tn) - p).norm_squared();
            if dsq_n <= dsq {
                accepted = Some((tn, dsq_n));
                break;
            }
            step *= 0.5;
        }
        let Some((tn, dsq_n)) = accepted else { break };
        let moved = (tn - t).abs();
        t = tn;
        dsq = dsq_n;
        d = c.derivs(t, 2);
        r = d[0] - p.coords;
        if moved * speed_sq.sqrt() <= tol || moved <= ptol {
            break;
        }
    }
    // Report `eval` (not the derivative routine's point) so `point == c.eval(t)` exactly.
    let point = c.eval(t);
    CurveProjection { t, point, distance_sq: (point - p).norm_squared() }
}

/// Projection onto any surface from the sample grid `us × vs`.
impl NurbsSurface {
    /// The closest point to `p` found by Newton iteration from the start `(u0, v0)`
    /// alone, without the global sampling of [`SurfaceProject::project`]: the local
    /// projection, for when a good start is known (a point matched by parameter on a
    /// neighbouring patch, the previous sample along an edge). It never returns a point
    /// farther from `p` than `S(u0, v0)`.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_nurbs::math::Point3;
    /// use cadmorph_nurbs::NurbsSurface;
    /// let s = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
    /// let pr = s.project_from(&Point3::new(0.3, 0.6, 2.0), (0.5, 0.5), 1e-12);
    /// assert!((pr.u - 0.3).abs() < 1e-12 && (pr.v - 0.6).abs() < 1e-12);
    /// ```
    pub fn project_from(&self, p: &Point3<f64>, (u0, v0): (f64, f64), tol: f64) -> Projection {
        let (du, dv) = self.domain();
        let domain = ((*du.start(), *du.end()), (*dv.start(), *dv.end()));
        let u0 = u0.clamp(domain.0 .0, domain.0 .1);
        let v0 = v0.clamp(domain.1 .0, domain.1 .1);
        newton_surface(self, p, (u0, v0), domain, tol)
    }

    /// The closest point to `p`, searched locally from `near` when that is given (see
    /// [`NurbsSurface::project_from`]) and kept when it lies within `accept` of `p`; else,
    /// or without `near`, the global [`SurfaceProject::project`]. For walking along a
    /// curve that lies on (or within `accept` of) the surface, each sample started from
    /// the previous sample's answer: one Newton solve per sample instead of a global
    /// search. Off the surface it is the global search, so a real gap is measured as such.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_nurbs::math::Point3;
    /// use cadmorph_nurbs::NurbsSurface;
    /// let s = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
    /// let mut near = None;
    /// for i in 0..=10 {
    ///     let pr = s.project_near(&Point3::new(0.1 * i as f64, 0.5, 0.0), near, 1e-12, 1e-9);
    ///     assert!((pr.u - 0.1 * i as f64).abs() < 1e-12 && pr.distance_sq < 1e-24);
    ///     near = Some((pr.u, pr.v));
    /// }
    /// ```
    pub fn project_near(&self, p: &Point3<f64>, near: Option<(f64, f64)>, tol: f64, accept: f64) -> Projection {
        if let Some(start) = near {
            let local = self.project_from(p, start, tol);
            if local.distance_sq <= accept * accept {
                return local;
            }
        }
        self.project(p, tol)
    }
}

fn project_surface<S: Surface + ?Sized>(s: &S, us: &[f64], vs: &[f64], p: &Point3<f64>, tol: f64) -> Projection {
    let (nu, nv) = (us.len(), vs.len());
    let mut d = Vec::with_capacity(nu * nv);
    for &u in us {
        for &v in vs {
            d.push((s.eval(u, v) - p).norm_squared());
        }
    }
    let is_min = |k: usize| {
        let (i, j) = ((k / nv) as isize, (k % nv) as isize);
        (-1..=1isize).all(|di| {
            (-1..=1isize).all(|dj| {
                let (a, b) = (i + di, j + dj);
                a < 0 || b < 0 || a >= nu as isize || b >= nv as isize || d[k] <= d[a as usize * nv + b as usize]
            })
        })
    };
    let starts = best_minima(&d, is_min);
    let domain = ((us[0], us[nu - 1]), (vs[0], vs[nv - 1]));
    starts
        .into_iter()
        .map(|k| newton_surface(s, p, (us[k / nv], vs[k % nv]), domain, tol))
        .min_by(|a, b| a.distance_sq.total_cmp(&b.distance_sq))
        .expect("at least one start")
}

/// Active-set, safeguarded Newton iteration on Piegl & Tiller (6.6)–(6.7):
///
/// ```text
/// J δ = −κ,  J = | |S_u|² + r·S_uu    S_u·S_v + r·S_uv |,  κ = | r·S_u |,  r = S − P
///                | S_u·S_v + r·S_uv   |S_v|² + r·S_vv  |       | r·S_v |
/// ```
///
/// with a parameter held on its bound while the gradient points out of the domain.
fn newton_surface<S: Surface + ?Sized>(
    s: &S,
    p: &Point3<f64>,
    (u0, v0): (f64, f64),
    ((ua, ub), (va, vb)): ((f64, f64), (f64, f64)),
    tol: f64,
) -> Projection {
    let (uptol, vptol) = (PARAM_STEP * (ub - ua), PARAM_STEP * (vb - va));
    let (mut u, mut v) = (u0, v0);
    let mut d = s.derivs(u, v, 2);
    if let Some(start) = leave_pole(s, p, (u, v), (d[(1, 0)], d[(0, 1)]), ((ua, ub), (va, vb))) {
        (u, v) = start;
        d = s.derivs(u, v, 2);
    }
    let mut dsq = (d.point() - p).norm_squared();
    for _ in 0..MAX_ITERATIONS {
        if dsq <= tol * tol {
            break;
        }
        let r: Vector3<f64> = d.point() - p;
        let (su, sv) = (d[(1, 0)], d[(0, 1)]);
        let g = [r.dot(&su), r.dot(&sv)];
        let gn = [su.norm_squared(), su.dot(&sv), sv.norm_squared()];
        let mut h = [gn[0] + r.dot(&d[(2, 0)]), gn[1] + r.dot(&d[(1, 1)]), gn[2] + r.dot(&d[(0, 2)])];
        let det = h[0] * h[2] - h[1] * h[1];
        if det.is_nan() || h[0] <= 0.0 || det <= 0.0 {
            // Not locally convex (or degenerate): Gauss–Newton, regularised where S_u or S_v vanish.
            let mu = 1e-12 * (gn[0] + gn[2]) + f64::MIN_POSITIVE;
            h = [gn[0] + mu, gn[1], gn[2] + mu];
        }
        let fix_u = (u <= ua && g[0] > 0.0) || (u >= ub && g[0] < 0.0);
        let fix_v = (v <= va && g[1] > 0.0) || (v >= vb && g[1] < 0.0);
        let (mut du, mut dv) = match (fix_u, fix_v) {
            (false, false) => {
                let det = h[0] * h[2] - h[1] * h[1];
                ((-g[0] * h[2] + g[1] * h[1]) / det, (g[0] * h[1] - g[1] * h[0]) / det)
            }
            // 1D Newton along the boundary curve u = const.
            (true, false) => (0.0, -g[1] / if h[2] > 0.0 { h[2] } else { gn[2] }),
            (false, true) => (-g[0] / if h[0] > 0.0 { h[0] } else { gn[0] }, 0.0),
            // A corner with the gradient pointing out on both sides.
            (true, true) => break,
        };
        if !(du.is_finite() && dv.is_finite()) || (du == 0.0 && dv == 0.0) {
            break;
        }
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let (un, vn) = ((u + du).clamp(ua, ub), (v + dv).clamp(va, vb));
            let dsq_n = (s.eval(un, vn) - p).norm_squared();
            if dsq_n <= dsq {
                accepted = Some((un, vn, dsq_n));
                break;
            }
            du *= 0.5;
            dv *= 0.5;
        }
        let Some((un, vn, dsq_n)) = accepted else { break };
        let moved = su * (un - u) + sv * (vn - v);
        let small_param = (un - u).abs() <= uptol && (vn - v).abs() <= vptol;
        (u, v, dsq) = (un, vn, dsq_n);
        d = s.derivs(u, v, 2);
        if moved.norm() <= tol || small_param {
            break;
        }
    }
    // Report `eval` (not the derivative routine's point) so `point == s.eval(u, v)` exactly.
    let point = s.eval(u, v);
    Projection { u, v, point, distance_sq: (point - p).norm_squared() }
}

/// Samples of the collapsed parameter [`leave_pole`] compares.
const POLE_SCAN: usize = 64;

/// The start of [`newton_surface`] at a pole: where one partial vanishes (a sphere's
/// pole, a cone's apex, a collapsed edge), every value of that parameter gives the same
/// point, so Newton cannot move it, and the step in the other parameter leaves along
/// whichever meridian the start happens to name, away from `p` when that one points
/// elsewhere. Given the partials `(su, sv)` at the start, returns the start with the
/// value of the collapsed parameter whose other partial points most towards `p` (of
/// [`POLE_SCAN`] evenly spaced ones); `None` away from a pole (the common case costs
/// nothing beyond the partials Newton already has).
fn leave_pole<S: Surface + ?Sized>(
    s: &S,
    p: &Point3<f64>,
    (u, v): (f64, f64),
    (su, sv): (Vector3<f64>, Vector3<f64>),
    ((ua, ub), (va, vb)): ((f64, f64), (f64, f64)),
) -> Option<(f64, f64)> {
    let (nu, nv) = (su.norm(), sv.norm());
    // Which parameter collapses, if any: its partial is negligible beside the other's.
    let u_collapsed = nu <= 1e-9 * nv;
    if u_collapsed == (nv <= 1e-9 * nu) || !(nu.is_finite() && nv.is_finite()) {
        return None;
    }
    let to_p = p - s.eval(u, v);
    if to_p.norm_squared() == 0.0 {
        return None;
    }
    // Leaving inward from a bound of the other parameter: its partial's sign as the domain allows.
    let inward = if (u_collapsed && v >= vb) || (!u_collapsed && u >= ub) { -1.0 } else { 1.0 };
    let toward = |x: f64| -> f64 {
        let (uu, vv) = if u_collapsed { (x, v) } else { (u, x) };
        let e = s.derivs(uu, vv, 1);
        let t = if u_collapsed { e[(0, 1)] } else { e[(1, 0)] };
        let n = t.norm();
        if n > 0.0 {
            inward * t.dot(&to_p) / n
        } else {
            f64::NEG_INFINITY
        }
    };
    let (a, b) = if u_collapsed { (ua, ub) } else { (va, vb) };
    let (best, _) = (0..=POLE_SCAN)
        .map(|k| a + (b - a) * k as f64 / POLE_SCAN as f64)
        .map(|x| (x, toward(x)))
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
    Some(if u_collapsed { (best, v) } else { (u, best) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::{AnalyticSurface, Placement, Sphere};
    use crate::Side;
    use rand::{Rng, SeedableRng};
    use rand_xorshift::XorShiftRng;

    /// Projection of a point at normal offset `d` recovers the parameters: Newton with a
    /// tight `tol` ends at rounding level; 1e-9 leaves room for ill-conditioning at
    /// higher curvature.
    const PARAM_RECOVERY: f64 = 1e-9;
    /// Distances are recovered to near rounding.
    const DISTANCE_RECOVERY: f64 = 1e-10;

    fn wavy_surface() -> NurbsSurface {
        // Bicubic 6 × 5 net over [0, 2] × [0, 1] with interior knots; heights form a bump.
        let (n_u, n_v) = (6, 5);
        let mut pts = Vec::new();
        for i in 0..n_u {
            for j in 0..n_v {
                let (x, y) = (2.0 * i as f64 / (n_u - 1) as f64, j as f64 / (n_v - 1) as f64);
                pts.push(Point3::new(x, y, 0.3 * (x * 2.0).sin() * (y * 3.0).cos()));
            }
        }
        let w: Vec<f64> = (0..n_u * n_v).map(|k| 1.0 + 0.3 * ((k * 7) % 5) as f64 / 5.0).collect();
        NurbsSurface::new(
            (3, 2),
            (
                KnotVector::try_new(vec![0., 0., 0., 0., 0.7, 1.3, 2., 2., 2., 2.]).unwrap(),
                KnotVector::try_new(vec![0., 0., 0., 0.4, 0.6, 1., 1., 1.]).unwrap(),
            ),
            (n_u, n_v),
            pts,
            Some(w),
        )
    }

    fn space_curve() -> NurbsCurve {
        NurbsCurve::new(
            3,
            KnotVector::try_new(vec![0., 0., 0., 0., 0.3, 0.6, 1., 1., 1., 1.]).unwrap(),
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.2),
                Point3::new(2.0, -0.5, 0.5),
                Point3::new(3.0, 0.8, 0.0),
                Point3::new(4.0, 0.0, -0.4),
                Point3::new(5.0, 0.5, 0.0),
            ],
            Some(vec![1.0, 1.2, 0.8, 1.0, 1.1, 1.0]),
        )
    }

    #[test]
    fn a_kept_sample_table_projects_as_the_curve_does() {
        let c = space_curve();
        let projector = CurveProjector::new(&c);
        let mut rng = XorShiftRng::seed_from_u64(13);
        for _ in 0..200 {
            let p = Point3::new(rng.gen_range(-1.0..6.0), rng.gen_range(-2.0..2.0), rng.gen_range(-1.0..1.0));
            let (a, b) = (c.project(&p, 1e-12), projector.project(&p, 1e-12));
            assert_eq!((a.t.to_bits(), a.distance_sq.to_bits()), (b.t.to_bits(), b.distance_sq.to_bits()), "{p}");
        }
    }

    fn brute_curve(c: &NurbsCurve, p: &Point3<f64>, n: usize) -> f64 {
        (0..=n).map(|i| (c.eval(i as f64 / n as f64) - p).norm_squared()).fold(f64::INFINITY, f64::min)
    }

    fn brute_surface(s: &NurbsSurface, p: &Point3<f64>, n: usize) -> f64 {
        let (du, dv) = s.domain();
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n {
                let u = du.start() + (du.end() - du.start()) * i as f64 / n as f64;
                let v = dv.start() + (dv.end() - dv.start()) * j as f64 / n as f64;
                best = best.min((s.eval(u, v) - p).norm_squared());
            }
        }
        best
    }

    #[test]
    fn curve_normal_offsets_project_back() {
        let c = space_curve();
        for i in 0..=40 {
            let t = i as f64 / 40.0;
            let der = c.derivs(t, 2);
            // A unit normal: the part of the second derivative (or any vector) orthogonal to C'.
            let tan = der[1].normalize();
            let side = if i % 2 == 0 { Vector3::z() } else { Vector3::new(0.3, -1.0, 0.5) };
            let n = (side - tan * side.dot(&tan)).normalize();
            for d in [1e-3, -1e-3, 0.0] {
                let q = Point3::from(der[0]) + n * d;
                let pr = c.project(&q, 1e-12);
                assert!((pr.t - t).abs() < PARAM_RECOVERY, "t {t} d {d}: got {}", pr.t);
                assert!((pr.distance_sq.sqrt() - d.abs()).abs() < DISTANCE_RECOVERY);
                assert!((pr.point - c.eval(pr.t)).norm() == 0.0);
            }
        }
    }

    #[test]
    fn curve_points_beyond_the_ends_project_to_the_ends() {
        let c = space_curve();
        for (t, sign) in [(0.0, -1.0), (1.0, 1.0)] {
            let der = c.derivs(t, 1);
            let q = Point3::from(der[0]) + der[1].normalize() * (0.5 * sign);
            let pr = c.project(&q, 1e-12);
            assert_eq!(pr.t, t);
            assert!((pr.distance_sq - 0.25).abs() < 1e-12);
        }
    }

    #[test]
    fn curve_never_worse_than_dense_sampling() {
        let c = space_curve();
        let mut rng = XorShiftRng::seed_from_u64(1);
        for _ in 0..200 {
            let q = Point3::new(rng.gen_range(-1.0..6.0), rng.gen_range(-2.0..2.0), rng.gen_range(-1.5..1.5));
            let pr = c.project(&q, 1e-10);
            let brute = brute_curve(&c, &q, 4000);
            assert!(pr.distance_sq <= brute + 1e-12, "{q}: {} > {brute}", pr.distance_sq);
            assert!((pr.point - c.eval(pr.t)).norm() == 0.0);
        }
    }

    #[test]
    fn surface_normal_offsets_project_back() {
        let s = wavy_surface();
        let (nu, nv) = (24, 12);
        for i in 0..=nu {
            for j in 0..=nv {
                let (u, v) = (2.0 * i as f64 / nu as f64, j as f64 / nv as f64);
                let n = s.normal(u, v).unwrap();
                for d in [2e-3, -2e-3] {
                    let q = s.eval(u, v) + n.into_inner() * d;
                    let pr = s.project(&q, 1e-12);
                    assert!(
                        (pr.u - u).abs() < PARAM_RECOVERY && (pr.v - v).abs() < PARAM_RECOVERY,
                        "({u}, {v}) d {d}: got ({}, {})",
                        pr.u,
                        pr.v
                    );
                    assert!((pr.distance_sq.sqrt() - d.abs()).abs() < DISTANCE_RECOVERY);
                }
            }
        }
    }

    #[test]
    fn surface_points_beyond_edges_project_onto_the_edge() {
        let s = wavy_surface();
        for side in Side::ALL {
            let edge = s.boundary(side);
            for k in 1..10 {
                let t = k as f64 / 10.0 * if matches!(side, Side::VMin | Side::VMax) { 2.0 } else { 1.0 };
                let (u, v) = match side {
                    Side::UMin => (0.0, t),
                    Side::UMax => (2.0, t),
                    Side::VMin => (t, 0.0),
                    Side::VMax => (t, 1.0),
                };
                let d = s.eval_d1(u, v);
                // Outward in the tangent plane, across the edge, plus a bit of normal offset.
                let out = match side {
                    Side::UMin => -d.du,
                    Side::UMax => d.du,
                    Side::VMin => -d.dv,
                    Side::VMax => d.dv,
                };
                let q = d.point + out.normalize() * 0.3 + Vector3::z() * 0.1;
                let pr = s.project(&q, 1e-12);
                let on_edge = match side {
                    Side::UMin => pr.u == 0.0,
                    Side::UMax => pr.u == 2.0,
                    Side::VMin => pr.v == 0.0,
                    Side::VMax => pr.v == 1.0,
                };
                assert!(on_edge, "{side:?} {t}: ({}, {})", pr.u, pr.v);
                // Same answer as projecting onto the boundary curve.
                let pe = edge.project(&q, 1e-12);
                assert!((pr.distance_sq - pe.distance_sq).abs() < 1e-12, "{side:?} {t}");
                assert!(pr.distance_sq <= brute_surface(&s, &q, 60) + 1e-12);
            }
        }
        // Beyond a corner: the corner.
        let q = s.eval(2.0, 1.0) + Vector3::new(1.0, 1.0, 0.0);
        let pr = s.project(&q, 1e-12);
        assert_eq!((pr.u, pr.v), (2.0, 1.0));
    }

    #[test]
    fn surface_never_worse_than_dense_sampling() {
        let s = wavy_surface();
        let mut rng = XorShiftRng::seed_from_u64(7);
        for _ in 0..60 {
            let q = Point3::new(rng.gen_range(-0.5..2.5), rng.gen_range(-0.5..1.5), rng.gen_range(-1.0..1.0));
            let pr = s.project(&q, 1e-10);
            let brute = brute_surface(&s, &q, 160);
            assert!(pr.distance_sq <= brute + 1e-12, "{q}: {} > {brute}", pr.distance_sq);
            assert_eq!(pr.point, s.eval(pr.u, pr.v));
        }
    }

    /// Projects through the blanket impls (`&Box<NurbsSurface>`).
    fn through_generic<S: SurfaceProject>(s: S, q: &Point3<f64>) -> Projection {
        s.project(q, 1e-12)
    }

    #[test]
    fn sphere_projection_including_poles() {
        let sphere = Sphere::try_new(Placement::standard(), 2.0).unwrap();
        let full = std::f64::consts::TAU;
        let s = sphere.to_nurbs(0.0..=full, -std::f64::consts::FRAC_PI_2..=std::f64::consts::FRAC_PI_2).unwrap();
        let s = Box::new(s.surface);
        let mut rng = XorShiftRng::seed_from_u64(3);
        for _ in 0..100 {
            let dir = Vector3::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
            let r = rng.gen_range(0.5..4.0);
            let q = Point3::from(dir.normalize() * r);
            let pr = s.project(&q, 1e-12);
            assert!((pr.distance_sq.sqrt() - (r - 2.0).abs()).abs() < 1e-9, "{q}: {}", pr.distance_sq.sqrt());
        }
        for z in [3.0, -3.0, 1.0] {
            let pr = through_generic(&s, &Point3::new(0.0, 0.0, z));
            assert!((pr.distance_sq.sqrt() - 1.0).abs() < 1e-9);
            assert!((pr.point.z.abs() - 2.0).abs() < 1e-9);
        }
    }

    /// Points a few degrees from a pole (the fillet corner of an OCCT-written box, whose
    /// sphere has its pole on the box edge): the grid's best starts are the pole itself,
    /// where Newton cannot turn towards the point; the search must still find it.
    #[test]
    fn points_next_to_a_pole_project_onto_themselves() {
        let sphere = Sphere::try_new(Placement::standard(), 3.0).unwrap();
        let (full, half) = (std::f64::consts::TAU, std::f64::consts::FRAC_PI_2);
        let s = sphere.to_nurbs(0.0..=full, -half..=half).unwrap().surface;
        for pole in [-1.0f64, 1.0] {
            for deg in [0.5f64, 2.0, 5.0, 10.0, 15.0] {
                for az in [0.0f64, 1.0, 2.5, 4.0, 4.712_388_980_384_69, 6.0] {
                    let lat = pole * (half - deg.to_radians());
                    for off in [0.0, 0.05] {
                        let r = 3.0 + off;
                        let q = Point3::new(r * lat.cos() * az.cos(), r * lat.cos() * az.sin(), r * lat.sin());
                        let pr = s.project(&q, 1e-12);
                        assert!((pr.distance_sq.sqrt() - off).abs() < 1e-9, "{q}: {}", pr.distance_sq.sqrt());
                        let from_pole = s.project_from(&q, (0.0, pole * half), 1e-12);
                        assert!((from_pole.distance_sq.sqrt() - off).abs() < 1e-9, "{q} from the pole");
                    }
                }
            }
        }
    }

    #[test]
    fn tolerance_stops_early_but_within_tol() {
        let s = wavy_surface();
        let q = s.eval(0.9, 0.45) + s.normal(0.9, 0.45).unwrap().into_inner() * 0.05;
        let exact = s.project(&q, 0.0);
        for tol in [1e-2, 1e-4, 1e-6] {
            let pr = s.project(&q, tol);
            assert!((pr.point - exact.point).norm() <= tol, "{tol}");
        }
    }

    #[test]
    fn samples_cover_every_span() {
        let k = KnotVector::try_new(vec![0., 0., 0., 0., 0.5, 1., 1., 1., 1.]).unwrap();
        let t = span_samples(&k, 3, (0.0, 1.0));
        assert_eq!(t.len(), 2 * 5 + 1);
        assert_eq!((t[0], t[5], t[10]), (0.0, 0.5, 1.0));
        let long = KnotVector::uniform(3, 1000);
        let t = span_samples(&long, 3, (3.0, 1000.0));
        assert!(t.len() <= 2 * 997 + 1 && t.len() >= 997);
    }
}
