//! Conversion of curves, surfaces and faces to cadmorph-nurbs types in model units.
//!
//! Every conversion but one is exact: analytic curves and surfaces become rational NURBS
//! through `cadmorph_nurbs::analytic`, 104 hyperbola and parabola arcs rational quadratic
//! B-splines (see `conic`: the pole from the end tangents, the weight from the implicit
//! equation), polynomial splines (112, 114) B-splines by a change of basis. The exception
//! is the 140 offset surface of a free-form base, which has no NURBS form: it is
//! approximated by a bicubic B-spline within a stated tolerance ([`offset`],
//! [`Document::offset_surface`]); offsets of planes, cylinders, cones, spheres, tori and
//! revolutions of lines and arcs are exact. Parameterisations follow OpenCASCADE's reading
//! of the same entity, so that OCCT's `(u, v)` map to cadmorph's through the
//! [`ParamMap`]s of the returned [`ExactSurface`]:
//!
//! | entity | u | v |
//! | --- | --- | --- |
//! | 108 plane, 190 | along X of the plane's frame (OCCT `gp_Ax3` rule) | along Y |
//! | 120 revolution | `EA − θ` about the reversed axis (arc map) | generatrix parameter (an arc's angle) |
//! | 122 tabulated cylinder | directrix parameter | length along the generatrix |
//! | 192 / 194 / 196 / 198 | angle (arc map) | axial length / cone length / latitude / angle |
//! | 110 line | length from the start point | |
//! | 100 arc | angle | |
//! | 140 offset | as its base surface | as its base surface |
//! | 104 hyperbola | hyperbolic angle from the start point | |
//! | 104 parabola | distance across the axis from the start point | |
//!
//! OCCT builds a 120 about its axis reversed (from the start point towards the end
//! point's opposite), with the generatrix turned to `2π − EA`, so that its normal is the
//! IGES normal `S_t × S_θ`; cadmorph builds the NURBS the same way, so OCCT's `(u, v)` are
//! cadmorph's through the maps, reflecting 124 matrices included. OCCT makes the face of a 140 over the offset's
//! natural bounds (a 120's full turn, not its angles), and no face at all over a whole 196
//! sphere; it misplaces the vertex of a 104 parabola not of the form `y² = 4fx`.
//!
//! Unbounded surfaces (108, 190–194) are cut to the box of the boundary curves of the face
//! that uses them (144 / 143 / 510), with a 1 % margin, or fail with
//! [`Error::Unsupported`] when nothing bounds them.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use cadmorph_nurbs::analytic::{
    AnalyticCurve, AnalyticSurface, Circle, Cone, Cylinder, ExactSurface, Extrusion, ParamMap, Placement, Revolution,
    Sphere, Torus,
};
use cadmorph_nurbs::{Curve, KnotVector, NurbsCurve, NurbsSurface, Surface};
use nalgebra::{Matrix3, Matrix4, Point3, Vector3};
use std::cell::Cell;

use crate::document::{Document, Entity, EntityId};
use crate::entity::View;
use crate::error::{Error, Result};

mod conic;
pub mod offset;

/// Deepest chain of 124 matrices, or of curves and surfaces nested in one another (a 102
/// of 142s on a 120 whose generatrix is a 142 on ...), followed.
const MAX_DEPTH: usize = 64;
/// Longest chain of surface pointers (140, 143, 144, 510 to their surfaces) converted.
const MAX_SURFACE_CHAIN: usize = 8;
/// Most curve and surface entities visited to convert one curve or surface (composite
/// curves may repeat pieces, and surfaces made of curves on surfaces may share them).
const MAX_CURVE_VISITS: usize = 100_000;
/// The error reason of a conversion nested deeper than [`MAX_DEPTH`].
const NESTED: &str = "curves and surfaces nesting deeper than 64 (or a reference cycle)";
/// The error reason of a conversion that visits more than [`MAX_CURVE_VISITS`] entities.
const TOO_MANY_VISITS: &str = "more than 100000 curve and surface entities visited to convert one entity";

/// Where a conversion is in its recursion: how deeply curves and surfaces are nested
/// (a 142 on a 120 whose generatrix is a 142 on a 118 ...), and how many more entities
/// the whole conversion may visit. One counter for every kind of entity, so that neither
/// a reference cycle through several kinds (which recursed until the stack overflowed:
/// each kind counted its own depth from zero) nor a wide graph of shared pieces runs away.
#[derive(Clone, Copy)]
struct Nest<'a> {
    depth: usize,
    visits: &'a Cell<usize>,
}

impl<'a> Nest<'a> {
    fn new(visits: &'a Cell<usize>) -> Self {
        Nest { depth: 0, visits }
    }

    /// One level deeper, into entity `id`: [`Error::Unsupported`] naming `id` when that is
    /// deeper than [`MAX_DEPTH`] or the conversion has visited [`MAX_CURVE_VISITS`] entities.
    fn enter(self, doc: &Document, id: EntityId) -> Result<Nest<'a>> {
        if self.depth >= MAX_DEPTH {
            return Err(unsupported(doc, id, NESTED));
        }
        let left = self.visits.get().checked_sub(1).ok_or_else(|| unsupported(doc, id, TOO_MANY_VISITS))?;
        self.visits.set(left);
        Ok(Nest { depth: self.depth + 1, visits: self.visits })
    }
}

/// Whether `e` is a nesting or visit limit of [`Nest`] (passed on as it is, not replaced
/// by the error of the entity that contains the nesting).
fn is_limit(e: &Error) -> bool {
    matches!(e, Error::Unsupported { reason, .. } if *reason == NESTED || *reason == TOO_MANY_VISITS)
}
/// Margin added around boundary boxes of unbounded surfaces (fraction of the extent).
const BOX_MARGIN: f64 = 0.01;

/// A face of the model: the entity that makes it (144, 143, 510, or a bare surface), its
/// underlying surface entity, and where 408 subfigure instances place it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceRef {
    /// The face entity (144, 143, 510) or the bare surface.
    pub face: EntityId,
    /// The surface entity under it (equal to `face` for bare surfaces).
    pub surface: EntityId,
    /// Whether the face trims its surface (144 with boundaries, 143, 510).
    pub trimmed: bool,
    /// Which placement of the face entity this is, 0-based in list order: 0 unless 408
    /// singular subfigure instances (IGES 5.3 §4.137) place its 308 definition more
    /// than once.
    pub occurrence: u32,
    /// Model space of the face's 308 definition to model space: the chain of 408
    /// instances that place it (each `M · translate(X, Y, Z) · scale(S)`, `M` the 408's
    /// own 124 matrix), the identity for faces outside subfigures. The face's and its
    /// surface's own 124 matrices come before it.
    pub placement: Matrix4<f64>,
}

/// From this many faces on, [`Document::face_surfaces`] converts them on rayon's threads
/// (as `cadmorph-step` does).
const PARALLEL_FACES: usize = 64;

/// From this many parameter lines of surface records in all (256 KiB of text),
/// [`Document::face_surfaces`] converts the faces on rayon's threads whatever their
/// count.
const PARALLEL_LINES: usize = 4096;

/// Most 408 instances followed in one file (nested instances multiply).
const MAX_INSTANCES: usize = 100_000;

/// What [`Document::surfaces`] reports for one face's surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceInfo {
    /// The face entity.
    pub face: EntityId,
    /// The surface entity.
    pub surface: EntityId,
    /// Surface entity type.
    pub entity_type: u32,
    /// Surface form number.
    pub form: i64,
    /// Whether the face trims the surface.
    pub trimmed: bool,
    /// The exact NURBS form's degrees, pole counts and rationality, or why there is none.
    pub nurbs: std::result::Result<NurbsInfo, Error>,
}

/// What [`Document::offset_surface`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetSurfaceNurbs {
    /// The offset surface with the base's parameter maps.
    pub surface: ExactSurface,
    /// Whether it is exact (analytic base) rather than approximated.
    pub exact: bool,
    /// Largest deviation from the true offset on the check grid (0 when exact).
    pub max_error: f64,
    /// The tolerance of the approximation (0 when exact).
    pub tolerance: f64,
}

#[derive(Debug, Clone, Copy)]
struct FitNumbers {
    max_error: f64,
    tolerance: f64,
}

/// Degrees, pole counts and rationality of a NURBS surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NurbsInfo {
    /// Degree in u.
    pub u_degree: usize,
    /// Degree in v.
    pub v_degree: usize,
    /// Poles in u.
    pub n_u: usize,
    /// Poles in v.
    pub n_v: usize,
    /// Whether weights differ.
    pub rational: bool,
}

impl NurbsInfo {
    /// The numbers of `s`.
    pub fn of(s: &NurbsSurface) -> Self {
        Self { u_degree: s.u_degree(), v_degree: s.v_degree(), n_u: s.n_u(), n_v: s.n_v(), rational: s.is_rational() }
    }
}

fn geometry(de: EntityId) -> impl Fn(cadmorph_nurbs::Error) -> Error {
    move |source| Error::Geometry { de: de.0, source }
}

fn unsupported(doc: &Document, id: EntityId, reason: &'static str) -> Error {
    let (t, f) = doc.entity(id).map_or((0, 0), |e| (e.entity_type(), e.form()));
    Error::Unsupported { de: id.0, entity_type: t, form: f, reason }
}

fn identity(s: NurbsSurface) -> ExactSurface {
    ExactSurface { surface: s, u_map: ParamMap::Identity, v_map: ParamMap::Identity }
}

pub(crate) use cadmorph_nurbs::analytic::occt_default_x as default_x;

/// Joins curves end to start into one (degrees raised to the highest, weights rescaled so
/// the joints match; each joint becomes a knot of multiplicity `degree`, C0). The
/// parameter of each piece is shifted to start where the previous one ended.
pub fn join_curves(curves: &[NurbsCurve]) -> cadmorph_nurbs::Result<NurbsCurve> {
    let p = curves.iter().map(NurbsCurve::degree).max().unwrap_or(1);
    let rational = curves.iter().any(NurbsCurve::is_rational);
    let mut knots: Vec<f64> = Vec::new();
    let mut points: Vec<Point3<f64>> = Vec::new();
    let mut weights: Vec<f64> = Vec::new();
    for c in curves {
        let mut c = c.clamped();
        if c.degree() < p {
            c.elevate_degree(p - c.degree())?;
        }
        let k = c.knots().as_slice();
        let w: Vec<f64> = c.weights().map_or_else(|| vec![1.0; c.control_points().len()], <[f64]>::to_vec);
        if knots.is_empty() {
            knots.extend_from_slice(k);
            points.extend_from_slice(c.control_points());
            weights.extend_from_slice(&w);
            continue;
        }
        let end = *knots.last().expect("knots");
        let shift = end - k[0];
        knots.pop();
        knots.extend(k[p + 1..].iter().map(|x| x + shift));
        let scale = weights.last().copied().unwrap_or(1.0) / w[0];
        points.extend_from_slice(&c.control_points()[1..]);
        weights.extend(w[1..].iter().map(|x| x * scale));
    }
    NurbsCurve::try_new(p, KnotVector::try_new(knots)?, points, rational.then_some(weights))
}

impl Document {
    /// The matrix of an entity's transformation chain (directory field 7, then that
    /// matrix's own field 7, ...): model space = `M · definition space`.
    ///
    /// # Errors
    ///
    /// [`Error::Transform`] for chains that loop or exceed 64 matrices.
    pub fn transform(&self, id: EntityId) -> Result<Matrix4<f64>> {
        let mut m = Matrix4::identity();
        let mut cur = self.entity(id)?.directory().transform;
        let mut depth = 0;
        while cur > 0 {
            depth += 1;
            if depth > MAX_DEPTH {
                return Err(Error::Transform { de: id.0, reason: "transformation chain loops or is deeper than 64" });
            }
            let tid = EntityId(cur as u32);
            let View::TransformationMatrix(t) = self.view(tid)? else {
                return Err(Error::Transform { de: id.0, reason: "transformation pointer to a non-124 entity" });
            };
            m = t.matrix * m;
            cur = self.entity(tid)?.directory().transform;
        }
        Ok(m)
    }

    /// The curve entity `id` as NURBS pieces, with its own transformation applied (model
    /// space for an independent entity; the parent's definition space for a child).
    /// A composite curve (102) gives its pieces; other curves one.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for entities that are not curves, 104 ellipses not in
    /// standard position, and 104 arcs whose numbers do not make the conic of their form
    /// (end points off the conic or on two branches, wrong form for `B² − 4AC`);
    /// [`Error::Geometry`] for invalid data.
    pub fn curve(&self, id: EntityId) -> Result<Vec<NurbsCurve>> {
        let visits = Cell::new(MAX_CURVE_VISITS);
        self.curve_at(id, Nest::new(&visits))
    }

    /// The curve entity `id` joined into one NURBS curve (see [`join_curves`]).
    ///
    /// # Errors
    ///
    /// As [`curve`](Self::curve).
    pub fn curve_joined(&self, id: EntityId) -> Result<NurbsCurve> {
        let visits = Cell::new(MAX_CURVE_VISITS);
        self.curve_joined_at(id, Nest::new(&visits))
    }

    /// [`curve_joined`](Self::curve_joined) inside a conversion.
    fn curve_joined_at(&self, id: EntityId, nest: Nest<'_>) -> Result<NurbsCurve> {
        let pieces = self.curve_at(id, nest)?;
        if pieces.len() == 1 {
            return Ok(pieces.into_iter().next().expect("one"));
        }
        if pieces.is_empty() {
            return Err(unsupported(self, id, "empty composite curve"));
        }
        join_curves(&pieces).map_err(geometry(id))
    }

    fn curve_at(&self, id: EntityId, nest: Nest<'_>) -> Result<Vec<NurbsCurve>> {
        // Composite curves may share (or repeat) pieces: the visits bound the total work.
        let nest = nest.enter(self, id)?;
        let g = geometry(id);
        let m = self.transform(id)?;
        let local: Vec<NurbsCurve> = match self.view(id)? {
            View::Line(l) => {
                let len = (l.end - l.start).norm();
                if !(len > 0.0 && len.is_finite()) {
                    return Err(unsupported(self, id, "line of zero length"));
                }
                let k = KnotVector::try_new(vec![0.0, 0.0, len, len]).map_err(&g)?;
                vec![NurbsCurve::try_new(1, k, vec![l.start, l.end], None).map_err(&g)?]
            }
            View::CircularArc(a) => vec![circular_arc(&a).map_err(&g)?.curve],
            // Hyperbolas and parabolas (and form 0, classified by its coefficients).
            View::ConicArc(c) if c.form != 1 => vec![conic::conic_arc(&c).map_err(|why| match why {
                conic::ConicError::Invalid(reason) => unsupported(self, id, reason),
                conic::ConicError::Geometry(source) => g(source),
            })?],
            View::ConicArc(c) => {
                let [a, b, cc, d, e, f] = c.coefficients;
                if b != 0.0 || d != 0.0 || e != 0.0 || a == 0.0 || cc == 0.0 {
                    return Err(unsupported(self, id, "only ellipses in standard position (form 1) are converted"));
                }
                let (ra, rb) = ((-f / a).sqrt(), (-f / cc).sqrt());
                if !(ra > 0.0 && rb > 0.0) {
                    return Err(unsupported(self, id, "ellipse with non-positive radii"));
                }
                let ang = |p: [f64; 2]| (p[1] / rb).atan2(p[0] / ra);
                let t0 = ang(c.start);
                let mut t1 = ang(c.end);
                while t1 <= t0 + 1e-12 {
                    t1 += TAU;
                }
                let circle = Circle::try_new(Placement::standard(), 1.0).map_err(&g)?;
                let mut unit = circle.to_nurbs(t0..=t1.min(t0 + TAU)).map_err(&g)?.curve;
                let mut s = Matrix4::identity();
                s[(0, 0)] = ra;
                s[(1, 1)] = rb;
                s[(2, 3)] = c.z;
                unit.transform_by(&s);
                vec![unit]
            }
            View::CopiousData(c) => {
                let n = c.points.len();
                if n < 2 {
                    return Err(unsupported(self, id, "copious data with fewer than 2 points"));
                }
                let mut k = vec![0.0];
                k.extend((0..n).map(|i| i as f64));
                k.push((n - 1) as f64);
                vec![NurbsCurve::try_new(1, KnotVector::try_new(k).map_err(&g)?, c.points, None).map_err(&g)?]
            }
            View::ParametricSplineCurve(s) => vec![spline_curve(&s).map_err(&g)?],
            View::BSplineCurve(b) => {
                let k = KnotVector::try_new(b.knots).map_err(&g)?;
                vec![NurbsCurve::try_new(b.degree, k, b.points, b.weights).map_err(&g)?]
            }
            View::CompositeCurve(c) => {
                let mut out = Vec::with_capacity(c.curves.len());
                for child in c.curves {
                    out.extend(self.curve_at(child, nest)?);
                }
                out
            }
            View::CurveOnSurface(c) => match (c.model_curve, c.parameter_curve) {
                (Some(mc), _) => self.curve_at(mc, nest)?,
                (None, Some(pc)) => self.curve_on_surface(id, c.surface, pc, nest)?,
                (None, None) => {
                    return Err(unsupported(
                        self,
                        id,
                        "curve on surface with neither a model-space nor a parameter curve",
                    ))
                }
            },
            _ => return Err(unsupported(self, id, "not a curve entity")),
        };
        Ok(local.into_iter().map(|c| if m == Matrix4::identity() { c } else { c.transformed(&m) }).collect())
    }

    /// The model-space curve of a curve on surface (142) that names only its
    /// parameter-space curve, rebuilt as OCCT's IGES reader does: the surface evaluated
    /// along the parameter curve, `S(p(t))`, here fitted by a cubic B-spline within
    /// `1e-8 ×` the surface's size (nurbs `fit_curve`, with the parameter curve's knots as
    /// breaks). IGES 5.3 §4.11 (entity 142): the parameter curve lives in the surface's
    /// parameter space, mapped to the exact NURBS form's parameters by its `ParamMap`.
    ///
    /// A surface whose extent comes from its face's bounds (an unbounded analytic
    /// surface) cannot be placed without them: that stays unsupported.
    fn curve_on_surface(
        &self,
        id: EntityId,
        surface: EntityId,
        parameter_curve: EntityId,
        nest: Nest<'_>,
    ) -> Result<Vec<NurbsCurve>> {
        let s = self.child_surface(surface, &[], nest).map_err(|e| {
            if is_limit(&e) {
                e
            } else {
                unsupported(self, id, "curve on surface without a model-space curve, on a surface placed by its bounds")
            }
        })?;
        let size = s.surface.control_extent();
        let (ud, vd) = s.surface.domain();
        let to_occt = self.parameter_space_map(surface)?;
        let mut out = Vec::new();
        for p in self.curve_at(parameter_curve, nest)? {
            let d = p.domain();
            let f = |t: f64| {
                let q = cadmorph_nurbs::Curve::eval(&p, t);
                let (a, b) = match to_occt {
                    Some((ea, scale)) => (ea - q.y, q.x * scale),
                    None => (q.x, q.y),
                };
                let (u, v) = s.nurbs_params(a, b);
                let (u, v) = (u.clamp(*ud.start(), *ud.end()), v.clamp(*vd.start(), *vd.end()));
                cadmorph_nurbs::Surface::eval(&s.surface, u, v)
            };
            let breaks = p.knots().as_slice().to_vec();
            let (c, _) =
                cadmorph_nurbs::fit_curve(f, (*d.start(), *d.end()), &breaks, 3, 1e-8 * size.max(1e-300), 4096)
                    .map_err(geometry(id))?;
            out.push(c);
        }
        Ok(out)
    }

    /// IGES parameter space of `surface` → the `(u, v)` of its [`ExactSurface`] maps
    /// (OCCT's parameters). The identity but for a 120, which IGES parameterises as
    /// (generatrix `t`, angle `θ`) (§4.18): `u = EA − θ` (see [`occt_revolution`]) and `v`
    /// the generatrix parameter, a line's `t ∈ [0, 1]` scaled to its length (§4.13).
    /// `Some((EA, scale))` for a 120, `None` for the identity.
    fn parameter_space_map(&self, surface: EntityId) -> Result<Option<(f64, f64)>> {
        if let View::SurfaceOfRevolution(r) = self.view(surface)? {
            let scale = match self.view(r.generatrix)? {
                View::Line(l) => (l.end - l.start).norm(),
                _ => 1.0,
            };
            return Ok(Some((r.end_angle, scale)));
        }
        Ok(None)
    }

    /// A point entity (116) with its own transformation applied.
    fn point_of(&self, id: EntityId) -> Result<Point3<f64>> {
        match self.view(id)? {
            View::Point(p) => Ok(self.transform(id)?.transform_point(&p.point)),
            _ => Err(unsupported(self, id, "expected a point (116)")),
        }
    }

    /// A direction entity (123) with its own transformation's linear part applied.
    fn direction_of(&self, id: EntityId) -> Result<Vector3<f64>> {
        match self.view(id)? {
            View::Direction(d) => Ok(self.transform(id)?.transform_vector(&d.vector)),
            _ => Err(unsupported(self, id, "expected a direction (123)")),
        }
    }

    /// Surface `id`'s transformation, and the boundary points of the face that bounds it
    /// (if one does) in the surface's own coordinates: where an unbounded surface's
    /// extent comes from.
    fn placement_and_hint(&self, id: EntityId) -> Result<(Matrix4<f64>, Vec<Point3<f64>>)> {
        let face = self.faces().into_iter().find(|f| f.surface == id && f.face != id);
        let hint = match face {
            Some(f) => self.boundary_points(f.face)?,
            None => Vec::new(),
        };
        let m = self.transform(id)?;
        let inv = m.try_inverse().ok_or(Error::Transform { de: id.0, reason: "singular transformation matrix" })?;
        Ok((m, hint.iter().map(|p| inv.transform_point(p)).collect()))
    }

    /// The surface entity `id` as an exact NURBS with its own transformation applied,
    /// with the maps from the entity's (OCCT's) parameters to the NURBS ones.
    ///
    /// Unbounded surfaces take their extent from the face that uses them (the first
    /// 144/143/510 pointing to `id`).
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for entities that are not surfaces, unbounded surfaces no face
    /// bounds, and offset surfaces [`offset_surface`](Self::offset_surface) refuses;
    /// [`Error::Geometry`] for invalid data.
    pub fn surface(&self, id: EntityId) -> Result<ExactSurface> {
        self.surface_chain(id)?;
        let (m, local_hint) = self.placement_and_hint(id)?;
        let visits = Cell::new(MAX_CURVE_VISITS);
        let mut s = self.surface_local(id, &local_hint, Nest::new(&visits))?;
        if m != Matrix4::identity() {
            s.surface.transform_by(&m);
        }
        Ok(s)
    }

    /// Refuses chains of surface pointers (140, 143, 144, 510 to their surfaces) that loop
    /// or are longer than [`MAX_SURFACE_CHAIN`], walking them without recursion: converting
    /// them recurses once per link, and a long chain would exhaust the stack before
    /// [`MAX_DEPTH`] stops it.
    fn surface_chain(&self, id: EntityId) -> Result<()> {
        let mut cur = id;
        for _ in 0..=MAX_SURFACE_CHAIN {
            // Only these types link on; any other surface (a B-spline surface of many
            // thousands of poles) ends the chain without being read.
            if !matches!(self.entity(cur).map(Entity::entity_type), Ok(140 | 143 | 144 | 510)) {
                return Ok(());
            }
            let next = match self.view(cur) {
                Ok(View::OffsetSurface(x)) => x.surface,
                Ok(View::TrimmedSurface(x)) => x.surface,
                Ok(View::BoundedSurface(x)) => x.surface,
                Ok(View::Face(x)) => x.surface,
                _ => return Ok(()),
            };
            if next == id {
                break;
            }
            cur = next;
        }
        Err(unsupported(self, id, "chain of surface entities (140, 143, 144, 510) loops or is longer than 8"))
    }

    /// The surface in its definition space (own transformation not applied).
    fn surface_local(&self, id: EntityId, hint: &[Point3<f64>], nest: Nest<'_>) -> Result<ExactSurface> {
        let nest = nest.enter(self, id)?;
        let g = geometry(id);
        Ok(match self.view(id)? {
            View::BSplineSurface(b) => {
                let uk = KnotVector::try_new(b.u_knots).map_err(&g)?;
                let vk = KnotVector::try_new(b.v_knots).map_err(&g)?;
                identity(
                    NurbsSurface::try_new((b.u_degree, b.v_degree), (uk, vk), (b.n_u, b.n_v), b.points, b.weights)
                        .map_err(&g)?,
                )
            }
            View::Plane(p) => {
                let [a, b, c, d] = p.coefficients;
                let n = Vector3::new(a, b, c);
                let (aa, ba, ca) = (a.abs(), b.abs(), c.abs());
                // OCCT gp_Pln(A, B, C, −D): origin on the axis of the largest coefficient.
                let origin = if ba <= aa && ba <= ca {
                    if aa > ca {
                        Point3::new(d / a, 0.0, 0.0)
                    } else {
                        Point3::new(0.0, 0.0, d / c)
                    }
                } else if aa <= ba && aa <= ca {
                    if ba > ca {
                        Point3::new(0.0, d / b, 0.0)
                    } else {
                        Point3::new(0.0, 0.0, d / c)
                    }
                } else if aa > ba {
                    Point3::new(d / a, 0.0, 0.0)
                } else {
                    Point3::new(0.0, d / b, 0.0)
                };
                let frame = Placement::try_new(origin, n, default_x(&n)).map_err(&g)?;
                let mut pts = hint.to_vec();
                if pts.is_empty() {
                    if let Some(bc) = p.boundary {
                        pts = self.curve_at(bc, nest)?.iter().flat_map(|c| c.control_points().to_vec()).collect();
                    } else if p.symbol_size > 0.0 {
                        let (sx, sy) = (frame.x_dir() * p.symbol_size, frame.y_dir() * p.symbol_size);
                        pts = vec![p.symbol - sx - sy, p.symbol + sx + sy];
                    }
                }
                plane_patch(self, id, &frame, &pts)?
            }
            View::PlaneSurface(p) => {
                let o = self.point_of(p.location)?;
                let n = self.direction_of(p.normal)?;
                let x = match p.reference {
                    Some(r) => self.direction_of(r)?,
                    None => default_x(&n),
                };
                let frame = Placement::try_new(o, n, x).map_err(&g)?;
                plane_patch(self, id, &frame, hint)?
            }
            View::CylindricalSurface(cy) => {
                let frame = self.frame(p_or(cy.location), cy.axis, cy.reference, &g)?;
                let cyl = Cylinder::try_new(frame, cy.radius).map_err(&g)?;
                let (v0, v1) = axial_range(self, id, &frame, hint, 1.0)?;
                cyl.to_nurbs(0.0..=TAU, v0..=v1).map_err(&g)?
            }
            View::ConicalSurface(co) => {
                let frame = self.frame(p_or(co.location), co.axis, co.reference, &g)?;
                let a = co.semi_angle_degrees.to_radians();
                let cone = Cone::try_new(frame, co.radius, a).map_err(&g)?;
                let (v0, v1) = axial_range(self, id, &frame, hint, a.cos())?;
                cone.to_nurbs(0.0..=TAU, v0..=v1).map_err(&g)?
            }
            View::SphericalSurface(sp) => {
                let o = self.point_of(sp.center)?;
                let frame = match sp.axis {
                    Some(ax) => self.frame(o.into(), ax, sp.reference, &g)?,
                    None => Placement::try_new(o, Vector3::z(), Vector3::x()).map_err(&g)?,
                };
                let s = Sphere::try_new(frame, sp.radius).map_err(&g)?;
                s.to_nurbs(0.0..=TAU, -FRAC_PI_2..=FRAC_PI_2).map_err(&g)?
            }
            View::ToroidalSurface(t) => {
                let frame = self.frame(p_or(t.center), t.axis, t.reference, &g)?;
                let s = Torus::try_new(frame, t.major_radius, t.minor_radius).map_err(&g)?;
                s.to_nurbs(0.0..=TAU, -PI..=PI).map_err(&g)?
            }
            View::SurfaceOfRevolution(r) => {
                let Some((a0, a1)) = self.axis_ends(&r, nest)? else {
                    return Err(unsupported(self, id, "axis of revolution is not a line"));
                };
                let gen = self.curve_joined_at(r.generatrix, nest)?;
                occt_revolution(gen, a0, a1, &r, self.generatrix_map(r.generatrix)?).map_err(&g)?
            }
            View::TabulatedCylinder(t) => {
                let dir = self.curve_joined_at(t.directrix, nest)?;
                let dom = dir.domain();
                let start = dir.eval(*dom.start());
                let d = t.end - start;
                let len = d.norm();
                let ext = Extrusion::try_new(dir, d).map_err(&g)?;
                ext.to_nurbs(dom, 0.0..=len).map_err(&g)?
            }
            View::RuledSurface(r) => identity(self.ruled(&r, &g, nest)?),
            View::ParametricSplineSurface(s) => identity(spline_surface(&s).map_err(&g)?),
            View::TrimmedSurface(t) => self.child_surface(t.surface, hint, nest)?,
            View::BoundedSurface(b) => self.child_surface(b.surface, hint, nest)?,
            View::Face(f) => self.child_surface(f.surface, hint, nest)?,
            View::OffsetSurface(o) => self.offset_local(id, &o, hint, nest, None)?.0,
            _ => return Err(unsupported(self, id, "not a surface entity")),
        })
    }

    /// The 140 offset surface `id` in model space (its transformation applied, extent from
    /// the face that uses it as for [`surface`](Self::surface)), with how close it is.
    ///
    /// Offsets of planes (108, 190), cylinders (192), cones (194, when the face does not
    /// reach the apex), spheres (196), tori (198) and 120 revolutions of a line or circular
    /// arc lying in a plane through the axis on one side of it, under a rigid 124, are
    /// exact: the same kind of surface with its radius or origin moved, in the same
    /// parameterisation (`max_error` 0). Any other base is
    /// approximated by [`offset::approximate_offset`] within `tolerance` (default
    /// [`offset::DEFAULT_RELATIVE_TOLERANCE`] × the base's size), in the base's
    /// parameterisation: `(u, v)` maps to the NURBS as for the base surface, like OCCT's
    /// `Geom_OffsetSurface`. The offset is `S + D·N` (IGES 5.3 §4.20) with `N` the unit
    /// normal `S_u × S_v / |S_u × S_v|` of the base in its IGES parameterisation: the
    /// normal of the converted NURBS, except for a 120, which IGES parameterises as
    /// (generatrix, angle), the other way round from OCCT's and cadmorph's (angle,
    /// generatrix), so the side is the opposite of the NURBS normal there. OCCT agrees on
    /// every base tried (it reverses the axis of the 120); it does not for a 120 under a
    /// reflecting 124 (see the module notes). Like OCCT, the offset indicator
    /// `(NX, NY, NZ)` is not used to choose the side.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] when `id` is not a 140, its base has no normal somewhere
    /// (`offset::OffsetError::DegenerateNormal`), an exact offset passes through the axis or
    /// centre (radius + D ≤ 0), or the approximation does not reach the tolerance; those of
    /// [`surface`](Self::surface) for the base.
    pub fn offset_surface(&self, id: EntityId, tolerance: Option<f64>) -> Result<OffsetSurfaceNurbs> {
        let View::OffsetSurface(o) = self.view(id)? else {
            return Err(unsupported(self, id, "not an offset surface (140)"));
        };
        let (m, local_hint) = self.placement_and_hint(id)?;
        let visits = Cell::new(MAX_CURVE_VISITS);
        let (mut s, fit) = self.offset_local(id, &o, &local_hint, Nest::new(&visits), tolerance)?;
        if m != Matrix4::identity() {
            s.surface.transform_by(&m);
        }
        let (max_error, tolerance) = fit.map_or((0.0, 0.0), |f| (f.max_error, f.tolerance));
        Ok(OffsetSurfaceNurbs { surface: s, exact: fit.is_none(), max_error, tolerance })
    }

    /// The 140 in its definition space, and the fit's numbers when approximated.
    fn offset_local(
        &self,
        id: EntityId,
        o: &crate::entity::OffsetSurface,
        hint: &[Point3<f64>],
        nest: Nest<'_>,
        tolerance: Option<f64>,
    ) -> Result<(ExactSurface, Option<FitNumbers>)> {
        let base = o.surface;
        self.surface_chain(id)?;
        // A 120 is built about the reversed axis as OCCT builds it, so S_u × S_v is the
        // IGES normal S_t × S_θ (§4.18) for it too.
        let d = o.distance;
        if !d.is_finite() {
            return Err(unsupported(self, id, "offset surface with a non-finite distance"));
        }
        let mb = self.transform(base)?;
        let lin: Matrix3<f64> = mb.fixed_view::<3, 3>(0, 0).into_owned();
        let rigid = (lin.transpose() * lin - Matrix3::identity()).abs().max() <= 1e-12;
        if rigid {
            let inv =
                mb.try_inverse().ok_or(Error::Transform { de: base.0, reason: "singular transformation matrix" })?;
            let local: Vec<Point3<f64>> = hint.iter().map(|p| inv.transform_point(p)).collect();
            // A reflection turns the normal: offset the untransformed base the other way.
            let dl = if lin.determinant() < 0.0 { -d } else { d };
            if let Some(mut s) = self.exact_offset(id, base, dl, &local, nest)? {
                if mb != Matrix4::identity() {
                    s.surface.transform_by(&mb);
                }
                return Ok((s, None));
            }
        }
        let b = self.child_surface(base, hint, nest)?;
        // (A base of size 0 has no normal: that error, not a bad tolerance.)
        let tol =
            tolerance.unwrap_or((offset::DEFAULT_RELATIVE_TOLERANCE * offset::size(&b.surface)).max(f64::MIN_POSITIVE));
        let fit = offset::approximate_offset(&b.surface, d, tol).map_err(|e| match e {
            offset::OffsetError::DegenerateNormal { .. } => unsupported(
                self,
                id,
                "offset surface: the base surface has no normal at some point (a pole or collapsed edge with no limit normal)",
            ),
            offset::OffsetError::NotConverged { .. } => unsupported(
                self,
                id,
                "offset surface: the B-spline approximation did not reach its tolerance (the offset folds, or is too detailed)",
            ),
            offset::OffsetError::BadInput => unsupported(self, id, "offset surface: non-finite distance or bad tolerance"),
            offset::OffsetError::Geometry(source) => Error::Geometry { de: id.0, source },
        })?;
        let numbers = FitNumbers { max_error: fit.max_error, tolerance: fit.tolerance };
        Ok((ExactSurface { surface: fit.surface, u_map: b.u_map, v_map: b.v_map }, Some(numbers)))
    }

    /// The exact offset by `d` of an analytic base in the base's definition space, or
    /// `None` when the base is not one with an exact offset.
    fn exact_offset(
        &self,
        id: EntityId,
        base: EntityId,
        d: f64,
        hint: &[Point3<f64>],
        nest: Nest<'_>,
    ) -> Result<Option<ExactSurface>> {
        let g = geometry(id);
        let through = || unsupported(self, id, "offset surface: the distance takes the radius to zero or below");
        Ok(Some(match self.view(base)? {
            View::Plane(_) | View::PlaneSurface(_) => {
                let mut s = self.surface_local(base, hint, nest)?;
                let (ud, vd) = s.surface.domain();
                let n = s
                    .surface
                    .normal((ud.start() + ud.end()) / 2.0, (vd.start() + vd.end()) / 2.0)
                    .ok_or_else(|| unsupported(self, id, "offset surface: the base plane has no normal"))?;
                for p in s.surface.control_points_mut() {
                    *p += n.into_inner() * d;
                }
                s
            }
            View::CylindricalSurface(cy) => {
                let frame = self.frame(p_or(cy.location), cy.axis, cy.reference, &g)?;
                let r = cy.radius + d;
                if !(r > 0.0 && r.is_finite()) {
                    return Err(through());
                }
                let cyl = Cylinder::try_new(frame, r).map_err(&g)?;
                let (v0, v1) = axial_range(self, id, &frame, hint, 1.0)?;
                cyl.to_nurbs(0.0..=TAU, v0..=v1).map_err(&g)?
            }
            View::ConicalSurface(co) => {
                // S + d N with N = cos a·X_r − sin a·Z (where R + v sin a > 0): the cone with
                // the same angle, radius R + d cos a, origin moved by −d sin a along the axis.
                let frame = self.frame(p_or(co.location), co.axis, co.reference, &g)?;
                let a = co.semi_angle_degrees.to_radians();
                let r = co.radius + d * a.cos();
                let o = frame.origin() - frame.z_dir() * (d * a.sin());
                let moved = Placement::try_new(o, frame.z_dir(), frame.x_dir()).map_err(&g)?;
                let (v0, v1) = axial_range(self, id, &moved, hint, a.cos())?;
                // The base must stay on one side of its apex for the offset to be a cone.
                let rho = |v: f64| r + v * a.sin();
                if !(r >= 0.0 && rho(v0) > d * a.cos() && rho(v1) > d * a.cos()) {
                    return Ok(None);
                }
                let cone = Cone::try_new(moved, r, a).map_err(&g)?;
                cone.to_nurbs(0.0..=TAU, v0..=v1).map_err(&g)?
            }
            View::SphericalSurface(sp) => {
                let o = self.point_of(sp.center)?;
                let frame = match sp.axis {
                    Some(ax) => self.frame(o.into(), ax, sp.reference, &g)?,
                    None => Placement::try_new(o, Vector3::z(), Vector3::x()).map_err(&g)?,
                };
                let r = sp.radius + d;
                if !(r > 0.0 && r.is_finite()) {
                    return Err(through());
                }
                let s = Sphere::try_new(frame, r).map_err(&g)?;
                s.to_nurbs(0.0..=TAU, -FRAC_PI_2..=FRAC_PI_2).map_err(&g)?
            }
            View::ToroidalSurface(t) => {
                let frame = self.frame(p_or(t.center), t.axis, t.reference, &g)?;
                let r = t.minor_radius + d;
                if !(r > 0.0 && r.is_finite()) {
                    return Err(through());
                }
                let s = Torus::try_new(frame, t.major_radius, r).map_err(&g)?;
                s.to_nurbs(0.0..=TAU, -PI..=PI).map_err(&g)?
            }
            View::SurfaceOfRevolution(r) => {
                let Some(gen) = self.revolution_offset_generatrix(id, &r, d, nest)? else {
                    return Ok(None);
                };
                let Some((a0, a1)) = self.axis_ends(&r, nest)? else {
                    return Ok(None);
                };
                occt_revolution(gen, a0, a1, &r, self.generatrix_map(r.generatrix)?).map_err(&g)?
            }
            _ => return Ok(None),
        }))
    }

    /// How a 120's generatrix's analytic parameter (OCCT's `v`) maps to its NURBS
    /// parameter: the angle of a 100 arc, the identity for the other curves (whose NURBS
    /// parameter is already OCCT's).
    fn generatrix_map(&self, id: EntityId) -> Result<ParamMap> {
        Ok(match self.view(id)? {
            View::CircularArc(a) => circular_arc(&a).map_err(geometry(id))?.map,
            _ => ParamMap::Identity,
        })
    }

    /// The start and end points of a 120's axis line, in the 120's definition space.
    fn axis_ends(
        &self,
        r: &crate::entity::SurfaceOfRevolution,
        nest: Nest<'_>,
    ) -> Result<Option<(Point3<f64>, Point3<f64>)>> {
        let axis = self.curve_at(r.axis, nest)?;
        Ok(match (axis.first().map(|c| c.control_points()[0]), axis.last().and_then(|c| c.control_points().last())) {
            (Some(a0), Some(&a1)) => Some((a0, a1)),
            _ => None,
        })
    }

    /// For a 120 whose generatrix is a line (110) or circular arc (100) in a plane through
    /// the axis, on one side of it: the generatrix of the offset surface (the line moved by
    /// `d` along its normal in that plane, the arc with its radius changed by `±d`), in the
    /// same parameterisation. `None` for other generatrices.
    fn revolution_offset_generatrix(
        &self,
        id: EntityId,
        r: &crate::entity::SurfaceOfRevolution,
        d: f64,
        nest: Nest<'_>,
    ) -> Result<Option<NurbsCurve>> {
        let arc_center = match self.view(r.generatrix)? {
            View::Line(_) => None,
            View::CircularArc(a) => {
                let m = self.transform(r.generatrix)?;
                Some(m.transform_point(&Point3::new(a.center[0], a.center[1], a.z)))
            }
            _ => return Ok(None),
        };
        let Some((a0, a1)) = self.axis_ends(r, nest)? else {
            return Ok(None);
        };
        // OCCT's axis (the IGES axis reversed), so that S_u × S_v is the IGES normal.
        let k = a0 - a1;
        if !(k.norm() > 0.0 && k.norm().is_finite()) {
            return Ok(None);
        }
        let k = k.normalize();
        let mut gen = self.curve_joined_at(r.generatrix, nest)?;
        let dom = gen.domain();
        let (t0, t1) = (*dom.start(), *dom.end());
        let samples: Vec<Point3<f64>> = (0..=32).map(|i| gen.eval(t0 + (t1 - t0) * f64::from(i) / 32.0)).collect();
        let radial = |p: &Point3<f64>| {
            let q = p - a0;
            q - k * q.dot(&k)
        };
        // The meridian plane: through the axis and the sample farthest from it.
        let far = samples.iter().map(radial).fold(Vector3::zeros(), |a, b| if b.norm() > a.norm() { b } else { a });
        let size = samples.iter().map(|p| (p - a0).norm()).fold(0.0, f64::max);
        if !(far.norm() > 1e-9 * size && size.is_finite()) {
            return Ok(None);
        }
        let rhat = far.normalize();
        let m = k.cross(&rhat);
        let planar = gen.control_points().iter().all(|p| (p - a0).dot(&m).abs() <= 1e-12 * size);
        let one_side = samples.iter().all(|p| radial(p).dot(&rhat) > 1e-9 * size);
        if !(planar && one_side) {
            return Ok(None);
        }
        // The surface normal at angle 0: (k × (C − a0)) × C', the IGES normal S_t × S_θ.
        let tm = (t0 + t1) / 2.0;
        let dv = gen.derivs(tm, 1);
        let c = Point3::from(dv[0]);
        let n = k.cross(&(c - a0)).cross(&dv[1]);
        if !(n.norm() > 0.0 && n.norm().is_finite()) {
            return Ok(None);
        }
        let n = n.normalize();
        match arc_center {
            None => {
                for p in gen.control_points_mut() {
                    *p += n * d;
                }
            }
            Some(center) => {
                let radius = (c - center).norm();
                if samples.iter().any(|p| ((p - center).norm() - radius).abs() > 1e-12 * size) {
                    return Ok(None);
                }
                // Outward (away from the centre) or inward normal.
                let s = if n.dot(&(c - center)) >= 0.0 { 1.0 } else { -1.0 };
                let new = radius + s * d;
                if !(new > 0.0 && new.is_finite()) {
                    return Err(unsupported(
                        self,
                        id,
                        "offset surface: the distance takes the radius to zero or below",
                    ));
                }
                let f = new / radius;
                for p in gen.control_points_mut() {
                    *p = center + (*p - center) * f;
                }
            }
        }
        Ok(Some(gen))
    }

    /// A child surface mapped into the parent's definition space.
    fn child_surface(&self, id: EntityId, hint: &[Point3<f64>], nest: Nest<'_>) -> Result<ExactSurface> {
        let m = self.transform(id)?;
        let inv = m.try_inverse().ok_or(Error::Transform { de: id.0, reason: "singular transformation matrix" })?;
        let local: Vec<Point3<f64>> = hint.iter().map(|p| inv.transform_point(p)).collect();
        let mut s = self.surface_local(id, &local, nest)?;
        if m != Matrix4::identity() {
            s.surface.transform_by(&m);
        }
        Ok(s)
    }

    fn frame(
        &self,
        origin: PointSource,
        axis: EntityId,
        reference: Option<EntityId>,
        g: &impl Fn(cadmorph_nurbs::Error) -> Error,
    ) -> Result<Placement> {
        let o = match origin {
            PointSource::Entity(id) => self.point_of(id)?,
            PointSource::Point(p) => p,
        };
        let z = self.direction_of(axis)?;
        let x = match reference {
            Some(r) => self.direction_of(r)?,
            None => default_x(&z),
        };
        Placement::try_new(o, z, x).map_err(g)
    }

    fn ruled(
        &self,
        r: &crate::entity::RuledSurface,
        g: &impl Fn(cadmorph_nurbs::Error) -> Error,
        nest: Nest<'_>,
    ) -> Result<NurbsSurface> {
        let norm = |c: NurbsCurve| -> cadmorph_nurbs::Result<NurbsCurve> {
            let c = c.clamped();
            let d = c.domain();
            let (a, b) = (*d.start(), *d.end());
            let k: Vec<f64> = c.knots().as_slice().iter().map(|x| (x - a) / (b - a)).collect();
            NurbsCurve::try_new(
                c.degree(),
                KnotVector::try_new(k)?,
                c.control_points().to_vec(),
                c.weights().map(<[f64]>::to_vec),
            )
        };
        let mut c1 = norm(self.curve_joined_at(r.curve1, nest)?).map_err(g)?;
        let mut c2 = norm(self.curve_joined_at(r.curve2, nest)?).map_err(g)?;
        if r.reversed {
            c2 = norm(c2.reversed()).map_err(g)?;
        }
        let p = c1.degree().max(c2.degree());
        if c1.degree() < p {
            c1.elevate_degree(p - c1.degree()).map_err(g)?;
        }
        if c2.degree() < p {
            c2.elevate_degree(p - c2.degree()).map_err(g)?;
        }
        let missing = |a: &NurbsCurve, b: &NurbsCurve| -> Vec<f64> {
            let mut out = Vec::new();
            let (va, ma) = a.knots().distinct();
            let (vb, mb) = b.knots().distinct();
            for (k, m) in vb.iter().zip(&mb) {
                let have = va.iter().zip(&ma).find(|(x, _)| (*x - k).abs() < 1e-12).map_or(0, |(_, m)| *m);
                out.extend(std::iter::repeat_n(*k, m.saturating_sub(have)));
            }
            out
        };
        let (add1, add2) = (missing(&c1, &c2), missing(&c2, &c1));
        if !add1.is_empty() {
            c1.refine(&add1).map_err(g)?;
        }
        if !add2.is_empty() {
            c2.refine(&add2).map_err(g)?;
        }
        let n = c1.control_points().len();
        let rational = c1.is_rational() || c2.is_rational();
        let w = |c: &NurbsCurve, i: usize| c.weights().map_or(1.0, |w| w[i]);
        let mut points = Vec::with_capacity(2 * n);
        let mut weights = Vec::with_capacity(2 * n);
        for i in 0..n {
            points.push(c1.control_points()[i]);
            points.push(c2.control_points()[i]);
            weights.push(w(&c1, i));
            weights.push(w(&c2, i));
        }
        let vk = KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).map_err(g)?;
        NurbsSurface::try_new((p, 1), (c1.knots().clone(), vk), (n, 2), points, rational.then_some(weights)).map_err(g)
    }

    /// Every face of the model in entity order: each 144, 143 and 510, and each
    /// independent surface entity no face uses; faces inside 308 subfigure definitions
    /// once per 408 instance that places them (see [`try_faces`](Self::try_faces)).
    /// Instances that cannot be read are left out (`try_faces` names them); groups
    /// nested past the limit (a 402 that contains itself) leave no face at all.
    pub fn faces(&self) -> Vec<FaceRef> {
        self.faces_impl(false, false).map(|f| f.0).unwrap_or_default()
    }

    /// Every face of the model, as OCCT 7.9's `IGESControl_Reader` lists them: each 144,
    /// 143 and 510 and each independent surface entity no face uses, in entity order;
    /// but the faces inside a 308 subfigure definition (IGES 5.3 §4.74: its entities,
    /// 402 groups, 186 solids and 514 shells among them, and nested 408s) are not listed
    /// on their own. They come once per 408 singular subfigure instance (§4.137) that
    /// places the definition, at the instance's place in entity order, with the
    /// instance's placement and a distinct [`FaceRef::occurrence`]: nested instances
    /// multiply. A 308 that no 408 instances is read once, unplaced, as OCCT does (it
    /// is a root of the file's reference graph), and a 308 listed inside another 308 as
    /// part of it.
    ///
    /// # Errors
    ///
    /// [`Error::Subfigure`] naming the 408 or 308: a 408 whose definition is not a 308,
    /// a 308 that contains itself (directly or through instances), nesting deeper than
    /// 64, more than 100000 instances followed; [`Error::Transform`] for a 408's bad
    /// matrix chain; the read errors of the 308s and 408s.
    pub fn try_faces(&self) -> Result<Vec<FaceRef>> {
        self.faces_impl(true, false).map(|f| f.0)
    }

    /// [`try_faces`](Self::try_faces), each face with the 408 instances that place it,
    /// outermost first (none for a face outside subfigures).
    pub(crate) fn faces_with_instances(&self) -> Result<Vec<(FaceRef, Vec<EntityId>)>> {
        let (faces, chains) = self.faces_impl(true, true)?;
        Ok(faces.into_iter().zip(chains).collect())
    }

    /// The faces, and with `chains` the 408 instances placing each (else none).
    fn faces_impl(&self, strict: bool, chains: bool) -> Result<(Vec<FaceRef>, Vec<Vec<EntityId>>)> {
        let mut used = vec![false; self.entities.len()];
        let mut plain = Vec::new();
        for e in &self.entities {
            if let Some(f) = self.face_of(e.id()) {
                if f.face != f.surface {
                    used[f.surface.index()] = true;
                }
                if matches!(e.entity_type(), 143 | 144 | 510) {
                    plain.push(f);
                }
            }
        }
        for e in &self.entities {
            let is_surface = matches!(e.entity_type(), 108 | 114 | 118 | 120 | 122 | 128 | 140 | 190..=198);
            if is_surface && !used[e.id().index()] && e.directory().status.subordinate == 0 {
                plain.push(FaceRef {
                    face: e.id(),
                    surface: e.id(),
                    trimmed: false,
                    occurrence: 0,
                    placement: Matrix4::identity(),
                });
            }
        }
        // Subfigures: what each 308 holds, which 308s are instanced, which 408s are inside one.
        let mut inside: std::collections::HashSet<EntityId> = std::collections::HashSet::new();
        let mut instanced: std::collections::HashSet<EntityId> = std::collections::HashSet::new();
        let mut roots: Vec<EntityId> = Vec::new();
        let mut walk = Subfigures {
            budget: MAX_INSTANCES,
            depth: 0,
            strict,
            instances: Vec::new(),
            chains: chains.then(Vec::new),
        };
        for e in self.entities.iter().filter(|e| matches!(e.entity_type(), 308 | 408)) {
            match self.view(e.id()) {
                Ok(View::SubfigureDefinition(d)) => {
                    let mut content = Vec::new();
                    walk.content(self, &d.entities, &mut vec![e.id()], &mut content, &mut inside)?;
                }
                Ok(View::SubfigureInstance(i)) => {
                    instanced.insert(i.definition);
                }
                Ok(_) => {}
                Err(err) if strict => return Err(err),
                Err(_) => {}
            }
        }
        for e in self.entities.iter().filter(|e| matches!(e.entity_type(), 308 | 408)) {
            let root = match e.entity_type() {
                408 => !inside.contains(&e.id()),
                _ => !instanced.contains(&e.id()) && !inside.contains(&e.id()),
            };
            if root {
                roots.push(e.id());
            }
        }
        let mut faces: Vec<(EntityId, FaceRef, Vec<EntityId>)> =
            plain.into_iter().filter(|f| !inside.contains(&f.face)).map(|f| (f.face, f, Vec::new())).collect();
        if let Some(c) = &mut walk.chains {
            c.clear();
        }
        for root in roots {
            let mut placed = Vec::new();
            walk.entity(self, root, Matrix4::identity(), &mut Vec::new(), &mut placed, &mut inside)?;
            let mut chains = walk.chains.as_mut().map(std::mem::take).unwrap_or_default().into_iter();
            faces.extend(placed.into_iter().map(|f| (root, f, chains.next().unwrap_or_default())));
        }
        faces.sort_by_key(|f| f.0);
        let mut count: std::collections::HashMap<EntityId, u32> = std::collections::HashMap::new();
        Ok(faces
            .into_iter()
            .map(|(_, mut f, chain)| {
                let n = count.entry(f.face).or_insert(0);
                f.occurrence = *n;
                *n += 1;
                (f, chain)
            })
            .unzip())
    }

    /// The face that entity `id` makes on its own: a 144, 143 or 510 with its surface (a
    /// record that does not read is listed with itself as surface, so that converting it
    /// reports the error), or a bare surface entity.
    fn face_of(&self, id: EntityId) -> Option<FaceRef> {
        let e = self.entity(id).ok()?;
        let (surface, trimmed) = match e.entity_type() {
            143 | 144 | 510 => match self.view(id) {
                Ok(View::TrimmedSurface(t)) => (t.surface, !t.outer_is_domain || !t.inner.is_empty()),
                Ok(View::BoundedSurface(b)) => (b.surface, true),
                Ok(View::Face(f)) => (f.surface, true),
                _ => (id, true),
            },
            108 | 114 | 118 | 120 | 122 | 128 | 140 | 190..=198 => (id, false),
            _ => return None,
        };
        Some(FaceRef { face: id, surface, trimmed, occurrence: 0, placement: Matrix4::identity() })
    }

    /// The surface of a face in model space (the face's and the surface's transformations
    /// applied, then the face's 408 [`placement`](FaceRef::placement)), exact, with
    /// OCCT's parameter maps.
    ///
    /// # Errors
    ///
    /// As [`surface`](Self::surface).
    pub fn face_surface(&self, face: &FaceRef) -> Result<ExactSurface> {
        self.surface_chain(face.face)?;
        self.surface_chain(face.surface)?;
        if face.face == face.surface {
            let mut s = self.surface(face.surface)?;
            if face.placement != Matrix4::identity() {
                s.surface.transform_by(&face.placement);
            }
            return Ok(s);
        }
        let hint = self.boundary_points(face.face)?;
        let m = self.transform(face.face)?;
        let inv =
            m.try_inverse().ok_or(Error::Transform { de: face.face.0, reason: "singular transformation matrix" })?;
        let local: Vec<Point3<f64>> = hint.iter().map(|p| inv.transform_point(p)).collect();
        let visits = Cell::new(MAX_CURVE_VISITS);
        let mut s = self.child_surface(face.surface, &local, Nest::new(&visits))?;
        let m = face.placement * m;
        if m != Matrix4::identity() {
            s.surface.transform_by(&m);
        }
        Ok(s)
    }

    /// [`face_surface`](Self::face_surface) of each of `faces`, in order. On rayon's
    /// threads when there is enough to share (each conversion only reads the document):
    /// 64 faces or more, or surfaces of 4 096 parameter lines (256 KiB of text) or more
    /// in all (a few large B-spline patches, whose reading and transposing
    /// outweigh a thread's start by far); this is how a model is loaded.
    pub fn face_surfaces(&self, faces: &[FaceRef]) -> Vec<Result<ExactSurface>> {
        let lines: usize = faces.iter().filter_map(|f| self.entity(f.surface).ok()).map(|e| e.p_count).sum();
        if rayon::current_num_threads() > 1
            && faces.len() >= 2
            && (faces.len() >= PARALLEL_FACES || lines >= PARALLEL_LINES)
        {
            use rayon::prelude::*;
            faces.par_iter().map(|f| self.face_surface(f)).collect()
        } else {
            faces.iter().map(|f| self.face_surface(f)).collect()
        }
    }

    /// Control points of the model-space boundary curves of a face (144, 143, 510), in
    /// the face's parent space; empty when the face has none.
    pub(crate) fn boundary_points(&self, face: EntityId) -> Result<Vec<Point3<f64>>> {
        let mut curves: Vec<EntityId> = Vec::new();
        for bound in self.face_bounds(face)? {
            match bound {
                // The 142 itself converts to its model-space curve.
                crate::bounds::FaceBound::Trim { bound, .. } => curves.push(bound),
                crate::bounds::FaceBound::Edge { list, index } => {
                    if let View::EdgeList(el) = self.view(list)? {
                        let k = usize::try_from(index - 1).ok();
                        if let Some(edge) = k.and_then(|k| el.edges.get(k)) {
                            curves.push(edge.curve);
                        }
                    }
                }
            }
        }
        let mut pts = Vec::new();
        for c in curves {
            for piece in self.curve(c)? {
                pts.extend_from_slice(piece.control_points());
            }
        }
        Ok(pts)
    }
}

/// The walk through 308 subfigure definitions and 408 instances (IGES 5.3 §4.74, §4.137).
struct Subfigures {
    /// Instances that may still be followed.
    budget: usize,
    /// How deeply [`Subfigures::entity`] is nested now (groups in groups, instances).
    depth: usize,
    /// Report broken instances (`false`: leave them out).
    strict: bool,
    /// The 408 instances being followed, outermost first.
    instances: Vec<EntityId>,
    /// When kept, `instances` as each face was placed (in the order faces are listed).
    chains: Option<Vec<Vec<EntityId>>>,
}

impl Subfigures {
    /// Marks in `inside` everything definition members reach (faces, groups, shells,
    /// solids, instances), and lists the faces of `members` in `out` unplaced.
    fn content(
        &mut self,
        doc: &Document,
        members: &[EntityId],
        stack: &mut Vec<EntityId>,
        out: &mut Vec<FaceRef>,
        inside: &mut std::collections::HashSet<EntityId>,
    ) -> Result<()> {
        for &m in members {
            inside.insert(m);
            self.entity(doc, m, Matrix4::identity(), stack, out, inside)?;
        }
        Ok(())
    }

    /// The faces entity `id` holds, placed by `placement`, appended to `out`; entities
    /// met on the way are marked in `inside` when they belong to a definition (`stack`
    /// holds the 308s being read, outermost first).
    fn entity(
        &mut self,
        doc: &Document,
        id: EntityId,
        placement: Matrix4<f64>,
        stack: &mut Vec<EntityId>,
        out: &mut Vec<FaceRef>,
        inside: &mut std::collections::HashSet<EntityId>,
    ) -> Result<()> {
        if self.depth >= 4 * MAX_DEPTH {
            // Always an error: leaving the nesting out would keep its copies so far.
            return Err(subfigure(
                id,
                "groups, solids and subfigures nested deeper than 256 (a 402 group that contains itself?)".into(),
            ));
        }
        self.depth += 1;
        let r = self.entity_at(doc, id, placement, stack, out, inside);
        self.depth -= 1;
        r
    }

    /// [`Subfigures::entity`] one level deeper.
    fn entity_at(
        &mut self,
        doc: &Document,
        id: EntityId,
        placement: Matrix4<f64>,
        stack: &mut Vec<EntityId>,
        out: &mut Vec<FaceRef>,
        inside: &mut std::collections::HashSet<EntityId>,
    ) -> Result<()> {
        let Ok(e) = doc.entity(id) else { return Ok(()) };
        let in_definition = !stack.is_empty();
        let mark = |inside: &mut std::collections::HashSet<EntityId>, x: EntityId| {
            if in_definition {
                inside.insert(x);
            }
        };
        match e.entity_type() {
            143 | 144 | 510 | 108 | 114 | 118 | 120 | 122 | 128 | 140 | 190..=198 => {
                if let Some(mut f) = doc.face_of(id) {
                    mark(inside, id);
                    f.placement = placement;
                    out.push(f);
                    if let Some(c) = &mut self.chains {
                        c.push(self.instances.clone());
                    }
                }
            }
            402 => {
                if let Ok(View::Associativity(a)) = doc.view(id) {
                    for m in a.members {
                        mark(inside, m);
                        self.entity(doc, m, placement, stack, out, inside)?;
                    }
                }
            }
            186 => {
                if let Ok(View::ManifoldSolid(s)) = doc.view(id) {
                    for sh in std::iter::once(s.shell).chain(s.voids.iter().map(|v| v.0)) {
                        mark(inside, sh);
                        self.entity(doc, sh, placement, stack, out, inside)?;
                    }
                }
            }
            514 => {
                if let Ok(View::Shell(s)) = doc.view(id) {
                    for (f, _) in s.faces {
                        mark(inside, f);
                        self.entity(doc, f, placement, stack, out, inside)?;
                    }
                }
            }
            308 => self.definition(doc, id, placement, stack, out, inside)?,
            408 => {
                let i = match doc.view(id) {
                    Ok(View::SubfigureInstance(i)) => i,
                    Ok(_) => return Ok(()),
                    Err(err) => return self.refuse(err),
                };
                let Some(budget) = self.budget.checked_sub(1) else {
                    return Err(subfigure(
                        id,
                        "more than 100000 subfigure instances followed (nested instances multiply)".into(),
                    ));
                };
                self.budget = budget;
                match doc.entity(i.definition).map(|d| (d.entity_type(), d.form())) {
                    Ok((308, _)) => {}
                    Ok((t, f)) => {
                        return self.refuse(subfigure(
                            id,
                            format!(
                                "408 instance of DE {} (type {t} form {f}), which is not a 308 subfigure definition",
                                i.definition.0
                            ),
                        ))
                    }
                    Err(err) => return self.refuse(err),
                }
                let m = match doc.transform(id) {
                    Ok(m) => m,
                    Err(err) => return self.refuse(err),
                };
                let local = m * Matrix4::new_translation(&i.translation.coords) * Matrix4::new_scaling(i.scale);
                self.instances.push(id);
                let r = self.definition(doc, i.definition, placement * local, stack, out, inside);
                self.instances.pop();
                r?;
            }
            _ => {}
        }
        Ok(())
    }

    /// The faces of 308 definition `id` placed by `placement`.
    fn definition(
        &mut self,
        doc: &Document,
        id: EntityId,
        placement: Matrix4<f64>,
        stack: &mut Vec<EntityId>,
        out: &mut Vec<FaceRef>,
        inside: &mut std::collections::HashSet<EntityId>,
    ) -> Result<()> {
        if let Some(&last) = stack.last().filter(|_| stack.contains(&id)) {
            return self.refuse(subfigure(
                id,
                format!("308 subfigure definition contains itself (reached again inside DE {})", last.0),
            ));
        }
        if stack.len() >= MAX_DEPTH {
            return self.refuse(subfigure(id, "subfigures nested deeper than 64".into()));
        }
        let d = match doc.view(id) {
            Ok(View::SubfigureDefinition(d)) => d,
            Ok(_) => return Ok(()),
            Err(err) => return self.refuse(err),
        };
        stack.push(id);
        let r = (|| {
            for m in d.entities {
                inside.insert(m);
                self.entity(doc, m, placement, stack, out, inside)?;
            }
            Ok(())
        })();
        stack.pop();
        r
    }

    /// `err` when strict, else nothing (the instance is left out).
    fn refuse(&self, err: Error) -> Result<()> {
        if self.strict {
            Err(err)
        } else {
            Ok(())
        }
    }
}

fn subfigure(id: EntityId, reason: String) -> Error {
    Error::Subfigure { de: id.0, reason }
}

/// Origin of a frame: a 116 entity or a point already known.
enum PointSource {
    Entity(EntityId),
    Point(Point3<f64>),
}

fn p_or(id: EntityId) -> PointSource {
    PointSource::Entity(id)
}

impl From<Point3<f64>> for PointSource {
    fn from(p: Point3<f64>) -> Self {
        PointSource::Point(p)
    }
}

/// Extent of `pts` along a direction, with the margin.
fn extent(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in values {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let pad = BOX_MARGIN * (hi - lo).max(1e-9 * hi.abs().max(lo.abs()).max(1.0));
    Some((lo - pad, hi + pad))
}

fn plane_patch(doc: &Document, id: EntityId, frame: &Placement, pts: &[Point3<f64>]) -> Result<ExactSurface> {
    let o = frame.origin();
    let u = extent(pts.iter().map(|p| (p - o).dot(&frame.x_dir())));
    let v = extent(pts.iter().map(|p| (p - o).dot(&frame.y_dir())));
    let (Some((u0, u1)), Some((v0, v1))) = (u, v) else {
        return Err(unsupported(doc, id, "unbounded plane: no face or boundary curve gives its extent"));
    };
    let plane = cadmorph_nurbs::analytic::Plane::new(*frame);
    plane.to_nurbs(u0..=u1, v0..=v1).map_err(geometry(id))
}

/// Range of the axial coordinate (divided by `scale`: cos of a cone's semi-angle).
fn axial_range(doc: &Document, id: EntityId, frame: &Placement, pts: &[Point3<f64>], scale: f64) -> Result<(f64, f64)> {
    let o = frame.origin();
    extent(pts.iter().map(|p| (p - o).dot(&frame.z_dir()) / scale))
        .ok_or_else(|| unsupported(doc, id, "unbounded surface: no face gives its extent along the axis"))
}

/// Bézier control values of the cubic `a + b s + c s² + d s³` on `s ∈ [0, h]`.
/// A 120 surface of revolution in OCCT's parameterisation (its IGES reader, entity 120):
/// the axis through the start point `a0` pointing back to `a1` (the IGES axis reversed),
/// the angles `SA' = 2π − EA`, `EA' = 2π − SA`, the generatrix turned by `SA'` about that
/// axis, `u ∈ [0, EA' − SA']` (the whole turn `[0, 2π]` when that is within 1e-9 of it)
/// and `v` the generatrix's analytic parameter (`v_map`: the angle of an arc, as OCCT
/// parameterises its basis curve). The points are IGES's `S(t, θ)` with `θ = EA − u`;
/// `S_u × S_v` is the IGES normal `S_t × S_θ` (IGES 5.3 §4.18).
fn occt_revolution(
    mut gen: NurbsCurve,
    a0: Point3<f64>,
    a1: Point3<f64>,
    r: &crate::entity::SurfaceOfRevolution,
    v_map: ParamMap,
) -> cadmorph_nurbs::Result<ExactSurface> {
    let (sa, ea) = (TAU - r.end_angle, TAU - r.start_angle);
    let mut delta = ea - sa;
    if delta > TAU - 1e-9 {
        delta = TAU;
    }
    let dir = a0 - a1;
    if sa != 0.0 && dir.norm() > 0.0 && dir.iter().all(|c| c.is_finite()) {
        let turn = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(dir), sa);
        let m = Matrix4::new_translation(&a0.coords) * turn.to_homogeneous() * Matrix4::new_translation(&-a0.coords);
        gen.transform_by(&m);
    }
    let dom = gen.domain();
    let mut s = Revolution::try_new(gen, a0, dir)?.to_nurbs(0.0..=delta, dom)?;
    s.v_map = v_map;
    Ok(s)
}

/// A 100 circular arc in its definition space, exact, with the angle as its analytic
/// parameter (OCCT's `Geom_Circle` trimmed from the start angle), IGES 5.3 §4.3.
fn circular_arc(a: &crate::entity::CircularArc) -> cadmorph_nurbs::Result<cadmorph_nurbs::analytic::ExactCurve> {
    let (cx, cy) = (a.center[0], a.center[1]);
    let (sx, sy) = (a.start[0] - cx, a.start[1] - cy);
    let (ex, ey) = (a.end[0] - cx, a.end[1] - cy);
    let r = sx.hypot(sy);
    let t0 = sy.atan2(sx);
    let mut t1 = ey.atan2(ex);
    while t1 <= t0 + 1e-12 {
        t1 += TAU;
    }
    if t1 - t0 > TAU {
        t1 = t0 + TAU;
    }
    let frame = Placement::try_new(Point3::new(cx, cy, a.z), Vector3::z(), Vector3::x())?;
    Circle::try_new(frame, r)?.to_nurbs(t0..=t1)
}

fn cubic_bezier(k: [f64; 4], h: f64) -> [f64; 4] {
    let (a, b, c, d) = (k[0], k[1] * h, k[2] * h * h, k[3] * h * h * h);
    [a, a + b / 3.0, a + 2.0 * b / 3.0 + c / 3.0, a + b + c + d]
}

/// 112 → cubic B-spline, exact: each segment's power basis to Bézier form, joined with
/// knots of multiplicity 3 at the break points.
fn spline_curve(s: &crate::entity::ParametricSplineCurve) -> cadmorph_nurbs::Result<NurbsCurve> {
    let n = s.coefficients.len();
    let t = &s.breakpoints;
    let mut knots = vec![t[0]; 4];
    let mut points = Vec::with_capacity(3 * n + 1);
    for (i, seg) in s.coefficients.iter().enumerate() {
        let h = t[i + 1] - t[i];
        let b: Vec<[f64; 4]> = seg.iter().map(|c| cubic_bezier(*c, h)).collect();
        let first = if i == 0 { 0 } else { 1 };
        for k in first..4 {
            points.push(Point3::new(b[0][k], b[1][k], if s.dimension == 2 { 0.0 } else { b[2][k] }));
        }
        knots.extend(std::iter::repeat_n(t[i + 1], if i + 1 == n { 4 } else { 3 }));
    }
    NurbsCurve::try_new(3, KnotVector::try_new(knots)?, points, None)
}

/// 114 → bicubic B-spline, exact (Bézier patches joined with triple knots).
fn spline_surface(s: &crate::entity::ParametricSplineSurface) -> cadmorph_nurbs::Result<NurbsSurface> {
    let (m, n) = (s.u_breakpoints.len() - 1, s.v_breakpoints.len() - 1);
    let (nu, nv) = (3 * m + 1, 3 * n + 1);
    let mut pts = vec![Point3::origin(); nu * nv];
    for i in 0..m {
        let hu = s.u_breakpoints[i + 1] - s.u_breakpoints[i];
        for j in 0..n {
            let hv = s.v_breakpoints[j + 1] - s.v_breakpoints[j];
            let patch = &s.patches[i * n + j];
            for (coord, coef) in patch.iter().enumerate() {
                // coef[k + 4 l]: u power k, v power l. Convert along u for each l, then along v.
                let mut mid = [[0.0; 4]; 4]; // mid[l][a]: Bézier index a in u, power l in v
                for (l, row) in mid.iter_mut().enumerate() {
                    *row = cubic_bezier([coef[4 * l], coef[1 + 4 * l], coef[2 + 4 * l], coef[3 + 4 * l]], hu);
                }
                for a in 0..4 {
                    let col = cubic_bezier([mid[0][a], mid[1][a], mid[2][a], mid[3][a]], hv);
                    for (b, val) in col.iter().enumerate() {
                        pts[(3 * i + a) * nv + 3 * j + b][coord] = *val;
                    }
                }
            }
        }
    }
    let knots = |t: &[f64]| {
        let k = t.len() - 1;
        let mut v = vec![t[0]; 4];
        for (i, x) in t.iter().enumerate().skip(1) {
            v.extend(std::iter::repeat_n(*x, if i == k { 4 } else { 3 }));
        }
        v
    };
    NurbsSurface::try_new(
        (3, 3),
        (KnotVector::try_new(knots(&s.u_breakpoints))?, KnotVector::try_new(knots(&s.v_breakpoints))?),
        (nu, nv),
        pts,
        None,
    )
}

impl Document {
    /// For each face ([`faces`](Self::faces)): its surface entity's type, form, trimmed
    /// flag, and the degrees, pole counts and rationality of its exact NURBS form.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_iges::Document;
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3.igs")).unwrap();
    /// let doc = Document::parse(&bytes).unwrap();
    /// let info = doc.surfaces();
    /// assert_eq!(info.len(), 3);
    /// let n = info[0].nurbs.as_ref().unwrap();
    /// assert_eq!((n.u_degree, n.v_degree, n.rational), (3, 3, false));
    /// ```
    pub fn surfaces(&self) -> Vec<SurfaceInfo> {
        self.faces()
            .into_iter()
            .map(|f| {
                let e = &self.entities[f.surface.index()];
                SurfaceInfo {
                    face: f.face,
                    surface: f.surface,
                    entity_type: e.entity_type(),
                    form: e.form(),
                    trimmed: f.trimmed,
                    nurbs: self.face_surface(&f).map(|s| NurbsInfo::of(&s.surface)),
                }
            })
            .collect()
    }
}
