//! Refinement driven by the seams themselves: after moving the control points of every
//! patch, the two sides of each shared edge must agree within a gap and an angle.

use cadmorph_morph::Deformation;
use cadmorph_nurbs::{NurbsSurface, Side, Surface};
use serde::{Deserialize, Serialize};

use crate::measure::side_uv;
use crate::refine::{deformed, exact_normal, short_directions, well_defined_normal};
use crate::{SharedBoundary, TrimEdge, SHARP_EDGE_DEG};

/// Settings of [`refine_seams`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeamRefineOptions {
    /// Largest allowed distance between the two sides at the same edge parameter
    /// after the morph, model units.
    pub tol: f64,
    /// Largest allowed angle between the two sides' normals after the morph, degrees.
    pub angle_tol_deg: f64,
    /// Rounds at most.
    pub max_rounds: usize,
    /// Stop before the patches would exceed this many control points in all.
    pub max_control_points: usize,
}

impl SeamRefineOptions {
    /// `tol` and `angle_tol_deg` with 30 rounds and 2 000 000 control points at most.
    pub fn new(tol: f64, angle_tol_deg: f64) -> Self {
        Self { tol, angle_tol_deg, max_rounds: 30, max_control_points: 2_000_000 }
    }

    /// The control-point budget a refinement of a model holding `before` control points
    /// gets unless told otherwise: 20 times the input, and at least 50 000. A small
    /// model refined as PyGeM refines it, 30 knots per direction, already holds several
    /// thousand (PyGeM's `test_pipe.igs`, 48 control points, gets 6 528), and a 14-face
    /// solid under a 3×3×3 FFD at 1e-5 of its size needs some 24 000 (`mixed_solid.stp`,
    /// its faces raised to quadratic first). It stops a runaway refinement (one chasing
    /// a gap it cannot close: 1.2 to 1.8 million control points on real files before
    /// the seams were measured against the input's) long before memory does.
    pub fn default_budget(before: usize) -> usize {
        before.saturating_mul(20).max(50_000)
    }
}

/// What [`refine_seams`] did. It reads back from its JSON form (`morph --json`'s
/// `refinement`); JSON written before `per_round` existed reads with no rounds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeamRefinement {
    /// Control points of all patches before.
    pub control_points_before: usize,
    /// Control points of all patches after.
    pub control_points_after: usize,
    /// Largest matched gap after the morph, over all iso edges; for trim edges, the
    /// sum of both sides' distances from the exact morph (what the morph adds to the
    /// gap the edge had before).
    pub max_gap: f64,
    /// Largest normal angle after the morph, degrees (unoriented), over the smooth iso
    /// edges; for trim edges and creases (sides meeting at more than
    /// [`SHARP_EDGE_DEG`](crate::SHARP_EDGE_DEG)), the sum of both sides' normal
    /// deviations from the exact morph (how far the crease or smooth join strays from
    /// what the morph makes of it).
    pub max_angle_deg: f64,
    /// Largest growth of an iso edge's matched gap over the gap it had before the morph
    /// (`gap after − gap before`, the quantity held to `tol`), over all iso edges; for
    /// trim edges, as `max_gap`.
    pub max_gap_growth: f64,
    /// Largest growth of a smooth iso edge's normal angle over its angle before the
    /// morph, degrees (held to `angle_tol_deg`); for creases and trim edges, as
    /// `max_angle_deg`.
    pub max_angle_growth_deg: f64,
    /// Iso edges whose sides were already apart by more than `tol` (matched gap), or
    /// whose smooth join was already off by more than `angle_tol_deg`, before the morph:
    /// defects of the input, which refinement carries along but does not chase.
    pub input_defects: usize,
    /// Rounds run.
    pub rounds: usize,
    /// Whether both tolerances were reached.
    pub converged: bool,
    /// What each round measured, `rounds + 1` entries: round 0 is the input (before any
    /// knot), round `k` the patches after `k` knot insertions. The last entry is the
    /// state this report gives (`control_points_after`, `max_gap`, ...), so the entries
    /// show how the control points grew and the errors fell round by round.
    pub per_round: Vec<RefineRound>,
}

/// One round of [`refine_edges`]: the patches' size and the errors of their morph as
/// that round measured them (the same samples as the final report's numbers).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RefineRound {
    /// The round: 0 for the input, `k` after `k` knot insertions.
    pub round: usize,
    /// Control points of all patches.
    pub control_points: usize,
    /// Largest gap after the morph, as [`SeamRefinement::max_gap`].
    pub max_gap: f64,
    /// Largest angle after the morph, degrees, as [`SeamRefinement::max_angle_deg`].
    pub max_angle_deg: f64,
    /// Largest gap growth, as [`SeamRefinement::max_gap_growth`] (held to `tol`).
    pub max_gap_growth: f64,
    /// Largest angle growth, degrees, as [`SeamRefinement::max_angle_growth_deg`].
    pub max_angle_growth_deg: f64,
}

/// The input's own matched gap and (unoriented) normal angle along an iso edge, largest
/// over `n` evenly spaced samples: what the edge is held to, plus the tolerances.
fn input_state(patches: &[NurbsSurface], e: &SharedBoundary, n: usize) -> (f64, f64) {
    let (mut gap, mut angle): (f64, f64) = (0.0, 0.0);
    for k in 0..n {
        let ta = e.a_range.0 + (e.a_range.1 - e.a_range.0) * k as f64 / (n - 1) as f64;
        let (ua, va) = side_uv(&patches[e.a.patch], e.a.side, ta);
        let (ub, vb) = side_uv(&patches[e.b.patch], e.b.side, e.b_param(ta));
        let g = (patches[e.a.patch].eval(ua, va) - patches[e.b.patch].eval(ub, vb)).norm();
        if g.is_finite() {
            gap = gap.max(g);
        }
        if let (Some(x), Some(y)) =
            (well_defined_normal(&patches[e.a.patch], ua, va), well_defined_normal(&patches[e.b.patch], ub, vb))
        {
            let t = x.cross(&y).norm().atan2(x.dot(&y)).to_degrees();
            angle = angle.max(t.min(180.0 - t));
        }
    }
    (gap, angle)
}

fn spans(s: &NurbsSurface, along_u: bool) -> Vec<f64> {
    let (ud, vd) = s.domain();
    let (k, d) = if along_u { (s.u_knots(), ud) } else { (s.v_knots(), vd) };
    k.distinct().0.into_iter().filter(|x| d.contains(x)).collect()
}

/// Index of the span of `breaks` holding `t`.
fn span_of(breaks: &[f64], t: f64) -> usize {
    breaks.partition_point(|&b| b <= t).saturating_sub(1).min(breaks.len() - 2)
}

/// Knots to insert per patch: `(u, v)` sets of span indices.
struct Marks {
    u: Vec<Vec<bool>>,
    v: Vec<Vec<bool>>,
}

impl Marks {
    fn along(&mut self, patch: usize, side: Side, span: usize) {
        let m = if matches!(side, Side::UMin | Side::UMax) { &mut self.v[patch] } else { &mut self.u[patch] };
        for k in span.saturating_sub(1)..=(span + 1).min(m.len() - 1) {
            m[k] = true;
        }
    }
    fn at(&mut self, patch: usize, u_span: usize, v_span: usize, (u, v): (bool, bool)) {
        if u {
            self.u[patch][u_span] = true;
        }
        if v {
            self.v[patch][v_span] = true;
        }
    }
    fn across(&mut self, patch: usize, side: Side) {
        match side {
            Side::UMin => self.u[patch][0] = true,
            Side::UMax => *self.u[patch].last_mut().expect("a span") = true,
            Side::VMin => self.v[patch][0] = true,
            Side::VMax => *self.v[patch].last_mut().expect("a span") = true,
        }
    }
}

/// Inserts knots into `patches` (their geometry does not change) until, after moving
/// every control point with `d`, the two sides of every edge in `edges` agree within
/// `opts.tol` (matched gap) and `opts.angle_tol_deg` (normal angle) more than they did
/// before the morph: each edge is held to `max(input gap, 0) + tol` and, if smooth, to
/// `input angle + angle_tol_deg`, so a gap the input already had (a defect that knot
/// insertion cannot close) is carried along and never drives refinement.
///
/// Along each edge, samples whose gap is too large bisect the knot spans along the
/// edge on both sides (with their neighbours: the boundary curve there depends on
/// them); samples whose normals differ too much bisect the span next to the edge
/// across it, on both sides: that shortens the leg from the boundary row to the next
/// row, and the normal error of a morphed leg shrinks with its length (where the sides
/// also show a gap, their rows differ and the spans along the edge are bisected too).
/// Two sides that
/// share their boundary row exactly (compatible knots, as when one surface was split)
/// keep a zero gap under any morph, so only the second rule then adds knots: a few rows
/// next to each seam, instead of refining whole patches.
///
/// # Tolerance
///
/// The angle falls by about half per round where it is too large (the leg halves); the
/// gap, where the boundary rows differ, by about a quarter.
pub fn refine_seams<D: Deformation + ?Sized>(
    patches: &mut [NurbsSurface],
    edges: &[SharedBoundary],
    d: &D,
    opts: &SeamRefineOptions,
) -> SeamRefinement {
    refine_edges(patches, edges, &[], d, opts)
}

/// [`refine_seams`] over iso edges and edges given by their curves ([`TrimEdge`]s,
/// from a file's topology or trims) together.
///
/// Along a trim edge neither side has the edge as a boundary row, so the two sides are
/// held to the exact morph separately: each edge point is projected onto each face, and
/// where the two sides' distances from `M ∘ S` add up to more than `tol` (or their
/// normals' deviations from the normals of `M ∘ S` to more than `angle_tol_deg`), the
/// knot spans holding that point are bisected on each side that takes more than its half
/// (`tol / 2`, `angle_tol_deg / 2`): in both directions for a distance, in the directions
/// whose derivatives fall short for a normal. Creases between iso edges are held the
/// same way. The gap the edge had before then grows by at most `tol`, and its angle
/// (smooth join or crease) changes as the exact morph changes it, within
/// `angle_tol_deg`.
pub fn refine_edges<D: Deformation + ?Sized>(
    patches: &mut [NurbsSurface],
    edges: &[SharedBoundary],
    trims: &[TrimEdge],
    d: &D,
    opts: &SeamRefineOptions,
) -> SeamRefinement {
    let count = |p: &[NurbsSurface]| p.iter().map(|s| s.control_points().len()).sum::<usize>();
    let before = count(patches);
    let mut rounds = 0;
    let mut per_round = Vec::new();
    // What each iso edge had before the morph (knots do not change the geometry).
    let input: Vec<(f64, f64)> = edges.iter().map(|e| input_state(patches, e, 201)).collect();
    let input_defects = edges.iter().zip(&input).filter(|(_, (g, a))| *g > opts.tol || *a > opts.angle_tol_deg).count();
    // Creases: edges whose sides meet at more than SHARP_EDGE_DEG somewhere (the angle
    // may fall along the edge, as where a loft's side faces meet its cap); refinement
    // keeps their angle as the morph makes it, not at zero. Knots do not change the
    // geometry, so this holds for every round.
    let crease: Vec<bool> = edges
        .iter()
        .map(|e| {
            (0..33).any(|k| {
                let ta = e.a_range.0 + (e.a_range.1 - e.a_range.0) * k as f64 / 32.0;
                let (ua, va) = side_uv(&patches[e.a.patch], e.a.side, ta);
                let (ub, vb) = side_uv(&patches[e.b.patch], e.b.side, e.b_param(ta));
                match (
                    well_defined_normal(&patches[e.a.patch], ua, va),
                    well_defined_normal(&patches[e.b.patch], ub, vb),
                ) {
                    (Some(x), Some(y)) => {
                        let t = x.cross(&y).norm().atan2(x.dot(&y)).to_degrees();
                        t.min(180.0 - t) > SHARP_EDGE_DEG
                    }
                    _ => false,
                }
            })
        })
        .collect();
    loop {
        let moved: Vec<NurbsSurface> = patches.iter().map(|s| deformed(s, d)).collect();
        let ubreaks: Vec<Vec<f64>> = patches.iter().map(|s| spans(s, true)).collect();
        let vbreaks: Vec<Vec<f64>> = patches.iter().map(|s| spans(s, false)).collect();
        let mut marks = Marks {
            u: ubreaks.iter().map(|b| vec![false; b.len() - 1]).collect(),
            v: vbreaks.iter().map(|b| vec![false; b.len() - 1]).collect(),
        };
        let (mut max_gap, mut max_angle): (f64, f64) = (0.0, 0.0);
        let (mut gap_growth, mut angle_growth): (f64, f64) = (0.0, 0.0);
        for (ei, e) in edges.iter().enumerate() {
            let (gap0, angle0) = input[ei];
            let allowed_gap = gap0 + opts.tol;
            let (a, b) = (e.a.patch, e.b.patch);
            let along = |patch: usize, side: Side| {
                if matches!(side, Side::UMin | Side::UMax) {
                    &vbreaks[patch]
                } else {
                    &ubreaks[patch]
                }
            };
            let n = 8 * (along(a, e.a.side).len() + along(b, e.b.side).len()) + 1;
            for k in 0..n {
                let ta = e.a_range.0 + (e.a_range.1 - e.a_range.0) * k as f64 / (n - 1) as f64;
                let tb = e.b_param(ta);
                let (ua, va) = side_uv(&patches[a], e.a.side, ta);
                let (ub, vb) = side_uv(&patches[b], e.b.side, tb);
                let gap = (moved[a].eval(ua, va) - moved[b].eval(ub, vb)).norm();
                max_gap = max_gap.max(if gap.is_nan() { f64::INFINITY } else { gap });
                gap_growth = gap_growth.max(if gap.is_nan() { f64::INFINITY } else { gap - gap0 });
                if gap > allowed_gap || gap.is_nan() {
                    marks.along(a, e.a.side, span_of(along(a, e.a.side), ta));
                    marks.along(b, e.b.side, span_of(along(b, e.b.side), tb));
                }
                // A crease (the sides meet at an angle by design): each side's normal is
                // held to the exact morph's instead, as along trim edges.
                if crease[ei] {
                    let mut devs = [None; 2];
                    for (i, (patch, (u, v))) in [(a, (ua, va)), (b, (ub, vb))].into_iter().enumerate() {
                        let p = patches[patch].eval(u, v);
                        let h = 1e-6 * (1.0 + p.coords.norm());
                        if let (Some(x), Some(y)) =
                            (well_defined_normal(&moved[patch], u, v), exact_normal(&patches[patch], d, u, v, h))
                        {
                            devs[i] = Some((x.cross(&y).norm().atan2(x.dot(&y)).to_degrees(), h));
                        }
                    }
                    let dev_sum: f64 = devs.iter().flatten().map(|(dev, _)| dev).sum();
                    // As along trim edges: only where the sum fails, the sides with more
                    // than their half.
                    for (i, (patch, side, (u, v))) in
                        [(a, e.a.side, (ua, va)), (b, e.b.side, (ub, vb))].into_iter().enumerate()
                    {
                        let Some((dev, h)) = devs[i] else { continue };
                        if dev_sum > opts.angle_tol_deg && dev > opts.angle_tol_deg / 2.0 {
                            // The normal depends on the tangent along the edge too:
                            // bisect the directions whose derivatives fall short.
                            let (du, dv) = short_directions(&patches[patch], &moved[patch], d, u, v, h);
                            let across_u = matches!(side, Side::UMin | Side::UMax);
                            let (across, along_too) = if across_u { (du, dv) } else { (dv, du) };
                            if across {
                                marks.across(patch, side);
                            }
                            if along_too {
                                let t = if i == 0 { ta } else { tb };
                                marks.along(patch, side, span_of(along(patch, side), t));
                            }
                        }
                    }
                    max_angle = max_angle.max(dev_sum);
                    angle_growth = angle_growth.max(dev_sum);
                } else if let (Some(na), Some(nb)) =
                    (well_defined_normal(&moved[a], ua, va), well_defined_normal(&moved[b], ub, vb))
                {
                    let angle = na.cross(&nb).norm().atan2(na.dot(&nb)).to_degrees();
                    let angle = angle.min(180.0 - angle);
                    max_angle = max_angle.max(angle);
                    angle_growth = angle_growth.max(angle - angle0);
                    if angle > angle0 + opts.angle_tol_deg {
                        marks.across(a, e.a.side);
                        marks.across(b, e.b.side);
                        // Sides whose boundary rows differ (a visible gap) also bend
                        // differently along the edge; shorter legs alone cannot fix that.
                        if gap > gap0 + 1e-3 * opts.tol {
                            marks.along(a, e.a.side, span_of(along(a, e.a.side), ta));
                            marks.along(b, e.b.side, span_of(along(b, e.b.side), tb));
                        }
                    }
                }
            }
        }
        for e in trims {
            let n = 8 * [e.a, e.b].iter().map(|&p| ubreaks[p].len() + vbreaks[p].len()).sum::<usize>() + 1;
            let sides = [e.on_surface(&patches[e.a], n), e.on_surface(&patches[e.b], n)];
            for k in 0..n {
                let mut each = [(0.0, 0.0, 0.0); 2];
                for (side, patch) in [e.a, e.b].into_iter().enumerate() {
                    let of = sides[side][k].2;
                    let err = (moved[patch].eval(of.u, of.v) - d.deform_point(&of.point)).norm();
                    let h = 1e-6 * (1.0 + of.point.coords.norm());
                    let dev = match (
                        well_defined_normal(&moved[patch], of.u, of.v),
                        exact_normal(&patches[patch], d, of.u, of.v, h),
                    ) {
                        (Some(x), Some(y)) => x.cross(&y).norm().atan2(x.dot(&y)).to_degrees(),
                        _ => 0.0,
                    };
                    each[side] = (if err.is_nan() { f64::INFINITY } else { err }, dev, h);
                }
                let gap = each[0].0 + each[1].0;
                let angle = each[0].1 + each[1].1;
                // Only where the edge fails, and there only the sides with more than their
                // half of the tolerance: a side that keeps within its half needs nothing,
                // nor does a side off by more when the other makes up for it.
                let (far, turned) = (gap > opts.tol, angle > opts.angle_tol_deg);
                for (side, patch) in [e.a, e.b].into_iter().enumerate() {
                    let (err, dev, h) = each[side];
                    let off = far && err > opts.tol / 2.0;
                    if off || (turned && dev > opts.angle_tol_deg / 2.0) {
                        let of = sides[side][k].2;
                        // A point off the exact morph needs both directions; a normal
                        // alone, only the directions whose derivatives fall short.
                        let dirs = if off {
                            (true, true)
                        } else {
                            short_directions(&patches[patch], &moved[patch], d, of.u, of.v, h)
                        };
                        marks.at(patch, span_of(&ubreaks[patch], of.u), span_of(&vbreaks[patch], of.v), dirs);
                    }
                }
                max_gap = max_gap.max(gap);
                max_angle = max_angle.max(angle);
                gap_growth = gap_growth.max(gap);
                angle_growth = angle_growth.max(angle);
            }
        }
        let done = gap_growth <= opts.tol && angle_growth <= opts.angle_tol_deg;
        per_round.push(RefineRound {
            round: rounds,
            control_points: count(patches),
            max_gap,
            max_angle_deg: max_angle,
            max_gap_growth: gap_growth,
            max_angle_growth_deg: angle_growth,
        });
        let inserts: Vec<(Vec<f64>, Vec<f64>)> = (0..patches.len())
            .map(|i| {
                let mid = |b: &[f64], m: &[bool]| -> Vec<f64> {
                    (0..m.len()).filter(|&k| m[k]).map(|k| (b[k] + b[k + 1]) / 2.0).collect()
                };
                (mid(&ubreaks[i], &marks.u[i]), mid(&vbreaks[i], &marks.v[i]))
            })
            .collect();
        let grown: usize =
            patches.iter().zip(&inserts).map(|(s, (xu, xv))| (s.n_u() + xu.len()) * (s.n_v() + xv.len())).sum();
        let nothing = inserts.iter().all(|(xu, xv)| xu.is_empty() && xv.is_empty());
        if done || rounds >= opts.max_rounds || grown > opts.max_control_points || nothing {
            return SeamRefinement {
                control_points_before: before,
                control_points_after: count(patches),
                max_gap,
                max_angle_deg: max_angle,
                max_gap_growth: gap_growth,
                max_angle_growth_deg: angle_growth,
                input_defects,
                rounds,
                converged: done,
                per_round,
            };
        }
        for (s, (xu, xv)) in patches.iter_mut().zip(&inserts) {
            s.refine_u(xu).expect("midpoints of non-empty spans are new interior knots");
            s.refine_v(xv).expect("midpoints of non-empty spans are new interior knots");
        }
        rounds += 1;
    }
}
