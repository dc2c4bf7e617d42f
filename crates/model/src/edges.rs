//! Shared edges from a document's bound curves: curves of the same topological edge
//! used by two faces (STEP `EDGE_CURVE`s, IGES 504 edges), and trimming curves of two
//! faces that lie on each other (IGES 144/143 without B-rep), besides the iso-boundaries
//! that coincide.

use std::collections::HashMap;

use cadmorph_brep::{BoundCurve, EntityRef, Face};
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, NurbsSurface};
use cadmorph_seam::{closing_seams, shared_boundaries, shared_curves, SharedBoundary, TrimCurve, TrimEdge};

/// The diagonal of the box around all control points of `faces`.
pub(crate) fn size_of(faces: &[Face]) -> f64 {
    let pts = faces.iter().flat_map(|p| p.surface.control_points());
    cadmorph_nurbs::Aabb::from_points(pts).map_or(0.0, |b| b.diagonal())
}

/// How far apart two sides may be and still be one edge: `1e-3 ×` the model size.
pub(crate) fn edge_tol(faces: &[Face]) -> f64 {
    1e-3 * size_of(faces)
}

/// The shared edges of `faces`, topology first (issue 22 item 4):
///
/// - a face with bound curves (STEP B-rep edges, IGES 504 edges of 510 faces, 142/141
///   trims of 144/143 faces) meets its neighbours exactly where those curves say: edges
///   the file names (the same `EDGE_CURVE` at the same occurrence, the same 504 edge),
///   and trimming curves of two faces that lie on each other over their length;
/// - faces without any bound curve (bare surfaces) are paired by their iso-boundaries
///   with each other, and with a bounded face where one of its bound curves lies on an
///   iso-boundary of theirs (see `mixed_edges`).
///
/// Such an edge is given as an iso-boundary edge (which seam repair can make exact)
/// when it runs along an iso-boundary of both its faces over that boundary overlap's
/// whole length; otherwise it is measured along its own curve, between the trimmed faces.
pub(crate) fn shared_edges(faces: &[Face], bounds: &[BoundCurve]) -> (Vec<SharedBoundary>, Vec<TrimEdge>) {
    let tol = edge_tol(faces);
    let mut bounded = vec![false; faces.len()];
    for b in bounds {
        if let Some(f) = bounded.get_mut(b.face) {
            *f = true;
        }
    }
    let bare: Vec<usize> = (0..faces.len()).filter(|&k| !bounded[k]).collect();
    let refs: Vec<&NurbsSurface> = bare.iter().map(|&k| &faces[k].surface).collect();
    let mut iso: Vec<SharedBoundary> = shared_boundaries(&refs, tol, 64, 0.9)
        .into_iter()
        .map(|mut e| {
            e.a.patch = bare[e.a.patch];
            e.b.patch = bare[e.b.patch];
            e
        })
        .collect();
    // A face closed in u or v keeps its own closing seam (a blade's section loop, a
    // full cylinder) whether or not the file bounds it: it is an edge of the face
    // with itself, which the topology pass below does not pair.
    let bounded_faces: Vec<usize> = (0..faces.len()).filter(|&k| bounded[k]).collect();
    let closed: Vec<&NurbsSurface> = bounded_faces.iter().map(|&k| &faces[k].surface).collect();
    // Edge pieces the file gives to more than one face, counted once here rather than
    // by a scan of every bound per closing seam.
    let mut faces_of: HashMap<(EntityRef, u32, usize), (usize, bool)> = HashMap::new();
    for b in bounds {
        if let Some(e) = b.edge {
            let f = faces_of.entry((e, b.edge_index, b.piece)).or_insert((b.face, false));
            f.1 |= f.0 != b.face;
        }
    }
    let shared = |b: &BoundCurve| b.edge.is_some_and(|e| faces_of[&(e, b.edge_index, b.piece)].1);
    for mut e in closing_seams(&closed, tol, 64, 0.9) {
        e.a.patch = bounded_faces[e.a.patch];
        e.b.patch = bounded_faces[e.b.patch];
        if !iso.contains(&e) && crosses_its_seam(faces, e.a.patch, bounds, &shared, e.a.side, tol) {
            iso.push(e);
        }
    }
    let mut trims = Vec::new();
    let mut pairs: HashMap<(usize, usize), Vec<SharedBoundary>> = HashMap::new();
    for t in topology_edges(bounds, tol) {
        let candidates = pairs.entry((t.a, t.b)).or_insert_with(|| iso_candidates(faces, t.a, t.b, tol));
        match iso_form(faces, candidates, &t, tol) {
            Some(e) if !iso.contains(&e) => iso.push(e),
            Some(_) => {}
            None => trims.push(t),
        }
    }
    trims.extend(mixed_edges(faces, bounds, &bounded, tol));
    (iso, trims)
}

/// Whether bounded face `k` on a closed surface crosses the surface's seam line (`side`),
/// so that the seam is an edge of the face with itself. It does not when a bound curve of
/// it lies on the line and is an edge the file shares with another face: the face ends
/// there (a ring sector's or a fillet's quarter cylinder, whose surface was made a whole
/// turn, only touches its seam, and listing it would add an edge the file's topology does
/// not have). A seam edge (a whole torus's, a hemisphere's) is used by the face alone; a
/// face with no curve on the line runs across it (a STEP cylinder band between two
/// circles); trimming curves that name no edge (IGES 144) keep the seam. `shared` tells
/// the edge pieces the file gives to more than one face.
fn crosses_its_seam(
    faces: &[Face],
    k: usize,
    bounds: &[BoundCurve],
    shared: &dyn Fn(&BoundCurve) -> bool,
    side: cadmorph_nurbs::Side,
    tol: f64,
) -> bool {
    use cadmorph_nurbs::CurveProject;
    let line = faces[k].surface.boundary(side);
    let on_tol = 1e-3 * tol;
    !bounds.iter().filter(|b| b.face == k && shared(b)).any(|b| {
        (1..=5).all(|i| {
            let t = b.range.0 + (b.range.1 - b.range.0) * i as f64 / 6.0;
            line.project(&b.curve.eval(t), 1e-3 * on_tol).distance_sq.sqrt() <= on_tol
        })
    })
}

/// Edges between a face with bound curves and a bare surface (IGES: a trimmed plane
/// closing a set of untrimmed B-spline patches, like a transom or a deck): a bound curve
/// of the one that lies on an iso-boundary of the other over its length. Bare
/// boundaries that have shrunk to a point (a patch closing at a stem) pair with nothing.
fn mixed_edges(faces: &[Face], bounds: &[BoundCurve], bounded: &[bool], tol: f64) -> Vec<TrimEdge> {
    if bounded.iter().all(|&b| b) || bounded.iter().all(|&b| !b) {
        return Vec::new();
    }
    let key =
        |m: &cadmorph_nurbs::math::Matrix4<f64>| -> [u64; 16] { std::array::from_fn(|k| m.as_slice()[k].to_bits()) };
    let mut groups: Vec<([u64; 16], Vec<TrimCurve>)> = Vec::new();
    let mut push = |k: [u64; 16], c: TrimCurve| match groups.iter_mut().find(|g| g.0 == k) {
        Some(g) => g.1.push(c),
        None => groups.push((k, vec![c])),
    };
    for b in bounds {
        push(key(&b.placement), TrimCurve { patch: b.face, curve: b.curve.clone(), label: Some(b.label) });
    }
    for (k, f) in faces.iter().enumerate().filter(|(k, _)| !bounded[*k]) {
        for side in cadmorph_nurbs::Side::ALL {
            let c = f.surface.boundary(side);
            let d = c.domain();
            let length: f64 = (0..16)
                .map(|i| {
                    let t = |j: usize| d.start() + (d.end() - d.start()) * j as f64 / 16.0;
                    (c.eval(t(i + 1)) - c.eval(t(i))).norm()
                })
                .sum();
            if length > tol {
                push(key(&f.placement), TrimCurve { patch: k, curve: c, label: None });
            }
        }
    }
    groups
        .into_iter()
        .flat_map(|(_, curves)| shared_curves(&curves, tol, 32, 0.9))
        .filter(|e| e.a != e.b && bounded[e.a] != bounded[e.b])
        .collect()
}

/// The shared edges of `bounds` that are not among the iso-boundary edges `iso`.
pub(crate) fn trims_off(faces: &[Face], bounds: &[BoundCurve], iso: &[SharedBoundary]) -> Vec<TrimEdge> {
    let tol = edge_tol(faces);
    topology_edges(bounds, tol)
        .into_iter()
        .filter(|t| !iso.iter().any(|e| t.lies_on(e, &faces[e.a.patch].surface, tol)))
        .collect()
}

/// The iso-boundary pairs between faces `a` and `b`, numbered as in `faces`.
fn iso_candidates(faces: &[Face], a: usize, b: usize, tol: f64) -> Vec<SharedBoundary> {
    let pair = [&faces[a].surface, &faces[b].surface];
    shared_boundaries(&pair, tol, 64, 0.9)
        .into_iter()
        .map(|mut e| {
            e.a.patch = if e.a.patch == 0 { a } else { b };
            e.b.patch = if e.b.patch == 0 { a } else { b };
            e
        })
        .collect()
}

/// The iso-boundary edge that topology edge `t` is, if any: its two faces have
/// iso-boundaries that lie on each other, `t`'s curve lies on that overlap, and the
/// overlap's ends are `t`'s ends, distinct (so the iso edge is the trimmed edge, not
/// more, and not a closed loop).
fn iso_form(faces: &[Face], candidates: &[SharedBoundary], t: &TrimEdge, tol: f64) -> Option<SharedBoundary> {
    let ends = [t.curve.eval(t.range.0), t.curve.eval(t.range.1)];
    candidates.iter().copied().find(|e| {
        let first = &faces[e.a.patch].surface;
        if !t.lies_on(e, first, tol) {
            return false;
        }
        // The ends must meet to 1e-6 of the model (`tol` is 1e-3 of it) on one of the
        // two faces (on the other, a gap the file has may move them: the defect hull's
        // 32.7 mm): an analytic face's NURBS made over its box with margins (IGES
        // 192/194 cylinders and cones, 2 % longer than the face) overhangs the edge on
        // both, and measured as the edge it read the overhangs as a 0.06 mm gap.
        let ends_tol = 1e-3 * tol;
        let covers = |p: &Point3<f64>| ends.iter().any(|q| (p - q).norm() <= ends_tol);
        let side = first.boundary(e.a.side);
        let (p0, p1) = (side.eval(e.a_range.0), side.eval(e.a_range.1));
        let other = faces[e.b.patch].surface.boundary(e.b.side);
        let (q0, q1) = (other.eval(e.b_range.0), other.eval(e.b_range.1));
        // A closed overlap (a whole circle) has no ends to pair the two sides by: the
        // linear map of ranges would pair points at different angles.
        (p0 - p1).norm() > tol && ((covers(&p0) && covers(&p1)) || (covers(&q0) && covers(&q1)))
    })
}

/// Every pair of distinct faces using the same edge piece, in order of first use; then
/// the free curves (trimming curves, which name no partner, and named edges that only
/// one face uses) that lie on each other within `tol` over their length, paired only
/// between faces with the same placement (never across assembly instances).
fn topology_edges(bounds: &[BoundCurve], tol: f64) -> Vec<TrimEdge> {
    let mut order: Vec<(EntityRef, u32, usize)> = Vec::new();
    let mut users: HashMap<(EntityRef, u32, usize), Vec<&BoundCurve>> = HashMap::new();
    let mut free: Vec<&BoundCurve> = Vec::new();
    for b in bounds {
        match b.edge {
            Some(e) => {
                let key = (e, b.edge_index, b.piece);
                let list = users.entry(key).or_default();
                if list.is_empty() {
                    order.push(key);
                }
                if !list.iter().any(|x| x.face == b.face) {
                    list.push(b);
                }
            }
            None => free.push(b),
        }
    }
    let mut out = Vec::new();
    for key in order {
        let mut list = users[&key].clone();
        if list.len() == 1 {
            free.push(list[0]);
            continue;
        }
        list.sort_by_key(|b| b.face);
        for i in 0..list.len() {
            for j in i + 1..list.len() {
                out.push(TrimEdge {
                    a: list[i].face,
                    b: list[j].face,
                    curve: list[i].curve.clone(),
                    range: list[i].range,
                    label: vec![list[i].label],
                });
            }
        }
    }
    // One group per placement, in order of first use.
    let mut groups: Vec<([u64; 16], Vec<TrimCurve>)> = Vec::new();
    for b in free {
        let key: [u64; 16] = std::array::from_fn(|k| b.placement.as_slice()[k].to_bits());
        let curve = TrimCurve { patch: b.face, curve: b.curve.clone(), label: Some(b.label) };
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push(curve),
            None => groups.push((key, vec![curve])),
        }
    }
    for (_, curves) in groups {
        out.extend(shared_curves(&curves, tol, 32, 0.9));
    }
    out
}
