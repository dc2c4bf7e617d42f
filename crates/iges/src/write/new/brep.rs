//! Faces with their loops as IGES B-rep solids (186 manifold solid → 514 shell → 510
//! faces → 508 loops → 504 edges → 502 vertices), for conversion from STEP solids.

use cadmorph_brep::{orient_outward, BoundedFace, Shell};
use cadmorph_nurbs::{Aabb, NurbsCurve};

use super::DocumentBuilder;
use crate::document::{EntityId, Status, Value};
use crate::edit::{bspline_curve_values, bspline_surface_values};
use crate::error::{Error, Result};

impl DocumentBuilder {
    /// Adds `faces` (`whole[i]`: face `i` is its whole surface): each connected piece
    /// that closes up is turned outward ([`orient_outward`]) and written as a manifold
    /// solid B-rep (IGES 5.3 §4.150–4.155, entity 186 over a 514 closed shell whose 510
    /// faces carry 508 loops of 504 edges between 502 vertices; each edge use with its
    /// parameter-space curve from [`Shell::pcurves`], so a reader measures the faces as
    /// given); every other face is written on its own, a whole one as its 128 surface and
    /// a trimmed one by [`add_trimmed_face`](Self::add_trimmed_face). Loop ends closer
    /// than `tol` are one vertex. Returns the number of solids.
    ///
    /// A 510 face's loops run counterclockwise around its surface's normal (`S_u × S_v`),
    /// each edge use's parameter curve running with the loop, and the 514 shell's
    /// orientation flag tells whether the face's normal agrees with the surface's, as
    /// OCCT's IGES reader takes them (`IGESToBRep_BRepEntity::TransferLoop`).
    ///
    /// # Errors
    ///
    /// [`Error::Geometry`] on the surface's DE number when a parameter curve cannot be
    /// fitted (a bound curve that is not on its surface).
    pub fn add_bounded_faces(&mut self, faces: &[BoundedFace], whole: &[bool], tol: f64) -> Result<usize> {
        let mut oriented = faces.to_vec();
        let pieces = orient_outward(&mut oriented, tol);
        let mut solids = 0;
        for (members, closed) in &pieces {
            if *closed {
                let piece: Vec<BoundedFace> = members.iter().map(|&f| oriented[f].clone()).collect();
                self.add_solid(&piece, tol)?;
                solids += 1;
                continue;
            }
            for &f in members {
                if whole.get(f).copied().unwrap_or(false) {
                    self.add_surface(&faces[f].surface);
                } else {
                    self.add_trimmed_face(&faces[f], tol)?;
                }
            }
        }
        Ok(solids)
    }

    /// One 186 solid of `faces`, which close up with outward normals.
    fn add_solid(&mut self, faces: &[BoundedFace], tol: f64) -> Result<EntityId> {
        let dependent = Status { subordinate: 1, ..Status::default() };
        let parametric = Status { subordinate: 1, entity_use: 5, ..Status::default() };
        let ptr = |id: EntityId| Value::Integer(i64::from(id.0));
        let int = |i: usize| Value::Integer(i as i64);
        let shell = Shell::from_faces(faces, tol);
        let size =
            Aabb::from_points(faces.iter().flat_map(|f| f.surface.control_points())).map_or(1.0, |b| b.diagonal());
        let surfaces: Vec<EntityId> = faces
            .iter()
            .map(|f| {
                self.track(f.surface.control_points());
                self.push(0, dependent, bspline_surface_values(&f.surface))
            })
            .collect();
        let pcurves =
            shell.pcurves(faces, size).map_err(|(f, source)| Error::Geometry { de: surfaces[f].0, source })?;
        let mut vl = vec![Value::Integer(502), int(shell.vertices.len())];
        for p in &shell.vertices {
            vl.extend([Value::Real(p.x), Value::Real(p.y), Value::Real(p.z)]);
        }
        let vlist = self.push(1, dependent, vl);
        let curves: Vec<EntityId> = shell
            .edges
            .iter()
            .map(|e| {
                self.track(e.curve.control_points());
                self.push(0, dependent, bspline_curve_values(&e.curve))
            })
            .collect();
        let mut el = vec![Value::Integer(504), int(shell.edges.len())];
        for (e, &c) in shell.edges.iter().zip(&curves) {
            el.extend([ptr(c), ptr(vlist), int(e.start + 1), ptr(vlist), int(e.end + 1)]);
        }
        let elist = self.push(1, dependent, el);
        let mut face_ids = Vec::with_capacity(faces.len());
        for (fi, f) in faces.iter().enumerate() {
            let mut loops = Vec::with_capacity(shell.loops[fi].len());
            for (lp, pcs) in shell.loops[fi].iter().zip(&pcurves[fi]) {
                // Each use: (edge, runs with the edge's curve, its parameter curve, which
                // runs with the edge's curve).
                let mut uses: Vec<(usize, bool, &NurbsCurve)> =
                    lp.iter().zip(pcs).map(|(&(e, agrees), pc)| (e, agrees, pc)).collect();
                if f.reversed {
                    // Around the surface's normal rather than the face's.
                    uses = uses.into_iter().rev().map(|(e, agrees, pc)| (e, !agrees, pc)).collect();
                }
                let mut l = vec![Value::Integer(508), int(uses.len())];
                for (e, agrees, pc) in uses {
                    // The parameter curve runs with the loop (OCCT reverses it with
                    // the edge when the orientation flag is 0).
                    let pc = if agrees { pc.clone() } else { pc.reversed() };
                    let p = self.push(0, parametric, bspline_curve_values(&pc));
                    l.extend([int(0), ptr(elist), int(e + 1), int(usize::from(agrees)), int(1), int(0), ptr(p)]);
                }
                loops.push(self.push(1, dependent, l));
            }
            let mut v = vec![Value::Integer(510), ptr(surfaces[fi]), int(loops.len()), int(1)];
            v.extend(loops.iter().map(|&l| ptr(l)));
            face_ids.push(self.push(1, dependent, v));
        }
        let mut sh = vec![Value::Integer(514), int(face_ids.len())];
        for (&id, f) in face_ids.iter().zip(faces) {
            sh.extend([ptr(id), int(usize::from(!f.reversed))]);
        }
        let shell_id = self.push(1, dependent, sh);
        Ok(self.push(0, Status::default(), vec![Value::Integer(186), ptr(shell_id), int(1), int(0)]))
    }
}
