//! The parameter box of a face on an analytic surface, from its edges.
//!
//! Each edge is sampled in 3D and every sample is inverted onto the surface in closed
//! form (planes, cylinders, cones, spheres, tori), by rotation and curve projection
//! (revolutions) or by projection along the direction (extrusions). Angles are unwrapped
//! along each edge, and the face's angular range is the complement of the largest gap
//! left by the union of the edges' arcs; an edge that goes all the way round gives a full
//! turn starting at its first point.
//!
//! Where the extremes along an edge are known in closed form (a line on a plane, a
//! cylinder's or cone's generator, a conic on a plane, a circle about the axis of a surface
//! of revolution type, a torus's meridian circle: the edges of most analytic B-reps), only
//! the edge's ends and those extremes are inverted ([`closed_form_params`]); other edges
//! are sampled and each sample's extreme sharpened by a one-dimensional search (Brent's).

use std::f64::consts::TAU;

use cadmorph_nurbs::analytic::{AnalyticCurve, AnalyticSurface};
use cadmorph_nurbs::math::{Matrix4, Point3, Vector3};
use cadmorph_nurbs::{Curve, CurveProject};

use super::geometry::{CurveGeom, SurfaceGeom};
use super::{Ctx, Face};
use crate::error::{Error, Result};

/// Samples per edge (plus its ends).
const EDGE_SAMPLES: usize = 24;

/// One parameter direction: periodic (an angle, or the parameter of a closed basis
/// curve: values taken modulo `period` into `[start, start + period)`) or linear.
#[derive(Clone, Copy, PartialEq)]
enum Dir {
    Periodic { start: f64, period: f64 },
    Linear,
}

/// Angles: periodic with period 2π from 0.
const ANGLE: Dir = Dir::Periodic { start: 0.0, period: TAU };

/// The parameter of a basis curve: periodic over its domain when the curve closes on
/// itself (its ends within `1e-9 ×` its size: a closed B-spline profile of an
/// extrusion, whose seam the face's edges cross), linear otherwise.
fn curve_dir(c: &cadmorph_nurbs::NurbsCurve) -> Dir {
    let pts = c.control_points();
    let size = pts.iter().fold(0.0f64, |m, p| m.max((p - pts[0]).norm()));
    let dom = c.domain();
    let (a, b) = (c.eval(*dom.start()), c.eval(*dom.end()));
    if size > 0.0 && (a - b).norm() <= 1e-9 * size {
        Dir::Periodic { start: *dom.start(), period: dom.end() - dom.start() }
    } else {
        Dir::Linear
    }
}

impl Ctx<'_> {
    pub fn face_box(&self, face: &Face, g: &SurfaceGeom) -> Result<((f64, f64), (f64, f64))> {
        let (du, dv) = match g {
            SurfaceGeom::Plane(_) => (Dir::Linear, Dir::Linear),
            SurfaceGeom::Extrusion(s) => (curve_dir(s.curve()), Dir::Linear),
            SurfaceGeom::Cylinder(_) | SurfaceGeom::Cone(_) => (ANGLE, Dir::Linear),
            SurfaceGeom::Revolution(s) => (ANGLE, curve_dir(s.curve())),
            SurfaceGeom::Sphere(_) => (ANGLE, Dir::Linear),
            SurfaceGeom::Torus(_) => (ANGLE, ANGLE),
            _ => (Dir::Linear, Dir::Linear),
        };
        // Per edge: the (u, v) of its samples, in order; u is None where undefined (poles).
        let mut edges: Vec<Vec<(Option<f64>, f64)>> = Vec::new();
        let mut any_edge = false;
        for &(_, lp, _) in &face.bounds {
            let lp_edges = self.loop_edges(lp)?;
            if lp_edges.is_empty() {
                // A vertex loop (apex of a cone, pole of a sphere).
                let r = self.any(lp)?;
                if r.name() == "VERTEX_LOOP" {
                    r.arity(2)?;
                    let vr = self.simple(r.reference(1)?, "VERTEX_POINT")?;
                    vr.arity(2)?;
                    let p = self.point(vr.reference(1)?)?;
                    edges.push(vec![invert(g, &p)]);
                }
                continue;
            }
            for (e, _) in lp_edges {
                any_edge = true;
                let eg = self.edge_geometry(e)?;
                let (c, t0, t1) = (&eg.0, eg.1, eg.2);
                if let Some(ts) = closed_form_params(g, c, t0, t1) {
                    edges.push(ts.into_iter().map(|t| invert(g, &c.eval(t))).collect());
                    continue;
                }
                let mut pts: Vec<(f64, (Option<f64>, f64))> = (0..=EDGE_SAMPLES)
                    .map(|i| {
                        let t = t0 + (t1 - t0) * i as f64 / EDGE_SAMPLES as f64;
                        (t, invert(g, &c.eval(t)))
                    })
                    .collect();
                // Sharpen the extremes of each coordinate between their neighbours.
                let mut extra = Vec::new();
                for coord in 0..2 {
                    let val = |s: &(Option<f64>, f64)| if coord == 0 { s.0 } else { Some(s.1) };
                    let period = match if coord == 0 { du } else { dv } {
                        Dir::Periodic { period, .. } => Some(period),
                        Dir::Linear => None,
                    };
                    for sign in [1.0, -1.0] {
                        let best = (0..pts.len())
                            .filter_map(|i| val(&pts[i].1).map(|x| (i, x)))
                            .max_by(|a, b| (sign * a.1).total_cmp(&(sign * b.1)));
                        let Some((i, x0)) = best else { continue };
                        let lo = pts[i.saturating_sub(1)].0;
                        let hi = pts[(i + 1).min(pts.len() - 1)].0;
                        let f = |t: f64| -> f64 {
                            match val(&invert_with(g, &c.eval(t), SHARPEN_AXIS)) {
                                Some(mut x) => {
                                    if let Some(p) = period {
                                        x += ((x0 - x) / p).round() * p;
                                    }
                                    sign * x
                                }
                                None => f64::NEG_INFINITY,
                            }
                        };
                        let t = brent_max(f, lo, pts[i].0, hi);
                        extra.push((t, invert(g, &c.eval(t))));
                    }
                }
                pts.extend(extra);
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                edges.push(pts.into_iter().map(|x| x.1).collect());
            }
        }
        let bad = || Error::Geometry {
            at: self.doc.position_of_id(face.id),
            source: cadmorph_nurbs::Error::EmptyDomain { start: 0.0, end: 0.0 },
        };
        if !any_edge {
            // Bounded by vertex loops alone (OCCT writes a whole surface of revolution of
            // a profile from the axis to the axis so: its seam and pole edges dropped, one
            // VERTEX_LOOP at a pole): the face is the whole closed surface.
            return match g {
                SurfaceGeom::Sphere(_) => Ok(((0.0, TAU), (-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2))),
                SurfaceGeom::Torus(_) => Ok(((0.0, TAU), (0.0, TAU))),
                SurfaceGeom::Revolution(s) => {
                    let d = s.curve().domain();
                    Ok(((0.0, TAU), (*d.start(), *d.end())))
                }
                _ => Err(bad()),
            };
        }
        let us: Vec<Vec<f64>> = edges.iter().map(|e| e.iter().filter_map(|s| s.0).collect()).collect();
        let vs: Vec<Vec<f64>> = edges.iter().map(|e| e.iter().map(|s| s.1).collect()).collect();
        let u = range(&us, du).ok_or_else(bad)?;
        let mut v = range(&vs, dv).ok_or_else(bad)?;
        if let SurfaceGeom::Sphere(_) = g {
            v = (v.0.max(-std::f64::consts::FRAC_PI_2), v.1.min(std::f64::consts::FRAC_PI_2));
        }
        if !(u.1 > u.0 && v.1 > v.0) {
            return Err(bad());
        }
        Ok((u, v))
    }
}

/// Directions within this sine of each other are parallel, and a centre within this
/// fraction of the radius from an axis is on it, for [`closed_form_params`]. A STEP
/// writer's 15 significant digits leave about 1e-15; a condition met only to a coarser
/// `PARALLEL` goes the sampled way, which is always right.
const PARALLEL: f64 = 1e-12;

/// Parameters of the edge `c` over `[t0, t1]`, in increasing order, among which the face
/// coordinates (u, v) of `g` reach every extreme along the edge and consecutive angles
/// differ by less than half a turn (so that [`range`] unwraps them), when that is known in
/// closed form; `None` otherwise.
///
/// - A line on a plane: u and v are affine along it, so its ends.
/// - A line along a cylinder's axis or an extrusion's direction: u is constant and v
///   affine; a line on a cone whose ends have the same angle is a generator that does not
///   pass the apex: u constant, v affine. Its ends.
/// - A conic `O + a cos t X + b sin t Y` on a plane: each coordinate is
///   `c₀ + α cos t + β sin t`, extreme where `tan t = β / α` (at `atan2(β, α) + kπ`);
///   those inside the edge and its ends.
/// - A polynomial B-spline (or polyline) on a plane: u and v are the curve's coordinates
///   along the plane's axes, extreme where their derivatives change sign on a Bézier
///   piece or at a knot ([`NurbsCurve::extreme_params`](cadmorph_nurbs::NurbsCurve::extreme_params));
///   those and its ends. Rational curves go the sampled way.
/// - A circle about the axis of a cylinder, cone, sphere, torus or surface of revolution
///   (its normal along the axis, its centre on it): v is constant and u moves with t, so
///   its ends and points at most a quarter turn apart for the unwrapping; a torus's
///   meridian circle (the tube's radius, centred on the major circle, in a plane through
///   the axis): u constant, v moving with t, likewise.
fn closed_form_params(g: &SurfaceGeom, c: &CurveGeom, t0: f64, t1: f64) -> Option<Vec<f64>> {
    let mut c = c;
    while let CurveGeom::Trimmed { basis, .. } = c {
        c = basis;
    }
    let parallel = |a: Vector3<f64>, b: Vector3<f64>| a.cross(&b).norm() <= PARALLEL * a.norm() * b.norm();
    let turning = || {
        let n = ((t1 - t0) / std::f64::consts::FRAC_PI_2).ceil().max(1.0) as usize;
        (0..=n).map(|i| if i == n { t1 } else { t0 + (t1 - t0) * i as f64 / n as f64 }).collect()
    };
    // A circle whose normal is along `axis` and whose centre is on the axis through `o`.
    let coaxial = |frame: &cadmorph_nurbs::analytic::Placement, a: f64, b: f64, o: Point3<f64>, axis: Vector3<f64>| {
        (a - b).abs() <= PARALLEL * a
            && parallel(frame.z_dir(), axis)
            && (frame.origin() - o).cross(&axis).norm() <= PARALLEL * a.max((frame.origin() - o).norm()) * axis.norm()
    };
    match (c, g) {
        (CurveGeom::Line(_), SurfaceGeom::Plane(_)) => Some(vec![t0, t1]),
        (CurveGeom::Line(l), SurfaceGeom::Cylinder(s)) if parallel(l.deriv(t0), s.placement().z_dir()) => {
            Some(vec![t0, t1])
        }
        (CurveGeom::Line(l), SurfaceGeom::Extrusion(s)) if parallel(l.deriv(t0), s.direction()) => Some(vec![t0, t1]),
        (CurveGeom::Line(l), SurfaceGeom::Cone(_)) => {
            let (u0, u1) = (invert(g, &l.eval(t0)).0?, invert(g, &l.eval(t1)).0?);
            let d = (u1 - u0).rem_euclid(TAU);
            (d.min(TAU - d) <= PARALLEL * TAU).then(|| vec![t0, t1])
        }
        (CurveGeom::Conic { frame, a, b }, SurfaceGeom::Plane(s)) => {
            let mut ts = vec![t0, t1];
            for e in [s.placement.x_dir(), s.placement.y_dir()] {
                let (alpha, beta) = (a * frame.x_dir().dot(&e), b * frame.y_dir().dot(&e));
                if alpha == 0.0 && beta == 0.0 {
                    continue;
                }
                let first = beta.atan2(alpha);
                // Every first + kπ inside (t0, t1).
                let mut t = first + ((t0 - first) / std::f64::consts::PI).ceil() * std::f64::consts::PI;
                while t < t1 {
                    if t > t0 {
                        ts.push(t);
                    }
                    t += std::f64::consts::PI;
                }
            }
            ts.sort_by(f64::total_cmp);
            Some(ts)
        }
        (CurveGeom::Nurbs(n) | CurveGeom::Polyline(n), SurfaceGeom::Plane(s)) => {
            let mut ts = vec![t0, t1];
            for e in [s.placement.x_dir(), s.placement.y_dir()] {
                ts.extend(n.extreme_params(&e, t0, t1)?);
            }
            ts.sort_by(f64::total_cmp);
            ts.dedup();
            Some(ts)
        }
        (CurveGeom::Conic { frame, a, b }, _) => {
            let about = match g {
                SurfaceGeom::Cylinder(s) => Some((s.placement().origin(), s.placement().z_dir())),
                SurfaceGeom::Cone(s) => Some((s.placement().origin(), s.placement().z_dir())),
                SurfaceGeom::Sphere(s) => Some((s.placement().origin(), s.placement().z_dir())),
                SurfaceGeom::Torus(s) => Some((s.placement().origin(), s.placement().z_dir())),
                SurfaceGeom::Revolution(s) => Some((s.axis_point(), s.axis_direction())),
                _ => None,
            }?;
            if coaxial(frame, *a, *b, about.0, about.1) {
                return Some(turning());
            }
            let SurfaceGeom::Torus(s) = g else { return None };
            // A meridian circle of a ring torus.
            let (o, z) = (s.placement().origin(), s.placement().z_dir());
            let radial = frame.origin() - o;
            let (big, small) = (s.major_radius(), s.minor_radius());
            let meridian = small < big
                && (a - small).abs() <= PARALLEL * big
                && (b - small).abs() <= PARALLEL * big
                && radial.dot(&z).abs() <= PARALLEL * big
                && (radial.norm() - big).abs() <= PARALLEL * big
                && parallel(frame.z_dir(), z.cross(&radial));
            meridian.then(turning)
        }
        _ => None,
    }
}

/// Distance from the axis (relative to the surface's scale) inside which the golden-section
/// sharpening of an angular extreme does not trust a sample's angle. The angle of a point
/// at distance `d` from the axis carries the error `δ / d` of the file's rounding `δ` (an
/// edge circle's 12-digit plane passes ~1e-11 beside a sphere's pole): searched for its
/// largest value near a pole, that noise is what the search finds (7.5e-7 rad, a 2.2e-6 mm
/// gap on an OCCT fillet corner, where the 24 evenly spaced samples alone give 1e-11).
/// Sharpening only refines those samples, so leaving out its last 1 % around a pole
/// loses nothing they found.
const SHARPEN_AXIS: f64 = 1e-2;

/// The file's (u, v) of a point on (or near) the surface; u is `None` on the axis of a
/// surface of revolution type.
fn invert(g: &SurfaceGeom, p: &Point3<f64>) -> (Option<f64>, f64) {
    invert_with(g, p, 0.0)
}

/// [`invert`], with u also `None` within `axis × scale` of the axis (see [`SHARPEN_AXIS`]).
fn invert_with(g: &SurfaceGeom, p: &Point3<f64>, axis: f64) -> (Option<f64>, f64) {
    let local = |f: &cadmorph_nurbs::analytic::Placement| {
        let d = p - f.origin();
        (d.dot(&f.x_dir()), d.dot(&f.y_dir()), d.dot(&f.z_dir()))
    };
    // Within 1e-6 of `scale` from the axis (a sphere's pole, a cone's apex) the angle is
    // rounding noise (the point's own rounding over its tiny distance from the axis):
    // taken there, it widens the face's box by up to 1e-5 rad, and the face's
    // iso-boundary then misses its edge (2.6e-5 on an OCCT fillet corner whose pole is an
    // end of its edges). Such samples bound only the other parameter.
    let angle = |x: f64, y: f64, scale: f64| (x.hypot(y) > axis.max(1e-6) * scale.max(1e-300)).then(|| y.atan2(x));
    match g {
        SurfaceGeom::Plane(s) => {
            let (x, y, _) = local(&s.placement);
            (Some(x), y)
        }
        SurfaceGeom::Cylinder(s) => {
            let (x, y, z) = local(s.placement());
            (angle(x, y, s.radius()), z)
        }
        SurfaceGeom::Cone(s) => {
            let (x, y, z) = local(s.placement());
            let v = z / s.semi_angle().cos();
            let rho = s.radius() + v * s.semi_angle().sin();
            let u = angle(x, y, s.radius().max(1.0)).map(|a| if rho < 0.0 { a + std::f64::consts::PI } else { a });
            (u, v)
        }
        SurfaceGeom::Sphere(s) => {
            let (x, y, z) = local(s.placement());
            (angle(x, y, s.radius()), z.atan2(x.hypot(y)))
        }
        SurfaceGeom::Torus(s) => {
            let (x, y, z) = local(s.placement());
            let rho = x.hypot(y) - s.major_radius();
            (angle(x, y, s.major_radius()), z.atan2(rho))
        }
        SurfaceGeom::Revolution(s) => {
            let (o, d) = (s.axis_point(), s.axis_direction());
            let dom = s.curve().domain();
            let c0 = s.curve().eval((dom.start() + dom.end()) / 2.0);
            let radial = |q: &Point3<f64>| {
                let r = q - o;
                r - d * r.dot(&d)
            };
            let (r0, r) = (radial(&c0), radial(p));
            let scale = r0.norm().max(1.0);
            let u =
                (r.norm() > axis.max(1e-12) * scale && r0.norm() > 0.0).then(|| d.cross(&r0).dot(&r).atan2(r0.dot(&r)));
            // Rotate p back by −u about the axis, then project onto the meridian.
            let back = match u {
                Some(a) => {
                    let rot = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(d), -a);
                    o + rot * (p - o)
                }
                None => *p,
            };
            let v = s.curve().project(&back, 1e-10 * scale).t;
            (u, v)
        }
        SurfaceGeom::Extrusion(s) => {
            let d = s.direction();
            let c = s.curve();
            let o = c.control_points()[0];
            let m = flatten_along(&d, &o);
            let flat = c.transformed(&m);
            let u = flat.project(&m.transform_point(p), 1e-10).t;
            let v = (p - AnalyticSurface::eval(s, u, 0.0)).dot(&d);
            (Some(u), v)
        }
        SurfaceGeom::Nurbs(_) | SurfaceGeom::Trimmed { .. } => (Some(0.0), 0.0),
    }
}

/// The argument of the maximum of `f` on `[a, b]`, starting from `start` (the best
/// sample): Brent's method (R. P. Brent, *Algorithms for Minimization without
/// Derivatives*, 1973, ch. 5: the vertex of the parabola through the three best points
/// where it can be trusted, a golden-section step where not), to
/// `1e-9 × |t| + 1e-11 × (b − a)` in `t`. Near a smooth maximum the value's error is of
/// the order of the square of that. The first parabola goes through the bracket's ends
/// and the start, the samples the bracket was chosen from.
fn brent_max(f: impl Fn(f64) -> f64, mut a: f64, start: f64, mut b: f64) -> f64 {
    let g = |t: f64| -f(t);
    let golden = (3.0 - 5f64.sqrt()) / 2.0;
    let abs_tol = 1e-11 * (b - a).abs();
    // The three points ordered best first (x), then w, then v.
    let start = if start > a && start < b { start } else { a + golden * (b - a) };
    let mut three = [(start, g(start)), (a, g(a)), (b, g(b))];
    three.sort_by(|p, q| p.1.total_cmp(&q.1));
    let [(mut x, mut fx), (mut w, mut fw), (mut v, mut fv)] = three;
    // A first step as large as the bracket lets the first parabola be tried.
    let (mut d, mut e) = (0.0f64, b - a);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        let tol1 = 1e-9 * x.abs() + abs_tol;
        let tol2 = 2.0 * tol1;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol1 {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let e_prev = e;
            e = d;
            // The vertex must fall inside the bracket and move less than half the step
            // before last (else the parabola is not converging); NaN fails every test.
            if p.abs() < (0.5 * q * e_prev).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if x < m { b - x } else { a - x };
            d = golden * e;
        }
        let u = if d.abs() >= tol1 { x + d } else { x + tol1.copysign(d) };
        let fu = g(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    x
}

/// The affine projection onto the plane through `o` normal to `d` (unit).
fn flatten_along(d: &Vector3<f64>, o: &Point3<f64>) -> Matrix4<f64> {
    let lin = nalgebra::Matrix3::identity() - d * d.transpose();
    let t = o.coords - lin * o.coords;
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&lin);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
    m
}

/// The range of one direction over all edges' samples.
fn range(edges: &[Vec<f64>], dir: Dir) -> Option<(f64, f64)> {
    let all: Vec<f64> = edges.iter().flatten().copied().filter(|x| x.is_finite()).collect();
    if all.is_empty() {
        return None;
    }
    let (origin, period) = match dir {
        Dir::Linear => {
            let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            return Some((lo, hi));
        }
        Dir::Periodic { start, period } => (start, period),
    };
    let half = period / 2.0;
    let normalize = |a: f64| normalize(a, origin, period);
    // Unwrap each edge; collect its arc [start, end] with start in [origin, origin + period).
    let mut arcs: Vec<(f64, f64)> = Vec::new();
    for e in edges {
        let mut it = e.iter().copied().filter(|x| x.is_finite());
        let Some(first) = it.next() else { continue };
        let (mut prev, mut lo, mut hi) = (first, first, first);
        for mut a in it {
            while a - prev > half {
                a -= period;
            }
            while prev - a > half {
                a += period;
            }
            lo = lo.min(a);
            hi = hi.max(a);
            prev = a;
        }
        if hi - lo >= period * (1.0 - 1e-9) {
            let s = normalize(first);
            return Some((s, s + period));
        }
        let s = normalize(lo);
        arcs.push((s, s + (hi - lo)));
    }
    arcs.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Merge on the circle and find the largest uncovered gap.
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (s, e) in arcs {
        match merged.last_mut() {
            Some(last) if s <= last.1 + 1e-12 => last.1 = last.1.max(e),
            _ => merged.push((s, e)),
        }
    }
    let n = merged.len();
    let mut best_gap = -1.0;
    let mut start = merged[0].0;
    for i in 0..n {
        let end = merged[i].1;
        let next = if i + 1 < n { merged[i + 1].0 } else { merged[0].0 + period };
        let gap = next - end;
        if gap > best_gap {
            best_gap = gap;
            start = next;
        }
    }
    if best_gap <= 1e-9 * period {
        let s = normalize(merged[0].0);
        return Some((s, s + period));
    }
    let s = normalize(start);
    Some((s, s + period - best_gap))
}

/// A periodic value in `[origin, origin + period)`, with values a rounding error below
/// either end taken as `origin`.
fn normalize(a: f64, origin: f64, period: f64) -> f64 {
    let mut x = (a - origin).rem_euclid(period);
    if x > period * (1.0 - 1e-9) {
        x = 0.0;
    }
    if x.abs() < 1e-12 * period {
        origin
    } else {
        origin + x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brent's search finds the maxima of smooth functions to the value's rounding, with
    /// far fewer evaluations than a 60-step golden section, and stays inside the bracket
    /// for a maximum at an end or a function undefined on part of it.
    #[test]
    fn brent_max_finds_maxima_in_few_evaluations() {
        let count = std::cell::Cell::new(0);
        type Case<'a> = (&'a dyn Fn(f64) -> f64, f64, f64, f64);
        let cases: [Case<'_>; 5] = [
            (&|t: f64| -(t - 0.3) * (t - 0.3), 0.0, 1.0, 0.3),
            (&|t: f64| t.sin(), 0.0, 3.0, std::f64::consts::FRAC_PI_2),
            (&|t: f64| (2.0 * t).cos() + 0.1 * t, 2.0, 4.0, std::f64::consts::PI + 0.025),
            (&|t: f64| t, 0.0, 2.0, 2.0),
            (&|t: f64| if t < 0.5 { f64::NEG_INFINITY } else { -(t - 0.7f64).powi(2) }, 0.0, 1.0, 0.7),
        ];
        for (n, (f, a, b, want)) in cases.into_iter().enumerate() {
            count.set(0);
            let t = brent_max(
                |t| {
                    count.set(count.get() + 1);
                    f(t)
                },
                a,
                (a + b) / 2.0,
                b,
            );
            assert!((a..=b).contains(&t), "case {n}: {t}");
            // The value is what matters: within rounding of the true maximum.
            let (ft, fw) = (f(t), f(want));
            assert!(fw - ft <= 1e-13 * fw.abs().max(1.0), "case {n}: f({t}) = {ft}, f({want}) = {fw}");
            assert!(count.get() <= 60, "case {n}: {} evaluations", count.get());
        }
    }

    /// The closed-form parameters of each kind of edge give the same (u, v) range as
    /// 20 001 evenly spaced points (they are points of the edge, so never wider, and
    /// must not be narrower); edges with no closed form are left to the search.
    #[test]
    fn closed_form_extremes_bound_the_whole_edge() {
        use cadmorph_nurbs::analytic::{Cone, Cylinder, Line, Placement, Plane, Torus};
        let frame = |o: [f64; 3], z: [f64; 3], x: [f64; 3]| {
            Placement::try_new(Point3::from(o), Vector3::from(z), Vector3::from(x)).unwrap()
        };
        let tilted = frame([1.0, -2.0, 3.0], [0.3, -0.5, 0.8], [1.0, 0.2, 0.0]);
        let (o, x, y, z) = (tilted.origin(), tilted.x_dir(), tilted.y_dir(), tilted.z_dir());
        let at = |a: f64, b: f64, c: f64| o + x * a + y * b + z * c;
        let plane = SurfaceGeom::Plane(Plane::new(tilted));
        let cylinder = SurfaceGeom::Cylinder(Cylinder::try_new(tilted, 4.0).unwrap());
        let cone = SurfaceGeom::Cone(Cone::try_new(tilted, 4.0, 0.4).unwrap());
        let torus = SurfaceGeom::Torus(Torus::try_new(tilted, 10.0, 3.0).unwrap());
        let conic = |f: Placement, a: f64, b: f64| CurveGeom::Conic { frame: f, a, b };
        let line = |p: Point3<f64>, d: Vector3<f64>| CurveGeom::Line(Line::try_new(p, d).unwrap());
        // A frame in the plane, turned by 0.7 about its normal, centred at (2, -1).
        let in_plane = Placement::try_new(at(2.0, -1.0, 0.0), z, x * 0.7f64.cos() + y * 0.7f64.sin()).unwrap();
        let phi = 0.9f64;
        let big = 10.0 + 3.0 * phi.cos();
        let meridian_centre = at(10.0 * 0.4f64.cos(), 10.0 * 0.4f64.sin(), 0.0);
        let meridian_normal = z.cross(&(meridian_centre - o)).normalize();
        let cases = [
            ("line on a plane", &plane, line(at(1.0, 2.0, 0.0), x * 2.0 - y), -3.0, 4.0),
            ("circle arc on a plane", &plane, conic(in_plane, 5.0, 5.0), 0.3, 5.0),
            ("ellipse on a plane", &plane, conic(in_plane, 5.0, 2.0), -2.0, 2.5),
            ("whole ellipse on a plane", &plane, conic(in_plane, 5.0, 2.0), 1.0, 1.0 + TAU),
            ("generator of a cylinder", &cylinder, line(at(0.0, 4.0, 1.0), z), -2.0, 5.0),
            (
                "circle about a cylinder's axis",
                &cylinder,
                conic(frame(at(0.0, 0.0, 3.0).into(), z.into(), y.into()), 4.0, 4.0),
                2.5,
                4.0,
            ),
            (
                "whole circle about a cylinder's axis",
                &cylinder,
                conic(frame(at(0.0, 0.0, -1.0).into(), (-z).into(), x.into()), 4.0, 4.0),
                1.0,
                1.0 + TAU,
            ),
            ("generator of a cone", &cone, line(at(4.0, 0.0, 0.0), x * 0.4f64.sin() + z * 0.4f64.cos()), 0.5, 6.0),
            (
                "parallel of a torus",
                &torus,
                conic(frame(at(0.0, 0.0, 3.0 * phi.sin()).into(), z.into(), x.into()), big, big),
                0.5,
                3.5,
            ),
            (
                "meridian of a torus",
                &torus,
                conic(Placement::try_new(meridian_centre, meridian_normal, z).unwrap(), 3.0, 3.0),
                0.2,
                5.9,
            ),
        ];
        for (what, g, c, t0, t1) in cases {
            let ts = closed_form_params(g, &c, t0, t1).unwrap_or_else(|| panic!("{what}: no closed form"));
            let (du, dv) = match g {
                SurfaceGeom::Plane(_) => (Dir::Linear, Dir::Linear),
                SurfaceGeom::Torus(_) => (ANGLE, ANGLE),
                _ => (ANGLE, Dir::Linear),
            };
            let fast: Vec<_> = ts.iter().map(|&t| invert(g, &c.eval(t))).collect();
            let n = 20_000;
            let dense: Vec<_> = (0..=n).map(|i| invert(g, &c.eval(t0 + (t1 - t0) * i as f64 / n as f64))).collect();
            for (k, dir) in [(0, du), (1, dv)] {
                let coord = |s: &[(Option<f64>, f64)]| -> Vec<f64> {
                    s.iter().filter_map(|p| if k == 0 { p.0 } else { Some(p.1) }).collect()
                };
                let (a, b) = (range(&[coord(&fast)], dir).unwrap(), range(&[coord(&dense)], dir).unwrap());
                // Never narrower than the dense points; wider only by what lies between them.
                assert!(a.0 <= b.0 + 1e-12 && a.1 >= b.1 - 1e-12, "{what}, coordinate {k}: {a:?} misses {b:?}");
                assert!(b.0 - a.0 < 1e-6 && a.1 - b.1 < 1e-6, "{what}, coordinate {k}: {a:?} against {b:?}");
            }
        }
        // A circle across a cylinder's axis at an angle (an ellipse on it in truth) and a
        // line across a plane's normal have no closed form here.
        let oblique = conic(frame(o.into(), (z + x).into(), y.into()), 4.0, 4.0);
        assert!(closed_form_params(&cylinder, &oblique, 0.0, 1.0).is_none());
        assert!(closed_form_params(&cylinder, &line(at(4.0, 0.0, 0.0), x + z), 0.0, 1.0).is_none());
    }

    #[test]
    fn angular_ranges() {
        let q = std::f64::consts::FRAC_PI_2;
        // One quarter arc.
        assert_eq!(range(&[vec![0.0, 0.5, 1.0]], ANGLE), Some((0.0, 1.0)));
        // An arc crossing the ±π cut.
        let r = range(&[vec![3.0, 3.1, -3.1, -3.0]], ANGLE).unwrap();
        assert!((r.0 - 3.0).abs() < 1e-12 && (r.1 - (TAU - 3.0)).abs() < 1e-12);
        // A full circle edge.
        let full: Vec<f64> =
            (0..=24).map(|i| (i as f64 * TAU / 24.0 + q).sin().atan2((i as f64 * TAU / 24.0 + q).cos())).collect();
        let r = range(&[full], ANGLE).unwrap();
        assert!((r.1 - r.0 - TAU).abs() < 1e-12);
    }
}
