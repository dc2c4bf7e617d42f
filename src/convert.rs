//! Conversion between IGES and STEP: a model's faces written as a new document of the
//! other format.
//!
//! Every face converts, written as its exact NURBS surface (analytic surfaces too: they
//! become rational B-splines) in the same length unit:
//! - when every face is its whole surface (untrimmed IGES 128/144 faces, STEP faces whose
//!   loops run along the surface's sides), STEP output is one shell whose faces share
//!   the edges and vertices that coincide and IGES output is one 128 per face;
//! - otherwise each trimmed face keeps its loops ([`crate::loops`]): STEP writes an
//!   ADVANCED_FACE per face with shared EDGE_CURVEs carrying a PCURVE on each side
//!   (a CLOSED_SHELL in a MANIFOLD_SOLID_BREP when every edge is used twice, else an
//!   OPEN_SHELL), IGES a 144 per trimmed face whose 142 bounds carry model and
//!   parameter-space curves (IGES 5.3 §4.32, §4.34);
//! - IGES output writes each connected set of faces that closes up as a 186 B-rep solid
//!   ([`IgesFaces::Brep`], the default) or every face on its own
//!   ([`IgesFaces::Trimmed`]); STEP output always makes such a set a solid. Faces of a
//!   solid are turned so their normals point out ([`cadmorph_brep::orient_outward`]):
//!   IGES faces outside a 186 carry no orientation.
//!
//! A document with curves outside faces (wireframe), or without faces, is refused
//! ([`Error::Unsupported`]) rather than written without them; a face whose loops cannot
//! be closed is refused with [`Error::Convert`] naming it.

use std::path::Path;

use cadmorph_brep::{BoundedFace, CadDocument, Format, ReadDocument};
use cadmorph_model::{write_atomic, Error, Model, Result};
use cadmorph_nurbs::{Curve, CurveProject, NurbsSurface, Side};

/// Whether every bound curve of face `i` runs along one of its surface's four sides
/// (within `tol`, all of it along the same side, checked at 9 points unevenly spaced so
/// that a curve touching the sides at a few points, like a circle in the square patch of
/// its plane, is not taken for them): the face is its whole surface.
fn is_natural<D: CadDocument>(m: &Model<D>, i: usize, tol: f64) -> bool {
    const AT: [f64; 9] = [0.0, 0.0917, 0.2113, 0.3371, 0.5, 0.6629, 0.7887, 0.9083, 1.0];
    let s = &m.patches()[i].surface;
    let sides: Vec<_> = [Side::UMin, Side::UMax, Side::VMin, Side::VMax].into_iter().map(|k| s.boundary(k)).collect();
    m.bound_curves().iter().filter(|b| b.face == i).all(|b| {
        let points: Vec<_> = AT.iter().map(|f| b.curve.eval(b.range.0 + (b.range.1 - b.range.0) * f)).collect();
        sides.iter().any(|c| points.iter().all(|p| c.project(p, tol * 1e-3).distance_sq <= tol * tol))
    })
}

/// What a model's faces become in the other format.
enum Faces {
    /// Every face is its whole surface.
    Natural(Vec<NurbsSurface>),
    /// Some face is trimmed inside its surface: every face with its loops, and whether
    /// it is its whole surface.
    Bounded(Vec<BoundedFace>, Vec<bool>),
}

/// The faces of `m`: their surfaces when every face is its whole surface, else every
/// face bounded by its loops ([`crate::loops`]).
fn faces<D: CadDocument>(m: &Model<D>, tol: f64) -> Result<Faces> {
    if m.patches().is_empty() || !m.free_curves().is_empty() {
        // Wireframe (curves outside faces) does not convert yet; refuse rather than drop it.
        return Err(Error::Unsupported("converting curves outside faces (only faces convert yet)"));
    }
    faces_of(m, tol)
}

/// [`faces`] without the wireframe check.
fn faces_of<D: CadDocument>(m: &Model<D>, tol: f64) -> Result<Faces> {
    let side_tol = 1e-6 * m.size().max(f64::MIN_POSITIVE);
    let natural: Vec<bool> =
        m.patches().iter().enumerate().map(|(i, f)| !f.trimmed || is_natural(m, i, side_tol)).collect();
    if natural.iter().all(|&n| n) {
        return Ok(Faces::Natural(m.patches().iter().map(|f| f.surface.clone()).collect()));
    }
    let mut out = Vec::with_capacity(natural.len());
    for (i, f) in m.patches().iter().enumerate() {
        out.push(if natural[i] {
            BoundedFace::natural(f.surface.clone(), f.reversed, tol)
        } else {
            crate::loops::bounded_face(m, i, tol)?
        });
    }
    Ok(Faces::Bounded(out, natural))
}

/// The model's tolerance (the file's own precision, at least 1e-9 of its size), and the
/// distance within which curve ends are one vertex: ten times that, at least 1e-6 of the
/// model's size (writers leave gaps of their tolerance at loop joints).
fn tolerances<D: CadDocument>(m: &Model<D>) -> (f64, f64) {
    let tol = m.units().uncertainty.unwrap_or(1e-7 * m.size()).max(1e-9 * m.size());
    (tol, (10.0 * tol).max(1e-6 * m.size()))
}

/// Every face of a model bounded by its loops, as the converters write them.
#[derive(Debug, Clone)]
pub struct BoundedFaces {
    /// Per face of the model, in its order: the face's surface and loops (its four sides
    /// when it is its whole surface).
    pub faces: Vec<BoundedFace>,
    /// Per face: whether it is its whole surface (its loops are the surface's sides).
    pub natural: Vec<bool>,
    /// The distance within which loop curve ends are one vertex, model units.
    pub join: f64,
}

/// The faces of `m` with their loops (see the `loops` module): what [`convert`] writes, and
/// what a watertight tessellation takes (`cadmorph_mesh::from_cad`). Curves outside
/// faces are left out.
///
/// # Errors
///
/// [`Error::Convert`] for a face whose loops do not close.
pub fn bounded_faces<D: CadDocument>(m: &Model<D>) -> Result<BoundedFaces> {
    let (_, join) = tolerances(m);
    let (faces, natural) = match faces_of(m, join)? {
        Faces::Natural(s) => {
            let n = s.len();
            let f = s.into_iter().zip(m.patches()).map(|(s, f)| BoundedFace::natural(s, f.reversed, join)).collect();
            (f, vec![true; n])
        }
        Faces::Bounded(f, natural) => (f, natural),
    };
    Ok(BoundedFaces { faces, natural, join })
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
/// [`Error::Unsupported`] for wireframe, a document without faces or a length unit IGES
/// has no flag for; [`Error::Convert`] for a face whose loops do not close; the writer's
/// errors.
pub fn convert<D: CadDocument>(m: &Model<D>, format: Format) -> Result<Box<dyn CadDocument>> {
    convert_with(m, format, &ConvertOptions::default())
}

/// How faces are written to IGES, which has two forms for them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum IgesFaces {
    /// Each connected set of faces that closes up as a 186 manifold solid B-rep (IGES 5.3
    /// §4.150–4.155: shell, faces, loops, shared edges and vertices), the others as
    /// trimmed surfaces: solids stay solids.
    #[default]
    Brep,
    /// Every face on its own, a 144 trimmed surface (a 128 when it is its whole
    /// surface), as OCCT's IGES writer does by default (`write.iges.brep.mode` Faces):
    /// for readers without B-rep entities.
    Trimmed,
}

/// Choices of [`convert_with`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ConvertOptions {
    /// The IGES form of faces.
    pub iges_faces: IgesFaces,
}

/// [`convert`] with `options`.
///
/// # Errors
///
/// Those of [`convert`].
pub fn convert_with<D: CadDocument>(
    m: &Model<D>,
    format: Format,
    options: &ConvertOptions,
) -> Result<Box<dyn CadDocument>> {
    let units = m.units();
    let (tol, join) = tolerances(m);
    let faces = faces(m, join)?;
    Ok(match format {
        Format::Step => {
            let wrap = |e| Error::Document(cadmorph_brep::Error::new(Format::Step, e));
            let mut b =
                crate::step::DocumentBuilder::new(crate::step::Schema::Ap214, "cadmorph", units.metres_per_unit, tol)
                    .map_err(wrap)?;
            match &faces {
                Faces::Natural(s) => {
                    b.add_shell(s, 1e-6 * m.size());
                }
                Faces::Bounded(f, _) => {
                    b.add_bounded_faces(f, join).map_err(wrap)?;
                }
            }
            Box::new(b.build().map_err(wrap)?)
        }
        Format::Iges => {
            let u =
                iges_units(units.metres_per_unit).ok_or(Error::Unsupported("a length unit IGES has no flag for"))?;
            let mut b = crate::iges::write::DocumentBuilder::new(u).resolution(tol);
            let wrap = |e| Error::Document(cadmorph_brep::Error::new(Format::Iges, e));
            match (&faces, options.iges_faces) {
                (Faces::Natural(s), IgesFaces::Trimmed) => {
                    for s in s {
                        b.add_surface(s);
                    }
                }
                (Faces::Natural(s), IgesFaces::Brep) => {
                    let bounded: Vec<BoundedFace> = s
                        .iter()
                        .zip(m.patches())
                        .map(|(s, f)| BoundedFace::natural(s.clone(), f.reversed, join))
                        .collect();
                    b.add_bounded_faces(&bounded, &vec![true; bounded.len()], join).map_err(wrap)?;
                }
                (Faces::Bounded(f, natural), IgesFaces::Trimmed) => {
                    for (face, &whole) in f.iter().zip(natural) {
                        if whole {
                            b.add_surface(&face.surface);
                        } else {
                            b.add_trimmed_face(face, join).map_err(wrap)?;
                        }
                    }
                }
                (Faces::Bounded(f, natural), IgesFaces::Brep) => {
                    b.add_bounded_faces(f, natural, join).map_err(wrap)?;
                }
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
    save_as_with(m, path, &ConvertOptions::default())
}

/// [`save_as`] converting with `options`.
///
/// # Errors
///
/// Those of [`save_as`].
pub fn save_as_with<D: CadDocument>(m: &Model<D>, path: &Path, options: &ConvertOptions) -> Result<()> {
    match Format::from_extension(path) {
        None => Err(Error::UnknownExtension { path: path.to_owned() }),
        Some(f) if f == m.format() => m.save(path),
        Some(f) => write_atomic(path, &convert_with(m, f, options)?.to_bytes()),
    }
}
