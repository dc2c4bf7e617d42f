//! [`CadDocument`] for STEP: faces of every shape representation and assembly
//! occurrence, bound curves from their loops' `EDGE_CURVE`s, and the edits with the
//! file's sharing of points kept ([`Document::write_surface_shared`],
//! [`Document::set_edge_curve`]).

use std::collections::{BTreeMap, HashMap};

use cadmorph_brep::{
    BoundCurve, CadDocument, EntityRef, Face, FaceSet, Format, FreeCurve, ReadDocument, Skipped, SurfaceKind as Kind,
    Units,
};
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface};

use crate::document::Document;
use crate::views::SurfaceKind;
use crate::EntityId;

fn err(e: crate::Error) -> cadmorph_brep::Error {
    cadmorph_brep::Error::new(Format::Step, e)
}

fn r(id: EntityId, occurrence: usize) -> EntityRef {
    EntityRef::new(Format::Step, id.0).with_occurrence(u32::try_from(occurrence).unwrap_or(u32::MAX))
}

fn id_of(e: EntityRef) -> cadmorph_brep::Result<EntityId> {
    if e.format == Format::Step {
        Ok(EntityId(e.id))
    } else {
        Err(err(crate::Error::NoSuchInstance(EntityId(e.id))))
    }
}

fn kind_of(k: &SurfaceKind) -> (Kind, String) {
    match k {
        SurfaceKind::Plane => (Kind::Plane, "Plane".into()),
        SurfaceKind::Cylinder => (Kind::Cylinder, "Cylinder".into()),
        SurfaceKind::Cone => (Kind::Cone, "Cone".into()),
        SurfaceKind::Sphere => (Kind::Sphere, "Sphere".into()),
        SurfaceKind::Torus => (Kind::Torus, "Torus".into()),
        SurfaceKind::Revolution => (Kind::Revolution, "Revolution".into()),
        SurfaceKind::Extrusion => (Kind::Extrusion, "Extrusion".into()),
        SurfaceKind::BSpline { .. } => (Kind::BSpline, "B_SPLINE_SURFACE".into()),
        SurfaceKind::Other(name) => (Kind::Other, name.clone()),
    }
}

impl Document {
    /// The STEP face behind brep face `face` (same instance and occurrence).
    fn step_face(&self, face: &Face) -> cadmorph_brep::Result<crate::Face> {
        let id = id_of(face.entity)?;
        let occ = face.entity.occurrence as usize;
        self.faces()
            .map_err(err)?
            .into_iter()
            .find(|f| f.id == id && f.occurrence == occ)
            .ok_or_else(|| err(crate::Error::NoSuchInstance(id)))
    }
}

impl CadDocument for Document {
    fn format(&self) -> Format {
        Format::Step
    }

    fn units(&self) -> cadmorph_brep::Result<Units> {
        let u = Document::units(self).map_err(err)?;
        Ok(Units { metres_per_unit: u.length.metres, name: u.length.name, uncertainty: u.uncertainty })
    }

    fn entity_counts(&self) -> BTreeMap<String, usize> {
        Document::entity_counts(self)
    }

    fn unknown_entities(&self) -> usize {
        0
    }

    fn faces(&self) -> cadmorph_brep::Result<FaceSet> {
        let mut out = FaceSet::default();
        let faces = Document::faces(self).map_err(err)?;
        for (f, world) in faces.iter().zip(self.faces_nurbs(&faces)) {
            let entity = r(f.id, f.occurrence);
            match world {
                Ok(ws) => {
                    let (kind, type_name) = kind_of(&f.kind);
                    out.faces.push(Face {
                        entity,
                        surface_entity: r(f.surface, f.occurrence),
                        surface: ws.surface,
                        parameter_box: (ws.u_range, ws.v_range),
                        reversed: !f.same_sense,
                        trimmed: true,
                        kind,
                        type_name,
                        placement: f.transform,
                    });
                }
                Err(e) => out.skipped.push(Skipped { entity, reason: e.to_string() }),
            }
        }
        Ok(out)
    }

    fn bound_curves(&self, faces: &[Face]) -> cadmorph_brep::Result<Vec<BoundCurve>> {
        let step_faces = Document::faces(self).map_err(err)?;
        let index: HashMap<(u64, u32), usize> =
            faces.iter().enumerate().map(|(i, f)| ((f.entity.id, f.entity.occurrence), i)).collect();
        let to_brep: Vec<Option<usize>> = step_faces
            .iter()
            .map(|f| index.get(&(f.id.0, u32::try_from(f.occurrence).unwrap_or(u32::MAX))).copied())
            .collect();
        let mut out = Vec::new();
        for e in self.edges(&step_faces).map_err(err)? {
            let mut users: Vec<usize> = e.faces.iter().filter_map(|&f| to_brep[f]).collect();
            users.dedup();
            if users.is_empty() {
                continue;
            }
            let Ok(wc) = self.edge_curve(&e) else { continue };
            let d = wc.curve.domain();
            let edge = r(e.id, e.occurrence);
            let mut seen = Vec::new();
            for fi in users {
                if seen.contains(&fi) {
                    continue;
                }
                seen.push(fi);
                out.push(BoundCurve {
                    face: fi,
                    label: EntityRef::new(Format::Step, e.id.0),
                    edge: Some(edge),
                    edge_index: 0,
                    target: Some(edge),
                    piece: 0,
                    curve: wc.curve.clone(),
                    range: (*d.start(), *d.end()),
                    placement: e.transform,
                });
            }
        }
        Ok(out)
    }

    /// STEP curves outside faces (wireframe) are not read yet: none.
    fn free_curves(&self) -> cadmorph_brep::Result<Vec<FreeCurve>> {
        Ok(Vec::new())
    }

    fn bspline_form(&mut self, face: &Face) -> cadmorph_brep::Result<NurbsSurface> {
        if face.kind == Kind::BSpline {
            return Ok(face.surface.clone());
        }
        let f = self.step_face(face)?;
        self.replace_with_bspline(&f).map_err(err)?;
        let f = self.step_face(face)?;
        Ok(self.face_nurbs(&f).map_err(err)?.surface)
    }

    fn set_face_surface(&mut self, face: &Face, s: &NurbsSurface) -> cadmorph_brep::Result<bool> {
        self.write_surface_shared(id_of(face.surface_entity)?, &face.placement, s).map_err(err)
    }

    fn set_bound_curve(&mut self, b: &BoundCurve, c: &NurbsCurve) -> cadmorph_brep::Result<bool> {
        let Some(target) = b.target else { return Ok(false) };
        self.set_edge_curve(id_of(target)?, &b.placement, c).map_err(err)
    }

    fn set_free_curve(&mut self, f: &FreeCurve, _c: &NurbsCurve) -> cadmorph_brep::Result<bool> {
        Err(err(crate::Error::NoSuchInstance(id_of(f.entity)?)))
    }

    fn unshare(&mut self, moved: &[EntityRef]) -> cadmorph_brep::Result<usize> {
        let mut set = std::collections::HashSet::with_capacity(moved.len());
        for &e in moved {
            set.insert((id_of(e)?, e.occurrence as usize));
        }
        Document::unshare(self, &set).map_err(err)
    }

    fn to_bytes(&self) -> Vec<u8> {
        self.write()
    }

    fn read_back(&self) -> cadmorph_brep::Result<Box<dyn CadDocument>> {
        Ok(Box::new(<Self as ReadDocument>::from_bytes(&self.write())?))
    }
}

impl ReadDocument for Document {
    fn from_bytes(bytes: &[u8]) -> cadmorph_brep::Result<Self> {
        Document::parse(bytes).map_err(err)
    }
}
