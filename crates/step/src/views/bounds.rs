//! The parameter box of a face on an analytic surface, from its edges.
//!
//! Each edge is sampled in 3D and every sample is inverted onto the surface in closed
//! form (planes, cylinders, cones, spheres, tori), by rotation and curve projection
//! (revolutions) or by projection along the direction (extrusions). Angles are unwrapped
//! along each edge, and the face's angular range is the complement of the largest gap
//! left by the union of the edges' arcs; an edge that goes all the way round gives a full
//! turn starting at its first point.

use std::f64::consts::TAU;

use cadmorph_nurbs::analytic::AnalyticSurface;
use cadmorph_nurbs::math::{Matrix4, Point3, Vector3};
use cadmorph_nurbs::{Curve, CurveProject};

use super::geometry::SurfaceGeom;
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
                let (c, t0, t1, _, _) = self.edge_geometry(e)?;
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
                        let t = golden_max(f, lo, hi);
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

/// The argument of the maximum of `f` on `[a, b]` (golden-section search, 60 steps).
fn golden_max(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..60 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    (a + b) / 2.0
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
