//! Typed views: units, geometry and B-rep topology as cadmorph-nurbs types in world
//! coordinates and model units.

mod bounds;
pub(crate) mod flat;
pub(crate) mod geometry;
mod topology;
mod units;

use std::cell::RefCell;
use std::rc::Rc;

use rustc_hash::FxHashMap;

use cadmorph_nurbs::analytic::ParamMap;
use cadmorph_nurbs::math::{Matrix4, Point3};
use cadmorph_nurbs::{NurbsCurve, NurbsSurface};

use crate::document::Document;
use crate::error::{Error, Position, Result};
use crate::read::param::{Body, Param, Record, Value};
use crate::EntityId;

pub(crate) use topology::{Link, Occurrence};

/// Surfaces [`Document::faces`] read to classify them, kept for the conversion that
/// usually follows ([`Document::faces_nurbs`]): analytic surfaces whole, B-spline
/// surfaces up to their control points' references (the points' coordinates are read
/// when the face is converted). Keyed by instance position and the bits of the angle
/// unit's scale the surface was read with. Emptied by every edit; a copy of the document starts
/// empty.
#[derive(Debug, Default)]
pub(crate) struct SurfaceCache(std::sync::Mutex<FxHashMap<(u64, u64), std::sync::Arc<geometry::CachedSurface>>>);

impl Clone for SurfaceCache {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl SurfaceCache {
    fn get(&self, key: (u64, u64)) -> Option<std::sync::Arc<geometry::CachedSurface>> {
        self.0.lock().ok()?.get(&key).cloned()
    }

    fn put(&self, key: (u64, u64), s: geometry::CachedSurface) {
        if let Ok(mut m) = self.0.lock() {
            m.insert(key, std::sync::Arc::new(s));
        }
    }
}
pub use units::{LengthUnit, Units};

/// Nesting of geometric references (trimmed curve of a surface curve of ...) beyond which
/// the reader gives up; real files use 3 or 4.
const MAX_NESTING: usize = 64;

/// The surface type of a face, with the B-spline numbers the `info` command shows.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceKind {
    /// `PLANE`.
    Plane,
    /// `CYLINDRICAL_SURFACE`.
    Cylinder,
    /// `CONICAL_SURFACE`.
    Cone,
    /// `SPHERICAL_SURFACE`.
    Sphere,
    /// `TOROIDAL_SURFACE`.
    Torus,
    /// `SURFACE_OF_REVOLUTION`.
    Revolution,
    /// `SURFACE_OF_LINEAR_EXTRUSION`.
    Extrusion,
    /// `B_SPLINE_SURFACE_WITH_KNOTS` or its rational complex form.
    BSpline {
        /// Degree in u.
        u_degree: usize,
        /// Degree in v.
        v_degree: usize,
        /// Poles in u.
        n_u: usize,
        /// Poles in v.
        n_v: usize,
        /// Whether it has weights.
        rational: bool,
    },
    /// A surface this crate does not convert (its entity name).
    Other(String),
}

/// A face of a B-rep, placed in the world: one per face and assembly occurrence.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The `ADVANCED_FACE` / `FACE_SURFACE` instance.
    pub id: EntityId,
    /// Its surface instance.
    pub surface: EntityId,
    /// The surface type (of the basis, for `RECTANGULAR_TRIMMED_SURFACE`).
    pub kind: SurfaceKind,
    /// `same_sense`: the face normal is the surface normal (`false`: reversed).
    pub same_sense: bool,
    /// The loops bounding the face: `(FACE_BOUND instance, loop instance, orientation)`.
    pub bounds: Vec<(EntityId, EntityId, bool)>,
    /// The shape representation the face belongs to.
    pub representation: EntityId,
    /// Which placement of that representation (0 unless an assembly places it twice).
    pub occurrence: usize,
    /// Local (file) coordinates to world coordinates in model units.
    pub transform: Matrix4<f64>,
}

/// An edge between faces, placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// The `EDGE_CURVE` instance.
    pub id: EntityId,
    /// Its geometry (curve) instance.
    pub curve: EntityId,
    /// Start vertex (`VERTEX_POINT`).
    pub start: EntityId,
    /// End vertex.
    pub end: EntityId,
    /// The edge runs along its curve (`false`: against it).
    pub same_sense: bool,
    /// Indices into [`Document::faces`] of the faces whose loops use this edge (two
    /// for a shared edge; the same face twice for a seam).
    pub faces: Vec<usize>,
    /// Placement occurrence, as in [`Face::occurrence`].
    pub occurrence: usize,
    /// Local to world, as in [`Face::transform`].
    pub transform: Matrix4<f64>,
}

/// A face's surface as a world-coordinate NURBS in model units.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldSurface {
    /// The surface. For analytic faces its domain is the face's parameter box.
    pub surface: NurbsSurface,
    /// The file's (OCCT's) u parameter → NURBS u.
    pub u_map: ParamMap,
    /// The file's v parameter → NURBS v.
    pub v_map: ParamMap,
    /// The face's parameter box in the file's parameters (the whole domain for B-splines).
    pub u_range: (f64, f64),
    /// See `u_range`.
    pub v_range: (f64, f64),
}

impl WorldSurface {
    /// The NURBS parameters of the file's parameters `(u, v)`; angles are first moved by
    /// whole turns into the face's range.
    ///
    /// # Examples
    ///
    /// ```
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/mixed_solid.stp")).unwrap();
    /// let doc = cadmorph_step::Document::parse(&bytes).unwrap();
    /// let faces = doc.faces().unwrap();
    /// let cyl = faces.iter().find(|f| f.kind == cadmorph_step::SurfaceKind::Cylinder).unwrap();
    /// let w = doc.face_nurbs(cyl).unwrap();
    /// let (s, _) = w.nurbs_params(w.u_range.0 - std::f64::consts::TAU, w.v_range.0);
    /// assert!((s - w.u_range.0).abs() < 1e-12);
    /// ```
    pub fn nurbs_params(&self, u: f64, v: f64) -> (f64, f64) {
        (wrap(&self.u_map, u), wrap(&self.v_map, v))
    }
}

fn wrap(m: &ParamMap, t: f64) -> f64 {
    match *m {
        ParamMap::Arc { start, end, .. } => {
            let tau = std::f64::consts::TAU;
            let mut t = t;
            let eps = 1e-9;
            if t < start - eps {
                t += ((start - t) / tau).ceil() * tau;
            }
            if t > end + eps {
                t -= ((t - end) / tau).ceil() * tau;
            }
            m.to_nurbs(t)
        }
        ParamMap::Identity => t,
    }
}

/// An edge's curve as a world-coordinate NURBS in model units, trimmed to the edge.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldCurve {
    /// The curve, running along the curve entity's direction over the edge's range.
    pub curve: NurbsCurve,
    /// The file's curve parameter → NURBS parameter.
    pub map: ParamMap,
    /// The edge's range in the file's curve parameter.
    pub range: (f64, f64),
    /// World position of the start vertex.
    pub start: Point3<f64>,
    /// World position of the end vertex.
    pub end: Point3<f64>,
}

/// Conversion context: the document, the angle unit, the stack of instances being
/// resolved (for cycle detection), and what it has read so far.
///
/// A context reads each edge's geometry once ([`edge_geometry`](Self::edge_geometry)):
/// the faces of a B-rep share their edges, and one context converts them all. It reads
/// each unit once ([`unit`](Self::unit)).
pub(crate) struct Ctx<'d> {
    pub doc: &'d Document,
    pub length_scale: f64,
    pub angle_scale: f64,
    stack: RefCell<Vec<u64>>,
    // The caches below are keyed by instance position, which the reader gives, not by
    // the file's ids: a hostile file could choose ids that collide in the fast hash.
    /// Edge geometry by `EDGE_CURVE` position.
    edges: RefCell<FxHashMap<usize, Rc<topology::EdgeGeometry>>>,
    /// Units by instance position.
    units: RefCell<FxHashMap<usize, units::Unit>>,
    /// Vertex points by `VERTEX_POINT` position (a vertex ends several edges).
    vertices: RefCell<FxHashMap<usize, nalgebra::Point3<f64>>>,
    /// The parameter stack every record of this context is read with.
    params: RefCell<Vec<crate::read::param::Param<'d>>>,
}

impl<'d> Ctx<'d> {
    pub fn new(doc: &'d Document, angle_scale: f64) -> Self {
        Self {
            doc,
            length_scale: 1.0,
            angle_scale,
            stack: RefCell::new(Vec::new()),
            edges: RefCell::new(FxHashMap::default()),
            units: RefCell::new(FxHashMap::default()),
            vertices: RefCell::new(FxHashMap::default()),
            params: RefCell::new(Vec::new()),
        }
    }

    pub fn index(&self, id: EntityId) -> Result<usize> {
        self.doc.index.get(id.0).ok_or(Error::NoSuchInstance(id))
    }

    /// The parsed body of the instance at position `k`. Not kept: most records are read
    /// once, and keeping them cost more than reading the few shared ones again.
    pub fn body(&self, k: usize) -> Result<Rc<Body<'d>>> {
        Ok(Rc::new(self.doc.body_at_in(k, &mut self.params.borrow_mut())?))
    }

    /// Runs `f` with `id` on the resolution stack; a second visit is a cycle.
    pub fn nested<T>(&self, id: EntityId, f: impl FnOnce() -> Result<T>) -> Result<T> {
        {
            let mut s = self.stack.borrow_mut();
            if s.contains(&id.0) {
                return Err(Error::ReferenceCycle { at: self.doc.position_of_id(id), target: id });
            }
            if s.len() >= MAX_NESTING {
                return Err(Error::Limit { at: self.doc.position_of_id(id), what: "references nested too deeply" });
            }
            s.push(id.0);
        }
        let r = f();
        self.stack.borrow_mut().pop();
        r
    }

    /// The simple record of `#id`, which must be entity `name`.
    pub fn simple(&self, id: EntityId, name: &'static str) -> Result<Rec<'d>> {
        let k = self.index(id)?;
        let r = Rec::new(self.doc, k, self.body(k)?)?;
        if r.name() != name {
            return Err(Error::UnexpectedEntity {
                at: self.doc.position_of(k, 0),
                expected: name,
                found: r.name().to_owned(),
            });
        }
        Ok(r)
    }

    /// The parameters after the name string of the instance at `k` when it is the flat
    /// record `name(...)` of `N` such parameters ([`flat::flat`]); `None` otherwise, and
    /// the caller reads it with the general reader.
    pub fn flat<const N: usize>(&self, k: usize, name: &[u8]) -> Option<[flat::Flat; N]> {
        flat::flat(self.doc.text(k), self.doc.instances[k].body as usize, name)
    }

    /// [`flat`](Self::flat) with `strings` leading strings instead of one.
    pub fn flat_after<const N: usize>(&self, k: usize, name: &[u8], strings: usize) -> Option<[flat::Flat; N]> {
        flat::flat_after(self.doc.text(k), self.doc.instances[k].body as usize, name, strings)
    }

    /// [`flat`](Self::flat) of the instance at `k` under its own name, whatever it is.
    pub fn flat_any<const N: usize>(&self, k: usize) -> Option<[flat::Flat; N]> {
        flat::flat(self.doc.text(k), self.doc.instances[k].body as usize, self.doc.name_bytes(k))
    }

    /// The references of a [`flat::Flat::List`] of the instance at `k` ([`flat::ref_list`]).
    pub fn ref_list(&self, k: usize, span: (usize, usize)) -> Option<Vec<EntityId>> {
        flat::ref_list(self.doc.text(k), span)
    }

    /// The references of the instance at `k` when it is `name('...', (#a, #b, …))` read
    /// flat (an edge loop, a shell); `None` otherwise.
    pub fn flat_refs(&self, k: usize, name: &[u8]) -> Option<Vec<EntityId>> {
        match self.flat::<1>(k, name)? {
            [flat::Flat::List(a, b)] => self.ref_list(k, (a, b)),
            _ => None,
        }
    }

    /// The simple record of `#id`, whatever its name.
    pub fn any(&self, id: EntityId) -> Result<Rec<'d>> {
        let k = self.index(id)?;
        Rec::new(self.doc, k, self.body(k)?)
    }
}

/// One record with the context needed to report errors; `shift` offsets parameter
/// indices (used to read a supertype's attributes inside a subtype record).
#[derive(Debug, Clone)]
pub(crate) struct Rec<'d> {
    doc: &'d Document,
    k: usize,
    /// Shared, so that a record read once can be viewed at several shifts (a subtype's
    /// own attributes after its supertype's), and each leaf of a complex instance on its
    /// own, without copying its parameter tree.
    body: Rc<Body<'d>>,
    /// Which leaf of a complex body (0 for a simple one).
    leaf: usize,
    shift: usize,
}

impl<'d> Rec<'d> {
    pub fn new(doc: &'d Document, k: usize, body: Rc<Body<'d>>) -> Result<Self> {
        match &*body {
            Body::Simple(_) => Ok(Self { doc, k, body, leaf: 0, shift: 0 }),
            Body::Complex(leaves) => Err(Error::UnexpectedEntity {
                at: doc.position_of(k, 0),
                expected: "a simple instance",
                found: format!("({})", leaves.iter().map(|r| r.name).collect::<Vec<_>>().join(" ")),
            }),
        }
    }

    pub fn from_record(doc: &'d Document, k: usize, rec: Record<'d>) -> Self {
        Self { doc, k, body: Rc::new(Body::Simple(rec)), leaf: 0, shift: 0 }
    }

    /// The leaf `name` of a complex body, or the simple record if it has that name.
    pub fn leaf(doc: &'d Document, k: usize, body: &Rc<Body<'d>>, name: &str) -> Option<Self> {
        let leaf = match &**body {
            Body::Simple(r) => (r.name == name).then_some(0)?,
            Body::Complex(v) => v.iter().position(|r| r.name == name)?,
        };
        Some(Self { doc, k, body: Rc::clone(body), leaf, shift: 0 })
    }

    /// The record viewed.
    pub fn rec(&self) -> &Record<'d> {
        match &*self.body {
            Body::Simple(r) => r,
            Body::Complex(v) => &v[self.leaf],
        }
    }

    pub fn shifted(mut self, by: usize) -> Self {
        self.shift += by;
        self
    }

    pub fn name(&self) -> &'d str {
        self.rec().name
    }

    pub fn position(&self, i: usize) -> Position {
        match self.rec().params.get(i + self.shift) {
            Some(p) => self.doc.position_of(self.k, p.start),
            None => self.doc.position_of(self.k, self.rec().start),
        }
    }

    pub fn arity(&self, n: usize) -> Result<()> {
        if self.rec().params.len() == n {
            Ok(())
        } else {
            Err(Error::Arity {
                at: self.doc.position_of(self.k, self.rec().start),
                entity: self.rec().name.to_owned(),
                expected: n,
                found: self.rec().params.len(),
            })
        }
    }

    pub fn param(&self, i: usize) -> Result<&Param<'d>> {
        self.rec().params.get(i + self.shift).ok_or_else(|| self.err(i, "a parameter"))
    }

    pub fn err(&self, i: usize, expected: &'static str) -> Error {
        Error::Parameter { at: self.position(i), entity: self.rec().name.to_owned(), index: i + self.shift, expected }
    }

    pub fn err_at(&self, p: &Param<'_>, i: usize, expected: &'static str) -> Error {
        Error::Parameter {
            at: self.doc.position_of(self.k, p.start),
            entity: self.rec().name.to_owned(),
            index: i + self.shift,
            expected,
        }
    }

    pub fn geometry(&self, source: cadmorph_nurbs::Error) -> Error {
        Error::Geometry { at: self.doc.position_of(self.k, self.rec().start), source }
    }

    pub fn real(&self, i: usize) -> Result<f64> {
        self.param(i)?.as_f64().ok_or_else(|| self.err(i, "a number"))
    }

    pub fn reference(&self, i: usize) -> Result<EntityId> {
        self.param(i)?.as_ref_id().ok_or_else(|| self.err(i, "a reference"))
    }

    pub fn list(&self, i: usize) -> Result<&[Param<'d>]> {
        self.param(i)?.as_list().ok_or_else(|| self.err(i, "a list"))
    }

    pub fn bool(&self, i: usize) -> Result<bool> {
        self.param(i)?.as_bool().ok_or_else(|| self.err(i, "a boolean .T. or .F."))
    }

    pub fn is_unset(&self, i: usize) -> bool {
        matches!(self.rec().params.get(i + self.shift).map(|p| &p.value), Some(Value::Unset) | None)
    }

    pub fn usize_at(&self, i: usize) -> Result<usize> {
        match self.param(i)?.value {
            Value::Integer(n) if n >= 0 => usize::try_from(n).map_err(|_| self.err(i, "a small non-negative integer")),
            _ => Err(self.err(i, "a non-negative integer")),
        }
    }

    pub fn usizes(&self, i: usize) -> Result<Vec<usize>> {
        let l = self.list(i)?;
        l.iter()
            .map(|p| match p.value {
                Value::Integer(n) if n >= 0 => usize::try_from(n).map_err(|_| self.err_at(p, i, "small integers")),
                _ => Err(self.err_at(p, i, "non-negative integers")),
            })
            .collect()
    }

    pub fn reals(&self, i: usize) -> Result<Vec<f64>> {
        let l = self.list(i)?;
        l.iter().map(|p| p.as_f64().ok_or_else(|| self.err_at(p, i, "numbers"))).collect()
    }

    pub fn refs(&self, i: usize) -> Result<Vec<EntityId>> {
        let l = self.list(i)?;
        l.iter().map(|p| p.as_ref_id().ok_or_else(|| self.err_at(p, i, "references"))).collect()
    }
}
