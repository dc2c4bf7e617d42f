//! CAD → watertight surface mesh: each NURBS face is tessellated within a chordal
//! tolerance ([`cadmorph_nurbs::NurbsSurface::tessellate`]), then the faces are stitched
//! along their shared edges so that both sides of a seam use the same vertices: every
//! boundary vertex of one face that falls inside a boundary segment of the other is
//! inserted there (the adjacent triangle split into a fan), and coincident vertices are
//! merged. No T-junction or duplicate vertex is left along a listed seam, so on a closed
//! model every edge is shared by exactly two triangles.
//!
//! The faces are untrimmed patches and the seams are given as pairs of patch sides
//! (as [`shared_sides`] finds them), so that a model's face/edge graph can drive it.

use nalgebra::Point3;

use cadmorph_nurbs::{NurbsSurface, Side, Surface};

use crate::{Error, Result};

/// A watertight triangulation of several faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Watertight {
    /// Vertices (each seam vertex once).
    pub points: Vec<Point3<f64>>,
    /// Triangles, indices into `points`, oriented as the face's `S_u × S_v`.
    pub triangles: Vec<[usize; 3]>,
    /// The face each triangle belongs to.
    pub face_of: Vec<usize>,
}

/// Sides of two faces that are the same curve: the side curves agree at 5 points (either
/// direction) to `tol`. Each pair is listed once, lower face first.
pub fn shared_sides(faces: &[NurbsSurface], tol: f64) -> Vec<(usize, Side, usize, Side)> {
    let samples =
        |f: &NurbsSurface, s: Side| -> Vec<Point3<f64>> { (0..5).map(|k| side_point(f, s, k as f64 / 4.0)).collect() };
    let mut out = Vec::new();
    for a in 0..faces.len() {
        for sa in Side::ALL {
            let pa = samples(&faces[a], sa);
            for (b, fb) in faces.iter().enumerate().skip(a + 1) {
                for sb in Side::ALL {
                    let pb = samples(fb, sb);
                    let fwd = pa.iter().zip(&pb).all(|(p, q)| (p - q).norm() <= tol);
                    let rev = pa.iter().zip(pb.iter().rev()).all(|(p, q)| (p - q).norm() <= tol);
                    if fwd || rev {
                        out.push((a, sa, b, sb));
                    }
                }
            }
        }
    }
    out
}

/// The point of side `s` at fraction `t` of its parameter range.
fn side_point(f: &NurbsSurface, s: Side, t: f64) -> Point3<f64> {
    let (du, dv) = f.domain();
    let (u0, u1, v0, v1) = (*du.start(), *du.end(), *dv.start(), *dv.end());
    let (u, v) = match s {
        Side::UMin => (u0, v0 + t * (v1 - v0)),
        Side::UMax => (u1, v0 + t * (v1 - v0)),
        Side::VMin => (u0 + t * (u1 - u0), v0),
        Side::VMax => (u0 + t * (u1 - u0), v1),
    };
    f.eval(u, v)
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Cumulative chord length of a polyline, scaled to end at 1.
fn chord_params(points: &[Point3<f64>], ids: &[usize]) -> Vec<f64> {
    let mut t = vec![0.0; ids.len()];
    for k in 1..ids.len() {
        t[k] = t[k - 1] + (points[ids[k]] - points[ids[k - 1]]).norm();
    }
    let total = t.last().copied().unwrap_or(0.0);
    if total > 0.0 {
        t.iter_mut().for_each(|x| *x /= total);
    }
    t
}

/// Tessellate `faces` within `tol` and stitch them along `seams`.
///
/// # Errors
///
/// [`Error::Topology`] when a listed seam's sides do not meet within `10·tol` at their
/// ends, or a face index is out of range.
pub fn tessellate_watertight(
    faces: &[NurbsSurface],
    seams: &[(usize, Side, usize, Side)],
    tol: f64,
) -> Result<Watertight> {
    let mut points = Vec::new();
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    let mut face_of = Vec::new();
    let mut sides: Vec<[Vec<usize>; 4]> = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        let m = f.tessellate(tol);
        let base = points.len();
        let (du, dv) = f.domain();
        let (u0, u1, v0, v1) = (*du.start(), *du.end(), *dv.start(), *dv.end());
        let mut s: [Vec<(f64, usize)>; 4] = Default::default();
        for (k, &(u, v)) in m.params.iter().enumerate() {
            if u == u0 {
                s[0].push((v, base + k));
            }
            if u == u1 {
                s[1].push((v, base + k));
            }
            if v == v0 {
                s[2].push((u, base + k));
            }
            if v == v1 {
                s[3].push((u, base + k));
            }
        }
        sides.push(s.map(|mut l| {
            l.sort_by(|a, b| a.0.total_cmp(&b.0));
            l.into_iter().map(|x| x.1).collect()
        }));
        points.extend(m.vertices.iter().copied());
        for t in &m.triangles {
            triangles.push(t.map(|i| base + i as usize));
            face_of.push(fi);
        }
    }
    let side_index = |s: Side| match s {
        Side::UMin => 0,
        Side::UMax => 1,
        Side::VMin => 2,
        Side::VMax => 3,
    };
    let mut parent: Vec<usize> = (0..points.len()).collect();
    // Points to insert into a boundary segment (p, q): (fraction from p, vertex).
    let mut inserts: std::collections::HashMap<(usize, usize), Vec<(f64, usize)>> = std::collections::HashMap::new();
    for &(a, sa, b, sb) in seams {
        if a >= faces.len() || b >= faces.len() {
            return Err(Error::Topology(format!(
                "seam ({a}, {sa:?}, {b}, {sb:?}): no such face (there are {})",
                faces.len()
            )));
        }
        let la = sides[a][side_index(sa)].clone();
        let mut lb = sides[b][side_index(sb)].clone();
        let (Some(&a0), Some(&b0), Some(&b1)) = (la.first(), lb.first(), lb.last()) else { continue };
        if (points[a0] - points[b1]).norm() < (points[a0] - points[b0]).norm() {
            lb.reverse();
        }
        let gap =
            (points[la[0]] - points[lb[0]]).norm().max((points[la[la.len() - 1]] - points[lb[lb.len() - 1]]).norm());
        if gap > 10.0 * tol {
            return Err(Error::Topology(format!(
                "seam ({a}, {sa:?}, {b}, {sb:?}): the sides end {gap:e} apart (more than 10 × tol)"
            )));
        }
        let ta = chord_params(&points, &la);
        let tb = chord_params(&points, &lb);
        // Vertices of one list that coincide with one of the other are merged; the others
        // are inserted into the other's segment that contains them.
        let mut place =
            |from: &[usize], tf: &[f64], into: &[usize], ti: &[f64], parent: &mut Vec<usize>, merge: bool| {
                for (k, &v) in from.iter().enumerate() {
                    let t = tf[k];
                    let j = ti.partition_point(|&x| x < t);
                    let near = [j.saturating_sub(1), j.min(ti.len() - 1)].into_iter().min_by(|&x, &y| {
                        (points[into[x]] - points[v]).norm().total_cmp(&(points[into[y]] - points[v]).norm())
                    });
                    if let Some(n) = near {
                        if (points[into[n]] - points[v]).norm() <= tol * 1e-3 + 1e-12 * (1.0 + points[v].coords.norm())
                        {
                            if merge {
                                let (r1, r2) = (find(parent, into[n]), find(parent, v));
                                parent[r2] = r1;
                            }
                            continue;
                        }
                    }
                    if j == 0 || j >= ti.len() {
                        continue;
                    }
                    let (p, q) = (into[j - 1], into[j]);
                    let frac = (t - ti[j - 1]) / (ti[j] - ti[j - 1]).max(f64::MIN_POSITIVE);
                    inserts.entry((p, q)).or_default().push((frac, v));
                }
            };
        place(&lb, &tb, &la, &ta, &mut parent, true);
        place(&la, &ta, &lb, &tb, &mut parent, false);
    }
    // Split the triangles next to segments that received points.
    let mut out = Vec::with_capacity(triangles.len());
    let mut out_face = Vec::with_capacity(triangles.len());
    for (t, &f) in triangles.iter().zip(&face_of) {
        let edge_points = |p: usize, q: usize| -> Vec<usize> {
            if let Some(l) = inserts.get(&(p, q)) {
                let mut l = l.clone();
                l.sort_by(|a, b| a.0.total_cmp(&b.0));
                l.into_iter().map(|x| x.1).collect()
            } else if let Some(l) = inserts.get(&(q, p)) {
                let mut l = l.clone();
                l.sort_by(|a, b| b.0.total_cmp(&a.0));
                l.into_iter().map(|x| x.1).collect()
            } else {
                Vec::new()
            }
        };
        let e = [edge_points(t[0], t[1]), edge_points(t[1], t[2]), edge_points(t[2], t[0])];
        let split: Vec<usize> = (0..3).filter(|&k| !e[k].is_empty()).collect();
        match split.len() {
            0 => {
                out.push(*t);
                out_face.push(f);
            }
            1 => {
                let k = split[0];
                let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let mut chain = vec![p];
                chain.extend(&e[k]);
                chain.push(q);
                for w in chain.windows(2) {
                    out.push([w[0], w[1], r]);
                    out_face.push(f);
                }
            }
            _ => {
                // A corner triangle split on two or three sides: fan around its centroid.
                let c = points.len();
                points.push(Point3::from((points[t[0]].coords + points[t[1]].coords + points[t[2]].coords) / 3.0));
                parent.push(c);
                let mut ring = Vec::new();
                for k in 0..3 {
                    ring.push(t[k]);
                    ring.extend(&e[k]);
                }
                for k in 0..ring.len() {
                    out.push([ring[k], ring[(k + 1) % ring.len()], c]);
                    out_face.push(f);
                }
            }
        }
    }
    // Merge, drop collapsed triangles, compact.
    let mut new_id = vec![usize::MAX; points.len()];
    let mut pts = Vec::new();
    let mut tris = Vec::with_capacity(out.len());
    let mut faces_out = Vec::with_capacity(out.len());
    for (t, f) in out.into_iter().zip(out_face) {
        let r = t.map(|v| find(&mut parent, v));
        if r[0] == r[1] || r[1] == r[2] || r[0] == r[2] {
            continue;
        }
        let ids = r.map(|v| {
            if new_id[v] == usize::MAX {
                new_id[v] = pts.len();
                pts.push(points[v]);
            }
            new_id[v]
        });
        tris.push(ids);
        faces_out.push(f);
    }
    Ok(Watertight { points: pts, triangles: tris, face_of: faces_out })
}
