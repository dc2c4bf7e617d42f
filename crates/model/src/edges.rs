//! Shared edges from a document's bound curves: curves of the same topological edge
//! used by two faces (STEP `EDGE_CURVE`s, IGES 504 edges), and trimming curves of two
//! faces that lie on each other (IGES 144/143 without B-rep), besides the iso-boundaries
//! that coincide.

use std::collections::HashMap;

use cadmorph_brep::{BoundCurve, EntityRef, Face};
use cadmorph_nurbs::NurbsSurface;
use cadmorph_seam::{shared_boundaries, shared_curves, SharedBoundary, TrimCurve, TrimEdge};

/// The diagonal of the box around all control points of `faces`.
pub(crate) fn size_of(faces: &[Face]) -> f64 {
    let pts = faces.iter().flat_map(|p| p.surface.control_points());
    cadmorph_nurbs::Aabb::from_points(pts).map_or(0.0, |b| b.diagonal())
}

/// How far apart two sides may be and still be one edge: `1e-3 ×` the model size.
pub(crate) fn edge_tol(faces: &[Face]) -> f64 {
    1e-3 * size_of(faces)
}

/// The iso-boundary edges of `faces` and the other shared edges of `bounds` (those that
/// are not also iso-boundary edges).
pub(crate) fn shared_edges(faces: &[Face], bounds: &[BoundCurve]) -> (Vec<SharedBoundary>, Vec<TrimEdge>) {
    let tol = edge_tol(faces);
    let refs: Vec<&NurbsSurface> = faces.iter().map(|p| &p.surface).collect();
    let iso = shared_boundaries(&refs, tol, 64, 0.9);
    let trims = trims_off(faces, bounds, &iso);
    (iso, trims)
}

/// The shared edges of `bounds` that are not among the iso-boundary edges `iso`.
pub(crate) fn trims_off(faces: &[Face], bounds: &[BoundCurve], iso: &[SharedBoundary]) -> Vec<TrimEdge> {
    let tol = edge_tol(faces);
    topology_edges(bounds, tol)
        .into_iter()
        .filter(|t| !iso.iter().any(|e| t.lies_on(e, &faces[e.a.patch].surface, tol)))
        .collect()
}

/// Every pair of distinct faces using the same edge piece, and the trimming curves that
/// lie on each other within `tol`, in order of first use.
fn topology_edges(bounds: &[BoundCurve], tol: f64) -> Vec<TrimEdge> {
    let mut order: Vec<(EntityRef, u32, usize)> = Vec::new();
    let mut users: HashMap<(EntityRef, u32, usize), Vec<&BoundCurve>> = HashMap::new();
    let mut trims: Vec<TrimCurve> = Vec::new();
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
            None => trims.push(TrimCurve { patch: b.face, curve: b.curve.clone(), label: Some(b.label) }),
        }
    }
    let mut out = Vec::new();
    for key in order {
        let mut list = users[&key].clone();
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
    out.extend(shared_curves(&trims, tol, 32, 0.9));
    out
}
