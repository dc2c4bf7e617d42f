//! Views of curve, surface, point, direction and transformation entities.

use nalgebra::{Matrix4, Point3, Vector3};

use super::Cursor;
use crate::document::EntityId;
use crate::error::Result;

/// 100 circular arc, in the plane `z = z_t` of its definition space, counter-clockwise
/// from `start` to `end` about `center`.
#[derive(Debug, Clone, PartialEq)]
pub struct CircularArc {
    /// Plane height `ZT`.
    pub z: f64,
    /// Centre `(x, y)`.
    pub center: [f64; 2],
    /// Start point `(x, y)`.
    pub start: [f64; 2],
    /// End point `(x, y)` (equal to start: a full circle).
    pub end: [f64; 2],
}

impl CircularArc {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let z = c.real("ZT")?;
        let center = [c.real("X1")?, c.real("Y1")?];
        let start = [c.real("X2")?, c.real("Y2")?];
        let end = [c.real("X3")?, c.real("Y3")?];
        Ok(Self { z, center, start, end })
    }
}

/// 102 composite curve: its pieces in order.
#[derive(Debug, Clone, PartialEq)]
pub struct CompositeCurve {
    /// The constituent curves.
    pub curves: Vec<EntityId>,
}

impl CompositeCurve {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let n = c.count("N (curves)", 1)?;
        Ok(Self { curves: c.pointers("curve", n)? })
    }
}

/// 104 conic arc `A x² + B xy + C y² + D x + E y + F = 0` in the plane `z = z_t`
/// (form 1 ellipse, 2 hyperbola, 3 parabola).
#[derive(Debug, Clone, PartialEq)]
pub struct ConicArc {
    /// Form number.
    pub form: i64,
    /// `[A, B, C, D, E, F]`.
    pub coefficients: [f64; 6],
    /// Plane height.
    pub z: f64,
    /// Start point `(x, y)`.
    pub start: [f64; 2],
    /// End point `(x, y)`.
    pub end: [f64; 2],
}

impl ConicArc {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let mut k = [0.0; 6];
        for (x, what) in k.iter_mut().zip(["A", "B", "C", "D", "E", "F"]) {
            *x = c.real(what)?;
        }
        let z = c.real("ZT")?;
        let start = [c.real("X1")?, c.real("Y1")?];
        let end = [c.real("X2")?, c.real("Y2")?];
        Ok(Self { form, coefficients: k, z, start, end })
    }
}

/// 106 copious data: points (forms 1, 11: `(x, y)` at a common `z`; 2, 12: `(x, y, z)`;
/// 3, 13: with a vector each, ignored here; 63: closed planar curve).
#[derive(Debug, Clone, PartialEq)]
pub struct CopiousData {
    /// Form number.
    pub form: i64,
    /// Data type flag IP (1, 2 or 3).
    pub kind: i64,
    /// The points.
    pub points: Vec<Point3<f64>>,
}

impl CopiousData {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let kind = c.int("IP")?;
        let n = c.int("N")?;
        let (n, per) = match kind {
            1 => {
                let per = 2;
                let n = checked_len(c, "N (points)", n, per, 1)?;
                let z = c.real("ZT")?;
                let mut pts = Vec::with_capacity(n);
                for _ in 0..n {
                    pts.push(Point3::new(c.real("X")?, c.real("Y")?, z));
                }
                return Ok(Self { form, kind, points: pts });
            }
            2 => (n, 3),
            _ => (n, 6),
        };
        let n = checked_len(c, "N (points)", n, per, 0)?;
        let mut pts = Vec::with_capacity(n);
        for _ in 0..n {
            pts.push(c.point("point")?);
            for _ in 3..per {
                c.real("vector")?;
            }
        }
        Ok(Self { form, kind, points: pts })
    }
}

fn checked_len(c: &Cursor, what: &'static str, n: i64, per: usize, extra: usize) -> Result<usize> {
    let left = c.remaining();
    match usize::try_from(n) {
        Ok(k) if k.checked_mul(per).and_then(|m| m.checked_add(extra)).is_some_and(|m| m <= left) => Ok(k),
        _ => Err(crate::error::Error::Count { at: c.e.position(c.i - 1), what, count: n, remaining: left }),
    }
}

/// 108 plane `A x + B y + C z = D`, unbounded (form 0) or bounded by a closed curve
/// (forms 1 and −1, a hole).
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// Form number.
    pub form: i64,
    /// `[A, B, C, D]`.
    pub coefficients: [f64; 4],
    /// The bounding curve (forms ±1).
    pub boundary: Option<EntityId>,
    /// Display symbol location.
    pub symbol: Point3<f64>,
    /// Display symbol size.
    pub symbol_size: f64,
}

impl Plane {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let coefficients = [c.real("A")?, c.real("B")?, c.real("C")?, c.real("D")?];
        let boundary = c.pointer("PTR (bounding curve)")?;
        let symbol = Point3::new(c.real_or("X", 0.0)?, c.real_or("Y", 0.0)?, c.real_or("Z", 0.0)?);
        let symbol_size = c.real_or("SIZE", 0.0)?;
        Ok(Self { form, coefficients, boundary, symbol, symbol_size })
    }
}

/// 110 line from `start` to `end` (form 0 segment, 1 ray, 2 infinite line).
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Form number.
    pub form: i64,
    /// First point.
    pub start: Point3<f64>,
    /// Second point.
    pub end: Point3<f64>,
}

impl Line {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        Ok(Self { form, start: c.point("start")?, end: c.point("end")? })
    }
}

/// 112 parametric spline curve: piecewise cubic polynomials
/// `x(s) = AX + BX s + CX s² + DX s³`, `s = t − T(i)`, per segment.
#[derive(Debug, Clone, PartialEq)]
pub struct ParametricSplineCurve {
    /// Spline type CTYPE.
    pub spline_type: i64,
    /// Continuity H.
    pub continuity: i64,
    /// Dimension NDIM (2 or 3).
    pub dimension: i64,
    /// Break points `T(1) … T(N+1)`.
    pub breakpoints: Vec<f64>,
    /// Per segment, per coordinate, `[A, B, C, D]`.
    pub coefficients: Vec<[[f64; 4]; 3]>,
}

impl ParametricSplineCurve {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let spline_type = c.int("CTYPE")?;
        let continuity = c.int("H")?;
        let dimension = c.int("NDIM")?;
        let n = c.count("N (segments)", 13)?;
        let breakpoints = c.reals("T (break points)", n + 1)?;
        let mut coefficients = Vec::with_capacity(n);
        for _ in 0..n {
            let mut seg = [[0.0; 4]; 3];
            for coord in &mut seg {
                for k in coord.iter_mut() {
                    *k = c.real("coefficient")?;
                }
            }
            coefficients.push(seg);
        }
        Ok(Self { spline_type, continuity, dimension, breakpoints, coefficients })
    }
}

/// 114 parametric spline surface: bicubic polynomial patches
/// `x(s, t) = Σ_{k,l ≤ 3} a_kl s^k t^l`, `s = u − TU(i)`, `t = v − TV(j)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParametricSplineSurface {
    /// Spline boundary type CTYPE.
    pub spline_type: i64,
    /// Patch type PTYPE.
    pub patch_type: i64,
    /// Break points in u, `TU(1) … TU(M+1)`.
    pub u_breakpoints: Vec<f64>,
    /// Break points in v, `TV(1) … TV(N+1)`.
    pub v_breakpoints: Vec<f64>,
    /// Patch `(i, j)` at `i * N + j`: per coordinate the 16 coefficients in IGES order
    /// (`a00, a10, a20, a30, a01, …, a33`, u power fastest).
    pub patches: Vec<[[f64; 16]; 3]>,
}

impl ParametricSplineSurface {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let spline_type = c.int("CTYPE")?;
        let patch_type = c.int("PTYPE")?;
        let m = c.count("M (u segments)", 1)?;
        let n = c.count("N (v segments)", 1)?;
        let u_breakpoints = c.reals("TU", m + 1)?;
        let v_breakpoints = c.reals("TV", n + 1)?;
        let count = m.saturating_mul(n);
        c.need("patch coefficients", count, 48)?;
        let mut patches = Vec::with_capacity(count);
        for i in 0..m {
            for j in 0..n {
                let mut p = [[0.0; 16]; 3];
                for coord in &mut p {
                    for k in coord.iter_mut() {
                        *k = c.real("coefficient")?;
                    }
                }
                patches.push(p);
                // Each column of patches ends with 48 extra values (the v-end patch), and
                // the last row with more; they are not needed to evaluate.
                if j + 1 == n && c.remaining() >= 48 && i + 1 < m {
                    for _ in 0..48 {
                        c.real("extra coefficient")?;
                    }
                }
            }
        }
        Ok(Self { spline_type, patch_type, u_breakpoints, v_breakpoints, patches })
    }
}

/// 116 point.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The point.
    pub point: Point3<f64>,
    /// Display symbol (a subfigure), if any.
    pub symbol: Option<EntityId>,
}

impl Point {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let point = c.point("point")?;
        let symbol = if c.remaining() > 0 { c.pointer("PTR (symbol)")? } else { None };
        Ok(Self { point, symbol })
    }
}

/// 118 ruled surface between two curves (form 0: equal relative arc length, form 1:
/// equal relative parameter).
#[derive(Debug, Clone, PartialEq)]
pub struct RuledSurface {
    /// Form number.
    pub form: i64,
    /// First curve.
    pub curve1: EntityId,
    /// Second curve.
    pub curve2: EntityId,
    /// DIRFLG: 0 join first to first, 1 first to last.
    pub reversed: bool,
    /// DEVFLG: 1 developable.
    pub developable: bool,
}

impl RuledSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        Ok(Self {
            form,
            curve1: c.required("DE1 (first curve)")?,
            curve2: c.required("DE2 (second curve)")?,
            reversed: c.int("DIRFLG")? == 1,
            developable: c.int_or("DEVFLG", 0)? == 1,
        })
    }
}

/// 120 surface of revolution: `generatrix` rotated about the line `axis` from
/// `start_angle` to `end_angle` (radians, counter-clockwise about the axis direction).
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceOfRevolution {
    /// The axis, a 110 line.
    pub axis: EntityId,
    /// The generatrix curve.
    pub generatrix: EntityId,
    /// Start angle (radians).
    pub start_angle: f64,
    /// End angle (radians).
    pub end_angle: f64,
}

impl SurfaceOfRevolution {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        Ok(Self {
            axis: c.required("L (axis)")?,
            generatrix: c.required("C (generatrix)")?,
            start_angle: c.real("SA")?,
            end_angle: c.real("TA")?,
        })
    }
}

/// 122 tabulated cylinder: the directrix swept along the vector from its start point to
/// `end`.
#[derive(Debug, Clone, PartialEq)]
pub struct TabulatedCylinder {
    /// The directrix curve.
    pub directrix: EntityId,
    /// End point of the generatrix line.
    pub end: Point3<f64>,
}

impl TabulatedCylinder {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        Ok(Self { directrix: c.required("DE (directrix)")?, end: c.point("generatrix end")? })
    }
}

/// 123 direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Direction {
    /// The vector (not necessarily unit).
    pub vector: Vector3<f64>,
}

impl Direction {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        Ok(Self { vector: c.vector("direction")? })
    }
}

/// 124 transformation matrix `x' = R x + T` (form 0: rotation, det +1; form 1:
/// reflection, det −1; forms 10–12 for coordinate systems).
#[derive(Debug, Clone, PartialEq)]
pub struct TransformationMatrix {
    /// Form number.
    pub form: i64,
    /// The matrix as a homogeneous 4×4 (last row `0 0 0 1`).
    pub matrix: Matrix4<f64>,
}

impl TransformationMatrix {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let mut m = Matrix4::identity();
        for r in 0..3 {
            for k in 0..4 {
                m[(r, k)] = c.real("matrix entry")?;
            }
        }
        Ok(Self { form, matrix: m })
    }
}

/// 126 rational B-spline curve, as stored.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurve {
    /// Form number (0 free-form, 1 line, 2 circular arc, ...).
    pub form: i64,
    /// Degree M.
    pub degree: usize,
    /// PROP1: planar.
    pub planar: bool,
    /// PROP2: closed.
    pub closed: bool,
    /// PROP3: polynomial (weights all equal).
    pub polynomial: bool,
    /// PROP4: periodic.
    pub periodic: bool,
    /// The knot sequence, K + M + 2 values.
    pub knots: Vec<f64>,
    /// Weights, K + 1 values (`None` when the record is polynomial).
    pub weights: Option<Vec<f64>>,
    /// Control points, K + 1.
    pub points: Vec<Point3<f64>>,
    /// Parameter range `[V0, V1]`.
    pub range: [f64; 2],
    /// Unit normal of the plane when planar.
    pub normal: Option<Vector3<f64>>,
}

impl BSplineCurve {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let k = c.count("K (upper index of the sum)", 5)?;
        let n = k + 1;
        let degree = c.count("M (degree)", 0)?;
        let props: [i64; 4] = [c.int("PROP1")?, c.int("PROP2")?, c.int("PROP3")?, c.int("PROP4")?];
        let n_knots = n.checked_add(degree).and_then(|x| x.checked_add(1)).unwrap_or(usize::MAX);
        c.need("knots", n_knots, 1)?;
        let knots = c.reals("knot", n_knots)?;
        let w = c.reals("weight", n)?;
        let mut xyz = Vec::new();
        c.reals_into("control point", 3 * n, &mut xyz)?;
        let points: Vec<Point3<f64>> = xyz.chunks_exact(3).map(|p| Point3::new(p[0], p[1], p[2])).collect();
        let range = [c.real_or("V0", knots[degree.min(n_knots - 1)])?, c.real_or("V1", knots[n.min(n_knots - 1)])?];
        let normal = if c.remaining() >= 3 { Some(c.vector("normal")?) } else { None };
        let polynomial = props[2] == 1 || w.iter().all(|&x| x == w[0]);
        Ok(Self {
            form,
            degree,
            planar: props[0] == 1,
            closed: props[1] == 1,
            polynomial: props[2] == 1,
            periodic: props[3] == 1,
            knots,
            weights: (!polynomial).then_some(w),
            points,
            range,
            normal: normal.filter(|_| props[0] == 1),
        })
    }
}

/// 128 rational B-spline surface, as stored (points with the u index running fastest in
/// the file are given here in cadmorph's order: `i * n_v + j`, `i` along u).
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineSurface {
    /// Form number (0 free-form, 1 plane, 2 cylinder, ...).
    pub form: i64,
    /// Degree in u (M1).
    pub u_degree: usize,
    /// Degree in v (M2).
    pub v_degree: usize,
    /// Poles in u (K1 + 1).
    pub n_u: usize,
    /// Poles in v (K2 + 1).
    pub n_v: usize,
    /// PROP1: closed in u.
    pub u_closed: bool,
    /// PROP2: closed in v.
    pub v_closed: bool,
    /// PROP3: polynomial.
    pub polynomial: bool,
    /// PROP4: periodic in u.
    pub u_periodic: bool,
    /// PROP5: periodic in v.
    pub v_periodic: bool,
    /// u knots.
    pub u_knots: Vec<f64>,
    /// v knots.
    pub v_knots: Vec<f64>,
    /// Weights (`None` when polynomial or all equal), cadmorph order.
    pub weights: Option<Vec<f64>>,
    /// Control points, cadmorph order.
    pub points: Vec<Point3<f64>>,
    /// Parameter range `[U0, U1, V0, V1]`.
    pub range: [f64; 4],
}

impl BSplineSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let k1 = c.count("K1 (upper index in u)", 1)?;
        let k2 = c.count("K2 (upper index in v)", 1)?;
        let u_degree = c.count("M1 (u degree)", 0)?;
        let v_degree = c.count("M2 (v degree)", 0)?;
        let props: [i64; 5] = [c.int("PROP1")?, c.int("PROP2")?, c.int("PROP3")?, c.int("PROP4")?, c.int("PROP5")?];
        let (n_u, n_v) = (k1 + 1, k2 + 1);
        let big = usize::MAX;
        let nuk = n_u.checked_add(u_degree).and_then(|x| x.checked_add(1)).unwrap_or(big);
        let nvk = n_v.checked_add(v_degree).and_then(|x| x.checked_add(1)).unwrap_or(big);
        let n = n_u.checked_mul(n_v).unwrap_or(big);
        c.need("knots", nuk.saturating_add(nvk), 1)?;
        c.need("weights and control points", n, 4)?;
        let u_knots = c.reals("u knot", nuk)?;
        let v_knots = c.reals("v knot", nvk)?;
        let wf = c.real_tokens("weight", n)?;
        let xyz = c.real_tokens("control point", 3 * n)?;
        let range = [
            c.real_or("U0", u_knots[u_degree])?,
            c.real_or("U1", u_knots[n_u])?,
            c.real_or("V0", v_knots[v_degree])?,
            c.real_or("V1", v_knots[n_v])?,
        ];
        // File order: u index fastest. Cadmorph order: i * n_v + j. The transpose goes by
        // tiles of TILE × TILE poles, so that both the tokens read and the poles written
        // stay within a few cache lines and pages per tile (a whole row or column at a
        // time missed the cache, and the TLB, on every pole of a large patch).
        const TILE: usize = 16;
        let mut points = vec![Point3::origin(); n];
        let mut w = vec![0.0; n];
        for j0 in (0..n_v).step_by(TILE) {
            for i0 in (0..n_u).step_by(TILE) {
                for j in j0..(j0 + TILE).min(n_v) {
                    for i in i0..(i0 + TILE).min(n_u) {
                        let f = j * n_u + i;
                        points[i * n_v + j] = Point3::new(xyz.get(3 * f), xyz.get(3 * f + 1), xyz.get(3 * f + 2));
                        w[i * n_v + j] = wf.get(f);
                    }
                }
            }
        }
        let polynomial = props[2] == 1 || w.iter().all(|&x| x == w[0]);
        Ok(Self {
            form,
            u_degree,
            v_degree,
            n_u,
            n_v,
            u_closed: props[0] == 1,
            v_closed: props[1] == 1,
            polynomial: props[2] == 1,
            u_periodic: props[3] == 1,
            v_periodic: props[4] == 1,
            u_knots,
            v_knots,
            weights: (!polynomial).then_some(w),
            points,
            range,
        })
    }
}

/// 140 offset surface: `surface` moved by `distance` along its normal.
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetSurface {
    /// Offset indicator vector.
    pub indicator: Vector3<f64>,
    /// Distance.
    pub distance: f64,
    /// The base surface.
    pub surface: EntityId,
}

impl OffsetSurface {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        Ok(Self { indicator: c.vector("N")?, distance: c.real("D")?, surface: c.required("DE (surface)")? })
    }
}

/// 190 plane surface: location, normal and (form 1) reference direction.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneSurface {
    /// A point of the plane (a 116).
    pub location: EntityId,
    /// The normal (a 123).
    pub normal: EntityId,
    /// Reference direction (a 123), parameterised form only.
    pub reference: Option<EntityId>,
}

impl PlaneSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let location = c.required("DELOC (location)")?;
        let normal = c.required("DENRML (normal)")?;
        let reference = if form == 1 { c.pointer("DEREFD (reference direction)")? } else { None };
        Ok(Self { location, normal, reference })
    }
}

/// 192 right circular cylindrical surface.
#[derive(Debug, Clone, PartialEq)]
pub struct CylindricalSurface {
    /// A point of the axis (116).
    pub location: EntityId,
    /// Axis direction (123).
    pub axis: EntityId,
    /// Radius.
    pub radius: f64,
    /// Reference direction (123), form 1.
    pub reference: Option<EntityId>,
}

impl CylindricalSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let location = c.required("LOCATION")?;
        let axis = c.required("AXIS")?;
        let radius = c.real("RADIUS")?;
        let reference = if form == 1 { c.pointer("REFDIR")? } else { None };
        Ok(Self { location, axis, radius, reference })
    }
}

/// 194 right circular conical surface (semi-angle in degrees, as IGES stores it).
#[derive(Debug, Clone, PartialEq)]
pub struct ConicalSurface {
    /// Point on the axis (116).
    pub location: EntityId,
    /// Axis direction (123).
    pub axis: EntityId,
    /// Radius at the location.
    pub radius: f64,
    /// Semi-angle in degrees.
    pub semi_angle_degrees: f64,
    /// Reference direction (123), form 1.
    pub reference: Option<EntityId>,
}

impl ConicalSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let location = c.required("LOCATION")?;
        let axis = c.required("AXIS")?;
        let radius = c.real("RADIUS")?;
        let semi_angle_degrees = c.real("SANGLE")?;
        let reference = if form == 1 { c.pointer("REFDIR")? } else { None };
        Ok(Self { location, axis, radius, semi_angle_degrees, reference })
    }
}

/// 196 spherical surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SphericalSurface {
    /// Centre (116).
    pub center: EntityId,
    /// Radius.
    pub radius: f64,
    /// Axis (123), form 1.
    pub axis: Option<EntityId>,
    /// Reference direction (123), form 1.
    pub reference: Option<EntityId>,
}

impl SphericalSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let center = c.required("LOCATION")?;
        let radius = c.real("RADIUS")?;
        let (axis, reference) = if form == 1 { (c.pointer("AXIS")?, c.pointer("REFDIR")?) } else { (None, None) };
        Ok(Self { center, radius, axis, reference })
    }
}

/// 198 toroidal surface.
#[derive(Debug, Clone, PartialEq)]
pub struct ToroidalSurface {
    /// Centre (116).
    pub center: EntityId,
    /// Axis (123).
    pub axis: EntityId,
    /// Major radius.
    pub major_radius: f64,
    /// Minor radius.
    pub minor_radius: f64,
    /// Reference direction (123), form 1.
    pub reference: Option<EntityId>,
}

impl ToroidalSurface {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let center = c.required("LOCATION")?;
        let axis = c.required("AXIS")?;
        let major_radius = c.real("MAJRAD")?;
        let minor_radius = c.real("MINRAD")?;
        let reference = if form == 1 { c.pointer("REFDIR")? } else { None };
        Ok(Self { center, axis, major_radius, minor_radius, reference })
    }
}
