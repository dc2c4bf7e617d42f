//! A seam report as the CLI shows it: the table with its legend, the JSON form, and the
//! pass/fail check of `seams --tol --angle-tol`. Faces are named the one way of
//! [`crate::faces`]; lengths and gaps are in the model's unit, named in words.

use std::fmt::Write as _;

use cadmorph::brep::Face;
use cadmorph::seam::{EdgeEnd, EdgeReport, SeamReport, Stat, SHARP_EDGE_DEG};
use serde_json::{json, Value};

/// Tolerances an edge must meet: the closest-point gap (model units) and the normal angle
/// across smooth edges (degrees). Unset tolerances are not checked.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Check {
    /// Largest closest-point gap.
    pub tol: Option<f64>,
    /// Largest G1 angle over smooth (not sharp) edges.
    pub angle_tol: Option<f64>,
}

impl Check {
    /// Whether any tolerance is set.
    pub fn is_set(&self) -> bool {
        self.tol.is_some() || self.angle_tol.is_some()
    }

    /// What edge `e` fails: `"gap"`, `"angle"` (empty: it passes or nothing is checked).
    pub fn failures(&self, e: &EdgeReport) -> Vec<&'static str> {
        let mut out = Vec::new();
        // A NaN measurement fails too.
        if self.tol.is_some_and(|t| e.gap_closest.max.is_nan() || e.gap_closest.max > t) {
            out.push("gap");
        }
        if self.angle_tol.is_some_and(|a| !e.sharp && (e.g1_angle_deg.max.is_nan() || e.g1_angle_deg.max > a)) {
            out.push("angle");
        }
        out
    }
}

fn side_name(end: &EdgeEnd) -> &'static str {
    use cadmorph::nurbs::Side;
    match end.side {
        Some(Side::UMin) => "u_min",
        Some(Side::UMax) => "u_max",
        Some(Side::VMin) => "v_min",
        Some(Side::VMax) => "v_max",
        None => "",
    }
}

/// `1 (DE 7) u_max`: the face of one side of an edge, and its iso-boundary.
pub fn end_label(end: &EdgeEnd, faces: &[Face]) -> String {
    let face =
        faces.get(end.patch).map_or_else(|| end.patch.to_string(), |f| crate::faces::label(end.patch, &f.entity));
    match side_name(end) {
        "" => face,
        side => format!("{face} {side}"),
    }
}

/// The edge's own entity when the file has one, else `iso boundary`.
fn edge_entity(e: &EdgeReport) -> String {
    if e.edge.is_empty() {
        "iso boundary".to_owned()
    } else {
        e.edge.iter().map(ToString::to_string).collect::<Vec<_>>().join(" / ")
    }
}

/// `edge 1 (face 1 (DE 7) u_max | face 2 (DE 11) u_min)`, or with the edge's entity.
pub fn edge_name(index: usize, e: &EdgeReport, faces: &[Face]) -> String {
    let ends = format!("face {} | face {}", end_label(&e.a, faces), end_label(&e.b, faces));
    if e.edge.is_empty() {
        format!("edge {index} ({ends})")
    } else {
        format!("edge {index}, {} ({ends})", edge_entity(e))
    }
}

/// The table and the totals. `unit` is the unit in words.
pub fn table(r: &SeamReport, faces: &[Face], unit: &str, check: &Check) -> String {
    let mut out = String::new();
    let ends: Vec<(String, String)> =
        r.edges.iter().map(|e| (end_label(&e.a, faces), end_label(&e.b, faces))).collect();
    let wa = ends.iter().map(|(a, _)| a.len()).chain([6]).max().unwrap_or(6);
    let wb = ends.iter().map(|(_, b)| b.len()).chain([6]).max().unwrap_or(6);
    let _ = write!(
        out,
        "{:>4}  {:<wa$}  {:<wb$}  {:>10} {:>11} {:>11} {:>11} {:>10} {:>10}  {:<13}",
        "edge",
        "face a",
        "face b",
        "length",
        "gap closest",
        "gap matched",
        "gap mean",
        "G1 angle",
        "C1 deriv",
        "edge entity"
    );
    let _ = writeln!(out, "{}", if check.is_set() { "  check" } else { "" });
    for (i, (e, (a, b))) in r.edges.iter().zip(&ends).enumerate() {
        let c1 = e.c1_mismatch.map_or_else(|| "-".to_owned(), |c| format!("{:.3e}", c.max));
        let g1 = format!("{:.3e}{}", e.g1_angle_deg.max, if e.sharp { " S" } else { "  " });
        let _ = write!(
            out,
            "{i:>4}  {a:<wa$}  {b:<wb$}  {:>10.4} {:>11.4e} {:>11.4e} {:>11.4e} {g1:>10} {c1:>10}  {:<13}",
            e.length,
            e.gap_closest.max,
            e.gap_matched.max,
            e.gap_closest.mean,
            edge_entity(e),
        );
        if check.is_set() {
            let f = check.failures(e);
            let _ =
                write!(out, "  {}", if f.is_empty() { "ok".to_owned() } else { format!("FAIL ({})", f.join(", ")) });
        }
        let _ = writeln!(out);
    }
    let _ = writeln!(
        out,
        "{} shared edges ({} sharp); max gap closest {:.4e}, matched {:.4e} {unit}; max G1 angle {:.4e} degrees (smooth edges)",
        r.edges.len(),
        r.sharp_edges,
        r.max_gap_closest,
        r.max_gap_matched,
        r.max_g1_angle_deg,
    );
    out
}

/// What the columns of [`table`] mean, and the check in force.
pub fn legend(unit: &str, check: &Check) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "\nface a, face b: the two faces, as index (entity) in file order (the numbering of `cadmorph info`),\n\
         \x20 and the iso-boundary (u_min, u_max, v_min, v_max) when the edge is one.\n\
         length, gap closest, gap matched, gap mean: {unit}. gap closest: the crack width (each edge point\n\
         \x20 to the closest point of the other face, both ways, largest); gap matched: between points of\n\
         \x20 equal edge parameter (what a mesher pairing boundary nodes sees); gap mean: mean of gap closest.\n\
         G1 angle: largest angle between the two faces' normals, degrees; S: a sharp edge (faces meet at\n\
         \x20 more than {SHARP_EDGE_DEG} degrees, a crease by design), left out of the G1 totals and of --angle-tol.\n\
         C1 deriv: |d_a + d_b| / max(|d_a|, |d_b|) of the cross-boundary derivatives (a ratio, no unit): 0 when\n\
         \x20 the two parametrisations also join C1; on a G1 edge a nonzero value only means the faces' parameter\n\
         \x20 speeds differ across it, not a crack or a kink. '-': an edge of trimmed faces (no such derivative).\n\
         edge entity: the edge in the file (STEP EDGE_CURVE, IGES 504/trim curve), or iso boundary.\n"
    );
    if let Some(t) = check.tol {
        let _ = writeln!(out, "check: an edge fails with gap closest above {t:e} {unit} (--tol)");
    }
    if let Some(a) = check.angle_tol {
        let _ = writeln!(out, "check: a smooth edge fails with a G1 angle above {a} degrees (--angle-tol)");
    }
    out
}

fn stat(s: &Stat) -> Value {
    json!({ "max": s.max, "mean": s.mean, "at": s.at, "t": s.t })
}

fn end_json(end: &EdgeEnd, faces: &[Face]) -> Value {
    let face = faces.get(end.patch).map_or_else(
        || json!({ "index": end.patch, "entity": null, "surface": null }),
        |f| crate::faces::json(end.patch, &f.entity, &f.surface_entity),
    );
    let side = match side_name(end) {
        "" => Value::Null,
        s => Value::String(s.to_owned()),
    };
    json!({ "face": face, "side": side })
}

/// The report in the JSON form of the schema's `seam_report`.
pub fn json(r: &SeamReport, faces: &[Face], check: &Check) -> Value {
    let edges: Vec<Value> = r
        .edges
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let failed = check.failures(e);
            json!({
                "index": i,
                "kind": if e.edge.is_empty() { "iso_boundary" } else { "topology" },
                "a": end_json(&e.a, faces),
                "b": end_json(&e.b, faces),
                "edge": e.edge.iter().map(crate::faces::entity).collect::<Vec<_>>(),
                "samples": e.samples,
                "length": e.length,
                "gap_closest": stat(&e.gap_closest),
                "gap_matched": stat(&e.gap_matched),
                "g1_angle_deg": stat(&e.g1_angle_deg),
                "g1_angle_unoriented_deg": stat(&e.g1_angle_unoriented_deg),
                "c1_derivative_mismatch": e.c1_mismatch.as_ref().map(stat),
                "sharp": e.sharp,
                "pass": if check.is_set() { Value::Bool(failed.is_empty()) } else { Value::Null },
                "failed": failed,
            })
        })
        .collect();
    let failed = r.edges.iter().filter(|e| !check.failures(e).is_empty()).count();
    json!({
        "edges": edges,
        "summary": {
            "edges": r.edges.len(),
            "sharp_edges": r.sharp_edges,
            "max_gap_closest": r.max_gap_closest,
            "max_gap_matched": r.max_gap_matched,
            "max_g1_angle_deg": r.max_g1_angle_deg,
            "max_g1_angle_unoriented_deg": r.max_g1_angle_unoriented_deg,
            "max_c1_derivative_mismatch": r.max_c1_mismatch,
        },
        "check": if check.is_set() {
            json!({ "tol": check.tol, "angle_tol_deg": check.angle_tol, "pass": failed == 0, "failed_edges": failed })
        } else {
            Value::Null
        },
    })
}
