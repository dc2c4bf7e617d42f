//! [`CadDocument`] for IGES: faces from 144/143/510 and bare surfaces, bound curves from
//! the face-bound walk ([`Document::face_bounds`]), free 126 curves, and the edits as
//! whole-record rewrites.

use std::collections::{BTreeMap, HashMap, HashSet};

use cadmorph_brep::{
    BoundCurve, CadDocument, EntityRef, Face, FaceSet, Format, FreeCurve, ReadDocument, Skipped, SurfaceKind, Units,
};
use cadmorph_nurbs::math::{Matrix4, Point3};
use cadmorph_nurbs::{Curve, CurveProject, NurbsCurve, NurbsSurface, Surface};

use crate::bounds::FaceBound;
use crate::document::{Document, EntityId};
use crate::entity::View;

fn r(id: EntityId) -> EntityRef {
    EntityRef::new(Format::Iges, u64::from(id.0))
}

fn de(e: EntityRef) -> cadmorph_brep::Result<EntityId> {
    u32::try_from(e.id).ok().filter(|_| e.format == Format::Iges).map(EntityId).ok_or_else(|| {
        cadmorph_brep::Error::new(Format::Iges, crate::Error::NoEntity { de: u32::try_from(e.id).unwrap_or(u32::MAX) })
    })
}

fn err(e: crate::Error) -> cadmorph_brep::Error {
    cadmorph_brep::Error::new(Format::Iges, e)
}

/// The brep kind of IGES surface entity type `t`.
fn kind_of(t: u32) -> SurfaceKind {
    match t {
        108 | 190 => SurfaceKind::Plane,
        192 => SurfaceKind::Cylinder,
        194 => SurfaceKind::Cone,
        196 => SurfaceKind::Sphere,
        198 => SurfaceKind::Torus,
        120 => SurfaceKind::Revolution,
        122 => SurfaceKind::Extrusion,
        118 => SurfaceKind::Ruled,
        140 => SurfaceKind::Offset,
        114 => SurfaceKind::Spline,
        128 => SurfaceKind::BSpline,
        _ => SurfaceKind::Other,
    }
}

/// `curve` trimmed to the part between `start` and `end` (by closest points), or its
/// whole domain for a closed edge or when the two ends do not lie on it.
fn edge_range(curve: &NurbsCurve, start: Option<Point3<f64>>, end: Option<Point3<f64>>) -> (f64, f64) {
    let d = curve.domain();
    let whole = (*d.start(), *d.end());
    let (Some(s), Some(e)) = (start, end) else { return whole };
    let size = curve.bounding_box().diagonal().max(f64::MIN_POSITIVE);
    let tol = 1e-6 * size;
    let ps = curve.project(&s, tol * 1e-3);
    let pe = curve.project(&e, tol * 1e-3);
    if ps.distance_sq > tol * tol || pe.distance_sq > tol * tol || (ps.t - pe.t).abs() <= 1e-9 * (whole.1 - whole.0) {
        return whole;
    }
    (ps.t.min(pe.t), ps.t.max(pe.t))
}

impl Document {
    /// The member curve entities of `curve` (the members of a 102, else itself), each
    /// with its model-space pieces.
    fn members(&self, curve: EntityId) -> Vec<(EntityId, Vec<NurbsCurve>)> {
        let ids = match self.view(curve) {
            Ok(View::CompositeCurve(c)) => c.curves,
            _ => vec![curve],
        };
        ids.into_iter().map(|m| (m, self.curve(m).unwrap_or_default())).collect()
    }

    /// The vertex `k` (1-based) of 502 list `id`, cached per list.
    fn vertex(&self, cache: &mut HashMap<EntityId, Vec<Point3<f64>>>, id: EntityId, k: i64) -> Option<Point3<f64>> {
        let list = cache.entry(id).or_insert_with(|| match self.view(id) {
            Ok(View::VertexList(v)) => v.vertices,
            _ => Vec::new(),
        });
        usize::try_from(k).ok().and_then(|k| k.checked_sub(1)).and_then(|k| list.get(k).copied())
    }
}

impl Document {
    /// Moves vertex `k` (1-based) of 502 list `list` to where `c` has the end of `b`'s
    /// range that the vertex was at on `b.curve` (within `1e-9` of the curve's size; the
    /// same fraction of `c`'s domain as of the old curve's); a vertex at neither end
    /// stays. Returns whether it moved.
    fn move_vertex_with(&mut self, list: EntityId, k: i64, b: &BoundCurve, c: &NurbsCurve) -> crate::Result<bool> {
        let Some(old) = self.vertex(&mut HashMap::new(), list, k) else { return Ok(false) };
        let ends = [b.range.0, b.range.1];
        let size = b.curve.control_points().iter().map(|p| p.coords.norm()).fold(1.0, f64::max);
        let Some(&t) = ends.iter().find(|&&t| (b.curve.eval(t) - old).norm() <= 1e-9 * size) else {
            return Ok(false);
        };
        // The new curve runs the way the old one did over its own domain (a traced iso
        // line takes the face's parameter): the same fraction of the domain.
        let (d0, d1) = (b.curve.domain(), c.domain());
        let f = (t - d0.start()) / (d0.end() - d0.start());
        let new = c.eval(d1.start() + f * (d1.end() - d1.start()));
        let mut values = self.entity(list)?.values();
        let at = usize::try_from(k).ok().and_then(|k| k.checked_sub(1)).map(|k| 2 + 3 * k);
        let Some(at) = at.filter(|&at| at + 3 <= values.len()) else { return Ok(false) };
        for (i, x) in new.coords.iter().enumerate() {
            values[at + i] = crate::document::Value::Real(*x);
        }
        self.set_values(list, values, None)
    }
}

/// The inverse of a 408 placement (last row exactly `0 0 0 1`, as `transformed` needs),
/// `None` for the identity; a singular one (scale 0) is
/// refused naming `at`.
fn local(placement: &Matrix4<f64>, at: EntityRef) -> cadmorph_brep::Result<Option<Matrix4<f64>>> {
    if *placement == Matrix4::identity() {
        return Ok(None);
    }
    cadmorph_nurbs::math::affine_inverse(placement).map(Some).ok_or_else(|| {
        err(crate::Error::Transform {
            de: u32::try_from(at.id).unwrap_or(u32::MAX),
            reason: "the subfigure instances placing it have a singular matrix (scale 0)",
        })
    })
}

impl CadDocument for Document {
    fn format(&self) -> Format {
        Format::Iges
    }

    fn units(&self) -> cadmorph_brep::Result<Units> {
        let g = self.global();
        Ok(Units {
            metres_per_unit: g.millimetres_per_unit().map_or(f64::NAN, |mm| mm * 1e-3),
            name: g.unit_name(),
            uncertainty: g.min_resolution(),
        })
    }

    fn entity_counts(&self) -> BTreeMap<String, usize> {
        self.counts_by_type().into_iter().map(|(k, v)| (k.to_string(), v)).collect()
    }

    fn unknown_entities(&self) -> usize {
        Document::unknown_entities(self).len()
    }

    fn faces(&self) -> cadmorph_brep::Result<FaceSet> {
        let reversed = self.reversed_faces();
        let mut out = FaceSet::default();
        let faces = Document::try_faces(self).map_err(err)?;
        let surfaces = self.face_surfaces(&faces);
        for (f, surface) in faces.into_iter().zip(surfaces) {
            let t = self.entity(f.surface).map(|e| e.entity_type()).unwrap_or(0);
            let entity = r(f.face).with_occurrence(f.occurrence);
            match surface {
                Ok(es) => {
                    let (ud, vd) = es.surface.domain();
                    out.faces.push(Face {
                        entity,
                        surface_entity: r(f.surface).with_occurrence(f.occurrence),
                        parameter_box: ((*ud.start(), *ud.end()), (*vd.start(), *vd.end())),
                        surface: es.surface,
                        reversed: reversed.get(&f.face).copied().unwrap_or(false),
                        trimmed: f.trimmed,
                        kind: kind_of(t),
                        type_name: format!("IGES {t}"),
                        placement: f.placement,
                    });
                }
                Err(e) => out.skipped.push(Skipped { entity, reason: e.to_string() }),
            }
        }
        Ok(out)
    }

    fn bound_curves(&self, faces: &[Face]) -> cadmorph_brep::Result<Vec<BoundCurve>> {
        let mut out = Vec::new();
        let mut vertices = HashMap::new();
        for (fi, face) in faces.iter().enumerate() {
            let id = de(face.entity)?;
            if face.entity == face.surface_entity {
                continue;
            }
            // A face placed by 408 instances: its curves placed alike, its edges and
            // curves named at its occurrence (never shared with another placement).
            let (at, placed) = (face.entity.occurrence, face.placement != Matrix4::identity());
            for bound in self.face_bounds(id).map_err(err)? {
                let (label, curve, edge) = match bound {
                    FaceBound::Trim { domain: true, .. } | FaceBound::Trim { curve: None, .. } => continue,
                    FaceBound::Trim { bound, curve: Some(c), .. } => (bound, c, None),
                    FaceBound::Edge { list, index } => {
                        let Some(e) = self.list_edge(list, index) else { continue };
                        (e.curve, e.curve, Some((list, index, e)))
                    }
                };
                let members = self.members(curve);
                let total: usize = members.iter().map(|(_, p)| p.len()).sum();
                let mut piece = 0;
                for (m, pieces) in &members {
                    for c in pieces {
                        let d = c.domain();
                        let range = match &edge {
                            Some((_, _, e)) if total == 1 => {
                                let s = self.vertex(&mut vertices, e.start.0, e.start.1);
                                let t = self.vertex(&mut vertices, e.end.0, e.end.1);
                                edge_range(c, s, t)
                            }
                            _ => (*d.start(), *d.end()),
                        };
                        let at = |id: EntityId| r(id).with_occurrence(at);
                        out.push(BoundCurve {
                            face: fi,
                            label: at(label),
                            edge: edge.as_ref().map(|(list, _, _)| at(*list)),
                            edge_index: edge.as_ref().map_or(0, |(_, index, _)| u32::try_from(*index).unwrap_or(0)),
                            target: (pieces.len() == 1).then(|| at(*m)),
                            piece,
                            curve: if placed { c.transformed(&face.placement) } else { c.clone() },
                            range,
                            placement: face.placement,
                        });
                        piece += 1;
                    }
                }
            }
        }
        Ok(out)
    }

    fn free_curves(&self) -> cadmorph_brep::Result<Vec<FreeCurve>> {
        // Curves that bound any face (converted or not) are not free.
        let mut bounding: HashSet<EntityId> = HashSet::new();
        for f in Document::faces(self) {
            for b in self.face_bounds(f.face).unwrap_or_default() {
                let c = match b {
                    FaceBound::Trim { curve: Some(c), .. } => c,
                    FaceBound::Edge { list, index } => match self.list_edge(list, index) {
                        Some(e) => e.curve,
                        None => continue,
                    },
                    FaceBound::Trim { curve: None, .. } => continue,
                };
                bounding.extend(self.members(c).into_iter().map(|(m, _)| m));
            }
        }
        let mut ids: Vec<EntityId> = Vec::new();
        for e in self.entities() {
            match e.entity_type() {
                126 if e.directory().status.subordinate == 0 && e.directory().status.entity_use != 5 => {
                    ids.push(e.id())
                }
                142 => {
                    if let Ok(View::CurveOnSurface(c)) = self.view(e.id()) {
                        if let Some(m) = c.model_curve {
                            if self.entity(m).map(|x| x.entity_type()) == Ok(126) {
                                ids.push(m);
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        ids.sort();
        ids.dedup();
        let mut out = Vec::new();
        for id in ids.into_iter().filter(|id| !bounding.contains(id)) {
            let Ok(pieces) = self.curve(id) else { continue };
            if let [c] = pieces.as_slice() {
                out.push(FreeCurve { entity: r(id), curve: c.clone() });
            }
        }
        Ok(out)
    }

    fn bspline_form(&mut self, face: &Face) -> cadmorph_brep::Result<NurbsSurface> {
        if face.kind == SurfaceKind::BSpline {
            return Ok(face.surface.clone());
        }
        let id = de(face.surface_entity)?;
        self.replace_with_bspline(id).map_err(err)?;
        // Placed where the face is (a 408 instance's placement).
        Ok(self.surface(id).map_err(err)?.surface.transformed(&face.placement))
    }

    fn set_face_surface(&mut self, face: &Face, s: &NurbsSurface) -> cadmorph_brep::Result<bool> {
        // A face placed by 408 instances goes back into its 308 definition's space.
        match local(&face.placement, face.surface_entity)? {
            Some(inv) => self.set_bspline_surface(de(face.surface_entity)?, &s.transformed(&inv)),
            None => self.set_bspline_surface(de(face.surface_entity)?, s),
        }
        .map_err(err)
    }

    fn set_bound_curve(&mut self, b: &BoundCurve, c: &NurbsCurve) -> cadmorph_brep::Result<bool> {
        // A curve placed by 408 instances goes back into its 308 definition's space.
        if let Some(inv) = local(&b.placement, b.label)?.filter(|_| b.target.is_some()) {
            let back = BoundCurve { curve: b.curve.transformed(&inv), placement: Matrix4::identity(), ..b.clone() };
            return self.set_bound_curve(&back, &c.transformed(&inv));
        }
        let Some(target) = b.target else { return Ok(false) };
        let written = self.set_bspline_curve(de(target)?, c).map_err(err)?;
        // A 504 edge's vertices (502 lists) follow its new curve, as STEP's do.
        if let Some(list) = b.edge {
            if let Some(e) = self.list_edge(de(list)?, i64::from(b.edge_index)) {
                for (vl, k) in [e.start, e.end] {
                    self.move_vertex_with(vl, k, b, c).map_err(err)?;
                }
            }
        }
        Ok(written)
    }

    fn set_free_curve(&mut self, f: &FreeCurve, c: &NurbsCurve) -> cadmorph_brep::Result<bool> {
        self.set_control_points(de(f.entity)?, c.control_points(), c.weights()).map_err(err)
    }

    fn unshare(&mut self, moved: &[EntityRef]) -> cadmorph_brep::Result<usize> {
        let mut set = std::collections::HashSet::with_capacity(moved.len());
        for &e in moved {
            set.insert((de(e)?, e.occurrence));
        }
        self.unshare_subfigures(&set).map_err(err)
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
