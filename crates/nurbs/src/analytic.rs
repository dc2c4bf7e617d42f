//! Exact NURBS form of analytic curves and surfaces, in OpenCASCADE's parameterisations.
//!
//! Every analytic type here evaluates its closed form exactly as OCCT's `Geom_*` class
//! does (same frame, same parameters), and converts itself to an exact NURBS over a
//! parameter range with [`AnalyticSurface::to_nurbs`] / [`AnalyticCurve::to_nurbs`]:
//!
//! ```text
//! Plane       P(u,v) = O + u·X + v·Y                                    Geom_Plane
//! Cylinder    P(u,v) = O + R (cos u·X + sin u·Y) + v·Z                  Geom_CylindricalSurface
//! Cone        P(u,v) = O + (R + v sin a)(cos u·X + sin u·Y) + v cos a·Z Geom_ConicalSurface
//! Sphere      P(u,v) = O + R cos v (cos u·X + sin u·Y) + R sin v·Z      Geom_SphericalSurface
//! Torus       P(u,v) = O + (R + r cos v)(cos u·X + sin u·Y) + r sin v·Z Geom_ToroidalSurface
//! Revolution  P(u,v) = C(v) rotated by u about the axis                 Geom_SurfaceOfRevolution
//! Extrusion   P(u,v) = C(u) + v·D                                       Geom_SurfaceOfLinearExtrusion
//! Line        C(u)   = O + u·D                                          Geom_Line
//! Circle      C(u)   = O + R (cos u·X + sin u·Y)                        Geom_Circle
//! Ellipse     C(u)   = O + a cos u·X + b sin u·Y                        Geom_Ellipse
//! ```
//!
//! # Angles and NURBS parameters
//!
//! Circular directions become rational quadratic arcs (Piegl & Tiller §7.5, A7.1),
//! split into `n = ⌈Δ/90°⌉` equal segments of at most 90° each, with weights
//! `(1, cos θ, 1)` where `θ` is the half-angle of a segment. The knots sit at the angles of
//! the segment joints (each with multiplicity 2), so the NURBS domain *is* the angle range
//! and the NURBS parameter equals the angle at every joint. Between joints a rational
//! quadratic arc is not angle-parameterised; [`ParamMap`] converts in closed form. On a
//! segment `[a, b]` with `θ = (b − a)/2`, the point at angle `φ` has NURBS parameter
//!
//! ```text
//! t = a + s (b − a),   s = ½ (1 + tan(α/2) / tan(θ/2)),   α = φ − (a + θ)
//! ```
//!
//! and conversely `φ = a + θ + 2 atan((2s − 1) tan(θ/2))`. (Derivation: for the
//! symmetric arc with `P₀, P₂` at `∓θ` and weight `cos θ`, with `m = 2s − 1`,
//! `tan α = 2m tan(θ/2) / (1 − m² tan²(θ/2)) = tan(2 atan(m tan(θ/2)))`.)
//! Linear directions (plane, cylinder and cone `v`, extrusion `v`, lines, and the curve
//! directions of revolutions and extrusions) map by the identity.
//!
//! So to evaluate the NURBS at the point OCCT evaluates at `(u, v)`:
//!
//! ```
//! use cadmorph_nurbs::analytic::{AnalyticSurface, Cylinder, Placement};
//! use cadmorph_nurbs::Surface;
//! let cyl = Cylinder::try_new(Placement::standard(), 2.0).unwrap();
//! let exact = cyl.to_nurbs(0.0..=3.0, -1.0..=1.0).unwrap();
//! let (u, v) = (1.1, 0.25);
//! let (s, t) = exact.nurbs_params(u, v);
//! assert!((exact.surface.eval(s, t) - cyl.eval(u, v)).norm() < 1e-14);
//! ```

use std::f64::consts::{FRAC_PI_2, TAU};
use std::ops::RangeInclusive;

use nalgebra::{Point3, Unit, Vector3};

use crate::{Curve, Error, KnotVector, NurbsCurve, NurbsSurface, Result, SurfacePointD1};

/// Angle ranges may exceed 2π by this relative amount (rounding of `u₀ + 2π`).
const FULL_TURN_SLACK: f64 = 1e-12;

/// A right-handed coordinate system: origin `O` and orthonormal axes `X`, `Y = Z × X`, `Z`
/// (OCCT `gp_Ax3` with a direct frame; STEP `AXIS2_PLACEMENT_3D`).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::Placement;
/// use nalgebra::{Point3, Vector3};
/// // Axis along +y, reference direction not quite orthogonal: it is projected.
/// let f = Placement::try_new(Point3::origin(), Vector3::new(0.0, 2.0, 0.0), Vector3::new(1.0, 1.0, 0.0)).unwrap();
/// assert_eq!(f.x_dir(), Vector3::new(1.0, 0.0, 0.0));
/// assert_eq!(f.y_dir(), Vector3::new(0.0, 0.0, -1.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    origin: Point3<f64>,
    x: Vector3<f64>,
    y: Vector3<f64>,
    z: Vector3<f64>,
}

impl Placement {
    /// The frame at `origin` with main axis `axis` (Z) and X the part of `ref_direction`
    /// orthogonal to it (normalised), as STEP's `AXIS2_PLACEMENT_3D` and OCCT's
    /// `gp_Ax3(P, N, Vx)` build it.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for a zero or non-finite axis, a non-finite origin, or a
    /// reference direction parallel to the axis.
    pub fn try_new(origin: Point3<f64>, axis: Vector3<f64>, ref_direction: Vector3<f64>) -> Result<Self> {
        let bad = |reason| Error::Analytic { shape: "placement", reason };
        if !origin.coords.iter().all(|c| c.is_finite()) {
            return Err(bad("non-finite origin"));
        }
        let z = unit(axis).ok_or(bad("zero or non-finite axis"))?;
        let parallel = bad("reference direction parallel to the axis, zero or non-finite");
        // Numerically parallel directions count as parallel.
        let off_axis = ref_direction.cross(&z).norm();
        if off_axis.is_nan() || off_axis <= 1e-12 * ref_direction.norm() {
            return Err(parallel);
        }
        let x = unit(ref_direction - z * ref_direction.dot(&z)).ok_or(parallel)?;
        Ok(Self { origin, x, y: z.cross(&x), z })
    }

    /// The world frame: origin 0, axes x, y, z.
    pub fn standard() -> Self {
        Self { origin: Point3::origin(), x: Vector3::x(), y: Vector3::y(), z: Vector3::z() }
    }

    /// The origin `O`.
    pub fn origin(&self) -> Point3<f64> {
        self.origin
    }
    /// The X direction (unit).
    pub fn x_dir(&self) -> Vector3<f64> {
        self.x
    }
    /// The Y direction (unit), `Z × X`.
    pub fn y_dir(&self) -> Vector3<f64> {
        self.y
    }
    /// The main axis Z (unit).
    pub fn z_dir(&self) -> Vector3<f64> {
        self.z
    }

    /// The point `O + a·X + b·Y + c·Z`.
    pub fn to_world(&self, a: f64, b: f64, c: f64) -> Point3<f64> {
        self.origin + self.x * a + self.y * b + self.z * c
    }

    /// The vector `a·X + b·Y + c·Z`.
    fn vec(&self, a: f64, b: f64, c: f64) -> Vector3<f64> {
        self.x * a + self.y * b + self.z * c
    }
}

fn unit(v: Vector3<f64>) -> Option<Vector3<f64>> {
    let n = v.norm();
    (n.is_finite() && n > 0.0).then(|| v / n)
}

/// How the parameter of an analytic curve or surface direction maps to the parameter of
/// its exact NURBS form (see the [module docs](self) for the formula).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::ParamMap;
/// let m = ParamMap::Arc { start: 0.0, end: std::f64::consts::PI, segments: 2 };
/// // Identity at the joints 0, π/2, π; in between the NURBS parameter differs.
/// assert_eq!(m.to_nurbs(std::f64::consts::FRAC_PI_2), std::f64::consts::FRAC_PI_2);
/// assert!((m.to_nurbs(0.3) - 0.3).abs() > 1e-3);
/// assert!((m.to_analytic(m.to_nurbs(0.3)) - 0.3).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamMap {
    /// The NURBS parameter is the analytic one.
    Identity,
    /// Angles `[start, end]` in `segments` equal rational quadratic arcs, knots at the joints.
    Arc {
        /// First angle (radians).
        start: f64,
        /// Last angle (radians).
        end: f64,
        /// Number of arc segments (each at most 90°).
        segments: usize,
    },
}

impl ParamMap {
    /// The NURBS parameter of the point at analytic parameter `t` (an angle for arcs).
    /// Angles outside the range extrapolate the first or last segment.
    pub fn to_nurbs(&self, t: f64) -> f64 {
        match *self {
            ParamMap::Identity => t,
            ParamMap::Arc { start, end, segments } => {
                let (a, b) = arc_segment(start, end, segments, t);
                let theta = (b - a) / 2.0;
                let alpha = (t - a) - theta;
                let s = 0.5 * (1.0 + (alpha / 2.0).tan() / (theta / 2.0).tan());
                a * (1.0 - s) + b * s
            }
        }
    }

    /// The analytic parameter (angle) of the point at NURBS parameter `t`; the inverse of
    /// [`to_nurbs`](Self::to_nurbs).
    pub fn to_analytic(&self, t: f64) -> f64 {
        match *self {
            ParamMap::Identity => t,
            ParamMap::Arc { start, end, segments } => {
                let (a, b) = arc_segment(start, end, segments, t);
                let theta = (b - a) / 2.0;
                let s = (t - a) / (b - a);
                if s == 0.0 {
                    return a;
                }
                if s == 1.0 {
                    return b;
                }
                a + theta + 2.0 * ((2.0 * s - 1.0) * (theta / 2.0).tan()).atan()
            }
        }
    }
}

/// Angle of joint `k` of `n` equal segments on `[start, end]`.
fn joint(start: f64, end: f64, n: usize, k: usize) -> f64 {
    if k == n {
        end
    } else {
        start + (end - start) * k as f64 / n as f64
    }
}

/// The segment `[a, b]` of the arc that holds `t` (clamped to the first/last).
fn arc_segment(start: f64, end: f64, n: usize, t: f64) -> (f64, f64) {
    let f = ((t - start) / (end - start) * n as f64).floor();
    let mut k = if f.is_nan() || f < 0.0 { 0 } else { (f as usize).min(n - 1) };
    // Rounding of the division may put t one segment off; the joints decide.
    while k > 0 && t < joint(start, end, n, k) {
        k -= 1;
    }
    while k + 1 < n && t >= joint(start, end, n, k + 1) {
        k += 1;
    }
    (joint(start, end, n, k), joint(start, end, n, k + 1))
}

/// A unit-circle arc `c(φ) = (cos φ, sin φ)` over an angle range as a rational quadratic
/// (Piegl & Tiller A7.1 with knots at the joint angles).
struct UnitArc {
    knots: Vec<f64>,
    points: Vec<[f64; 2]>,
    weights: Vec<f64>,
    map: ParamMap,
}

fn check_angles(shape: &'static str, r: &RangeInclusive<f64>) -> Result<(f64, f64)> {
    let (start, end) = (*r.start(), *r.end());
    if !(start.is_finite() && end.is_finite() && end > start) {
        return Err(Error::Analytic { shape, reason: "empty or non-finite angle range" });
    }
    if end - start > TAU * (1.0 + FULL_TURN_SLACK) {
        return Err(Error::Analytic { shape, reason: "angle range wider than 2π" });
    }
    Ok((start, end))
}

fn check_linear(shape: &'static str, r: &RangeInclusive<f64>, reason: &'static str) -> Result<(f64, f64)> {
    let (start, end) = (*r.start(), *r.end());
    if !(start.is_finite() && end.is_finite() && end > start) {
        return Err(Error::Analytic { shape, reason });
    }
    Ok((start, end))
}

fn unit_arc(shape: &'static str, r: &RangeInclusive<f64>) -> Result<UnitArc> {
    let (start, end) = check_angles(shape, r)?;
    let n = (((end - start) / FRAC_PI_2) * (1.0 - FULL_TURN_SLACK)).ceil().max(1.0) as usize;
    let mut knots = vec![start; 3];
    let mut points = Vec::with_capacity(2 * n + 1);
    let mut weights = Vec::with_capacity(2 * n + 1);
    for k in 0..n {
        let (a, b) = (joint(start, end, n, k), joint(start, end, n, k + 1));
        let theta = (b - a) / 2.0;
        let (m, w) = (a + theta, theta.cos());
        points.push([a.cos(), a.sin()]);
        weights.push(1.0);
        points.push([m.cos() / w, m.sin() / w]);
        weights.push(w);
        if k + 1 < n {
            knots.extend([b, b]);
        }
    }
    points.push([end.cos(), end.sin()]);
    weights.push(1.0);
    knots.extend([end; 3]);
    Ok(UnitArc { knots, points, weights, map: ParamMap::Arc { start, end, segments: n } })
}

/// A planar profile `(ρ(v), z(v))` in the half-plane spanned by a radial direction and the axis.
struct Profile {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<[f64; 2]>,
    weights: Option<Vec<f64>>,
    map: ParamMap,
}

fn line_profile(v0: f64, v1: f64, a: [f64; 2], b: [f64; 2]) -> Profile {
    Profile { degree: 1, knots: vec![v0, v0, v1, v1], points: vec![a, b], weights: None, map: ParamMap::Identity }
}

fn arc_profile(center: [f64; 2], radius: f64, arc: UnitArc) -> Profile {
    Profile {
        degree: 2,
        points: arc.points.iter().map(|c| [center[0] + radius * c[0], center[1] + radius * c[1]]).collect(),
        knots: arc.knots,
        weights: Some(arc.weights),
        map: arc.map,
    }
}

/// The surface `O + ρ(v)(cᵤ X + cᵥ Y) + z(v) Z` with `c` the unit arc in u: the
/// tensor product of arc and profile (Piegl & Tiller A8.1 in the placement's frame).
fn revolve_profile(frame: &Placement, arc: UnitArc, profile: Profile) -> Result<ExactSurface> {
    let (n_u, n_v) = (arc.points.len(), profile.points.len());
    let mut points = Vec::with_capacity(n_u * n_v);
    let mut weights = Vec::with_capacity(n_u * n_v);
    for (c, wu) in arc.points.iter().zip(&arc.weights) {
        for (j, q) in profile.points.iter().enumerate() {
            points.push(frame.to_world(q[0] * c[0], q[0] * c[1], q[1]));
            weights.push(wu * profile.weights.as_ref().map_or(1.0, |w| w[j]));
        }
    }
    let surface = NurbsSurface::try_new(
        (2, profile.degree),
        (KnotVector::try_new(arc.knots)?, KnotVector::try_new(profile.knots)?),
        (n_u, n_v),
        points,
        Some(weights),
    )?;
    Ok(ExactSurface { surface, u_map: arc.map, v_map: profile.map })
}

/// A NURBS curve that is exactly an analytic curve, with the map between their parameters.
///
/// `curve.eval(map.to_nurbs(t))` is the point the analytic curve has at `t`.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactCurve {
    /// The exact NURBS form; its domain is the analytic parameter range.
    pub curve: NurbsCurve,
    /// Analytic parameter ↔ NURBS parameter.
    pub map: ParamMap,
}

impl ExactCurve {
    /// The NURBS parameter of the analytic parameter `t`.
    pub fn nurbs_param(&self, t: f64) -> f64 {
        self.map.to_nurbs(t)
    }
    /// The analytic parameter of the NURBS parameter `t`.
    pub fn analytic_param(&self, t: f64) -> f64 {
        self.map.to_analytic(t)
    }
}

/// A NURBS surface that is exactly an analytic surface, with the maps between their
/// parameters in u and in v.
///
/// `surface.eval(u_map.to_nurbs(u), v_map.to_nurbs(v))` is the point the analytic
/// surface has at `(u, v)`; the NURBS domain is the analytic parameter rectangle.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactSurface {
    /// The exact NURBS form.
    pub surface: NurbsSurface,
    /// Analytic u ↔ NURBS u.
    pub u_map: ParamMap,
    /// Analytic v ↔ NURBS v.
    pub v_map: ParamMap,
}

impl ExactSurface {
    /// The NURBS parameters of the analytic parameters `(u, v)`.
    pub fn nurbs_params(&self, u: f64, v: f64) -> (f64, f64) {
        (self.u_map.to_nurbs(u), self.v_map.to_nurbs(v))
    }
    /// The analytic parameters of the NURBS parameters `(s, t)`.
    pub fn analytic_params(&self, s: f64, t: f64) -> (f64, f64) {
        (self.u_map.to_analytic(s), self.v_map.to_analytic(t))
    }
}

/// An analytic surface with OCCT's closed-form evaluation and an exact NURBS form.
pub trait AnalyticSurface {
    /// Point and first partials at `(u, v)`, closed form (OCCT `D1`).
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1;

    /// The point at `(u, v)`, closed form (OCCT `Value`).
    fn eval(&self, u: f64, v: f64) -> Point3<f64> {
        self.d1(u, v).point
    }

    /// Unit normal `∂S/∂u × ∂S/∂v`, normalised, or `None` where it vanishes (apex, poles):
    /// where `|S_u × S_v| ≤ 1e-12 · max(|S_u|, |S_v|)²`.
    fn normal(&self, u: f64, v: f64) -> Option<Unit<Vector3<f64>>> {
        let d = self.d1(u, v);
        let n = d.du.cross(&d.dv);
        // Relative to the larger partial, so a partial that is zero up to rounding (a
        // pole, an apex) gives `None` rather than a direction made of rounding noise.
        let scale = d.du.norm().max(d.dv.norm()).powi(2);
        if n.norm().is_nan() || n.norm() <= 1e-12 * scale {
            return None;
        }
        Unit::try_new(n, 0.0)
    }

    /// The exact NURBS form over `u × v`; its domain is that rectangle.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for empty or non-finite ranges, angle ranges wider than 2π, or
    /// ranges the surface does not have (sphere `v` outside `[−π/2, π/2]`, curve
    /// parameters outside the curve's domain).
    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface>;
}

/// An analytic curve with OCCT's closed-form evaluation and an exact NURBS form.
pub trait AnalyticCurve {
    /// The point at `t` (OCCT `Value`).
    fn eval(&self, t: f64) -> Point3<f64>;
    /// The first derivative at `t` (OCCT `D1`).
    fn deriv(&self, t: f64) -> Vector3<f64>;
    /// The exact NURBS form over `range`; its domain is that range.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for an empty or non-finite range or an angle range wider than 2π.
    fn to_nurbs(&self, range: RangeInclusive<f64>) -> Result<ExactCurve>;
}

/// An infinite plane `P(u,v) = O + u·X + v·Y` (OCCT `Geom_Plane`); normal `Z`.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Placement, Plane};
/// use cadmorph_nurbs::Surface;
/// let plane = Plane::new(Placement::standard());
/// let patch = plane.to_nurbs(-1.0..=2.0, 0.0..=3.0).unwrap().surface;
/// assert_eq!((patch.u_degree(), patch.v_degree()), (1, 1));
/// assert_eq!(patch.eval(0.5, 2.0), plane.eval(0.5, 2.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Origin and axes; `Z` is the normal.
    pub placement: Placement,
}

impl Plane {
    /// The plane of `placement`.
    pub fn new(placement: Placement) -> Self {
        Self { placement }
    }
}

impl AnalyticSurface for Plane {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let f = &self.placement;
        SurfacePointD1 { point: f.to_world(u, v, 0.0), du: f.x, dv: f.y }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let (u0, u1) = check_linear("plane", &u, "empty or non-finite u range")?;
        let (v0, v1) = check_linear("plane", &v, "empty or non-finite v range")?;
        let f = &self.placement;
        let points =
            vec![f.to_world(u0, v0, 0.0), f.to_world(u0, v1, 0.0), f.to_world(u1, v0, 0.0), f.to_world(u1, v1, 0.0)];
        let surface = NurbsSurface::try_new(
            (1, 1),
            (KnotVector::try_new(vec![u0, u0, u1, u1])?, KnotVector::try_new(vec![v0, v0, v1, v1])?),
            (2, 2),
            points,
            None,
        )?;
        Ok(ExactSurface { surface, u_map: ParamMap::Identity, v_map: ParamMap::Identity })
    }
}

/// A circular cylinder `P(u,v) = O + R (cos u·X + sin u·Y) + v·Z` (OCCT
/// `Geom_CylindricalSurface`); the normal points away from the axis.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Cylinder, Placement};
/// use cadmorph_nurbs::Surface;
/// let cyl = Cylinder::try_new(Placement::standard(), 1.5).unwrap();
/// let full = cyl.to_nurbs(0.0..=std::f64::consts::TAU, 0.0..=1.0).unwrap().surface;
/// // Four 90° arcs: 9 poles around, 2 along the axis.
/// assert_eq!((full.n_u(), full.n_v()), (9, 2));
/// let p = full.eval(1.0, 0.5);
/// assert!((p.x.hypot(p.y) - 1.5).abs() < 1e-14);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    placement: Placement,
    radius: f64,
}

impl Cylinder {
    /// The cylinder of radius `radius` about the placement's Z axis.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] unless `radius` is positive and finite.
    pub fn try_new(placement: Placement, radius: f64) -> Result<Self> {
        positive("cylinder", radius, "radius must be positive and finite")?;
        Ok(Self { placement, radius })
    }
    /// The placement (axis = Z).
    pub fn placement(&self) -> &Placement {
        &self.placement
    }
    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }
}

fn positive(shape: &'static str, x: f64, reason: &'static str) -> Result<()> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(Error::Analytic { shape, reason })
    }
}

impl AnalyticSurface for Cylinder {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let (s, c) = u.sin_cos();
        let (f, r) = (&self.placement, self.radius);
        SurfacePointD1 { point: f.to_world(r * c, r * s, v), du: f.vec(-r * s, r * c, 0.0), dv: f.z }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let arc = unit_arc("cylinder", &u)?;
        let (v0, v1) = check_linear("cylinder", &v, "empty or non-finite v range")?;
        let r = self.radius;
        revolve_profile(&self.placement, arc, line_profile(v0, v1, [r, v0], [r, v1]))
    }
}

/// A circular cone `P(u,v) = O + (R + v sin a)(cos u·X + sin u·Y) + v cos a·Z` (OCCT
/// `Geom_ConicalSurface`, semi-angle `a`, reference radius `R` at `v = 0`).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Cone, Placement};
/// use cadmorph_nurbs::Surface;
/// let a = std::f64::consts::FRAC_PI_6;
/// let cone = Cone::try_new(Placement::standard(), 1.0, a).unwrap();
/// let exact = cone.to_nurbs(0.0..=1.0, 0.0..=2.0).unwrap();
/// let (s, t) = exact.nurbs_params(0.7, 1.5);
/// assert!((exact.surface.eval(s, t) - cone.eval(0.7, 1.5)).norm() < 1e-14);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    placement: Placement,
    radius: f64,
    semi_angle: f64,
}

impl Cone {
    /// The cone with reference radius `radius` (at `v = 0`) and semi-angle `semi_angle`.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for a negative or non-finite radius, or a semi-angle with
    /// `|a|` not strictly between 0 and π/2 (OCCT's limits).
    pub fn try_new(placement: Placement, radius: f64, semi_angle: f64) -> Result<Self> {
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(Error::Analytic { shape: "cone", reason: "radius must be non-negative and finite" });
        }
        if !(semi_angle.abs() > crate::tol::ANGULAR && semi_angle.abs() < FRAC_PI_2 - crate::tol::ANGULAR) {
            return Err(Error::Analytic { shape: "cone", reason: "semi-angle must be in (0, π/2) in absolute value" });
        }
        Ok(Self { placement, radius, semi_angle })
    }
    /// The placement (axis = Z).
    pub fn placement(&self) -> &Placement {
        &self.placement
    }
    /// The reference radius at `v = 0`.
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// The semi-angle (radians).
    pub fn semi_angle(&self) -> f64 {
        self.semi_angle
    }
}

impl AnalyticSurface for Cone {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let (s, c) = u.sin_cos();
        let (sa, ca) = self.semi_angle.sin_cos();
        let rho = self.radius + v * sa;
        let f = &self.placement;
        SurfacePointD1 {
            point: f.to_world(rho * c, rho * s, v * ca),
            du: f.vec(-rho * s, rho * c, 0.0),
            dv: f.vec(sa * c, sa * s, ca),
        }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let arc = unit_arc("cone", &u)?;
        let (v0, v1) = check_linear("cone", &v, "empty or non-finite v range")?;
        let (sa, ca) = self.semi_angle.sin_cos();
        let at = |v: f64| [self.radius + v * sa, v * ca];
        revolve_profile(&self.placement, arc, line_profile(v0, v1, at(v0), at(v1)))
    }
}

/// A sphere `P(u,v) = O + R cos v (cos u·X + sin u·Y) + R sin v·Z`, `v ∈ [−π/2, π/2]`
/// (OCCT `Geom_SphericalSurface`); the normal points outward.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Placement, Sphere};
/// use cadmorph_nurbs::Surface;
/// use std::f64::consts::{FRAC_PI_2, TAU};
/// let sphere = Sphere::try_new(Placement::standard(), 2.0).unwrap();
/// let s = sphere.to_nurbs(0.0..=TAU, -FRAC_PI_2..=FRAC_PI_2).unwrap().surface;
/// for (u, v) in [(0.1, 0.2), (3.0, -1.2), (6.0, 1.5)] {
///     assert!((s.eval(u, v).coords.norm() - 2.0).abs() < 1e-14);
/// }
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    placement: Placement,
    radius: f64,
}

impl Sphere {
    /// The sphere of radius `radius` centred at the placement's origin.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] unless `radius` is positive and finite.
    pub fn try_new(placement: Placement, radius: f64) -> Result<Self> {
        positive("sphere", radius, "radius must be positive and finite")?;
        Ok(Self { placement, radius })
    }
    /// The placement (polar axis = Z).
    pub fn placement(&self) -> &Placement {
        &self.placement
    }
    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }
}

impl AnalyticSurface for Sphere {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let (su, cu) = u.sin_cos();
        let (sv, cv) = v.sin_cos();
        let (f, r) = (&self.placement, self.radius);
        SurfacePointD1 {
            point: f.to_world(r * cv * cu, r * cv * su, r * sv),
            du: f.vec(-r * cv * su, r * cv * cu, 0.0),
            dv: f.vec(-r * sv * cu, -r * sv * su, r * cv),
        }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let arc = unit_arc("sphere", &u)?;
        let slack = FRAC_PI_2 * FULL_TURN_SLACK;
        if *v.start() < -FRAC_PI_2 - slack || *v.end() > FRAC_PI_2 + slack {
            return Err(Error::Analytic { shape: "sphere", reason: "v range outside [-π/2, π/2]" });
        }
        let meridian = unit_arc("sphere", &v)?;
        revolve_profile(&self.placement, arc, arc_profile([0.0, 0.0], self.radius, meridian))
    }
}

/// A torus `P(u,v) = O + (R + r cos v)(cos u·X + sin u·Y) + r sin v·Z` (OCCT
/// `Geom_ToroidalSurface`, major radius `R`, minor radius `r`).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Placement, Torus};
/// use cadmorph_nurbs::Surface;
/// let torus = Torus::try_new(Placement::standard(), 3.0, 1.0).unwrap();
/// let exact = torus.to_nurbs(0.0..=1.0, 0.0..=std::f64::consts::TAU).unwrap();
/// let p = exact.surface.eval(0.5, 2.0);
/// let rho = p.x.hypot(p.y);
/// assert!(((rho - 3.0).powi(2) + p.z * p.z - 1.0).abs() < 1e-13);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torus {
    placement: Placement,
    major_radius: f64,
    minor_radius: f64,
}

impl Torus {
    /// The torus about the placement's Z axis.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] unless both radii are positive and finite.
    pub fn try_new(placement: Placement, major_radius: f64, minor_radius: f64) -> Result<Self> {
        positive("torus", major_radius, "major radius must be positive and finite")?;
        positive("torus", minor_radius, "minor radius must be positive and finite")?;
        Ok(Self { placement, major_radius, minor_radius })
    }
    /// The placement (axis = Z).
    pub fn placement(&self) -> &Placement {
        &self.placement
    }
    /// The major radius `R`.
    pub fn major_radius(&self) -> f64 {
        self.major_radius
    }
    /// The minor radius `r`.
    pub fn minor_radius(&self) -> f64 {
        self.minor_radius
    }
}

impl AnalyticSurface for Torus {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let (su, cu) = u.sin_cos();
        let (sv, cv) = v.sin_cos();
        let (f, big, r) = (&self.placement, self.major_radius, self.minor_radius);
        let rho = big + r * cv;
        SurfacePointD1 {
            point: f.to_world(rho * cu, rho * su, r * sv),
            du: f.vec(-rho * su, rho * cu, 0.0),
            dv: f.vec(-r * sv * cu, -r * sv * su, r * cv),
        }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let arc = unit_arc("torus", &u)?;
        let meridian = unit_arc("torus", &v)?;
        revolve_profile(&self.placement, arc, arc_profile([self.major_radius, 0.0], self.minor_radius, meridian))
    }
}

/// The part of `curve` on `[t0, t1]` (same parameterisation), by splitting.
fn trim(shape: &'static str, curve: &NurbsCurve, r: &RangeInclusive<f64>) -> Result<NurbsCurve> {
    let (t0, t1) = check_linear(shape, r, "empty or non-finite curve parameter range")?;
    let d = curve.domain();
    let (a, b) = (*d.start(), *d.end());
    let eps = crate::tol::KNOT_EQUALITY * (b - a);
    if t0 < a - eps || t1 > b + eps {
        return Err(Error::Analytic { shape, reason: "curve parameter range outside the curve's domain" });
    }
    let mut c = curve.clone();
    if t0 > a + eps {
        c = c.split(t0)?.1;
    }
    if t1 < b - eps {
        c = c.split(t1)?.0;
    }
    Ok(c)
}

/// A surface of revolution: the curve `C(v)` rotated by the angle `u` about an axis
/// through `A` with unit direction `D` (OCCT `Geom_SurfaceOfRevolution`):
///
/// ```text
/// P(u,v) = A + a D + cos u · r + sin u · D × r,   a = (C(v) − A)·D,   r = C(v) − A − a D
/// ```
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Revolution};
/// use cadmorph_nurbs::{KnotVector, NurbsCurve, Surface};
/// use nalgebra::{Point3, Vector3};
/// // A segment parallel to z at distance 1 sweeps a cylinder.
/// let line = NurbsCurve::new(
///     1,
///     KnotVector::try_new(vec![0., 0., 1., 1.]).unwrap(),
///     vec![Point3::new(1., 0., 0.), Point3::new(1., 0., 2.)],
///     None,
/// );
/// let rev = Revolution::try_new(line, Point3::origin(), Vector3::z()).unwrap();
/// let s = rev.to_nurbs(0.0..=std::f64::consts::PI, 0.0..=1.0).unwrap().surface;
/// let p = s.eval(2.0, 0.5);
/// assert!((p.x.hypot(p.y) - 1.0).abs() < 1e-14 && (p.z - 1.0).abs() < 1e-14);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Revolution {
    curve: NurbsCurve,
    axis_point: Point3<f64>,
    axis_dir: Vector3<f64>,
}

impl Revolution {
    /// Revolves `curve` about the axis through `axis_point` along `axis_direction`
    /// (normalised).
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for a zero or non-finite direction or a non-finite point.
    pub fn try_new(curve: NurbsCurve, axis_point: Point3<f64>, axis_direction: Vector3<f64>) -> Result<Self> {
        let axis_dir = unit(axis_direction)
            .ok_or(Error::Analytic { shape: "surface of revolution", reason: "zero or non-finite axis direction" })?;
        if !axis_point.coords.iter().all(|c| c.is_finite()) {
            return Err(Error::Analytic { shape: "surface of revolution", reason: "non-finite axis point" });
        }
        Ok(Self { curve, axis_point, axis_dir })
    }
    /// The meridian curve `C(v)`.
    pub fn curve(&self) -> &NurbsCurve {
        &self.curve
    }
    /// A point of the axis.
    pub fn axis_point(&self) -> Point3<f64> {
        self.axis_point
    }
    /// The unit axis direction.
    pub fn axis_direction(&self) -> Vector3<f64> {
        self.axis_dir
    }

    /// `(a D, r, D × r)` for a point `q`: its axial part and radial frame.
    fn split_point(&self, q: &Point3<f64>) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let d = self.axis_dir;
        let rel = q - self.axis_point;
        let axial = d * rel.dot(&d);
        let r = rel - axial;
        (axial, r, d.cross(&r))
    }
}

impl AnalyticSurface for Revolution {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let (s, c) = u.sin_cos();
        let der = self.curve.derivs(v, 1);
        let (axial, r, dr) = self.split_point(&Point3::from(der[0]));
        let d = self.axis_dir;
        let t = der[1];
        let t_ax = d * t.dot(&d);
        SurfacePointD1 {
            point: self.axis_point + axial + r * c + dr * s,
            du: -r * s + dr * c,
            dv: t_ax + (t - t_ax) * c + d.cross(&t) * s,
        }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let arc = unit_arc("surface of revolution", &u)?;
        let c = trim("surface of revolution", &self.curve, &v)?;
        let n_v = c.control_points().len();
        let n_u = arc.points.len();
        let mut points = Vec::with_capacity(n_u * n_v);
        let mut weights = Vec::with_capacity(n_u * n_v);
        for (cu, wu) in arc.points.iter().zip(&arc.weights) {
            for (j, q) in c.control_points().iter().enumerate() {
                let (axial, r, dr) = self.split_point(q);
                points.push(self.axis_point + axial + r * cu[0] + dr * cu[1]);
                weights.push(wu * c.weights().map_or(1.0, |w| w[j]));
            }
        }
        let surface = NurbsSurface::try_new(
            (2, c.degree()),
            (KnotVector::try_new(arc.knots)?, c.knots().clone()),
            (n_u, n_v),
            points,
            Some(weights),
        )?;
        Ok(ExactSurface { surface, u_map: arc.map, v_map: ParamMap::Identity })
    }
}

/// A surface of linear extrusion `P(u,v) = C(u) + v·D` with `D` a unit direction (OCCT
/// `Geom_SurfaceOfLinearExtrusion`, whose direction is a `gp_Dir`).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticSurface, Extrusion};
/// use cadmorph_nurbs::{KnotVector, NurbsCurve, Surface};
/// use nalgebra::{Point3, Vector3};
/// let c = NurbsCurve::new(
///     2,
///     KnotVector::try_new(vec![0., 0., 0., 1., 1., 1.]).unwrap(),
///     vec![Point3::new(0., 0., 0.), Point3::new(1., 1., 0.), Point3::new(2., 0., 0.)],
///     None,
/// );
/// let ext = Extrusion::try_new(c, Vector3::new(0.0, 0.0, 5.0)).unwrap(); // normalised to +z
/// let s = ext.to_nurbs(0.0..=1.0, -1.0..=1.0).unwrap().surface;
/// assert_eq!(s.eval(0.5, 0.75), Point3::new(1.0, 0.5, 0.75));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Extrusion {
    curve: NurbsCurve,
    direction: Vector3<f64>,
}

impl Extrusion {
    /// Extrudes `curve` along `direction` (normalised, so `v` is a length).
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for a zero or non-finite direction.
    pub fn try_new(curve: NurbsCurve, direction: Vector3<f64>) -> Result<Self> {
        let direction = unit(direction)
            .ok_or(Error::Analytic { shape: "surface of linear extrusion", reason: "zero or non-finite direction" })?;
        Ok(Self { curve, direction })
    }
    /// The directrix `C(u)`.
    pub fn curve(&self) -> &NurbsCurve {
        &self.curve
    }
    /// The unit direction `D`.
    pub fn direction(&self) -> Vector3<f64> {
        self.direction
    }
}

impl AnalyticSurface for Extrusion {
    fn d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        let der = self.curve.derivs(u, 1);
        SurfacePointD1 { point: Point3::from(der[0] + self.direction * v), du: der[1], dv: self.direction }
    }

    fn to_nurbs(&self, u: RangeInclusive<f64>, v: RangeInclusive<f64>) -> Result<ExactSurface> {
        let c = trim("surface of linear extrusion", &self.curve, &u)?;
        let (v0, v1) = check_linear("surface of linear extrusion", &v, "empty or non-finite v range")?;
        let n_u = c.control_points().len();
        let mut points = Vec::with_capacity(2 * n_u);
        for q in c.control_points() {
            points.push(q + self.direction * v0);
            points.push(q + self.direction * v1);
        }
        let weights = c.weights().map(|w| w.iter().flat_map(|&w| [w, w]).collect());
        let surface = NurbsSurface::try_new(
            (c.degree(), 1),
            (c.knots().clone(), KnotVector::try_new(vec![v0, v0, v1, v1])?),
            (n_u, 2),
            points,
            weights,
        )?;
        Ok(ExactSurface { surface, u_map: ParamMap::Identity, v_map: ParamMap::Identity })
    }
}

/// An infinite line `C(u) = O + u·D`, `D` unit (OCCT `Geom_Line`).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticCurve, Line};
/// use cadmorph_nurbs::Curve;
/// use nalgebra::{Point3, Vector3};
/// let line = Line::try_new(Point3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 3.0, 4.0)).unwrap();
/// let seg = line.to_nurbs(0.0..=5.0).unwrap().curve;
/// assert_eq!(seg.eval(5.0), Point3::new(1.0, 3.0, 4.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    origin: Point3<f64>,
    direction: Vector3<f64>,
}

impl Line {
    /// The line through `origin` along `direction` (normalised, so `u` is a length).
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] for a zero or non-finite direction or a non-finite origin.
    pub fn try_new(origin: Point3<f64>, direction: Vector3<f64>) -> Result<Self> {
        let direction =
            unit(direction).ok_or(Error::Analytic { shape: "line", reason: "zero or non-finite direction" })?;
        if !origin.coords.iter().all(|c| c.is_finite()) {
            return Err(Error::Analytic { shape: "line", reason: "non-finite origin" });
        }
        Ok(Self { origin, direction })
    }
}

impl AnalyticCurve for Line {
    fn eval(&self, t: f64) -> Point3<f64> {
        self.origin + self.direction * t
    }
    fn deriv(&self, _t: f64) -> Vector3<f64> {
        self.direction
    }
    fn to_nurbs(&self, range: RangeInclusive<f64>) -> Result<ExactCurve> {
        let (t0, t1) = check_linear("line", &range, "empty or non-finite parameter range")?;
        let curve = NurbsCurve::try_new(
            1,
            KnotVector::try_new(vec![t0, t0, t1, t1])?,
            vec![self.eval(t0), self.eval(t1)],
            None,
        )?;
        Ok(ExactCurve { curve, map: ParamMap::Identity })
    }
}

/// A circle `C(u) = O + R (cos u·X + sin u·Y)` (OCCT `Geom_Circle`).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticCurve, Circle, Placement};
/// use cadmorph_nurbs::Curve;
/// let circle = Circle::try_new(Placement::standard(), 2.0).unwrap();
/// let exact = circle.to_nurbs(0.0..=std::f64::consts::TAU).unwrap();
/// assert_eq!(exact.curve.control_points().len(), 9);
/// let t = exact.nurbs_param(1.0);
/// assert!((exact.curve.eval(t) - circle.eval(1.0)).norm() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    placement: Placement,
    radius: f64,
}

impl Circle {
    /// The circle of radius `radius` about the placement's Z axis, in its XY plane.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] unless `radius` is positive and finite.
    pub fn try_new(placement: Placement, radius: f64) -> Result<Self> {
        positive("circle", radius, "radius must be positive and finite")?;
        Ok(Self { placement, radius })
    }
}

/// The arc `O + a cos u·X + b sin u·Y` over `range` as an exact NURBS.
fn elliptic_arc(shape: &'static str, f: &Placement, a: f64, b: f64, range: &RangeInclusive<f64>) -> Result<ExactCurve> {
    let arc = unit_arc(shape, range)?;
    let points = arc.points.iter().map(|c| f.to_world(a * c[0], b * c[1], 0.0)).collect();
    let curve = NurbsCurve::try_new(2, KnotVector::try_new(arc.knots)?, points, Some(arc.weights))?;
    Ok(ExactCurve { curve, map: arc.map })
}

impl AnalyticCurve for Circle {
    fn eval(&self, t: f64) -> Point3<f64> {
        let (s, c) = t.sin_cos();
        self.placement.to_world(self.radius * c, self.radius * s, 0.0)
    }
    fn deriv(&self, t: f64) -> Vector3<f64> {
        let (s, c) = t.sin_cos();
        self.placement.vec(-self.radius * s, self.radius * c, 0.0)
    }
    fn to_nurbs(&self, range: RangeInclusive<f64>) -> Result<ExactCurve> {
        elliptic_arc("circle", &self.placement, self.radius, self.radius, &range)
    }
}

/// An ellipse `C(u) = O + a cos u·X + b sin u·Y`, `a ≥ b > 0` (OCCT `Geom_Ellipse`:
/// major radius along X).
///
/// The exact NURBS form is the affine image of the circular arcs, so the angle map
/// ([`ParamMap`]) is the circle's one with `u` the eccentric angle.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::{AnalyticCurve, Ellipse, Placement};
/// use cadmorph_nurbs::Curve;
/// let e = Ellipse::try_new(Placement::standard(), 3.0, 1.0).unwrap();
/// let c = e.to_nurbs(0.0..=std::f64::consts::PI).unwrap().curve;
/// let p = c.eval(0.4);
/// assert!(((p.x / 3.0).powi(2) + p.y * p.y - 1.0).abs() < 1e-14);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    placement: Placement,
    major_radius: f64,
    minor_radius: f64,
}

impl Ellipse {
    /// The ellipse with semi-axes `major_radius` along X and `minor_radius` along Y.
    ///
    /// # Errors
    ///
    /// [`Error::Analytic`] unless `major_radius ≥ minor_radius > 0`, both finite.
    pub fn try_new(placement: Placement, major_radius: f64, minor_radius: f64) -> Result<Self> {
        positive("ellipse", minor_radius, "minor radius must be positive and finite")?;
        if !(major_radius.is_finite() && major_radius >= minor_radius) {
            return Err(Error::Analytic {
                shape: "ellipse",
                reason: "major radius must be finite and >= minor radius",
            });
        }
        Ok(Self { placement, major_radius, minor_radius })
    }
}

impl AnalyticCurve for Ellipse {
    fn eval(&self, t: f64) -> Point3<f64> {
        let (s, c) = t.sin_cos();
        self.placement.to_world(self.major_radius * c, self.minor_radius * s, 0.0)
    }
    fn deriv(&self, t: f64) -> Vector3<f64> {
        let (s, c) = t.sin_cos();
        self.placement.vec(-self.major_radius * s, self.minor_radius * c, 0.0)
    }
    fn to_nurbs(&self, range: RangeInclusive<f64>) -> Result<ExactCurve> {
        elliptic_arc("ellipse", &self.placement, self.major_radius, self.minor_radius, &range)
    }
}

/// OCCT's X direction for a frame given only its main direction `n` (`gp_Ax2(P, N)`):
/// perpendicular to `n`, built by zeroing the component of `n` of smallest magnitude and
/// swapping the other two with a sign change. IGES and STEP placements without a
/// reference direction use it, so their analytic faces get OCCT's parameterisation.
/// A zero `n` gives the x axis.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::analytic::occt_default_x;
/// use cadmorph_nurbs::math::Vector3;
/// assert_eq!(occt_default_x(&Vector3::z()), Vector3::new(1.0, 0.0, 0.0));
/// ```
pub fn occt_default_x(n: &Vector3<f64>) -> Vector3<f64> {
    let (a, b, c) = (n.x, n.y, n.z);
    let (aa, ba, ca) = (a.abs(), b.abs(), c.abs());
    let v = if ba <= aa && ba <= ca {
        if aa > ca {
            Vector3::new(-c, 0.0, a)
        } else {
            Vector3::new(c, 0.0, -a)
        }
    } else if aa <= ba && aa <= ca {
        if ba > ca {
            Vector3::new(0.0, -c, b)
        } else {
            Vector3::new(0.0, c, -b)
        }
    } else if aa > ba {
        Vector3::new(-b, a, 0.0)
    } else {
        Vector3::new(b, -a, 0.0)
    };
    if v.norm() > 0.0 {
        v
    } else {
        Vector3::x()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Surface;
    use std::f64::consts::{FRAC_PI_3, PI};

    /// The NURBS forms are exact: only rounding separates them from the closed forms.
    const EXACT: f64 = 1e-12;

    /// Parameters: a dense uniform grid, the range ends and every knot value.
    fn params(range: (f64, f64), knots: &[f64], n: usize) -> Vec<f64> {
        let mut t: Vec<f64> = (0..=n).map(|i| range.0 + (range.1 - range.0) * i as f64 / n as f64).collect();
        t.extend(knots.iter().copied().filter(|k| *k >= range.0 && *k <= range.1));
        t
    }

    fn frame() -> Placement {
        Placement::try_new(Point3::new(1.0, -2.0, 0.5), Vector3::new(1.0, 2.0, 2.0), Vector3::new(0.3, -1.0, 0.7))
            .unwrap()
    }

    /// Signed distance of a point from an analytic surface given implicitly.
    type Implicit<'a> = dyn Fn(&Point3<f64>) -> f64 + 'a;

    /// Checks an exact conversion against the closed form:
    /// 1. every NURBS point (on a dense grid including every knot) lies on the analytic
    ///    surface — `on_surface`, when the surface has an implicit form, returns its
    ///    distance — and equals the closed form at the mapped-back parameters;
    /// 2. at analytic parameters, the NURBS evaluated through the map equals the closed form;
    /// 3. normals agree in direction.
    fn check_surface(
        shape: &dyn AnalyticSurface,
        u: (f64, f64),
        v: (f64, f64),
        scale: f64,
        on_surface: Option<&Implicit<'_>>,
    ) -> ExactSurface {
        let exact = shape.to_nurbs(u.0..=u.1, v.0..=v.1).unwrap();
        let s = &exact.surface;
        let (du, dv) = s.domain();
        assert_eq!((*du.start(), *du.end(), *dv.start(), *dv.end()), (u.0, u.1, v.0, v.1));
        let tol = EXACT * scale;
        for &a in &params(u, s.u_knots().as_slice(), 23) {
            for &b in &params(v, s.v_knots().as_slice(), 19) {
                // NURBS parameters (a, b).
                let p = s.eval(a, b);
                if let Some(on_surface) = on_surface {
                    let dist = on_surface(&p);
                    assert!(dist.abs() <= tol, "off surface by {dist} at ({a}, {b})");
                }
                let (ua, va) = exact.analytic_params(a, b);
                let q = shape.eval(ua, va);
                assert!((p - q).norm() <= tol, "mapped-back point differs by {} at ({a}, {b})", (p - q).norm());
                // Analytic parameters (a, b).
                let (sa, sb) = exact.nurbs_params(a, b);
                let d = (s.eval(sa, sb) - shape.eval(a, b)).norm();
                assert!(d <= tol, "OCCT point differs by {d} at ({a}, {b})");
                // Compare normals away from poles and apexes, where both are well defined.
                let d = s.eval_d1(sa, sb);
                let big = d.du.norm().max(d.dv.norm());
                let regular = d.du.norm() > 1e-6 * big && d.dv.norm() > 1e-6 * big;
                if let (true, Some(n1), Some(n2)) = (regular, s.normal(sa, sb), shape.normal(a, b)) {
                    assert!(n1.dot(&n2) > 1.0 - 1e-9, "normals differ at ({a}, {b}): {n1:?} vs {n2:?}");
                }
            }
        }
        exact
    }

    #[test]
    fn arc_map_is_the_tan_formula() {
        for (start, end) in [(0.0, TAU), (-1.0, 0.5), (2.0, 2.0 + 3.0 * FRAC_PI_2 + 0.1), (0.3, 0.30001)] {
            let arc = unit_arc("test", &(start..=end)).unwrap();
            let c = NurbsCurve::new(
                2,
                KnotVector::try_new(arc.knots.clone()).unwrap(),
                arc.points.iter().map(|p| Point3::new(p[0], p[1], 0.0)).collect(),
                Some(arc.weights.clone()),
            );
            let ParamMap::Arc { segments, .. } = arc.map else { panic!("arc map expected") };
            assert!((end - start) / segments as f64 <= FRAC_PI_2 * (1.0 + 1e-12));
            for &phi in &params((start, end), &arc.knots, 101) {
                let t = arc.map.to_nurbs(phi);
                let p = c.eval(t);
                assert!((p.x - phi.cos()).abs() < 1e-15 && (p.y - phi.sin()).abs() < 1e-15, "{phi}: {p}");
                assert!((arc.map.to_analytic(t) - phi).abs() < 1e-14);
            }
            // Identity at every joint knot.
            for &k in &arc.knots {
                assert_eq!(arc.map.to_nurbs(k), k);
                assert_eq!(arc.map.to_analytic(k), k);
            }
        }
    }

    #[test]
    fn segment_counts() {
        let count = |span: f64| match unit_arc("t", &(0.0..=span)).unwrap().map {
            ParamMap::Arc { segments, .. } => segments,
            ParamMap::Identity => 0,
        };
        assert_eq!(count(FRAC_PI_2), 1);
        assert_eq!(count(FRAC_PI_2 + 1e-9), 2);
        assert_eq!(count(PI), 2);
        assert_eq!(count(TAU), 4);
        assert_eq!(count(0.001), 1);
    }

    #[test]
    fn plane_is_exact() {
        let plane = Plane::new(frame());
        let o = frame().origin();
        let z = frame().z_dir();
        let exact = check_surface(&plane, (-2.0, 3.0), (0.5, 4.0), 10.0, Some(&|p| (p - o).dot(&z)));
        assert_eq!(exact.surface.u_degree(), 1);
        assert!(!exact.surface.is_rational());
        let n = exact.surface.normal(0.0, 1.0).unwrap();
        assert!((n.into_inner() - plane.normal(0.0, 1.0).unwrap().into_inner()).norm() < 1e-15);
    }

    fn radial(f: &Placement, p: &Point3<f64>) -> (f64, f64) {
        let rel = p - f.origin();
        let z = rel.dot(&f.z_dir());
        ((rel - f.z_dir() * z).norm(), z)
    }

    #[test]
    fn cylinder_is_exact() {
        let f = frame();
        let cyl = Cylinder::try_new(f, 2.5).unwrap();
        for u in [(0.0, TAU), (-0.5, 1.0), (1.0, 1.0 + 5.0 * FRAC_PI_3), (3.0, 3.2)] {
            check_surface(&cyl, u, (-1.0, 3.0), 10.0, Some(&|p| radial(&f, p).0 - 2.5));
        }
        // Outward normal with the direct frame.
        let exact = cyl.to_nurbs(0.0..=TAU, 0.0..=1.0).unwrap();
        for u in [0.1, 1.7, 4.0] {
            let (s, t) = exact.nurbs_params(u, 0.4);
            let n = exact.surface.normal(s, t).unwrap();
            let p = exact.surface.eval(s, t);
            let out = (p - f.origin()) - f.z_dir() * (p - f.origin()).dot(&f.z_dir());
            assert!(n.dot(&out.normalize()) > 1.0 - 1e-12);
        }
    }

    #[test]
    fn cone_is_exact() {
        let f = frame();
        for (r, a) in [(1.0, 0.3), (2.0, -0.7), (0.0, 1.2)] {
            let cone = Cone::try_new(f, r, a).unwrap();
            // Implicit form: ρ = R + z tan a.
            let on = move |p: &Point3<f64>| {
                let (rho, z) = radial(&f, p);
                (rho - (r + z * a.tan()).abs()) * a.cos()
            };
            let v = if a < 0.0 { (-1.0, 2.0) } else { (0.0, 2.0) };
            check_surface(&cone, (0.0, TAU), v, 10.0, Some(&on));
            check_surface(&cone, (0.4, 2.0), v, 10.0, Some(&on));
        }
    }

    #[test]
    fn sphere_is_exact() {
        let f = frame();
        let sphere = Sphere::try_new(f, 3.0).unwrap();
        let on = |p: &Point3<f64>| (p - f.origin()).norm() - 3.0;
        check_surface(&sphere, (0.0, TAU), (-FRAC_PI_2, FRAC_PI_2), 10.0, Some(&on));
        check_surface(&sphere, (-1.0, 0.2), (0.1, 1.4), 10.0, Some(&on));
        // Outward normal.
        let exact = sphere.to_nurbs(0.0..=TAU, -FRAC_PI_2..=FRAC_PI_2).unwrap();
        let (s, t) = exact.nurbs_params(2.0, 0.3);
        let p = exact.surface.eval(s, t);
        assert!(exact.surface.normal(s, t).unwrap().dot(&(p - f.origin()).normalize()) > 1.0 - 1e-12);
    }

    #[test]
    fn torus_is_exact() {
        let f = frame();
        let torus = Torus::try_new(f, 4.0, 1.5).unwrap();
        let on = |p: &Point3<f64>| {
            let (rho, z) = radial(&f, p);
            (rho - 4.0).hypot(z) - 1.5
        };
        check_surface(&torus, (0.0, TAU), (0.0, TAU), 10.0, Some(&on));
        check_surface(&torus, (1.0, 2.5), (-PI, 0.5), 10.0, Some(&on));
    }

    fn sample_curve(rational: bool) -> NurbsCurve {
        NurbsCurve::new(
            3,
            KnotVector::try_new(vec![0., 0., 0., 0., 0.4, 1., 1., 1., 1.]).unwrap(),
            vec![
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(2.0, 0.5, 1.0),
                Point3::new(1.5, -0.5, 2.0),
                Point3::new(3.0, 1.0, 3.0),
                Point3::new(0.5, 0.0, 4.0),
            ],
            rational.then(|| vec![1.0, 0.7, 1.3, 0.9, 1.0]),
        )
    }

    #[test]
    fn revolution_is_exact() {
        let axis_point = Point3::new(0.5, 0.2, -1.0);
        let axis = Vector3::new(0.1, 0.2, 1.0).normalize();
        for rational in [false, true] {
            let curve = sample_curve(rational);
            let rev = Revolution::try_new(curve.clone(), axis_point, axis * 3.0).unwrap();
            // No implicit form: `check_surface` compares with the closed form at the
            // mapped-back parameters, and the loop below checks the rotation invariants.
            for (u, v) in [((0.0, TAU), (0.0, 1.0)), ((-0.3, 2.0), (0.2, 0.9))] {
                let exact = check_surface(&rev, u, v, 10.0, None);
                // Every NURBS v iso is a rotated copy of the curve: same axial and radial coordinates.
                for &t in &params(v, &[0.4], 13) {
                    let c = curve.eval(t);
                    let (ax, r) =
                        (axis.dot(&(c - axis_point)), ((c - axis_point) - axis * axis.dot(&(c - axis_point))).norm());
                    for &s in &params(u, exact.surface.u_knots().as_slice(), 11) {
                        let p = exact.surface.eval(s, t);
                        let (ax2, r2) = (
                            axis.dot(&(p - axis_point)),
                            ((p - axis_point) - axis * axis.dot(&(p - axis_point))).norm(),
                        );
                        assert!((ax - ax2).abs() < 1e-12 && (r - r2).abs() < 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn extrusion_is_exact() {
        for rational in [false, true] {
            let curve = sample_curve(rational);
            let d = Vector3::new(0.3, -1.0, 0.2);
            let ext = Extrusion::try_new(curve.clone(), d * 7.0).unwrap();
            let dn = d.normalize();
            // No implicit form: `check_surface` compares with the closed form, and the loop
            // below checks that the offset from the curve is v·D.
            let exact = check_surface(&ext, (0.1, 0.8), (-2.0, 1.0), 10.0, None);
            for &u in &params((0.1, 0.8), &[0.4], 17) {
                let off = exact.surface.eval(u, 0.7) - curve.eval(u);
                assert!((off - dn * 0.7).norm() < 1e-12);
            }
            check_surface(&ext, (0.0, 1.0), (0.0, 1.0), 10.0, None);
        }
    }

    #[test]
    fn curves_are_exact() {
        let f = frame();
        let circle = Circle::try_new(f, 2.0).unwrap();
        let ellipse = Ellipse::try_new(f, 3.0, 1.25).unwrap();
        let line = Line::try_new(Point3::new(1.0, 2.0, 3.0), Vector3::new(1.0, 1.0, 0.0)).unwrap();
        let curves: [(&dyn AnalyticCurve, (f64, f64)); 5] = [
            (&circle, (0.0, TAU)),
            (&circle, (-2.0, 0.5)),
            (&ellipse, (0.0, TAU)),
            (&ellipse, (1.0, 4.0)),
            (&line, (-3.0, 2.0)),
        ];
        for (c, (t0, t1)) in curves {
            let exact = c.to_nurbs(t0..=t1).unwrap();
            assert_eq!(exact.curve.domain(), t0..=t1);
            for &t in &params((t0, t1), exact.curve.knots().as_slice(), 97) {
                let p = exact.curve.eval(exact.nurbs_param(t));
                assert!((p - c.eval(t)).norm() < EXACT * 10.0, "{t}");
                let q = exact.curve.eval(t);
                assert!((q - c.eval(exact.analytic_param(t))).norm() < EXACT * 10.0);
                // Tangents point the same way.
                let d = exact.curve.derivs(exact.nurbs_param(t), 1)[1];
                assert!(d.normalize().dot(&c.deriv(t).normalize()) > 1.0 - 1e-12);
            }
        }
        // Closed-form checks independent of the map.
        let e = ellipse.to_nurbs(0.0..=TAU).unwrap().curve;
        for i in 0..=50 {
            let p = e.eval(i as f64 * TAU / 50.0) - f.origin();
            let (x, y, z) = (p.dot(&f.x_dir()), p.dot(&f.y_dir()), p.dot(&f.z_dir()));
            assert!(((x / 3.0).powi(2) + (y / 1.25).powi(2) - 1.0).abs() < EXACT && z.abs() < EXACT);
        }
    }

    #[test]
    fn d1_matches_central_differences() {
        let f = frame();
        let shapes: Vec<Box<dyn AnalyticSurface>> = vec![
            Box::new(Plane::new(f)),
            Box::new(Cylinder::try_new(f, 2.0).unwrap()),
            Box::new(Cone::try_new(f, 1.0, 0.4).unwrap()),
            Box::new(Sphere::try_new(f, 2.0).unwrap()),
            Box::new(Torus::try_new(f, 3.0, 1.0).unwrap()),
            Box::new(Revolution::try_new(sample_curve(true), Point3::origin(), Vector3::z()).unwrap()),
            Box::new(Extrusion::try_new(sample_curve(true), Vector3::x()).unwrap()),
        ];
        let h = 1e-5;
        for s in &shapes {
            let (u, v) = (0.6, 0.3);
            let d = s.d1(u, v);
            let fu = (s.eval(u + h, v) - s.eval(u - h, v)) / (2.0 * h);
            let fv = (s.eval(u, v + h) - s.eval(u, v - h)) / (2.0 * h);
            assert!((d.du - fu).norm() < 1e-8 && (d.dv - fv).norm() < 1e-8, "{:?} {:?} {fu:?} {fv:?}", d.du, d.dv);
        }
    }

    #[test]
    fn bad_input_is_an_analytic_error() {
        let f = Placement::standard();
        let analytic = |r: Result<ExactSurface>| matches!(r, Err(Error::Analytic { .. }));
        assert!(matches!(Cylinder::try_new(f, 0.0), Err(Error::Analytic { shape: "cylinder", .. })));
        assert!(matches!(Cylinder::try_new(f, -1.0), Err(Error::Analytic { .. })));
        assert!(matches!(Sphere::try_new(f, f64::NAN), Err(Error::Analytic { .. })));
        assert!(matches!(Torus::try_new(f, 1.0, 0.0), Err(Error::Analytic { .. })));
        assert!(matches!(Cone::try_new(f, -1.0, 0.3), Err(Error::Analytic { .. })));
        assert!(matches!(Cone::try_new(f, 1.0, FRAC_PI_2), Err(Error::Analytic { .. })));
        assert!(matches!(Cone::try_new(f, 1.0, 0.0), Err(Error::Analytic { .. })));
        assert!(matches!(Circle::try_new(f, 0.0), Err(Error::Analytic { .. })));
        assert!(matches!(Ellipse::try_new(f, 1.0, 2.0), Err(Error::Analytic { .. })));
        assert!(matches!(
            Placement::try_new(Point3::origin(), Vector3::zeros(), Vector3::x()),
            Err(Error::Analytic { shape: "placement", .. })
        ));
        assert!(Placement::try_new(Point3::origin(), Vector3::z(), Vector3::z() * 2.0).is_err());
        assert!(Revolution::try_new(sample_curve(false), Point3::origin(), Vector3::zeros()).is_err());
        assert!(Extrusion::try_new(sample_curve(false), Vector3::zeros()).is_err());
        assert!(Line::try_new(Point3::origin(), Vector3::zeros()).is_err());
        let cyl = Cylinder::try_new(f, 1.0).unwrap();
        assert!(analytic(cyl.to_nurbs(1.0..=1.0, 0.0..=1.0)));
        assert!(analytic(cyl.to_nurbs(0.0..=TAU + 1e-6, 0.0..=1.0)));
        assert!(analytic(cyl.to_nurbs(0.0..=1.0, 2.0..=1.0)));
        assert!(analytic(cyl.to_nurbs(0.0..=f64::INFINITY, 0.0..=1.0)));
        assert!(cyl.to_nurbs(0.0..=TAU, 0.0..=1.0).is_ok());
        let sphere = Sphere::try_new(f, 1.0).unwrap();
        assert!(analytic(sphere.to_nurbs(0.0..=1.0, -2.0..=0.0)));
        let rev = Revolution::try_new(sample_curve(false), Point3::origin(), Vector3::z()).unwrap();
        assert!(analytic(rev.to_nurbs(0.0..=1.0, 0.0..=1.5)));
        assert!(analytic(Plane::new(f).to_nurbs(0.0..=0.0, 0.0..=1.0)));
        let e = Error::Analytic { shape: "cylinder", reason: "radius must be positive and finite" };
        assert_eq!(e.to_string(), "analytic cylinder: radius must be positive and finite");
    }
}
