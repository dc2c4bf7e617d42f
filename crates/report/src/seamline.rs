//! The seam edges of a model as polylines, with the gap and G1 angle at each vertex.
//!
//! The numbers of each edge (largest and mean gap, angle, where) are the seam report's
//! ([`cadmorph_seam::EdgeReport`]); this module adds the local values along the edge,
//! so a view can colour the edge where it opens rather than as a whole. Each vertex is
//! a point of the edge on its first face; its gap is the distance to the second face
//! (the closest point, at most the parameter-matched distance), its angle the one
//! between the two faces' oriented normals there.

use cadmorph_brep::CadDocument;
use cadmorph_model::Model;
use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{Curve, NurbsSurface, Side, Surface, SurfaceProject};
use cadmorph_seam::{EdgeReport, SeamReport};
use serde::Serialize;

/// Vertices per seam polyline.
pub const SEAM_VERTICES: usize = 64;

/// One shared edge: where it runs and how it measures.
#[derive(Debug, Clone, Serialize)]
pub struct SeamLine {
    /// The two faces' patch indices.
    pub patches: [usize; 2],
    /// The two faces' entities (`DE 3`, `#12`).
    pub faces: [String; 2],
    /// The edge's own entities in the file, if it has any.
    pub edge: Vec<String>,
    /// Polyline vertices on the first face, model units.
    pub points: Vec<[f64; 3]>,
    /// Gap at each vertex, model units.
    pub gap: Vec<f64>,
    /// Normal angle at each vertex, degrees (oriented; unoriented for sharp edges).
    pub angle_deg: Vec<f64>,
    /// The seam report's numbers for the edge.
    pub report: EdgeReport,
}

fn side_uv(s: &NurbsSurface, side: Side, t: f64) -> (f64, f64) {
    let (ud, vd) = s.domain();
    match side {
        Side::UMin => (*ud.start(), t),
        Side::UMax => (*ud.end(), t),
        Side::VMin => (t, *vd.start()),
        Side::VMax => (t, *vd.end()),
    }
}

fn normal(s: &NurbsSurface, reversed: bool, u: f64, v: f64) -> Option<Vector3<f64>> {
    let n = s.normal(u, v)?.into_inner();
    Some(if reversed { -n } else { n })
}

fn angle(a: Option<Vector3<f64>>, b: Option<Vector3<f64>>, sharp: bool) -> f64 {
    match (a, b) {
        (Some(a), Some(b)) => {
            let d = a.cross(&b).norm().atan2(a.dot(&b)).to_degrees();
            if sharp {
                d.min(180.0 - d)
            } else {
                d
            }
        }
        _ => f64::NAN,
    }
}

fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// The seam lines of `model`, one per edge of `report` (which must be `model`'s seam
/// report: iso-boundary edges first, then trim edges, as [`Model::seams`] gives them).
/// Edges the report has beyond the model's are left out.
pub fn seam_lines<D: CadDocument>(model: &Model<D>, report: &SeamReport) -> Vec<SeamLine> {
    let patches = model.patches();
    let name = |i: usize| patches.get(i).map_or_else(|| format!("face {i}"), |p| p.entity.to_string());
    let n = SEAM_VERTICES;
    let iso = model.edges().iter().map(Some).chain(std::iter::repeat(None));
    let trims = model.trim_edges();
    let mut out = Vec::with_capacity(report.edges.len());
    for (k, (e, iso)) in report.edges.iter().zip(iso).enumerate() {
        let (mut points, mut gap, mut angle_deg) = (Vec::new(), Vec::new(), Vec::new());
        let (pa, pb) = match iso {
            Some(b) => {
                let (fa, fb) = (&patches[b.a.patch], &patches[b.b.patch]);
                let (sa, sb) = (&fa.surface, &fb.surface);
                for i in 0..n {
                    let t = b.a_range.0 + (b.a_range.1 - b.a_range.0) * i as f64 / (n - 1) as f64;
                    let (ua, va) = side_uv(sa, b.a.side, t);
                    let (ub, vb) = side_uv(sb, b.b.side, b.b_param(t));
                    let p = sa.eval(ua, va);
                    let matched = (p - sb.eval(ub, vb)).norm();
                    let pr = sb.project_from(&p, (ub, vb), 1e-12 * model.size().max(f64::MIN_POSITIVE));
                    let close = pr.distance_sq.sqrt().min(matched);
                    let (uc, vc) = if pr.distance_sq.sqrt() <= matched { (pr.u, pr.v) } else { (ub, vb) };
                    points.push(arr(&p));
                    gap.push(close);
                    angle_deg.push(angle(normal(sa, fa.reversed, ua, va), normal(sb, fb.reversed, uc, vc), e.sharp));
                }
                (b.a.patch, b.b.patch)
            }
            None => {
                let Some(t) = trims.get(k - model.edges().len()) else { break };
                let (fa, fb) = (&patches[t.a], &patches[t.b]);
                let tol = 1e-12 * model.size().max(f64::MIN_POSITIVE);
                for s in t.params(n) {
                    let c = t.curve.eval(s);
                    let on_a = fa.surface.project(&c, tol);
                    let on_b = fb.surface.project(&on_a.point, tol);
                    points.push(arr(&on_a.point));
                    gap.push(on_b.distance_sq.sqrt());
                    angle_deg.push(angle(
                        normal(&fa.surface, fa.reversed, on_a.u, on_a.v),
                        normal(&fb.surface, fb.reversed, on_b.u, on_b.v),
                        e.sharp,
                    ));
                }
                (t.a, t.b)
            }
        };
        out.push(SeamLine {
            patches: [pa, pb],
            faces: [name(pa), name(pb)],
            edge: e.edge.iter().map(|r| r.to_string()).collect(),
            points,
            gap,
            angle_deg,
            report: e.clone(),
        });
    }
    out
}
