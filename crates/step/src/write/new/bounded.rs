//! Faces bounded by arbitrary loops (trimmed faces, holes), for conversion from IGES and
//! for any writer that knows its faces' boundary curves.

use cadmorph_brep::{orient_outward, BoundedFace, Shell};
use cadmorph_nurbs::{Aabb, NurbsCurve};

use super::{knot_lists, real_list, DocumentBuilder};
use crate::error::{Error, Position, Result};

impl DocumentBuilder {
    /// Adds `faces` as one shell (see [`Shell::from_faces`] for how vertices and edges are
    /// shared within `tol`): each an `ADVANCED_FACE` with a `FACE_OUTER_BOUND` and one
    /// `FACE_BOUND` per hole (ISO 10303-42 §5.4.24), `same_sense` false for a reversed
    /// face, each loop an `EDGE_LOOP` of `ORIENTED_EDGE`s on `EDGE_CURVE`s. An edge's
    /// geometry is a `SURFACE_CURVE` (a `SEAM_CURVE` for the seam of a closed surface)
    /// holding the model-space curve and, for each face that uses the edge, its `PCURVE`
    /// on that face's surface ([`Shell::pcurves`]), so a reader measures the faces as
    /// exactly as they were given instead of projecting the curves itself.
    ///
    /// Each connected piece of faces that closes up is turned so that its normals point
    /// out ([`orient_outward`]) and written as a `CLOSED_SHELL` held by a
    /// `MANIFOLD_SOLID_BREP`; the other pieces are `OPEN_SHELL`s of one
    /// `SHELL_BASED_SURFACE_MODEL`, their faces as given. Returns the number of solids.
    ///
    /// # Errors
    ///
    /// [`Error::Edit`] naming the face whose parameter curve cannot be fitted (a bound
    /// curve that is not on its surface).
    pub fn add_bounded_faces(&mut self, faces: &[BoundedFace], tol: f64) -> Result<usize> {
        let mut faces = faces.to_vec();
        let pieces = orient_outward(&mut faces, tol);
        let faces = faces.as_slice();
        let shell = Shell::from_faces(faces, tol);
        let size =
            Aabb::from_points(faces.iter().flat_map(|f| f.surface.control_points())).map_or(1.0, |b| b.diagonal());
        let pcurves = shell.pcurves(faces, size).map_err(|(f, e)| Error::Edit {
            at: Position { line: 0, column: 0, id: None },
            reason: format!("face {} of the shell: its parameter curve: {e}", f + 1),
        })?;
        let surface: Vec<u64> = faces.iter().map(|f| self.surface(&f.surface)).collect();
        let vertex: Vec<u64> = shell
            .vertices
            .iter()
            .map(|p| {
                let pt = self.point(p);
                self.add(format!("VERTEX_POINT('',#{pt})"))
            })
            .collect();
        // Per edge, the faces using it with their parameter curves.
        let mut uses: Vec<Vec<(usize, &NurbsCurve)>> = vec![Vec::new(); shell.edges.len()];
        for (fi, loops) in shell.loops.iter().enumerate() {
            for (lp, pcs) in loops.iter().zip(&pcurves[fi]) {
                for (&(e, _), pc) in lp.iter().zip(pcs) {
                    uses[e].push((fi, pc));
                }
            }
        }
        let context = self.add(
            "( GEOMETRIC_REPRESENTATION_CONTEXT(2) PARAMETRIC_REPRESENTATION_CONTEXT() REPRESENTATION_CONTEXT('2D SPACE','') )"
                .to_owned(),
        );
        let mut edge = Vec::with_capacity(shell.edges.len());
        for (e, u) in shell.edges.iter().zip(&uses) {
            let g = self.curve(&e.curve);
            let mut pcs = Vec::with_capacity(u.len());
            for &(fi, pc) in u {
                let c2 = self.curve_2d(pc);
                let rep = self.add(format!("DEFINITIONAL_REPRESENTATION('',(#{c2}),#{context})"));
                pcs.push(format!("#{}", self.add(format!("PCURVE('',#{},#{rep})", surface[fi]))));
            }
            let seam = u.len() == 2 && u[0].0 == u[1].0;
            let kind = if seam { "SEAM_CURVE" } else { "SURFACE_CURVE" };
            let sc = self.add(format!("{kind}('',#{g},({}),.CURVE_3D.)", pcs.join(",")));
            edge.push(self.add(format!("EDGE_CURVE('',#{},#{},#{sc},.T.)", vertex[e.start], vertex[e.end])));
        }
        let mut ids = Vec::with_capacity(faces.len());
        for (fi, (f, loops)) in faces.iter().zip(&shell.loops).enumerate() {
            let mut bounds = Vec::with_capacity(loops.len());
            for (k, lp) in loops.iter().enumerate() {
                let list: Vec<String> = lp
                    .iter()
                    .map(|&(e, agrees)| {
                        let o = self.add(format!(
                            "ORIENTED_EDGE('',*,*,#{},{})",
                            edge[e],
                            if agrees { ".T." } else { ".F." }
                        ));
                        format!("#{o}")
                    })
                    .collect();
                let l = self.add(format!("EDGE_LOOP('',({}))", list.join(",")));
                let kind = if k == 0 { "FACE_OUTER_BOUND" } else { "FACE_BOUND" };
                bounds.push(format!("#{}", self.add(format!("{kind}('',#{l},.T.)"))));
            }
            let sense = if f.reversed { ".F." } else { ".T." };
            ids.push(format!(
                "#{}",
                self.add(format!("ADVANCED_FACE('',({}),#{},{sense})", bounds.join(","), surface[fi]))
            ));
        }
        let mut open = Vec::new();
        let mut solids = 0;
        for (members, closed) in &pieces {
            let list: Vec<&str> = members.iter().map(|&f| ids[f].as_str()).collect();
            if *closed {
                let sh = self.add(format!("CLOSED_SHELL('',({}))", list.join(",")));
                let solid = self.add(format!("MANIFOLD_SOLID_BREP('',#{sh})"));
                self.items.push(solid);
                solids += 1;
            } else {
                open.push(format!("#{}", self.add(format!("OPEN_SHELL('',({}))", list.join(",")))));
            }
        }
        if !open.is_empty() {
            let model = self.add(format!("SHELL_BASED_SURFACE_MODEL('',({}))", open.join(",")));
            self.items.push(model);
        }
        Ok(solids)
    }

    /// A non-rational planar curve `(x, y, 0)` as a 2D `B_SPLINE_CURVE_WITH_KNOTS`.
    fn curve_2d(&mut self, c: &NurbsCurve) -> u64 {
        let ids: Vec<String> = c
            .control_points()
            .iter()
            .map(|p| format!("#{}", self.add(format!("CARTESIAN_POINT('',{})", real_list([p.x, p.y])))))
            .collect();
        let (m, k) = knot_lists(c.knots());
        self.add(format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{},({}),.UNSPECIFIED.,.F.,.F.,{m},{k},.UNSPECIFIED.)",
            c.degree(),
            ids.join(",")
        ))
    }
}
