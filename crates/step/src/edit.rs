//! In-place edits: points, weights, analytic surfaces replaced by B-splines, face
//! surfaces and edge curves rewritten.

use std::collections::{HashMap, HashSet};

use cadmorph_nurbs::math::{affine_inverse, Matrix4, Point3};
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface};

use crate::document::Document;
use crate::error::{Error, Result};
use crate::read::param::Body;
use crate::views::{Ctx, Edge, Face, SurfaceKind};
use crate::write::{knot_lists, real_list};
use crate::EntityId;

/// Control points to move in place: `(point instance, new position)`.
type PointMoves = Vec<(EntityId, Point3<f64>)>;

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
        let inverse = affine_inverse(&face.transform)
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

    /// Gives each of `edges` a new 3D curve: the (rational) B-spline curve given (world
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
    /// placement or a non-finite curve.
    pub fn set_edge_curves(&mut self, edges: &[(Edge, NurbsCurve)]) -> Result<usize> {
        let mut n = 0;
        for (e, c) in edges {
            let k = self.index.get(e.id.0).ok_or(Error::NoSuchInstance(e.id))?;
            let edit = |reason: &str| Error::Edit { at: self.position_of(k, 0), reason: reason.into() };
            let inverse = affine_inverse(&e.transform).ok_or_else(|| edit("singular edge placement"))?;
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
            let curve = self.add_instance(&match local.weights() {
                None => format!(
                    "B_SPLINE_CURVE_WITH_KNOTS('',{},({poles}),.UNSPECIFIED.,.F.,.F.,{mults},{knots},.UNSPECIFIED.)",
                    local.degree()
                ),
                Some(w) => format!(
                    "( BOUNDED_CURVE() B_SPLINE_CURVE({},({poles}),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS({mults},{knots},.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE({}) REPRESENTATION_ITEM('') )",
                    local.degree(),
                    weight_text(w, None)
                ),
            })?;
            self.splice(at, start, end, &format!("#{}", curve.0))?;
            n += 1;
        }
        Ok(n)
    }

    /// Writes `s` (world coordinates, model units) as the B-spline surface `#surface`
    /// placed by `transform` (local to world), keeping the file's sharing of points: where
    /// the instance is already a B-spline with the same degrees, knots, pole counts and
    /// weights, only its moved control points are rewritten in place, and **a point
    /// shared by two faces moves once**: a point that an earlier write in this session
    /// already moved (to the position this surface also wants) is left alone. When this
    /// surface wants a shared point elsewhere than an earlier write put it, when a point
    /// to move is also a control point of another curve or surface that has not been
    /// written (it would move along), or when the structure differs, the surface gets
    /// its own new points
    /// ([`set_face_surface`](Self::set_face_surface)'s way) and no other face moves.
    /// Returns whether anything was written.
    ///
    /// # Errors
    ///
    /// [`Error::NoSuchInstance`]; [`Error::Edit`] for a singular placement or
    /// non-finite values.
    pub fn write_surface_shared(
        &mut self,
        surface: EntityId,
        transform: &Matrix4<f64>,
        s: &NurbsSurface,
    ) -> Result<bool> {
        let k = self.index.get(surface.0).ok_or(Error::NoSuchInstance(surface))?;
        let inverse = affine_inverse(transform)
            .ok_or_else(|| Error::Edit { at: self.position_of(k, 0), reason: "singular face placement".into() })?;
        let local = if *transform == Matrix4::identity() { s.clone() } else { s.transformed(&inverse) };
        if local.control_points().iter().any(|p| !p.coords.iter().all(|c| c.is_finite())) {
            return Err(Error::Edit { at: self.position_of(k, 0), reason: "non-finite control point".into() });
        }
        if let Ok(old) = self.bspline_surface(surface) {
            if old == local {
                return Ok(false);
            }
            let same_structure = old.u_degree() == local.u_degree()
                && old.v_degree() == local.v_degree()
                && old.n_u() == local.n_u()
                && old.n_v() == local.n_v()
                && old.u_knots() == local.u_knots()
                && old.v_knots() == local.v_knots()
                && old.weights() == local.weights();
            if same_structure {
                let plan = self.in_place_plan(surface, old.control_points(), local.control_points())?;
                let plan = plan.filter(|p| !self.shared_with_other_geometry(surface, p));
                if let Some(plan) = plan {
                    for (id, p) in plan {
                        self.set_point(id, p)?;
                    }
                    return Ok(true);
                }
            }
        }
        self.write_bspline_surface(surface, &local)?;
        Ok(true)
    }

    /// The points of `#surface` to move in place to take its poles from `old` to `new`,
    /// or `None` when a point is wanted at two places (already moved elsewhere by an
    /// earlier write, or listed twice with different targets).
    fn in_place_plan(&self, surface: EntityId, old: &[Point3<f64>], new: &[Point3<f64>]) -> Result<Option<PointMoves>> {
        let ids = self.control_point_ids(surface)?;
        let mut plan: HashMap<u64, Point3<f64>> = HashMap::new();
        for ((id, p_old), p_new) in ids.iter().zip(old).zip(new) {
            if let Some(q) = plan.get(&id.0) {
                if q != p_new {
                    return Ok(None);
                }
                continue;
            }
            if p_old == p_new {
                // Unmoved here; but if another write moved it, this face would follow.
                plan.insert(id.0, *p_new);
                continue;
            }
            if self.rewritten(*id) {
                // Moved by an earlier write to where it is now, which is not where this
                // face wants it.
                return Ok(None);
            }
            plan.insert(id.0, *p_new);
        }
        let mut out: Vec<(EntityId, Point3<f64>)> = Vec::new();
        for ((id, p_old), p_new) in ids.iter().zip(old).zip(new) {
            if p_old != p_new && plan.remove(&id.0).is_some() {
                out.push((*id, *p_new));
            }
        }
        Ok(Some(out))
    }

    /// Whether an instance other than `#surface` and vertices references one of the
    /// points of `moves` (one pass over the document's text): moving them in place would
    /// move that curve or surface too.
    fn shared_with_other_geometry(&self, surface: EntityId, moves: &PointMoves) -> bool {
        let ids: HashSet<u64> = moves.iter().map(|(id, _)| id.0).collect();
        if ids.is_empty() {
            return false;
        }
        (0..self.instances.len()).any(|k| {
            let inst = &self.instances[k];
            if inst.id == surface.0 || ids.contains(&inst.id) || self.name_of(k) == "VERTEX_POINT" {
                return false;
            }
            let body = &self.text(k)[inst.body as usize..];
            let mut i = 0;
            while i < body.len() {
                if body[i] == b'#' {
                    let start = i + 1;
                    let mut j = start;
                    let mut n: u64 = 0;
                    while j < body.len() && body[j].is_ascii_digit() {
                        n = n.saturating_mul(10).saturating_add(u64::from(body[j] - b'0'));
                        j += 1;
                    }
                    if j > start && ids.contains(&n) {
                        return true;
                    }
                    i = j;
                } else {
                    i += 1;
                }
            }
            false
        })
    }

    /// Gives `EDGE_CURVE` `#edge` (placed by `transform`) the new 3D curve `c` (see
    /// [`set_edge_curves`](Self::set_edge_curves)) and moves its vertices to the curve's
    /// ends (the start vertex to `c`'s start when the edge runs along its curve, to its
    /// end otherwise). A vertex point that an earlier write already moved is left where
    /// it is (a vertex shared by several edges moves once), and so is one that is also a
    /// control point of some curve or surface (moving it would move that geometry).
    /// Returns whether anything was written.
    ///
    /// # Errors
    ///
    /// Those of [`set_edge_curves`](Self::set_edge_curves); malformed edges or vertices.
    pub fn set_edge_curve(&mut self, edge: EntityId, transform: &Matrix4<f64>, c: &NurbsCurve) -> Result<bool> {
        let ctx = Ctx::new(self, 1.0);
        let r = ctx.simple(edge, "EDGE_CURVE")?;
        r.arity(5)?;
        let (start, end, curve, same_sense) = (r.reference(1)?, r.reference(2)?, r.reference(3)?, r.bool(4)?);
        let vertex_point = |v: EntityId| -> Result<EntityId> {
            let vr = ctx.simple(v, "VERTEX_POINT")?;
            vr.arity(2)?;
            vr.reference(1)
        };
        let (ps, pe) = (vertex_point(start)?, vertex_point(end)?);
        drop(ctx);
        let e =
            Edge { id: edge, curve, start, end, same_sense, faces: Vec::new(), occurrence: 0, transform: *transform };
        if self.set_edge_curves(&[(e, c.clone())])? == 0 {
            return Ok(false);
        }
        let d = c.domain();
        let (a, b) = (c.eval(*d.start()), c.eval(*d.end()));
        let (at_start, at_end) = if same_sense { (a, b) } else { (b, a) };
        let inverse = affine_inverse(transform).unwrap_or_else(Matrix4::identity);
        for (pid, w) in [(ps, at_start), (pe, at_end)] {
            // A point an earlier write moved stays; so does one that is also a control
            // point of a curve or surface (that geometry owns it and moves it itself).
            if self.rewritten(pid) || self.referrers(pid).into_iter().any(|k| self.name_of(k) != "VERTEX_POINT") {
                continue;
            }
            let local = inverse.transform_point(&w);
            if self.point(pid)? != local {
                self.set_point(pid, local)?;
            }
        }
        Ok(true)
    }

    /// Whether an edit rewrote `#id` or added it with content of its own: the copies
    /// [`unshare`](Self::unshare) makes count as the file's until an edit rewrites them.
    fn rewritten(&self, id: EntityId) -> bool {
        self.index.get(id.0).is_some_and(|k| self.texts.contains_key(&k) && !self.pristine.contains(&k))
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
}

fn weight_text(w: &[f64], rows: Option<usize>) -> String {
    match rows {
        Some(n_u) if n_u > 0 && w.len().is_multiple_of(n_u) => {
            let n_v = w.len() / n_u;
            format!(
                "({})",
                (0..n_u).map(|i| real_list(w[i * n_v..(i + 1) * n_v].iter().copied())).collect::<Vec<_>>().join(",")
            )
        }
        _ => real_list(w.iter().copied()),
    }
}
