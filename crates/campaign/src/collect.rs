//! `campaign status` and `campaign collect`: every variant's state and one table of all
//! reports (issue 16, Deliver 3).

use std::fmt::Write as _;

use serde::Serialize;

use crate::manifest::{num, Manifest};
use crate::report::Report;
use crate::run::variant_dir;
use crate::space::DesignSpace;

/// Where a variant stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    /// Not made (or made from other inputs, or an output is missing or changed).
    Pending,
    /// Made, seams within tolerance.
    Ok,
    /// Made, seams out of tolerance.
    OutOfTolerance,
    /// The morph or a writer failed.
    Failed,
}

/// Counts of [`State`]s.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Status {
    /// Variants planned.
    pub planned: usize,
    /// Not made yet.
    pub pending: usize,
    /// Made, within tolerance.
    pub ok: usize,
    /// Made, out of tolerance.
    pub out_of_tolerance: usize,
    /// Failed.
    pub failed: usize,
}

/// Each variant of the plan with its state and report.
pub fn states(space: &DesignSpace, manifest: &Manifest) -> Vec<(State, Option<Report>)> {
    manifest
        .variants
        .iter()
        .map(|v| {
            let dir = variant_dir(space, &v.id);
            match Report::read(&dir) {
                Some(r) if r.is_complete(&dir, &v.input_sha256) => {
                    let s = if r.status != "ok" {
                        State::Failed
                    } else if r.in_tolerance {
                        State::Ok
                    } else {
                        State::OutOfTolerance
                    };
                    (s, Some(r))
                }
                _ => (State::Pending, None),
            }
        })
        .collect()
}

/// The counts of [`states`].
pub fn status(space: &DesignSpace, manifest: &Manifest) -> Status {
    let mut s = Status { planned: manifest.variants.len(), ..Default::default() };
    for (state, _) in states(space, manifest) {
        match state {
            State::Pending => s.pending += 1,
            State::Ok => s.ok += 1,
            State::OutOfTolerance => s.out_of_tolerance += 1,
            State::Failed => s.failed += 1,
        }
    }
    s
}

/// One CSV of every variant: id, the parameter values, state, the seam maxima of the
/// written document, control points, rewritten faces and curves, volume and area, step
/// times and the error of failed ones. Pending variants have empty result columns.
pub fn collect(space: &DesignSpace, manifest: &Manifest) -> String {
    let mut s = String::from("id");
    for p in &manifest.parameters {
        let _ = write!(s, ",{p}");
    }
    s.push_str(
        ",state,in_tolerance,max_gap_closest,max_gap_matched,max_g1_angle_deg,max_c1_mismatch,control_points,\
         faces_rewritten,curves_rewritten,volume,area,morph_ms,write_ms,verify_ms,measure_ms,total_ms,error\n",
    );
    for (v, (state, report)) in manifest.variants.iter().zip(states(space, manifest)) {
        s.push_str(&v.id);
        for x in &v.values {
            let _ = write!(s, ",{}", num(*x));
        }
        let state_name =
            serde_json::to_value(state).ok().and_then(|x| x.as_str().map(str::to_owned)).unwrap_or_default();
        let _ = write!(s, ",{state_name}");
        match report {
            None => s.push_str(",,,,,,,,,,,,,,,,\n"),
            Some(r) => {
                let seam =
                    |f: fn(&crate::report::Seams) -> f64| r.seams.as_ref().map(|x| num(f(x))).unwrap_or_default();
                let measure = |f: fn(&crate::report::Measures) -> Option<f64>| {
                    r.measures.as_ref().and_then(f).map(num).unwrap_or_default()
                };
                let _ = write!(
                    s,
                    ",{},{},{},{},{},{},{},{},{},{},{:.3},{:.3},{:.3},{:.3},{:.3},",
                    r.in_tolerance,
                    seam(|x| x.max_gap_closest),
                    seam(|x| x.max_gap_matched),
                    seam(|x| x.max_g1_angle_deg),
                    seam(|x| x.max_c1_mismatch),
                    r.control_points,
                    r.faces_rewritten,
                    r.curves_rewritten,
                    measure(|m| m.volume),
                    measure(|m| m.area),
                    r.timings.morph_ms,
                    r.timings.write_ms,
                    r.timings.verify_ms,
                    r.timings.measure_ms,
                    r.timings.total_ms
                );
                if let Some(e) = &r.error {
                    let _ = write!(s, "\"{}\"", e.replace('"', "\"\""));
                }
                s.push('\n');
            }
        }
    }
    s
}
