//! Orientation of faces that close up: every face's normal pointing out of the solid it
//! bounds, as a `CLOSED_SHELL` needs (ISO 10303-42 §5.4.28: the face normals of a closed
//! shell point away from the volume it encloses).
//!
//! A format without face orientation (IGES 144 trimmed surfaces, or 128 surfaces listed
//! outside a 186 solid) leaves each face's normal where its parameters put it; a reader
//! (OCCT's sewing, for one) then makes only an open shell. When every edge of a set of
//! faces is used by exactly two of them the orientation is recoverable:
//! 1. the faces around each shared edge must run along it in opposite directions, which
//!    decides every face's orientation relative to its neighbours, one connected piece
//!    at a time (breadth first; a piece where it cannot hold, a Möbius-like surface, is
//!    left alone);
//! 2. the signed volume of each piece (the divergence theorem, `V = ⅓ ∮ P·n dA`, each
//!    face integrated over its trimmed parameter region by the midpoint rule on a grid
//!    of scan lines) says whether its normals point out; a piece whose volume is negative
//!    is turned over as a whole.

use std::collections::VecDeque;

use cadmorph_nurbs::{Aabb, NurbsCurve, Surface};

use crate::pcurve::{uv_polyline, Periods};
use crate::{BoundedFace, Shell};

/// Grid lines per direction of a face's parameter box in the volume integral: enough
/// for its sign (a piece is turned over only when that sign is clear, see
/// [`orient_outward`]).
const GRID: usize = 64;

impl BoundedFace {
    /// The same face seen from its other side: the normal turned over and every loop run
    /// the other way.
    pub fn flipped(&self) -> Self {
        Self {
            surface: self.surface.clone(),
            reversed: !self.reversed,
            loops: self.loops.iter().map(|lp| lp.iter().rev().map(NurbsCurve::reversed).collect()).collect(),
        }
    }
}

/// Turns the faces of `faces` so that each connected piece that closes up (every edge
/// used by two faces of [`Shell::from_faces`] within `tol`) has its normals pointing out
/// of the volume it encloses (see the module docs for how). Returns, per piece (a list
/// of face indices), whether it closed and was oriented: a piece with an edge used once
/// or more than twice, one that cannot be oriented, or one whose enclosed volume is too
/// small against its box to tell in from out (below 1e-6 of it) is left as it was.
pub fn orient_outward(faces: &mut [BoundedFace], tol: f64) -> Vec<(Vec<usize>, bool)> {
    let shell = Shell::from_faces(faces, tol);
    let mut uses: Vec<Vec<(usize, bool)>> = vec![Vec::new(); shell.edges.len()];
    for (fi, loops) in shell.loops.iter().enumerate() {
        for &(e, agrees) in loops.iter().flatten() {
            uses[e].push((fi, agrees));
        }
    }
    // Per face, the edges it uses.
    let mut face_edges: Vec<Vec<usize>> = vec![Vec::new(); faces.len()];
    for (e, u) in uses.iter().enumerate() {
        for &(f, _) in u {
            face_edges[f].push(e);
        }
    }
    let mut piece_of = vec![usize::MAX; faces.len()];
    let mut flip = vec![false; faces.len()];
    let mut out = Vec::new();
    for seed in 0..faces.len() {
        if piece_of[seed] != usize::MAX {
            continue;
        }
        let id = out.len();
        let mut members = Vec::new();
        let mut ok = true;
        let mut queue = VecDeque::from([seed]);
        piece_of[seed] = id;
        while let Some(f) = queue.pop_front() {
            members.push(f);
            for &e in &face_edges[f] {
                let u = &uses[e];
                if u.len() != 2 {
                    ok = false;
                    for &(g, _) in u {
                        if piece_of[g] == usize::MAX {
                            piece_of[g] = id;
                            queue.push_back(g);
                        }
                    }
                    continue;
                }
                let ((a, sa), (b, sb)) = (u[0], u[1]);
                // The runs of this edge as they will be once the faces are flipped.
                let run = |g: usize, s: bool| s != flip[g];
                if a == b {
                    ok &= sa != sb;
                    continue;
                }
                let (g, sg, sf) = if a == f { (b, sb, sa) } else { (a, sa, sb) };
                if piece_of[g] == usize::MAX {
                    piece_of[g] = id;
                    // Opposite runs: g is flipped when its run equals f's.
                    flip[g] = sg == run(f, sf);
                    queue.push_back(g);
                } else {
                    ok &= run(g, sg) != run(f, sf);
                }
            }
        }
        members.sort_unstable();
        out.push((members, ok));
    }
    for (members, ok) in &mut out {
        if !*ok {
            continue;
        }
        let mut oriented: Vec<BoundedFace> =
            members.iter().map(|&f| if flip[f] { faces[f].flipped() } else { faces[f].clone() }).collect();
        let bounds = Aabb::from_points(oriented.iter().flat_map(|f| f.surface.control_points()));
        let Some(bounds) = bounds else {
            *ok = false;
            continue;
        };
        let extent = bounds.max - bounds.min;
        let box_volume = extent.x * extent.y * extent.z;
        let size = bounds.diagonal();
        let volume: f64 = oriented.iter().map(|f| signed_volume(f, size)).sum();
        if volume.is_nan() || volume.abs() <= 1e-6 * box_volume {
            *ok = false;
            continue;
        }
        if volume < 0.0 {
            oriented = oriented.iter().map(BoundedFace::flipped).collect();
        }
        for (&f, o) in members.iter().zip(oriented) {
            faces[f] = o;
        }
    }
    out
}

/// `⅓ ∫ P·n dA` over the face (its contribution to the enclosed volume), `n` its normal:
/// the midpoint rule on a [`GRID`]² grid of its loops' parameter box, each grid row
/// cut by the loops (even–odd) into the spans inside the face.
fn signed_volume(f: &BoundedFace, size: f64) -> f64 {
    let s = &f.surface;
    let polys: Vec<Vec<(f64, f64)>> = f.loops.iter().map(|lp| uv_polyline(s, lp, size)).collect();
    let (mut lo, mut hi) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for &(u, v) in polys.iter().flatten() {
        lo = (lo.0.min(u), lo.1.min(v));
        hi = (hi.0.max(u), hi.1.max(v));
    }
    if !(hi.0 > lo.0 && hi.1 > lo.1) {
        return 0.0;
    }
    let periods = Periods::of(s, 1e-7 * size);
    let (du, dv) = s.domain();
    let wrap = |x: f64, start: f64, end: f64, p: Option<f64>| match p {
        Some(p) if p > 0.0 => start + (x - start).rem_euclid(p),
        _ => x.clamp(start, end),
    };
    let (hu, hv) = ((hi.0 - lo.0) / GRID as f64, (hi.1 - lo.1) / GRID as f64);
    let mut total = 0.0;
    let mut cuts = Vec::new();
    for j in 0..GRID {
        let v = lo.1 + (j as f64 + 0.5) * hv;
        cuts.clear();
        for p in &polys {
            for k in 0..p.len() {
                let (a, b) = (p[k], p[(k + 1) % p.len()]);
                if (a.1 <= v) != (b.1 <= v) {
                    cuts.push(a.0 + (v - a.1) / (b.1 - a.1) * (b.0 - a.0));
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        for i in 0..GRID {
            let u = lo.0 + (i as f64 + 0.5) * hu;
            // Inside when an odd number of crossings lie left of u.
            if cuts.partition_point(|&c| c < u) % 2 == 1 {
                let d =
                    s.eval_d1(wrap(u, *du.start(), *du.end(), periods.u), wrap(v, *dv.start(), *dv.end(), periods.v));
                total += d.point.coords.dot(&d.du.cross(&d.dv));
            }
        }
    }
    let sign = if f.reversed { -1.0 } else { 1.0 };
    sign * total * hu * hv / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_nurbs::NurbsSurface;

    /// The six faces of the unit cube, each a bilinear patch with its parameters running
    /// so that `S_u × S_v` points out (`out`) or in.
    fn cube(outward: [bool; 6]) -> Vec<BoundedFace> {
        let c = |x: f64, y: f64, z: f64| [x, y, z];
        // Corners (p00, p10, p01, p11) with (p10 - p00) × (p01 - p00) pointing out.
        let sides = [
            [c(0., 0., 0.), c(0., 1., 0.), c(1., 0., 0.), c(1., 1., 0.)], // z = 0, -z
            [c(0., 0., 1.), c(1., 0., 1.), c(0., 1., 1.), c(1., 1., 1.)], // z = 1, +z
            [c(0., 0., 0.), c(1., 0., 0.), c(0., 0., 1.), c(1., 0., 1.)], // y = 0, -y
            [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 0.), c(1., 1., 1.)], // y = 1, +y
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 0.), c(0., 1., 1.)], // x = 0, -x
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 0., 1.), c(1., 1., 1.)], // x = 1, +x
        ];
        sides
            .iter()
            .zip(outward)
            .map(|(q, out)| {
                let q = if out { *q } else { [q[0], q[2], q[1], q[3]] };
                BoundedFace::natural(NurbsSurface::bilinear(q), false, 1e-9)
            })
            .collect()
    }

    #[test]
    fn a_cube_with_mixed_normals_is_turned_outward() {
        for outward in [[true; 6], [false; 6], [true, false, false, true, false, true]] {
            let mut faces = cube(outward);
            let pieces = orient_outward(&mut faces, 1e-9);
            assert_eq!(pieces, vec![((0..6).collect::<Vec<_>>(), true)], "{outward:?}");
            let volume: f64 = faces.iter().map(|f| signed_volume(f, 3f64.sqrt())).sum();
            assert!((volume - 1.0).abs() < 1e-12, "{outward:?}: volume {volume}");
            // Every edge is now run once each way.
            assert!(Shell::from_faces(&faces, 1e-9).is_closed(), "{outward:?}");
            for (f, was) in faces.iter().zip(outward) {
                assert_eq!(f.reversed, !was, "{outward:?}");
            }
        }
    }

    #[test]
    fn an_open_box_is_left_alone() {
        let mut faces = cube([false; 6]);
        faces.pop();
        let before = faces.clone();
        let pieces = orient_outward(&mut faces, 1e-9);
        assert_eq!(pieces, vec![((0..5).collect::<Vec<_>>(), false)]);
        assert_eq!(faces, before);
    }
}
