//! The one morph path, for every format: refine, move every control point once, write
//! each face once, trace each bound curve once on its morphed face.

use std::collections::HashSet;

use cadmorph_brep::{CadDocument, EntityRef, Face, SurfaceKind};
use cadmorph_morph::Deformation;
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{NurbsSurface, Surface};
use cadmorph_seam::{
    area_and_volume, covers_side, make_compatible, refine_edges, refine_uniform, repair, SeamCheck, SeamRefineOptions,
    SeamRefinement, SeamReport, SharedBoundary,
};
use serde::Serialize;

use crate::exact::{ExactFfd, ExactReport};
use crate::model::{Model, Progress, Silent};
use crate::trace::{follow_face, moved_by, refined_like};
use crate::{Error, Result};

/// Settings of [`Model::morph`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MorphOptions {
    /// Seam-driven refinement before the morph (gap and angle tolerances).
    pub refine: Option<SeamRefineOptions>,
    /// PyGeM-style refinement: this many evenly spaced knots per direction on every patch.
    pub uniform_knots: Option<usize>,
    /// Repair the smooth shared iso edges between B-spline faces (see
    /// [`RepairOutcome`]): knots made compatible across them before the morph, both
    /// sides made identical after it (exact C0, and G1 for non-rational patches).
    /// Sharp edges (creases by design) and edges of analytic faces are left as the
    /// morph makes them.
    pub repair: bool,
}

/// What seam repair did ([`MorphOptions::repair`]).
///
/// An edge is repaired when it is a shared iso boundary of two B-spline faces (their
/// boundaries are the edge), covers both sides completely, and was smooth in the input
/// (normal angle at most [`SHARP_EDGE_DEG`](cadmorph_seam::SHARP_EDGE_DEG), so a
/// pre-existing gap with a small kink is repaired, a crease never). The others keep
/// what the morph makes of them: their angle, their faces, the solid's topology.
#[derive(Debug, Clone, Serialize)]
pub struct RepairOutcome {
    /// Shared iso edges repaired.
    pub edges_repaired: usize,
    /// Shared iso edges left alone because they are sharp in the input.
    pub sharp_kept: usize,
    /// Shared iso edges left alone because a side is an analytic face (its patch is
    /// not its boundary) or the edge covers a side only in part.
    pub other_kept: usize,
    /// Largest distance a boundary control point moved to meet its partner.
    pub max_move: f64,
    /// Total area of the repaired faces' patches (untrimmed) after the morph, before
    /// the repair.
    pub area_before: f64,
    /// The same after the repair.
    pub area_after: f64,
    /// Sum of the repaired patches' volume shares (`(1/3) ∬ S · n dA`, see
    /// [`area_and_volume`]) before the repair: its change is the enclosed volume's
    /// change when the faces bound a closed shell.
    pub volume_share_before: f64,
    /// The same after the repair.
    pub volume_share_after: f64,
}

/// What [`Model::morph`] did, counted from what was written.
#[derive(Debug, Clone, Serialize)]
pub struct MorphOutcome {
    /// Control points of all patches before.
    pub control_points_before: usize,
    /// Control points of all patches after (refinement adds some).
    pub control_points_after: usize,
    /// Faces whose surface entities were written.
    pub faces_rewritten: usize,
    /// Model-space curves whose entities were written (each shared edge once).
    pub curves_rewritten: usize,
    /// Parts copied so that the placements of a part placed more than once could move
    /// differently (STEP representations, IGES subfigure definitions; see
    /// [`CadDocument::unshare`]): 0 when no moved part is shared.
    pub parts_copied: usize,
    /// The seam refinement's report, when it ran.
    pub refinement: Option<SeamRefinement>,
    /// The seam repair's report, when it ran.
    pub repair: Option<RepairOutcome>,
    /// Seams before the morph.
    pub seams_before: SeamReport,
    /// Seams after the morph: the written document read back, its edges found and
    /// measured as `cadmorph seams` finds and measures them in the file.
    pub seams_after: SeamReport,
    /// The "after" seams checked against the "before" ones, when a caller asked for it
    /// (the CLI's `--tol`); [`Model::morph`] leaves it `None`.
    pub check: Option<SeamCheck>,
}

/// `s` raised to at least `degree` in each direction (A5.9; the geometry and the
/// parameters do not change); a direction already there is left as it is.
fn raise_to(s: &mut NurbsSurface, degree: usize, face: EntityRef) -> Result<()> {
    let (p, q) = (s.u_degree(), s.v_degree());
    let up = |s: &mut NurbsSurface| -> cadmorph_nurbs::Result<()> {
        if p < degree {
            s.elevate_u_degree(degree - p)?;
        }
        if q < degree {
            s.elevate_v_degree(degree - q)?;
        }
        Ok(())
    };
    up(s).map_err(|source| Error::Exact { what: format!("face {face} (elevation to degree {degree})"), source })
}

fn count(faces: &[cadmorph_brep::Face]) -> usize {
    faces.iter().map(|p| p.surface.control_points().len()).sum()
}

impl<D: CadDocument> Model<D> {
    /// Inserts knots without moving anything: evenly spaced (`opts.uniform_knots`) or
    /// where the morph `d` needs them to keep the seams (`opts.refine`), and rewrites the
    /// refined B-spline faces. The geometry does not change; analytic faces keep their
    /// exact analytic form (a plane or cylinder needs no knots until it moves). Returns
    /// the control points before and after.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for seam refinement without a morph; the document's errors.
    pub fn refine(&mut self, opts: &MorphOptions, d: Option<&dyn Deformation>) -> Result<(usize, usize)> {
        let before = count(&self.faces);
        let mut patches: Vec<NurbsSurface> = self.faces.iter().map(|p| p.surface.clone()).collect();
        if let Some(n) = opts.uniform_knots {
            for (s, p) in patches.iter_mut().zip(&self.faces) {
                if !p.kind.is_analytic() {
                    refine_uniform(s, n)?;
                }
            }
        }
        if let Some(r) = opts.refine {
            let d = d.ok_or(Error::Unsupported("seam refinement needs the morph it refines for"))?;
            refine_edges(&mut patches, &self.iso, &self.trims, d, &r);
        }
        for (face, s) in self.faces.iter_mut().zip(patches) {
            if face.kind.is_analytic() || s == face.surface {
                continue;
            }
            self.doc.set_face_surface(face, &s)?;
            face.surface = s;
        }
        self.rebuild_edges();
        Ok((before, count(&self.faces)))
    }

    /// Morphs the model with `d`: optional refinement and repair (see [`MorphOptions`]),
    /// then every control point of every face moves with `d` once (weights kept), each
    /// face is written once (analytic faces that move become their exact B-spline form
    /// first), and each curve bounding a face is traced once on its morphed face
    /// (control points moved where that stays within `1e-7 ×` the model size of the
    /// face, else a cubic fit broken where the curve crosses the face's knot lines); a
    /// curve shared by two faces is traced on the first. Other model-space curves move
    /// their control points. Only the entities that changed are rewritten: a morph that
    /// moves nothing leaves the document byte-identical.
    ///
    /// A part placed more than once (a STEP assembly's repeated component, a mapped
    /// representation, an IGES subfigure definition) first gets its own copy for each
    /// placement holding a face the morph moves ([`CadDocument::unshare`]), so each
    /// placement moves its own way; placements that do not move keep sharing the
    /// original.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] or [`Error::Folded`] before anything is changed;
    /// [`Error::SharedSurface`] for a moved part placed more than once that the document
    /// could not copy; the document's errors.
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
        self.morph_impl(d, opts, progress, None)
    }

    /// [`morph_with_progress`](Self::morph_with_progress), with the faces `exact` marks
    /// replaced by their exact image (see [`Model::morph_exact`]).
    pub(crate) fn morph_impl(
        &mut self,
        d: &dyn Deformation,
        opts: &MorphOptions,
        progress: &dyn Progress,
        mut exact: Option<(&ExactFfd, &[bool], &mut ExactReport)>,
    ) -> Result<MorphOutcome> {
        // One surface placed twice (a part repeated in an assembly) would be moved two
        // ways: the placements that move get their own copies of the part first (the
        // document keeps the faces' order and places). Faces sharing a surface in one
        // placement move it once; placements that move nothing may keep sharing.
        let mut parts_copied = 0;
        if shared_placed_surface(&self.faces, |_| true).is_some() {
            let moved: Vec<EntityRef> =
                self.faces.iter().filter(|f| moved_by(d, f.surface.control_points())).map(|f| f.entity).collect();
            if !moved.is_empty() {
                parts_copied = self.doc.unshare(&moved)?;
                if parts_copied > 0 {
                    self.reload()?;
                }
            }
            let moved: Vec<bool> = self.faces.iter().map(|f| moved_by(d, f.surface.control_points())).collect();
            if let Some((surface, first, second)) = shared_placed_surface(&self.faces, |i| moved[i]) {
                return Err(Error::SharedSurface { surface, first, second });
            }
        }
        let edges = self.iso.clone();
        let seams_before = self.seams_with_progress(200, progress);
        let domains: Vec<_> = self.faces.iter().map(|p| p.surface.domain()).collect();
        let before = count(&self.faces);
        let mut patches: Vec<NurbsSurface> = self.faces.iter().map(|p| p.surface.clone()).collect();
        // The edges repair may touch: smooth shared iso edges of two B-spline faces that
        // cover both sides (seams_before lists the iso edges first, in the same order).
        let (mut sharp_kept, mut other_kept) = (0, 0);
        let to_repair: Vec<SharedBoundary> = if opts.repair {
            edges
                .iter()
                .zip(&seams_before.edges)
                .filter(|(e, r)| {
                    let analytic = self.faces[e.a.patch].kind.is_analytic() || self.faces[e.b.patch].kind.is_analytic();
                    let whole = covers_side(&patches[e.a.patch], e.a.side, e.a_range)
                        && covers_side(&patches[e.b.patch], e.b.side, e.b_range);
                    if r.sharp {
                        sharp_kept += 1;
                        false
                    } else if analytic || !whole || e.a.patch == e.b.patch {
                        other_kept += 1;
                        false
                    } else {
                        true
                    }
                })
                .map(|(e, _)| *e)
                .collect()
        } else {
            Vec::new()
        };
        // When the seams drive a refinement, the faces the morph moves (and the analytic
        // ones, whose curves may move them) are planned at least quadratic: along a
        // direction of degree 1 (a plane, a ruled side, a cylinder's generatrix) moved
        // control points bend the face only between rows, so the normals of the morphed
        // face converge to the exact morph's only as the span, and at 0.01° that took
        // whole-patch refinement to some 100 000 control points on a 14-face solid; from
        // degree 2 on they converge as its square. Degree 2, not 3: at the same number of
        // rounds a cubic plan of PyGeM's pipe held twice the control points (11 922
        // against 6 216, above PyGeM's own 30-knot refinement). Without refinement the
        // faces keep their degrees (B-spline faces move their control points as PyGeM
        // moves them; analytic faces are written cubic, see `write_faces`).
        if opts.refine.is_some() {
            for (s, face) in patches.iter_mut().zip(&self.faces) {
                if face.kind.is_analytic() || moved_by(d, face.surface.control_points()) {
                    raise_to(s, 2, face.entity)?;
                }
            }
        }
        make_compatible(&mut patches, &to_repair)?;
        if let Some(n) = opts.uniform_knots {
            for s in &mut patches {
                refine_uniform(s, n)?;
            }
        }
        let refinement = opts.refine.map(|r| {
            progress.start("refining", 0);
            match &exact {
                // Edges between two exact faces need no knots.
                Some((_, inside, _)) => {
                    let iso: Vec<_> =
                        edges.iter().filter(|e| !(inside[e.a.patch] && inside[e.b.patch])).cloned().collect();
                    let trims: Vec<_> = self.trims.iter().filter(|e| !(inside[e.a] && inside[e.b])).cloned().collect();
                    refine_edges(&mut patches, &iso, &trims, d, &r)
                }
                None => refine_edges(&mut patches, &edges, &self.trims, d, &r),
            }
        });
        let refined = patches.clone();
        progress.start("moving control points", patches.len() as u64);
        // Move and check every control point before touching the document.
        for (p, s) in self.faces.iter().zip(&mut patches) {
            for (i, q) in s.control_points_mut().iter_mut().enumerate() {
                if let Some(j) = d.jacobian(q) {
                    let det = j.determinant();
                    if det.is_nan() || det <= 0.0 {
                        return Err(Error::Folded { face: p.entity, point: i, det });
                    }
                }
                let moved = d.deform_point(q);
                if !moved.coords.iter().all(|c| c.is_finite()) {
                    return Err(Error::NonFinite { face: p.entity, point: i });
                }
                *q = moved;
            }
            progress.step(1);
        }
        if let Some((e, inside, report)) = exact.as_mut() {
            for (k, (p, s)) in self.faces.iter().zip(&mut patches).enumerate() {
                // Analytic faces are composed in their file's B-spline form when written.
                if inside[k] && !p.kind.is_analytic() {
                    let (r, composed, bound, reduction) = e.surface(&p.surface, p.entity)?;
                    report.composed_control_points += composed;
                    report.removal_bound = report.removal_bound.max(bound);
                    report.reduction_bound = report.reduction_bound.max(reduction);
                    *s = r;
                }
            }
        }
        let repair_outcome = if opts.repair {
            let touched: Vec<usize> = {
                let mut t: Vec<usize> = to_repair.iter().flat_map(|e| [e.a.patch, e.b.patch]).collect();
                t.sort_unstable();
                t.dedup();
                t
            };
            let sums = |p: &[NurbsSurface]| {
                touched.iter().map(|&i| area_and_volume(&p[i])).fold((0.0, 0.0), |s, x| (s.0 + x.0, s.1 + x.1))
            };
            let (area_before, volume_share_before) = sums(&patches);
            let mut max_move: f64 = 0.0;
            for e in &to_repair {
                let (lo, hi) = (e.a.patch.min(e.b.patch), e.a.patch.max(e.b.patch));
                let (left, right) = patches.split_at_mut(hi);
                let (x, y) = (&mut left[lo], &mut right[0]);
                let (a, b) = if e.a.patch == lo { (x, y) } else { (y, x) };
                max_move = max_move.max(repair(a, b, e, true)?.max_move);
            }
            let (area_after, volume_share_after) = sums(&patches);
            Some(RepairOutcome {
                edges_repaired: to_repair.len(),
                sharp_kept,
                other_kept,
                max_move,
                area_before,
                area_after,
                volume_share_before,
                volume_share_after,
            })
        } else {
            None
        };
        progress.start("writing", 0);
        let tol = 1e-7 * self.size();
        let (faces_rewritten, unmoved, in_plane) = self.write_faces(&refined, patches, d, exact.as_mut())?;
        // Faces the repair changed besides the morph: their curves follow them even where
        // the morph itself moves nothing.
        let mut repaired = vec![false; self.faces.len()];
        for e in &to_repair {
            repaired[e.a.patch] = true;
            repaired[e.b.patch] = true;
        }
        let curves_rewritten = self.write_curves(&unmoved, d, tol, &repaired, &in_plane, exact.as_mut())?;
        // The iso-boundary pairs stay the same sides while the domains do; the other
        // edges follow the curves as written.
        let now: Vec<_> = self.faces.iter().map(|p| p.surface.domain()).collect();
        if now == domains {
            self.rebuild_trims();
        } else {
            self.rebuild_edges();
        }
        // The document as written, read back and measured as `cadmorph seams` would.
        let seams_after = Model::new(self.doc.read_back()?)?.seams_with_progress(200, progress);
        Ok(MorphOutcome {
            control_points_before: before,
            control_points_after: count(&self.faces),
            faces_rewritten,
            curves_rewritten,
            parts_copied,
            refinement,
            repair: repair_outcome,
            seams_before,
            seams_after,
            check: None,
        })
    }

    /// Writes every face whose surface the morph changed; returns how many were written,
    /// each face's surface before the morph in the parameters of the surface it has now
    /// (what its curves are traced from), and which planes the morph keeps in their
    /// plane (see [`in_plane`]: their curves move with the morph itself).
    fn write_faces(
        &mut self,
        refined: &[NurbsSurface],
        moved: Vec<NurbsSurface>,
        d: &dyn Deformation,
        mut exact: Option<&mut (&ExactFfd, &[bool], &mut ExactReport)>,
    ) -> Result<(usize, Vec<NurbsSurface>, Vec<bool>)> {
        let mut written = 0;
        let mut unmoved = Vec::with_capacity(moved.len());
        let mut in_plane_faces = vec![false; moved.len()];
        let size = self.size();
        let bounds = &self.bounds;
        for (k, ((face, r), s)) in self.faces.iter_mut().zip(refined).zip(moved).enumerate() {
            unmoved.push(face.surface.clone());
            if face.kind.is_analytic() {
                // An exact face moves wherever the FFD does, also where its control
                // points do not (a plane through a moved lattice node).
                let exact_here = exact.as_ref().is_some_and(|(_, inside, _)| inside[k]);
                // A face moves when its patch does or when the curves bounding it do (an
                // IGES trimmed plane's patch may reach beyond the part the morph moves).
                let curves_move = || bounds.iter().any(|c| c.face == k && moved_by(d, c.curve.control_points()));
                if !exact_here && (s == face.surface || !moved_by(d, face.surface.control_points())) && !curves_move() {
                    continue;
                }
                // The exact B-spline form in the file (for IGES in the entity's own
                // extent, the trims rewritten to match); the refinement planned on the
                // patch carries over where that form has the patch's knots.
                let b = self.doc.bspline_form(face)?;
                let target = match exact.as_mut().filter(|(e, inside, _)| inside[k] && e.holds_surface(&b)) {
                    Some((e, _, report)) => {
                        *unmoved.last_mut().expect("pushed above") = b.clone();
                        let (r, composed, bound, reduction) = e.surface(&b, face.entity)?;
                        report.composed_control_points += composed;
                        report.removal_bound = report.removal_bound.max(bound);
                        report.reduction_bound = report.reduction_bound.max(reduction);
                        r
                    }
                    None => {
                        // A morphed plane or cylinder is at least cubic in both directions:
                        // moving the control points of a bilinear net keeps it a bilinear
                        // (ruled) patch, while the morph bends it. Elevation (A5.9) keeps
                        // the geometry and the parameters, so seams are measured where
                        // they were. A refined patch was elevated before the refinement
                        // was planned on it (to quadratic, see `morph_impl`): the file's
                        // form is elevated first and refined after, as the patch was, so
                        // that the inserted knots stay simple (elevating a refined form
                        // would make each of them a C⁰ knot of multiplicity 1 + t); such a
                        // form keeps the degrees of its plan.
                        let mut target = refined_like(&face.surface, r, &b);
                        // The form as it is when the refinement could not be carried over
                        // (its own knots) or did not elevate it.
                        if target == b {
                            raise_to(&mut target, 3, face.entity)?;
                        }
                        // Curves are traced from this form (its parameters), not from the patch.
                        *unmoved.last_mut().expect("pushed above") = target.clone();
                        d.deform(target.control_points_mut());
                        match in_plane(&b, &target, bounds.iter().filter(|c| c.face == k), d, size) {
                            Some(p) => {
                                in_plane_faces[k] = true;
                                p
                            }
                            None => target,
                        }
                    }
                };
                face.kind = SurfaceKind::BSpline;
                self.doc.set_face_surface(face, &target)?;
                face.surface = target;
                written += 1;
            } else if s != face.surface {
                if self.doc.set_face_surface(face, &s)? {
                    written += 1;
                }
                face.surface = s;
            }
        }
        Ok((written, unmoved, in_plane_faces))
    }

    /// Traces every moved bound curve, and every curve of a face the seam repair changed
    /// (`repaired`), once on its first morphed face (a curve of a plane kept in its plane,
    /// `in_plane`, moves its control points) (from `unmoved`, the face before the
    /// morph in the parameters it has now), then moves the free curves' control points;
    /// returns how many curve entities were written. A traced curve stays within `tol` of
    /// its face.
    fn write_curves(
        &mut self,
        unmoved: &[NurbsSurface],
        d: &dyn Deformation,
        tol: f64,
        repaired: &[bool],
        in_plane: &[bool],
        mut exact: Option<&mut (&ExactFfd, &[bool], &mut ExactReport)>,
    ) -> Result<usize> {
        let mut n = 0;
        let mut traced: HashSet<EntityRef> = HashSet::new();
        let step = self.format() == cadmorph_brep::Format::Step;
        let ends_before: Vec<Option<[Point3<f64>; 2]>> = self.bounds.iter().map(whole_curve_ends).collect();
        // Curves shared with a face the morph bends (not kept in its plane): traced on
        // that face, also where a plane kept in its plane comes first. Moving a curve's
        // control points is not the morph of the curve (a line stays straight where the
        // morph bends it), and the bent face's boundary is what the edge must follow; the
        // plane takes the traced curve, which stays in it as that boundary does.
        let on_bent_face: HashSet<EntityRef> =
            self.bounds.iter().filter(|b| !in_plane[b.face]).filter_map(|b| b.target).collect();
        for k in 0..self.bounds.len() {
            let b = &self.bounds[k];
            let Some(target) = b.target else { continue };
            if in_plane[b.face] && on_bent_face.contains(&target) {
                continue;
            }
            // IGES trimming curves are traced on the exact face instead: OCCT's IGES reader
            // re-parameterizes each against its parameter-space curve, and fails on the
            // exact image of a conic arc (edge tolerance 0.14 mm on mixed_solid.igs).
            let exact_here =
                step && exact.as_ref().is_some_and(|(e, inside, _)| inside[b.face] && e.holds_curve(&b.curve));
            if traced.contains(&target) || !(exact_here || moved_by(d, b.curve.control_points()) || repaired[b.face]) {
                continue;
            }
            traced.insert(target);
            let face = b.face;
            let composed = match exact.as_mut().filter(|_| exact_here) {
                Some((e, _, report)) => {
                    report.exact_curves += 1;
                    Some(e.curve(&b.curve, b.label)?)
                }
                None => None,
            };
            // A plane kept in its plane was re-bounded, not moved. Its curve follows the
            // face the morph bends on the other side of the edge (an IGES face's own
            // trimming curve), as that face's boundary moves, which stays in the plane;
            // with no such face, the morph's image of the curve.
            let own = in_plane[face].then(|| {
                let size = self.size();
                let bent = (0..self.faces.len())
                    .filter(|&j| j != face && !in_plane[j])
                    .find(|&j| lies_on(&b.curve, &unmoved[j], 1e-6 * size));
                match bent {
                    Some(j) => follow_face(&b.curve, &unmoved[j], &self.faces[j].surface, d, tol)
                        .unwrap_or_else(|| morphed_curve(&b.curve, d, tol)),
                    None => morphed_curve(&b.curve, d, tol),
                }
            });
            let Some(c) =
                composed.or(own).or_else(|| follow_face(&b.curve, &unmoved[face], &self.faces[face].surface, d, tol))
            else {
                continue;
            };
            if self.doc.set_bound_curve(b, &c)? {
                n += 1;
            }
            self.set_bound_in_memory(k, c);
        }
        n += self.close_plane_loops(&ends_before, in_plane)?;
        for f in &mut self.free {
            if traced.contains(&f.entity) {
                continue;
            }
            let mut c = f.curve.clone();
            d.deform(c.control_points_mut());
            if self.doc.set_free_curve(f, &c)? {
                n += 1;
            }
            f.curve = c;
        }
        Ok(n)
    }
}

impl<D: CadDocument> Model<D> {
    /// Closes the loops of the planes kept in their plane (IGES trimming curves, each a
    /// face's own): their curves follow the different faces across their edges (or are the
    /// morph's image where no face bends there), whose corners differ by what those faces
    /// are off the exact morph. Where two of a plane's curves met before the morph (within
    /// `1e-9 ×` the model size), their new ends are moved to their midpoint (the end
    /// control point of each clamped curve; both stay in the plane): a loop left open by
    /// 2e-4 mm made OCCT's IGES reader fill each gap with an edge of its own. Returns how
    /// many curve entities were rewritten.
    fn close_plane_loops(&mut self, ends_before: &[Option<[Point3<f64>; 2]>], in_plane: &[bool]) -> Result<usize> {
        let meet = 1e-9 * self.size();
        let mut n = 0;
        for face in (0..self.faces.len()).filter(|&f| in_plane[f]) {
            let ks: Vec<usize> = (0..self.bounds.len())
                .filter(|&k| {
                    let b = &self.bounds[k];
                    b.face == face && b.edge.is_none() && b.target.is_some() && ends_before[k].is_some()
                })
                .collect();
            for (x, &i) in ks.iter().enumerate() {
                for &j in &ks[x + 1..] {
                    for (ei, ej) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                        let (Some(bi), Some(bj)) = (ends_before[i], ends_before[j]) else { continue };
                        if (bi[ei] - bj[ej]).norm() > meet {
                            continue;
                        }
                        let (Some(ni), Some(nj)) =
                            (whole_curve_ends(&self.bounds[i]), whole_curve_ends(&self.bounds[j]))
                        else {
                            continue;
                        };
                        if ni[ei] == nj[ej] {
                            continue;
                        }
                        let mid = Point3::from((ni[ei].coords + nj[ej].coords) / 2.0);
                        for (k, end) in [(i, ei), (j, ej)] {
                            let mut c = self.bounds[k].curve.clone();
                            let last = c.control_points().len() - 1;
                            c.control_points_mut()[if end == 0 { 0 } else { last }] = mid;
                            if self.doc.set_bound_curve(&self.bounds[k], &c)? {
                                n += 1;
                            }
                            self.set_bound_in_memory(k, c);
                        }
                    }
                }
            }
        }
        Ok(n)
    }
}

/// The ends of a bound curve that bounds its face over its whole domain and is clamped
/// there (its end control points are its ends); `None` otherwise.
fn whole_curve_ends(b: &cadmorph_brep::BoundCurve) -> Option<[Point3<f64>; 2]> {
    use cadmorph_nurbs::Curve;
    let c = &b.curve;
    let dom = c.domain();
    let (t0, t1) = (*dom.start(), *dom.end());
    if b.range != (t0, t1) {
        return None;
    }
    let (p, q) = (c.eval(t0), c.eval(t1));
    let pts = c.control_points();
    let scale = c.bounding_box().diagonal().max(f64::MIN_POSITIVE);
    ((p - pts[0]).norm() <= 1e-12 * scale && (q - pts[pts.len() - 1]).norm() <= 1e-12 * scale).then_some([p, q])
}

/// Whether nine evenly spaced points of `c` lie within `eps` of surface `s` (checked
/// against its control points' box first: the surface lies in their hull, P&T P4.7).
fn lies_on(c: &cadmorph_nurbs::NurbsCurve, s: &NurbsSurface, eps: f64) -> bool {
    use cadmorph_nurbs::Curve;
    let Some(b) = cadmorph_nurbs::Aabb::from_points(s.control_points()) else { return false };
    let dom = c.domain();
    let pts: Vec<_> = (0..=8).map(|k| c.eval(dom.start() + (dom.end() - dom.start()) * k as f64 / 8.0)).collect();
    let inside =
        |p: &cadmorph_nurbs::math::Point3<f64>| (0..3).all(|i| p[i] >= b.min[i] - eps && p[i] <= b.max[i] + eps);
    if !pts.iter().all(inside) {
        return false;
    }
    let mut near = None;
    pts.iter().all(|p| {
        let pr = s.project_near(p, near, 1e-3 * eps, eps);
        near = Some((pr.u, pr.v));
        pr.distance_sq <= eps * eps
    })
}

/// The morph's image of `c` (for a curve of a plane kept in its plane that no bent face
/// shares): a cubic fit of `d` applied to the curve's points within `tol`, broken where
/// the curve's own knots are full (its image bends there), or, when the fit runs out of
/// poles, `c` with its control points moved (a line stays straight that way, where the
/// morph bends it).
fn morphed_curve(c: &cadmorph_nurbs::NurbsCurve, d: &dyn Deformation, tol: f64) -> cadmorph_nurbs::NurbsCurve {
    use cadmorph_nurbs::Curve;
    let dom = c.domain();
    let (t0, t1) = (*dom.start(), *dom.end());
    let breaks = crate::trace::full_knots(c);
    let image = |t: f64| d.deform_point(&c.eval(t));
    match cadmorph_nurbs::fit_curve(image, (t0, t1), &breaks, 3, tol, 2048 + 64 * breaks.len()) {
        Ok((f, _)) => f,
        Err(_) => {
            let mut moved = c.clone();
            d.deform(moved.control_points_mut());
            moved
        }
    }
}

/// A plane face that the morph maps into its own plane (a transverse plane under a law
/// that keeps x, a symmetry plane under a symmetric morph): when every moved control point
/// of its B-spline form `plane` (`moved`) and of its bounding curves stays in the plane
/// (within `1e-12 ×` the model size), the face stays that plane, bounded by the moved
/// curves. Moving the form's corners would give the same plane in other parameters whose
/// extent may no longer cover the moved boundary; instead the form is re-bounded: a
/// bilinear patch of the plane's own parameterisation over the box of the moved curves'
/// control points (which hold the curves, Piegl & Tiller property P4.9) and of the
/// morph's image of the curves (what a curve traced on a bent neighbour follows), 1 %
/// wider on each side and at least `3e-3 ×` the model size wider (so that no side of
/// the new patch lies within the edge pairing tolerance, `1e-3 ×` the size, of a
/// neighbour's side: the plane's edges are its curves now, not its iso-boundaries; a
/// narrow side face of an OCCT plate, 0.25 in, kept 1 % = 2.5e-3 in off the bent top's
/// side, was paired with it as an iso-boundary and failed the check). `None` when the
/// morph takes the face out of its plane (or the form is not an affine plane, or it has
/// no curves).
fn in_plane<'a>(
    plane: &NurbsSurface,
    moved: &NurbsSurface,
    curves: impl Iterator<Item = &'a cadmorph_brep::BoundCurve>,
    d: &dyn Deformation,
    size: f64,
) -> Option<NurbsSurface> {
    use cadmorph_nurbs::Surface as _;
    let (ud, vd) = plane.domain();
    let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
    let o = plane.eval(u0, v0);
    let (eu, ev) = (plane.eval(u1, v0) - o, plane.eval(u0, v1) - o);
    let n = eu.cross(&ev);
    if n.norm() <= f64::EPSILON * eu.norm() * ev.norm() {
        return None;
    }
    let n = n.normalize();
    let tol = 1e-12 * size;
    // The form must be the affine parallelogram o + s eu + t ev.
    let grid = (0..=4).flat_map(|i| (0..=4).map(move |j| (i as f64 / 4.0, j as f64 / 4.0)));
    for (s, t) in grid {
        let p = plane.eval(u0 + (u1 - u0) * s, v0 + (v1 - v0) * t);
        if (p - (o + eu * s + ev * t)).norm() > tol {
            return None;
        }
    }
    let off = |p: &cadmorph_morph::math::Point3<f64>| (p - o).dot(&n).abs();
    if moved.control_points().iter().any(|p| off(p) > tol) {
        return None;
    }
    // (s, t) of a point of the plane: least squares on eu, ev.
    let (a, b, c) = (eu.dot(&eu), eu.dot(&ev), ev.dot(&ev));
    let det = a * c - b * b;
    let st = |p: &cadmorph_morph::math::Point3<f64>| {
        let r = p - o;
        let (x, y) = (r.dot(&eu), r.dot(&ev));
        ((c * x - b * y) / det, (a * y - b * x) / det)
    };
    let (mut lo, mut hi) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for curve in curves {
        let mut k = curve.curve.clone();
        d.deform(k.control_points_mut());
        for p in k.control_points() {
            if off(p) > tol {
                return None;
            }
            let (s, t) = st(p);
            lo = (lo.0.min(s), lo.1.min(t));
            hi = (hi.0.max(s), hi.1.max(t));
        }
        // A curve shared with a face the morph bends is traced on that face (see
        // `write_curves`): it follows the morph of the curve, which may bulge out of the
        // hull of the moved control points (a line's chord). The box holds the morph's
        // image of the curve as well.
        let dom = cadmorph_nurbs::Curve::domain(&curve.curve);
        for i in 0..=64 {
            let u = dom.start() + (dom.end() - dom.start()) * i as f64 / 64.0;
            let (s, t) = st(&d.deform_point(&cadmorph_nurbs::Curve::eval(&curve.curve, u)));
            lo = (lo.0.min(s), lo.1.min(t));
            hi = (hi.0.max(s), hi.1.max(t));
        }
    }
    if !(lo.0 < hi.0 && lo.1 < hi.1) {
        return None;
    }
    // A margin of 1 % of the extent for what lies between those points (and a traced
    // curve's own tolerance): the face is trimmed by its curves, so a larger plane patch
    // changes nothing else.
    let floor = 3e-3 * size;
    let (ms, mt) = ((0.01 * (hi.0 - lo.0)).max(floor / eu.norm()), (0.01 * (hi.1 - lo.1)).max(floor / ev.norm()));
    let (lo, hi) = ((lo.0 - ms, lo.1 - mt), (hi.0 + ms, hi.1 + mt));
    let at = |s: f64, t: f64| o + eu * s + ev * t;
    // In the form's parameter ranges, so the face keeps its parameter domain; control
    // points u-major like every surface here (P00, P01, P10, P11).
    let knots = |a: f64, b: f64| cadmorph_nurbs::KnotVector::new_unchecked(vec![a, a, b, b]);
    let out = NurbsSurface::new(
        (1, 1),
        (knots(u0, u1), knots(v0, v1)),
        (2, 2),
        vec![at(lo.0, lo.1), at(lo.0, hi.1), at(hi.0, lo.1), at(hi.0, hi.1)],
        None,
    );
    Some(out)
}

/// A surface that faces at two different placements use, with two such faces, when any
/// of its faces satisfies `moved` (by face index).
fn shared_placed_surface(faces: &[Face], moved: impl Fn(usize) -> bool) -> Option<(EntityRef, EntityRef, EntityRef)> {
    let mut users: std::collections::HashMap<u64, Vec<usize>> = std::collections::HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        users.entry(f.surface_entity.id).or_default().push(i);
    }
    let mut found: Vec<(usize, usize)> = users
        .values()
        .filter(|us| us.iter().any(|&i| moved(i)))
        .filter_map(|us| us.iter().find(|&&i| faces[i].placement != faces[us[0]].placement).map(|&i| (us[0], i)))
        .collect();
    found.sort_unstable();
    found.first().map(|&(a, b)| (faces[b].surface_entity, faces[a].entity, faces[b].entity))
}
