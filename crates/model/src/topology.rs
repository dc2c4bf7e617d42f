//! Edges and face orientation from a file's topology: STEP B-rep edges, IGES 186/514/510
//! with 508 loops over 504 edge lists, and IGES 144/143 trimming curves that lie on each
//! other (the only adjacency a trimmed-surface file without B-rep carries).

use std::collections::{BTreeMap, HashMap};

use cadmorph_iges as iges;
use cadmorph_nurbs::{Curve, CurveProject, NurbsCurve};
use cadmorph_seam::{shared_curves, TrimCurve, TrimEdge};
use cadmorph_step as step;

use crate::model::{Patch, Source};
use crate::Result;

/// Pairs `(i, j)`, `i < j`, of the distinct entries of `faces`.
fn pairs(faces: &[usize]) -> Vec<(usize, usize)> {
    let mut f = faces.to_vec();
    f.sort_unstable();
    f.dedup();
    let mut out = Vec::new();
    for i in 0..f.len() {
        for j in i + 1..f.len() {
            out.push((f[i], f[j]));
        }
    }
    out
}

/// The patch index of every face of `faces` (from [`step::Document::faces`]), given that
/// `patches` were made from the same list in order, skipping faces that did not convert.
pub(crate) fn step_face_patches(faces: &[step::Face], patches: &[Patch]) -> Vec<Option<usize>> {
    let mut next = 0;
    faces
        .iter()
        .map(|f| match patches.get(next).map(|p| p.source) {
            Some(Source::Step { face, .. }) if face == f.id.0 => {
                next += 1;
                Some(next - 1)
            }
            _ => None,
        })
        .collect()
}

/// Every STEP edge bounding two (or more) different patches, with its curve trimmed to
/// the edge. Edges used twice by one face (the seam of a closed surface) bound nothing
/// else and are left out.
pub(crate) fn step_edges(doc: &step::Document, patches: &[Patch]) -> Result<Vec<TrimEdge>> {
    let faces = doc.faces()?;
    let patch_of = step_face_patches(&faces, patches);
    let mut out = Vec::new();
    for e in doc.edges(&faces)? {
        let users: Vec<usize> = e.faces.iter().filter_map(|&f| patch_of[f]).collect();
        let pairs = pairs(&users);
        if pairs.is_empty() {
            continue;
        }
        let wc = doc.edge_curve(&e)?;
        let d = wc.curve.domain();
        for (a, b) in pairs {
            out.push(TrimEdge {
                a,
                b,
                curve: wc.curve.clone(),
                range: (*d.start(), *d.end()),
                label: Some(format!("#{}", e.id.0)),
            });
        }
    }
    Ok(out)
}

/// IGES face orientation from B-rep shells: a 510 face is reversed when its 514 shell
/// says its normal opposes the shell's, flipped again for a 186 solid's shell whose
/// orientation flag is false. Faces in no shell are not in the map.
pub(crate) fn iges_reversed_faces(doc: &iges::Document) -> HashMap<u32, bool> {
    let mut shell_flip: HashMap<u32, bool> = HashMap::new();
    for e in doc.entities().filter(|e| e.entity_type() == 186) {
        if let Ok(iges::View::ManifoldSolid(m)) = doc.view(e.id()) {
            shell_flip.insert(m.shell.0, !m.same_orientation);
            for (v, same) in m.voids {
                shell_flip.insert(v.0, !same);
            }
        }
    }
    let mut out = HashMap::new();
    for e in doc.entities().filter(|e| e.entity_type() == 514) {
        if let Ok(iges::View::Shell(s)) = doc.view(e.id()) {
            let flip = shell_flip.get(&e.id().0).copied().unwrap_or(false);
            for (f, agrees) in s.faces {
                out.insert(f.0, !agrees ^ flip);
            }
        }
    }
    out
}

/// The curve pieces of IGES entity `id` in model space, or none when it does not convert.
fn pieces(doc: &iges::Document, id: iges::EntityId) -> Vec<NurbsCurve> {
    doc.curve(id).unwrap_or_default()
}

/// `curve` trimmed to the part between `start` and `end` (by closest points), or its
/// whole domain for a closed edge or when the two ends do not lie on it.
fn edge_range(curve: &NurbsCurve, start: Option<[f64; 3]>, end: Option<[f64; 3]>) -> (f64, f64) {
    let d = curve.domain();
    let whole = (*d.start(), *d.end());
    let (Some(s), Some(e)) = (start, end) else { return whole };
    let size = curve.bounding_box().diagonal().max(f64::MIN_POSITIVE);
    let tol = 1e-6 * size;
    let ps = curve.project(&s.into(), tol * 1e-3);
    let pe = curve.project(&e.into(), tol * 1e-3);
    if ps.distance_sq > tol * tol || pe.distance_sq > tol * tol || (ps.t - pe.t).abs() <= 1e-9 * (whole.1 - whole.0) {
        return whole;
    }
    (ps.t.min(pe.t), ps.t.max(pe.t))
}

/// What bounds an IGES face: a model-space trimming curve (of a 142 under a 144, or of a
/// 141 under a 143), or an edge of a 504 list that a 508 loop of a 510 face uses.
pub(crate) enum FaceBound {
    /// A trimming curve and the entity that names it in reports (the 142, or the curve).
    Trim { curve: iges::EntityId, label: iges::EntityId },
    /// Edge `index` (1-based) of 504 list `list`.
    Edge { list: iges::EntityId, index: i64 },
}

/// Every bound of every IGES face among `patches`, with the patch's index. A 144 whose
/// outer boundary is its surface's domain contributes only its inner ones.
pub(crate) fn iges_face_bounds(doc: &iges::Document, patches: &[Patch]) -> Vec<(usize, FaceBound)> {
    let mut out = Vec::new();
    for (pi, p) in patches.iter().enumerate() {
        let Source::Iges { face, .. } = p.source else { continue };
        match doc.view(iges::EntityId(face)) {
            Ok(iges::View::Face(f)) => {
                for lp in f.loops {
                    if let Ok(iges::View::Loop(l)) = doc.view(lp) {
                        for le in l.edges.iter().filter(|le| le.kind == 0) {
                            out.push((pi, FaceBound::Edge { list: le.list, index: le.index }));
                        }
                    }
                }
            }
            Ok(iges::View::TrimmedSurface(t)) => {
                for b in t.outer.filter(|_| !t.outer_is_domain).into_iter().chain(t.inner) {
                    if let Ok(iges::View::CurveOnSurface(c)) = doc.view(b) {
                        if let Some(curve) = c.model_curve {
                            out.push((pi, FaceBound::Trim { curve, label: b }));
                        }
                    }
                }
            }
            Ok(iges::View::BoundedSurface(bs)) => {
                for b in bs.boundaries {
                    if let Ok(iges::View::Boundary(bd)) = doc.view(b) {
                        for bc in bd.curves {
                            out.push((pi, FaceBound::Trim { curve: bc.curve, label: bc.curve }));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// IGES shared edges: edges of 504 lists used by the 508 loops of two 510 faces, and
/// trimming curves (142 model-space curves of 144 faces, 141 boundaries of 143 faces)
/// of different faces that lie on each other within `tol`.
pub(crate) fn iges_edges(doc: &iges::Document, patches: &[Patch], tol: f64) -> Vec<TrimEdge> {
    let mut out = Vec::new();
    let mut uses: BTreeMap<(u32, i64), Vec<usize>> = BTreeMap::new();
    let mut trims: Vec<TrimCurve> = Vec::new();
    for (pi, bound) in iges_face_bounds(doc, patches) {
        match bound {
            FaceBound::Edge { list, index } => uses.entry((list.0, index)).or_default().push(pi),
            FaceBound::Trim { curve, label } => {
                for c in pieces(doc, curve) {
                    trims.push(TrimCurve { patch: pi, curve: c, label: Some(format!("DE {}", label.0)) });
                }
            }
        }
    }
    let mut vertices: HashMap<u32, Vec<[f64; 3]>> = HashMap::new();
    let mut vertex = |id: iges::EntityId, k: i64| -> Option<[f64; 3]> {
        let list = vertices.entry(id.0).or_insert_with(|| match doc.view(id) {
            Ok(iges::View::VertexList(v)) => v.vertices.iter().map(|p| [p.x, p.y, p.z]).collect(),
            _ => Vec::new(),
        });
        usize::try_from(k).ok().and_then(|k| k.checked_sub(1)).and_then(|k| list.get(k).copied())
    };
    for ((list, index), users) in uses {
        let pairs = pairs(&users);
        if pairs.is_empty() {
            continue;
        }
        let Ok(iges::View::EdgeList(el)) = doc.view(iges::EntityId(list)) else { continue };
        let Some(edge) = usize::try_from(index).ok().and_then(|k| k.checked_sub(1)).and_then(|k| el.edges.get(k))
        else {
            continue;
        };
        let curves = pieces(doc, edge.curve);
        let ends = (vertex(edge.start.0, edge.start.1), vertex(edge.end.0, edge.end.1));
        for curve in curves.iter() {
            let range = if curves.len() == 1 {
                edge_range(curve, ends.0, ends.1)
            } else {
                let d = curve.domain();
                (*d.start(), *d.end())
            };
            for &(a, b) in &pairs {
                out.push(TrimEdge {
                    a,
                    b,
                    curve: curve.clone(),
                    range,
                    label: Some(format!("DE {list} edge {index}")),
                });
            }
        }
    }
    out.extend(shared_curves(&trims, tol, 32, 0.9));
    out
}
