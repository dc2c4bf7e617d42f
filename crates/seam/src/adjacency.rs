//! Shared boundaries of untrimmed patches found from geometry alone, for files that
//! carry no topology (bare IGES 128 surfaces).

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Aabb, Curve, CurveProjector, NurbsCurve, NurbsSurface, Side, Surface};
use serde::Serialize;

use crate::index::BoxIndex;

/// One side of one patch: `patch` indexes the caller's patch list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct SideRef {
    /// Index of the patch.
    pub patch: usize,
    /// Which iso-boundary.
    #[serde(serialize_with = "side_name")]
    pub side: Side,
}

fn side_name<S: serde::Serializer>(side: &Side, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(crate::measure::side_label(*side))
}

/// Two iso-boundaries that coincide (over part of their length at least).
///
/// `a_range` and `b_range` are the overlapping parameter intervals on each side's
/// boundary curve, oriented so that `a_range.0` meets `b_range.0` (so `b_range` runs
/// backwards when the two boundaries run in opposite directions).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SharedBoundary {
    /// The first side.
    pub a: SideRef,
    /// The second side.
    pub b: SideRef,
    /// Overlap on `a`'s boundary curve, increasing.
    pub a_range: (f64, f64),
    /// Matching overlap on `b`'s boundary curve (decreasing if reversed).
    pub b_range: (f64, f64),
}

impl SharedBoundary {
    /// Whether `b` runs against `a`.
    pub fn reversed(&self) -> bool {
        self.b_range.1 < self.b_range.0
    }

    /// The parameter on `b` matched to parameter `t` on `a`, by linear map of the ranges.
    pub fn b_param(&self, t: f64) -> f64 {
        let f = (t - self.a_range.0) / (self.a_range.1 - self.a_range.0);
        self.b_range.0 + f * (self.b_range.1 - self.b_range.0)
    }
}

/// Boundary curves of a patch, with their bounding boxes.
struct Boundary {
    side: SideRef,
    curve: NurbsCurve,
    bbox: Aabb,
    length: f64,
}

fn polyline_length(c: &NurbsCurve, n: usize) -> f64 {
    let d = c.domain();
    let pts: Vec<Point3<f64>> =
        (0..=n).map(|i| c.eval(d.start() + (d.end() - d.start()) * i as f64 / n as f64)).collect();
    pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Finds every pair of iso-boundaries of `patches` that lie on each other within `tol`
/// (model units) over at least `min_fraction` of the shorter one's length, and the
/// closing seam of every face closed in u or v (an edge of a patch with itself,
/// `a.patch == b.patch`; see [`closing_seams`]).
///
/// Each boundary is sampled at `samples` points; a sample counts as lying on the other
/// boundary when its projection onto that boundary curve is within `tol`. The overlap is
/// the parameter interval of the matched samples, and the matching interval on the other
/// side comes from projecting its two ends. Collapsed boundaries (poles, whose length
/// is below `tol`) never pair; boundaries that merely touch (less than `min_fraction`
/// of the shorter on the other) do not either.
///
/// # Pairing
///
/// Each boundary is sampled onto the boundaries at least as long as it (by length, then
/// by index), found through a bounding-box index (`BoxIndex`), and keeps the one
/// partner it lies on over the largest part of its length (the first in index order
/// among equals), as OCCT's sewing gives each free edge one partner. So a model of `n`
/// faces pairs in `O(n log n)` box queries plus a bounded number of overlap tests per
/// boundary, and `k` coincident copies of a face give `k − 1` edges, not `k²/2`.
///
/// # Tolerance
///
/// `tol` should exceed the gaps one wants to see (a defective seam of 2 mm needs
/// `tol` above 2 mm) and stay below the patches' size; `1e-3 × model size` is a
/// reasonable default for CAD that was joined by construction.
pub fn shared_boundaries(
    patches: &[&NurbsSurface],
    tol: f64,
    samples: usize,
    min_fraction: f64,
) -> Vec<SharedBoundary> {
    let samples = samples.max(3);
    let mut boundaries = Vec::new();
    for (patch, s) in patches.iter().enumerate() {
        for side in Side::ALL {
            let curve = s.boundary(side);
            let length = polyline_length(&curve, 64);
            if length <= tol || !length.is_finite() {
                continue;
            }
            let bbox = curve.bounding_box().inflated(tol);
            boundaries.push(Boundary { side: SideRef { patch, side }, curve, bbox, length });
        }
    }
    let index = BoxIndex::new(boundaries.iter().map(|b| &b.bbox));
    let mut out = Vec::new();
    for i in 0..boundaries.len() {
        let short = &boundaries[i];
        let candidates = index.overlapping(&short.bbox).into_iter().filter(|&j| {
            let long = &boundaries[j];
            long.side.patch != short.side.patch && (long.length, j) > (short.length, i)
        });
        let best = best_partner(candidates, &short.curve, |j| &boundaries[j].curve, tol, samples, min_fraction);
        let Some((j, (short_range, long_range))) = best else { continue };
        // Orient as (a, b) in index order.
        let shared = if j < i {
            orient(boundaries[j].side, short.side, long_range, short_range)
        } else {
            orient(short.side, boundaries[j].side, short_range, long_range)
        };
        out.push(shared);
    }
    out.sort_by_key(|e| (e.a.patch, e.b.patch, e.a.side as u8, e.b.side as u8));
    out.extend(closing_seams(patches, tol, samples, min_fraction));
    out
}

/// Ranges `(on short, on long)` of an overlap and the fraction of `short`'s domain it covers.
type Overlap = ((f64, f64), (f64, f64));

/// Among `candidates` (indices whose curves `curve_of` gives), the one `short` lies on
/// over the largest part of its domain, with the overlap; the scan stops at the first
/// that covers all of it.
pub(crate) fn best_partner<'c>(
    candidates: impl Iterator<Item = usize>,
    short: &NurbsCurve,
    curve_of: impl Fn(usize) -> &'c NurbsCurve,
    tol: f64,
    samples: usize,
    min_fraction: f64,
) -> Option<(usize, Overlap)> {
    let d = short.domain();
    let span = (d.end() - d.start()).abs().max(f64::MIN_POSITIVE);
    let mut best: Option<(usize, Overlap, f64)> = None;
    for j in candidates {
        let Some(o) = overlap(short, curve_of(j), tol, samples, min_fraction) else { continue };
        let cover = (o.0 .1 - o.0 .0).abs() / span;
        if best.as_ref().is_none_or(|b| cover > b.2) {
            best = Some((j, o, cover));
        }
        if cover >= 1.0 - 1e-9 {
            break;
        }
    }
    best.map(|(j, o, _)| (j, o))
}

/// The closing seams of faces closed in u or v (a blade's section loop, a full
/// cylinder): the two opposite sides of one patch that lie on each other, as an edge
/// of the patch with itself. Sides lie on each other within `max(tol, 1e-2 × the
/// distance across the face)` (the length of the iso line from one side to the other
/// through the middle), so a closing seam opened by a defect larger than `tol` is still
/// seen as one, while a narrow strip's two long sides never pair. Collapsed sides
/// (poles) never pair.
pub fn closing_seams(patches: &[&NurbsSurface], tol: f64, samples: usize, min_fraction: f64) -> Vec<SharedBoundary> {
    let mut out = Vec::new();
    for (patch, s) in patches.iter().enumerate() {
        let (ud, vd) = s.domain();
        for (lo, hi) in [(Side::UMin, Side::UMax), (Side::VMin, Side::VMax)] {
            let (a, b) = (s.boundary(lo), s.boundary(hi));
            if polyline_length(&a, 64) <= tol || polyline_length(&b, 64) <= tol {
                continue;
            }
            let across = if lo == Side::UMin {
                s.v_iso((vd.start() + vd.end()) / 2.0)
            } else {
                s.u_iso((ud.start() + ud.end()) / 2.0)
            };
            let close = tol.max(1e-2 * polyline_length(&across, 256));
            // The two sides of a patch share their parameter (`S(u₀, t)` and `S(u₁, t)`
            // for a patch closed in u), so a closing seam matches them at equal `t`, not
            // by projection: sides that are closed curves themselves (a torus's, a
            // revolved loop's) project their ends onto either end of the other, which
            // would pair points half a turn apart.
            let d = a.domain();
            let (t0, t1) = (*d.start(), *d.end());
            let mut matched = 0usize;
            let (mut first, mut last) = (None, None);
            for i in 0..samples {
                let t = t0 + (t1 - t0) * i as f64 / (samples - 1) as f64;
                if (a.eval(t) - b.eval(t)).norm() <= close {
                    matched += 1;
                    first = first.or(Some(t));
                    last = Some(t);
                }
            }
            let (Some(f), Some(l)) = (first, last) else { continue };
            if (matched as f64) < min_fraction * samples as f64 || l <= f {
                continue;
            }
            out.push(orient(SideRef { patch, side: lo }, SideRef { patch, side: hi }, (f, l), (f, l)));
        }
    }
    out
}

fn orient(a: SideRef, b: SideRef, a_range: (f64, f64), b_range: (f64, f64)) -> SharedBoundary {
    if a_range.0 <= a_range.1 {
        SharedBoundary { a, b, a_range, b_range }
    } else {
        SharedBoundary { a, b, a_range: (a_range.1, a_range.0), b_range: (b_range.1, b_range.0) }
    }
}

/// The matched intervals of `short` on `long`: `(range on short, range on long)` with
/// the first entries matched, or `None` if less than `min_fraction` of `short` lies on `long`.
pub(crate) fn overlap(
    short: &NurbsCurve,
    long: &NurbsCurve,
    tol: f64,
    samples: usize,
    min_fraction: f64,
) -> Option<((f64, f64), (f64, f64))> {
    let d = short.domain();
    let (t0, t1) = (*d.start(), *d.end());
    let mut first: Option<(f64, f64)> = None;
    let mut last: Option<(f64, f64)> = None;
    let mut matched = 0;
    // Once more samples have missed than `min_fraction` allows, the answer is no.
    let allowed_misses = samples as f64 * (1.0 - min_fraction);
    let projector = CurveProjector::new(long);
    for i in 0..samples {
        let t = t0 + (t1 - t0) * i as f64 / (samples - 1) as f64;
        let pr = projector.project(&short.eval(t), tol * 1e-3);
        if pr.distance_sq <= tol * tol {
            matched += 1;
            if first.is_none() {
                first = Some((t, pr.t));
            }
            last = Some((t, pr.t));
        } else if (i + 1 - matched) as f64 > allowed_misses {
            return None;
        }
    }
    if (matched as f64) < min_fraction * samples as f64 {
        return None;
    }
    let (first, last) = (first?, last?);
    // Snap the matched ends on `long` to its own ends when they lie within `tol` of them
    // in space, so that two boundaries that meet end to end (up to the gap being
    // measured) are recognised as covering each other completely.
    let ld = long.domain();
    let snap = |t: f64| {
        for end in [*ld.start(), *ld.end()] {
            if (long.eval(t) - long.eval(end)).norm() <= tol {
                return end;
            }
        }
        t
    };
    Some(((first.0, last.0), (snap(first.1), snap(last.1))))
}
