//! Geometry entities as cadmorph-nurbs types (local coordinates, file units).

use cadmorph_nurbs::analytic::{
    AnalyticCurve, AnalyticSurface, Circle, Cone, Cylinder, ExactSurface, Extrusion, Line, ParamMap, Placement, Plane,
    Revolution, Sphere, Torus,
};
use cadmorph_nurbs::math::{Matrix3, Matrix4, Point3, Vector3};
use cadmorph_nurbs::{Curve, CurveProject, KnotVector, NurbsCurve, NurbsSurface};

use super::flat::Flat;
use super::{Ctx, Rec, SurfaceKind};
use crate::error::{Error, Result};
use crate::read::param::{Body, Param, Value};
use crate::EntityId;

use std::rc::Rc;

/// A 3D curve as the file defines it.
#[derive(Debug, Clone)]
pub(crate) enum CurveGeom {
    Line(Line),
    /// A circle or an ellipse (semi-axes `a ≥ b`; `a = b` for circles) and its frame.
    Conic {
        frame: Placement,
        a: f64,
        b: f64,
    },
    Nurbs(NurbsCurve),
    /// A polyline: degree-1 NURBS with the vertex index as parameter (as OCCT reads it).
    Polyline(NurbsCurve),
    Trimmed {
        basis: Box<CurveGeom>,
        t0: f64,
        t1: f64,
    },
}

/// A surface as the file defines it.
#[derive(Debug, Clone)]
pub(crate) enum SurfaceGeom {
    Plane(Plane),
    Cylinder(Cylinder),
    Cone(Cone),
    Sphere(Sphere),
    Torus(Torus),
    Revolution(Revolution),
    Extrusion(Extrusion),
    Nurbs(NurbsSurface),
    Trimmed { basis: Box<SurfaceGeom>, u: (f64, f64), v: (f64, f64) },
}

impl CurveGeom {
    pub fn eval(&self, t: f64) -> Point3<f64> {
        match self {
            CurveGeom::Line(l) => l.eval(t),
            CurveGeom::Conic { frame, a, b } => {
                let (s, c) = t.sin_cos();
                frame.to_world(a * c, b * s, 0.0)
            }
            CurveGeom::Nurbs(c) | CurveGeom::Polyline(c) => Curve::eval(c, t),
            CurveGeom::Trimmed { basis, .. } => basis.eval(t),
        }
    }

    /// Period of a closed curve (circles and ellipses), if any.
    pub fn period(&self) -> Option<f64> {
        match self {
            CurveGeom::Conic { .. } => Some(std::f64::consts::TAU),
            CurveGeom::Trimmed { basis, .. } => basis.period(),
            _ => None,
        }
    }

    /// The curve's own parameter range, if bounded.
    pub fn domain(&self) -> Option<(f64, f64)> {
        match self {
            CurveGeom::Nurbs(c) | CurveGeom::Polyline(c) => {
                let d = c.domain();
                Some((*d.start(), *d.end()))
            }
            CurveGeom::Trimmed { t0, t1, .. } => Some((*t0, *t1)),
            _ => None,
        }
    }

    /// The parameter of the point of the curve closest to `p`.
    pub fn param_of(&self, p: &Point3<f64>, tol: f64) -> f64 {
        match self {
            CurveGeom::Line(l) => {
                let o = l.eval(0.0);
                (p - o).dot(&l.deriv(0.0))
            }
            CurveGeom::Conic { frame, a, b } => {
                let d = p - frame.origin();
                (d.dot(&frame.y_dir()) / b).atan2(d.dot(&frame.x_dir()) / a)
            }
            CurveGeom::Nurbs(c) | CurveGeom::Polyline(c) => {
                // A vertex at an end of an open curve, where writers put them: that end,
                // without a search (a closed curve's ends are one point: searched).
                let d = c.domain();
                let (a, b) = (*d.start(), *d.end());
                let (pa, pb) = (c.eval(a), c.eval(b));
                if (pa - pb).norm() > 2.0 * tol {
                    if (pa - p).norm() <= tol {
                        return a;
                    }
                    if (pb - p).norm() <= tol {
                        return b;
                    }
                }
                c.project(p, tol).t
            }
            CurveGeom::Trimmed { basis, .. } => basis.param_of(p, tol),
        }
    }

    /// The exact NURBS form over `[t0, t1]` and the map from this curve's parameter.
    pub fn to_nurbs(&self, t0: f64, t1: f64) -> cadmorph_nurbs::Result<(NurbsCurve, ParamMap)> {
        match self {
            CurveGeom::Line(l) => l.to_nurbs(t0..=t1).map(|e| (e.curve, e.map)),
            CurveGeom::Conic { frame, a, b } => {
                // The unit circle's exact form, stretched by (a, b) in the frame (NURBS are
                // affinely invariant, and the angle map is the circle's).
                let e = Circle::try_new(*frame, 1.0)?.to_nurbs(t0..=t1)?;
                Ok((e.curve.transformed(&stretch(frame, *a, *b)), e.map))
            }
            CurveGeom::Nurbs(c) | CurveGeom::Polyline(c) => Ok((c.segment(t0, t1)?, ParamMap::Identity)),
            CurveGeom::Trimmed { basis, .. } => basis.to_nurbs(t0, t1),
        }
    }
}

/// The affine map scaling by `a` along the frame's X and `b` along its Y about its origin.
fn stretch(f: &Placement, a: f64, b: f64) -> Matrix4<f64> {
    let r = Matrix3::from_columns(&[f.x_dir(), f.y_dir(), f.z_dir()]);
    let lin = r * Matrix3::from_diagonal(&Vector3::new(a, b, 1.0)) * r.transpose();
    let o = f.origin().coords;
    let t = o - lin * o;
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&lin);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
    m
}

impl SurfaceGeom {
    /// The exact NURBS form over `u × v` (the B-spline itself for B-spline surfaces).
    pub fn to_nurbs(&self, u: (f64, f64), v: (f64, f64)) -> cadmorph_nurbs::Result<ExactSurface> {
        match self {
            SurfaceGeom::Plane(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Cylinder(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Cone(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Sphere(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Torus(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Revolution(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Extrusion(s) => s.to_nurbs(u.0..=u.1, v.0..=v.1),
            SurfaceGeom::Nurbs(s) => {
                Ok(ExactSurface { surface: s.clone(), u_map: ParamMap::Identity, v_map: ParamMap::Identity })
            }
            SurfaceGeom::Trimmed { basis, .. } => basis.to_nurbs(u, v),
        }
    }
}

impl<'a> Ctx<'a> {
    /// `CARTESIAN_POINT('', (x, y, z))`, with a fast path that reads the numbers straight
    /// from the text.
    pub fn point(&self, id: EntityId) -> Result<Point3<f64>> {
        let k = self.index(id)?;
        if let Some(p) = fast_point(self.doc.text(k), self.doc.instances[k].body as usize) {
            return Ok(p);
        }
        let r = self.simple(id, "CARTESIAN_POINT")?;
        r.arity(2)?;
        let c = r.list(1)?;
        if c.is_empty() || c.len() > 3 {
            return Err(r.err(1, "a list of 1 to 3 coordinates"));
        }
        let mut xyz = [0.0; 3];
        for (i, p) in c.iter().enumerate() {
            xyz[i] = p.as_f64().ok_or_else(|| r.err_at(p, 1, "a number"))?;
        }
        Ok(Point3::from(xyz))
    }

    /// The points `ids` in order, as [`point`](Self::point) reads each. A large net
    /// (at least [`PARALLEL_POINTS`]) is read on rayon's threads: its points are most of a
    /// B-spline file's text, and reading one is independent of the others. A point the
    /// fast form does not read (or an error) is read again here, on this thread, with the
    /// full reader and its error.
    pub fn points(&self, ids: &[EntityId]) -> Result<Vec<Point3<f64>>> {
        let doc = self.doc;
        let fast = |id: &EntityId| {
            let k = doc.index.get(id.0)?;
            fast_point(doc.text(k), doc.instances[k].body as usize)
        };
        let read: Vec<Option<Point3<f64>>> = if ids.len() >= PARALLEL_POINTS {
            use rayon::prelude::*;
            ids.par_iter().with_min_len(1024).map(fast).collect()
        } else {
            ids.iter().map(fast).collect()
        };
        ids.iter().zip(read).map(|(&id, p)| p.map_or_else(|| self.point(id), Ok)).collect()
    }

    /// `DIRECTION('', (x, y, z))`.
    pub fn direction(&self, id: EntityId) -> Result<Vector3<f64>> {
        let k = self.index(id)?;
        if let Some(d) = fast_triple(self.doc.text(k), self.doc.instances[k].body as usize, b"DIRECTION") {
            return Ok(Vector3::from(d));
        }
        let r = self.simple(id, "DIRECTION")?;
        r.arity(2)?;
        let c = r.list(1)?;
        if c.is_empty() || c.len() > 3 {
            return Err(r.err(1, "a list of 1 to 3 direction ratios"));
        }
        let mut xyz = [0.0; 3];
        for (i, p) in c.iter().enumerate() {
            xyz[i] = p.as_f64().ok_or_else(|| r.err_at(p, 1, "a number"))?;
        }
        Ok(Vector3::from(xyz))
    }

    /// `VECTOR('', direction, magnitude)` as (unit direction, magnitude).
    pub fn vector(&self, id: EntityId) -> Result<(Vector3<f64>, f64)> {
        if let Some([Flat::Ref(d), Flat::Number(m)]) = self.flat::<2>(self.index(id)?, b"VECTOR") {
            return Ok((self.direction(d)?, m * self.length_scale));
        }
        let r = self.simple(id, "VECTOR")?;
        r.arity(3)?;
        let d = self.direction(r.reference(1)?)?;
        Ok((d, r.real(2)? * self.length_scale))
    }

    /// `AXIS2_PLACEMENT_3D('', location, axis, ref_direction)` with OCCT's defaults for `$`.
    pub fn placement(&self, id: EntityId) -> Result<Placement> {
        let k = self.index(id)?;
        if let Some([Flat::Ref(o), z @ (Flat::Ref(_) | Flat::Unset), x @ (Flat::Ref(_) | Flat::Unset)]) =
            self.flat::<3>(k, b"AXIS2_PLACEMENT_3D")
        {
            // What the general reading below does, in its order; a placement it refuses is
            // read again there for the error.
            let o = self.point(o)?;
            let z = match z {
                Flat::Ref(d) => self.direction(d)?,
                _ => Vector3::z(),
            };
            let x = match x {
                Flat::Ref(d) => self.direction(d)?,
                _ => default_x(&z),
            };
            if let Ok(p) = Placement::try_new(o, z, x).or_else(|_| Placement::try_new(o, z, default_x(&z))) {
                return Ok(p);
            }
        }
        let r = self.simple(id, "AXIS2_PLACEMENT_3D")?;
        r.arity(4)?;
        let o = self.point(r.reference(1)?)?;
        let z = if r.is_unset(2) { Vector3::z() } else { self.direction(r.reference(2)?)? };
        let x = if r.is_unset(3) { default_x(&z) } else { self.direction(r.reference(3)?)? };
        Placement::try_new(o, z, x).or_else(|_| Placement::try_new(o, z, default_x(&z))).map_err(|e| r.geometry(e))
    }

    /// `AXIS1_PLACEMENT('', location, axis)`.
    pub fn axis1(&self, id: EntityId) -> Result<(Point3<f64>, Vector3<f64>)> {
        let r = self.simple(id, "AXIS1_PLACEMENT")?;
        r.arity(3)?;
        let o = self.point(r.reference(1)?)?;
        let z = if r.is_unset(2) { Vector3::z() } else { self.direction(r.reference(2)?)? };
        Ok((o, z))
    }

    /// A 3D curve entity.
    pub fn curve(&self, id: EntityId) -> Result<CurveGeom> {
        self.nested(id, || self.curve_inner(id))
    }

    fn curve_inner(&self, id: EntityId) -> Result<CurveGeom> {
        let k = self.index(id)?;
        // Lines and circles as flat records (what the general reading below does, in its
        // order; one it refuses is read again there for the error).
        if let Some([Flat::Ref(o), Flat::Ref(v)]) = self.flat::<2>(k, b"LINE") {
            let o = self.point(o)?;
            let (d, _) = self.vector(v)?;
            if let Ok(l) = Line::try_new(o, d) {
                return Ok(CurveGeom::Line(l));
            }
        } else if let Some([Flat::Ref(f), Flat::Number(a)]) = self.flat::<2>(k, b"CIRCLE") {
            let frame = self.placement(f)?;
            let a = a * self.length_scale;
            if Circle::try_new(frame, a).is_ok() {
                return Ok(CurveGeom::Conic { frame, a, b: a });
            }
        } else if matches!(self.doc.name_bytes(k), b"SURFACE_CURVE" | b"SEAM_CURVE" | b"INTERSECTION_CURVE") {
            if let Some([Flat::Ref(c), _, _]) = self.flat_any::<3>(k) {
                return self.curve(c);
            }
        }
        let body = self.body(k)?;
        if let Body::Complex(_) = &*body {
            return self.bspline_curve(k, &body).map(CurveGeom::Nurbs);
        }
        let r = Rec::new(self.doc, k, Rc::clone(&body))?;
        match r.name() {
            "LINE" => {
                r.arity(3)?;
                let o = self.point(r.reference(1)?)?;
                let (d, _) = self.vector(r.reference(2)?)?;
                Line::try_new(o, d).map(CurveGeom::Line).map_err(|e| r.geometry(e))
            }
            "CIRCLE" => {
                r.arity(3)?;
                let frame = self.placement(r.reference(1)?)?;
                let a = r.real(2)? * self.length_scale;
                Circle::try_new(frame, a).map_err(|e| r.geometry(e))?;
                Ok(CurveGeom::Conic { frame, a, b: a })
            }
            "ELLIPSE" => {
                r.arity(4)?;
                let frame = self.placement(r.reference(1)?)?;
                let (a, b) = (r.real(2)? * self.length_scale, r.real(3)? * self.length_scale);
                if !(a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0) {
                    return Err(r.err(2, "positive finite semi-axes"));
                }
                Ok(CurveGeom::Conic { frame, a, b })
            }
            "B_SPLINE_CURVE_WITH_KNOTS" => self.bspline_curve(k, &body).map(CurveGeom::Nurbs),
            "POLYLINE" => {
                r.arity(2)?;
                let pts = r.list(1)?;
                let mut ps = Vec::with_capacity(pts.len());
                for p in pts {
                    ps.push(self.point(p.as_ref_id().ok_or_else(|| r.err_at(p, 1, "a point reference"))?)?);
                }
                let n = ps.len();
                let mut knots = vec![0.0];
                knots.extend((0..n).map(|i| i as f64));
                knots.push((n.max(1) - 1) as f64);
                let kv = KnotVector::try_new(knots).map_err(|e| r.geometry(e))?;
                NurbsCurve::try_new(1, kv, ps, None).map(CurveGeom::Polyline).map_err(|e| r.geometry(e))
            }
            "TRIMMED_CURVE" => {
                // TRIMMED_CURVE('', basis, (trim1), (trim2), sense, preference)
                r.arity(6)?;
                let basis = self.curve(r.reference(1)?)?;
                let t1 = self.trim_param(&r, 2, &basis)?;
                let t2 = self.trim_param(&r, 3, &basis)?;
                let sense = r.bool(4)?;
                let (mut a, mut b) = if sense { (t1, t2) } else { (t2, t1) };
                if let Some(per) = basis.period() {
                    while b <= a {
                        b += per;
                    }
                    while b - a > per + 1e-12 {
                        a += per;
                    }
                }
                Ok(CurveGeom::Trimmed { basis: Box::new(basis), t0: a, t1: b })
            }
            "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE" => {
                r.arity(4)?;
                self.curve(r.reference(1)?)
            }
            other => Err(Error::UnexpectedEntity {
                at: self.doc.position_of(k, 0),
                expected: "a supported curve",
                found: other.to_owned(),
            }),
        }
    }

    /// A trimming select: a parameter value, or a point (converted to its parameter).
    fn trim_param(&self, r: &Rec<'_>, i: usize, basis: &CurveGeom) -> Result<f64> {
        let items = r.list(i)?;
        let mut point = None;
        for p in items {
            match &p.value {
                Value::Typed(name, v) if *name == "PARAMETER_VALUE" && v.len() == 1 => {
                    let x = v[0].as_f64().ok_or_else(|| r.err_at(p, i, "a number"))?;
                    return Ok(if basis.period().is_some() { x * self.angle_scale } else { x });
                }
                Value::Real(x) => return Ok(*x),
                Value::Reference(id) => point = Some(*id),
                _ => {}
            }
        }
        match point {
            Some(id) => Ok(basis.param_of(&self.point(id)?, 1e-9)),
            None => Err(r.err(i, "a parameter value or a point")),
        }
    }

    /// `B_SPLINE_CURVE_WITH_KNOTS` (simple) or the rational complex form.
    fn bspline_curve(&self, k: usize, body: &Rc<Body<'a>>) -> Result<NurbsCurve> {
        let (head, knots_rec, weights) = match &**body {
            Body::Simple(_) => {
                let r = Rec::new(self.doc, k, Rc::clone(body))?;
                r.arity(9)?;
                (r.clone().shifted(1), r.shifted(6), None)
            }
            Body::Complex(_) => {
                let b = self.leaf(k, body, "B_SPLINE_CURVE")?;
                b.arity(5)?;
                let kn = self.leaf(k, body, "B_SPLINE_CURVE_WITH_KNOTS")?;
                kn.arity(3)?;
                let w = match Rec::leaf(self.doc, k, body, "RATIONAL_B_SPLINE_CURVE") {
                    Some(w) => {
                        w.arity(1)?;
                        Some(w.reals(0)?)
                    }
                    None => None,
                };
                (b, kn, w)
            }
        };
        let degree = head.usize_at(0)?;
        let cps = head.list(1)?;
        let mut points = Vec::with_capacity(cps.len());
        for p in cps {
            points.push(self.point(p.as_ref_id().ok_or_else(|| head.err_at(p, 1, "a point reference"))?)?);
        }
        let mults = knots_rec.usizes(0)?;
        let values = knots_rec.reals(1)?;
        let kv = knot_vector(&knots_rec, &values, &mults)?;
        NurbsCurve::try_new(degree, kv, points, weights).map_err(|e| head.geometry(e))
    }

    fn leaf(&self, k: usize, body: &Rc<Body<'a>>, name: &'static str) -> Result<Rec<'a>> {
        match Rec::leaf(self.doc, k, body, name) {
            Some(rec) => Ok(rec),
            None => Err(Error::UnexpectedEntity {
                at: self.doc.position_of(k, 0),
                expected: name,
                found: self.doc.name_of(k).to_owned(),
            }),
        }
    }

    /// A surface entity.
    pub fn surface(&self, id: EntityId) -> Result<SurfaceGeom> {
        self.nested(id, || {
            let k = self.index(id)?;
            if let Some(g) = self.flat_surface(k)? {
                return Ok(g);
            }
            self.surface_inner(k, self.body(k)?)
        })
    }

    /// A `PLANE` or `CYLINDRICAL_SURFACE` at `k` read as a flat record
    /// ([`flat`](super::flat)): what [`surface`](Self::surface) gives, or `None` for any
    /// other record and for one that reading refuses (the general reading then reads it
    /// and reports).
    pub fn flat_surface(&self, k: usize) -> Result<Option<SurfaceGeom>> {
        if let Some([Flat::Ref(a)]) = self.flat::<1>(k, b"PLANE") {
            return Ok(Some(SurfaceGeom::Plane(Plane::new(self.placement(a)?))));
        }
        if let Some([Flat::Ref(a), Flat::Number(r)]) = self.flat::<2>(k, b"CYLINDRICAL_SURFACE") {
            let f = self.placement(a)?;
            return Ok(Cylinder::try_new(f, r * self.length_scale).ok().map(SurfaceGeom::Cylinder));
        }
        Ok(None)
    }

    /// [`surface`](Self::surface) of the instance at `k`, whose record the caller read.
    pub fn surface_read(&self, id: EntityId, k: usize, body: Rc<Body<'a>>) -> Result<SurfaceGeom> {
        self.nested(id, || self.surface_inner(k, body))
    }

    /// The document cache's key of surface `#id`: its instance position (given by the
    /// reader, so that a file cannot choose keys that collide in the hash map) and the
    /// angle unit's bits. `None` for an id the file lacks.
    fn cache_key(&self, id: EntityId) -> Option<(u64, u64)> {
        Some((self.doc.index.get(id.0)? as u64, self.angle_scale.to_bits()))
    }

    /// [`surface`](Self::surface), taking what [`surface_kind_of`](Self::surface_kind_of)
    /// kept of it in the document's [`SurfaceCache`](super::SurfaceCache).
    pub fn surface_kept(&self, id: EntityId) -> Result<SurfaceGeom> {
        match self.cache_key(id).and_then(|key| self.doc.surface_cache.get(key)).as_deref() {
            Some(CachedSurface::Geom(g)) => Ok(g.clone()),
            Some(CachedSurface::Net(net)) => self.net_surface(self.index(id)?, net).map(SurfaceGeom::Nurbs),
            None => self.surface(id),
        }
    }

    /// Keeps `g`, the surface `#id`, in the document's cache.
    pub fn keep_surface(&self, id: EntityId, g: &SurfaceGeom) {
        if let Some(key) = self.cache_key(id) {
            self.doc.surface_cache.put(key, CachedSurface::Geom(g.clone()));
        }
    }

    fn surface_inner(&self, k: usize, body: Rc<Body<'a>>) -> Result<SurfaceGeom> {
        if matches!(*body, Body::Complex(_)) || self.doc.name_of(k) == "B_SPLINE_SURFACE_WITH_KNOTS" {
            return self.bspline_surface(k, body).map(SurfaceGeom::Nurbs);
        }
        let r = Rec::new(self.doc, k, body)?;
        let ls = self.length_scale;
        match r.name() {
            "PLANE" => {
                r.arity(2)?;
                Ok(SurfaceGeom::Plane(Plane::new(self.placement(r.reference(1)?)?)))
            }
            "CYLINDRICAL_SURFACE" => {
                r.arity(3)?;
                let f = self.placement(r.reference(1)?)?;
                Cylinder::try_new(f, r.real(2)? * ls).map(SurfaceGeom::Cylinder).map_err(|e| r.geometry(e))
            }
            "CONICAL_SURFACE" => {
                r.arity(4)?;
                let f = self.placement(r.reference(1)?)?;
                Cone::try_new(f, r.real(2)? * ls, r.real(3)? * self.angle_scale)
                    .map(SurfaceGeom::Cone)
                    .map_err(|e| r.geometry(e))
            }
            "SPHERICAL_SURFACE" => {
                r.arity(3)?;
                let f = self.placement(r.reference(1)?)?;
                Sphere::try_new(f, r.real(2)? * ls).map(SurfaceGeom::Sphere).map_err(|e| r.geometry(e))
            }
            "TOROIDAL_SURFACE" => {
                r.arity(4)?;
                let f = self.placement(r.reference(1)?)?;
                Torus::try_new(f, r.real(2)? * ls, r.real(3)? * ls).map(SurfaceGeom::Torus).map_err(|e| r.geometry(e))
            }
            "SURFACE_OF_REVOLUTION" => {
                r.arity(3)?;
                let c = self.curve(r.reference(1)?)?;
                let (o, d) = self.axis1(r.reference(2)?)?;
                let nc = self.bounded_nurbs(&r, 1, &c)?;
                Revolution::try_new(nc, o, d).map(SurfaceGeom::Revolution).map_err(|e| r.geometry(e))
            }
            "SURFACE_OF_LINEAR_EXTRUSION" => {
                r.arity(3)?;
                let c = self.curve(r.reference(1)?)?;
                let (d, m) = self.vector(r.reference(2)?)?;
                let _ = m;
                let nc = self.bounded_nurbs(&r, 1, &c)?;
                Extrusion::try_new(nc, d).map(SurfaceGeom::Extrusion).map_err(|e| r.geometry(e))
            }
            "RECTANGULAR_TRIMMED_SURFACE" => {
                // ('', basis, u1, u2, v1, v2, usense, vsense)
                r.arity(8)?;
                let basis = self.surface(r.reference(1)?)?;
                let (su, sv) = match basis {
                    SurfaceGeom::Plane(_) | SurfaceGeom::Nurbs(_) | SurfaceGeom::Extrusion(_) => (1.0, 1.0),
                    SurfaceGeom::Cylinder(_) | SurfaceGeom::Cone(_) | SurfaceGeom::Revolution(_) => {
                        (self.angle_scale, 1.0)
                    }
                    _ => (self.angle_scale, self.angle_scale),
                };
                let (u1, u2, v1, v2) = (r.real(2)? * su, r.real(3)? * su, r.real(4)? * sv, r.real(5)? * sv);
                Ok(SurfaceGeom::Trimmed {
                    basis: Box::new(basis),
                    u: (u1.min(u2), u1.max(u2)),
                    v: (v1.min(v2), v1.max(v2)),
                })
            }
            other => Err(Error::UnexpectedEntity {
                at: self.doc.position_of(k, 0),
                expected: "a supported surface",
                found: other.to_owned(),
            }),
        }
    }

    /// The NURBS form of a curve that must be bounded (sweeps' generatrix).
    fn bounded_nurbs(&self, r: &Rec<'_>, i: usize, c: &CurveGeom) -> Result<NurbsCurve> {
        let (t0, t1) = c.domain().ok_or_else(|| r.err(i, "a bounded curve (B-spline or trimmed)"))?;
        c.to_nurbs(t0, t1).map(|(n, _)| n).map_err(|e| r.geometry(e))
    }

    /// `B_SPLINE_SURFACE_WITH_KNOTS` (simple) or the rational complex form.
    pub fn bspline_surface(&self, k: usize, body: Rc<Body<'a>>) -> Result<NurbsSurface> {
        self.net_surface(k, &self.bspline_net(k, body)?.0)
    }

    /// The surface of a checked net (of the instance at position `k`), its points read.
    fn net_surface(&self, k: usize, net: &BSplineNet) -> Result<NurbsSurface> {
        let points = self.points(&net.ids)?;
        NurbsSurface::try_new(net.degrees, net.knots.clone(), net.counts, points, net.weights.clone())
            .map_err(|e| Error::Geometry { at: self.doc.position_of(k, net.start), source: e })
    }

    /// What [`Document::faces`](crate::Document::faces) lists of a B-spline surface
    /// (instance position `k`): read from its own record (degrees, knot vectors, weights,
    /// the net of references) and checked as [`bspline_surface`](Self::bspline_surface)
    /// checks it, each reference checked to name a `CARTESIAN_POINT` instance, but the points'
    /// coordinates not read (that is the bulk of a large surface's reading, done again
    /// when the face is converted).
    pub fn bspline_surface_kind(&self, id: EntityId, k: usize, body: Rc<Body<'a>>) -> Result<SurfaceKind> {
        let (net, head) = self.bspline_net(k, body)?;
        for (n, id) in net.ids.iter().enumerate() {
            let j = self.index(*id)?;
            if self.doc.instances[j].complex || self.doc.name_bytes(j) != b"CARTESIAN_POINT" {
                let row = net.counts.1.max(1);
                return Err(Error::UnexpectedEntity {
                    at: self.doc.position_of_id(*id),
                    expected: "a CARTESIAN_POINT (a control point)",
                    found: format!("{} (control point {} of row {})", self.doc.name_of(j), n % row + 1, n / row + 1),
                });
            }
        }
        let rational = net.weights.is_some();
        NurbsSurface::check_net(
            net.degrees,
            (&net.knots.0, &net.knots.1),
            net.counts,
            net.ids.len(),
            net.weights.as_deref(),
        )
        .map_err(|e| head.geometry(e))?;
        let kind = SurfaceKind::BSpline {
            u_degree: net.degrees.0,
            v_degree: net.degrees.1,
            n_u: net.counts.0,
            n_v: net.counts.1,
            rational,
        };
        if let Some(key) = self.cache_key(id) {
            self.doc.surface_cache.put(key, CachedSurface::Net(net));
        }
        Ok(kind)
    }

    /// A B-spline surface's record read up to its control points: their references.
    fn bspline_net(&self, k: usize, body: Rc<Body<'a>>) -> Result<(BSplineNet, Rec<'a>)> {
        let (head, knots_rec, weights) = match &*body {
            Body::Simple(_) => {
                let r = Rec::new(self.doc, k, Rc::clone(&body))?;
                if r.name() != "B_SPLINE_SURFACE_WITH_KNOTS" {
                    return Err(Error::UnexpectedEntity {
                        at: self.doc.position_of(k, 0),
                        expected: "a B-spline surface",
                        found: r.name().to_owned(),
                    });
                }
                r.arity(13)?;
                (r.clone().shifted(1), r.shifted(8), None)
            }
            Body::Complex(_) => {
                let b = self.leaf(k, &body, "B_SPLINE_SURFACE")?;
                b.arity(7)?;
                let kn = self.leaf(k, &body, "B_SPLINE_SURFACE_WITH_KNOTS")?;
                kn.arity(5)?;
                let w = match Rec::leaf(self.doc, k, &body, "RATIONAL_B_SPLINE_SURFACE") {
                    Some(w) => {
                        w.arity(1)?;
                        Some(w)
                    }
                    None => None,
                };
                (b, kn, w)
            }
        };
        let p = head.usize_at(0)?;
        let q = head.usize_at(1)?;
        let rows = head.list(2)?;
        let n_u = rows.len();
        let n_v = rows.first().and_then(Param::as_list).map_or(0, <[Param<'_>]>::len);
        let mut ids = Vec::with_capacity(n_u * n_v);
        for row in rows {
            let row = row.as_list().ok_or_else(|| head.err_at(row, 2, "a list of rows of point references"))?;
            if row.len() != n_v {
                return Err(head.err(2, "rows of equal length"));
            }
            for p in row {
                ids.push(p.as_ref_id().ok_or_else(|| head.err_at(p, 2, "a point reference"))?);
            }
        }
        let weights = match weights {
            Some(w) => {
                let rows = w.list(0)?;
                let mut out = Vec::with_capacity(n_u * n_v);
                if rows.len() != n_u {
                    return Err(w.err(0, "one row of weights per row of control points"));
                }
                for row in rows {
                    let row = row.as_list().ok_or_else(|| w.err_at(row, 0, "a list of rows of weights"))?;
                    if row.len() != n_v {
                        return Err(w.err(0, "rows of weights as long as the rows of control points"));
                    }
                    for x in row {
                        out.push(x.as_f64().ok_or_else(|| w.err_at(x, 0, "a number"))?);
                    }
                }
                Some(out)
            }
            None => None,
        };
        let uk = knot_vector(&knots_rec, &knots_rec.reals(2)?, &knots_rec.usizes(0)?)?;
        let vk = knot_vector(&knots_rec, &knots_rec.reals(3)?, &knots_rec.usizes(1)?)?;
        let start = head.rec().start;
        Ok((BSplineNet { start, degrees: (p, q), knots: (uk, vk), counts: (n_u, n_v), ids, weights }, head))
    }
}

/// What [`SurfaceCache`](super::SurfaceCache) keeps of a surface.
#[derive(Debug)]
pub(crate) enum CachedSurface {
    /// Any surface but a B-spline one, converted.
    Geom(SurfaceGeom),
    /// A B-spline surface's record, checked, up to its control points.
    Net(BSplineNet),
}

/// A B-spline surface's record read up to its control points.
#[derive(Debug, Clone)]
pub(crate) struct BSplineNet {
    /// Offset of the record (or leaf) holding the degrees, for errors.
    start: usize,
    degrees: (usize, usize),
    knots: (KnotVector, KnotVector),
    counts: (usize, usize),
    /// The control points' references, row by row (u index slowest).
    ids: Vec<EntityId>,
    weights: Option<Vec<f64>>,
}

fn knot_vector(r: &Rec<'_>, values: &[f64], mults: &[usize]) -> Result<KnotVector> {
    if values.len() != mults.len() {
        return Err(r.err(0, "as many multiplicities as knots"));
    }
    // Bound the expanded length by the input (a multiplicity cannot exceed degree + 1
    // = 26 in any valid file; refuse absurd sums before allocating).
    let total: usize = mults.iter().fold(0usize, |a, &m| a.saturating_add(m));
    if total > 64 * (values.len() + 1) + 1_000_000 {
        return Err(Error::Limit { at: r.position(0), what: "knot multiplicities sum beyond the input size" });
    }
    KnotVector::from_multiplicities(values, mults).map_err(|e| r.geometry(e))
}

pub(crate) use cadmorph_nurbs::analytic::occt_default_x as default_x;

/// Pole nets of at least this many points are read in parallel by [`Ctx::points`]
/// (about a millisecond of reading on one thread; below it, waking threads costs more
/// than it saves).
pub(crate) const PARALLEL_POINTS: usize = 4096;

/// Reads `CARTESIAN_POINT ( '...' , ( x , y , z ) )` directly; `None` when the text has
/// any other shape (then the general parser decides).
fn fast_point(text: &[u8], body: usize) -> Option<Point3<f64>> {
    fast_triple(text, body, b"CARTESIAN_POINT").map(Point3::from)
}

/// Reads `KEYWORD ( '...' , ( x , y , z ) )` (a `CARTESIAN_POINT` or `DIRECTION`)
/// directly; `None` when the text has any other shape.
fn fast_triple(text: &[u8], body: usize, keyword: &[u8]) -> Option<[f64; 3]> {
    use super::flat::{blanks as ws, plain_string_end};
    let t = &text[body..];
    let t = t.strip_prefix(keyword)?;
    let mut i = ws(t, 0);
    if t.get(i)? != &b'(' {
        return None;
    }
    i = ws(t, plain_string_end(t, ws(t, i + 1))?);
    if t.get(i)? != &b',' {
        return None;
    }
    i = ws(t, i + 1);
    if t.get(i)? != &b'(' {
        return None;
    }
    i += 1;
    let mut xyz = [0.0; 3];
    for (n, slot) in xyz.iter_mut().enumerate() {
        i = ws(t, i);
        let start = i;
        while i < t.len() && matches!(t[i], b'0'..=b'9' | b'.' | b'-' | b'+' | b'E' | b'e') {
            i += 1;
        }
        let s = &t[start..i];
        if !s.first()?.is_ascii_digit() && !matches!(s[0], b'-' | b'+') {
            return None;
        }
        // Correctly rounded, as `str::parse`, from the bytes (no UTF-8 check).
        *slot = fast_float2::parse(s).ok()?;
        i = ws(t, i);
        let want = if n == 2 { b')' } else { b',' };
        if t.get(i)? != &want {
            return None;
        }
        i += 1;
    }
    i = ws(t, i);
    (t.get(i)? == &b')').then_some(xyz)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_point_reads_and_declines() {
        assert_eq!(fast_point(b"#1 = CARTESIAN_POINT('',(1.,-2.5E-1, 3));", 5), Some(Point3::new(1.0, -0.25, 3.0)));
        assert_eq!(fast_point(b"#1 = CARTESIAN_POINT('',(1.,2.));", 5), None);
        assert_eq!(fast_point(b"#1 = CARTESIAN_POINT('it''s',(1.,2.,3.));", 5), None);
        assert_eq!(fast_point(b"#1 = CARTESIAN_POINT('',(1.,2.,3./**/));", 5), None);
        assert_eq!(fast_point(b"#1 = DIRECTION('',(1.,2.,3.));", 5), None);
        assert_eq!(fast_triple(b"#1 = DIRECTION('',(1.,2.,3.));", 5, b"DIRECTION"), Some([1.0, 2.0, 3.0]));
        assert_eq!(fast_triple(b"#1 = DIRECTIONS('',(1.,2.,3.));", 5, b"DIRECTION"), None);
        // Every real form of ISO 10303-21 §6.3.2 reads as `str::parse` reads it.
        for x in [
            "1.",
            "+1.",
            "-0.",
            "1.E5",
            "1.E-05",
            "-2.5E-07",
            "3.14159265358979",
            "1.7976931348623157E308",
            "2.2250738585072014E-308",
            "0.1000000000000000055511151231257827",
        ] {
            let text = format!("#1 = CARTESIAN_POINT('',({x},{x},{x}));");
            let want: f64 = x.parse().unwrap();
            let p = fast_point(text.as_bytes(), 5).unwrap();
            assert!(p.iter().all(|c| c.to_bits() == want.to_bits()), "{x}: {p:?}");
        }
    }

    #[test]
    fn default_x_is_perpendicular() {
        for n in [Vector3::z(), Vector3::x(), Vector3::new(1.0, 2.0, 3.0), Vector3::new(-3.0, 0.1, 0.2)] {
            let x = default_x(&n);
            assert!(x.dot(&n).abs() < 1e-15 && x.norm() > 0.0);
        }
        assert_eq!(default_x(&Vector3::z()), Vector3::new(1.0, 0.0, 0.0));
    }
}
