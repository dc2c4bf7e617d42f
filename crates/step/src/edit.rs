//! In-place edits: points, weights, analytic surfaces replaced by B-splines, and the
//! morph of a whole B-rep with its edges and vertices kept on the faces.

use std::collections::{HashMap, HashSet};

use cadmorph_nurbs::math::{Matrix4, Point3};
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface};

use crate::document::Document;
use crate::error::{Error, Result};
use crate::read::param::Body;
use crate::views::{Ctx, Edge, Face, SurfaceKind};
use crate::write::{knot_lists, real_list};
use crate::EntityId;

/// How [`Document::morph`] moves the edges and vertices of the morphed faces.
///
/// Measured by `tests/edits.rs::edge_policy_gap` (largest distance from 17 samples per
/// edge and from the vertices to the adjacent morphed faces, under the smooth non-affine
/// map `y·(1 + 0.05 sin(x/20)), z + 0.1 (y/4)²`):
///
/// | sample | `MoveControlPoints` | `Recompute` | file uncertainty |
/// | --- | --- | --- | --- |
/// | `hull3.stp` (10 edges) | 1.404e-10 m | 1.404e-10 m | 1e-7 m |
/// | `blade.stp` (3 edges) | 1.263e-12 m | 1.264e-12 m | 1e-7 m |
///
/// Both are at the floor of the projection used to measure: in these files (as OCCT and
/// most lofting tools write them) every edge curve is the boundary iso-curve of its
/// patches with the same knots and poles, so moving its poles with the map moves it
/// exactly with the face. [`Recompute`](EdgePolicy::Recompute) is the default because it
/// stays on the morphed face by construction when that is not so (an edge curve with
/// other knots or degree than the face, an interior iso-curve): it rebuilds the edge from
/// the morphed surface instead of mapping a second, independent set of control points.
/// That case is not in the samples and is not measured here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EdgePolicy {
    /// Apply the map to the control points of the edge curves and to the vertex points.
    /// Exact for affine maps; otherwise the edge follows the map, not the face.
    MoveControlPoints,
    /// Recompute each edge from a morphed adjacent face: the edge curve keeps its degree
    /// and knots, its control points interpolate `S'(u(tᵢ), v(tᵢ))` at the Greville
    /// abscissae `tᵢ`, with `(u, v)` the edge's parameter-space position on the original
    /// face; vertices become `S'(u, v)`. Rational edge curves fall back to moving their
    /// control points.
    #[default]
    Recompute,
}

/// What [`Document::morph`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct MorphReport {
    /// Distinct Cartesian points rewritten.
    pub points_moved: usize,
    /// Largest distance from an edge sample or vertex to an adjacent morphed face (model
    /// units).
    pub max_gap: f64,
    /// Edges measured.
    pub edges: usize,
}

impl Document {
    /// Moves the Cartesian point `#id` to `p` (file coordinates). Every curve and surface
    /// that lists the point moves with it, once.
    ///
    /// # Errors
    ///
    /// [`Error::NoSuchInstance`]; [`Error::UnexpectedEntity`] when `#id` is not a
    /// `CARTESIAN_POINT`; [`Error::Edit`] for a non-finite point.
    pub fn set_point(&mut self, id: EntityId, p: Point3<f64>) -> Result<()> {
        let k = self.index.get(id.0).ok_or(Error::NoSuchInstance(id))?;
        if !p.coords.iter().all(|c| c.is_finite()) {
            return Err(Error::Edit { at: self.position_of(k, 0), reason: "non-finite coordinates".into() });
        }
        let (start, end, dim) = {
            let body = self.body_at(k)?;
            let rec = match &body {
                Body::Simple(r) if r.name == "CARTESIAN_POINT" && r.params.len() == 2 => r,
                _ => {
                    return Err(Error::UnexpectedEntity {
                        at: self.position_of(k, 0),
                        expected: "CARTESIAN_POINT",
                        found: self.name_of(k).to_owned(),
                    })
                }
            };
            let p1 = &rec.params[1];
            let dim = p1.as_list().map_or(3, <[_]>::len);
            (p1.start, p1.end, dim)
        };
        let text = real_list(p.coords.iter().copied().take(dim.clamp(1, 3)));
        self.splice(k, start, end, &text)
    }

    /// Sets the weights of the rational B-spline curve or surface `#id` (row-major
    /// `i * n_v + j` for surfaces). A non-rational B-spline is rewritten in the
    /// rational complex form.
    ///
    /// # Errors
    ///
    /// [`Error::NoSuchInstance`], [`Error::UnexpectedEntity`] for other entities,
    /// [`Error::Edit`] for a wrong count or non-positive weights.
    pub fn set_weights(&mut self, id: EntityId, weights: &[f64]) -> Result<()> {
        let k = self.index.get(id.0).ok_or(Error::NoSuchInstance(id))?;
        let at = self.position_of(k, 0);
        if weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(Error::Edit { at, reason: "weights must be positive and finite".into() });
        }
        let ids = self.control_point_ids(id)?;
        if ids.len() != weights.len() {
            return Err(Error::Edit {
                at,
                reason: format!("{} weights for {} control points", weights.len(), ids.len()),
            });
        }
        enum Plan {
            Splice(usize, usize, String),
            Rewrite(String),
        }
        let plan = {
            let text = self.text(k);
            let body = self.body_at(k)?;
            let raw = |s: usize, e: usize| String::from_utf8_lossy(&text[s..e]).into_owned();
            match &body {
                Body::Complex(_) => {
                    let (rat, rows) =
                        match (body.record("RATIONAL_B_SPLINE_SURFACE"), body.record("RATIONAL_B_SPLINE_CURVE")) {
                            (Some(r), _) => (
                                r,
                                body.record("B_SPLINE_SURFACE")
                                    .and_then(|b| b.params.get(2))
                                    .and_then(|p| p.as_list())
                                    .map(|l| l.len()),
                            ),
                            (_, Some(r)) => (r, None),
                            _ => {
                                return Err(Error::Edit {
                                    at,
                                    reason: "a complex B-spline without a rational leaf".into(),
                                })
                            }
                        };
                    let p = rat.params.first().ok_or(Error::Edit { at, reason: "empty rational leaf".into() })?;
                    Plan::Splice(p.start, p.end, weight_text(weights, rows))
                }
                Body::Simple(r) if r.name == "B_SPLINE_SURFACE_WITH_KNOTS" && r.params.len() == 13 => {
                    let ps = &r.params;
                    let n_u = ps[3].as_list().map_or(1, <[_]>::len);
                    let a: Vec<String> = ps.iter().map(|p| raw(p.start, p.end)).collect();
                    Plan::Rewrite(format!(
                        "#{} = ( BOUNDED_SURFACE() B_SPLINE_SURFACE({},{},{},{},{},{},{}) B_SPLINE_SURFACE_WITH_KNOTS({},{},{},{},{}) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE({}) REPRESENTATION_ITEM({}) SURFACE() );",
                        id.0, a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], a[9], a[10], a[11], a[12],
                        weight_text(weights, Some(n_u)), a[0]
                    ))
                }
                Body::Simple(r) if r.name == "B_SPLINE_CURVE_WITH_KNOTS" && r.params.len() == 9 => {
                    let a: Vec<String> = r.params.iter().map(|p| raw(p.start, p.end)).collect();
                    Plan::Rewrite(format!(
                        "#{} = ( BOUNDED_CURVE() B_SPLINE_CURVE({},{},{},{},{}) B_SPLINE_CURVE_WITH_KNOTS({},{},{}) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE({}) REPRESENTATION_ITEM({}) );",
                        id.0, a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], weight_text(weights, None), a[0]
                    ))
                }
                _ => {
                    return Err(Error::UnexpectedEntity {
                        at,
                        expected: "a B-spline curve or surface",
                        found: self.name_of(k).to_owned(),
                    })
                }
            }
        };
        match plan {
            Plan::Splice(s, e, t) => self.splice(k, s, e, &t),
            Plan::Rewrite(t) => self.replace_instance_text(id, t),
        }
    }

    /// Replaces the analytic surface of `face` by its exact B-spline form over the face's
    /// parameter box (same instance id, so every reference stays valid; new control
    /// points are added). The pcurves that lived on the analytic surface are dropped
    /// (their parameterisation no longer applies; readers rebuild them by projection):
    /// a `SURFACE_CURVE` keeps its other pcurves, or its edges point at its 3D curve.
    /// Returns the new surface's control point ids (row-major).
    ///
    /// # Errors
    ///
    /// [`Error::Edit`] when the face is already a B-spline or cannot be converted.
    pub fn replace_with_bspline(&mut self, face: &Face) -> Result<Vec<EntityId>> {
        let k = self.index.get(face.surface.0).ok_or(Error::NoSuchInstance(face.surface))?;
        if matches!(face.kind, SurfaceKind::BSpline { .. } | SurfaceKind::Other(_)) {
            return Err(Error::Edit { at: self.position_of(k, 0), reason: "not an analytic surface".into() });
        }
        // The exact form in the surface's own (file) coordinates.
        let mut local = face.clone();
        local.transform = Matrix4::identity();
        let exact = self.face_nurbs(&local)?.surface;
        let ids = self.write_bspline_surface(face.surface, &exact)?;
        self.drop_pcurves_on(face.surface)?;
        Ok(ids)
    }

    /// Rewrites the surface of `face` as the B-spline surface `s`, given in world
    /// coordinates and model units (the face's placement is undone here), with new
    /// control-point instances. Meant for refined surfaces (knot insertion, degree
    /// elevation): their parameterisation is the old one, so the face's pcurves stay
    /// valid and are kept. Returns the new control point ids (row-major).
    ///
    /// # Errors
    ///
    /// [`Error::NoSuchInstance`]; [`Error::Edit`] for a singular placement or
    /// non-finite values.
    pub fn set_face_surface(&mut self, face: &Face, s: &NurbsSurface) -> Result<Vec<EntityId>> {
        let k = self.index.get(face.surface.0).ok_or(Error::NoSuchInstance(face.surface))?;
        let inverse = face
            .transform
            .try_inverse()
            .ok_or_else(|| Error::Edit { at: self.position_of(k, 0), reason: "singular face placement".into() })?;
        let local = s.transformed(&inverse);
        if local.control_points().iter().any(|p| !p.coords.iter().all(|c| c.is_finite())) {
            return Err(Error::Edit { at: self.position_of(k, 0), reason: "non-finite control point".into() });
        }
        self.write_bspline_surface(face.surface, &local)
    }

    /// Rewrites instance `#id` as the (rational) B-spline surface `s` with new points.
    fn write_bspline_surface(&mut self, id: EntityId, s: &NurbsSurface) -> Result<Vec<EntityId>> {
        let mut ids = Vec::with_capacity(s.control_points().len());
        for p in s.control_points() {
            ids.push(self.add_instance(&format!("CARTESIAN_POINT('',{})", real_list(p.coords.iter().copied())))?);
        }
        let (n_u, n_v) = (s.n_u(), s.n_v());
        let rows = (0..n_u)
            .map(|i| {
                format!("({})", (0..n_v).map(|j| format!("#{}", ids[i * n_v + j].0)).collect::<Vec<_>>().join(","))
            })
            .collect::<Vec<_>>()
            .join(",");
        let (um, uk) = knot_lists(s.u_knots());
        let (vm, vk) = knot_lists(s.v_knots());
        let knots = format!("{um},{vm},{uk},{vk},.UNSPECIFIED.");
        let text = match s.weights() {
            Some(w) => format!(
                "#{} = ( BOUNDED_SURFACE() B_SPLINE_SURFACE({},{},({rows}),.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS({knots}) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE({}) REPRESENTATION_ITEM('') SURFACE() );",
                id.0,
                s.u_degree(),
                s.v_degree(),
                weight_text(w, Some(n_u))
            ),
            None => format!(
                "#{} = B_SPLINE_SURFACE_WITH_KNOTS('',{},{},({rows}),.UNSPECIFIED.,.F.,.F.,.F.,{knots});",
                id.0,
                s.u_degree(),
                s.v_degree()
            ),
        };
        self.replace_instance_text(id, text)?;
        Ok(ids)
    }

    /// Gives each of `edges` a new 3D curve: the non-rational B-spline curve given (world
    /// coordinates, model units; the edge's placement is undone here), written as a new
    /// instance that the edge's `SURFACE_CURVE`/`SEAM_CURVE` (where it has one) or the
    /// `EDGE_CURVE` itself then points at; the old curve stays in the file, unused by
    /// this edge. Meant for edges traced on morphed faces: each new curve must run the
    /// way the old one did between the edge's vertices, so the edge's sense and the
    /// vertices stay valid. Returns how many edges were given a curve.
    ///
    /// # Errors
    ///
    /// [`Error::NoSuchInstance`] for an unknown edge; [`Error::Edit`] for a singular
    /// placement, a rational or non-finite curve.
    pub fn set_edge_curves(&mut self, edges: &[(Edge, NurbsCurve)]) -> Result<usize> {
        let mut n = 0;
        for (e, c) in edges {
            let k = self.index.get(e.id.0).ok_or(Error::NoSuchInstance(e.id))?;
            let edit = |reason: &str| Error::Edit { at: self.position_of(k, 0), reason: reason.into() };
            if c.is_rational() {
                return Err(edit("rational edge curve"));
            }
            let inverse = e.transform.try_inverse().ok_or_else(|| edit("singular edge placement"))?;
            let local = c.transformed(&inverse);
            if local.control_points().iter().any(|p| !p.coords.iter().all(|x| x.is_finite())) {
                return Err(edit("non-finite edge curve"));
            }
            // Where the reference to the 3D curve sits: the SURFACE_CURVE's first
            // parameter, or the EDGE_CURVE's fourth.
            let kc = self.index.get(e.curve.0).ok_or(Error::NoSuchInstance(e.curve))?;
            let site = match self.body_at(kc)? {
                Body::Simple(r)
                    if matches!(self.name_of(kc), "SURFACE_CURVE" | "SEAM_CURVE")
                        && r.params.get(1).and_then(|p| p.as_ref_id()).is_some() =>
                {
                    Some((kc, r.params[1].start, r.params[1].end))
                }
                _ => match self.body_at(k)? {
                    Body::Simple(r) if r.params.len() == 5 => Some((k, r.params[3].start, r.params[3].end)),
                    _ => None,
                },
            };
            let Some((at, start, end)) = site else { continue };
            let mut ids = Vec::with_capacity(local.control_points().len());
            for p in local.control_points() {
                ids.push(self.add_instance(&format!("CARTESIAN_POINT('',{})", real_list(p.coords.iter().copied())))?);
            }
            let (mults, knots) = knot_lists(local.knots());
            let poles = ids.iter().map(|i| format!("#{}", i.0)).collect::<Vec<_>>().join(",");
            let curve = self.add_instance(&format!(
                "B_SPLINE_CURVE_WITH_KNOTS('',{},({poles}),.UNSPECIFIED.,.F.,.F.,{mults},{knots},.UNSPECIFIED.)",
                local.degree()
            ))?;
            self.splice(at, start, end, &format!("#{}", curve.0))?;
            n += 1;
        }
        Ok(n)
    }

    /// Instances that reference `#target`, by position.
    fn referrers(&self, target: EntityId) -> Vec<usize> {
        let needle = format!("#{}", target.0);
        (0..self.instances.len())
            .filter(|&k| {
                let t = self.text(k);
                let body = &t[self.instances[k].body as usize..];
                body.windows(needle.len())
                    .enumerate()
                    .any(|(i, w)| w == needle.as_bytes() && !body.get(i + needle.len()).is_some_and(u8::is_ascii_digit))
            })
            .collect()
    }

    fn drop_pcurves_on(&mut self, surface: EntityId) -> Result<()> {
        let pcurves: HashSet<u64> = self
            .referrers(surface)
            .into_iter()
            .filter(|&k| self.name_of(k) == "PCURVE")
            .map(|k| self.instances[k].id)
            .collect();
        if pcurves.is_empty() {
            return Ok(());
        }
        let mut owners = HashSet::new();
        for &pc in &pcurves {
            for k in self.referrers(EntityId(pc)) {
                if matches!(self.name_of(k), "SURFACE_CURVE" | "SEAM_CURVE") {
                    owners.insert(k);
                }
            }
        }
        let mut owners: Vec<usize> = owners.into_iter().collect();
        owners.sort_unstable();
        for k in owners {
            let id = EntityId(self.instances[k].id);
            let (keep, list_span, curve3d) = {
                let body = self.body_at(k)?;
                let Body::Simple(r) = &body else { continue };
                if r.params.len() != 4 {
                    continue;
                }
                let list = r.params[2].as_list().unwrap_or(&[]);
                let keep: Vec<u64> =
                    list.iter().filter_map(|p| p.as_ref_id()).map(|i| i.0).filter(|i| !pcurves.contains(i)).collect();
                (keep, (r.params[2].start, r.params[2].end), r.params[1].as_ref_id())
            };
            if !keep.is_empty() {
                let t = format!("({})", keep.iter().map(|i| format!("#{i}")).collect::<Vec<_>>().join(","));
                self.splice(k, list_span.0, list_span.1, &t)?;
            } else if let Some(c3) = curve3d {
                for e in self.referrers(id) {
                    if self.name_of(e) != "EDGE_CURVE" {
                        continue;
                    }
                    let span = match self.body_at(e)? {
                        Body::Simple(r) if r.params.len() == 5 && r.params[3].as_ref_id() == Some(id) => {
                            (r.params[3].start, r.params[3].end)
                        }
                        _ => continue,
                    };
                    self.splice(e, span.0, span.1, &format!("#{}", c3.0))?;
                }
            }
        }
        Ok(())
    }

    /// Morphs every B-spline face with `map` (world coordinates, model units): each
    /// Cartesian control point moves once, even when several surfaces share it; then the
    /// edges and vertices of those faces follow `policy`. Analytic faces stay as they
    /// are; convert them first with [`replace_with_bspline`](Self::replace_with_bspline)
    /// to morph them too. Points used under two different assembly placements move with
    /// the first.
    ///
    /// # Errors
    ///
    /// The views' errors; [`Error::Edit`] when the map gives a non-finite point.
    pub fn morph(&mut self, map: &dyn Fn(&Point3<f64>) -> Point3<f64>, policy: EdgePolicy) -> Result<MorphReport> {
        let faces = self.faces()?;
        let edges = self.edges(&faces)?;
        let originals: Vec<Option<NurbsSurface>> = faces
            .iter()
            .map(|f| match f.kind {
                SurfaceKind::BSpline { .. } => self.face_nurbs(f).ok().map(|w| w.surface),
                _ => None,
            })
            .collect();
        let mut moved: HashMap<u64, Point3<f64>> = HashMap::new();
        let move_point =
            |doc: &Document, moved: &mut HashMap<u64, Point3<f64>>, id: EntityId, t: &Matrix4<f64>| -> Result<()> {
                if moved.contains_key(&id.0) {
                    return Ok(());
                }
                let p = doc.point(id)?;
                let w = map(&t.transform_point(&p));
                let inv = t.try_inverse().unwrap_or_else(Matrix4::identity);
                moved.insert(id.0, inv.transform_point(&w));
                Ok(())
            };
        for (f, o) in faces.iter().zip(&originals) {
            if o.is_some() {
                for id in self.control_point_ids(f.surface)? {
                    move_point(self, &mut moved, id, &f.transform)?;
                }
            }
        }
        let morphed_face = |fi: usize| originals[fi].is_some();
        let ctx_doc = self.clone();
        let ctx = Ctx::new(&ctx_doc, ctx_doc.units()?.plane_angle);
        let mut edge_points: HashMap<u64, Point3<f64>> = HashMap::new();
        for e in &edges {
            let Some(&fi) = e.faces.iter().find(|&&fi| morphed_face(fi)) else { continue };
            let curve_id = bspline_of(&ctx, e.curve)?;
            let vertex_pts: Vec<EntityId> = [e.start, e.end]
                .iter()
                .filter_map(|v| ctx.simple(*v, "VERTEX_POINT").ok().and_then(|r| r.reference(1).ok()))
                .collect();
            let rational = curve_id.and_then(|c| ctx_doc.curve_nurbs_local(c).ok()).is_some_and(|c| c.is_rational());
            if policy == EdgePolicy::MoveControlPoints || rational {
                if let Some(c) = curve_id {
                    for id in ctx_doc.control_point_ids(c)? {
                        move_point(self, &mut moved, id, &e.transform)?;
                    }
                }
                for id in vertex_pts {
                    move_point(self, &mut moved, id, &e.transform)?;
                }
                continue;
            }
            // Recompute from the morphed face.
            let orig = originals[fi].as_ref().expect("morphed face");
            let t = e.transform;
            let inv = t.try_inverse().unwrap_or_else(Matrix4::identity);
            let face_after = self.morphed_surface(&faces[fi], &moved)?;
            // Points along the edge lie on the face: each projection starts from the
            // previous one's answer (a global search only for the first, or off the face).
            let size = orig.control_extent().max(1.0);
            let last = std::cell::Cell::new(None::<(f64, f64)>);
            let on_face = |p: &Point3<f64>| {
                let w = t.transform_point(p);
                let pr = orig.project_near(&w, last.get(), 1e-12 * (1.0 + w.coords.norm()), 1e-6 * size);
                last.set(Some((pr.u, pr.v)));
                inv.transform_point(&cadmorph_nurbs::Surface::eval(&face_after, pr.u, pr.v))
            };
            if let Some(c) = curve_id {
                let curve = ctx_doc.curve_nurbs_local(c)?;
                let ids = ctx_doc.control_point_ids(c)?;
                let targets: Vec<Point3<f64>> = cadmorph_nurbs::greville(curve.knots(), curve.degree())
                    .iter()
                    .map(|&g| on_face(&Curve::eval(&curve, g)))
                    .collect();
                let fitted = cadmorph_nurbs::interpolate(curve.degree(), curve.knots(), &targets);
                if let Some(new_pts) = fitted.ok().map(|c| c.control_points().to_vec()) {
                    for (id, p) in ids.iter().zip(new_pts) {
                        if !moved.contains_key(&id.0) {
                            edge_points.insert(id.0, p);
                        }
                    }
                }
            }
            for id in vertex_pts {
                if !moved.contains_key(&id.0) && !edge_points.contains_key(&id.0) {
                    let p = ctx_doc.point(id)?;
                    edge_points.insert(id.0, on_face(&p));
                }
            }
        }
        for (id, p) in edge_points {
            moved.entry(id).or_insert(p);
        }
        let n = moved.len();
        let mut ordered: Vec<(u64, Point3<f64>)> = moved.into_iter().collect();
        ordered.sort_unstable_by_key(|x| x.0);
        for (id, p) in ordered {
            if !p.coords.iter().all(|c| c.is_finite()) {
                return Err(Error::Edit {
                    at: self.position_of_id(EntityId(id)),
                    reason: "the map gave a non-finite point".into(),
                });
            }
            self.set_point(EntityId(id), p)?;
        }
        let (max_gap, measured) = self.edge_gap()?;
        Ok(MorphReport { points_moved: n, max_gap, edges: measured })
    }

    /// The B-spline surface of a face with the moved points substituted (world coordinates).
    fn morphed_surface(&self, face: &Face, moved: &HashMap<u64, Point3<f64>>) -> Result<NurbsSurface> {
        let mut s = self.bspline_surface(face.surface)?;
        let ids = self.control_point_ids(face.surface)?;
        for (slot, id) in s.control_points_mut().iter_mut().zip(ids) {
            if let Some(p) = moved.get(&id.0) {
                *slot = *p;
            }
        }
        s.transform_by(&face.transform);
        Ok(s)
    }

    fn curve_nurbs_local(&self, id: EntityId) -> Result<NurbsCurve> {
        let ctx = Ctx::new(self, 1.0);
        match ctx.curve(id)? {
            crate::views::geometry::CurveGeom::Nurbs(c) => Ok(c),
            _ => Err(Error::UnexpectedEntity {
                at: self.position_of_id(id),
                expected: "a B-spline curve",
                found: String::new(),
            }),
        }
    }

    /// Largest distance from the edges (17 samples each) and vertices of B-spline faces
    /// to those faces, and the number of edges measured.
    ///
    /// # Errors
    ///
    /// The views' errors.
    pub fn edge_gap(&self) -> Result<(f64, usize)> {
        let faces = self.faces()?;
        let edges = self.edges(&faces)?;
        // Each B-spline face with the distance within which a local projection is kept.
        let mut surfaces: HashMap<usize, (NurbsSurface, f64)> = HashMap::new();
        for (i, f) in faces.iter().enumerate() {
            if matches!(f.kind, SurfaceKind::BSpline { .. }) {
                let s = self.face_nurbs(f)?.surface;
                let accept = 1e-6 * s.control_extent().max(1.0);
                surfaces.insert(i, (s, accept));
            }
        }
        let (mut worst, mut n) = (0.0f64, 0);
        for e in &edges {
            let adj: Vec<&(NurbsSurface, f64)> = e.faces.iter().filter_map(|i| surfaces.get(i)).collect();
            if adj.is_empty() {
                continue;
            }
            let Ok(c) = self.edge_curve(e) else { continue };
            n += 1;
            let d = c.curve.domain();
            let mut pts: Vec<Point3<f64>> =
                (0..=16).map(|i| Curve::eval(&c.curve, d.start() + (d.end() - d.start()) * i as f64 / 16.0)).collect();
            pts.extend([c.start, c.end]);
            for (s, accept) in adj {
                // Along the edge, each projection starts from the previous one's answer
                // when that lands on the face; a real gap gets the global search.
                let mut near = None;
                for p in &pts {
                    let pr = s.project_near(p, near, 1e-12 * (1.0 + p.coords.norm()), *accept);
                    near = Some((pr.u, pr.v));
                    worst = worst.max(pr.distance_sq.sqrt());
                }
            }
        }
        Ok((worst, n))
    }
}

/// The B-spline curve behind an edge geometry (through surface curves), if it is one.
fn bspline_of(ctx: &Ctx<'_>, id: EntityId) -> Result<Option<EntityId>> {
    let k = ctx.index(id)?;
    let name = ctx.doc.name_of(k);
    if ctx.doc.instances[k].complex {
        return Ok(ctx.doc.text(k).windows(14).any(|w| w == b"B_SPLINE_CURVE").then_some(id));
    }
    match name {
        "B_SPLINE_CURVE_WITH_KNOTS" => Ok(Some(id)),
        "SURFACE_CURVE" | "SEAM_CURVE" => {
            let r = ctx.any(id)?;
            r.arity(4)?;
            bspline_of(ctx, r.reference(1)?)
        }
        _ => Ok(None),
    }
}

fn weight_text(w: &[f64], rows: Option<usize>) -> String {
    match rows {
        Some(n_u) if n_u > 0 && w.len() % n_u == 0 => {
            let n_v = w.len() / n_u;
            format!(
                "({})",
                (0..n_u).map(|i| real_list(w[i * n_v..(i + 1) * n_v].iter().copied())).collect::<Vec<_>>().join(",")
            )
        }
        _ => real_list(w.iter().copied()),
    }
}
