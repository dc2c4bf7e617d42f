//! `campaign run`: every variant of a share into its own folder, idempotent and
//! resumable (issue 16, Deliver 3).
//!
//! Offline, once per campaign and cached in `base/`: the base geometry refined so that
//! the seams hold for every variant (see [`refined_base`]). Offline, once per process:
//! the deformation's basis at the refined base's control points ([`Basis`]). Online,
//! per variant: one product for the control points, the model's morph path (which moves
//! the trims and curves and checks for folds), the outputs, the written document read
//! back and its seams measured, and `report.json` last.

use std::path::{Path, PathBuf};
use std::time::Instant;

use cadmorph::model::MorphOptions;
use cadmorph::morph::math::Point3;
use cadmorph::seam::SeamRefineOptions;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{io, Error, Result};
use crate::fsutil::{remove_temporaries, write_atomic};
use crate::manifest::{Manifest, Variant};
use crate::online::{Base, Basis, Online};
use crate::report::{Measures, Output, Report, Seams, Timings};
use crate::shard::Shard;
use crate::space::{sha256_hex, DesignSpace};

/// `base/refined.json`: how the cached refined base was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Refinement {
    /// The campaign it was refined for.
    pub campaign_sha256: String,
    /// SHA-256 of the refined document.
    pub sha256: String,
    /// Its file name in `base/`.
    pub file: String,
    /// Control points before.
    pub control_points_before: usize,
    /// Control points after.
    pub control_points_after: usize,
    /// Deformations it was refined for (corners of the parameter box, or the plan).
    pub deformations: usize,
    /// Wall time, milliseconds.
    pub ms: f64,
}

/// The corners of the parameter box (`2^d`), or for more than 8 parameters the plan's
/// own points: the campaign values the base is refined for.
fn refinement_points(space: &DesignSpace, manifest: &Manifest) -> Vec<Vec<f64>> {
    let d = space.parameters.len();
    if d > 8 {
        return manifest.variants.iter().map(|v| v.values.clone()).collect();
    }
    (0..1usize << d)
        .map(|mask| {
            space
                .parameters
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let (lo, hi) = p.values.bounds();
                    if mask >> i & 1 == 1 {
                        hi
                    } else {
                        lo
                    }
                })
                .collect()
        })
        .collect()
}

/// The full parameter vector θ of the variant with campaign values `mu`.
pub(crate) fn theta_of(space: &DesignSpace, base_theta: &[f64], mu: &[f64]) -> Vec<f64> {
    let mut theta = base_theta.to_vec();
    for (p, &m) in space.parameters.iter().zip(mu) {
        theta[p.theta] = m;
    }
    theta
}

fn cad(context: impl Into<String>) -> impl FnOnce(cadmorph::Error) -> Error {
    let context = context.into();
    move |error| Error::Cad { context, error }
}

/// The base geometry refined for the campaign, cached as `base/refined.EXT` with
/// `base/refined.json` in the campaign folder.
///
/// The seam gap of a variant is, at every sample point of every edge, the norm of an
/// affine function of μ (control points are linear in μ, and a surface point is linear
/// in its control points with the weights fixed), so its maximum over the parameter
/// box is reached at a corner. Refining the base in turn for the deformation of every
/// corner (Model::refine, the seam-driven refinement of `cadmorph-seam`), until a pass
/// over the corners (taken cyclically) adds no knot, therefore refines for every variant at once, and the
/// refinement depends on the campaign only, not on the share a process makes. Each
/// variant's seams are still measured and out-of-tolerance ones flagged.
///
/// Without `refine_tol` the base is used as it is.
///
/// # Errors
///
/// [`Error::Cad`] for a base that does not read or refine; [`Error::Io`].
pub fn refined_base(space: &DesignSpace, manifest: &Manifest) -> Result<(Vec<u8>, Refinement)> {
    let bytes = std::fs::read(&space.geometry).map_err(io(&space.geometry))?;
    let what = format!("reading {}", space.geometry.display());
    let mut model = cadmorph::from_bytes(&bytes).map_err(cad(&what))?;
    let count = |m: &cadmorph::Model| m.patches().iter().map(|p| p.surface.control_points().len()).sum::<usize>();
    let before = count(&model);
    let file = format!("refined.{}", model.format().extension());
    let dir = space.output.join("base");
    let meta_path = dir.join("refined.json");
    if let Ok(text) = std::fs::read_to_string(&meta_path) {
        if let Ok(meta) = serde_json::from_str::<Refinement>(&text) {
            if let Ok(cached) = std::fs::read(dir.join(&meta.file)) {
                if meta.campaign_sha256 == space.hash && sha256_hex(&cached) == meta.sha256 {
                    return Ok((cached, meta));
                }
            }
        }
    }
    let start = Instant::now();
    let mut deformations = 0;
    if let Some(tol) = space.settings.refine_tol {
        let base = Base::new(&space.deformation)?;
        let theta0 = base.theta();
        let opts =
            MorphOptions { refine: Some(SeamRefineOptions::new(tol, space.settings.angle_tol)), ..Default::default() };
        let corners = refinement_points(space, manifest);
        // Cyclically over the corners until a whole cycle adds no knot (at most 4 cycles).
        let mut unchanged = 0;
        while unchanged < corners.len() && deformations < 4 * corners.len() {
            let n0 = count(&model);
            let d = base.with_theta(&theta_of(space, &theta0, &corners[deformations % corners.len()]))?;
            model.refine(&opts, Some(d.deformation())).map_err(cad("refining the base for the campaign"))?;
            deformations += 1;
            unchanged = if count(&model) == n0 { unchanged + 1 } else { 0 };
        }
    }
    let refined = model.to_bytes();
    let meta = Refinement {
        campaign_sha256: space.hash.clone(),
        sha256: sha256_hex(&refined),
        file: file.clone(),
        control_points_before: before,
        control_points_after: count(&model),
        deformations,
        ms: start.elapsed().as_secs_f64() * 1e3,
    };
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    write_atomic(&dir.join(&file), &refined)?;
    write_atomic(&meta_path, serde_json::to_string_pretty(&meta).expect("plain data").as_bytes())?;
    Ok((refined, meta))
}

/// What a process needs to make variants: built once (offline).
pub struct Prepared {
    space: DesignSpace,
    refined: Vec<u8>,
    base: Base,
    theta0: Vec<f64>,
    basis: Basis,
    stem: String,
    /// How each face's volume and area are integrated, told once on the refined base
    /// (a morph keeps them), or why they cannot be.
    methods: std::result::Result<Vec<cadmorph_hull::FaceMethod>, String>,
    /// How the refined base was made.
    pub refinement: Refinement,
    /// Wall time of the offline phase of this process (refined base loaded or made,
    /// basis built), milliseconds.
    pub offline_ms: f64,
}

impl Prepared {
    /// The offline phase for `space` planned as `manifest`.
    ///
    /// # Errors
    ///
    /// As [`refined_base`]; [`Error::Morph`] when the deformation cannot be built.
    pub fn new(space: &DesignSpace, manifest: &Manifest) -> Result<Prepared> {
        let start = Instant::now();
        let (refined, refinement) = refined_base(space, manifest)?;
        let model = cadmorph::from_bytes(&refined).map_err(cad("reading the refined base"))?;
        let points: Vec<Point3<f64>> =
            model.patches().iter().flat_map(|p| p.surface.control_points().iter().copied()).collect();
        let base = Base::new(&space.deformation)?;
        let basis = Basis::new(&base, &space.parameters, points);
        let by_face = cadmorph_hull::volume::bounds_by_face(model.patches().len(), model.bound_curves());
        let methods = model
            .patches()
            .iter()
            .zip(&by_face)
            .map(|(f, b)| cadmorph_hull::volume::face_method(f, b, model.size()))
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| e.to_string());
        let stem =
            space.geometry.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "variant".into());
        Ok(Prepared {
            space: space.clone(),
            refined,
            theta0: base.theta(),
            base,
            basis,
            stem,
            methods,
            refinement,
            offline_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// The basis (for sensitivities).
    pub fn basis(&self) -> &Basis {
        &self.basis
    }

    /// Makes `variant` into `dir` (outputs first, each through a temporary file and a
    /// rename, `report.json` last) and returns its report. A failure of the morph or of
    /// a writer is recorded as a failed report, not returned.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] when the folder or the report cannot be written.
    pub fn make(&self, variant: &Variant, dir: &Path) -> Result<Report> {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let start = Instant::now();
        let mut report = Report {
            id: variant.id.clone(),
            input_sha256: variant.input_sha256.clone(),
            values: variant.values.clone(),
            status: "ok".into(),
            error: None,
            outputs: Vec::new(),
            control_points: 0,
            faces_rewritten: 0,
            curves_rewritten: 0,
            seams: None,
            measures: None,
            refine_tol: self.space.settings.refine_tol,
            angle_tol: self.space.settings.angle_tol,
            in_tolerance: false,
            timings: Timings { morph_ms: 0.0, write_ms: 0.0, verify_ms: 0.0, measure_ms: 0.0, total_ms: 0.0 },
        };
        if let Err(e) = self.make_into(variant, dir, &mut report, start) {
            if let Error::Io { .. } = e {
                return Err(e);
            }
            report.status = "failed".into();
            report.error = Some(e.to_string());
            report.in_tolerance = false;
        }
        report.timings.total_ms = start.elapsed().as_secs_f64() * 1e3;
        let text = serde_json::to_string_pretty(&report).expect("plain data") + "\n";
        write_atomic(&dir.join("report.json"), text.as_bytes())?;
        Ok(report)
    }

    fn make_into(&self, variant: &Variant, dir: &Path, report: &mut Report, start: Instant) -> Result<()> {
        let what = format!("variant {}", variant.id);
        let mut model = cadmorph::from_bytes(&self.refined).map_err(cad(&what))?;
        let moved = self.basis.control_points(&variant.values);
        let full = self.base.with_theta(&theta_of(&self.space, &self.theta0, &variant.values))?;
        let online = Online::new(&self.basis.points, &moved, full.deformation());
        let outcome = model.morph(&online, &MorphOptions::default()).map_err(cad(&what))?;
        report.control_points = outcome.control_points_after;
        report.faces_rewritten = outcome.faces_rewritten;
        report.curves_rewritten = outcome.curves_rewritten;
        let t_morph = start.elapsed();
        report.timings.morph_ms = t_morph.as_secs_f64() * 1e3;
        for &format in &self.space.settings.formats {
            let bytes = if format == model.format() {
                model.to_bytes()
            } else {
                cadmorph::convert(&model, format).map_err(cad(format!("{what}: converting to {format}")))?.to_bytes()
            };
            let file = format!("{}.{}", self.stem, format.extension());
            write_atomic(&dir.join(&file), &bytes)?;
            report.outputs.push(Output { file, sha256: sha256_hex(&bytes), bytes: bytes.len() });
        }
        let t_write = start.elapsed();
        report.timings.write_ms = (t_write - t_morph).as_secs_f64() * 1e3;
        let back = model.verify().map_err(cad(format!("{what}: reading the written document back")))?;
        let s = &back.seams;
        report.seams = Some(Seams {
            edges: s.edges.len(),
            max_gap_closest: s.max_gap_closest,
            max_gap_matched: s.max_gap_matched,
            max_g1_angle_deg: s.max_g1_angle_deg,
            max_c1_mismatch: s.max_c1_mismatch,
        });
        report.in_tolerance = match self.space.settings.refine_tol {
            Some(tol) => s.max_gap_closest <= tol && s.max_g1_angle_deg <= self.space.settings.angle_tol,
            None => true,
        };
        let t_verify = start.elapsed();
        report.timings.verify_ms = (t_verify - t_write).as_secs_f64() * 1e3;
        report.measures = Some(measures(&model, &self.methods));
        report.timings.measure_ms = (start.elapsed() - t_verify).as_secs_f64() * 1e3;
        Ok(())
    }
}

/// Volume and area of `model`'s faces (see [`Measures`]), each face integrated as
/// `methods` says.
fn measures(
    model: &cadmorph::Model,
    methods: &std::result::Result<Vec<cadmorph_hull::FaceMethod>, String>,
) -> Measures {
    let methods = match methods {
        Ok(m) => m,
        Err(e) => return Measures { volume: None, area: None, note: Some(e.clone()) },
    };
    match cadmorph_hull::volume::enclosed_with(model.patches(), model.bound_curves(), model.size(), methods) {
        Ok(e) => Measures { volume: Some(e.total.volume), area: Some(e.total.area), note: None },
        // An open shell (such as a half hull without its deck) still has an area.
        Err(e @ cadmorph_hull::Error::OpenShell { area, .. }) => {
            Measures { volume: None, area: Some(area), note: Some(e.to_string()) }
        }
        Err(e) => Measures { volume: None, area: None, note: Some(e.to_string()) },
    }
}

/// What a `run` did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RunSummary {
    /// Variants in the share.
    pub in_share: usize,
    /// Made now.
    pub made: usize,
    /// Skipped: complete from an earlier run.
    pub skipped: usize,
    /// Made now, and failed.
    pub failed: usize,
    /// Temporary files of a killed run removed.
    pub temporaries_removed: usize,
    /// Offline time of this process, milliseconds.
    pub offline_ms: f64,
    /// Wall time of the whole run, milliseconds.
    pub wall_ms: f64,
}

/// The folder of variant `id`.
pub fn variant_dir(space: &DesignSpace, id: &str) -> PathBuf {
    space.output.join("variants").join(id)
}

/// Plans `space` (writing the manifest, which must agree with one already there) and
/// makes the variants of `shard` that are not complete, in parallel; `each` is told of
/// every variant made or skipped.
///
/// # Errors
///
/// [`Error::StaleManifest`]; those of [`Prepared::new`]; [`Error::Io`].
pub fn run(
    space: &DesignSpace,
    shard: Shard,
    retry_failed: bool,
    each: &(dyn Fn(&Report, bool) + Sync),
) -> Result<RunSummary> {
    let start = Instant::now();
    let manifest = Manifest::plan(space);
    manifest.write(&space.output)?;
    let range = shard.range(manifest.variants.len());
    let share = &manifest.variants[range];
    let mut summary = RunSummary { in_share: share.len(), ..Default::default() };
    let mut todo = Vec::new();
    for v in share {
        let dir = variant_dir(space, &v.id);
        summary.temporaries_removed += remove_temporaries(&dir)?;
        match Report::read(&dir) {
            Some(r) if r.is_complete(&dir, &v.input_sha256) && (r.status == "ok" || !retry_failed) => {
                each(&r, true);
                summary.skipped += 1;
            }
            _ => todo.push(v),
        }
    }
    if !todo.is_empty() {
        let prepared = Prepared::new(space, &manifest)?;
        summary.offline_ms = prepared.offline_ms;
        let reports: Vec<Result<Report>> = todo
            .par_iter()
            .map(|v| {
                let r = prepared.make(v, &variant_dir(space, &v.id))?;
                each(&r, false);
                Ok(r)
            })
            .collect();
        for r in reports {
            let r = r?;
            summary.made += 1;
            if r.status != "ok" {
                summary.failed += 1;
            }
        }
    }
    summary.wall_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(summary)
}
