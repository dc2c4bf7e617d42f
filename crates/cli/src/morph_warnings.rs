//! Warnings about a morph that will not do what its parameters suggest: an FFD box that
//! holds no control point of any face (the run would rewrite nothing), and an FFD whose
//! lattice nodes on the box faces move (the morph is then discontinuous where geometry
//! leaves the box, PyGeM #275). They go to standard error; the run goes on.

use cadmorph::brep::Face;
use cadmorph::morph::{Ffd, Parameters};

/// The warning for an FFD box that holds no control point of `faces`.
pub fn box_touches_no_face(ffd: &Ffd, faces: &[Face]) -> Option<String> {
    if faces.is_empty() {
        return None;
    }
    let points: Vec<_> = faces.iter().flat_map(|f| f.surface.control_points().iter().copied()).collect();
    if ffd.bind(&points).n_inside() > 0 {
        return None;
    }
    let (o, l) = (ffd.box_origin(), ffd.box_length());
    Some(format!(
        "the FFD box (origin {:.6}, {:.6}, {:.6}, lengths {:.6}, {:.6}, {:.6}) holds no control point of any of \
         the {} faces: nothing will move (see the model's bounding box with `cadmorph info`, or fit a box with \
         `cadmorph ffd fit`)",
        o.x,
        o.y,
        o.z,
        l.x,
        l.y,
        l.z,
        faces.len()
    ))
}

/// The warning for lattice nodes on the box faces with a displacement.
pub fn moved_boundary_nodes(ffd: &Ffd) -> Option<String> {
    let shape = ffd.n_control_points();
    let [l, m, n] = shape;
    let mut moved = Vec::new();
    for i in 0..l {
        for j in 0..m {
            for k in 0..n {
                let mu = ffd.mu().get(i, j, k);
                if crate::ffd::on_boundary([i, j, k], shape) && mu.iter().any(|c| *c != 0.0) {
                    moved.push(format!("[{i},{j},{k}]"));
                }
            }
        }
    }
    if moved.is_empty() {
        return None;
    }
    let shown: Vec<&str> = moved.iter().take(6).map(String::as_str).collect();
    Some(format!(
        "{} of the FFD's lattice nodes on the box faces move ({}{}): geometry that crosses the box faces \
         will tear there, since the morph is not continuous across them (PyGeM #275); keep the boundary \
         nodes still, or make the box hold the geometry that should move",
        moved.len(),
        shown.join(", "),
        if moved.len() > shown.len() { ", ..." } else { "" }
    ))
}

/// Every warning for `params` applied to `faces`.
pub fn warnings(params: &Parameters, faces: &[Face]) -> Vec<String> {
    match params {
        Parameters::Ffd(f) => box_touches_no_face(f, faces).into_iter().chain(moved_boundary_nodes(f)).collect(),
        _ => Vec::new(),
    }
}
