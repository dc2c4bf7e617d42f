//! The planing-hull chine law (paper section 2.2.1, Figures 4 and 5).
//!
//! A planing hull's transverse sections share one topology over most of the length: the
//! keel point `K`, the inner chine `C₁`, the outer chine `C₂` (absent on a single-chine
//! hull) and the deck edge `D`, joined by the V bottom (`K`–`C₁`), the narrow chine
//! strip (`C₁`–`C₂`) and the straight flared wall (`C₂`–`D`). The law changes each
//! section with these points, per side (starboard `y > 0`, port mirrored):
//!
//! 1. the bottom rotates rigidly about the keel point by `θ(x)`, positive raising the
//!    chine (the deadrise angle grows by `θ`): `C₁' = K + R(θ)(C₁ − K)`;
//! 2. the chine strip translates rigidly by the inner chine's displacement, then
//!    optionally rotates about the moved inner chine by `φ(x)`:
//!    `C₂' = C₁' + R(φ)(C₂ − C₁)`;
//! 3. the wall follows: its lower end moves with the outer chine and its upper end, the
//!    deck edge, stays. This is the paper's rigid translation of the wall followed by
//!    the wall rotation that brings it back to the deck line: a wall translated and left
//!    there would move the deck edge and open the deck, which must stay as it was. Each
//!    wall section stays a straight segment;
//! 4. everything at or above the deck edge's height stays where it was.
//!
//! `θ(x)` and `φ(x)` are B-spline laws along the length ([`Law`]) whose control values
//! are the parameters.
//!
//! The law is applied to CAD faces as a [`Deformation`] of all space, so shared control
//! points of two faces move together and the chines stay joined exactly (C0 at the
//! control points) while staying sharp. For it to be a function of position that is
//! continuous everywhere (control points lie off the surface), each section plane is
//! cut into wedges from the point `O` on the centreline at the deck edge's height, with
//! rays through `K`, `C₁`, `C₂` and `D`; in each wedge the map is the affine map fixing
//! `O` that moves the wedge's two section points as above. On the section's segments
//! themselves this is exactly the rotation, the translation and the straight wall of the
//! law (an affine map of a line is fixed by two of its points); the ray `O`–`D` is
//! horizontal, so the region above the deck edge's height is the identity. The wedge
//! maps vary with `x`, so moving control points differs from moving the surface by
//! `O(h²)` in the knot spacing `h` along the length: [`chine`] bisects the spans along
//! the length until the morphed faces are within the tolerance of the law applied to
//! every point of the input surfaces.
//!
//! Keel and chine lines are the model's sharp edges that run along the length (x span at
//! least a quarter of the hull's length, x monotone along them): at each section the
//! centreline one lowest is the keel, and the starboard (port) ones, from the bottom up,
//! the inner chine, the outer chine and the deck edge (two lines per side make a
//! single-chine hull).

use cadmorph_brep::CadDocument;
use cadmorph_model::{Model, MorphOptions, MorphOutcome};

use crate::refine::along_length;
use cadmorph_morph::math::Point3;
use cadmorph_morph::Deformation;
use cadmorph_nurbs::{Curve, KnotVector, NurbsCurve};
use serde::Serialize;

use crate::{Error, Result};

/// A law along the length: a clamped uniform B-spline of degree `min(3, n − 1)` over
/// `ξ ∈ [0, 1]` (`ξ = 0` at the aft end of the lines, `1` at the fore end) whose `n`
/// control values are the parameters; one value is a constant law. The control values
/// sit at the Greville abscissae (Piegl & Tiller eq. 9.22), so `ξ` is the curve
/// parameter and the law's value at `ξ` is a B-spline evaluation (Piegl & Tiller A3.1).
#[derive(Debug, Clone, PartialEq)]
pub struct Law {
    values: Vec<f64>,
    curve: Option<NurbsCurve>,
}

impl Law {
    /// The law with these control values.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for no values or a non-finite one.
    pub fn new(values: &[f64]) -> Result<Self> {
        if values.is_empty() {
            return Err(Error::Invalid("a law needs at least one control value".into()));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Invalid(format!(
                "control value {} of the law is {}, not a finite number",
                i + 1,
                values[i]
            )));
        }
        if values.len() == 1 {
            return Ok(Law { values: values.to_vec(), curve: None });
        }
        let p = (values.len() - 1).min(3);
        let knots = KnotVector::clamped_uniform(p, values.len());
        let k = knots.as_slice();
        let points = values
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let g = k[i + 1..=i + p].iter().sum::<f64>() / p as f64;
                Point3::new(g, v, 0.0)
            })
            .collect();
        Ok(Law { values: values.to_vec(), curve: Some(NurbsCurve::new(p, knots, points, None)) })
    }

    /// The law's value at `ξ` (clamped to `[0, 1]`).
    pub fn at(&self, xi: f64) -> f64 {
        match &self.curve {
            None => self.values[0],
            Some(c) => c.eval(xi.clamp(0.0, 1.0)).y,
        }
    }

    /// The control values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Every control value is zero.
    pub fn is_zero(&self) -> bool {
        self.values.iter().all(|&v| v == 0.0)
    }
}

/// Which side of the centreline a line runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// `y = 0` (the keel).
    Centre,
    /// `y > 0`.
    Starboard,
    /// `y < 0`.
    Port,
}

/// A sharp edge running along the length, as the law uses it.
#[derive(Debug, Clone)]
pub struct LinePiece {
    /// Index of the edge in the model's seam report ([`Model::seams`]: iso edges, then
    /// trim edges).
    pub edge: usize,
    /// Its side of the centreline (measured at its middle).
    pub side: Side,
    /// Its x range.
    pub x: (f64, f64),
    curve: NurbsCurve,
    /// `(x, t)` at 65 points of the piece, sorted by x.
    table: Vec<(f64, f64)>,
}

impl LinePiece {
    fn new(edge: usize, side: Side, curve: NurbsCurve, t: (f64, f64)) -> Self {
        let n = 64;
        let table: Vec<(f64, f64)> = (0..=n)
            .map(|i| {
                let ti = t.0 + (t.1 - t.0) * i as f64 / n as f64;
                (curve.eval(ti).x, ti)
            })
            .collect();
        let mut table = table;
        table.sort_by(|a, b| a.0.total_cmp(&b.0));
        let x = (table[0].0, table[n].0);
        LinePiece { edge, side, x, curve, table }
    }

    /// The point of the piece in the plane `x`: the bracket from the sampled table, then
    /// Newton on the monotone `x(t)` kept inside it (bisection where a step leaves it).
    fn at(&self, x: f64) -> Point3<f64> {
        let t = &self.table;
        if x <= t[0].0 {
            return self.curve.eval(t[0].1);
        }
        if x >= t[t.len() - 1].0 {
            return self.curve.eval(t[t.len() - 1].1);
        }
        let j = t.partition_point(|e| e.0 <= x).clamp(1, t.len() - 1);
        let ((xa, mut a), (xb, mut b)) = (t[j - 1], t[j]);
        let rising_t = b > a;
        let mut s = if xb > xa { a + (b - a) * (x - xa) / (xb - xa) } else { a };
        for _ in 0..60 {
            let d = self.curve.derivs(s, 1);
            let f = d[0].x - x;
            if f == 0.0 {
                break;
            }
            // Keep the bracket: f < 0 means s is on a's side.
            if f < 0.0 {
                a = s;
            } else {
                b = s;
            }
            let mut next = if d[1].x != 0.0 { s - f / d[1].x } else { f64::NAN };
            let inside = if rising_t { next > a && next < b } else { next < a && next > b };
            if !inside {
                next = 0.5 * (a + b);
            }
            if next == s || (next - s).abs() <= 4.0 * f64::EPSILON * s.abs().max(1.0) {
                s = next;
                break;
            }
            s = next;
        }
        let mut p = self.curve.eval(s);
        p.x = x;
        p
    }
}

/// Where the keel and chine lines cross one transverse plane, on one side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// The keel point.
    pub keel: Point3<f64>,
    /// The inner chine.
    pub inner_chine: Point3<f64>,
    /// The outer chine (none on a single-chine hull).
    pub outer_chine: Option<Point3<f64>>,
    /// The deck edge.
    pub deck_edge: Point3<f64>,
}

/// One side of a transverse section, in the side's own coordinates `(s, z)` with `s = |y|`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct HalfSection {
    keel: [f64; 2],
    inner: [f64; 2],
    outer: Option<[f64; 2]>,
    deck: [f64; 2],
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn rotate(d: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [d[0] * c - d[1] * s, d[0] * s + d[1] * c]
}

impl HalfSection {
    /// The wedge apex: on the centreline at the deck edge's height.
    fn apex(&self) -> [f64; 2] {
        [0.0, self.deck[1]]
    }

    /// The section's points in order up the side, with where the law moves them.
    fn moved(&self, theta: f64, phi: f64) -> Vec<([f64; 2], [f64; 2])> {
        let k = self.keel;
        let inner = {
            let r = rotate(sub(self.inner, k), theta);
            [k[0] + r[0], k[1] + r[1]]
        };
        let mut out = vec![(k, k), (self.inner, inner)];
        if let Some(o) = self.outer {
            let r = rotate(sub(o, self.inner), phi);
            out.push((o, [inner[0] + r[0], inner[1] + r[1]]));
        }
        out.push((self.deck, self.deck));
        out
    }

    /// The displacement of the point `p` (side coordinates) by the wedge maps.
    fn displacement(&self, p: [f64; 2], moved: &[([f64; 2], [f64; 2])]) -> [f64; 2] {
        let o = self.apex();
        let q = sub(p, o);
        for w in moved.windows(2) {
            let ((a, a1), (b, b1)) = (w[0], w[1]);
            let (da, db) = (sub(a, o), sub(b, o));
            let det = cross(da, db);
            if det.abs() <= 1e-300 {
                continue;
            }
            let la = cross(q, db) / det;
            let lb = cross(da, q) / det;
            if la >= 0.0 && lb >= 0.0 {
                let (ma, mb) = (sub(a1, a), sub(b1, b));
                return [la * ma[0] + lb * mb[0], la * ma[1] + lb * mb[1]];
            }
        }
        [0.0, 0.0]
    }
}

/// The chine law on one model: its lines and its laws (see the module docs).
#[derive(Debug, Clone)]
pub struct ChineLaw {
    lines: Vec<LinePiece>,
    x_range: (f64, f64),
    theta: Law,
    phi: Option<Law>,
    eps: f64,
}

/// Sharp longitudinal edges of a model, classified.
fn lines_of<D: CadDocument>(model: &Model<D>) -> Result<(Vec<LinePiece>, (f64, f64))> {
    let faces = model.patches();
    let seams = model.seams(64);
    let size = model.size();
    let (x_lo, x_hi) = faces
        .iter()
        .flat_map(|f| f.surface.control_points().iter().map(|p| p.x))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let length = x_hi - x_lo;
    let eps = 1e-6 * size;
    let mut curves: Vec<(NurbsCurve, (f64, f64))> =
        model.edges().iter().map(|e| (faces[e.a.patch].surface.boundary(e.a.side), e.a_range)).collect();
    curves.extend(model.trim_edges().iter().map(|e| (e.curve.clone(), e.range)));
    let mut lines = Vec::new();
    for (k, ((curve, t), report)) in curves.into_iter().zip(&seams.edges).enumerate() {
        if !report.sharp {
            continue;
        }
        let n = 32;
        let xs: Vec<Point3<f64>> = (0..=n).map(|i| curve.eval(t.0 + (t.1 - t.0) * i as f64 / n as f64)).collect();
        let rising = xs[n].x > xs[0].x;
        let monotone = xs.windows(2).all(|w| if rising { w[1].x > w[0].x } else { w[1].x < w[0].x });
        let span = (xs[n].x - xs[0].x).abs();
        if !monotone || span < 0.25 * length {
            continue;
        }
        let mid = curve.eval(0.5 * (t.0 + t.1));
        let side_of = if mid.y > eps {
            Side::Starboard
        } else if mid.y < -eps {
            Side::Port
        } else {
            Side::Centre
        };
        lines.push(LinePiece::new(k, side_of, curve, t));
    }
    let lo = lines.iter().map(|l| l.x.0).fold(f64::INFINITY, f64::min);
    let hi = lines.iter().map(|l| l.x.1).fold(f64::NEG_INFINITY, f64::max);
    if lines.is_empty() {
        return Err(Error::Invalid(
            "the model has no sharp edges along its length (x): no keel or chine lines to apply the chine law to"
                .into(),
        ));
    }
    Ok((lines, (lo, hi)))
}

impl ChineLaw {
    /// The chine law of `model` (x along the length, y to starboard, z up) with the
    /// bottom rotation `theta` (radians) and the optional chine-strip rotation `phi`
    /// (radians), both along the length of the lines.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] when the keel and chine lines cannot be found at every section
    /// (at least 65 sections along the length are checked), when a section closes
    /// (zero half-breadth) where `θ` is not zero, when `phi` is given for a single-chine
    /// hull, or when the law folds a section (a moved chine crossing the centreline, or
    /// the section points out of order).
    pub fn new<D: CadDocument>(model: &Model<D>, theta: Law, phi: Option<Law>) -> Result<Self> {
        let (lines, x_range) = lines_of(model)?;
        let law = ChineLaw { lines, x_range, theta, phi, eps: 1e-9 * model.size() };
        let stations = 64;
        let mut outer = None;
        for i in 0..=stations {
            let x = x_range.0 + (x_range.1 - x_range.0) * i as f64 / stations as f64;
            for side in [Side::Starboard, Side::Port] {
                let h = law.half_section(x, side)?;
                match outer {
                    None => outer = Some(h.outer.is_some()),
                    Some(o) if o != h.outer.is_some() => {
                        return Err(Error::Invalid(format!(
                            "the hull's sections change topology along the length: the {side:?} side has {} chine lines at x = {x} and {} elsewhere",
                            if h.outer.is_some() { 2 } else { 1 },
                            if o { 2 } else { 1 }
                        )))
                    }
                    _ => {}
                }
                law.check_section(x, side, &h)?;
            }
        }
        if outer == Some(false) && law.phi.as_ref().is_some_and(|p| !p.is_zero()) {
            return Err(Error::Invalid(
                "a chine-strip rotation needs a double-chine hull; this one has a single chine per side".into(),
            ));
        }
        Ok(law)
    }

    /// The sharp edges the law found and uses.
    pub fn lines(&self) -> &[LinePiece] {
        &self.lines
    }

    /// The x range of the lines (the law's `ξ = 0` and `ξ = 1`).
    pub fn x_range(&self) -> (f64, f64) {
        self.x_range
    }

    /// The section of the lines at `x` on one side (world coordinates): keel, inner
    /// chine, outer chine (none on a single-chine hull), deck edge.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] where the lines are not found (`side` must be starboard or port).
    pub fn section(&self, x: f64, side: Side) -> Result<Section> {
        if side == Side::Centre {
            return Err(Error::Invalid("a section side is starboard or port, not the centreline".into()));
        }
        let h = self.half_section(x, side)?;
        let m = if side == Side::Port { -1.0 } else { 1.0 };
        let w = |p: [f64; 2]| Point3::new(x, m * p[0], p[1]);
        Ok(Section { keel: w(h.keel), inner_chine: w(h.inner), outer_chine: h.outer.map(w), deck_edge: w(h.deck) })
    }

    /// The bottom rotation at `x`, radians.
    pub fn theta(&self, x: f64) -> f64 {
        self.theta.at(self.xi(x))
    }

    /// The chine-strip rotation at `x`, radians.
    pub fn phi(&self, x: f64) -> f64 {
        self.phi.as_ref().map_or(0.0, |p| p.at(self.xi(x)))
    }

    fn xi(&self, x: f64) -> f64 {
        (x - self.x_range.0) / (self.x_range.1 - self.x_range.0)
    }

    /// One side of the section `x`, in `(|y|, z)`.
    fn half_section(&self, x: f64, side: Side) -> Result<HalfSection> {
        let mirror = if side == Side::Port { -1.0 } else { 1.0 };
        let at = |l: &LinePiece| {
            let p = l.at(x);
            [mirror * p.y, p.z]
        };
        let covers = |l: &&LinePiece| x >= l.x.0 - self.eps && x <= l.x.1 + self.eps;
        let keel = self
            .lines
            .iter()
            .filter(|l| l.side == Side::Centre)
            .filter(covers)
            .map(at)
            .min_by(|a, b| a[1].total_cmp(&b[1]))
            .ok_or_else(|| Error::Invalid(format!("no keel line (a sharp edge on the centreline) at x = {x}")))?;
        let mut up: Vec<[f64; 2]> = self.lines.iter().filter(|l| l.side == side).filter(covers).map(at).collect();
        up.sort_by(|a, b| a[1].total_cmp(&b[1]));
        let name = if side == Side::Port { "port" } else { "starboard" };
        match up.len() {
            2 => Ok(HalfSection { keel, inner: up[0], outer: None, deck: up[1] }),
            3 => Ok(HalfSection { keel, inner: up[0], outer: Some(up[1]), deck: up[2] }),
            n => Err(Error::Invalid(format!(
                "at x = {x} the {name} side has {n} sharp lines along the length; the chine law needs the inner chine, optionally the outer chine, and the deck edge (2 or 3)"
            ))),
        }
    }

    /// The section's moved points must keep their order up the side and stay on it.
    fn check_section(&self, x: f64, side: Side, h: &HalfSection) -> Result<()> {
        let (theta, phi) = (self.theta(x), self.phi(x));
        let name = if side == Side::Port { "port" } else { "starboard" };
        let closed = (h.inner[0] - h.keel[0]).abs() <= self.eps;
        if closed && theta != 0.0 {
            return Err(Error::Invalid(format!(
                "the section at x = {x} closes (the {name} inner chine is on the centreline), so the bottom rotation must be 0 there, not {:.6}°: make the law's end value 0",
                theta.to_degrees()
            )));
        }
        let moved = h.moved(theta, phi);
        let o = h.apex();
        for w in moved.windows(2) {
            let (a, b) = (sub(w[0].1, o), sub(w[1].1, o));
            let (a0, b0) = (sub(w[0].0, o), sub(w[1].0, o));
            if cross(a0, b0) > self.eps * self.eps && cross(a, b) <= 0.0 {
                return Err(Error::Invalid(format!(
                    "the law folds the {name} side of the section at x = {x} (θ = {:.4}°, φ = {:.4}°): its moved chine points leave their order up the side",
                    theta.to_degrees(),
                    phi.to_degrees()
                )));
            }
        }
        if moved.iter().any(|(p, q)| p[0] > self.eps && q[0] < 0.0) {
            return Err(Error::Invalid(format!(
                "the law carries a {name} chine across the centreline at x = {x} (θ = {:.4}°)",
                theta.to_degrees()
            )));
        }
        Ok(())
    }

    /// The law at `p`, or `None` where it fails (no lines there).
    fn try_deform(&self, p: &Point3<f64>) -> Option<Point3<f64>> {
        if p.x < self.x_range.0 || p.x > self.x_range.1 || p.y == 0.0 {
            return Some(*p);
        }
        let side = if p.y > 0.0 { Side::Starboard } else { Side::Port };
        let h = self.half_section(p.x, side).ok()?;
        let moved = h.moved(self.theta(p.x), self.phi(p.x));
        let d = h.displacement([p.y.abs(), p.z], &moved);
        Some(Point3::new(p.x, p.y + p.y.signum() * d[0], p.z + d[1]))
    }
}

impl Deformation for ChineLaw {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        // `new` checked every section: a point whose section has no lines is outside them.
        self.try_deform(p).unwrap_or(*p)
    }
}

/// What [`chine`] did.
#[derive(Debug, Clone, Serialize)]
pub struct ChineReport {
    /// The lines used: seam-report edge index, side, x range.
    pub lines: Vec<(usize, Side, (f64, f64))>,
    /// Bisection rounds along the length.
    pub rounds: usize,
    /// Control points of all faces before the refinement.
    pub control_points_before: usize,
    /// Control points of all faces after it.
    pub control_points_after: usize,
    /// Largest distance between a morphed B-spline face and the law applied to every
    /// point of its input surface (sampled), after the refinement.
    pub max_deviation: f64,
    /// The tolerance asked for it.
    pub tolerance: f64,
    /// The morph's own report (seams before and after, read back from the document).
    pub morph: MorphOutcome,
}

/// Applies the chine law to `model`: the B-spline faces the law moves are refined along
/// the length until each is within `tol` of the law applied to every point of it
/// ([`along_length`]), then the model is morphed (analytic faces that move, such as a
/// transom, become their exact B-spline form).
///
/// # Errors
///
/// Those of [`along_length`]; the model's errors.
pub fn chine<D: CadDocument>(model: &mut Model<D>, law: &ChineLaw, tol: f64) -> Result<ChineReport> {
    if tol.is_nan() || tol <= 0.0 {
        return Err(Error::Invalid(format!("the chine law's tolerance must be positive, not {tol}")));
    }
    let r = along_length(model, law, tol, "the chine law")?;
    let morph = model.morph(law, &MorphOptions::default())?;
    Ok(ChineReport {
        lines: law.lines.iter().map(|l| (l.edge, l.side, l.x)).collect(),
        rounds: r.rounds,
        control_points_before: r.control_points_before,
        control_points_after: r.control_points_after,
        max_deviation: r.max_deviation,
        tolerance: tol,
        morph,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn law_interpolates_its_end_values_and_is_constant_for_one_value() {
        let l = Law::new(&[0.1, 0.3, 0.2, 0.0]).unwrap();
        assert_eq!(l.at(0.0), 0.1);
        assert!(l.at(1.0).abs() < 1e-15);
        assert_eq!(Law::new(&[0.25]).unwrap().at(0.7), 0.25);
        // A linear law with values at the Greville abscissae is the straight line.
        let lin = Law::new(&[0.0, 1.0]).unwrap();
        assert!((lin.at(0.3) - 0.3).abs() < 1e-15);
        assert!(Law::new(&[]).is_err());
        assert!(Law::new(&[0.0, f64::NAN]).unwrap_err().to_string().contains("control value 2"));
    }

    #[test]
    fn wedge_maps_rotate_the_bottom_translate_the_chine_and_keep_the_top() {
        let h = HalfSection { keel: [0.0, 0.0], inner: [1.2, 0.45], outer: Some([1.35, 0.55]), deck: [1.6, 2.0] };
        let theta = 0.07;
        let moved = h.moved(theta, 0.0);
        // A point on the bottom rotates about the keel.
        let p = [0.6, 0.225];
        let d = h.displacement(p, &moved);
        let q = rotate(p, theta);
        assert!((p[0] + d[0] - q[0]).abs() < 1e-15 && (p[1] + d[1] - q[1]).abs() < 1e-15);
        // A point on the chine strip translates with the inner chine.
        let c1 = rotate(h.inner, theta);
        let shift = sub(c1, h.inner);
        let m = [1.275, 0.5];
        let dm = h.displacement(m, &moved);
        assert!((dm[0] - shift[0]).abs() < 1e-15 && (dm[1] - shift[1]).abs() < 1e-15);
        // The deck edge and anything above its height stay.
        assert_eq!(h.displacement(h.deck, &moved), [0.0, 0.0]);
        assert_eq!(h.displacement([0.8, 2.3], &moved), [0.0, 0.0]);
        // The wall stays straight: its midpoint goes to the middle of the moved ends.
        let w = [0.5 * (1.35 + 1.6), 0.5 * (0.55 + 2.0)];
        let dw = h.displacement(w, &moved);
        assert!((dw[0] - 0.5 * shift[0]).abs() < 1e-15 && (dw[1] - 0.5 * shift[1]).abs() < 1e-15);
    }
}
