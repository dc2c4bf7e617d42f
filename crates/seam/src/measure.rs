//! Dense sampling of shared edges: C0 gap (two ways), G1 normal angle, C1 mismatch.

use cadmorph_brep::EntityRef;
use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{NurbsSurface, Side, Surface, SurfaceProject};
use serde::Serialize;

use crate::{SharedBoundary, SideRef};

/// Edges whose faces meet at more than this normal angle (unoriented, degrees) are
/// design creases (box edges, chines), not seams that should be smooth: they are
/// reported, with [`EdgeReport::sharp`] set, but kept out of the G1 totals.
pub const SHARP_EDGE_DEG: f64 = 10.0;

/// One side of a measured edge: the patch, and its iso-boundary when the edge is one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct EdgeEnd {
    /// Index of the patch.
    pub patch: usize,
    /// The iso-boundary, for edges found as coinciding iso-boundaries; `None` for
    /// edges from the file's topology or from trimming curves.
    #[serde(serialize_with = "side_name")]
    pub side: Option<Side>,
}

impl From<SideRef> for EdgeEnd {
    fn from(s: SideRef) -> Self {
        Self { patch: s.patch, side: Some(s.side) }
    }
}

fn side_name<S: serde::Serializer>(side: &Option<Side>, s: S) -> Result<S::Ok, S::Error> {
    match side {
        Some(side) => s.serialize_str(side_label(*side)),
        None => s.serialize_none(),
    }
}

pub(crate) fn side_label(side: Side) -> &'static str {
    match side {
        Side::UMin => "u_min",
        Side::UMax => "u_max",
        Side::VMin => "v_min",
        Side::VMax => "v_max",
    }
}

/// A face for seam measurement: its surface and whether the face's orientation is
/// opposite to the surface's (`S_u × S_v` points inward).
#[derive(Debug, Clone, Copy)]
pub struct Face<'a> {
    /// The surface, in world coordinates.
    pub surface: &'a NurbsSurface,
    /// Face orientation reversed relative to the surface normal.
    pub reversed: bool,
}

/// Largest and mean value of one quantity along an edge, and where the largest is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stat {
    /// Largest value.
    pub max: f64,
    /// Mean over the samples.
    pub mean: f64,
    /// World position of the largest value (on the first face).
    pub at: [f64; 3],
    /// Parameter on the first face's boundary curve where the largest value is.
    pub t: f64,
}

/// What one shared edge measures.
///
/// - `gap_closest`: distance from the edge point on one face to the other face (the
///   closest point), taken both ways and the larger kept: the geometric crack width.
/// - `gap_matched`: distance between the two faces' points at the same edge parameter
///   (the two boundary curves mapped linearly onto each other): what a mesher that
///   pairs boundary nodes by parameter sees.
/// - `g1_angle_deg`: angle between the faces' normals (each flipped by its face
///   orientation), at the closest-point pair; `g1_angle_unoriented_deg` ignores the
///   orientation (`min(a, 180° − a)`), for faces without a consistent orientation.
/// - `c1_mismatch`: `|d_a + d_b| / max(|d_a|, |d_b|)` with `d` the outward
///   cross-boundary derivative of each side (`±S_u` or `±S_v`): 0 for a C1 join of
///   two iso boundaries with matching parameter speed; `None` where either side is not
///   an iso boundary (trimmed faces), since there is no cross-boundary derivative then.
/// - `sharp`: the faces meet at more than [`SHARP_EDGE_DEG`], a crease by design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgeReport {
    /// First side.
    pub a: EdgeEnd,
    /// Second side.
    pub b: EdgeEnd,
    /// The edge's entity in the file (`#id` in STEP, `DE n` in IGES) when the edge comes
    /// from the file's topology or trims.
    pub edge: Vec<EntityRef>,
    /// Samples taken.
    pub samples: usize,
    /// Polyline length of the sampled edge on the first face.
    pub length: f64,
    /// See the type docs.
    pub gap_closest: Stat,
    /// See the type docs.
    pub gap_matched: Stat,
    /// See the type docs.
    pub g1_angle_deg: Stat,
    /// See the type docs.
    pub g1_angle_unoriented_deg: Stat,
    /// See the type docs.
    pub c1_mismatch: Option<Stat>,
    /// See the type docs.
    pub sharp: bool,
    /// Samples where the edge point could not be taken to a face (the closest-point
    /// search ended farther than a known point of the face): left out of every number
    /// above, never reported as a gap. When all are, the edge is "not measured".
    pub unmeasured: usize,
}

/// Every shared edge of a model, with the totals.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeamReport {
    /// One entry per shared edge.
    pub edges: Vec<EdgeReport>,
    /// Largest `gap_closest` over all edges (0 with no edges).
    pub max_gap_closest: f64,
    /// Largest `gap_matched`.
    pub max_gap_matched: f64,
    /// Largest oriented normal angle over the smooth (not sharp) edges, degrees.
    pub max_g1_angle_deg: f64,
    /// Largest unoriented normal angle over the smooth edges, degrees.
    pub max_g1_angle_unoriented_deg: f64,
    /// Largest relative C1 mismatch.
    pub max_c1_mismatch: f64,
    /// Edges whose faces meet at a crease (more than [`SHARP_EDGE_DEG`]).
    pub sharp_edges: usize,
}

pub(crate) struct Acc {
    max: f64,
    sum: f64,
    pub(crate) n: usize,
    at: Point3<f64>,
    t: f64,
}

impl Acc {
    pub(crate) fn new() -> Self {
        Self { max: 0.0, sum: 0.0, n: 0, at: Point3::origin(), t: f64::NAN }
    }
    pub(crate) fn add(&mut self, value: f64, at: Point3<f64>, t: f64) {
        if value.is_nan() {
            return;
        }
        self.sum += value;
        self.n += 1;
        if value >= self.max || self.t.is_nan() {
            self.max = value;
            self.at = at;
            self.t = t;
        }
    }
    pub(crate) fn stat(&self) -> Stat {
        Stat {
            max: self.max,
            mean: if self.n == 0 { 0.0 } else { self.sum / self.n as f64 },
            at: [self.at.x, self.at.y, self.at.z],
            t: self.t,
        }
    }
}

/// `(u, v)` of parameter `t` along a side's boundary curve.
pub(crate) fn side_uv(s: &NurbsSurface, side: Side, t: f64) -> (f64, f64) {
    let (ud, vd) = s.domain();
    match side {
        Side::UMin => (*ud.start(), t),
        Side::UMax => (*ud.end(), t),
        Side::VMin => (t, *vd.start()),
        Side::VMax => (t, *vd.end()),
    }
}

/// The outward cross-boundary derivative at `(u, v)` on `side`.
fn outward(s: &NurbsSurface, side: Side, u: f64, v: f64) -> Vector3<f64> {
    let d = s.eval_d1(u, v);
    match side {
        Side::UMin => -d.du,
        Side::UMax => d.du,
        Side::VMin => -d.dv,
        Side::VMax => d.dv,
    }
}

pub(crate) fn oriented_normal(f: &Face, u: f64, v: f64) -> Option<Vector3<f64>> {
    let n = f.surface.normal(u, v)?.into_inner();
    Some(if f.reversed { -n } else { n })
}

pub(crate) fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    // atan2 of |a × b| and a · b stays accurate near 0° and 180°, where acos does not.
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

/// Measures one shared boundary between `faces[edge.a.patch]` and `faces[edge.b.patch]`
/// at `samples` points (ends included).
///
/// # Tolerance
///
/// The closest-point projections run to `ptol = 1e-12 × edge length`, far below any gap
/// worth reporting; the sampled maxima converge like `O(1/samples²)` for smooth gaps.
pub fn measure_boundary(faces: &[Face], edge: &SharedBoundary, samples: usize) -> EdgeReport {
    let samples = samples.max(2);
    let (fa, fb) = (&faces[edge.a.patch], &faces[edge.b.patch]);
    let (sa, sb) = (fa.surface, fb.surface);
    let mut gap_closest = Acc::new();
    let mut gap_matched = Acc::new();
    let mut g1 = Acc::new();
    let mut g1u = Acc::new();
    let mut c1 = Acc::new();
    let mut length = 0.0;
    let mut prev: Option<Point3<f64>> = None;
    let first_pass: Vec<(f64, Point3<f64>)> = (0..samples)
        .map(|k| {
            let t = edge.a_range.0 + (edge.a_range.1 - edge.a_range.0) * k as f64 / (samples - 1) as f64;
            let (u, v) = side_uv(sa, edge.a.side, t);
            (t, sa.eval(u, v))
        })
        .collect();
    let scale = first_pass.windows(2).map(|w| (w[1].1 - w[0].1).norm()).sum::<f64>().max(f64::MIN_POSITIVE);
    let ptol = 1e-12 * scale;
    for &(t, pa) in &first_pass {
        if let Some(q) = prev {
            length += (pa - q).norm();
        }
        prev = Some(pa);
        let (ua, va) = side_uv(sa, edge.a.side, t);
        let tb = edge.b_param(t);
        let (ub, vb) = side_uv(sb, edge.b.side, tb);
        let pb = sb.eval(ub, vb);
        gap_matched.add((pa - pb).norm(), pa, t);
        // Closest point both ways: Newton from the parameter-matched point, which lies
        // on the right sheet of the other face; the global search (sampling the whole
        // face) only where the local one ends farther than the matched point itself.
        let local = |s: &NurbsSurface, p: &Point3<f64>, start: (f64, f64), matched: f64| {
            let pr = s.project_from(p, start, ptol);
            if pr.distance_sq.sqrt() <= matched * (1.0 + 1e-9) {
                pr
            } else {
                s.project(p, ptol)
            }
        };
        let matched = (pa - pb).norm();
        let on_b = local(sb, &pa, (ub, vb), matched);
        let on_a = local(sa, &pb, (ua, va), matched);
        // Each side's matched point lies on the other face, so no closest distance can
        // exceed the matched one: a projection that says so has lost its way.
        let closest = on_b.distance_sq.sqrt().min(matched).max(on_a.distance_sq.sqrt().min(matched));
        gap_closest.add(closest, pa, t);
        if let (Some(na), Some(nb)) = (oriented_normal(fa, ua, va), oriented_normal(fb, on_b.u, on_b.v)) {
            let a = angle_deg(&na, &nb);
            g1.add(a, pa, t);
            g1u.add(a.min(180.0 - a), pa, t);
        }
        let (da, db) = (outward(sa, edge.a.side, ua, va), outward(sb, edge.b.side, ub, vb));
        let denom = da.norm().max(db.norm());
        if denom > 0.0 {
            c1.add((da + db).norm() / denom, pa, t);
        }
    }
    let c1_mismatch = (c1.n > 0).then(|| c1.stat());
    let sides = (edge.a.into(), edge.b.into(), Vec::new());
    EdgeReport::from_sums(sides, samples, length, [&gap_closest, &gap_matched, &g1, &g1u], c1_mismatch)
}

impl EdgeReport {
    /// The report of an edge between `sides` (with its file label) from the sums of its
    /// samples: closest gap, matched gap, oriented and unoriented normal angle.
    pub(crate) fn from_sums(
        (a, b, edge): (EdgeEnd, EdgeEnd, Vec<EntityRef>),
        samples: usize,
        length: f64,
        [gap_closest, gap_matched, g1, g1u]: [&Acc; 4],
        c1_mismatch: Option<Stat>,
    ) -> Self {
        let g1_angle_unoriented_deg = g1u.stat();
        let unmeasured = samples.saturating_sub(gap_matched.n);
        Self {
            unmeasured,
            a,
            b,
            edge,
            samples,
            length,
            gap_closest: gap_closest.stat(),
            gap_matched: gap_matched.stat(),
            g1_angle_deg: g1.stat(),
            sharp: g1_angle_unoriented_deg.max > SHARP_EDGE_DEG,
            g1_angle_unoriented_deg,
            c1_mismatch,
        }
    }
}

impl SeamReport {
    /// Collects edge reports and their totals.
    pub fn new(edges: Vec<EdgeReport>) -> Self {
        // An edge none of whose samples could be measured has no numbers to count.
        let max =
            |f: fn(&EdgeReport) -> f64| edges.iter().filter(|e| e.unmeasured < e.samples).map(f).fold(0.0, f64::max);
        let smooth = |f: fn(&EdgeReport) -> f64| {
            edges.iter().filter(|e| !e.sharp && e.unmeasured < e.samples).map(f).fold(0.0, f64::max)
        };
        Self {
            max_gap_closest: max(|e| e.gap_closest.max),
            max_gap_matched: max(|e| e.gap_matched.max),
            max_g1_angle_deg: smooth(|e| e.g1_angle_deg.max),
            max_g1_angle_unoriented_deg: smooth(|e| e.g1_angle_unoriented_deg.max),
            max_c1_mismatch: max(|e| e.c1_mismatch.map_or(0.0, |s| s.max)),
            sharp_edges: edges.iter().filter(|e| e.sharp).count(),
            edges,
        }
    }

    /// A table for people: one row per edge, then the totals. Sides are `patch:u0`
    /// (iso boundaries) or `patch` (topology edges, named in the last column); sharp
    /// edges are marked `*` after their angle.
    pub fn table(&self) -> String {
        use std::fmt::Write;
        let side = |s: &EdgeEnd| match s.side {
            Some(side) => {
                let n = match side {
                    Side::UMin => "u0",
                    Side::UMax => "u1",
                    Side::VMin => "v0",
                    Side::VMax => "v1",
                };
                format!("{}:{n}", s.patch)
            }
            None => s.patch.to_string(),
        };
        let mut out = String::new();
        let _ = writeln!(
            out,
            "{:<7} {:<7} {:>10} {:>12} {:>12} {:>12} {:>11} {:>10}  edge",
            "face a", "face b", "length", "gap closest", "gap matched", "gap mean", "G1 (deg)", "C1 rel"
        );
        for e in &self.edges {
            let labels = e.edge.iter().map(ToString::to_string).collect::<Vec<_>>().join(" / ");
            if e.unmeasured >= e.samples {
                let _ = writeln!(
                    out,
                    "{:<7} {:<7} {:>10} {:>12}  {}  (the edge's points could not be taken to its faces)",
                    side(&e.a),
                    side(&e.b),
                    "-",
                    "not measured",
                    labels
                );
                continue;
            }
            let labels = if e.unmeasured > 0 {
                format!("{labels} ({} of {} samples not measured)", e.unmeasured, e.samples)
            } else {
                labels
            };
            let c1 = e.c1_mismatch.map_or_else(|| "-".to_owned(), |c| format!("{:.3e}", c.max));
            let _ = writeln!(
                out,
                "{:<7} {:<7} {:>10.4} {:>12.4e} {:>12.4e} {:>12.4e} {:>10.4e}{} {:>10}  {}",
                side(&e.a),
                side(&e.b),
                e.length,
                e.gap_closest.max,
                e.gap_matched.max,
                e.gap_closest.mean,
                e.g1_angle_deg.max,
                if e.sharp { '*' } else { ' ' },
                c1,
                labels
            );
        }
        let _ = writeln!(
            out,
            "{} shared edges ({} sharp, *); max gap closest {:.4e}, matched {:.4e}; max G1 {:.4e} deg (smooth edges); max C1 {:.3e}",
            self.edges.len(),
            self.sharp_edges,
            self.max_gap_closest,
            self.max_gap_matched,
            self.max_g1_angle_deg,
            self.max_c1_mismatch
        );
        out
    }
}
