//! A polyhedral mesh (OpenFOAM's face-based description) from a cell list: each volume
//! cell contributes its faces (outward, [`CellKind::faces`]); a face met twice is
//! internal, owned by the lower cell, and internal faces are put in OpenFOAM's
//! upper-triangular order (by owner, then neighbour). Faces met once form one boundary
//! patch `boundary` of type `wall`, unless the caller names the patch of each boundary
//! face.

use std::collections::HashMap;

use nalgebra::Point3;

use crate::format::foam::{Patch, PolyMesh};
use crate::{Cell, Error, Result};

impl PolyMesh {
    /// The polyhedral mesh of the volume cells in `cells` (surface and line cells are
    /// ignored).
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] for a cell node that is not a point; [`Error::Topology`] for
    /// a face shared by three or more cells, or no volume cell at all.
    pub fn from_cells(points: Vec<Point3<f64>>, cells: &[Cell]) -> Result<PolyMesh> {
        let vol: Vec<&Cell> = cells.iter().filter(|c| c.kind.dim() == 3).collect();
        if vol.is_empty() {
            return Err(Error::Topology("no volume cell (tetrahedron, pyramid, wedge or hexahedron)".into()));
        }
        let mut map: HashMap<Vec<usize>, (usize, Vec<usize>, Option<usize>)> = HashMap::new();
        for (ci, c) in vol.iter().enumerate() {
            if c.kind.n_nodes() != Some(c.nodes.len()) {
                return Err(Error::Topology(format!(
                    "cell {ci}: a {:?} has {:?} nodes, found {}",
                    c.kind,
                    c.kind.n_nodes(),
                    c.nodes.len()
                )));
            }
            if let Some(&n) = c.nodes.iter().find(|&&n| n >= points.len()) {
                return Err(Error::OutOfRange {
                    what: "cell",
                    index: ci,
                    target_kind: "point",
                    target: n as i64,
                    count: points.len(),
                });
            }
            for local in c.kind.faces() {
                let f: Vec<usize> = local.iter().map(|&k| c.nodes[k]).collect();
                let mut key = f.clone();
                key.sort_unstable();
                match map.get_mut(&key) {
                    None => {
                        map.insert(key, (ci, f, None));
                    }
                    Some(e) => {
                        if e.2.is_some() {
                            return Err(Error::Topology(format!(
                                "face {key:?} is shared by three or more cells (cells {}, {:?}, {ci})",
                                e.0, e.2
                            )));
                        }
                        e.2 = Some(ci);
                    }
                }
            }
        }
        let mut internal: Vec<(usize, usize, Vec<usize>)> = Vec::new();
        let mut boundary: Vec<(usize, Vec<usize>)> = Vec::new();
        for (_, (c, f, other)) in map {
            match other {
                Some(o) => {
                    // The face is oriented outward of `c`; the owner is the lower cell.
                    if c < o {
                        internal.push((c, o, f));
                    } else {
                        let mut r = f;
                        r.reverse();
                        internal.push((o, c, r));
                    }
                }
                None => boundary.push((c, f)),
            }
        }
        internal.sort_unstable_by_key(|a| (a.0, a.1));
        boundary.sort_unstable();
        let ni = internal.len();
        let nb = boundary.len();
        let mut faces = Vec::with_capacity(ni + nb);
        let mut owner = Vec::with_capacity(ni + nb);
        let mut neighbour = Vec::with_capacity(ni);
        for (o, n, f) in internal {
            faces.push(f);
            owner.push(o);
            neighbour.push(n);
        }
        for (o, f) in boundary {
            faces.push(f);
            owner.push(o);
        }
        let patches = vec![Patch { name: "boundary".into(), kind: "wall".into(), start_face: ni, n_faces: nb }];
        PolyMesh::try_new(points, faces, owner, neighbour, patches)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CellKind;

    #[test]
    fn two_tets_share_one_face() {
        let p = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [1., 1., 1.]];
        let pts = p.iter().map(|&c| Point3::from(c)).collect();
        // Both positively oriented: (p1 − p0) × (p2 − p0) · (p3 − p0) > 0.
        let cells = [Cell::new(CellKind::Tetra, vec![0, 1, 2, 3]), Cell::new(CellKind::Tetra, vec![1, 2, 3, 4])];
        let m = PolyMesh::from_cells(pts, &cells).unwrap();
        assert_eq!(m.n_internal_faces(), 1);
        assert_eq!(m.n_faces(), 7);
        let q = crate::quality::Quality::of(&m);
        assert!(q.ok(), "{}", q.table());
        assert!((q.total_volume - (1.0 / 6.0 + 1.0 / 3.0)).abs() < 1e-15, "{}", q.total_volume);
    }
}
