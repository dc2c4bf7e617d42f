//! Which part of a face's parameter box the face covers: its bound curves (trimming
//! curves, loop edges) projected onto its surface, and a point-in-face test on them.
//!
//! The faces' boundaries come as model-space curves ([`BoundCurve`]): each is sampled
//! and projected onto the face's surface, giving polylines in the surface's `(u, v)`.
//! No loop has to be assembled or oriented: a point is inside when a ray from it
//! crosses the polylines an odd number of times, with the box's own sides standing for
//! the boundary parts that lie on them.
//!
//! ```text
//! ray from (u, v) towards +v up to the box's top side v₁:
//!   inside(u, v) = (crossings of the polylines inside the box is odd)
//!                  XOR (the top side at u is itself part of the boundary)
//! ```
//!
//! Boundary pieces that run along a side of the box (within `1e-9` of its size) are
//! taken out of the crossing count and kept as "this stretch of the side bounds the
//! face" instead; this handles faces whose outer loop is (partly) the box (a hull
//! patch, a box face with a hole, a cylinder between its two circles and its seam
//! line) and those cut inside it (an ellipse on a plane, a corner cut off a B-spline
//! patch) alike. On a surface closed in v (a sphere's or a revolution's seam at the
//! top and bottom sides) the ray runs along +u instead; steps of a polyline that jump
//! across more than half the box (a curve crossing the closing seam) are not part of
//! the boundary. Faces closed in both directions, curves that do not lie on the
//! surface and faces with no curve are not trimmed ([`Trim::of`] gives `None`) and are
//! drawn over their whole box. A face whose curves span less than its surface's box
//! (in a direction that is not closed) is drawn over the box they span
//! ([`Trim::parameter_box`]), then cut to them: the grid then has its cells where the
//! face is, and a loop that runs just inside the box (as IGES planes, drawn with a
//! margin, have) is met exactly instead of to within a cell.

use cadmorph_brep::{BoundCurve, Face};
use cadmorph_nurbs::{Curve, Surface};

/// A face's boundary in its surface's parameters, ready for [`Trim::contains`].
#[derive(Debug, Clone, PartialEq)]
pub struct Trim {
    /// Whether coordinates are swapped (`(v, u)`), so that the ray runs along the
    /// second coordinate (the surface is closed in v).
    swapped: bool,
    /// The box drawn, `((a0, a1), (b0, b1))` in the (possibly swapped) coordinates; the
    /// ray runs towards `b1`.
    bounds: ((f64, f64), (f64, f64)),
    /// Polyline steps inside the box, `[(a, b), (a, b)]`.
    segments: Vec<[(f64, f64); 2]>,
    /// Stretches `a0..a1` of the top side `b = b1` that bound the face.
    top: Vec<(f64, f64)>,
}

/// Parameters sampled along one bound curve: 8 per control point (between 16 and 400)
/// evenly over its range, and every knot inside it (the corners of a polyline).
fn samples(b: &BoundCurve) -> Vec<f64> {
    let n = (8 * b.curve.control_points().len()).clamp(16, 400);
    let (t0, t1) = (b.range.0.min(b.range.1), b.range.0.max(b.range.1));
    let mut ts: Vec<f64> = (0..n).map(|k| b.range.0 + (b.range.1 - b.range.0) * k as f64 / (n - 1) as f64).collect();
    ts.extend(b.curve.knots().distinct().0.into_iter().filter(|&t| t > t0 && t < t1));
    ts.sort_by(f64::total_cmp);
    if b.range.1 < b.range.0 {
        ts.reverse();
    }
    ts
}

impl Trim {
    /// The boundary of `face` from its bound curves `bounds` (those with
    /// `b.face == index of face`), inside the parameter box `((u0, u1), (v0, v1))` of its
    /// NURBS surface; `None` when the face is to be drawn whole (see the module docs).
    ///
    /// # Tolerance
    ///
    /// Curve samples are projected to within `1e-9` of the face's size and must lie
    /// within `1e-3` of it from the surface, else the face is not trimmed.
    pub fn of(face: &Face, bounds: &[&BoundCurve], ((u0, u1), (v0, v1)): ((f64, f64), (f64, f64))) -> Option<Trim> {
        if !face.trimmed || bounds.is_empty() || !(u1 > u0 && v1 > v0) {
            return None;
        }
        let s = &face.surface;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in s.control_points() {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        if !size.is_finite() || size == 0.0 {
            return None;
        }
        let closed = |along_u: bool| {
            (0..=4).all(|k| {
                let t = k as f64 / 4.0;
                let (p, q) = if along_u {
                    let v = v0 + (v1 - v0) * t;
                    (s.eval(u0, v), s.eval(u1, v))
                } else {
                    let u = u0 + (u1 - u0) * t;
                    (s.eval(u, v0), s.eval(u, v1))
                };
                (p - q).norm() <= 1e-7 * size
            })
        };
        let (closed_u, closed_v) = (closed(true), closed(false));
        let swapped = match (closed_u, closed_v) {
            (_, false) => false,
            (false, true) => true,
            (true, true) => return None,
        };
        // The curves in (u, v).
        let mut lines = Vec::with_capacity(bounds.len());
        for b in bounds {
            let ts = samples(b);
            let mut near = None;
            let mut line = Vec::with_capacity(ts.len());
            for t in ts {
                let p = b.curve.eval(t);
                let pr = s.project_near(&p, near, 1e-9 * size, 1e-4 * size);
                if pr.distance_sq.is_nan() || pr.distance_sq.sqrt() > 1e-3 * size {
                    return None;
                }
                near = Some((pr.u, pr.v));
                line.push((pr.u, pr.v));
            }
            lines.push(line);
        }
        // The box the curves span, in each direction that is not closed: the box to
        // draw (a face whose loop lies inside its surface's box all round, as IGES
        // planes drawn with a margin, is drawn over its loop's box).
        let span = |k: usize, lo: f64, hi: f64| {
            let c = |p: &(f64, f64)| if k == 0 { p.0 } else { p.1 };
            let a = lines.iter().flatten().map(c).fold(f64::INFINITY, f64::min).max(lo);
            let b = lines.iter().flatten().map(c).fold(f64::NEG_INFINITY, f64::max).min(hi);
            let ptol = 1e-9 * (hi - lo);
            (if a > lo + ptol { a } else { lo }, if b < hi - ptol { b } else { hi })
        };
        let (u0n, u1n) = if closed_u { (u0, u1) } else { span(0, u0, u1) };
        let (v0n, v1n) = if closed_v { (v0, v1) } else { span(1, v0, v1) };
        if !(u1n > u0n && v1n > v0n) {
            return None;
        }
        let shrunk = (u0n, u1n, v0n, v1n) != (u0, u1, v0, v1);
        let sw = |(u, v): (f64, f64)| if swapped { (v, u) } else { (u, v) };
        let ((a0, a1), (b0, b1)) = if swapped { ((v0n, v1n), (u0n, u1n)) } else { ((u0n, u1n), (v0n, v1n)) };
        let (ptol_a, ptol_b) = (1e-9 * (a1 - a0), 1e-9 * (b1 - b0));
        let mut segments = Vec::new();
        let mut top = Vec::new();
        for line in &lines {
            for w in line.windows(2) {
                let (p, q) = (sw(w[0]), sw(w[1]));
                // A step across the closing seam of a closed direction is no boundary.
                if (q.0 - p.0).abs() > 0.5 * (a1 - a0) || (q.1 - p.1).abs() > 0.5 * (b1 - b0) {
                    continue;
                }
                let on = |x: f64, y: f64, tol: f64| (x - y).abs() <= tol;
                if on(p.1, b1, ptol_b) && on(q.1, b1, ptol_b) {
                    top.push((p.0.min(q.0), p.0.max(q.0)));
                } else if (on(p.1, b0, ptol_b) && on(q.1, b0, ptol_b))
                    || (on(p.0, a0, ptol_a) && on(q.0, a0, ptol_a))
                    || (on(p.0, a1, ptol_a) && on(q.0, a1, ptol_a))
                {
                    // Along the bottom or a side: parallel to the ray or below every
                    // point, it is never crossed.
                } else {
                    segments.push([p, q]);
                }
            }
        }
        // Loops along the whole box only: no trim.
        if segments.is_empty() && !shrunk {
            return None;
        }
        Some(Trim { swapped, bounds: ((a0, a1), (b0, b1)), segments, top })
    }

    /// The part of the surface's parameter box to draw, `((u0, u1), (v0, v1))`: the
    /// box the face's bound curves span (the whole box in a closed direction).
    pub fn parameter_box(&self) -> ((f64, f64), (f64, f64)) {
        let (a, b) = self.bounds;
        if self.swapped {
            (b, a)
        } else {
            (a, b)
        }
    }

    /// Whether the boundary cuts into the drawn box (else the face is the whole
    /// [`Trim::parameter_box`]).
    pub fn cuts(&self) -> bool {
        !self.segments.is_empty()
    }

    /// Whether the surface point `(u, v)` belongs to the face.
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let (a, b) = if self.swapped { (v, u) } else { (u, v) };
        let ((a0, a1), (b0, b1)) = self.bounds;
        if !(a0..=a1).contains(&a) || !(b0..=b1).contains(&b) {
            return false;
        }
        let mut inside = self.top.iter().any(|&(x, y)| x <= a && a < y);
        for [p, q] in &self.segments {
            // Half-open in a, so that a ray through a vertex counts it once.
            if (p.0 <= a) != (q.0 <= a) {
                let t = (a - p.0) / (q.0 - p.0);
                if p.1 + t * (q.1 - p.1) > b {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_brep::{EntityRef, Format, SurfaceKind};
    use cadmorph_nurbs::math::{Matrix4, Point3};
    use cadmorph_nurbs::{KnotVector, NurbsCurve, NurbsSurface};

    fn plane() -> Face {
        // The square [0, 4]² of z = 0, parameters (u, v) = (x, y) / 4.
        let surface = NurbsSurface::bilinear([[0., 0., 0.], [4., 0., 0.], [0., 4., 0.], [4., 4., 0.]]);
        let e = EntityRef::new(Format::Iges, 1);
        Face {
            entity: e,
            surface_entity: e,
            surface,
            parameter_box: ((0.0, 1.0), (0.0, 1.0)),
            reversed: false,
            trimmed: true,
            kind: SurfaceKind::BSpline,
            type_name: "IGES 128".into(),
            placement: Matrix4::identity(),
        }
    }

    fn polyline(points: &[[f64; 2]]) -> BoundCurve {
        let n = points.len();
        let pts: Vec<Point3<f64>> = points.iter().map(|p| Point3::new(p[0], p[1], 0.0)).collect();
        let curve = NurbsCurve::try_new(1, KnotVector::clamped_uniform(1, n), pts, None).unwrap();
        let e = EntityRef::new(Format::Iges, 2);
        BoundCurve {
            face: 0,
            label: e,
            edge: None,
            edge_index: 0,
            target: None,
            piece: 0,
            curve,
            range: (0.0, 1.0),
            placement: Matrix4::identity(),
        }
    }

    const BOX: ((f64, f64), (f64, f64)) = ((0.0, 1.0), (0.0, 1.0));

    #[test]
    fn a_square_with_a_hole() {
        let outer = polyline(&[[0., 0.], [4., 0.], [4., 4.], [0., 4.], [0., 0.]]);
        let hole = polyline(&[[1., 1.], [3., 1.], [3., 3.], [1., 3.], [1., 1.]]);
        let t = Trim::of(&plane(), &[&outer, &hole], BOX).unwrap();
        assert!(t.contains(0.1, 0.1) && t.contains(0.9, 0.5) && t.contains(0.5, 0.9));
        assert!(!t.contains(0.5, 0.5) && !t.contains(0.3, 0.6));
        // The outer loop alone is the box: no trim.
        assert!(Trim::of(&plane(), &[&outer], BOX).is_none());
    }

    #[test]
    fn a_loop_inside_the_box_all_round_is_its_box() {
        // The square [0.4, 3.6]² (parameters 0.1..0.9): drawn over its own box, uncut.
        let inner = polyline(&[[0.4, 0.4], [3.6, 0.4], [3.6, 3.6], [0.4, 3.6], [0.4, 0.4]]);
        let t = Trim::of(&plane(), &[&inner], BOX).unwrap();
        let ((u0, u1), (v0, v1)) = t.parameter_box();
        for (x, want) in [(u0, 0.1), (u1, 0.9), (v0, 0.1), (v1, 0.9)] {
            assert!((x - want).abs() < 1e-12, "{:?}", t.parameter_box());
        }
        assert!(!t.cuts());
        assert!(t.contains(0.5, 0.5) && t.contains(0.11, 0.89) && !t.contains(0.05, 0.5));
    }

    #[test]
    fn a_corner_cut_off() {
        // Outer loop: bottom, right up to y = 2, a diagonal to (2, 4), top back, left down.
        let pieces = [
            polyline(&[[0., 0.], [4., 0.], [4., 2.]]),
            polyline(&[[4., 2.], [2., 4.]]),
            polyline(&[[2., 4.], [0., 4.], [0., 0.]]),
        ];
        let refs: Vec<&BoundCurve> = pieces.iter().collect();
        let t = Trim::of(&plane(), &refs, BOX).unwrap();
        assert_eq!(t.parameter_box(), BOX);
        assert!(t.cuts());
        assert!(t.contains(0.2, 0.9) && t.contains(0.9, 0.2) && t.contains(0.6, 0.6));
        assert!(!t.contains(0.9, 0.9) && !t.contains(0.8, 0.75));
        assert!(!t.contains(1.5, 0.5), "outside the box");
    }

    #[test]
    fn a_diamond_inside() {
        let d = polyline(&[[2., 0.], [4., 2.], [2., 4.], [0., 2.], [2., 0.]]);
        let t = Trim::of(&plane(), &[&d], BOX).unwrap();
        assert!(t.contains(0.5, 0.5) && t.contains(0.5, 0.1) && t.contains(0.1, 0.5));
        assert!(!t.contains(0.1, 0.1) && !t.contains(0.9, 0.9) && !t.contains(0.1, 0.9));
    }

    #[test]
    fn curves_off_the_surface_do_not_trim() {
        let mut d = polyline(&[[2., 0.], [4., 2.], [2., 4.], [0., 2.], [2., 0.]]);
        for p in d.curve.control_points_mut() {
            p.z = 1.0;
        }
        assert!(Trim::of(&plane(), &[&d], BOX).is_none());
        let mut f = plane();
        f.trimmed = false;
        assert!(Trim::of(&f, &[&polyline(&[[2., 0.], [4., 2.], [2., 4.]])], BOX).is_none());
    }
}
