//! The JSON document of `morph --json` (schema `cadmorph.morph/1`): what was read and
//! written, the parameters' kind, the unit, the time taken, and the seams before and
//! after in the form of `seams --json`.

use std::path::Path;

use anyhow::Result;
use cadmorph::model::MorphOutcome;
use cadmorph::morph::Parameters;
use cadmorph::Model;
use serde_json::json;

use crate::seam_report::Check;

/// Prints the document of a finished morph; `written` is the output read back when it
/// is in another format than the input (its faces name the "after" seams).
pub fn print(
    input: &Path,
    output: &Path,
    params_path: &Path,
    params: &Parameters,
    m: &Model,
    o: &MorphOutcome,
    written: Option<&Model>,
    exact: Option<serde_json::Value>,
    seconds: f64,
) -> Result<()> {
    let info = m.info();
    let none = Check::default();
    let refinement = o.refinement.as_ref().map(|r| {
        json!({
            "rounds": r.rounds,
            "converged": r.converged,
            "max_gap": r.max_gap,
            "max_angle_deg": r.max_angle_deg,
            "control_points_before": r.control_points_before,
            "control_points_after": r.control_points_after,
            "max_gap_growth": r.max_gap_growth,
            "max_angle_growth_deg": r.max_angle_growth_deg,
            "input_defects": r.input_defects,
            "per_round": r.per_round,
        })
    });
    crate::schema::print(
        "morph",
        json!({
            "input": input.display().to_string(),
            "output": output.display().to_string(),
            "format": m.format().to_string(),
            "parameters": { "file": params_path.display().to_string(), "kind": crate::params::kind_of(params) },
            "unit": crate::units::json(info.metres_per_unit, &info.unit),
            "seconds": seconds,
            "control_points_before": o.control_points_before,
            "control_points_after": o.control_points_after,
            "faces_rewritten": o.faces_rewritten,
            "curves_rewritten": o.curves_rewritten,
            "parts_copied": o.parts_copied,
            "refinement": refinement,
            "seams_before": crate::seam_report::json(&o.seams_before, m.patches(), &none),
            "seams_after": crate::seam_report::json(&o.seams_after, written.unwrap_or(m).patches(), &none),
            "check": serde_json::to_value(&o.check)?,
            "repair": serde_json::to_value(&o.repair)?,
            "exact": exact,
        }),
    )
}
