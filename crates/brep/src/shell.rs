//! Faces bounded by loops of model-space curves, and the shell topology a writer makes
//! of them: shared vertices and edges, each loop as a list of oriented edges.
//!
//! This is the neutral form both writers take when a model is converted from one format
//! to the other (ISO 10303-42 §5.4 `ADVANCED_FACE` → `FACE_BOUND` → `EDGE_LOOP` →
//! `ORIENTED_EDGE` → `EDGE_CURVE`; IGES 5.3 §4.151 510 face → 508 loop → 504 edge list →
//! 502 vertex list). Loops carry only model-space curves: both formats let a reader
//! compute the parameter-space curves (STEP `EDGE_CURVE` without `PCURVE`s is the
//! common AP214 form; an IGES 508 entry may have no parameter curve), as OCCT does.

use std::collections::HashMap;

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface, Side, Surface};

use crate::pcurve::Periods;

/// A face to write: a surface and the closed loops that bound it.
///
/// `loops[0]` is the outer loop; the others are holes. Each loop is a chain of curves,
/// each starting where the one before it ends (within the shell tolerance), the last
/// ending where the first starts. The outer loop runs counterclockwise around the face
/// normal (`S_u × S_v`, or its opposite for a reversed face), holes clockwise: the face
/// lies to the left of every loop (ISO 10303-42 §5.4.22), so in a closed, consistently
/// oriented shell two faces run along a shared edge in opposite directions.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundedFace {
    /// The surface, in model units.
    pub surface: NurbsSurface,
    /// The face normal opposes `S_u × S_v`.
    pub reversed: bool,
    /// The outer loop, then the holes.
    pub loops: Vec<Vec<NurbsCurve>>,
}

impl BoundedFace {
    /// The whole surface as a face: one loop `VMin(+) UMax(+) VMax(−) UMin(−)` (the
    /// other way round for a reversed face), without sides collapsed to a point (within
    /// `tol`), as STEP writers bound an untrimmed B-spline face.
    pub fn natural(surface: NurbsSurface, reversed: bool, tol: f64) -> Self {
        let tol_sq = tol * tol;
        let mut lp = Vec::new();
        for (side, forward) in [(Side::VMin, true), (Side::UMax, true), (Side::VMax, false), (Side::UMin, false)] {
            let c = surface.boundary(side);
            let first = c.control_points()[0];
            if c.control_points().iter().all(|p| (p - first).norm_squared() <= tol_sq) {
                continue;
            }
            lp.push(if forward { c } else { c.reversed() });
        }
        if reversed {
            lp = lp.iter().rev().map(NurbsCurve::reversed).collect();
        }
        Self { surface, reversed, loops: vec![lp] }
    }
}

/// An edge of a [`Shell`]: its end vertices and its curve, which runs from `start` to `end`.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellEdge {
    /// Index of the start vertex.
    pub start: usize,
    /// Index of the end vertex.
    pub end: usize,
    /// The curve, from the first face loop that used the edge.
    pub curve: NurbsCurve,
}

/// The fit tolerances of parameter curves ([`Shell::pcurves`]), as fractions of the
/// parameter box's diagonal, tightest first: 1e-10 keeps a face's area to about 1e-10
/// relative; projections of curves that lie on their surface only to 1e-9 need more.
pub const PCURVE_TOLS: [f64; 4] = [1e-10, 1e-9, 1e-8, 1e-6];

/// The topology of a set of [`BoundedFace`]s: vertices and edges that coincide within
/// the tolerance are shared, so faces that meet along an edge use one edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Shell {
    /// The vertices.
    pub vertices: Vec<Point3<f64>>,
    /// The edges.
    pub edges: Vec<ShellEdge>,
    /// Per face, per loop: `(edge, agrees)`, `agrees` when the loop runs along the
    /// edge's curve direction.
    pub loops: Vec<Vec<Vec<(usize, bool)>>>,
}

impl Shell {
    /// The shell of `faces`: a loop curve's ends become vertices (one per point within
    /// `tol`); two loop curves with the same end vertices whose midpoints lie within
    /// `10 tol` are one edge.
    pub fn from_faces(faces: &[BoundedFace], tol: f64) -> Self {
        let mut vertices = Vertices::new(tol);
        let mut edges: Vec<ShellEdge> = Vec::new();
        let mut mids: Vec<Point3<f64>> = Vec::new();
        let mut by_vertices: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        let mid_tol_sq = 100.0 * tol * tol;
        let mut loops = Vec::with_capacity(faces.len());
        for f in faces {
            let mut face_loops = Vec::with_capacity(f.loops.len());
            for lp in &f.loops {
                let mut oriented = Vec::with_capacity(lp.len());
                for c in lp {
                    let d = c.domain();
                    let (a, b) = (vertices.id(c.eval(*d.start())), vertices.id(c.eval(*d.end())));
                    let mid = c.eval(0.5 * (d.start() + d.end()));
                    let key = (a.min(b), a.max(b));
                    let found = by_vertices
                        .get(&key)
                        .and_then(|ks| ks.iter().copied().find(|&k| (mids[k] - mid).norm_squared() <= mid_tol_sq));
                    let (k, agrees) = match found {
                        Some(k) => (k, edges[k].start == a && (a != b || same_direction(&edges[k].curve, c))),
                        None => {
                            edges.push(ShellEdge { start: a, end: b, curve: c.clone() });
                            mids.push(mid);
                            by_vertices.entry(key).or_default().push(edges.len() - 1);
                            (edges.len() - 1, true)
                        }
                    };
                    oriented.push((k, agrees));
                }
                face_loops.push(oriented);
            }
            loops.push(face_loops);
        }
        Self { vertices: vertices.points, edges, loops }
    }

    /// The parameter curves of every loop: per face, per loop, per edge use, the edge's
    /// curve on the face's surface in `(u, v)` ([`crate::pcurve`]), running the way the
    /// edge's curve runs. Each loop is walked in its own order, each curve started where
    /// the one before it ended (so a seam edge a face uses twice gets both sides of a
    /// closed surface), then moved by whole periods into the surface's domain. Each is
    /// fitted within [`PCURVE_TOLS`]`[0]` of the parameter box's diagonal, or the next
    /// tolerance of that list when the curve's projection is too noisy for it; `size` is
    /// the model's size.
    ///
    /// # Errors
    ///
    /// Those of [`pcurve`](crate::pcurve::pcurve) at the last tolerance, with the face
    /// index.
    pub fn pcurves(
        &self,
        faces: &[BoundedFace],
        size: f64,
    ) -> std::result::Result<Vec<Vec<Vec<NurbsCurve>>>, (usize, cadmorph_nurbs::Error)> {
        (0..faces.len()).map(|fi| self.face_pcurves(faces, fi, size).map_err(|e| (fi, e))).collect()
    }

    /// The parameter curves of face `fi`'s loops, as [`pcurves`](Self::pcurves) makes
    /// them.
    ///
    /// # Errors
    ///
    /// Those of [`pcurve`](crate::pcurve::pcurve) at the last tolerance.
    pub fn face_pcurves(
        &self,
        faces: &[BoundedFace],
        fi: usize,
        size: f64,
    ) -> std::result::Result<Vec<Vec<NurbsCurve>>, cadmorph_nurbs::Error> {
        let (f, loops) = (&faces[fi], &self.loops[fi]);
        let s = &f.surface;
        let periods = Periods::of(s, 1e-7 * size);
        let (du, dv) = s.domain();
        let box_size = (du.end() - du.start()).hypot(dv.end() - dv.start());
        let mut face_out = Vec::with_capacity(loops.len());
        for lp in loops {
            let mut near = None;
            let mut curves = Vec::with_capacity(lp.len());
            for &(e, agrees) in lp {
                let c = &self.edges[e].curve;
                let mut fitted = Err(cadmorph_nurbs::Error::EmptyDomain { start: 0.0, end: 0.0 });
                for tol in PCURVE_TOLS {
                    fitted = crate::pcurve::pcurve(s, c, !agrees, near, periods, tol * box_size, size);
                    if fitted.is_ok() {
                        break;
                    }
                }
                let (pc, end) = fitted?;
                near = Some(end);
                curves.push(pc);
            }
            into_domain(&mut curves, periods, (*du.start(), *du.end()), (*dv.start(), *dv.end()));
            face_out.push(curves);
        }
        Ok(face_out)
    }

    /// Whether every edge is used exactly twice, once in each direction: the faces close
    /// up into one or more closed, consistently oriented shells.
    pub fn is_closed(&self) -> bool {
        let mut uses = vec![(0u32, 0u32); self.edges.len()];
        for lp in self.loops.iter().flatten().flatten() {
            let u = &mut uses[lp.0];
            if lp.1 {
                u.0 += 1;
            } else {
                u.1 += 1;
            }
        }
        !uses.is_empty() && uses.iter().all(|&u| u == (1, 1))
    }
}

/// Moves a loop's parameter curves by whole periods so that the middle of their `u`
/// (`v`) range lies in the domain.
fn into_domain(curves: &mut [NurbsCurve], periods: Periods, du: (f64, f64), dv: (f64, f64)) {
    let range = |k: usize| {
        let xs = curves.iter().flat_map(|c| c.control_points().iter().map(move |p| p[k]));
        let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        0.5 * (lo + hi)
    };
    let shift = |mid: f64, (lo, hi): (f64, f64), p: Option<f64>| match p {
        Some(p) if p > 0.0 && (mid < lo || mid > hi) => -p * ((mid - lo) / p).floor(),
        _ => 0.0,
    };
    let (su, sv) = (shift(range(0), du, periods.u), shift(range(1), dv, periods.v));
    if su != 0.0 || sv != 0.0 {
        for c in curves.iter_mut() {
            for p in c.control_points_mut() {
                p.x += su;
                p.y += sv;
            }
        }
    }
}

/// For a closed edge (start = end): whether `c` runs the way `e` does, by the point a
/// quarter along each.
fn same_direction(e: &NurbsCurve, c: &NurbsCurve) -> bool {
    let (de, dc) = (e.domain(), c.domain());
    let q = |d: &std::ops::RangeInclusive<f64>, s: f64| d.start() + s * (d.end() - d.start());
    let (e1, c1, c3) = (e.eval(q(&de, 0.25)), c.eval(q(&dc, 0.25)), c.eval(q(&dc, 0.75)));
    (e1 - c1).norm_squared() <= (e1 - c3).norm_squared()
}

/// Points merged within a tolerance, found through a grid of cells `2 tol` wide.
struct Vertices {
    tol_sq: f64,
    cell: f64,
    points: Vec<Point3<f64>>,
    grid: HashMap<[i64; 3], Vec<usize>>,
}

impl Vertices {
    fn new(tol: f64) -> Self {
        let tol = if tol.is_finite() && tol > 0.0 { tol } else { f64::MIN_POSITIVE };
        Self { tol_sq: tol * tol, cell: 2.0 * tol, points: Vec::new(), grid: HashMap::new() }
    }

    fn key(&self, p: &Point3<f64>) -> [i64; 3] {
        // Saturating float-to-int casts: a far point lands in an edge cell, still correct.
        [(p.x / self.cell).floor() as i64, (p.y / self.cell).floor() as i64, (p.z / self.cell).floor() as i64]
    }

    /// The index of the vertex within the tolerance of `p`, the closest if several;
    /// a new vertex otherwise.
    fn id(&mut self, p: Point3<f64>) -> usize {
        let k = self.key(&p);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let c = [k[0].saturating_add(dx), k[1].saturating_add(dy), k[2].saturating_add(dz)];
                    for &i in self.grid.get(&c).map_or(&[][..], Vec::as_slice) {
                        let d = (self.points[i] - p).norm_squared();
                        if d <= self.tol_sq && best.is_none_or(|b| d < b.0) {
                            best = Some((d, i));
                        }
                    }
                }
            }
        }
        match best {
            Some((_, i)) => i,
            None => {
                self.points.push(p);
                self.grid.entry(k).or_default().push(self.points.len() - 1);
                self.points.len() - 1
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, x1: f64) -> NurbsSurface {
        NurbsSurface::bilinear([[x0, 0., 0.], [x1, 0., 0.], [x0, 1., 0.], [x1, 1., 0.]])
    }

    #[test]
    fn neighbours_share_one_edge_in_opposite_directions() {
        let faces =
            [BoundedFace::natural(square(0., 1.), false, 1e-9), BoundedFace::natural(square(1., 2.), false, 1e-9)];
        let s = Shell::from_faces(&faces, 1e-9);
        assert_eq!(s.vertices.len(), 6);
        assert_eq!(s.edges.len(), 7);
        // Face 0's UMax side is face 1's UMin side: the same edge, once each way.
        let (e0, a0) = s.loops[0][0][1];
        let (e1, a1) = s.loops[1][0][3];
        assert_eq!(e0, e1);
        assert_ne!(a0, a1);
        assert!(!s.is_closed());
    }

    #[test]
    fn a_collapsed_side_is_left_out() {
        // A triangle as a bilinear patch whose VMax side is one point.
        let t = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0.5, 1., 0.], [0.5, 1., 0.]]);
        let f = BoundedFace::natural(t, false, 1e-9);
        assert_eq!(f.loops[0].len(), 3);
    }
}
