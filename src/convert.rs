//! Conversion between IGES and STEP: a model's faces written as a new document of the
//! other format.
//!
//! What converts today: faces bounded by their surface's own boundary (untrimmed IGES
//! 128/144 faces, STEP faces whose loops run along the surface's sides), written as
//! their exact NURBS form (analytic surfaces too: they become rational B-splines), in
//! the same length unit. STEP output is one shell whose faces share the edges and
//! vertices that coincide; IGES output is one 128 per face. A face trimmed inside its
//! surface is refused ([`Error::Unsupported`]) rather than written without its trims, and
//! so is a document with curves outside faces (wireframe), or without faces.

use std::path::Path;

use cadmorph_brep::{CadDocument, Format, ReadDocument};
use cadmorph_model::{write_atomic, Error, Model, Result};
use cadmorph_nurbs::{Curve, CurveProject, NurbsSurface, Side};

/// Whether every bound curve of face `i` runs along one of its surface's four sides
/// (within `tol`, checked at 5 points each): the face is its whole surface.
fn is_natural<D: CadDocument>(m: &Model<D>, i: usize, tol: f64) -> bool {
    let s = &m.patches()[i].surface;
    let sides: Vec<_> = [Side::UMin, Side::UMax, Side::VMin, Side::VMax].into_iter().map(|k| s.boundary(k)).collect();
    m.bound_curves().iter().filter(|b| b.face == i).all(|b| {
        (0..5).all(|k| {
            let t = b.range.0 + (b.range.1 - b.range.0) * k as f64 / 4.0;
            let p = b.curve.eval(t);
            sides.iter().any(|c| c.project(&p, tol * 1e-3).distance_sq <= tol * tol)
        })
    })
}

/// The faces of `m` as untrimmed NURBS surfaces, or [`Error::Unsupported`] for a face
/// trimmed inside its surface.
fn surfaces<D: CadDocument>(m: &Model<D>) -> Result<Vec<NurbsSurface>> {
    if m.patches().is_empty() || !m.free_curves().is_empty() {
        // Wireframe (curves outside faces) does not convert yet; refuse rather than drop it.
        return Err(Error::Unsupported("converting curves outside faces (only faces convert yet)"));
    }
    let tol = 1e-6 * m.size().max(f64::MIN_POSITIVE);
    for (i, f) in m.patches().iter().enumerate() {
        if f.trimmed && !is_natural(m, i, tol) {
            return Err(Error::Unsupported(
                "converting a face trimmed inside its surface (only untrimmed faces convert yet)",
            ));
        }
    }
    Ok(m.patches().iter().map(|f| f.surface.clone()).collect())
}

/// The IGES unit of `metres` per unit (IGES 5.3 §2.2.4.3, global parameter 14), if
/// there is one.
fn iges_units(metres: f64) -> Option<crate::iges::Units> {
    use crate::iges::Units as U;
    [U::Inch, U::Millimetre, U::Foot, U::Mile, U::Metre, U::Kilometre, U::Mil, U::Micron, U::Centimetre, U::Microinch]
        .into_iter()
        .find(|u| u.millimetres().is_some_and(|mm| (mm * 1e-3 - metres).abs() <= 1e-9 * metres))
}

/// `m`'s faces as a new document of `format` (see the module docs for what converts).
///
/// # Errors
///
/// [`Error::Unsupported`] for trimmed faces or a length unit IGES has no flag for; the
/// writer's errors.
pub fn convert<D: CadDocument>(m: &Model<D>, format: Format) -> Result<Box<dyn CadDocument>> {
    let faces = surfaces(m)?;
    let units = m.units();
    let tol = units.uncertainty.unwrap_or(1e-7 * m.size()).max(1e-9 * m.size());
    Ok(match format {
        Format::Step => {
            let wrap = |e| Error::Document(cadmorph_brep::Error::new(Format::Step, e));
            let mut b =
                crate::step::DocumentBuilder::new(crate::step::Schema::Ap214, "cadmorph", units.metres_per_unit, tol)
                    .map_err(wrap)?;
            b.add_shell(&faces, 1e-6 * m.size());
            Box::new(b.build().map_err(wrap)?)
        }
        Format::Iges => {
            let u =
                iges_units(units.metres_per_unit).ok_or(Error::Unsupported("a length unit IGES has no flag for"))?;
            let mut b = crate::iges::write::DocumentBuilder::new(u).resolution(tol);
            for s in &faces {
                b.add_surface(s);
            }
            Box::new(<crate::iges::Document as ReadDocument>::from_bytes(&b.to_bytes())?)
        }
    })
}

/// Writes `m` to `path` in the format its extension names: the edited document itself
/// for the model's own format, a converted one ([`convert`]) for the other.
///
/// # Errors
///
/// [`Error::UnknownExtension`] for an extension of no format (nothing is written);
/// those of [`convert`]; [`Error::Write`].
pub fn save_as<D: CadDocument>(m: &Model<D>, path: &Path) -> Result<()> {
    match Format::from_extension(path) {
        None => Err(Error::UnknownExtension { path: path.to_owned() }),
        Some(f) if f == m.format() => m.save(path),
        Some(f) => write_atomic(path, &convert(m, f)?.to_bytes()),
    }
}
