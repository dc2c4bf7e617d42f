//! Shape representations, assembly placements, faces and edges.

use std::collections::HashMap;

use cadmorph_nurbs::analytic::Placement;
use cadmorph_nurbs::math::{Matrix4, Point3};

use super::flat::Flat;
use super::geometry::SurfaceGeom;
use super::{Ctx, Edge, Face, SurfaceKind, WorldCurve, WorldSurface};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::read::param::Body;
use crate::EntityId;

/// Models of at least this many faces have them converted in parallel by
/// [`Document::faces_nurbs`]. A face takes some 10 µs; on the 35 faces of
/// `samples/mapped_item.stp` two threads gave a better best time but a worse median
/// (waking and then spinning workers cost as much as they save), on 300 faces they halve
/// the time.
pub(crate) const PARALLEL_FACES: usize = 64;

/// A face's surface, its `same_sense`, and its bounds `(bound, loop, orientation)`.
type FaceRecord = (EntityId, bool, Vec<(EntityId, EntityId, bool)>);

/// An edge's curve, range `[t0, t1]` along it, and its start and end points.
pub(crate) type EdgeGeometry = (super::geometry::CurveGeom, f64, f64, Point3<f64>, Point3<f64>);

/// A shape representation placed in the world: the run of its items `items` (a
/// representation's items between two `MAPPED_ITEM`s, so that faces come in item order,
/// as OCCT's `STEPControl_ActorRead` lists them).
#[derive(Debug, Clone)]
pub(crate) struct Occurrence {
    pub rep: EntityId,
    pub transform: Matrix4<f64>,
    pub items: Vec<EntityId>,
    /// How the walk reached `rep`: the root representation, then each link taken (a
    /// representation relationship or a `MAPPED_ITEM`) with the representation it led to.
    pub root: EntityId,
    pub path: Vec<Link>,
}

/// One step down the placement tree: the relationship instance or `MAPPED_ITEM` taken
/// and the representation it leads to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Link {
    pub via: EntityId,
    pub rep: EntityId,
}

/// Each representation's related representations: `(other, its ITEM_DEFINED_TRANSFORMATION
/// if any, the relationship instance)`.
type Children = HashMap<u64, Vec<(u64, Option<EntityId>, EntityId)>>;

/// What [`Ctx::descend`] needs to know of the file's representations.
struct Tree<'m> {
    /// Model units per unit of each shape representation's context.
    rep_scale: &'m HashMap<u64, f64>,
    /// Children of each representation by (SHAPE_)REPRESENTATION_RELATIONSHIP, with the
    /// ITEM_DEFINED_TRANSFORMATION if any and the relationship instance.
    children: &'m Children,
    /// Most occurrences (item runs) listed, and representations visited, before giving up.
    limit: usize,
    /// Representations visited so far (empty ones too: a map of maps of nothing).
    visits: std::cell::Cell<usize>,
}

/// Where [`Ctx::descend`] stands: the representations entered (to find cycles) and the
/// links taken from the root.
struct Walk {
    stack: Vec<u64>,
    root: EntityId,
    path: Vec<Link>,
    /// The representations of the shape being read at this placement (joined by
    /// relationships without a transformation), each read once.
    shape: Vec<u64>,
}

impl Walk {
    fn enter(&mut self, link: Link) {
        self.stack.push(link.rep.0);
        self.path.push(link);
    }

    fn leave(&mut self) {
        self.stack.pop();
        self.path.pop();
    }
}

/// Whether a simple instance's name may be one [`Ctx::occurrences`] looks for: they all
/// end in `REPRESENTATION`, `REPRESENTATION_MAP` or `REPRESENTATION_RELATIONSHIP`
/// (a suffix test, where a search through every name cost a tenth of listing the faces).
fn representation_name(name: &[u8]) -> bool {
    name.ends_with(b"REPRESENTATION") || name.ends_with(b"REPRESENTATION_MAP") || name.ends_with(b"_RELATIONSHIP")
}

fn is_shape_rep(name: &str) -> bool {
    name.ends_with("REPRESENTATION")
        && !matches!(
            name,
            "DEFINITIONAL_REPRESENTATION"
                | "SHAPE_DEFINITION_REPRESENTATION"
                | "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION"
                | "PROPERTY_DEFINITION_REPRESENTATION"
        )
}

pub(crate) fn placement_matrix(p: &Placement, scale: f64) -> Matrix4<f64> {
    let (x, y, z, o) = (p.x_dir(), p.y_dir(), p.z_dir(), p.origin().coords * scale);
    Matrix4::new(x.x, y.x, z.x, o.x, x.y, y.y, z.y, o.y, x.z, y.z, z.z, o.z, 0.0, 0.0, 0.0, 1.0)
}

fn rigid_inverse(m: &Matrix4<f64>) -> Matrix4<f64> {
    cadmorph_nurbs::math::affine_inverse(m).unwrap_or_else(Matrix4::identity)
}

impl Ctx<'_> {
    /// Every shape representation with its world placements, in file order of the
    /// representations (roots first, then children depth-first).
    pub fn occurrences(&self, model_metres: f64) -> Result<Vec<Occurrence>> {
        let doc = self.doc;
        let mut reps = Vec::new(); // (id, scale)
        let mut rep_scale: HashMap<u64, f64> = HashMap::new();
        let mut context_scale: HashMap<u64, f64> = HashMap::new();
        // The model units' own context (most files have only that one) was read by
        // `Document::units` already.
        if let Some((c, metres)) = doc.units_context() {
            context_scale.insert(c, metres / model_metres);
        }
        let mut children: Children = HashMap::new();
        let mut is_child: HashMap<u64, bool> = HashMap::new();
        // Pairs joined by relationships without a transformation.
        let mut plain: Vec<(u64, u64)> = Vec::new();
        // Representations a REPRESENTATION_MAP maps, and those a product's
        // SHAPE_DEFINITION_REPRESENTATION names.
        let mut mapped: HashMap<u64, bool> = HashMap::new();
        let mut defined: HashMap<u64, bool> = HashMap::new();
        let relationship = memchr::memmem::Finder::new(b"REPRESENTATION_RELATIONSHIP");
        for k in 0..doc.instances.len() {
            let inst = &doc.instances[k];
            // Every name looked for below holds REPRESENTATION: the bulk of a file's
            // instances (points, curves, topology) are passed over from their bytes.
            if !inst.complex && !representation_name(doc.name_bytes(k)) {
                continue;
            }
            let name = doc.name_of(k);
            let id = EntityId(inst.id);
            if !inst.complex && is_shape_rep(name) {
                let r = self.any(id)?;
                if r.rec().params.len() != 3 || r.param(1)?.as_list().is_none() {
                    continue;
                }
                let scale = match r.param(2)?.as_ref_id() {
                    Some(c) => match context_scale.get(&c.0) {
                        Some(&s) => s,
                        None => {
                            let s = self.context_units(c)?.0.map_or(1.0, |l| l.metres / model_metres);
                            context_scale.insert(c.0, s);
                            s
                        }
                    },
                    None => 1.0,
                };
                reps.push(id);
                rep_scale.insert(id.0, scale);
            } else if !inst.complex && name == "REPRESENTATION_MAP" {
                let r = self.any(id)?;
                r.arity(2)?;
                mapped.insert(r.reference(1)?.0, true);
            } else if !inst.complex && name == "SHAPE_DEFINITION_REPRESENTATION" {
                let r = self.any(id)?;
                r.arity(2)?;
                defined.insert(r.reference(1)?.0, true);
            } else if (!inst.complex
                && matches!(name, "SHAPE_REPRESENTATION_RELATIONSHIP" | "REPRESENTATION_RELATIONSHIP"))
                || (inst.complex && relationship.find(doc.text(k)).is_some())
            {
                let body = doc.body_at(k)?;
                let Some(rr) = body
                    .record("REPRESENTATION_RELATIONSHIP")
                    .or_else(|| body.record("SHAPE_REPRESENTATION_RELATIONSHIP"))
                else {
                    continue;
                };
                let r = super::Rec::from_record(doc, k, rr.clone());
                r.arity(4)?;
                let (child, parent) = (r.reference(2)?, r.reference(3)?);
                let transform = match body.record("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") {
                    Some(t) => {
                        let t = super::Rec::from_record(doc, k, t.clone());
                        t.arity(1)?;
                        Some(t.reference(0)?)
                    }
                    None => None,
                };
                children.entry(parent.0).or_default().push((child.0, transform, id));
                if transform.is_some() {
                    is_child.insert(child.0, true);
                } else {
                    // A relationship without a transformation joins two representations of
                    // one shape (an axis-only SHAPE_REPRESENTATION that a product names and
                    // the ADVANCED_BREP_SHAPE_REPRESENTATION holding its solid, in either
                    // order: CATIA and NX write the named one first, OCCT the other way):
                    // OCCT follows it both ways, so the walk does too.
                    children.entry(child.0).or_default().push((parent.0, None, id));
                    plain.push((child.0, parent.0));
                }
            }
        }
        let tree = Tree {
            rep_scale: &rep_scale,
            children: &children,
            limit: doc.instances.len() * 4 + 1024,
            visits: 0.into(),
        };
        let mut out = Vec::new();
        // A representation only a REPRESENTATION_MAP reaches is read where MAPPED_ITEMs
        // place it; one that a product also names is a root as well (OCCT 7.9 reads it
        // both unplaced and at every MAPPED_ITEM).
        // Representations joined without a transformation are one shape: it is placed
        // where any of them is (a child of a placing relationship), and read once from its
        // first candidate root otherwise.
        let mut group: HashMap<u64, u64> = HashMap::new();
        // Union-find with path halving: a hostile file's long chains stay near-linear.
        fn find(group: &mut HashMap<u64, u64>, mut r: u64) -> u64 {
            loop {
                let up = match group.get(&r) {
                    Some(&up) if up != r => up,
                    _ => return r,
                };
                let next = match group.get(&up) {
                    Some(&next) if next != up => next,
                    _ => return up,
                };
                group.insert(r, next);
                r = next;
            }
        }
        for &(a, b) in &plain {
            let (ra, rb) = (find(&mut group, a), find(&mut group, b));
            if ra != rb {
                group.insert(ra, rb);
                group.entry(rb).or_insert(rb);
            }
        }
        let mut placed_groups: std::collections::HashSet<u64> = std::collections::HashSet::new();
        for r in is_child.keys() {
            placed_groups.insert(find(&mut group, *r));
        }
        let mut rooted: std::collections::HashSet<u64> = std::collections::HashSet::new();
        let mut roots = Vec::new();
        for r in &reps {
            let g = find(&mut group, r.0);
            if !is_child.contains_key(&r.0)
                && (!mapped.contains_key(&r.0) || defined.contains_key(&r.0))
                && !placed_groups.contains(&g)
                && rooted.insert(g)
            {
                roots.push(*r);
            }
        }
        for &root in &roots {
            let mut walk = Walk { stack: vec![root.0], root, path: Vec::new(), shape: vec![root.0] };
            self.descend(root, Matrix4::identity(), &tree, &mut walk, &mut out)?;
        }
        Ok(out)
    }

    /// Lists `rep` placed by `world` (model units, without `rep`'s own unit scale), then
    /// its relationship children. A `MAPPED_ITEM` among its items (ISO 10303-43 §4.5.7:
    /// `mapped_item(name, mapping_source, mapping_target)`, the source a
    /// `representation_map(mapping_origin, mapped_representation)`, §4.5.6) places the
    /// mapped representation's items in `rep`'s coordinates (origin in the mapped
    /// representation's units, target in `rep`'s), listed where the item stands among
    /// `rep`'s items, nested maps in turn.
    ///
    /// The placement is OCCT's, `origin⁻¹ ∘ target` (OCCT 7.9
    /// `STEPControl_ActorRead::ComputeTransformation`: `gp_Trsf::SetTransformation(target,
    /// origin)`), measured on `samples/mapped_item.stp`. ISO 10303-43 §4.5.7 means
    /// `target ∘ origin⁻¹` (the origin frame carried onto the target frame); the two agree
    /// when either frame is the identity, as writers write them (an identity origin, the
    /// representation's own axis), and differ otherwise. cadmorph follows OCCT, its
    /// reference reader.
    fn descend(
        &self,
        rep: EntityId,
        world: Matrix4<f64>,
        tree: &Tree<'_>,
        walk: &mut Walk,
        out: &mut Vec<Occurrence>,
    ) -> Result<()> {
        let (rep_scale, children) = (tree.rep_scale, tree.children);
        tree.visits.set(tree.visits.get() + 1);
        if tree.visits.get() > tree.limit {
            return Err(Error::Limit {
                at: self.doc.position_of_id(rep),
                what: "more assembly occurrences than the file can describe",
            });
        }
        let s = rep_scale.get(&rep.0).copied().unwrap_or(1.0);
        let mut run = Vec::new();
        let kr = self.index(rep)?;
        let items = match self.flat_any::<2>(kr) {
            Some([Flat::List(a, b), _]) => self.ref_list(kr, (a, b)),
            _ => None,
        };
        let items = match items {
            Some(items) => items,
            None => self.any(rep)?.refs(1)?,
        };
        for item in items {
            let k = self.index(item)?;
            if self.doc.instances[k].complex || self.doc.name_of(k) != "MAPPED_ITEM" {
                run.push(item);
                continue;
            }
            self.push_run(rep, world * Matrix4::new_scaling(s), &mut run, tree, walk, out)?;
            // Read flat when the item and its map both are (every reading below then
            // succeeds as the general one would); the general readings' results are kept
            // and their errors reported in the general order.
            let flat = match self.flat::<2>(k, b"MAPPED_ITEM") {
                Some([Flat::Ref(source), Flat::Ref(target)]) => {
                    match self.flat_after::<2>(self.index(source)?, b"REPRESENTATION_MAP", 0) {
                        Some([Flat::Ref(origin), Flat::Ref(mapped)]) => Some((origin, mapped, target)),
                        _ => None,
                    }
                }
                _ => None,
            };
            let (origin, mapped, target) = match flat {
                Some((origin, mapped, target)) => (Ok(origin), mapped, Ok(target)),
                None => {
                    let mi = self.any(item)?;
                    mi.arity(3)?;
                    let source = mi.reference(1)?;
                    let map = self.simple(source, "REPRESENTATION_MAP")?;
                    map.arity(2)?;
                    (map.reference(0), map.reference(1)?, mi.reference(2))
                }
            };
            if walk.stack.contains(&mapped.0) {
                return Err(Error::ReferenceCycle { at: self.doc.position_of_id(item), target: mapped });
            }
            if walk.stack.len() > 256 {
                return Err(Error::Limit { at: self.doc.position_of_id(item), what: "mapped items nested too deeply" });
            }
            let Some(&sc) = rep_scale.get(&mapped.0) else { continue };
            let from = placement_matrix(&self.placement(origin?)?, sc);
            let to = placement_matrix(&self.placement(target?)?, s);
            // OCCT's order, not ISO's: see `descend`'s docs.
            let rel = Matrix4::new_scaling(1.0 / s) * rigid_inverse(&from) * to;
            let w = world * Matrix4::new_scaling(s) * rel * Matrix4::new_scaling(1.0 / sc);
            let outer = std::mem::replace(&mut walk.shape, vec![mapped.0]);
            walk.enter(Link { via: item, rep: mapped });
            self.descend(mapped, w, tree, walk, out)?;
            walk.leave();
            walk.shape = outer;
        }
        self.push_run(rep, world * Matrix4::new_scaling(s), &mut run, tree, walk, out)?;
        let Some(kids) = children.get(&rep.0) else { return Ok(()) };
        for &(child, t, via) in kids {
            if t.is_none() {
                // One shape's representations, each read once per placement.
                if walk.shape.contains(&child) || walk.stack.contains(&child) {
                    continue;
                }
                walk.shape.push(child);
            }
            if walk.stack.contains(&child) {
                return Err(Error::ReferenceCycle {
                    at: self.doc.position_of_id(EntityId(child)),
                    target: EntityId(child),
                });
            }
            if walk.stack.len() > 256 {
                return Err(Error::Limit { at: self.doc.position_of_id(rep), what: "assembly nested too deeply" });
            }
            let sc = rep_scale.get(&child).copied().unwrap_or(1.0);
            let rel = match t {
                None => Matrix4::identity(),
                Some(t) => {
                    let r = self.any(t)?;
                    if r.name() != "ITEM_DEFINED_TRANSFORMATION" {
                        return Err(Error::UnexpectedEntity {
                            at: self.doc.position_of_id(t),
                            expected: "ITEM_DEFINED_TRANSFORMATION",
                            found: r.name().to_owned(),
                        });
                    }
                    r.arity(4)?;
                    let from = placement_matrix(&self.placement(r.reference(2)?)?, sc);
                    let to = placement_matrix(&self.placement(r.reference(3)?)?, s);
                    // Parent coordinates of a child point: to · from⁻¹, in model units;
                    // `world` already holds the parent's scale, so undo it here.
                    Matrix4::new_scaling(1.0 / s) * to * rigid_inverse(&from)
                }
            };
            if rep_scale.contains_key(&child) {
                let outer = if t.is_some() { Some(std::mem::replace(&mut walk.shape, vec![child])) } else { None };
                walk.enter(Link { via, rep: EntityId(child) });
                // The child's own scale is applied by `descend`; `rel` works in model
                // units, so remove it again from the child's point of view.
                let w = world * Matrix4::new_scaling(s) * rel * Matrix4::new_scaling(1.0 / sc);
                self.descend(EntityId(child), w, tree, walk, out)?;
                walk.leave();
                if let Some(outer) = outer {
                    walk.shape = outer;
                }
            }
        }
        Ok(())
    }

    /// Lists the items gathered in `run` (if any) as one occurrence of `rep` at
    /// `transform`, and empties `run`; [`Error::Limit`] past the tree's limit.
    fn push_run(
        &self,
        rep: EntityId,
        transform: Matrix4<f64>,
        run: &mut Vec<EntityId>,
        tree: &Tree<'_>,
        walk: &Walk,
        out: &mut Vec<Occurrence>,
    ) -> Result<()> {
        if out.len() >= tree.limit {
            return Err(Error::Limit {
                at: self.doc.position_of_id(rep),
                what: "more assembly occurrences than the file can describe",
            });
        }
        if !run.is_empty() {
            out.push(Occurrence {
                rep,
                transform,
                items: std::mem::take(run),
                root: walk.root,
                path: walk.path.clone(),
            });
        }
        Ok(())
    }

    /// The faces of one placement run, in item and file order, with their orientation.
    pub(crate) fn run_faces(&self, occ: &Occurrence) -> Result<Vec<(EntityId, bool)>> {
        let mut faces = Vec::new();
        for &item in &occ.items {
            self.item_faces(item, &mut faces, 0)?;
        }
        Ok(faces)
    }

    /// The faces reachable from one representation item, in file order.
    fn item_faces(&self, id: EntityId, out: &mut Vec<(EntityId, bool)>, depth: usize) -> Result<()> {
        if depth > 16 {
            return Err(Error::Limit { at: self.doc.position_of_id(id), what: "shells nested too deeply" });
        }
        let k = self.index(id)?;
        if self.doc.instances[k].complex {
            return Ok(());
        }
        let name = self.doc.name_of(k);
        match name {
            "MANIFOLD_SOLID_BREP" | "FACETED_BREP" => {
                if let Some([Flat::Ref(shell)]) = self.flat_any::<1>(k) {
                    return self.item_faces(shell, out, depth + 1);
                }
                let r = self.any(id)?;
                r.arity(2)?;
                self.item_faces(r.reference(1)?, out, depth + 1)
            }
            "BREP_WITH_VOIDS" => {
                let r = self.any(id)?;
                r.arity(3)?;
                self.item_faces(r.reference(1)?, out, depth + 1)?;
                for v in r.refs(2)? {
                    self.item_faces(v, out, depth + 1)?;
                }
                Ok(())
            }
            "SHELL_BASED_SURFACE_MODEL" | "FACE_BASED_SURFACE_MODEL" => {
                let r = self.any(id)?;
                r.arity(2)?;
                for s in r.refs(1)? {
                    self.item_faces(s, out, depth + 1)?;
                }
                Ok(())
            }
            "CLOSED_SHELL" | "OPEN_SHELL" | "CONNECTED_FACE_SET" => {
                let faces = match self.flat_refs(k, self.doc.name_bytes(k)) {
                    Some(faces) => faces,
                    None => {
                        let r = self.any(id)?;
                        r.arity(2)?;
                        r.refs(1)?
                    }
                };
                for f in faces {
                    self.item_faces(f, out, depth + 1)?;
                }
                Ok(())
            }
            "ORIENTED_CLOSED_SHELL" | "ORIENTED_OPEN_SHELL" => {
                let r = self.any(id)?;
                r.arity(4)?;
                self.item_faces(r.reference(2)?, out, depth + 1)
            }
            "ADVANCED_FACE" | "FACE_SURFACE" => {
                out.push((id, true));
                Ok(())
            }
            "ORIENTED_FACE" => {
                let r = self.any(id)?;
                r.arity(4)?;
                let start = out.len();
                self.item_faces(r.reference(2)?, out, depth + 1)?;
                if !r.bool(3)? {
                    for f in &mut out[start..] {
                        f.1 = !f.1;
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// The kind of surface `id` is: B-spline surfaces from their own record
    /// ([`bspline_surface_kind`](Self::bspline_surface_kind): their control points'
    /// coordinates are read when the face is converted), any other surface converted
    /// ([`surface`](Self::surface)) and classified ([`surface_kind`](Self::surface_kind)).
    ///
    /// # Errors
    ///
    /// As [`surface`](Self::surface), for what it reads.
    pub fn surface_kind_of(&self, id: EntityId) -> Result<SurfaceKind> {
        let k = self.index(id)?;
        if let Some(g) = self.flat_surface(k)? {
            self.keep_surface(id, &g);
            return Ok(self.surface_kind(&g));
        }
        let body = self.body(k)?;
        if matches!(*body, Body::Complex(_)) || self.doc.name_bytes(k) == b"B_SPLINE_SURFACE_WITH_KNOTS" {
            return self.bspline_surface_kind(id, k, body);
        }
        let g = self.surface_read(id, k, body)?;
        self.keep_surface(id, &g);
        Ok(self.surface_kind(&g))
    }

    pub fn surface_kind(&self, g: &SurfaceGeom) -> SurfaceKind {
        match g {
            SurfaceGeom::Plane(_) => SurfaceKind::Plane,
            SurfaceGeom::Cylinder(_) => SurfaceKind::Cylinder,
            SurfaceGeom::Cone(_) => SurfaceKind::Cone,
            SurfaceGeom::Sphere(_) => SurfaceKind::Sphere,
            SurfaceGeom::Torus(_) => SurfaceKind::Torus,
            SurfaceGeom::Revolution(_) => SurfaceKind::Revolution,
            SurfaceGeom::Extrusion(_) => SurfaceKind::Extrusion,
            SurfaceGeom::Nurbs(s) => SurfaceKind::BSpline {
                u_degree: s.u_degree(),
                v_degree: s.v_degree(),
                n_u: s.n_u(),
                n_v: s.n_v(),
                rational: s.is_rational(),
            },
            SurfaceGeom::Trimmed { basis, .. } => self.surface_kind(basis),
        }
    }
}

impl Document {
    pub(crate) fn ctx(&self) -> Result<(Ctx<'_>, super::Units)> {
        let units = self.units()?;
        Ok((Ctx::new(self, units.plane_angle), units))
    }

    /// Every face of every shape representation, once per assembly occurrence and per
    /// `MAPPED_ITEM` placement (ISO 10303-43 §4.5.7), with its world placement. Faces of
    /// the same representation come in file order (OCCT's order for single-part files),
    /// those of a mapped representation where its `MAPPED_ITEM` stands among the items.
    /// A representation only `REPRESENTATION_MAP`s reach is not read unplaced; one a
    /// product's `SHAPE_DEFINITION_REPRESENTATION` also names is (as OCCT 7.9 does).
    ///
    /// # Errors
    ///
    /// Malformed topology or placements (arity, parameter types, unexpected entities, a
    /// `MAPPED_ITEM` whose origin or target is not an `AXIS2_PLACEMENT_3D`), placement
    /// cycles ([`Error::ReferenceCycle`] at the `MAPPED_ITEM` or relationship that closes
    /// it), absurd assembly fan-out or nesting ([`Error::Limit`]). A face whose surface
    /// cannot be read is still listed, with [`SurfaceKind::Other`]; a B-spline surface
    /// is read here up to its control points' references (each must name a
    /// `CARTESIAN_POINT`), their coordinates only when the face is converted
    /// ([`face_nurbs`](Self::face_nurbs)).
    pub fn faces(&self) -> Result<Vec<Face>> {
        let (ctx, units) = self.ctx()?;
        let mut out = Vec::new();
        let mut kinds: HashMap<u64, SurfaceKind> = HashMap::new();
        let mut occurrences_of: HashMap<u64, usize> = HashMap::new();
        let mut read: HashMap<u64, FaceRecord> = HashMap::new();
        for occ in ctx.occurrences(units.length.metres)? {
            for (fid, orient) in ctx.run_faces(&occ)? {
                // A face placed several times (assembly occurrences, mapped items) is read
                // once.
                let (surface, face_sense, bounds) = match read.get(&fid.0) {
                    Some(f) => f.clone(),
                    None => {
                        let f = self.face_record(&ctx, fid)?;
                        read.insert(fid.0, f.clone());
                        f
                    }
                };
                let same_sense = face_sense == orient;
                let kind = match kinds.get(&surface.0) {
                    Some(k) => k.clone(),
                    None => {
                        let k = match ctx.surface_kind_of(surface) {
                            Ok(k) => k,
                            Err(Error::ReferenceCycle { at, target }) => {
                                return Err(Error::ReferenceCycle { at, target })
                            }
                            Err(_) => {
                                SurfaceKind::Other(self.get(surface).map_or(String::new(), |i| i.name().to_owned()))
                            }
                        };
                        kinds.insert(surface.0, k.clone());
                        k
                    }
                };
                let seen = occurrences_of.entry(fid.0).or_insert(0usize);
                let occurrence = *seen;
                *seen += 1;
                out.push(Face {
                    id: fid,
                    surface,
                    kind,
                    same_sense,
                    bounds,
                    representation: occ.rep,
                    occurrence,
                    transform: occ.transform,
                });
            }
        }
        Ok(out)
    }

    /// [`face_nurbs`](Self::face_nurbs) of each of `faces`, in order. From 64 faces on
    /// they are converted on rayon's threads (each face's conversion only reads the
    /// document); this is how a model is loaded.
    ///
    /// A face placed several times (assembly occurrences, `MAPPED_ITEM`s) is converted
    /// once and placed for each: its surface and parameter box do not depend on the
    /// placement.
    pub fn faces_nurbs(&self, faces: &[Face]) -> Vec<Result<WorldSurface>> {
        // Each face entity's slot in `unique` (its first face), and how many faces use it.
        let mut slot_of: HashMap<EntityId, usize> = HashMap::new();
        let mut unique: Vec<usize> = Vec::new();
        let slots: Vec<usize> = faces
            .iter()
            .enumerate()
            .map(|(i, f)| {
                *slot_of.entry(f.id).or_insert_with(|| {
                    unique.push(i);
                    unique.len() - 1
                })
            })
            .collect();
        let mut uses = vec![0usize; unique.len()];
        for &s in &slots {
            uses[s] += 1;
        }
        // One context per thread: faces share edges, vertices and placements, read once.
        // (Without one, e.g. unreadable units, each face reports the error itself.)
        let local = |ctx: &mut Option<(Ctx<'_>, super::Units)>, &i: &usize| {
            Some(match ctx {
                Some((ctx, _)) => self.face_local_in(ctx, &faces[i]),
                None => self.face_local(&faces[i]),
            })
        };
        let mut converted: Vec<Option<Result<WorldSurface>>> = if unique.len() >= PARALLEL_FACES {
            use rayon::prelude::*;
            unique.par_iter().with_min_len(4).map_init(|| self.ctx().ok(), local).collect()
        } else {
            let mut ctx = self.ctx().ok();
            unique.iter().map(|i| local(&mut ctx, i)).collect()
        };
        faces
            .iter()
            .zip(slots)
            .map(|(f, s)| {
                // The last face of an entity takes its conversion, the others a copy.
                uses[s] -= 1;
                let mut w = if uses[s] == 0 { converted[s].take() } else { converted[s].clone() }
                    .expect("each slot is taken by its last face only")?;
                if f.transform != Matrix4::identity() {
                    w.surface.transform_by(&f.transform);
                }
                Ok(w)
            })
            .collect()
    }

    /// The face's surface as a world-coordinate NURBS in model units: B-spline surfaces
    /// as they are (whole domain), analytic surfaces in their exact NURBS form over the
    /// face's parameter box (found by inverting points of its edges onto the surface).
    ///
    /// # Errors
    ///
    /// The surface's own errors, [`Error::Geometry`] when the box is empty, and
    /// [`Error::UnexpectedEntity`] for surfaces this crate does not convert.
    pub fn face_nurbs(&self, face: &Face) -> Result<WorldSurface> {
        let mut w = self.face_local(face)?;
        if face.transform != Matrix4::identity() {
            w.surface.transform_by(&face.transform);
        }
        Ok(w)
    }

    /// [`face_nurbs`](Self::face_nurbs) before the face's placement
    /// ([`Face::transform`]) is applied.
    fn face_local(&self, face: &Face) -> Result<WorldSurface> {
        let (ctx, _) = self.ctx()?;
        self.face_local_in(&ctx, face)
    }

    /// [`face_local`](Self::face_local) in a context that may have read other faces.
    fn face_local_in(&self, ctx: &Ctx<'_>, face: &Face) -> Result<WorldSurface> {
        let g = ctx.surface_kept(face.surface)?;
        let (u, v) = match &g {
            SurfaceGeom::Nurbs(s) => {
                let (du, dv) = cadmorph_nurbs::Surface::domain(s);
                ((*du.start(), *du.end()), (*dv.start(), *dv.end()))
            }
            SurfaceGeom::Trimmed { u, v, .. } => (*u, *v),
            _ => ctx.face_box(face, &g)?,
        };
        let exact =
            g.to_nurbs(u, v).map_err(|e| Error::Geometry { at: self.position_of_id(face.surface), source: e })?;
        Ok(WorldSurface { surface: exact.surface, u_map: exact.u_map, v_map: exact.v_map, u_range: u, v_range: v })
    }

    /// A face's record: its surface, its own sense, and its bounds.
    fn face_record(&self, ctx: &Ctx<'_>, fid: EntityId) -> Result<FaceRecord> {
        let kf = ctx.index(fid)?;
        let fast = match ctx.flat_any::<3>(kf) {
            Some([Flat::List(a, b), Flat::Ref(surface), Flat::Bool(sense)]) => {
                ctx.ref_list(kf, (a, b)).map(|bounds| (surface, sense, bounds))
            }
            _ => None,
        };
        let (surface, sense, listed) = match fast {
            Some(read) => read,
            None => {
                let r = ctx.any(fid)?;
                r.arity(4)?;
                (r.reference(2)?, r.bool(3)?, r.refs(1)?)
            }
        };
        let mut bounds = Vec::with_capacity(listed.len());
        for b in listed {
            let k = ctx.index(b)?;
            if let Some([Flat::Ref(lp), Flat::Bool(sense)]) =
                ctx.flat::<2>(k, b"FACE_OUTER_BOUND").or_else(|| ctx.flat::<2>(k, b"FACE_BOUND"))
            {
                bounds.push((b, lp, sense));
                continue;
            }
            let br = ctx.any(b)?;
            if !matches!(br.name(), "FACE_BOUND" | "FACE_OUTER_BOUND") {
                return Err(Error::UnexpectedEntity {
                    at: self.position_of_id(b),
                    expected: "FACE_BOUND or FACE_OUTER_BOUND",
                    found: br.name().to_owned(),
                });
            }
            br.arity(3)?;
            bounds.push((b, br.reference(1)?, br.bool(2)?));
        }
        Ok((surface, sense, bounds))
    }

    /// [`faces`](Self::faces) and [`face_nurbs`](Self::face_nurbs) of each, in order.
    ///
    /// # Errors
    ///
    /// The first error of either.
    pub fn world_surfaces(&self) -> Result<Vec<WorldSurface>> {
        self.faces()?.iter().map(|f| self.face_nurbs(f)).collect()
    }

    /// The edges of the given faces (from [`faces`](Self::faces)), once per edge and
    /// occurrence, each with the indices of the faces it bounds. The seam checker builds
    /// adjacency from this.
    ///
    /// # Errors
    ///
    /// Malformed loops or edges.
    pub fn edges(&self, faces: &[Face]) -> Result<Vec<Edge>> {
        let (ctx, _) = self.ctx()?;
        let mut out: Vec<Edge> = Vec::new();
        let mut seen: HashMap<(u64, usize, EntityId), usize> = HashMap::new();
        for (fi, face) in faces.iter().enumerate() {
            for &(_, lp, _) in &face.bounds {
                for (e, _) in ctx.loop_edges(lp)? {
                    let key = (e.0, face.occurrence, face.representation);
                    if let Some(&i) = seen.get(&key) {
                        out[i].faces.push(fi);
                        continue;
                    }
                    let r = ctx.simple(e, "EDGE_CURVE")?;
                    r.arity(5)?;
                    seen.insert(key, out.len());
                    out.push(Edge {
                        id: e,
                        start: r.reference(1)?,
                        end: r.reference(2)?,
                        curve: r.reference(3)?,
                        same_sense: r.bool(4)?,
                        faces: vec![fi],
                        occurrence: face.occurrence,
                        transform: face.transform,
                    });
                }
            }
        }
        Ok(out)
    }

    /// The edge's curve in world coordinates, trimmed to the edge.
    ///
    /// # Errors
    ///
    /// The curve's errors; [`Error::Geometry`] for an empty range.
    pub fn edge_curve(&self, edge: &Edge) -> Result<WorldCurve> {
        let (ctx, _) = self.ctx()?;
        let g = ctx.edge_geometry(edge.id)?;
        let (c, t0, t1, p0, p1) = (&g.0, g.1, g.2, g.3, g.4);
        let (mut curve, map) =
            c.to_nurbs(t0, t1).map_err(|e| Error::Geometry { at: self.position_of_id(edge.curve), source: e })?;
        curve.transform_by(&edge.transform);
        let tr = |p: Point3<f64>| edge.transform.transform_point(&p);
        Ok(WorldCurve { curve, map, range: (t0, t1), start: tr(p0), end: tr(p1) })
    }

    /// The world position of a vertex (`VERTEX_POINT`) under a transform.
    ///
    /// # Errors
    ///
    /// When `#id` is not a vertex with a point.
    pub fn vertex_point(&self, id: EntityId) -> Result<Point3<f64>> {
        let ctx = Ctx::new(self, 1.0);
        let r = ctx.simple(id, "VERTEX_POINT")?;
        r.arity(2)?;
        ctx.point(r.reference(1)?)
    }

    /// The B-spline surface `#id` in local coordinates and file units.
    ///
    /// # Errors
    ///
    /// When `#id` is not a (rational) `B_SPLINE_SURFACE_WITH_KNOTS` or is invalid.
    pub fn bspline_surface(&self, id: EntityId) -> Result<cadmorph_nurbs::NurbsSurface> {
        let ctx = Ctx::new(self, 1.0);
        let k = ctx.index(id)?;
        ctx.bspline_surface(k, ctx.body(k)?)
    }

    /// The B-spline curve `#id` (simple or rational complex form) over its whole domain,
    /// local coordinates and file units.
    ///
    /// # Errors
    ///
    /// When `#id` is not a B-spline curve or is invalid.
    pub fn bspline_curve(&self, id: EntityId) -> Result<cadmorph_nurbs::NurbsCurve> {
        match Ctx::new(self, 1.0).curve(id)? {
            super::geometry::CurveGeom::Nurbs(c) => Ok(c),
            _ => Err(Error::UnexpectedEntity {
                at: self.position_of_id(id),
                expected: "a B-spline curve",
                found: self.get(id).map_or(String::new(), |i| i.name().to_owned()),
            }),
        }
    }

    /// The point `#id` (`CARTESIAN_POINT`) in local coordinates and file units.
    ///
    /// # Errors
    ///
    /// When `#id` is not a Cartesian point.
    pub fn point(&self, id: EntityId) -> Result<Point3<f64>> {
        Ctx::new(self, 1.0).point(id)
    }

    /// The 3D curve `#id` (any supported curve entity) as NURBS over `[t0, t1]` of its
    /// own parameter, local coordinates.
    ///
    /// # Errors
    ///
    /// Unsupported or malformed curves, empty ranges.
    pub fn curve_nurbs(&self, id: EntityId, t0: f64, t1: f64) -> Result<cadmorph_nurbs::NurbsCurve> {
        let (ctx, _) = self.ctx()?;
        ctx.curve(id)?
            .to_nurbs(t0, t1)
            .map(|(c, _)| c)
            .map_err(|e| Error::Geometry { at: self.position_of_id(id), source: e })
    }

    /// The control point instances of a B-spline curve or surface (row-major for
    /// surfaces, `i * n_v + j`), as the file lists them (shared points repeat).
    ///
    /// # Errors
    ///
    /// When `#id` is not a B-spline curve or surface.
    pub fn control_point_ids(&self, id: EntityId) -> Result<Vec<EntityId>> {
        let ctx = Ctx::new(self, 1.0);
        let k = ctx.index(id)?;
        let body = self.body_at(k)?;
        let (rec, idx) = match &body {
            Body::Simple(r) if r.name == "B_SPLINE_SURFACE_WITH_KNOTS" => (r.clone(), 3),
            Body::Simple(r) if r.name == "B_SPLINE_CURVE_WITH_KNOTS" => (r.clone(), 2),
            Body::Complex(_) => match body.record("B_SPLINE_SURFACE").or_else(|| body.record("B_SPLINE_CURVE")) {
                Some(r) => (r.clone(), if r.name == "B_SPLINE_SURFACE" { 2 } else { 1 }),
                None => return Err(not_bspline(self, k)),
            },
            _ => return Err(not_bspline(self, k)),
        };
        let r = super::Rec::from_record(self, k, rec);
        let list = r.list(idx)?;
        let mut out = Vec::new();
        for p in list {
            match p.as_list() {
                Some(row) => {
                    for q in row {
                        out.push(q.as_ref_id().ok_or_else(|| r.err_at(q, idx, "point references"))?);
                    }
                }
                None => out.push(p.as_ref_id().ok_or_else(|| r.err_at(p, idx, "point references"))?),
            }
        }
        Ok(out)
    }
}

fn not_bspline(doc: &Document, k: usize) -> Error {
    Error::UnexpectedEntity {
        at: doc.position_of(k, 0),
        expected: "a B-spline curve or surface",
        found: doc.name_of(k).to_owned(),
    }
}

impl Ctx<'_> {
    /// `(EDGE_CURVE, orientation)` of each `ORIENTED_EDGE` of an `EDGE_LOOP` (empty for
    /// vertex and poly loops).
    pub fn loop_edges(&self, lp: EntityId) -> Result<Vec<(EntityId, bool)>> {
        let k = self.index(lp)?;
        let edges = match self.flat_refs(k, b"EDGE_LOOP") {
            Some(edges) => edges,
            None => {
                let r = self.any(lp)?;
                if r.name() != "EDGE_LOOP" {
                    return Ok(vec![]);
                }
                r.arity(2)?;
                r.refs(1)?
            }
        };
        let mut out = Vec::with_capacity(edges.len());
        for oe in edges {
            // The general reading below reads only the edge and its orientation.
            if let Some([_, _, Flat::Ref(e), Flat::Bool(b)]) = self.flat::<4>(self.index(oe)?, b"ORIENTED_EDGE") {
                out.push((e, b));
                continue;
            }
            let o = self.any(oe)?;
            match o.name() {
                "ORIENTED_EDGE" => {
                    o.arity(5)?;
                    out.push((o.reference(3)?, o.bool(4)?));
                }
                "EDGE_CURVE" => out.push((oe, true)),
                other => {
                    return Err(Error::UnexpectedEntity {
                        at: self.doc.position_of_id(oe),
                        expected: "ORIENTED_EDGE",
                        found: other.to_owned(),
                    })
                }
            }
        }
        Ok(out)
    }

    /// An edge's curve, its parameter range along the curve's direction, and its vertex
    /// points (local coordinates); read once per context (an edge bounds two faces).
    pub fn edge_geometry(&self, e: EntityId) -> Result<std::rc::Rc<EdgeGeometry>> {
        let k = self.index(e)?;
        if let Some(g) = self.edges.borrow().get(&k) {
            return Ok(std::rc::Rc::clone(g));
        }
        let g = std::rc::Rc::new(self.read_edge_geometry(e)?);
        self.edges.borrow_mut().insert(k, std::rc::Rc::clone(&g));
        Ok(g)
    }

    fn read_edge_geometry(&self, e: EntityId) -> Result<EdgeGeometry> {
        let vp = |v: EntityId| -> Result<Point3<f64>> {
            let k = self.index(v)?;
            if let Some(&p) = self.vertices.borrow().get(&k) {
                return Ok(p);
            }
            let p = match self.flat::<1>(k, b"VERTEX_POINT") {
                Some([Flat::Ref(p)]) => self.point(p)?,
                _ => {
                    let vr = self.simple(v, "VERTEX_POINT")?;
                    vr.arity(2)?;
                    self.point(vr.reference(1)?)?
                }
            };
            self.vertices.borrow_mut().insert(k, p);
            Ok(p)
        };
        let (p0, p1, c, same) = match self.flat::<4>(self.index(e)?, b"EDGE_CURVE") {
            Some([Flat::Ref(a), Flat::Ref(b), Flat::Ref(c), Flat::Bool(same)]) => {
                (vp(a)?, vp(b)?, self.curve(c)?, same)
            }
            _ => {
                let r = self.simple(e, "EDGE_CURVE")?;
                r.arity(5)?;
                let (p0, p1) = (vp(r.reference(1)?)?, vp(r.reference(2)?)?);
                let c = self.curve(r.reference(3)?)?;
                (p0, p1, c, r.bool(4)?)
            }
        };
        let tol = 1e-9 * (p0.coords.norm() + p1.coords.norm() + 1.0);
        let (ta, tb) = (c.param_of(&p0, tol), c.param_of(&p1, tol));
        let (mut t0, mut t1) = if same { (ta, tb) } else { (tb, ta) };
        if let Some(per) = c.period() {
            if (p0 - p1).norm() <= tol * 10.0 && (t1 - t0).abs() < 1e-9 {
                t1 = t0 + per;
            }
            while t1 <= t0 {
                t1 += per;
            }
            while t1 - t0 > per + 1e-12 {
                t1 -= per;
            }
        } else if t1 < t0 {
            std::mem::swap(&mut t0, &mut t1);
        }
        if let Some((a, b)) = c.domain() {
            // A closed edge (one vertex) on a closed bounded curve: the whole curve.
            if (t1 - t0).abs() <= 1e-9 * (b - a).abs().max(1.0) && (p0 - p1).norm() <= tol * 10.0 {
                t0 = a;
                t1 = b;
            }
        }
        if t1.partial_cmp(&t0) != Some(std::cmp::Ordering::Greater) {
            return Err(Error::Geometry {
                at: self.doc.position_of_id(e),
                source: cadmorph_nurbs::Error::EmptyDomain { start: t0, end: t1 },
            });
        }
        Ok((c, t0, t1, p0, p1))
    }
}
