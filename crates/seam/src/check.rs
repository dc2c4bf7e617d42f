//! Pass/fail of a morphed model's seams relative to the input's: each edge is held to
//! the gap and angle it had before, plus the tolerances, so that a defect the input
//! already had is reported as such and never counts as the morph's failure.

use serde::Serialize;

use crate::{EdgeReport, SeamReport};

/// One edge of [`SeamCheck`]: the edge as measured after the morph, matched to the same
/// edge before it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgeCheck {
    /// Index of the edge in the "after" report.
    pub after: usize,
    /// Index of the same edge in the "before" report (`None`: the input had no such edge,
    /// held to the tolerances alone).
    pub before: Option<usize>,
    /// Closest-point gap before the morph (0 when there was no such edge).
    pub gap_before: f64,
    /// Closest-point gap after.
    pub gap_after: f64,
    /// Matched gap before.
    pub matched_before: f64,
    /// Matched gap after.
    pub matched_after: f64,
    /// Unoriented normal angle before, degrees.
    pub angle_before_deg: f64,
    /// Unoriented normal angle after, degrees.
    pub angle_after_deg: f64,
    /// The input already had a gap above the gap tolerance (closest or matched) or,
    /// on a smooth edge, an angle above the angle tolerance: a defect of the input,
    /// that `--repair` closes where the edge is a shared iso boundary.
    pub input_defect: bool,
    /// Both gaps after are within `max(before, 0) + tol` and, on a smooth edge, the angle
    /// within `before + angle_tol`.
    pub pass: bool,
}

/// Every edge of a morphed model checked against the input ([`SeamCheck::new`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeamCheck {
    /// Gap tolerance, model units.
    pub tol: f64,
    /// Angle tolerance, degrees.
    pub angle_tol_deg: f64,
    /// One entry per edge of the "after" report.
    pub edges: Vec<EdgeCheck>,
    /// Edges that failed.
    pub failed: usize,
    /// Edges whose input was already defective.
    pub input_defects: usize,
}

fn same_sides(a: &EdgeReport, b: &EdgeReport) -> bool {
    (a.a == b.a && a.b == b.b) || (a.a == b.b && a.b == b.a)
}

impl SeamCheck {
    /// Matches each edge of `after` to the edge of `before` with the same two sides (face
    /// and iso boundary) and the same file entities, else the same two sides in order,
    /// and holds it to `max(gap before, 0) + tol` (closest and matched gaps) and, for
    /// edges that were smooth before (not [`sharp`](EdgeReport::sharp)), to
    /// `angle before + angle_tol_deg`. A crease keeps no angle bound here: its angle is
    /// what the morph makes of it.
    pub fn new(before: &SeamReport, after: &SeamReport, tol: f64, angle_tol_deg: f64) -> Self {
        let mut used = vec![false; before.edges.len()];
        let mut pick = |e: &EdgeReport, exact: bool| {
            let i = before
                .edges
                .iter()
                .enumerate()
                .position(|(i, b)| !used[i] && same_sides(b, e) && (!exact || b.edge == e.edge))?;
            used[i] = true;
            Some(i)
        };
        // Exact matches first, so that an edge whose entity changed takes what is left.
        let mut matched: Vec<Option<usize>> = after.edges.iter().map(|e| pick(e, true)).collect();
        for (m, e) in matched.iter_mut().zip(&after.edges) {
            if m.is_none() {
                *m = pick(e, false);
            }
        }
        let edges: Vec<EdgeCheck> = after
            .edges
            .iter()
            .zip(matched)
            .enumerate()
            .map(|(i, (e, m))| {
                let b = m.map(|j| &before.edges[j]);
                let gap_before = b.map_or(0.0, |b| b.gap_closest.max);
                let matched_before = b.map_or(0.0, |b| b.gap_matched.max);
                let angle_before_deg = b.map_or(0.0, |b| b.g1_angle_unoriented_deg.max);
                let sharp = b.map_or(e.sharp, |b| b.sharp);
                let input_defect =
                    gap_before > tol || matched_before > tol || (!sharp && angle_before_deg > angle_tol_deg);
                let within = |after: f64, before: f64| after.is_finite() && after <= before.max(0.0) + tol;
                let angle_after_deg = e.g1_angle_unoriented_deg.max;
                let pass = within(e.gap_closest.max, gap_before)
                    && within(e.gap_matched.max, matched_before)
                    && (sharp || angle_after_deg <= angle_before_deg + angle_tol_deg);
                EdgeCheck {
                    after: i,
                    before: m,
                    gap_before,
                    gap_after: e.gap_closest.max,
                    matched_before,
                    matched_after: e.gap_matched.max,
                    angle_before_deg,
                    angle_after_deg,
                    input_defect,
                    pass,
                }
            })
            .collect();
        Self {
            tol,
            angle_tol_deg,
            failed: edges.iter().filter(|e| !e.pass).count(),
            input_defects: edges.iter().filter(|e| e.input_defect).count(),
            edges,
        }
    }

    /// Lines for people: the input's defects (with the `--repair` hint) and the failed
    /// edges, each naming the edge as the "after" table does (`row n`, faces, entity).
    pub fn summary(&self, after: &SeamReport) -> String {
        use std::fmt::Write;
        let name = |c: &EdgeCheck| {
            let e = &after.edges[c.after];
            let side = |s: &crate::EdgeEnd| match s.side {
                Some(side) => format!("{}:{}", s.patch, crate::measure::side_label(side)),
                None => s.patch.to_string(),
            };
            let label = e.edge.iter().map(ToString::to_string).collect::<Vec<_>>().join(" / ");
            format!(
                "edge {} ({} - {}{}{})",
                c.after,
                side(&e.a),
                side(&e.b),
                if label.is_empty() { "" } else { ", " },
                label
            )
        };
        let mut out = String::new();
        for c in self.edges.iter().filter(|c| c.input_defect) {
            let _ = writeln!(
                out,
                "pre-existing defect in the input, {}: gap {:.4e} closest, {:.4e} matched, G1 {:.4e} deg before the \
                 morph; held to that (+ {:.1e}), not refined; --repair closes a shared iso edge",
                name(c),
                c.gap_before,
                c.matched_before,
                c.angle_before_deg,
                self.tol
            );
        }
        for c in self.edges.iter().filter(|c| !c.pass) {
            let _ = writeln!(
                out,
                "FAILED {}: gap {:.4e} closest / {:.4e} matched after (before {:.4e} / {:.4e}), G1 {:.4e} deg (before \
                 {:.4e}); allowed + {:.1e} and + {} deg",
                name(c),
                c.gap_after,
                c.matched_after,
                c.gap_before,
                c.matched_before,
                c.angle_after_deg,
                c.angle_before_deg,
                self.tol,
                self.angle_tol_deg
            );
        }
        out
    }
}
