//! The one walk over what bounds an IGES face (144 → 142, 143 → 141, 510 → 508 → 504)
//! and face orientation from B-rep shells (186 → 514), used for face tracing, edge
//! finding and the parameter boxes of unbounded surfaces.

use std::collections::HashMap;

use crate::document::{Document, EntityId};
use crate::entity::View;
use crate::error::Result;

/// One bound of an IGES face (IGES 5.3 §4.34, §4.33, §4.149, §4.148, §4.147).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceBound {
    /// A trimming curve: a 142 under a 144 (its model-space curve, when it names one), or
    /// a model-space curve of a 141 under a 143.
    Trim {
        /// The entity that bounds the face: the 142, or the 141's curve.
        bound: EntityId,
        /// Its model-space curve (the 142's `BPTR`, or the 141's curve itself).
        curve: Option<EntityId>,
        /// The 144's outer boundary when the 144 says it is the surface's domain
        /// (`N1 = 0`): it trims nothing.
        domain: bool,
    },
    /// Edge `index` (1-based) of 504 list `list`, used by a 508 loop of a 510 face.
    Edge {
        /// The 504 edge list.
        list: EntityId,
        /// 1-based index into it.
        index: i64,
    },
}

impl Document {
    /// What bounds face entity `face` (144, 143, 510), in the order the file lists the
    /// bounds; empty for any other entity. Loop edges of kind 1 (vertex loops) are left
    /// out.
    ///
    /// # Errors
    ///
    /// Bound entities whose records do not read.
    pub fn face_bounds(&self, face: EntityId) -> Result<Vec<FaceBound>> {
        let mut out = Vec::new();
        match self.view(face)? {
            View::Face(f) => {
                for lp in f.loops {
                    if let View::Loop(l) = self.view(lp)? {
                        for le in l.edges.iter().filter(|le| le.kind == 0) {
                            out.push(FaceBound::Edge { list: le.list, index: le.index });
                        }
                    }
                }
            }
            View::TrimmedSurface(t) => {
                let outer = t.outer.map(|b| (b, t.outer_is_domain));
                for (b, domain) in outer.into_iter().chain(t.inner.iter().map(|&b| (b, false))) {
                    let curve = match self.view(b)? {
                        View::CurveOnSurface(c) => c.model_curve,
                        _ => None,
                    };
                    out.push(FaceBound::Trim { bound: b, curve, domain });
                }
            }
            View::BoundedSurface(bs) => {
                for b in bs.boundaries {
                    if let View::Boundary(bd) = self.view(b)? {
                        for bc in bd.curves {
                            out.push(FaceBound::Trim { bound: bc.curve, curve: Some(bc.curve), domain: false });
                        }
                    }
                }
            }
            _ => {}
        }
        Ok(out)
    }

    /// The model-space curve of a 504 edge, with its start and end vertex positions
    /// (`None` where the vertex list or index does not resolve).
    pub(crate) fn list_edge(&self, list: EntityId, index: i64) -> Option<crate::entity::Edge> {
        let View::EdgeList(el) = self.view(list).ok()? else { return None };
        let k = usize::try_from(index).ok()?.checked_sub(1)?;
        el.edges.get(k).cloned()
    }

    /// Face orientation from B-rep shells: a 510 face is reversed when its 514 shell says
    /// its normal opposes the shell's, flipped again for a 186 solid's shell whose
    /// orientation flag is false (IGES 5.3 §4.150, §4.151). Faces in no shell are not in
    /// the map.
    pub fn reversed_faces(&self) -> HashMap<EntityId, bool> {
        let mut shell_flip: HashMap<EntityId, bool> = HashMap::new();
        for e in self.entities().filter(|e| e.entity_type() == 186) {
            if let Ok(View::ManifoldSolid(m)) = self.view(e.id()) {
                shell_flip.insert(m.shell, !m.same_orientation);
                for (v, same) in m.voids {
                    shell_flip.insert(v, !same);
                }
            }
        }
        let mut out = HashMap::new();
        for e in self.entities().filter(|e| e.entity_type() == 514) {
            if let Ok(View::Shell(s)) = self.view(e.id()) {
                let flip = shell_flip.get(&e.id()).copied().unwrap_or(false);
                for (f, agrees) in s.faces {
                    out.insert(f, !agrees ^ flip);
                }
            }
        }
        out
    }
}
