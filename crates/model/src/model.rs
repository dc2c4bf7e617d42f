//! The model: patches of an IGES or STEP document, seams, morph, save.

use std::collections::{BTreeMap, HashSet};
use std::fmt;
use std::ops::RangeInclusive;
use std::path::Path;

use cadmorph_iges as iges;
use cadmorph_morph::Deformation;
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{NurbsSurface, Surface};
use cadmorph_seam::{
    make_compatible, measure_boundary, measure_edge, measure_edge_samples, refine_edges, refine_uniform, repair,
    shared_boundaries, EdgeSamples, Face, SeamRefineOptions, SeamRefinement, SeamReport, SharedBoundary, TrimEdge,
};
use cadmorph_step as step;
use serde::Serialize;

use crate::topology::{iges_edges, iges_face_bounds, iges_reversed_faces, step_edges, step_face_patches, FaceBound};
use crate::{Error, Result};

/// The file format a model came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Format {
    /// IGES 5.3 fixed format.
    Iges,
    /// ISO 10303-21 (STEP).
    Step,
}

/// The entities a patch came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Source {
    /// IGES: the face entity (144, 143, 510, or the bare surface) and its surface entity.
    Iges {
        /// Face DE number.
        face: u32,
        /// Surface DE number.
        surface: u32,
    },
    /// STEP: the face instance and its surface instance.
    Step {
        /// Face instance id.
        face: u64,
        /// Surface instance id.
        surface: u64,
    },
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Iges { face, surface } if face == surface => write!(f, "DE {face}"),
            Source::Iges { face, surface } => write!(f, "DE {face} (surface DE {surface})"),
            Source::Step { face, surface } => write!(f, "#{face} (surface #{surface})"),
        }
    }
}

/// One face as a NURBS patch in world coordinates and model units.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// The exact NURBS form of the face's surface.
    pub surface: NurbsSurface,
    /// Face orientation opposite to the surface normal.
    pub reversed: bool,
    /// Where it came from.
    pub source: Source,
    /// The surface type as the file names it (IGES entity type, STEP surface kind).
    pub kind: String,
    /// Whether the file holds an analytic surface (plane, cylinder, ...) here.
    pub analytic: bool,
    /// Whether the face trims its surface.
    pub trimmed: bool,
}

enum Doc {
    Iges(Box<iges::Document>),
    Step(Box<step::Document>),
}

/// An IGES or STEP document with its faces as patches.
pub struct Model {
    doc: Doc,
    patches: Vec<Patch>,
    skipped: Vec<(String, String)>,
    unit: String,
    /// Coinciding iso-boundaries.
    iso: Vec<SharedBoundary>,
    /// Edges from the file's topology or trims that are not among `iso`.
    trims: Vec<TrimEdge>,
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

/// Settings of [`Model::morph`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MorphOptions {
    /// Seam-driven refinement before the morph (gap and angle tolerances).
    pub refine: Option<SeamRefineOptions>,
    /// PyGeM-style refinement: this many evenly spaced knots per direction on every patch.
    pub uniform_knots: Option<usize>,
    /// Make knots compatible across shared edges before the morph and make the two
    /// sides of every shared edge identical after it (exact C0, and G1 for
    /// non-rational patches).
    pub repair: bool,
}

/// What [`Model::morph`] did.
#[derive(Debug, Clone, Serialize)]
pub struct MorphOutcome {
    /// Control points of all patches before.
    pub control_points_before: usize,
    /// Control points of all patches after (refinement adds some).
    pub control_points_after: usize,
    /// Faces whose entities were rewritten.
    pub faces_rewritten: usize,
    /// Model-space curves whose entities were rewritten.
    pub curves_rewritten: usize,
    /// The seam refinement's report, when it ran.
    pub refinement: Option<SeamRefinement>,
    /// Seams before the morph.
    pub seams_before: SeamReport,
    /// Seams of the written document, read back.
    pub seams_after: SeamReport,
}

/// Per-face summary of [`Info`].
#[derive(Debug, Clone, Serialize)]
pub struct PatchInfo {
    /// Where the face came from.
    pub source: String,
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
    /// Entity (IGES type number) or instance (STEP name) counts.
    pub entity_counts: BTreeMap<String, usize>,
    /// IGES entities kept verbatim without a typed view.
    pub unknown_entities: usize,
    /// The faces.
    pub patches: Vec<PatchInfo>,
    /// Faces that could not be converted, with the reason.
    pub skipped: Vec<(String, String)>,
}

fn is_step(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    bytes[start..].starts_with(b"ISO-10303-21")
}

impl Model {
    /// Reads an IGES or STEP document (told apart by the STEP header line) and converts
    /// every face to a world-coordinate NURBS patch. Faces that cannot be converted are
    /// kept in the file and listed by [`Info::skipped`].
    ///
    /// # Errors
    ///
    /// The reader's error, naming the position in the file.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        if is_step(bytes) {
            Self::from_step(step::Document::parse(bytes)?)
        } else {
            Self::from_iges(iges::Document::parse(bytes)?)
        }
    }

    /// Reads a file; see [`from_bytes`](Self::from_bytes).
    ///
    /// # Errors
    ///
    /// I/O errors are reported as unsupported input with the reason.
    pub fn open(path: &Path) -> std::result::Result<Self, Box<dyn std::error::Error + Send + Sync>> {
        let bytes = std::fs::read(path)?;
        Ok(Self::from_bytes(&bytes)?)
    }

    fn from_iges(doc: iges::Document) -> Result<Self> {
        let mut patches = Vec::new();
        let mut skipped = Vec::new();
        let reversed = iges_reversed_faces(&doc);
        for f in doc.faces() {
            let source = Source::Iges { face: f.face.0, surface: f.surface.0 };
            let kind = doc.entity(f.surface).map(|e| e.entity_type()).unwrap_or(0);
            match doc.face_surface(&f) {
                Ok(es) => patches.push(Patch {
                    surface: es.surface,
                    reversed: reversed.get(&f.face.0).copied().unwrap_or(false),
                    source,
                    kind: format!("IGES {kind}"),
                    analytic: kind != 128,
                    trimmed: f.trimmed,
                }),
                Err(e) => skipped.push((source.to_string(), e.to_string())),
            }
        }
        let unit = doc.global().unit_name();
        let tol = edge_tol(&patches);
        let trims = iges_edges(&doc, &patches, tol);
        Ok(Self::with_edges(Doc::Iges(Box::new(doc)), patches, skipped, unit, trims))
    }

    /// Finds the iso-boundary edges and keeps the topology edges that are not among them.
    fn with_edges(
        doc: Doc,
        patches: Vec<Patch>,
        skipped: Vec<(String, String)>,
        unit: String,
        trims: Vec<TrimEdge>,
    ) -> Self {
        let tol = edge_tol(&patches);
        let refs: Vec<&NurbsSurface> = patches.iter().map(|p| &p.surface).collect();
        let iso = shared_boundaries(&refs, tol, 64, 0.9);
        let trims =
            trims.into_iter().filter(|t| !iso.iter().any(|e| t.lies_on(e, &patches[e.a.patch].surface, tol))).collect();
        Self { doc, patches, skipped, unit, iso, trims }
    }

    fn from_step(doc: step::Document) -> Result<Self> {
        let mut patches = Vec::new();
        let mut skipped = Vec::new();
        for f in doc.faces()? {
            let source = Source::Step { face: f.id.0, surface: f.surface.0 };
            let analytic = !matches!(f.kind, step::SurfaceKind::BSpline { .. });
            let kind = match &f.kind {
                step::SurfaceKind::BSpline { .. } => "B_SPLINE_SURFACE".to_string(),
                other => format!("{other:?}"),
            };
            match doc.face_nurbs(&f) {
                Ok(ws) => patches.push(Patch {
                    surface: ws.surface,
                    reversed: !f.same_sense,
                    source,
                    kind,
                    analytic,
                    trimmed: true,
                }),
                Err(e) => skipped.push((source.to_string(), e.to_string())),
            }
        }
        let unit = doc.units()?.length.name;
        let trims = match step_edges(&doc, &patches) {
            Ok(t) => t,
            Err(e) => {
                skipped.push(("edges".to_owned(), e.to_string()));
                Vec::new()
            }
        };
        Ok(Self::with_edges(Doc::Step(Box::new(doc)), patches, skipped, unit, trims))
    }

    /// The file format.
    pub fn format(&self) -> Format {
        match self.doc {
            Doc::Iges(_) => Format::Iges,
            Doc::Step(_) => Format::Step,
        }
    }

    /// The faces as patches, in file order.
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// The name of the length unit.
    pub fn unit(&self) -> &str {
        &self.unit
    }

    /// The diagonal of the box around all control points (the model size).
    pub fn size(&self) -> f64 {
        size_of(&self.patches)
    }

    /// A summary: format, unit, entity counts, faces.
    pub fn info(&self) -> Info {
        let (entity_counts, unknown_entities) = match &self.doc {
            Doc::Iges(d) => {
                (d.counts_by_type().into_iter().map(|(k, v)| (k.to_string(), v)).collect(), d.unknown_entities().len())
            }
            Doc::Step(d) => (d.entity_counts(), 0),
        };
        let patches = self
            .patches
            .iter()
            .map(|p| PatchInfo {
                source: p.source.to_string(),
                kind: p.kind.clone(),
                u_degree: p.surface.u_degree(),
                v_degree: p.surface.v_degree(),
                n_u: p.surface.n_u(),
                n_v: p.surface.n_v(),
                rational: p.surface.is_rational(),
                analytic: p.analytic,
                trimmed: p.trimmed,
                reversed: p.reversed,
            })
            .collect();
        Info {
            format: self.format(),
            unit: self.unit.clone(),
            entity_counts,
            unknown_entities,
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

    /// The seams after a morph: iso edges found again, trim edges at the face parameters
    /// they had before (`samples`), when the faces kept their parameter domains;
    /// otherwise the trim edges found again.
    fn seams_at(
        &self,
        samples: &[EdgeSamples],
        domains: &[(RangeInclusive<f64>, RangeInclusive<f64>)],
        progress: &dyn Progress,
    ) -> SeamReport {
        let now: Vec<_> = self.patches.iter().map(|p| p.surface.domain()).collect();
        if now != domains {
            return self.seams_with_progress(200, progress);
        }
        progress.start("measuring seams", (self.iso.len() + samples.len()) as u64);
        let faces: Vec<Face> =
            self.patches.iter().map(|p| Face { surface: &p.surface, reversed: p.reversed }).collect();
        let iso = self.iso.iter().map(|e| measure_boundary(&faces, e, 200));
        let trims = samples.iter().map(|s| measure_edge_samples(&faces, s));
        SeamReport::new(iso.chain(trims).inspect(|_| progress.step(1)).collect())
    }

    /// Measures every shared edge, iso-boundary and trim edges, with `samples` points.
    pub fn seams(&self, samples: usize) -> SeamReport {
        self.seams_with_progress(samples, &Silent)
    }

    /// [`seams`](Self::seams), reporting each edge measured to `progress`.
    pub fn seams_with_progress(&self, samples: usize, progress: &dyn Progress) -> SeamReport {
        progress.start("measuring seams", (self.iso.len() + self.trims.len()) as u64);
        let faces: Vec<Face> =
            self.patches.iter().map(|p| Face { surface: &p.surface, reversed: p.reversed }).collect();
        let iso = self.iso.iter().map(|e| measure_boundary(&faces, e, samples));
        let trims = self.trims.iter().map(|e| measure_edge(&faces, e, samples));
        SeamReport::new(iso.chain(trims).inspect(|_| progress.step(1)).collect())
    }

    /// The document as bytes: the input, byte for byte, where nothing was edited.
    pub fn to_bytes(&self) -> Vec<u8> {
        match &self.doc {
            Doc::Iges(d) => d.write(),
            Doc::Step(d) => d.write(),
        }
    }

    /// Writes the document to `path` through a temporary file in the same folder and a
    /// rename, so a failure never leaves half a file.
    ///
    /// # Errors
    ///
    /// I/O errors.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        let bytes = self.to_bytes();
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
        std::fs::write(&tmp, &bytes)?;
        std::fs::rename(&tmp, path).inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
    }

    /// Inserts knots without moving anything: evenly spaced (`opts.uniform_knots`) or
    /// where the morph `d` needs them to keep the seams (`opts.refine`), and rewrites the
    /// refined B-spline faces. The geometry does not change. Returns the control points
    /// before and after.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for seam refinement without a morph; the file layer's errors.
    pub fn refine(&mut self, opts: &MorphOptions, d: Option<&dyn Deformation>) -> Result<(usize, usize)> {
        let before: usize = self.patches.iter().map(|p| p.surface.control_points().len()).sum();
        let mut patches: Vec<NurbsSurface> = self.patches.iter().map(|p| p.surface.clone()).collect();
        if let Some(n) = opts.uniform_knots {
            for (s, p) in patches.iter_mut().zip(&self.patches) {
                if !p.analytic {
                    refine_uniform(s, n)?;
                }
            }
        }
        if let Some(r) = opts.refine {
            let d = d.ok_or(Error::Unsupported("seam refinement needs the morph it refines for"))?;
            refine_edges(&mut patches, &self.iso, &self.trims, d, &r);
        }
        // Analytic faces keep their exact analytic form: inserting knots does not change
        // the geometry, and a plane or cylinder needs none until it moves.
        match &mut self.doc {
            Doc::Iges(doc) => {
                for (p, s) in self.patches.iter().zip(&patches) {
                    if let (Source::Iges { surface, .. }, false) = (p.source, p.analytic) {
                        if s != &p.surface {
                            doc.set_bspline_surface(iges::EntityId(surface), s)?;
                        }
                    }
                }
            }
            Doc::Step(doc) => {
                let faces = doc.faces()?;
                for (p, s) in self.patches.iter().zip(&patches) {
                    if let (Source::Step { face, .. }, false) = (p.source, p.analytic) {
                        if s != &p.surface {
                            if let Some(f) = faces.iter().find(|f| f.id.0 == face) {
                                doc.set_face_surface(f, s)?;
                            }
                        }
                    }
                }
            }
        }
        *self = Model::from_bytes(&self.to_bytes())?;
        Ok((before, self.patches.iter().map(|p| p.surface.control_points().len()).sum()))
    }

    /// Morphs the model with `d`: optional refinement and repair (see [`MorphOptions`]),
    /// then every control point of every face moves with `d` (weights kept), the
    /// model-space trimming curves follow, analytic faces that move are first replaced
    /// by their exact B-spline form, and only the entities that changed are rewritten.
    /// A morph that moves nothing leaves the document byte-identical.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] or [`Error::Folded`] before anything is changed; the file
    /// layers' errors.
    pub fn morph(&mut self, d: &dyn Deformation, opts: &MorphOptions) -> Result<MorphOutcome> {
        self.morph_with_progress(d, opts, &Silent)
    }

    /// [`morph`](Self::morph), reporting its stages to `progress`.
    ///
    /// # Errors
    ///
    /// Those of [`morph`](Self::morph).
    pub fn morph_with_progress(
        &mut self,
        d: &dyn Deformation,
        opts: &MorphOptions,
        progress: &dyn Progress,
    ) -> Result<MorphOutcome> {
        let edges = self.iso.clone();
        let seams_before = self.seams_with_progress(200, progress);
        // Where the trim edges lie on their faces, in the faces' parameters: the seams
        // after the morph are measured there, between the faces' own trimmed boundaries.
        let faces: Vec<Face> =
            self.patches.iter().map(|p| Face { surface: &p.surface, reversed: p.reversed }).collect();
        let trim_samples: Vec<EdgeSamples> = self.trims.iter().map(|e| e.samples(&faces, 200)).collect();
        let domains: Vec<_> = self.patches.iter().map(|p| p.surface.domain()).collect();
        let before: usize = self.patches.iter().map(|p| p.surface.control_points().len()).sum();
        let mut patches: Vec<NurbsSurface> = self.patches.iter().map(|p| p.surface.clone()).collect();
        if opts.repair {
            make_compatible(&mut patches, &edges)?;
        }
        if let Some(n) = opts.uniform_knots {
            for s in &mut patches {
                refine_uniform(s, n)?;
            }
        }
        let refinement = opts.refine.map(|r| {
            progress.start("refining", 0);
            refine_edges(&mut patches, &edges, &self.trims, d, &r)
        });
        let refined = patches.clone();
        progress.start("moving control points", patches.len() as u64);
        // Move and check every control point before touching the document.
        for (p, s) in self.patches.iter().zip(&mut patches) {
            for (i, q) in s.control_points_mut().iter_mut().enumerate() {
                if let Some(j) = d.jacobian(q) {
                    let det = j.determinant();
                    if det.is_nan() || det <= 0.0 {
                        return Err(Error::Folded { face: p.source.to_string(), point: i, det });
                    }
                }
                let moved = d.deform_point(q);
                if !moved.coords.iter().all(|c| c.is_finite()) {
                    return Err(Error::NonFinite { face: p.source.to_string(), point: i });
                }
                *q = moved;
            }
            progress.step(1);
        }
        if opts.repair {
            for e in &edges {
                if e.a.patch == e.b.patch {
                    continue;
                }
                let (lo, hi) = (e.a.patch.min(e.b.patch), e.a.patch.max(e.b.patch));
                let (left, right) = patches.split_at_mut(hi);
                let (x, y) = (&mut left[lo], &mut right[0]);
                let (a, b) = if e.a.patch == lo { (x, y) } else { (y, x) };
                match repair(a, b, e, true) {
                    Ok(_) | Err(cadmorph_seam::Error::PartialEdge { .. }) => {}
                    Err(other) => return Err(other.into()),
                }
            }
        }
        progress.start("writing", 0);
        let (faces_rewritten, curves_rewritten) = match &mut self.doc {
            Doc::Iges(doc) => write_iges(doc, &self.patches, &refined, &patches, d)?,
            Doc::Step(doc) => write_step(doc, &self.patches, &refined, &patches, d, opts.repair)?,
        };
        // Read the written document back: the report describes what was written.
        *self = Model::from_bytes(&self.to_bytes())?;
        let after: usize = self.patches.iter().map(|p| p.surface.control_points().len()).sum();
        Ok(MorphOutcome {
            control_points_before: before,
            control_points_after: after,
            faces_rewritten,
            curves_rewritten,
            refinement,
            seams_before,
            seams_after: self.seams_at(&trim_samples, &domains, progress),
        })
    }
}

fn size_of(patches: &[Patch]) -> f64 {
    let pts = patches.iter().flat_map(|p| p.surface.control_points());
    cadmorph_nurbs::Aabb::from_points(pts).map_or(0.0, |b| b.diagonal())
}

/// How far apart two sides may be and still be one edge: `1e-3 ×` the model size.
fn edge_tol(patches: &[Patch]) -> f64 {
    1e-3 * size_of(patches)
}

fn moved_by(d: &dyn Deformation, pts: &[Point3<f64>]) -> bool {
    pts.iter().any(|p| d.deform_point(p) != *p)
}

/// The knots `refined` has beyond `base` in each direction, to insert into `target`
/// (another copy of `base`'s geometry, such as the B-spline an analytic face becomes);
/// `None` when `target` does not have `base`'s knots, so the insertion would not mean
/// the same there.
fn inserted_knots(base: &NurbsSurface, refined: &NurbsSurface, target: &NurbsSurface) -> Option<(Vec<f64>, Vec<f64>)> {
    let same = |a: &cadmorph_nurbs::KnotVector, b: &cadmorph_nurbs::KnotVector| {
        a.len() == b.len()
            && a.as_slice().iter().zip(b.as_slice()).all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + x.abs()))
    };
    if base.u_degree() != target.u_degree()
        || base.v_degree() != target.v_degree()
        || !same(base.u_knots(), target.u_knots())
        || !same(base.v_knots(), target.v_knots())
    {
        return None;
    }
    let extra = |from: &[f64], to: &[f64]| {
        let mut out = Vec::new();
        let mut i = 0;
        for &k in to {
            if i < from.len() && from[i] == k {
                i += 1;
            } else {
                out.push(k);
            }
        }
        out
    };
    Some((
        extra(base.u_knots().as_slice(), refined.u_knots().as_slice()),
        extra(base.v_knots().as_slice(), refined.v_knots().as_slice()),
    ))
}

/// `target` (another copy of `base`'s geometry) with the knots that took `base` to
/// `refined`; `target` itself where the two do not match.
fn refined_like(base: &NurbsSurface, refined: &NurbsSurface, target: &NurbsSurface) -> NurbsSurface {
    let mut out = target.clone();
    if let Some((xu, xv)) = inserted_knots(base, refined, target) {
        if out.refine_u(&xu).is_err() || out.refine_v(&xv).is_err() {
            return target.clone();
        }
    }
    out
}

fn write_iges(
    doc: &mut iges::Document,
    old: &[Patch],
    refined: &[NurbsSurface],
    new: &[NurbsSurface],
    d: &dyn Deformation,
) -> Result<(usize, usize)> {
    let mut faces = 0;
    for ((p, r), s) in old.iter().zip(refined).zip(new) {
        let Source::Iges { surface, .. } = p.source else { continue };
        let id = iges::EntityId(surface);
        if s == &p.surface {
            continue;
        }
        if p.analytic {
            // The exact B-spline form in the entity's own extent (the trims are rewritten
            // to match), then moved.
            if !moved_by(d, p.surface.control_points()) {
                continue;
            }
            doc.replace_with_bspline(id)?;
            // The refinement (seam-driven or uniform) carries over where the B-spline the
            // entity becomes has the knots of the patch it was planned on.
            let mut b = refined_like(&p.surface, r, &doc.surface(id)?.surface);
            d.deform(b.control_points_mut());
            doc.set_bspline_surface(id, &b)?;
        } else {
            doc.set_bspline_surface(id, s)?;
        }
        faces += 1;
    }
    // Curves that bound faces (trims, B-rep edges) are traced on their morphed face;
    // any other model-space 126 moves its control points.
    let tol = 1e-7 * size_of(old);
    let mut n_curves = 0;
    let mut traced: HashSet<u32> = HashSet::new();
    for (id, patch) in face_curves(doc, old) {
        let Ok(pieces) = doc.curve(id) else { continue };
        let [c] = pieces.as_slice() else { continue };
        if !moved_by(d, c.control_points()) || !traced.insert(id.0) {
            continue;
        }
        if let Some(new_curve) = follow_face(c, &old[patch].surface, &new[patch], d, tol) {
            if doc.set_bspline_curve(id, &new_curve)? {
                n_curves += 1;
            }
        }
    }
    let mut curves: Vec<iges::EntityId> = Vec::new();
    for e in doc.entities() {
        match e.entity_type() {
            126 if e.directory().status.subordinate == 0 && e.directory().status.entity_use != 5 => curves.push(e.id()),
            142 => {
                if let Ok(iges::View::CurveOnSurface(c)) = doc.view(e.id()) {
                    if let Some(m) = c.model_curve {
                        if doc.entity(m).map(|x| x.entity_type()) == Ok(126) {
                            curves.push(m);
                        }
                    }
                }
            }
            _ => {}
        }
    }
    curves.sort_by_key(|c| c.0);
    curves.dedup();
    for id in curves.into_iter().filter(|id| !traced.contains(&id.0)) {
        let Ok(pieces) = doc.curve(id) else { continue };
        let [c] = pieces.as_slice() else { continue };
        let pts = d.deformed(c.control_points());
        if doc.set_control_points(id, &pts, c.weights())? {
            n_curves += 1;
        }
    }
    Ok((faces, n_curves))
}

/// The model-space curves that bound faces, each with the (first) patch it bounds: 142
/// model curves of 144 faces, 141 curves of 143 faces, edges of 504 lists used by the
/// loops of 510 faces; composite curves (102) give their members.
fn face_curves(doc: &iges::Document, patches: &[Patch]) -> Vec<(iges::EntityId, usize)> {
    let mut out = Vec::new();
    for (pi, bound) in iges_face_bounds(doc, patches) {
        let curve = match bound {
            FaceBound::Trim { curve, .. } => curve,
            FaceBound::Edge { list, index } => {
                let Ok(iges::View::EdgeList(el)) = doc.view(list) else { continue };
                let edge = usize::try_from(index).ok().and_then(|k| k.checked_sub(1)).and_then(|k| el.edges.get(k));
                let Some(edge) = edge else { continue };
                edge.curve
            }
        };
        match doc.view(curve) {
            Ok(iges::View::CompositeCurve(c)) => out.extend(c.curves.into_iter().map(|m| (m, pi))),
            _ => out.push((curve, pi)),
        }
    }
    out
}

/// The curve `c`, lying on `before`, made to lie on `after` (the same face morphed, in the
/// same parameters): its control points moved by `d` where that stays within `tol` of
/// the face's image of the curve (always for affine maps and for iso-boundaries that
/// share the face's knots), else a cubic fit of that image within `tol`. `None` when
/// neither works (the curve is left as it is).
fn follow_face(
    c: &cadmorph_nurbs::NurbsCurve,
    before: &NurbsSurface,
    after: &NurbsSurface,
    d: &dyn Deformation,
    tol: f64,
) -> Option<cadmorph_nurbs::NurbsCurve> {
    use cadmorph_nurbs::Curve;
    let dom = c.domain();
    let (t0, t1) = (*dom.start(), *dom.end());
    let size = before.control_extent().max(1.0);
    let ptol = 1e-12 * size;
    let last = std::cell::Cell::new(None::<(f64, f64)>);
    let image = |t: f64| {
        let pr = before.project_near(&c.eval(t), last.get(), ptol, 1e-6 * size);
        last.set(Some((pr.u, pr.v)));
        after.eval(pr.u, pr.v)
    };
    let mut moved = c.clone();
    d.deform(moved.control_points_mut());
    let n = 8 * moved.control_points().len() + 1;
    let off = (0..n).map(|k| t0 + (t1 - t0) * k as f64 / (n - 1) as f64).map(|t| (moved.eval(t) - image(t)).norm());
    if off.fold(0.0, f64::max) <= tol {
        return Some(moved);
    }
    // The image bends where the curve crosses a knot line of the morphed face: break the
    // fit there.
    // Parameters on the face, each search started from a nearby known answer.
    let uv = |t: f64, near: Option<(f64, f64)>| {
        let pr = before.project_near(&c.eval(t), near, ptol, 1e-6 * size);
        (pr.u, pr.v)
    };
    let spans = |(u, v): (f64, f64)| {
        (after.u_knots().find_span(after.u_degree(), u), after.v_knots().find_span(after.v_degree(), v))
    };
    let crossings = after.u_knots().len() + after.v_knots().len();
    let m = (8 * crossings).clamp(32, 1024);
    let ts: Vec<f64> = (0..=m).map(|k| t0 + (t1 - t0) * k as f64 / m as f64).collect();
    let mut uvs: Vec<(f64, f64)> = Vec::with_capacity(ts.len());
    for &t in &ts {
        let near = uvs.last().copied();
        uvs.push(uv(t, near));
    }
    let mut breaks = Vec::new();
    for k in 0..m {
        let cell = spans(uvs[k]);
        if cell == spans(uvs[k + 1]) {
            continue;
        }
        let (mut lo, mut hi) = (ts[k], ts[k + 1]);
        let mut near = uvs[k];
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            let at = uv(mid, Some(near));
            if spans(at) == cell {
                lo = mid;
                near = at;
            } else {
                hi = mid;
            }
        }
        breaks.push(0.5 * (lo + hi));
    }
    last.set(None);
    match cadmorph_nurbs::fit_curve(image, (t0, t1), &breaks, 3, tol, 4 * (breaks.len() + 1) * 16 + 64) {
        Ok((f, _)) => Some(f),
        // Moved control points at least follow the morph, if not the face exactly.
        Err(_) => Some(moved),
    }
}

/// STEP: refined faces are rewritten first (unmoved), analytic faces that move become
/// B-splines, then the document's own morph moves every control point once and
/// rebuilds the edges on the morphed faces; repaired faces are written last.
fn write_step(
    doc: &mut step::Document,
    old: &[Patch],
    refined: &[NurbsSurface],
    new: &[NurbsSurface],
    d: &dyn Deformation,
    repaired: bool,
) -> Result<(usize, usize)> {
    let changed = old.iter().zip(new).filter(|(p, s)| p.surface != **s).count();
    if changed == 0 {
        return Ok((0, 0));
    }
    let faces = doc.faces()?;
    let face_of = |p: &Patch| match p.source {
        Source::Step { face, .. } => faces.iter().find(|f| f.id.0 == face).cloned(),
        Source::Iges { .. } => None,
    };
    for (p, r) in old.iter().zip(refined) {
        if !p.analytic && r != &p.surface {
            if let Some(f) = face_of(p) {
                doc.set_face_surface(&f, r)?;
            }
        }
    }
    let mut replaced = Vec::new();
    for f in &faces {
        let analytic = !matches!(f.kind, step::SurfaceKind::BSpline { .. });
        if analytic {
            if let Ok(ws) = doc.face_nurbs(f) {
                if moved_by(d, ws.surface.control_points()) {
                    doc.replace_with_bspline(f)?;
                    replaced.push((f.id, f.occurrence));
                }
            }
        }
    }
    // Carry the refinement planned on each replaced face's patch over to its new B-spline.
    if !replaced.is_empty() {
        for g in doc.faces()? {
            if !replaced.contains(&(g.id, g.occurrence)) {
                continue;
            }
            let source = Source::Step { face: g.id.0, surface: g.surface.0 };
            let Some((p, r)) = old.iter().zip(refined).find(|(p, r)| p.source == source && p.surface != **r) else {
                continue;
            };
            let b = doc.face_nurbs(&g)?.surface;
            let target = refined_like(&p.surface, r, &b);
            if target != b {
                doc.set_face_surface(&g, &target)?;
            }
        }
    }
    // Edge curves: the document's recompute keeps each curve's knots, which follows the
    // face only where the edge is an iso-boundary with the face's knots (a straight edge
    // stays straight). So every edge is also traced on its first morphed face before the
    // morph (control points moved where that stays within tolerance, else a fit) and
    // written after it.
    let faces = doc.faces()?;
    let patch_of = step_face_patches(&faces, old);
    let tol = 1e-7 * size_of(old);
    let mut traced = Vec::new();
    for e in doc.edges(&faces)? {
        let Some(patch) = e.faces.iter().find_map(|&f| patch_of[f]) else { continue };
        let Ok(wc) = doc.edge_curve(&e) else { continue };
        if !moved_by(d, wc.curve.control_points()) {
            continue;
        }
        if let Some(c) = follow_face(&wc.curve, &old[patch].surface, &new[patch], d, tol) {
            if !c.is_rational() {
                traced.push((e, c));
            }
        }
    }
    let report = doc.morph(&|p: &Point3<f64>| d.deform_point(p), step::EdgePolicy::default())?;
    doc.set_edge_curves(&traced)?;
    if repaired {
        let faces = doc.faces()?;
        for (p, s) in old.iter().zip(new) {
            if p.analytic {
                continue;
            }
            let Source::Step { face, .. } = p.source else { continue };
            if let Some(f) = faces.iter().find(|f| f.id.0 == face) {
                doc.set_face_surface(f, s)?;
            }
        }
    }
    Ok((changed, report.edges))
}
