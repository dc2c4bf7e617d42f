//! Principal dimensions of a hull: length by its parallel middle body, beam and draft by
//! scaling, and the block coefficient by a Lackenby section shift ([`crate::lackenby`]).
//!
//! The dimensions are those of the model's box ([`extent`]), x along the length, y across, z up:
//! length `L` the x extent, beam `B` the y extent, draft `T` from the lowest point to the
//! waterline (the top of the model unless given: a model closed at its waterplane is the
//! underwater body), block coefficient `C_B = V / (L B T)` with `V` the exact enclosed
//! volume ([`crate::volume`]).
//!
//! - **Length.** A parallel middle body `[x₀, x₁]` (where every section is the same) is
//!   stretched: `x' = x` aft of it, `x' = x₀ + (x − x₀)(1 + ΔL / (x₁ − x₀))` in it,
//!   `x' = x + ΔL` forward of it. The stern and the bow keep their shape exactly (they only
//!   translate), the middle body stays prismatic. The map bends at `x₀` and `x₁`: faces
//!   whose length-wise parameter alone gives x get knots of full multiplicity there (the
//!   face splits into pieces the map moves affinely, so the morph is exact), others are
//!   refined until within the tolerance ([`crate::refine::along_length`]). Without a
//!   middle body the whole length scales about the aft end (bow and stern stretched with
//!   it).
//! - **Beam and draft.** `y' = y B'/B` about the centreline, `z' = z₀ + (z − z₀) T'/T`
//!   about the baseline: affine, exact on every face.

use cadmorph_brep::{BoundCurve, CadDocument, Face};
use cadmorph_model::{Model, MorphOptions};
use cadmorph_morph::math::{Matrix3, Point3, Vector3};
use cadmorph_morph::{Affine, Deformation};
use cadmorph_nurbs::{Curve, NurbsSurface, Surface};
use serde::Serialize;

use crate::refine::{along_length, Refined};
use crate::volume::enclosed;
use crate::{Error, Result};

/// The length change by the parallel middle body (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stretch {
    /// Aft end of the stretched part.
    pub x0: f64,
    /// Fore end of the stretched part.
    pub x1: f64,
    /// The length added (negative shortens).
    pub added: f64,
}

impl Stretch {
    fn factor(&self) -> f64 {
        1.0 + self.added / (self.x1 - self.x0)
    }

    /// `x'` of `x`.
    pub fn map(&self, x: f64) -> f64 {
        if x <= self.x0 {
            x
        } else if x >= self.x1 {
            x + self.added
        } else {
            self.x0 + (x - self.x0) * self.factor()
        }
    }
}

impl Deformation for Stretch {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::new(self.map(p.x), p.y, p.z)
    }

    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        let mut j = Matrix3::identity();
        if p.x > self.x0 && p.x < self.x1 {
            j[(0, 0)] = self.factor();
        }
        Some(j)
    }
}

/// Length, beam, draft, volume and block coefficient of a closed hull.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Dimensions {
    /// x extent.
    pub length: f64,
    /// y extent.
    pub beam: f64,
    /// From the lowest point to the waterline.
    pub draft: f64,
    /// The lowest z (the baseline).
    pub baseline: f64,
    /// The enclosed volume.
    pub volume: f64,
    /// `V / (L B T)`.
    pub block_coefficient: f64,
    /// The longitudinal centroid of the enclosed volume.
    pub lcb: f64,
    /// Aft end (lowest x).
    pub x_aft: f64,
}

/// The dimensions of `model` with the waterline at `waterline` (the top of the model
/// when `None`).
///
/// # Errors
///
/// Those of [`enclosed`]; [`Error::Invalid`] for a waterline at or below the baseline.
pub fn dimensions<D: CadDocument>(model: &Model<D>, waterline: Option<f64>) -> Result<Dimensions> {
    let (lo, hi) = extent(model.patches(), model.bound_curves());
    let top = waterline.unwrap_or(hi[2]);
    if top <= lo[2] {
        return Err(Error::Invalid(format!("the waterline z = {top} is not above the baseline z = {}", lo[2])));
    }
    let e = enclosed(model.patches(), model.bound_curves(), model.size())?;
    let (length, beam, draft) = (hi[0] - lo[0], hi[1] - lo[1], top - lo[2]);
    Ok(Dimensions {
        length,
        beam,
        draft,
        baseline: lo[2],
        volume: e.total.volume,
        block_coefficient: e.total.volume / (length * beam * draft),
        lcb: e.total.centroid().x,
        x_aft: lo[0],
    })
}

/// The box of a model: its bounding curves and its untrimmed faces, sampled (33 points
/// per curve, 33 × 33 per face). A trimmed face's patch may reach far beyond the face
/// (IGES trimmed planes, STEP faces on a larger surface), so it counts by the curves that
/// bound it; a face bulging beyond its own edges is under-counted by that.
pub fn extent(faces: &[Face], bounds: &[BoundCurve]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut add = |p: Point3<f64>| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    };
    for b in bounds {
        let (t0, t1) = b.range;
        for i in 0..=32 {
            add(b.curve.eval(t0 + (t1 - t0) * i as f64 / 32.0));
        }
    }
    let bounded: Vec<bool> = (0..faces.len()).map(|i| bounds.iter().any(|b| b.face == i)).collect();
    for (f, &has_curves) in faces.iter().zip(&bounded) {
        if f.trimmed && has_curves {
            continue;
        }
        let (ud, vd) = f.surface.domain();
        let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
        for i in 0..=32 {
            for j in 0..=32 {
                add(f.surface.eval(u0 + (u1 - u0) * i as f64 / 32.0, v0 + (v1 - v0) * j as f64 / 32.0));
            }
        }
    }
    (lo, hi)
}

/// What to change (each `None` keeps it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct DimsChange {
    /// The new length.
    pub length: Option<f64>,
    /// The parallel middle body `[x₀, x₁]` the length change stretches (the whole
    /// length when `None`).
    pub middle_body: Option<(f64, f64)>,
    /// The new beam.
    pub beam: Option<f64>,
    /// The new draft (to the same waterline, scaled with the hull).
    pub draft: Option<f64>,
    /// The waterline height of the draft and block coefficient (the top of the model
    /// when `None`).
    pub waterline: Option<f64>,
    /// The LCB shift along +x, model units.
    pub lcb_shift: Option<f64>,
    /// The new block coefficient (by a section shift, at the input's length, beam and
    /// draft).
    pub block_coefficient: Option<f64>,
}

/// What [`change_dimensions`] did.
#[derive(Debug, Clone, Serialize)]
pub struct DimsReport {
    /// Before.
    pub before: Dimensions,
    /// After, measured on the morphed faces.
    pub after: Dimensions,
    /// The section shift's coefficients `(a, b)`, when one ran.
    pub section_shift: Option<(f64, f64)>,
    /// The length stretch, when one ran.
    pub stretch: Option<Stretch>,
    /// Knots of full multiplicity inserted where the stretch bends.
    pub knots_at_bends: usize,
    /// The refinement for the stretch.
    pub refined: Option<Refined>,
    /// Largest seam gap after the last morph (read back from the document).
    pub max_gap_after: f64,
}

/// Knots of full multiplicity at the parameters where `s` reaches `x0` and `x1`, when x
/// on `s` depends on its length-wise parameter alone and is monotone in it. Returns the
/// number of knots inserted.
fn split_at_bends(s: &mut NurbsSurface, xs: [f64; 2], eps: f64) -> Result<usize> {
    let (ud, vd) = s.domain();
    let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
    // Which parameter carries x, and that the other does not change it.
    let n = 16;
    // Knot insertion keeps the geometry: x(t) is read on the surface as it came.
    let reference = s.clone();
    for along_u in [true, false] {
        let at = |t: f64, w: f64| if along_u { reference.eval(t, w).x } else { reference.eval(w, t).x };
        let (t0, t1, w0, w1) = if along_u { (u0, u1, v0, v1) } else { (v0, v1, u0, u1) };
        let ts: Vec<f64> = (0..=n).map(|i| t0 + (t1 - t0) * i as f64 / n as f64).collect();
        let alone =
            ts.iter().all(|&t| (0..=4).all(|j| (at(t, w0 + (w1 - w0) * j as f64 / 4.0) - at(t, w0)).abs() <= eps));
        let xs_t: Vec<f64> = ts.iter().map(|&t| at(t, w0)).collect();
        let rising = xs_t[n] > xs_t[0];
        let monotone = xs_t.windows(2).all(|w| if rising { w[1] > w[0] } else { w[1] < w[0] });
        if !(alone && monotone) {
            continue;
        }
        let mut inserted = 0;
        for &x in &xs {
            let (lo, hi) = (xs_t[0].min(xs_t[n]), xs_t[0].max(xs_t[n]));
            if x <= lo + eps || x >= hi - eps {
                continue;
            }
            // Bisection on the monotone x(t).
            let (mut a, mut b) = (t0, t1);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if m <= a || m >= b {
                    break;
                }
                if (at(m, w0) < x) == rising {
                    a = m;
                } else {
                    b = m;
                }
            }
            let t = 0.5 * (a + b);
            let (p, knots) = if along_u { (s.u_degree(), s.u_knots()) } else { (s.v_degree(), s.v_knots()) };
            let have = knots.multiplicity(t, 0.0);
            if have >= p {
                continue;
            }
            let r = if along_u { s.insert_u_knot(t, p - have) } else { s.insert_v_knot(t, p - have) };
            inserted += r.map_err(|e| Error::Invalid(format!("splitting a face where the stretch bends: {e}")))?;
        }
        return Ok(inserted);
    }
    Ok(0)
}

/// Changes the principal dimensions of the closed hull `model` (x along the length, y
/// across, z up): first the section shift (LCB, block coefficient), then the length,
/// then beam and draft. `tol` bounds the faces' distance from the stretch where it is not
/// exact.
///
/// # Errors
///
/// [`Error::Invalid`] for dimensions that are not positive, a middle body outside the
/// hull or a shortening longer than it; those of [`section_shift`](crate::section_shift),
/// [`along_length`] and the model's.
pub fn change_dimensions<D: CadDocument>(model: &mut Model<D>, c: &DimsChange, tol: f64) -> Result<DimsReport> {
    let before = dimensions(model, c.waterline)?;
    for (what, v) in
        [("length", c.length), ("beam", c.beam), ("draft", c.draft), ("block coefficient", c.block_coefficient)]
    {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Invalid(format!("the new {what} must be positive, not {v}")));
            }
        }
    }
    let mut max_gap_after = 0.0;
    let mut section_shift = None;
    if c.lcb_shift.is_some() || c.block_coefficient.is_some() {
        let dx = c.lcb_shift.unwrap_or(0.0);
        let factor = c.block_coefficient.map_or(1.0, |cb| cb / before.block_coefficient);
        let (shift, _) = crate::section_shift(model.patches(), model.bound_curves(), model.size(), dx, factor)?;
        let o = model.morph(&shift, &MorphOptions::default())?;
        max_gap_after = o.seams_after.max_gap_closest;
        section_shift = Some((shift.a, shift.b));
    }
    let (mut stretch, mut knots_at_bends, mut refined) = (None, 0, None);
    if let Some(l) = c.length.filter(|&l| l != before.length) {
        let x_fore = before.x_aft + before.length;
        let (x0, x1) = c.middle_body.unwrap_or((before.x_aft, x_fore));
        if !(x0 < x1 && x0 >= before.x_aft - 1e-9 * before.length && x1 <= x_fore + 1e-9 * before.length) {
            return Err(Error::Invalid(format!(
                "the parallel middle body {x0} .. {x1} must be an interval inside the hull's length {} .. {x_fore}",
                before.x_aft
            )));
        }
        let added = l - before.length;
        if x1 - x0 + added <= 0.0 {
            return Err(Error::Invalid(format!(
                "shortening by {} removes more than the middle body {x0} .. {x1} ({} long)",
                -added,
                x1 - x0
            )));
        }
        let s = Stretch { x0, x1, added };
        let eps = 1e-12 * model.size();
        for i in 0..model.patches().len() {
            let f = &model.patches()[i];
            if f.kind.is_analytic() {
                continue;
            }
            let mut surface = f.surface.clone();
            let n = split_at_bends(&mut surface, [x0, x1], eps)?;
            if n > 0 {
                knots_at_bends += n;
                model.set_patch_surface(i, surface)?;
            }
        }
        refined = Some(along_length(model, &s, tol, "the length stretch")?);
        let o = model.morph(&s, &MorphOptions::default())?;
        max_gap_after = o.seams_after.max_gap_closest;
        stretch = Some(s);
    }
    let fb = c.beam.map_or(1.0, |b| b / before.beam);
    let ft = c.draft.map_or(1.0, |t| t / before.draft);
    if fb != 1.0 || ft != 1.0 {
        let z0 = before.baseline;
        let a =
            Affine::new(Matrix3::from_diagonal(&Vector3::new(1.0, fb, ft)), Vector3::new(0.0, 0.0, z0 * (1.0 - ft)));
        let o = model.morph(&a, &MorphOptions::default())?;
        max_gap_after = o.seams_after.max_gap_closest;
    }
    let waterline = c.waterline.map(|w| before.baseline + (w - before.baseline) * ft);
    let after = dimensions(model, waterline)?;
    Ok(DimsReport { before, after, section_shift, stretch, knots_at_bends, refined, max_gap_after })
}
