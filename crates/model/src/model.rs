//! The model: the faces of any [`CadDocument`] as patches, their shared edges, and the
//! document they came from.

use crate::output::write_atomic;
use std::collections::BTreeMap;
use std::path::Path;

use cadmorph_brep::{BoundCurve, CadDocument, EntityRef, Face, Format, FreeCurve, ReadDocument, Skipped, Units};
use cadmorph_nurbs::{NurbsCurve, NurbsSurface};
use cadmorph_seam::{measure_boundary, measure_edge, Face as SeamFace, SeamReport, SharedBoundary, TrimEdge};
use serde::Serialize;

use crate::edges::{shared_edges, size_of};
use crate::{Error, Result};

/// A face of the model: an exact NURBS patch in world coordinates and model units, tied
/// to its entities (see [`cadmorph_brep::Face`]).
pub type Patch = Face;

/// A CAD document with its faces as patches and the edges they share.
///
/// The model knows no file format: everything it reads and writes goes through the
/// [`CadDocument`] trait, so the same code morphs, refines and measures IGES and STEP.
/// `D` defaults to a boxed document of either format, as the facade's `cadmorph::open`
/// returns it.
///
/// State is kept in memory: after a morph or an edit the patches and curves are what
/// was written, without reading the file again. [`verify`](Self::verify) reads the
/// written document back and measures it, for reports that must describe the file.
pub struct Model<D: CadDocument = Box<dyn CadDocument>> {
    pub(crate) doc: D,
    pub(crate) faces: Vec<Face>,
    pub(crate) skipped: Vec<Skipped>,
    pub(crate) units: Units,
    /// Curves bounding the faces (trims, B-rep edges), by face.
    pub(crate) bounds: Vec<BoundCurve>,
    /// Model-space curves bounding no face.
    pub(crate) free: Vec<FreeCurve>,
    /// Coinciding iso-boundaries.
    pub(crate) iso: Vec<SharedBoundary>,
    /// Edges from the file's topology or trims that are not among `iso`.
    pub(crate) trims: Vec<TrimEdge>,
}

/// Progress of long model work (seam measurement, refinement, moving control points,
/// writing), for a progress bar. Both methods default to doing nothing.
pub trait Progress: Sync {
    /// A stage of `total` steps begins (`total` 0: unknown).
    fn start(&self, _stage: &str, _total: u64) {}
    /// `n` more steps of the current stage are done.
    fn step(&self, _n: u64) {}
}

/// Reports no progress.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}

/// Per-face summary of [`Info`].
#[derive(Debug, Clone, Serialize)]
pub struct PatchInfo {
    /// The face entity.
    pub face: EntityRef,
    /// Its surface entity.
    pub surface: EntityRef,
    /// Surface type as the file names it.
    pub kind: String,
    /// Degree in u of the exact NURBS form.
    pub u_degree: usize,
    /// Degree in v.
    pub v_degree: usize,
    /// Poles in u.
    pub n_u: usize,
    /// Poles in v.
    pub n_v: usize,
    /// Whether it has weights.
    pub rational: bool,
    /// Whether the file holds an analytic surface.
    pub analytic: bool,
    /// Whether the face is trimmed.
    pub trimmed: bool,
    /// Whether the face is reversed.
    pub reversed: bool,
}

/// What `cadmorph info` prints.
#[derive(Debug, Clone, Serialize)]
pub struct Info {
    /// File format.
    pub format: Format,
    /// Length unit name.
    pub unit: String,
    /// Metres per model unit.
    pub metres_per_unit: f64,
    /// Entity (IGES type number) or instance (STEP name) counts.
    pub entity_counts: BTreeMap<String, usize>,
    /// IGES entities kept verbatim without a typed view.
    pub unknown_entities: usize,
    /// The faces.
    pub patches: Vec<PatchInfo>,
    /// Faces that could not be converted, with the reason.
    pub skipped: Vec<Skipped>,
}

/// What [`Model::verify`] found in the written document, read back.
#[derive(Debug, Clone, Serialize)]
pub struct Verification {
    /// Seams of the document as read back, found and measured as `cadmorph seams` finds
    /// and measures them in the written file (its edges, its edge curves, 200 samples).
    pub seams: SeamReport,
    /// Largest distance between a B-spline face's control point in memory and the one
    /// read back (the file's number format; 0 for STEP's round-trip reals).
    pub max_deviation: f64,
}

impl<D: ReadDocument> Model<D> {
    /// Reads a document of format `D` from `bytes`; see [`new`](Model::new).
    ///
    /// # Errors
    ///
    /// The reader's error ([`Error::Document`]), naming the position in the input.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        Model::new(D::from_bytes(bytes)?)
    }

    /// Reads the file at `path` as a document of format `D`.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] or [`Error::Read`] with the path.
    pub fn open(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_owned(), source })?;
        let doc = D::from_bytes(&bytes).map_err(|source| Error::Read { path: path.to_owned(), source })?;
        Model::new(doc).map_err(|e| match e {
            Error::Document(source) => Error::Read { path: path.to_owned(), source },
            other => other,
        })
    }
}

impl<D: CadDocument> Model<D> {
    /// The model of `doc`: every face as a world-coordinate NURBS patch, the curves that
    /// bound them, and the edges they share. Faces that cannot be converted stay in the
    /// file untouched and are listed by [`Info::skipped`].
    ///
    /// # Errors
    ///
    /// The document's errors (units, topology).
    pub fn new(doc: D) -> Result<Self> {
        let units = doc.units()?;
        let mut model = Self {
            doc,
            faces: Vec::new(),
            skipped: Vec::new(),
            units,
            bounds: Vec::new(),
            free: Vec::new(),
            iso: Vec::new(),
            trims: Vec::new(),
        };
        model.reload()?;
        Ok(model)
    }

    /// Reads the faces, their curves and shared edges from the document again (after
    /// an edit that changed entities, such as [`CadDocument::unshare`]).
    pub(crate) fn reload(&mut self) -> Result<()> {
        let set = self.doc.faces()?;
        let bounds = self.doc.bound_curves(&set.faces)?;
        let free = self.doc.free_curves()?;
        let (iso, trims) = shared_edges(&set.faces, &bounds);
        (self.faces, self.skipped, self.bounds, self.free, self.iso, self.trims) =
            (set.faces, set.skipped, bounds, free, iso, trims);
        Ok(())
    }

    /// The document (as edited so far).
    pub fn document(&self) -> &D {
        &self.doc
    }

    /// The document, giving up the model.
    pub fn into_document(self) -> D {
        self.doc
    }

    /// The file format.
    pub fn format(&self) -> Format {
        self.doc.format()
    }

    /// The faces as patches, in file order.
    pub fn patches(&self) -> &[Patch] {
        &self.faces
    }

    /// The curves that bound the faces (trims, B-rep edges), one per face using each.
    pub fn bound_curves(&self) -> &[BoundCurve] {
        &self.bounds
    }

    /// The model-space curves that bound no face.
    pub fn free_curves(&self) -> &[FreeCurve] {
        &self.free
    }

    /// The model's units.
    pub fn units(&self) -> &Units {
        &self.units
    }

    /// The name of the length unit.
    pub fn unit(&self) -> &str {
        &self.units.name
    }

    /// The diagonal of the box around all control points (the model size).
    pub fn size(&self) -> f64 {
        size_of(&self.faces)
    }

    /// A summary: format, unit, entity counts, faces.
    pub fn info(&self) -> Info {
        let patches = self
            .faces
            .iter()
            .map(|p| PatchInfo {
                face: p.entity,
                surface: p.surface_entity,
                kind: p.type_name.clone(),
                u_degree: p.surface.u_degree(),
                v_degree: p.surface.v_degree(),
                n_u: p.surface.n_u(),
                n_v: p.surface.n_v(),
                rational: p.surface.is_rational(),
                analytic: p.kind.is_analytic(),
                trimmed: p.trimmed,
                reversed: p.reversed,
            })
            .collect();
        Info {
            format: self.format(),
            unit: self.units.name.clone(),
            metres_per_unit: self.units.metres_per_unit,
            entity_counts: self.doc.entity_counts(),
            unknown_entities: self.doc.unknown_entities(),
            patches,
            skipped: self.skipped.clone(),
        }
    }

    /// Shared iso boundaries between the patches, found from geometry: sides that lie on
    /// each other within `1e-3 ×` the model size (so defects up to that size are seen).
    /// These are the edges that seam repair can make exact.
    pub fn edges(&self) -> &[SharedBoundary] {
        &self.iso
    }

    /// The other shared edges: from the file's topology (STEP B-rep edges, IGES 504
    /// edges used by two 510 faces) and trimming curves of two faces that lie on each
    /// other within `1e-3 ×` the model size (IGES 144/143), leaving out those that are
    /// also iso-boundary edges ([`edges`](Self::edges)).
    pub fn trim_edges(&self) -> &[TrimEdge] {
        &self.trims
    }

    pub(crate) fn seam_faces(&self) -> Vec<SeamFace<'_>> {
        self.faces.iter().map(|p| SeamFace { surface: &p.surface, reversed: p.reversed }).collect()
    }

    /// Measures every shared edge, iso-boundary and trim edges, with `samples` points.
    pub fn seams(&self, samples: usize) -> SeamReport {
        self.seams_with_progress(samples, &Silent)
    }

    /// [`seams`](Self::seams), reporting each edge measured to `progress`.
    pub fn seams_with_progress(&self, samples: usize, progress: &dyn Progress) -> SeamReport {
        progress.start("measuring seams", (self.iso.len() + self.trims.len()) as u64);
        use rayon::prelude::*;
        let faces = self.seam_faces();
        // Edges are measured in parallel (each on its own; the report keeps their order).
        let iso = self.iso.par_iter().map(|e| measure_boundary(&faces, e, samples));
        let trims = self.trims.par_iter().map(|e| measure_edge(&faces, e, samples));
        SeamReport::new(iso.chain(trims).inspect(|_| progress.step(1)).collect())
    }

    /// Finds the edges that are not iso-boundaries again from the curves in memory,
    /// keeping the iso-boundary edges.
    pub(crate) fn rebuild_trims(&mut self) {
        self.trims = crate::edges::trims_off(&self.faces, &self.bounds, &self.iso);
    }

    /// Finds the shared edges again from the patches and curves in memory.
    pub(crate) fn rebuild_edges(&mut self) {
        let (iso, trims) = shared_edges(&self.faces, &self.bounds);
        self.iso = iso;
        self.trims = trims;
    }

    /// Writes `s` (world coordinates, model units) as the surface of patch `index`, and
    /// re-traces the curves that bound it on the new surface (in the face's parameters:
    /// each curve point keeps its `(u, v)` on the face), so the face's trims and edges
    /// stay on it. An analytic face first becomes its exact B-spline form. A curve the
    /// face shares with a neighbour is traced on this face; keep the neighbour's side
    /// along it yourself. Returns the number of curves rewritten.
    ///
    /// # Errors
    ///
    /// [`Error::NoPatch`]; the document's errors (non-finite values, ...).
    pub fn set_patch_surface(&mut self, index: usize, s: NurbsSurface) -> Result<usize> {
        let len = self.faces.len();
        let face = self.faces.get(index).ok_or(Error::NoPatch { index, len })?.clone();
        let mut written = face.clone();
        if face.kind.is_analytic() {
            self.doc.bspline_form(&face)?;
            written.kind = cadmorph_brep::SurfaceKind::BSpline;
        }
        self.doc.set_face_surface(&written, &s)?;
        let tol = 1e-7 * self.size();
        let identity = cadmorph_morph::Affine::identity();
        let mut n = 0;
        let mut done: Vec<EntityRef> = Vec::new();
        for k in 0..self.bounds.len() {
            let b = &self.bounds[k];
            if b.face != index {
                continue;
            }
            let traced = crate::trace::follow_face(&b.curve, &face.surface, &s, &identity, tol);
            let Some(c) = traced.filter(|c| *c != b.curve) else { continue };
            if let Some(t) = b.target {
                if !done.contains(&t) && self.doc.set_bound_curve(b, &c)? {
                    n += 1;
                }
                done.push(t);
            }
            self.set_bound_in_memory(k, c);
        }
        written.surface = s;
        self.faces[index] = written;
        self.rebuild_edges();
        Ok(n)
    }

    /// Puts curve `c` in place of bound curve `k` and of every other bound curve with the
    /// same target and piece (the same edge seen from its other face). A range that was
    /// the whole curve becomes the new curve's whole domain.
    pub(crate) fn set_bound_in_memory(&mut self, k: usize, c: NurbsCurve) {
        let (target, piece) = (self.bounds[k].target, self.bounds[k].piece);
        let d = cadmorph_nurbs::Curve::domain(&c);
        for (j, b) in self.bounds.iter_mut().enumerate() {
            if j == k || (target.is_some() && b.target == target && b.piece == piece) {
                let d0 = cadmorph_nurbs::Curve::domain(&b.curve);
                if b.range == (*d0.start(), *d0.end()) {
                    b.range = (*d.start(), *d.end());
                }
                b.curve = c.clone();
            }
        }
    }

    /// The document as bytes: the input, byte for byte, where nothing was edited.
    pub fn to_bytes(&self) -> Vec<u8> {
        self.doc.to_bytes()
    }

    /// Writes the document to `path` through a temporary file in the same folder and a
    /// rename, so a failure never leaves half a file. The file's extension must be one
    /// of the document's format (`.igs`/`.iges` for IGES, `.stp`/`.step`/`.p21` for
    /// STEP); a document is written in its own format only.
    ///
    /// # Errors
    ///
    /// [`Error::UnknownExtension`] for an extension of no format or of the other format
    /// (nothing is written), [`Error::Write`].
    pub fn save(&self, path: &Path) -> Result<()> {
        match Format::from_extension(path) {
            Some(f) if f == self.format() => write_atomic(path, &self.to_bytes()),
            _ => Err(Error::UnknownExtension { path: path.to_owned() }),
        }
    }

    /// Reads what was written back into a new document of the same format and measures
    /// it: the seams, exactly as `cadmorph seams` finds them in the written file, and the
    /// largest control-point difference to the patches in memory.
    ///
    /// # Errors
    ///
    /// [`Error::ReadBack`] when the document does not read back with the same faces;
    /// the reader's errors.
    pub fn verify(&self) -> Result<Verification> {
        let back_doc = self.doc.read_back()?;
        let back_faces = back_doc.faces()?.faces;
        if back_faces.len() != self.faces.len() {
            return Err(Error::ReadBack(format!(
                "{} faces in memory, {} read back",
                self.faces.len(),
                back_faces.len()
            )));
        }
        let mut max_deviation = 0.0f64;
        for (a, b) in self.faces.iter().zip(&back_faces) {
            if a.entity != b.entity {
                return Err(Error::ReadBack(format!("face {} reads back as {}", a.entity, b.entity)));
            }
            // An analytic face's patch spans the box of its edges, which edits of its
            // neighbours move: only B-spline faces are held to what was written.
            if a.kind.is_analytic() {
                continue;
            }
            if a.surface.control_points().len() != b.surface.control_points().len() {
                return Err(Error::ReadBack(format!("face {} reads back with other poles", a.entity)));
            }
            for (p, q) in a.surface.control_points().iter().zip(b.surface.control_points()) {
                max_deviation = max_deviation.max((p - q).norm());
            }
        }
        let seams = Model::new(back_doc)?.seams(200);
        Ok(Verification { seams, max_deviation })
    }
}
