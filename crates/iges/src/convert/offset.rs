//! Offset surfaces `S(u, v) + d·N(u, v)` (IGES 140, OCCT `Geom_OffsetSurface`).
//!
//! The offset of a free-form surface is not a NURBS. [`approximate_offset`] builds a
//! bicubic B-spline within a stated tolerance **in the base surface's own
//! parameterisation**, so `fit(u, v)` approximates the offset point at the same `(u, v)`
//! that OCCT's `Geom_OffsetSurface` evaluates there:
//!
//! 1. Knots: the base's distinct knots (a base knot of multiplicity `m` in degree `p`
//!    leaves the offset `C^(p−m−1)`, so the cubic gets multiplicity `3 − min(p−m−1, 2)`
//!    there, at least 1), each base span first cut in 2.
//! 2. Interpolation of the true offset points at the Greville abscissae of those knots
//!    (tensor-product global interpolation, Piegl & Tiller §9.2.5; the Schoenberg–Whitney
//!    condition holds at Greville points).
//! 3. Check against the true offset on a denser grid: the quarter and middle points of
//!    every knot span in u at every interpolation v, the same in v, and the centre of every
//!    knot rectangle. Spans whose samples miss by more than the tolerance are halved (a
//!    direction's own samples decide which of its spans; the centres only when those all
//!    pass), and 2–3 repeat (at most 12 rounds, 1 000 poles in a direction and 250 000 in
//!    all).
//!
//! The returned [`OffsetFit::max_error`] is the largest deviation seen on the last check
//! grid. The tolerance is absolute; [`DEFAULT_RELATIVE_TOLERANCE`] times the base's size
//! (diagonal of the bounding box of its poles) is what [`crate::Document::surface`] uses.
//!
//! `N = S_u × S_v / |S_u × S_v|`. Where that cross product vanishes (a pole of a sphere, an
//! apex, a collapsed edge) the limit normal from inside the domain is used: with `S_u = 0`
//! it is `±S_uv × S_v`, with `S_v = 0` it is `±S_u × S_uv` (signs so that the limit is
//! taken from the interior). When that also vanishes the offset is undefined and
//! [`OffsetError::DegenerateNormal`] says where.

use cadmorph_nurbs::{basis_funs, KnotVector, NurbsSurface, Surface};
use nalgebra::{DMatrix, Point3, Vector3};

/// Default tolerance of [`approximate_offset`] as used by the IGES conversion: this
/// fraction of the base surface's size (diagonal of its poles' bounding box).
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-6;

/// Most refinement rounds.
const MAX_ROUNDS: usize = 12;
/// Most poles of the approximation.
const MAX_POLES: usize = 250_000;
/// Most poles in one direction (the interpolation solves dense systems of this size).
const MAX_POLES_PER_DIRECTION: usize = 1_000;
/// `|S_u × S_v|` below this fraction of `max(|S_u|, |S_v|)²` is a degenerate normal.
const DEGENERATE: f64 = 1e-10;
/// Sample fractions of each knot span on the check grid.
const CHECK: [f64; 3] = [0.25, 0.5, 0.75];

/// A B-spline approximation of an offset surface.
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetFit {
    /// The bicubic approximation, on the base surface's parameter domain.
    pub surface: NurbsSurface,
    /// Largest distance to the true offset found on the check grid.
    pub max_error: f64,
    /// The tolerance it was built to.
    pub tolerance: f64,
}

/// Why an offset could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OffsetError {
    /// The base surface has no normal (not even a limit normal) at `(u, v)`.
    #[error("the base surface's normal is undefined at (u, v) = ({u}, {v})")]
    DegenerateNormal {
        /// Parameter u.
        u: f64,
        /// Parameter v.
        v: f64,
    },
    /// The approximation did not reach the tolerance within the limits.
    #[error("the offset approximation stopped at error {error:e} with {poles} poles (tolerance {tolerance:e})")]
    NotConverged {
        /// Largest error of the last round.
        error: f64,
        /// The tolerance asked for.
        tolerance: f64,
        /// Poles of the last round.
        poles: usize,
    },
    /// The distance or tolerance is not a finite number (tolerance: positive).
    #[error("offset distance and tolerance must be finite, the tolerance positive")]
    BadInput,
    /// The kernel refused a knot vector or the fitted surface.
    #[error(transparent)]
    Geometry(#[from] cadmorph_nurbs::Error),
}

/// Diagonal of the bounding box of the poles of `s`.
pub fn size(s: &NurbsSurface) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in s.control_points() {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    (hi - lo).norm()
}

/// The unit normal `S_u × S_v / |S_u × S_v|` at `(u, v)`, or its limit from inside the
/// domain where the cross product vanishes.
///
/// # Errors
///
/// [`OffsetError::DegenerateNormal`] where neither exists.
pub fn unit_normal(s: &NurbsSurface, u: f64, v: f64) -> Result<Vector3<f64>, OffsetError> {
    Ok(point_normal(s, u, v)?.1)
}

fn point_normal(s: &NurbsSurface, u: f64, v: f64) -> Result<(Point3<f64>, Vector3<f64>), OffsetError> {
    let d1 = s.eval_d1(u, v);
    let (su, sv) = (d1.du, d1.dv);
    let n = su.cross(&sv);
    let big = su.norm().max(sv.norm());
    if n.norm() > DEGENERATE * big * big && n.norm().is_finite() {
        return Ok((d1.point, n / n.norm()));
    }
    let d = s.derivs(u, v, 2);
    let (su, sv) = (d[(1, 0)], d[(0, 1)]);
    let (ud, vd) = s.domain();
    let suv = d[(1, 1)];
    // Which partial collapsed, and the sign of the step into the domain.
    let (lim, scale) = if su.norm() <= sv.norm() {
        let inward = if v > (vd.start() + vd.end()) / 2.0 { -1.0 } else { 1.0 };
        (suv.cross(&sv) * inward, suv.norm() * sv.norm())
    } else {
        let inward = if u > (ud.start() + ud.end()) / 2.0 { -1.0 } else { 1.0 };
        (su.cross(&suv) * inward, su.norm() * suv.norm())
    };
    if lim.norm() > DEGENERATE * scale && lim.norm().is_finite() && scale > 0.0 {
        Ok((d1.point, lim / lim.norm()))
    } else {
        Err(OffsetError::DegenerateNormal { u, v })
    }
}

/// The true offset point `S(u, v) + d·N(u, v)`.
///
/// # Errors
///
/// As [`unit_normal`].
pub fn offset_point(s: &NurbsSurface, u: f64, v: f64, d: f64) -> Result<Point3<f64>, OffsetError> {
    let (p, n) = point_normal(s, u, v)?;
    Ok(p + n * d)
}

/// Breakpoints of one direction of the approximation: value and cubic multiplicity.
#[derive(Debug, Clone)]
struct Breaks(Vec<(f64, usize)>);

impl Breaks {
    /// From the base knots (degree `p`) over `[a, b]`, each span cut in `cuts`.
    fn from_base(knots: &KnotVector, p: usize, a: f64, b: f64, cuts: usize) -> Self {
        let (vals, mults) = knots.distinct();
        let mut out = vec![(a, 4)];
        let inner: Vec<(f64, usize)> = vals
            .iter()
            .zip(&mults)
            .filter(|(x, _)| **x > a && **x < b)
            .map(|(x, m)| {
                let cont = p as i64 - *m as i64 - 1;
                (*x, (3 - cont.clamp(0, 2)) as usize)
            })
            .collect();
        for &(x, m) in &inner {
            out.push((x, m));
        }
        out.push((b, 4));
        let mut b = Breaks(out);
        for _ in 1..cuts {
            let all: Vec<usize> = (0..b.0.len() - 1).collect();
            b.split(&all);
        }
        b
    }

    /// Halves the spans with these indices.
    fn split(&mut self, spans: &[usize]) {
        let mut out = Vec::with_capacity(self.0.len() + spans.len());
        for (i, w) in self.0.windows(2).enumerate() {
            out.push(w[0]);
            if spans.contains(&i) {
                out.push(((w[0].0 + w[1].0) / 2.0, 1));
            }
        }
        out.push(*self.0.last().expect("two breakpoints"));
        self.0 = out;
    }

    fn knots(&self) -> Vec<f64> {
        self.0.iter().flat_map(|&(x, m)| std::iter::repeat_n(x, m)).collect()
    }

    fn spans(&self) -> usize {
        self.0.len() - 1
    }
}

/// Greville abscissae of a cubic knot vector.
fn greville(k: &[f64]) -> Vec<f64> {
    (0..k.len() - 4).map(|i| (k[i + 1] + k[i + 2] + k[i + 3]) / 3.0).collect()
}

/// The collocation matrix `N_j(t_i)` of a cubic knot vector.
fn collocation(k: &KnotVector, t: &[f64]) -> DMatrix<f64> {
    let n = t.len();
    let mut m = DMatrix::zeros(n, n);
    for (i, &x) in t.iter().enumerate() {
        let span = k.find_span(3, x);
        for (r, b) in basis_funs(k, 3, x).into_iter().enumerate() {
            let j = span + r - 3;
            if j < n {
                m[(i, j)] = b;
            }
        }
    }
    m
}

/// A bicubic B-spline approximation of the offset of `base` by `distance` along its unit
/// normal, within `tolerance` (absolute, model units) on the check grid, on the base's
/// parameter domain.
///
/// # Errors
///
/// [`OffsetError::DegenerateNormal`] where the base has no normal,
/// [`OffsetError::NotConverged`] when 12 refinements, 1 000 poles in a direction or
/// 250 000 in all do not reach the tolerance (a distance beyond the radius of curvature folds the offset),
/// [`OffsetError::BadInput`] for a non-finite distance or a tolerance that is not a
/// positive number.
///
/// # Examples
///
/// ```
/// use cadmorph_iges::convert::offset::{approximate_offset, offset_point};
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Cylinder, Placement};
/// use cadmorph_nurbs::Surface;
/// let cyl = Cylinder::try_new(Placement::standard(), 2.0).unwrap().to_nurbs(0.0..=3.0, 0.0..=1.0).unwrap();
/// let fit = approximate_offset(&cyl.surface, 0.5, 1e-7).unwrap();
/// assert!(fit.max_error <= 1e-6);
/// let p = fit.surface.eval(1.0, 0.5);
/// assert!(((p.x * p.x + p.y * p.y).sqrt() - 2.5).abs() < 1e-7);
/// ```
pub fn approximate_offset(base: &NurbsSurface, distance: f64, tolerance: f64) -> Result<OffsetFit, OffsetError> {
    if !(distance.is_finite() && tolerance.is_finite() && tolerance > 0.0) {
        return Err(OffsetError::BadInput);
    }
    let (ud, vd) = base.domain();
    let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
    let mut bu = Breaks::from_base(base.u_knots(), base.u_degree(), u0, u1, 2);
    let mut bv = Breaks::from_base(base.v_knots(), base.v_degree(), v0, v1, 2);
    let mut last = (f64::INFINITY, 0);
    for _ in 0..MAX_ROUNDS {
        let (ku, kv) = (bu.knots(), bv.knots());
        let (tu, tv) = (greville(&ku), greville(&kv));
        let (nu, nv) = (tu.len(), tv.len());
        if nu.saturating_mul(nv) > MAX_POLES || nu.max(nv) > MAX_POLES_PER_DIRECTION {
            break;
        }
        let (ku, kv) = (KnotVector::try_new(ku)?, KnotVector::try_new(kv)?);
        // Right-hand sides: for each u row, the offset points along v (3 columns each).
        let mut q = DMatrix::zeros(nu, 3 * nv);
        for (i, &u) in tu.iter().enumerate() {
            for (j, &v) in tv.iter().enumerate() {
                let p = offset_point(base, u, v, distance)?;
                for c in 0..3 {
                    q[(i, 3 * j + c)] = p[c];
                }
            }
        }
        let singular = || OffsetError::NotConverged { error: f64::INFINITY, tolerance, poles: nu * nv };
        // Along u: N_u R = Q.
        let r = collocation(&ku, &tu).lu().solve(&q).ok_or_else(singular)?;
        // Along v: N_v Pᵢ = Rᵢ for every row i; as one system with the rows as columns.
        let mut rt = DMatrix::zeros(nv, 3 * nu);
        for i in 0..nu {
            for j in 0..nv {
                for c in 0..3 {
                    rt[(j, 3 * i + c)] = r[(i, 3 * j + c)];
                }
            }
        }
        let pt = collocation(&kv, &tv).lu().solve(&rt).ok_or_else(singular)?;
        let mut points = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                points.push(Point3::new(pt[(j, 3 * i)], pt[(j, 3 * i + 1)], pt[(j, 3 * i + 2)]));
            }
        }
        let fit = NurbsSurface::try_new((3, 3), (ku, kv), (nu, nv), points, None)?;
        // Check between the interpolation points.
        let samples = |b: &Breaks| -> Vec<(usize, f64)> {
            let mut out = Vec::new();
            for (k, w) in b.0.windows(2).enumerate() {
                out.extend(CHECK.iter().map(|f| (k, w[0].0 + f * (w[1].0 - w[0].0))));
            }
            out
        };
        let (su, sv) = (samples(&bu), samples(&bv));
        let mut bad_u = vec![false; bu.spans()];
        let mut bad_v = vec![false; bv.spans()];
        let mut worst = 0.0f64;
        let mut check = |u: f64, v: f64| -> Result<bool, OffsetError> {
            let e = (fit.eval(u, v) - offset_point(base, u, v, distance)?).norm();
            worst = if e.is_nan() { f64::INFINITY } else { worst.max(e) };
            Ok(e.is_nan() || e > tolerance)
        };
        // Between the interpolation points along u (at the v ones): u's share of the error;
        // the same along v; then the cross grid.
        for &(ki, u) in &su {
            for &v in &tv {
                if check(u, v)? {
                    bad_u[ki] = true;
                }
            }
        }
        for &u in &tu {
            for &(kj, v) in &sv {
                if check(u, v)? {
                    bad_v[kj] = true;
                }
            }
        }
        let mut cross = Vec::new();
        for (ki, w) in bu.0.windows(2).enumerate() {
            for (kj, x) in bv.0.windows(2).enumerate() {
                if check((w[0].0 + w[1].0) / 2.0, (x[0].0 + x[1].0) / 2.0)? {
                    cross.push((ki, kj));
                }
            }
        }
        if !bad_u.iter().chain(&bad_v).any(|x| *x) {
            for (ki, kj) in cross {
                bad_u[ki] = true;
                bad_v[kj] = true;
            }
        }
        if worst <= tolerance {
            return Ok(OffsetFit { surface: fit, max_error: worst, tolerance });
        }
        last = (worst, nu * nv);
        let idx = |b: &[bool]| -> Vec<usize> { b.iter().enumerate().filter(|(_, x)| **x).map(|(i, _)| i).collect() };
        bu.split(&idx(&bad_u));
        bv.split(&idx(&bad_v));
    }
    Err(OffsetError::NotConverged { error: last.0, tolerance, poles: last.1 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_nurbs::analytic::{AnalyticSurface, Cylinder, Placement, Sphere, Torus};
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    #[test]
    fn sphere_offset_is_a_bigger_sphere_poles_included() {
        let r = 3.0;
        let s = Sphere::try_new(Placement::standard(), r).unwrap().to_nurbs(0.0..=TAU, -FRAC_PI_2..=FRAC_PI_2).unwrap();
        for d in [0.5, -1.0] {
            let fit = approximate_offset(&s.surface, d, 1e-6).unwrap();
            assert!(fit.max_error <= 1e-6);
            let (ud, vd) = fit.surface.domain();
            let mut worst = 0.0f64;
            for i in 0..=40 {
                for j in 0..=40 {
                    let u = ud.start() + (ud.end() - ud.start()) * i as f64 / 40.0;
                    let v = vd.start() + (vd.end() - vd.start()) * j as f64 / 40.0;
                    let p = fit.surface.eval(u, v);
                    worst = worst.max((p.coords.norm() - (r + d)).abs());
                    // Same parameterisation as the base: the point is radially above S(u, v).
                    let q = s.surface.eval(u, v);
                    worst = worst.max((p.coords - q.coords * ((r + d) / r)).norm());
                }
            }
            assert!(worst <= 1e-6, "d = {d}: {worst:e}");
        }
    }

    #[test]
    fn torus_and_cylinder_offsets() {
        let t = Torus::try_new(Placement::standard(), 5.0, 1.0).unwrap().to_nurbs(0.0..=TAU, -PI..=PI).unwrap();
        let fit = approximate_offset(&t.surface, 0.25, 1e-6).unwrap();
        let (ud, vd) = fit.surface.domain();
        for i in 0..=30 {
            for j in 0..=30 {
                let u = ud.start() + (ud.end() - ud.start()) * i as f64 / 30.0;
                let v = vd.start() + (vd.end() - vd.start()) * j as f64 / 30.0;
                let p = fit.surface.eval(u, v);
                let rho = p.x.hypot(p.y) - 5.0;
                let e = (rho.hypot(p.z) - 1.25).abs();
                assert!(e <= 1e-6, "{e:e}");
            }
        }
        let c = Cylinder::try_new(Placement::standard(), 1.0).unwrap().to_nurbs(0.0..=PI, -1.0..=1.0).unwrap();
        let fit = approximate_offset(&c.surface, -0.5, 1e-8).unwrap();
        assert!(fit.max_error <= 1e-8);
    }

    #[test]
    fn degenerate_normals_are_errors() {
        // All poles of one column coincide and the next column too: no limit normal.
        let k = KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).unwrap();
        let p = Point3::origin();
        let s = NurbsSurface::try_new((1, 1), (k.clone(), k), (2, 2), vec![p; 4], None).unwrap();
        assert!(matches!(approximate_offset(&s, 1.0, 1e-6), Err(OffsetError::DegenerateNormal { .. })));
        assert!(matches!(approximate_offset(&s, f64::NAN, 1e-6), Err(OffsetError::BadInput)));
        assert!(matches!(approximate_offset(&s, 1.0, 0.0), Err(OffsetError::BadInput)));
    }
}
