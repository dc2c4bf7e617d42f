//! Trimmed faces (144 over 142 curves on the surface), for conversion from STEP and for
//! any writer that knows its faces' boundary curves.

use cadmorph_brep::{BoundedFace, Shell};
use cadmorph_nurbs::{Aabb, NurbsCurve};

use super::DocumentBuilder;
use crate::document::{EntityId, Status, Value};
use crate::edit::{bspline_curve_values, bspline_surface_values};
use crate::error::{Error, Result};

impl DocumentBuilder {
    /// Adds `face` as a trimmed surface, the form OCCT's IGES writer uses by default
    /// (IGES 5.3 §4.34 entity 144, §4.32 entity 142): a 144 on the face's 128 surface,
    /// its outer loop then its holes each a 142 curve on the surface with both curves:
    /// the model-space curve (`CPTR`) and the parameter-space curve (`BPTR`, fitted by
    /// [`Shell::pcurves`], with `PREF = 1`: a reader measures the face in its
    /// parameters), each a 126 (a loop of one curve) or a 102 composite of 126s. Loop
    /// ends closer than `tol` are one point. Loops run counterclockwise in the surface's
    /// `(u, v)` (holes clockwise) whatever the face's orientation, which a 144 does not
    /// record. Returns the 144's DE number.
    ///
    /// # Errors
    ///
    /// [`Error::Geometry`] on the surface's DE number when a parameter curve cannot be
    /// fitted (a bound curve that is not on the surface).
    pub fn add_trimmed_face(&mut self, face: &BoundedFace, tol: f64) -> Result<EntityId> {
        let dependent = Status { subordinate: 1, ..Status::default() };
        let parametric = Status { subordinate: 1, entity_use: 5, ..Status::default() };
        let ptr = |id: EntityId| Value::Integer(i64::from(id.0));
        self.track(face.surface.control_points());
        let surface = self.push(0, dependent, bspline_surface_values(&face.surface));
        let shell = Shell::from_faces(std::slice::from_ref(face), tol);
        let size = Aabb::from_points(face.surface.control_points()).map_or(1.0, |b| b.diagonal());
        let pcurves = shell
            .pcurves(std::slice::from_ref(face), size)
            .map_err(|(_, source)| Error::Geometry { de: surface.0, source })?;
        let mut bounds = Vec::with_capacity(face.loops.len());
        for (lp, pcs) in shell.loops[0].iter().zip(&pcurves[0]) {
            // Each use along the loop: the edge's curves, turned to run with the loop.
            let mut pairs: Vec<(NurbsCurve, NurbsCurve)> = lp
                .iter()
                .zip(pcs)
                .map(|(&(e, agrees), pc)| {
                    let c = &shell.edges[e].curve;
                    if agrees {
                        (c.clone(), pc.clone())
                    } else {
                        (c.reversed(), pc.reversed())
                    }
                })
                .collect();
            if face.reversed {
                pairs = pairs.into_iter().rev().map(|(c, pc)| (c.reversed(), pc.reversed())).collect();
            }
            let mut model = Vec::with_capacity(pairs.len());
            let mut param = Vec::with_capacity(pairs.len());
            for (c, pc) in &pairs {
                self.track(c.control_points());
                model.push(self.push(0, dependent, bspline_curve_values(c)));
                param.push(self.push(0, parametric, bspline_curve_values(pc)));
            }
            let model_curve = self.composite(&model, dependent);
            let param_curve = self.composite(&param, parametric);
            bounds.push(self.push(
                0,
                dependent,
                vec![
                    Value::Integer(142),
                    Value::Integer(0),
                    ptr(surface),
                    ptr(param_curve),
                    ptr(model_curve),
                    Value::Integer(1),
                ],
            ));
        }
        let holes = bounds.len().saturating_sub(1);
        let mut v = vec![Value::Integer(144), ptr(surface), Value::Integer(1), Value::Integer(holes as i64)];
        v.extend(bounds.iter().map(|&b| ptr(b)));
        Ok(self.push(0, Status::default(), v))
    }

    /// One curve as it is, several as a 102 composite curve of them.
    fn composite(&mut self, ids: &[EntityId], status: Status) -> EntityId {
        if let [one] = ids {
            return *one;
        }
        let mut v = vec![Value::Integer(102), Value::Integer(ids.len() as i64)];
        v.extend(ids.iter().map(|&i| Value::Integer(i64::from(i.0))));
        self.push(0, status, v)
    }
}
