//! Shared edges that are not iso-boundaries: edges from a file's topology (STEP B-rep
//! `EDGE_CURVE`s, IGES 504 edge lists) and trimming curves of two faces that lie on each
//! other (IGES 144/142 without topology).

use cadmorph_brep::EntityRef;
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Aabb, Curve, CurveProject, NurbsCurve, NurbsSurface, Projection, Surface, SurfaceProject};

use crate::adjacency::best_partner;
use crate::index::BoxIndex;
use crate::measure::{angle_deg, oriented_normal, Acc, EdgeEnd, EdgeReport, Face};
use crate::SharedBoundary;

/// An edge shared by two faces, given by its model-space curve: the edge is the curve
/// over `range`. Neither face needs to have the edge as an iso-boundary.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimEdge {
    /// Index of the first face's patch.
    pub a: usize,
    /// Index of the second face's patch.
    pub b: usize,
    /// The edge curve, world coordinates.
    pub curve: NurbsCurve,
    /// The edge's part of the curve's domain.
    pub range: (f64, f64),
    /// The entities it came from, for reports (`#12` in STEP, `DE 45` in IGES; both
    /// faces' trimming curves when it was matched from geometry).
    pub label: Vec<EntityRef>,
}

/// A face's trimming curve (one piece of a boundary) for [`shared_curves`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrimCurve {
    /// Index of the face's patch.
    pub patch: usize,
    /// The curve, world coordinates.
    pub curve: NurbsCurve,
    /// The entity it came from, for reports.
    pub label: Option<EntityRef>,
}

/// Where an edge sample lies on one face: parameters and point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OnFace {
    pub u: f64,
    pub v: f64,
    pub point: Point3<f64>,
}

impl TrimEdge {
    /// `n ≥ 2` evenly spaced parameters over the edge, ends included.
    pub fn params(&self, n: usize) -> impl Iterator<Item = f64> + '_ {
        let n = n.max(2);
        (0..n).map(move |k| self.range.0 + (self.range.1 - self.range.0) * k as f64 / (n - 1) as f64)
    }

    /// The points of the edge at [`params`](Self::params)`(n)` and the closest point on
    /// `surface` to each, found by Newton from the previous sample's (a global search
    /// for the first, and wherever the local answer jumps away).
    pub(crate) fn on_surface(&self, surface: &NurbsSurface, n: usize) -> Vec<(f64, Point3<f64>, OnFace)> {
        let pts: Vec<(f64, Point3<f64>)> = self.params(n).map(|t| (t, self.curve.eval(t))).collect();
        let scale = pts.windows(2).map(|w| (w[1].1 - w[0].1).norm()).sum::<f64>().max(f64::MIN_POSITIVE);
        let ptol = 1e-12 * scale;
        let known = known_points(surface);
        let mut prev: Option<Projection> = None;
        let mut out = Vec::with_capacity(pts.len());
        for (t, p) in pts {
            let pr = match prev {
                Some(q) => {
                    let local = surface.project_from(&p, (q.u, q.v), ptol);
                    // A local answer farther than the last one plus the step taken is suspect.
                    if local.distance_sq.sqrt() > q.distance_sq.sqrt() + 1e-6 * scale {
                        let global = surface.project(&p, ptol);
                        if global.distance_sq < local.distance_sq {
                            global
                        } else {
                            local
                        }
                    } else {
                        local
                    }
                }
                None => surface.project(&p, ptol),
            };
            // No closest point is farther than a point of the surface we know: a search
            // that ends farther has failed, and its distance is no measurement.
            let bound = known.iter().map(|k| (k - p).norm()).fold(f64::INFINITY, f64::min);
            let lost = |pr: &Projection| {
                let d = pr.distance_sq.sqrt();
                !(d.is_finite() && pr.u.is_finite() && pr.v.is_finite()) || d > bound * (1.0 + 1e-9) + ptol
            };
            // A local answer that lost its way gets the global search before giving up.
            let pr = if lost(&pr) && prev.is_some() { surface.project(&p, ptol) } else { pr };
            if lost(&pr) {
                out.push((t, p, OnFace { u: f64::NAN, v: f64::NAN, point: p }));
                continue;
            }
            out.push((t, p, OnFace { u: pr.u, v: pr.v, point: pr.point }));
            prev = Some(pr);
        }
        out
    }

    /// Whether this edge is `iso` seen from its curve: the same two patches, and the
    /// edge's quarter, middle and three-quarter points lie within `tol` of the iso
    /// edge's first side (on `first`, the surface of patch `iso.a.patch`).
    pub fn lies_on(&self, iso: &SharedBoundary, first: &NurbsSurface, tol: f64) -> bool {
        let same = (iso.a.patch, iso.b.patch) == (self.a, self.b) || (iso.a.patch, iso.b.patch) == (self.b, self.a);
        if !same {
            return false;
        }
        let side = first.boundary(iso.a.side);
        let (lo, hi) = (iso.a_range.0.min(iso.a_range.1), iso.a_range.0.max(iso.a_range.1));
        let slack = 1e-6 * (hi - lo).abs().max(f64::MIN_POSITIVE);
        [0.25, 0.5, 0.75].iter().all(|f| {
            let p = self.curve.eval(self.range.0 + (self.range.1 - self.range.0) * f);
            let pr = side.project(&p, tol * 1e-3);
            pr.distance_sq <= tol * tol && pr.t >= lo - slack && pr.t <= hi + slack
        })
    }
}

/// Points of `s` on a 9 × 9 grid of its domain: upper bounds for closest-point distances.
fn known_points(s: &NurbsSurface) -> Vec<Point3<f64>> {
    let (ud, vd) = s.domain();
    let at = |r: &std::ops::RangeInclusive<f64>, k: usize| r.start() + (r.end() - r.start()) * k as f64 / 8.0;
    (0..9).flat_map(|i| (0..9).map(move |j| (i, j))).map(|(i, j)| s.eval(at(&ud, i), at(&vd, j))).collect()
}

/// One sample of [`EdgeSamples`]: edge parameter, `(u, v)` on the first face and on the
/// second.
pub type EdgeSample = (f64, (f64, f64), (f64, f64));

/// Where the samples of a [`TrimEdge`] lie on its two faces: what [`measure_edge`]
/// measures, kept so that the same surface points can be measured again after the
/// faces move (their parameters are those of the faces, which a morph of control
/// points keeps, so the samples follow the faces as trimming curves in parameter space
/// do).
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeSamples {
    /// First patch.
    pub a: usize,
    /// Second patch.
    pub b: usize,
    /// The edge's entities in the file.
    pub label: Vec<EntityRef>,
    /// Edge parameter, then `(u, v)` on the first and on the second face; `NaN`
    /// parameters where the edge point could not be taken to that face.
    pub at: Vec<EdgeSample>,
}

impl TrimEdge {
    /// The edge's `n` samples taken to both faces by closest-point projection.
    pub fn samples(&self, faces: &[Face], n: usize) -> EdgeSamples {
        let on_a = self.on_surface(faces[self.a].surface, n);
        let on_b = self.on_surface(faces[self.b].surface, n);
        EdgeSamples {
            a: self.a,
            b: self.b,
            label: self.label.clone(),
            at: on_a.iter().zip(&on_b).map(|((t, _, pa), (_, _, pb))| (*t, (pa.u, pa.v), (pb.u, pb.v))).collect(),
        }
    }
}

/// Measures an edge given by its curve between `faces[edge.a]` and `faces[edge.b]` at
/// `samples` points (ends included), with the quantities of [`EdgeReport`].
///
/// Each edge point is taken to each face by closest-point projection, which gives the
/// two faces' points at the same edge parameter (`gap_matched`, as OCCT's check with
/// p-curves would pair them); `gap_closest` is the larger distance from either of those
/// points to the other face; the G1 angle compares the oriented normals at the first
/// face's point and its closest point on the second. `c1_mismatch` is `None`: there is
/// no cross-boundary derivative across a trimming curve.
pub fn measure_edge(faces: &[Face], edge: &TrimEdge, samples: usize) -> EdgeReport {
    measure_edge_samples(faces, &edge.samples(faces, samples))
}

/// [`measure_edge`] at given face parameters: after a morph that moved the faces'
/// control points, the samples taken before it measure the gap the morph opened
/// between the faces' own trimmed boundaries, whatever the file's edge curve does.
pub fn measure_edge_samples(faces: &[Face], s: &EdgeSamples) -> EdgeReport {
    let (fa, fb) = (&faces[s.a], &faces[s.b]);
    let (sa, sb) = (fa.surface, fb.surface);
    // Samples with a failed projection (NaN parameters) are not measured: counted by
    // the report, never a gap.
    let pts: Vec<Option<(Point3<f64>, Point3<f64>)>> =
        s.at.iter()
            .map(|(_, (ua, va), (ub, vb))| {
                [ua, va, ub, vb].iter().all(|x| x.is_finite()).then(|| (sa.eval(*ua, *va), sb.eval(*ub, *vb)))
            })
            .collect();
    let measured: Vec<Point3<f64>> = pts.iter().flatten().map(|p| p.0).collect();
    let length = measured.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
    let ptol = 1e-12 * length.max(f64::MIN_POSITIVE);
    let (mut gap_closest, mut gap_matched, mut g1, mut g1u) = (Acc::new(), Acc::new(), Acc::new(), Acc::new());
    for ((t, (ua, va), (ub, vb)), p) in s.at.iter().zip(&pts) {
        let Some((pa, pb)) = p else { continue };
        let matched = (pa - pb).norm();
        gap_matched.add(matched, *pa, *t);
        let to_b = sb.project_from(pa, (*ub, *vb), ptol);
        let to_a = sa.project_from(pb, (*ua, *va), ptol);
        let closest = to_b.distance_sq.sqrt().min(matched).max(to_a.distance_sq.sqrt().min(matched));
        gap_closest.add(closest, *pa, *t);
        if let (Some(na), Some(nb)) = (oriented_normal(fa, *ua, *va), oriented_normal(fb, to_b.u, to_b.v)) {
            let a = angle_deg(&na, &nb);
            g1.add(a, *pa, *t);
            g1u.add(a.min(180.0 - a), *pa, *t);
        }
    }
    let sides = (EdgeEnd { patch: s.a, side: None }, EdgeEnd { patch: s.b, side: None }, s.label.clone());
    EdgeReport::from_sums(sides, s.at.len(), length, [&gap_closest, &gap_matched, &g1, &g1u], None)
}

/// Pairs of trimming curves of different faces that lie on each other within `tol`
/// over at least `min_fraction` of the shorter one (sampled at `samples` points): the
/// shared edges of faces that carry no topology. Each edge is the shorter curve over
/// its matched part; its label joins both curves' labels. Curves that merely touch
/// another (less than `min_fraction` of the shorter on it) do not pair.
///
/// Each curve is sampled onto the curves at least as long as it that a bounding-box
/// index finds near it and keeps the one it lies on over the largest part (see
/// [`shared_boundaries`](crate::shared_boundaries)): near-linear in the number of
/// curves, and `k` coincident copies give `k − 1` edges.
pub fn shared_curves(curves: &[TrimCurve], tol: f64, samples: usize, min_fraction: f64) -> Vec<TrimEdge> {
    let samples = samples.max(3);
    let boxes: Vec<(Aabb, f64)> = curves
        .iter()
        .map(|c| {
            let d = c.curve.domain();
            let n = 32;
            let pts: Vec<Point3<f64>> =
                (0..=n).map(|i| c.curve.eval(d.start() + (d.end() - d.start()) * i as f64 / n as f64)).collect();
            (c.curve.bounding_box().inflated(tol), pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum())
        })
        .collect();
    let index = BoxIndex::new(boxes.iter().map(|b| &b.0));
    let mut out = Vec::new();
    for i in 0..curves.len() {
        let len = boxes[i].1;
        if len <= tol || !len.is_finite() {
            continue;
        }
        let candidates = index
            .overlapping(&boxes[i].0)
            .into_iter()
            .filter(|&j| curves[j].patch != curves[i].patch && (boxes[j].1, j) > (len, i));
        let best = best_partner(candidates, &curves[i].curve, |j| &curves[j].curve, tol, samples, min_fraction);
        let Some((j, (range, _))) = best else { continue };
        let (a, b) = if i < j { (&curves[i], &curves[j]) } else { (&curves[j], &curves[i]) };
        let label: Vec<EntityRef> = a.label.iter().chain(&b.label).copied().collect();
        let range = (range.0.min(range.1), range.0.max(range.1));
        out.push(TrimEdge { a: a.patch, b: b.patch, curve: curves[i].curve.clone(), range, label });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SeamReport;

    fn squares() -> (NurbsSurface, NurbsSurface) {
        let a = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
        let b = NurbsSurface::bilinear([[1., 0., 0.], [2., 0., 0.], [1., 1., 0.], [2., 1., 0.]]);
        (a, b)
    }

    #[test]
    fn failed_projections_are_not_measured_not_gaps() {
        let (a, b) = squares();
        let faces = [Face { surface: &a, reversed: false }, Face { surface: &b, reversed: false }];
        // The shared side x = 1 at 5 samples, the middle one's projection lost.
        let mut at: Vec<EdgeSample> =
            (0..5).map(|k| (k as f64 / 4.0, (1.0, k as f64 / 4.0), (0.0, k as f64 / 4.0))).collect();
        at[2].1 = (f64::NAN, f64::NAN);
        let s = EdgeSamples { a: 0, b: 1, label: Vec::new(), at };
        let r = measure_edge_samples(&faces, &s);
        assert_eq!(r.unmeasured, 1);
        assert!(r.gap_closest.max.is_finite() && r.gap_closest.max < 1e-12, "{:?}", r.gap_closest);
        // Every sample lost: the edge is "not measured", and counts in no total.
        let all = EdgeSamples { at: s.at.iter().map(|x| (x.0, (f64::NAN, f64::NAN), x.2)).collect(), ..s };
        let r = measure_edge_samples(&faces, &all);
        assert_eq!(r.unmeasured, 5);
        let report = SeamReport::new(vec![r]);
        assert!(report.table().contains("not measured"), "{}", report.table());
        assert_eq!(report.max_gap_closest, 0.0);
    }

    #[test]
    fn edge_points_on_the_face_are_all_measured() {
        let (a, b) = squares();
        let faces = [Face { surface: &a, reversed: false }, Face { surface: &b, reversed: false }];
        let curve = a.boundary(cadmorph_nurbs::Side::UMax);
        let d = curve.domain();
        let e = TrimEdge { a: 0, b: 1, curve, range: (*d.start(), *d.end()), label: Vec::new() };
        let r = measure_edge(&faces, &e, 20);
        assert_eq!(r.unmeasured, 0);
        assert!(r.gap_closest.max < 1e-12);
        assert!((r.length - 1.0).abs() < 1e-12);
    }
}
