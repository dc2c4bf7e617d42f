//! CAD → watertight surface mesh of trimmed faces: what a CFD user feeds
//! snappyHexMesh (paper §3.1.1: the triangulated surface the volume mesher snaps to).
//!
//! The faces are [`BoundedFace`]s (a surface and its loops of model-space curves, as
//! `cadmorph::bounded_faces` makes them from any IGES or STEP model). Their shell
//! ([`Shell::from_faces`]) shares the edges two faces meet along, so:
//!
//! 1. every shell edge is sampled once, on its 3D curve, until each chord is within the
//!    chordal tolerance of the curve and turns by at most the angular tolerance;
//! 2. each face's loops become polygons in its `(u, v)` through the edges' parameter
//!    curves ([`Shell::pcurves`]) at those samples, and the surface's own tessellation
//!    within the tolerance ([`cadmorph_nurbs::NurbsSurface::tessellate`]) gives the points inside;
//! 3. a constrained Delaunay triangulation in `(u, v)` (the `spade` crate) keeps the
//!    polygon edges, the triangles outside the face (even–odd rule) are dropped, and a
//!    triangle whose centroid lies farther than the chordal tolerance from the surface,
//!    or whose normal turns from the surface's by more than the angular tolerance, gets
//!    its parameter centroid inserted, until none does;
//! 4. boundary vertices take the edge samples' 3D points, shared by both faces of an
//!    edge, interior vertices the surface's points.
//!
//! No edge vertex is duplicated and none lies inside another face's edge (both faces
//! use the same samples), so on a closed model every mesh edge has exactly two
//! triangles, one on open borders. Vertices closer than 1e-7 of the model's size (what
//! single-precision STL cannot tell apart) are made one. Triangles run counterclockwise
//! around the face normal (`S_u × S_v`, reversed for a reversed face), each closed piece
//! turned to point out first ([`cadmorph_brep::orient_outward`]). `spade` is used because
//! it is the maintained pure-Rust constrained Delaunay triangulation.

use std::collections::HashMap;

use nalgebra::Point3;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use cadmorph_brep::{BoundedFace, Shell};
use cadmorph_nurbs::{Curve, CurveProject, NurbsCurve, Side, Surface};

use crate::tessellate::Watertight;
use crate::{Error, Result};

/// How closely the triangles follow the CAD.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshTolerance {
    /// Largest distance from a triangle (its centroid, and each edge's midpoint on the
    /// boundary) to the surface, model units.
    pub chord: f64,
    /// Largest angle between a triangle's normal and the surface normal at its centroid,
    /// and between the tangents at a boundary chord's ends, degrees.
    pub angle_deg: f64,
}

/// Refinement rounds of step 3.
const MAX_ROUNDS: usize = 12;
/// Vertices one face may take before it is refused (a tolerance far below the model's
/// resolution).
const MAX_FACE_VERTICES: usize = 2_000_000;

/// Parameters of `c` from its start to its end such that each chord is within
/// `tol.chord` of the curve at its middle and quarters, and turns by at most
/// `tol.angle_deg` (every distinct knot is a sample).
fn sample_curve(c: &NurbsCurve, tol: &MeshTolerance) -> Vec<f64> {
    let d = c.domain();
    let (a, b) = (*d.start(), *d.end());
    let mut base: Vec<f64> = vec![a];
    let (knots, _) = c.knots().distinct();
    for k in knots {
        if k > a && k < b {
            base.push(k);
        }
    }
    base.push(b);
    let cos_max = tol.angle_deg.to_radians().cos();
    let tangent = |t: f64| {
        let h = 1e-7 * (b - a);
        let (t0, t1) = ((t - h).max(a), (t + h).min(b));
        (c.eval(t1) - c.eval(t0)).normalize()
    };
    let mut out = vec![a];
    // Each span split in `degree` pieces first, then bisected where needed.
    for w in base.windows(2) {
        let n = c.degree().max(2);
        let mut stack: Vec<(f64, f64, usize)> = (0..n)
            .rev()
            .map(|i| (w[0] + (w[1] - w[0]) * i as f64 / n as f64, w[0] + (w[1] - w[0]) * (i + 1) as f64 / n as f64, 0))
            .collect();
        while let Some((t0, t1, depth)) = stack.pop() {
            let (p0, p1) = (c.eval(t0), c.eval(t1));
            let far = [0.25, 0.5, 0.75].iter().any(|&f| {
                let t = t0 + f * (t1 - t0);
                let q = p0 + (p1 - p0) * f;
                (c.eval(t) - q).norm() > tol.chord
            });
            let turns = tangent(t0).dot(&tangent(t1)) < cos_max;
            if depth < 24 && (far || turns) {
                let m = 0.5 * (t0 + t1);
                stack.push((m, t1, depth + 1));
                stack.push((t0, m, depth + 1));
            } else {
                out.push(t1);
            }
        }
    }
    out
}

/// Whether `p` lies inside the region the polygons bound (even–odd rule).
fn inside(p: (f64, f64), polygons: &[Vec<(f64, f64)>]) -> bool {
    let mut odd = false;
    for poly in polygons {
        let n = poly.len();
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            if (a.1 > p.1) != (b.1 > p.1) && p.0 < a.0 + (p.1 - a.1) / (b.1 - a.1) * (b.0 - a.0) {
                odd = !odd;
            }
        }
    }
    odd
}

/// The distance from `p` to the nearest polygon edge.
fn distance_to_bounds(p: (f64, f64), polygons: &[Vec<(f64, f64)>]) -> f64 {
    let mut best = f64::INFINITY;
    for poly in polygons {
        let n = poly.len();
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 { (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
            best = best.min((p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy));
        }
    }
    best
}

/// The watertight triangulation of `faces` ([module docs](self)): `natural[i]` says face
/// `i` is its whole surface (its loops its sides: their parameters are then found on the
/// sides, which also holds where a side collapses to a point and a projection onto the
/// surface would not; missing entries count as `false`), `join` is the distance within
/// which loop curve ends are one vertex (as the converters use it), `size` the model's
/// size.
///
/// # Errors
///
/// [`Error::Topology`] naming the face when a parameter curve cannot be fitted, its loop
/// polygon crosses itself in `(u, v)`, or the tolerance would need more than two million
/// vertices on one face.
pub fn tessellate_faces(
    faces: &[BoundedFace],
    natural: &[bool],
    join: f64,
    size: f64,
    tol: MeshTolerance,
) -> Result<Watertight> {
    if !(tol.chord > 0.0 && tol.angle_deg > 0.0) {
        return Err(Error::Topology(format!(
            "tessellation tolerances must be positive (chord {}, angle {}°)",
            tol.chord, tol.angle_deg
        )));
    }
    // Each closed piece turned outward ([`cadmorph_brep::orient_outward`]): IGES faces
    // outside a B-rep carry no orientation, and a mesher wants the normals consistent.
    let mut oriented = faces.to_vec();
    cadmorph_brep::orient_outward(&mut oriented, join);
    let faces = oriented.as_slice();
    let shell = Shell::from_faces(faces, join);
    let mut points = shell.vertices.clone();
    // Each edge sampled once: parameters and vertex ids (its end vertices at the ends).
    let mut samples: Vec<(Vec<f64>, Vec<usize>)> = Vec::with_capacity(shell.edges.len());
    for e in &shell.edges {
        let ts = sample_curve(&e.curve, &tol);
        let mut ids = Vec::with_capacity(ts.len());
        ids.push(e.start);
        for &t in &ts[1..ts.len() - 1] {
            ids.push(points.len());
            points.push(e.curve.eval(t));
        }
        ids.push(e.end);
        samples.push((ts, ids));
    }
    let mut triangles = Vec::new();
    let mut face_of = Vec::new();
    for (fi, face) in faces.iter().enumerate() {
        let uvs = bound_parameters(faces, fi, natural.get(fi).copied().unwrap_or(false), &shell, &samples, join, size)?;
        let tris = face_triangles(fi, face, &shell, &uvs, &samples, &mut points, &tol)?;
        face_of.extend(std::iter::repeat_n(fi, tris.len()));
        triangles.extend(tris);
    }
    Ok(weld(Watertight { points, triangles, face_of }, 1e-7 * size))
}

/// Vertices closer than `eps` made one (the first of them), the triangles that then
/// have a repeated vertex dropped (an edge collapse, which keeps every other edge's two
/// triangles), unused vertices removed. STL holds single-precision coordinates: points
/// closer than about 1e-7 of the model's size become one point in every reader, and a
/// triangle between them a degenerate one (OpenFOAM's `surfaceCheck` calls it illegal). A
/// thin trailing edge leaves such pairs of bound samples.
fn weld(w: Watertight, eps: f64) -> Watertight {
    if eps.is_nan() || eps <= 0.0 {
        return w;
    }
    let key = |p: &Point3<f64>| [(p.x / eps).floor() as i64, (p.y / eps).floor() as i64, (p.z / eps).floor() as i64];
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut to: Vec<usize> = (0..w.points.len()).collect();
    for (i, p) in w.points.iter().enumerate() {
        let k = key(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        if let Some(&j) = list.iter().find(|&&j| (w.points[j] - p).norm() < eps) {
                            found = Some(j);
                            break 'search;
                        }
                    }
                }
            }
        }
        match found {
            Some(j) => to[i] = j,
            None => grid.entry(k).or_default().push(i),
        }
    }
    let mut triangles = Vec::with_capacity(w.triangles.len());
    let mut face_of = Vec::with_capacity(w.triangles.len());
    for (t, &f) in w.triangles.iter().zip(&w.face_of) {
        let t = t.map(|i| to[i]);
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            triangles.push(t);
            face_of.push(f);
        }
    }
    let mut index = vec![usize::MAX; w.points.len()];
    let mut points = Vec::with_capacity(w.points.len());
    for t in &mut triangles {
        for v in t.iter_mut() {
            if index[*v] == usize::MAX {
                index[*v] = points.len();
                points.push(w.points[*v]);
            }
            *v = index[*v];
        }
    }
    Watertight { points, triangles, face_of }
}

/// Which faces of the triangulation lie inside the bounds, by face index: a flood
/// from the outside (the faces along the convex hull), the state flipping across each
/// constraint edge. (Robust where a centroid test is not: a sliver between three nearly
/// collinear bound points has its centroid on the bound.)
fn inside_faces(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<bool> {
    let mut state: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for e in cdt.directed_edges() {
        if e.face().is_outer() {
            if let Some(f) = e.rev().face().as_inner() {
                let ins = e.is_constraint_edge();
                if state[f.fix().index()].is_none() {
                    state[f.fix().index()] = Some(ins);
                    stack.push(f.fix());
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        let ins = state[f.index()].unwrap_or(false);
        for e in cdt.face(f).adjacent_edges() {
            if let Some(g) = e.rev().face().as_inner() {
                let i = g.fix().index();
                if state[i].is_none() {
                    state[i] = Some(ins != e.is_constraint_edge());
                    stack.push(g.fix());
                }
            }
        }
    }
    state.into_iter().map(|s| s.unwrap_or(false)).collect()
}

/// The `(u, v)` of an edge's samples on one face.
type EdgeUv = Vec<(f64, f64)>;

/// Per loop of face `fi`, per edge use, the `(u, v)` of each of the edge's samples (in
/// the edge's own order): on the side it runs along for a natural face, else from its
/// parameter curve ([`Shell::face_pcurves`]).
fn bound_parameters(
    faces: &[BoundedFace],
    fi: usize,
    natural: bool,
    shell: &Shell,
    samples: &[(Vec<f64>, Vec<usize>)],
    join: f64,
    size: f64,
) -> Result<Vec<Vec<EdgeUv>>> {
    let s = &faces[fi].surface;
    if !natural {
        let pcs = shell
            .face_pcurves(faces, fi, size)
            .map_err(|e| Error::Topology(format!("face {fi}: no parameter curve for its bounds: {e}")))?;
        return Ok(shell.loops[fi]
            .iter()
            .zip(&pcs)
            .map(|(lp, pcs)| {
                lp.iter()
                    .zip(pcs)
                    .map(|(&(e, _), pc)| samples[e].0.iter().map(|&t| (pc.eval(t).x, pc.eval(t).y)).collect())
                    .collect()
            })
            .collect());
    }
    // The loop of `BoundedFace::natural`: VMin, UMax, VMax, UMin (backwards for a
    // reversed face), without the sides collapsed to a point.
    let face = &faces[fi];
    let mut sides: Vec<(Side, NurbsCurve)> = [Side::VMin, Side::UMax, Side::VMax, Side::UMin]
        .into_iter()
        .map(|k| (k, s.boundary(k)))
        .filter(|(_, c)| {
            let first = c.control_points()[0];
            !c.control_points().iter().all(|p| (p - first).norm_squared() <= join * join)
        })
        .collect();
    if face.reversed {
        sides.reverse();
    }
    let lp = match shell.loops[fi].as_slice() {
        [lp] if lp.len() == sides.len() => lp,
        _ => return Err(Error::Topology(format!("face {fi}: a whole-surface face whose loop is not its sides"))),
    };
    let (du, dv) = s.domain();
    let ptol = 1e-12 * size.max(f64::MIN_POSITIVE);
    let uvs = lp
        .iter()
        .zip(&sides)
        .map(|(&(e, _), (side, curve))| {
            let c = &shell.edges[e].curve;
            let ts = &samples[e].0;
            let mut qs: Vec<f64> = ts.iter().map(|&t| curve.project(&c.eval(t), ptol).t).collect();
            // A closed side (a full circle) projects both its ends onto one end of its
            // domain: they are its two ends, in the order the samples between run.
            let n = qs.len();
            let cd = curve.domain();
            if n >= 3 && (curve.eval(*cd.start()) - curve.eval(*cd.end())).norm() <= join {
                let (a, b) = (*cd.start(), *cd.end());
                let rising = qs[n - 2] > qs[1];
                qs[0] = if rising { a } else { b };
                qs[n - 1] = if rising { b } else { a };
            }
            qs.into_iter()
                .map(|q| match side {
                    Side::UMin => (*du.start(), q),
                    Side::UMax => (*du.end(), q),
                    Side::VMin => (q, *dv.start()),
                    Side::VMax => (q, *dv.end()),
                })
                .collect()
        })
        .collect();
    Ok(vec![uvs])
}

/// The triangles of face `fi`, adding its interior vertices to `points`.
fn face_triangles(
    fi: usize,
    face: &BoundedFace,
    shell: &Shell,
    uvs: &[Vec<EdgeUv>],
    samples: &[(Vec<f64>, Vec<usize>)],
    points: &mut Vec<Point3<f64>>,
    tol: &MeshTolerance,
) -> Result<Vec<[usize; 3]>> {
    let s = &face.surface;
    let err = |what: String| Error::Topology(format!("face {fi}: {what}"));
    // The surface's own tessellation within the tolerance: the points inside, and the
    // mean speeds |S_u|, |S_v| that scale (u, v) so that the Delaunay triangles are
    // well shaped in space, not only in the parameters.
    let seeds = s.tessellate(tol.chord);
    let step = (seeds.params.len() / 256).max(1);
    let (mut su, mut sv, mut n) = (0.0, 0.0, 0usize);
    for &(u, v) in seeds.params.iter().step_by(step) {
        let d = s.eval_d1(u, v);
        if d.du.norm().is_finite() && d.dv.norm().is_finite() {
            su += d.du.norm();
            sv += d.dv.norm();
            n += 1;
        }
    }
    let positive = |x: f64| if x > 0.0 && x.is_finite() { x } else { 1.0 };
    let (su, sv) = (positive(su / n.max(1) as f64), positive(sv / n.max(1) as f64));
    let to_uv = |p: Point2<f64>| (p.x / su, p.y / sv);
    // The loop polygons in scaled (u, v), each vertex with its id; a parameter within
    // 1e-12 of the domain's end is put on it (a bound along a side then runs straight).
    let (du, dv) = s.domain();
    let snap = |x: f64, d: &std::ops::RangeInclusive<f64>| {
        let eps = 1e-12 * (d.end() - d.start());
        if (x - d.start()).abs() <= eps {
            *d.start()
        } else if (x - d.end()).abs() <= eps {
            *d.end()
        } else {
            x
        }
    };
    let mut polygons: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut boundary: Vec<Vec<usize>> = Vec::new();
    for (lp, loop_uv) in shell.loops[fi].iter().zip(uvs) {
        let (mut uv, mut ids) = (Vec::new(), Vec::new());
        for (&(e, agrees), edge_uv) in lp.iter().zip(loop_uv) {
            let vs = &samples[e].1;
            let order: Vec<usize> = if agrees { (0..vs.len()).collect() } else { (0..vs.len()).rev().collect() };
            for k in order {
                if ids.last() == Some(&vs[k]) {
                    continue;
                }
                let q = edge_uv[k];
                uv.push((snap(q.0, &du) * su, snap(q.1, &dv) * sv));
                ids.push(vs[k]);
            }
        }
        if ids.len() > 1 && ids.first() == ids.last() {
            uv.pop();
            ids.pop();
        }
        if ids.len() >= 3 {
            polygons.push(uv);
            boundary.push(ids);
        }
    }
    if polygons.is_empty() {
        return Ok(Vec::new());
    }
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = ConstrainedDelaunayTriangulation::new();
    // spade vertex index → mesh vertex id.
    let mut id_of: HashMap<usize, usize> = HashMap::new();
    let insert = |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>, (u, v): (f64, f64)| {
        // spade takes no magnitude below about 1.8e-43 but 0.
        let snap = |x: f64| if x.abs() < 1e-40 { 0.0 } else { x };
        cdt.insert(Point2::new(snap(u), snap(v))).map_err(|e| err(format!("parameter point ({u}, {v}): {e:?}")))
    };
    for (poly, ids) in polygons.iter().zip(&boundary) {
        let handles: Vec<_> = poly.iter().map(|&q| insert(&mut cdt, q)).collect::<Result<_>>()?;
        for (h, &id) in handles.iter().zip(ids) {
            id_of.entry(h.index()).or_insert(id);
        }
        for k in 0..handles.len() {
            let (a, b) = (handles[k], handles[(k + 1) % handles.len()]);
            if a == b {
                continue;
            }
            if !cdt.can_add_constraint(a, b) {
                return Err(err(format!("its bound crosses itself in (u, v) near ({}, {})", poly[k].0, poly[k].1)));
            }
            cdt.add_constraint(a, b);
        }
    }
    // Points inside, from the surface's own tessellation within the tolerance; none on
    // or next to a bound (a point there would split a bound edge that the face on the
    // other side does not split).
    let margin = 1e-6 * ((du.end() - du.start()) * su).hypot((dv.end() - dv.start()) * sv);
    for &(u, v) in &seeds.params {
        let q = (u * su, v * sv);
        if inside(q, &polygons) && distance_to_bounds(q, &polygons) > margin {
            insert(&mut cdt, q)?;
        }
    }
    let reversed = face.reversed;
    let cos_max = tol.angle_deg.to_radians().cos();
    let eval = |cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>,
                id_of: &HashMap<usize, usize>,
                points: &[Point3<f64>],
                h: spade::handles::FixedVertexHandle| {
        match id_of.get(&h.index()) {
            Some(&id) => points[id],
            None => {
                let (u, v) = to_uv(cdt.vertex(h).position());
                s.eval(u, v)
            }
        }
    };
    // Which triangles are inside, for the triangulation as it stands.
    let mut within = Vec::new();
    for round in 0..=MAX_ROUNDS {
        let mut split = Vec::new();
        within = inside_faces(&cdt);
        for f in cdt.inner_faces() {
            if !within[f.fix().index()] {
                continue;
            }
            let vs = f.vertices();
            let uv = vs.map(|v| v.position());
            let c = ((uv[0].x + uv[1].x + uv[2].x) / 3.0, (uv[0].y + uv[1].y + uv[2].y) / 3.0);
            let p = vs.map(|v| eval(&cdt, &id_of, points, v.fix()));
            let centroid = Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
            let (cu, cv) = to_uv(Point2::new(c.0, c.1));
            let far = (s.eval(cu, cv) - centroid).norm() > tol.chord;
            // The surface turns across the triangle: its normal at a corner against the
            // one at the centroid (the curvature the triangle flattens). Not looked at on
            // a triangle with two bound corners: splitting inside cannot change the turn
            // along a bound edge, which its sampling settles.
            let on_bound = vs.iter().filter(|v| id_of.contains_key(&v.fix().index())).count();
            let turns = on_bound < 2
                && s.normal(cu, cv).is_some_and(|nc| {
                    uv.iter().any(|q| {
                        let (u, v) = to_uv(*q);
                        s.normal(u, v).is_some_and(|n| n.dot(&nc) < cos_max)
                    })
                });
            if far || turns {
                split.push(c);
            }
        }
        if split.is_empty() {
            break;
        }
        if round == MAX_ROUNDS || cdt.num_vertices() + split.len() > MAX_FACE_VERTICES {
            return Err(err(format!(
                "the tolerance (chord {}, angle {}°) needs more than {} refinement rounds or {MAX_FACE_VERTICES} vertices",
                tol.chord, tol.angle_deg, MAX_ROUNDS
            )));
        }
        for c in split {
            insert(&mut cdt, c)?;
        }
    }
    // Mesh ids for the interior vertices, then the triangles inside.
    for v in cdt.vertices() {
        let i = v.fix().index();
        if let std::collections::hash_map::Entry::Vacant(slot) = id_of.entry(i) {
            let (u, v) = to_uv(v.position());
            slot.insert(points.len());
            points.push(s.eval(u, v));
        }
    }
    // The last round split nothing: its `within` is the final triangulation's.
    let mut out = Vec::new();
    for f in cdt.inner_faces() {
        if !within[f.fix().index()] {
            continue;
        }
        let vs = f.vertices();
        let uv = vs.map(|v| v.position());
        let mut t = vs.map(|v| id_of[&v.fix().index()]);
        // Counterclockwise in (u, v): along S_u × S_v.
        if (uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[1].y - uv[0].y) * (uv[2].x - uv[0].x) < 0.0 {
            t.swap(1, 2);
        }
        // Collapsed sides (a pole) leave triangles with a repeated vertex: not part of
        // the surface.
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        out.push(if reversed { [t[0], t[2], t[1]] } else { t });
    }
    Ok(out)
}

/// The mesh as an ASCII STL with one `solid` per face (named `names[face]`): the
/// per-patch surfaces snappyHexMesh reads from one file.
///
/// # Errors
///
/// As [`crate::format::stl::Stl::from_triangles`] (non-finite points).
pub fn to_stl(w: &Watertight, names: &[String]) -> Result<Vec<u8>> {
    let (tris, solids) = grouped(w, names);
    let solids = solids.into_iter().map(|(name, triangles)| crate::format::stl::Solid { name, triangles }).collect();
    Ok(crate::format::stl::Stl::from_triangles(w.points.clone(), tris, solids)?.write_ascii().into_bytes())
}

/// The mesh as a Wavefront OBJ, shared vertices written once, one `g` group per face
/// (named `names[face]`, white space replaced by `_`).
pub fn to_obj(w: &Watertight, names: &[String]) -> Vec<u8> {
    use std::fmt::Write;
    let (tris, groups) = grouped(w, names);
    let mut s = String::with_capacity(40 * (w.points.len() + tris.len()));
    for p in &w.points {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for (name, range) in groups {
        let _ = writeln!(s, "g {}", name.split_whitespace().collect::<Vec<_>>().join("_"));
        for t in &tris[range] {
            let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
    }
    s.into_bytes()
}

/// A face's name and its range of the grouped triangles.
type Group = (String, std::ops::Range<usize>);

/// The triangles ordered by face, and each face's name with its range of them.
fn grouped(w: &Watertight, names: &[String]) -> (Vec<[usize; 3]>, Vec<Group>) {
    let n_faces = w.face_of.iter().map(|&f| f + 1).max().unwrap_or(0);
    let mut by_face: Vec<Vec<[usize; 3]>> = vec![Vec::new(); n_faces];
    for (t, &f) in w.triangles.iter().zip(&w.face_of) {
        by_face[f].push(*t);
    }
    let mut tris = Vec::with_capacity(w.triangles.len());
    let mut groups = Vec::new();
    for (f, ts) in by_face.into_iter().enumerate() {
        if ts.is_empty() {
            continue;
        }
        let start = tris.len();
        tris.extend(ts);
        let name = names.get(f).cloned().unwrap_or_else(|| format!("face{f}"));
        groups.push((name, start..tris.len()));
    }
    (tris, groups)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles of a strip whose far corners are 1e-9 apart: welding at 1e-7 makes
    /// them one vertex, the sliver between them goes, the fan around keeps its edges.
    #[test]
    fn weld_collapses_close_vertices() {
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let w = Watertight {
            points: vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1e-9), p(0.0, 1.0)],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            face_of: vec![0, 1],
        };
        let out = weld(w, 1e-7);
        assert_eq!(out.points, vec![p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)]);
        assert_eq!(out.triangles, vec![[0, 1, 2]]);
        assert_eq!(out.face_of, vec![1]);
    }

    #[test]
    fn even_odd_inside_with_a_hole() {
        let outer = vec![(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)];
        let hole = vec![(1.0, 1.0), (1.0, 3.0), (3.0, 3.0), (3.0, 1.0)];
        let polys = vec![outer, hole];
        assert!(inside((0.5, 0.5), &polys));
        assert!(!inside((2.0, 2.0), &polys));
        assert!(!inside((5.0, 2.0), &polys));
    }
}
