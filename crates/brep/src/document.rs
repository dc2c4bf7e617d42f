//! The document trait both formats implement.

use std::collections::BTreeMap;

use cadmorph_nurbs::{NurbsCurve, NurbsSurface};

use crate::{BoundCurve, EntityRef, Face, FaceSet, Format, FreeCurve, Result, Units};

/// A CAD document seen through what IGES and STEP have in common: faces as exact NURBS
/// patches, the curves that bound them, the other model-space curves, and the edits a
/// shape-parameterisation run makes.
///
/// # Contract
///
/// Every implementation keeps these rules; `cadmorph-model` relies on them.
///
/// 1. **Lossless.** [`to_bytes`](Self::to_bytes) of a document nothing was set on is
///    the input, byte for byte. An edit rewrites only the entities it changes (and adds
///    new ones); every other entity keeps its text.
/// 2. **One frame.** Every surface and curve given or taken is in world coordinates
///    (assembly placements and IGES 124 matrices applied) and model units
///    ([`units`](Self::units)).
/// 3. **Stable order.** [`faces`](Self::faces) lists faces in file order, and the same
///    document gives the same list each time; [`bound_curves`](Self::bound_curves) takes
///    that list (or a subsequence of it) and refers to its faces by index into it.
/// 4. **Same parameters.** A face's [`Face::surface`] has the parameterisation its
///    trims and pcurves refer to (OCCT's, through the exact NURBS form's maps), so a
///    surface set with [`set_face_surface`](Self::set_face_surface) that keeps the
///    domain keeps the trims valid.
/// 5. **Edits are exact or refused.** A setter writes the geometry it is given (to the
///    file's number format) or returns an error and leaves the document as it was
///    for that entity; it returns `Ok(false)` when the geometry equals what is there and
///    nothing was written.
/// 6. **Shared entities move once.** Where two faces share an entity (STEP control
///    points, an IGES 504 edge, a STEP edge's vertices), setting it from one face and
///    then from the other with the same value writes it once; setting it to a different
///    value from the second face gives that face its own copy rather than moving the
///    first face.
pub trait CadDocument {
    /// The document's format.
    fn format(&self) -> Format;

    /// The model's length unit and tolerance.
    ///
    /// # Errors
    ///
    /// Malformed unit entities.
    fn units(&self) -> Result<Units>;

    /// Entities by type (IGES entity type number, STEP entity name) and how many.
    fn entity_counts(&self) -> BTreeMap<String, usize>;

    /// Entities kept verbatim without a typed view (0 where the format keeps all alike).
    fn unknown_entities(&self) -> usize;

    /// Every face as an exact NURBS patch, in file order; faces that do not convert are
    /// listed in [`FaceSet::skipped`] (and stay in the file untouched).
    ///
    /// # Errors
    ///
    /// Malformed topology that makes the face list itself unreadable.
    fn faces(&self) -> Result<FaceSet>;

    /// The model-space curves bounding `faces` (as [`faces`](Self::faces) returned
    /// them, or a subsequence of that list), one entry per face that uses a curve.
    ///
    /// # Errors
    ///
    /// Malformed loops or edges.
    fn bound_curves(&self, faces: &[Face]) -> Result<Vec<BoundCurve>>;

    /// Model-space curves that bound no face.
    ///
    /// # Errors
    ///
    /// Malformed curve entities.
    fn free_curves(&self) -> Result<Vec<FreeCurve>>;

    /// Replaces the analytic (or offset, or polynomial) surface of `face` by its exact
    /// B-spline form in the file and returns that form (world coordinates, model units).
    /// Its domain may differ from [`Face::surface`]'s (IGES writes the entity's own
    /// extent), and the face's trims are rewritten to match. A face that is already a
    /// B-spline is returned as it is.
    ///
    /// # Errors
    ///
    /// Surfaces that have no exact B-spline form the format can write.
    fn bspline_form(&mut self, face: &Face) -> Result<NurbsSurface>;

    /// Writes `s` (world coordinates, model units) as the B-spline surface of `face`,
    /// which must already be a B-spline in the file (see
    /// [`bspline_form`](Self::bspline_form)). Returns whether anything was written.
    ///
    /// # Errors
    ///
    /// Non-finite values, a singular placement, a face whose surface is not a B-spline.
    fn set_face_surface(&mut self, face: &Face, s: &NurbsSurface) -> Result<bool>;

    /// Gives the bound curve `b` the geometry `c` (world coordinates, model units,
    /// running the way `b.curve` runs, ends at the edge's vertices), moving the edge's
    /// vertices to its ends where the file has vertices. Returns whether anything was
    /// written; `Ok(false)` also when `b.target` is `None`.
    ///
    /// # Errors
    ///
    /// Non-finite or (for STEP) rational curves, a singular placement.
    fn set_bound_curve(&mut self, b: &BoundCurve, c: &NurbsCurve) -> Result<bool>;

    /// Gives the free curve `f` the geometry `c` (world coordinates, model units).
    /// Returns whether anything was written.
    ///
    /// # Errors
    ///
    /// Non-finite values.
    fn set_free_curve(&mut self, f: &FreeCurve, c: &NurbsCurve) -> Result<bool>;

    /// Gives each placement of a part placed more than once (an assembly's repeated
    /// component, a mapped representation, an IGES subfigure) that holds one of the
    /// placed faces `moved` its own copy of the part, so that a morph can move each
    /// placement its own way. Afterwards [`faces`](Self::faces) lists the same faces in the same order at the
    /// same places; those of the copies carry new entities. Placements holding no moved
    /// face keep sharing. Returns the number of copies made; the default, for formats
    /// that cannot copy, makes none.
    ///
    /// # Errors
    ///
    /// Malformed placements or product structure.
    fn unshare(&mut self, _moved: &[EntityRef]) -> Result<usize> {
        Ok(0)
    }

    /// The document as file bytes.
    fn to_bytes(&self) -> Vec<u8>;

    /// A new document read from [`to_bytes`](Self::to_bytes), by the same format's
    /// reader: what a program reading the written file would see. Used to verify
    /// that what was written is what was meant.
    ///
    /// # Errors
    ///
    /// The reader's errors (a document that does not read back is a bug).
    fn read_back(&self) -> Result<Box<dyn CadDocument>>;
}

/// A [`CadDocument`] that reads itself from bytes.
pub trait ReadDocument: CadDocument + Sized {
    /// Reads a document of this format.
    ///
    /// # Errors
    ///
    /// The format reader's errors, naming the position in the input.
    fn from_bytes(bytes: &[u8]) -> Result<Self>;
}

impl<D: CadDocument + ?Sized> CadDocument for Box<D> {
    fn format(&self) -> Format {
        (**self).format()
    }
    fn units(&self) -> Result<Units> {
        (**self).units()
    }
    fn entity_counts(&self) -> BTreeMap<String, usize> {
        (**self).entity_counts()
    }
    fn unknown_entities(&self) -> usize {
        (**self).unknown_entities()
    }
    fn faces(&self) -> Result<FaceSet> {
        (**self).faces()
    }
    fn bound_curves(&self, faces: &[Face]) -> Result<Vec<BoundCurve>> {
        (**self).bound_curves(faces)
    }
    fn free_curves(&self) -> Result<Vec<FreeCurve>> {
        (**self).free_curves()
    }
    fn bspline_form(&mut self, face: &Face) -> Result<NurbsSurface> {
        (**self).bspline_form(face)
    }
    fn set_face_surface(&mut self, face: &Face, s: &NurbsSurface) -> Result<bool> {
        (**self).set_face_surface(face, s)
    }
    fn set_bound_curve(&mut self, b: &BoundCurve, c: &NurbsCurve) -> Result<bool> {
        (**self).set_bound_curve(b, c)
    }
    fn set_free_curve(&mut self, f: &FreeCurve, c: &NurbsCurve) -> Result<bool> {
        (**self).set_free_curve(f, c)
    }
    fn unshare(&mut self, moved: &[EntityRef]) -> Result<usize> {
        (**self).unshare(moved)
    }
    fn to_bytes(&self) -> Vec<u8> {
        (**self).to_bytes()
    }
    fn read_back(&self) -> Result<Box<dyn CadDocument>> {
        (**self).read_back()
    }
}
