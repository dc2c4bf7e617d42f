//! A Lackenby-style shift of the longitudinal centre of buoyancy: transverse sections
//! move along the length, the displacement stays.
//!
//! Lackenby (1950, "On the systematic geometrical variation of ship forms", Trans. INA
//! 92) changes the LCB and the prismatic coefficient by moving each section along the
//! length by a smooth `δx(x)` that vanishes at the ends. Here the shift is the
//! two-parameter family
//!
//! ```text
//! ξ = (x − x_aft) / L,   δx(x) = L ξ (1 − ξ) (a + b ξ)      (0 outside the hull's length)
//! ```
//!
//! which leaves the end sections (transom, stem) where they are and moves every other
//! section rigidly along x. `(a, b)` are solved by Newton so that, measured exactly on
//! the faces as the morph moves them ([`crate::volume`]), the centroid of the enclosed
//! volume moves by the asked `Δx` and the volume is unchanged. `V` and `M_x` are
//! polynomials of degree ≤ 4 in `(a, b)`, so the five-point central differences used
//! for the Newton Jacobian are exact up to rounding.
//!
//! The LCB is the longitudinal centroid of the enclosed volume: the centre of buoyancy
//! when the model is the underwater body (closed at its waterplane), the centre of
//! volume of the closed hull otherwise.

use cadmorph_brep::{BoundCurve, Face};
use cadmorph_morph::math::{Matrix3, Point3};
use cadmorph_morph::Deformation;
use nalgebra::{Matrix2, Vector2};
use serde::Serialize;

use crate::volume::{bounds_by_face, enclosed, enclosed_with, face_method, FaceMethod, Moments};
use crate::{Error, Result};

/// The section shift `δx(x) = L ξ (1 − ξ) (a + b ξ)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SectionShift {
    /// Aft end of the hull (`ξ = 0`).
    pub x_aft: f64,
    /// Fore end (`ξ = 1`).
    pub x_fore: f64,
    /// Symmetric coefficient.
    pub a: f64,
    /// Skew coefficient.
    pub b: f64,
}

impl SectionShift {
    fn length(&self) -> f64 {
        self.x_fore - self.x_aft
    }

    /// `δx` at `x`.
    pub fn shift(&self, x: f64) -> f64 {
        let l = self.length();
        let xi = (x - self.x_aft) / l;
        if !(0.0..=1.0).contains(&xi) {
            return 0.0;
        }
        l * xi * (1.0 - xi) * (self.a + self.b * xi)
    }

    /// `dδx/dx`.
    fn slope(&self, x: f64) -> f64 {
        let xi = (x - self.x_aft) / self.length();
        if !(0.0..=1.0).contains(&xi) {
            return 0.0;
        }
        self.a * (1.0 - 2.0 * xi) + self.b * (2.0 * xi - 3.0 * xi * xi)
    }
}

impl Deformation for SectionShift {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::new(p.x + self.shift(p.x), p.y, p.z)
    }

    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        let mut j = Matrix3::identity();
        j[(0, 0)] += self.slope(p.x);
        Some(j)
    }
}

/// What [`lcb_shift`] did.
#[derive(Debug, Clone, Serialize)]
pub struct LcbReport {
    /// The solved shift.
    pub shift: SectionShift,
    /// Volume and moments before.
    pub before: Moments,
    /// Volume and moments of the faces as the shift moves them.
    pub after: Moments,
    /// The LCB change asked.
    pub asked: f64,
    /// The LCB change reached.
    pub reached: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// The faces and bounding curves with their control points moved by `d`, as the
/// model's morph moves them.
fn moved(faces: &[Face], bounds: &[BoundCurve], d: &dyn Deformation) -> (Vec<Face>, Vec<BoundCurve>) {
    let mut f = faces.to_vec();
    for face in &mut f {
        d.deform(face.surface.control_points_mut());
    }
    let mut b = bounds.to_vec();
    for c in &mut b {
        d.deform(c.curve.control_points_mut());
    }
    (f, b)
}

/// The section shift that moves the LCB by `dx` (model units, positive forward = +x)
/// and keeps the enclosed volume, for the closed model of `faces` and `bounds`.
///
/// # Errors
///
/// Those of [`enclosed`]; [`Error::Invalid`] when Newton does not converge or the shift
/// would fold the sections (`|dx|` too large for the hull's length).
pub fn lcb_shift(faces: &[Face], bounds: &[BoundCurve], size: f64, dx: f64) -> Result<(SectionShift, LcbReport)> {
    section_shift(faces, bounds, size, dx, 1.0)
}

/// The section shift that moves the LCB by `dx` and multiplies the enclosed volume by
/// `volume_factor`: at a fixed length, beam and draft this changes the block coefficient
/// `C_B = V / (L B T)` by the same factor (Lackenby's change of fullness).
///
/// # Errors
///
/// Those of [`lcb_shift`]; [`Error::Invalid`] for a factor that is not positive.
pub fn section_shift(
    faces: &[Face],
    bounds: &[BoundCurve],
    size: f64,
    dx: f64,
    volume_factor: f64,
) -> Result<(SectionShift, LcbReport)> {
    if !dx.is_finite() {
        return Err(Error::Invalid(format!("the LCB shift must be finite, not {dx}")));
    }
    if !(volume_factor.is_finite() && volume_factor > 0.0) {
        return Err(Error::Invalid(format!("the volume factor must be positive, not {volume_factor}")));
    }
    let before = enclosed(faces, bounds, size)?;
    let by_face = bounds_by_face(faces.len(), bounds);
    let methods: Vec<FaceMethod> =
        faces.iter().zip(&by_face).map(|(f, fb)| face_method(f, fb, size)).collect::<Result<_>>()?;
    // The hull's ends from its curves and untrimmed faces: a trimmed face's patch may reach
    // beyond the hull (IGES trimmed planes), which would move the end sections.
    let (lo, hi) = crate::dims::extent(faces, bounds);
    let (x_aft, x_fore) = (lo[0], hi[0]);
    let length = x_fore - x_aft;
    let v0 = before.total.volume;
    let v_target = v0 * volume_factor;
    let target = before.total.centroid().x + dx;
    let eval = |a: f64, b: f64| -> Result<Vector2<f64>> {
        let s = SectionShift { x_aft, x_fore, a, b };
        let (f, bc) = moved(faces, bounds, &s);
        let e = enclosed_with(&f, &bc, size, &methods)?;
        Ok(Vector2::new(
            (e.total.moment[0] - target * e.total.volume) / (v0 * length),
            (e.total.volume - v_target) / v0,
        ))
    };
    let (mut a, mut b) = (0.0, 0.0);
    let h = 1e-3;
    for it in 0..20 {
        let c = eval(a, b)?;
        if c.norm() <= 1e-13 {
            let shift = SectionShift { x_aft, x_fore, a, b };
            let (f, bc) = moved(faces, bounds, &shift);
            let after = enclosed_with(&f, &bc, size, &methods)?.total;
            let report = LcbReport {
                shift,
                before: before.total,
                after,
                asked: dx,
                reached: after.centroid().x - before.total.centroid().x,
                iterations: it,
            };
            // No section may overtake its neighbour: 1 + δx' > 0 along the length.
            let worst =
                (0..=200).map(|k| 1.0 + shift.slope(x_aft + length * k as f64 / 200.0)).fold(f64::INFINITY, f64::min);
            if worst <= 0.0 {
                return Err(Error::Invalid(format!(
                    "an LCB shift of {dx} (volume times {volume_factor}) needs sections to overtake each other (dδx/dx = {:.3}): too large for a hull of length {length}",
                    worst - 1.0
                )));
            }
            return Ok((shift, report));
        }
        let d = |da: f64, db: f64| -> Result<Vector2<f64>> {
            let f1 = eval(a + da, b + db)?;
            let f_1 = eval(a - da, b - db)?;
            let f2 = eval(a + 2.0 * da, b + 2.0 * db)?;
            let f_2 = eval(a - 2.0 * da, b - 2.0 * db)?;
            Ok((8.0 * (f1 - f_1) - (f2 - f_2)) / (12.0 * h))
        };
        let ja = d(h, 0.0)?;
        let jb = d(0.0, h)?;
        let j = Matrix2::from_columns(&[ja, jb]);
        let step = j
            .lu()
            .solve(&(-c))
            .ok_or_else(|| Error::Invalid("the section shift cannot change the LCB (singular Jacobian)".into()))?;
        a += step.x;
        b += step.y;
        if !(a.is_finite() && b.is_finite()) {
            break;
        }
    }
    Err(Error::Invalid(format!(
        "no section shift moving the LCB by {dx} with the volume times {volume_factor} was found (Newton did not converge)"
    )))
}
