//! Faces as exact NURBS patches tied to their entities.

use cadmorph_nurbs::math::Matrix4;
use cadmorph_nurbs::NurbsSurface;
use serde::Serialize;

use crate::EntityRef;

/// The kind of surface a face lies on, as the file holds it.
///
/// | kind | IGES | STEP |
/// | --- | --- | --- |
/// | `Plane` | 108, 190 | `PLANE` |
/// | `Cylinder` | 192 | `CYLINDRICAL_SURFACE` |
/// | `Cone` | 194 | `CONICAL_SURFACE` |
/// | `Sphere` | 196 | `SPHERICAL_SURFACE` |
/// | `Torus` | 198 | `TOROIDAL_SURFACE` |
/// | `Revolution` | 120 | `SURFACE_OF_REVOLUTION` |
/// | `Extrusion` | 122 | `SURFACE_OF_LINEAR_EXTRUSION` |
/// | `Ruled` | 118 | |
/// | `Offset` | 140 | |
/// | `Spline` | 114 | |
/// | `BSpline` | 128 | `B_SPLINE_SURFACE_WITH_KNOTS` (and the rational complex form) |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum SurfaceKind {
    /// A plane.
    Plane,
    /// A right circular cylinder.
    Cylinder,
    /// A right circular cone.
    Cone,
    /// A sphere.
    Sphere,
    /// A torus.
    Torus,
    /// A surface of revolution.
    Revolution,
    /// A surface of linear extrusion (IGES tabulated cylinder).
    Extrusion,
    /// A ruled surface between two curves.
    Ruled,
    /// An offset surface.
    Offset,
    /// A parametric (polynomial) spline surface.
    Spline,
    /// A (rational) B-spline surface.
    BSpline,
    /// Any other surface the format layer converts.
    Other,
}

impl SurfaceKind {
    /// Whether the file holds the surface in another form than a B-spline (analytic,
    /// offset, polynomial): a morph first replaces it by its exact B-spline form
    /// ([`CadDocument::bspline_form`](crate::CadDocument::bspline_form)).
    pub fn is_analytic(self) -> bool {
        self != SurfaceKind::BSpline
    }
}

/// One face of a document as an exact NURBS patch in world coordinates and model units.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The face entity (IGES 144, 143, 510 or a bare surface; STEP `ADVANCED_FACE`,
    /// `FACE_SURFACE`), with its assembly occurrence.
    pub entity: EntityRef,
    /// The surface entity under it (equal to `entity` for a bare IGES surface).
    pub surface_entity: EntityRef,
    /// The exact NURBS form of the surface: B-splines over their whole domain, analytic
    /// surfaces over the face's parameter box, world coordinates, model units.
    pub surface: NurbsSurface,
    /// The face's parameter box in the file's own surface parameters (OCCT's), `(u, v)`.
    pub parameter_box: ((f64, f64), (f64, f64)),
    /// The face's normal opposes the surface normal.
    pub reversed: bool,
    /// The face trims its surface (IGES 144 with boundaries, 143, 510; every STEP face).
    pub trimmed: bool,
    /// The kind of surface the file holds.
    pub kind: SurfaceKind,
    /// The surface's type as the file names it (`IGES 128`, `B_SPLINE_SURFACE`, `Plane`).
    pub type_name: String,
    /// File coordinates of the surface entity to world coordinates (a STEP assembly
    /// placement; identity for IGES, whose 124 matrices are applied in `surface`).
    pub placement: Matrix4<f64>,
}

/// A face the format layer could not convert: it stays in the file untouched.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Skipped {
    /// The face entity.
    pub entity: EntityRef,
    /// Why (the format layer's error message).
    pub reason: String,
}

/// What [`CadDocument::faces`](crate::CadDocument::faces) returns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FaceSet {
    /// The faces that convert, in file order.
    pub faces: Vec<Face>,
    /// The faces that do not.
    pub skipped: Vec<Skipped>,
}
