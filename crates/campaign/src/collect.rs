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

/// The values of one column of [`Table`], `None` where a variant has none (pending
/// variants, failed ones' results).
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Text.
    Text(Vec<Option<String>>),
    /// Numbers; in CSV shortest round-trip (`None` decimals) or with fixed decimals.
    Float(Vec<Option<f64>>, Option<usize>),
    /// Counts.
    Int(Vec<Option<i64>>),
    /// Flags.
    Bool(Vec<Option<bool>>),
}

/// One column of [`Table`].
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Its name (the CSV header, the Parquet field).
    pub name: String,
    /// Its values, one per variant.
    pub values: Values,
}

/// The results of every variant as typed columns: written as CSV ([`Table::to_csv`]) and
/// as Parquet ([`crate::parquet::write`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The columns, in order.
    pub columns: Vec<Column>,
    /// Rows (variants).
    pub rows: usize,
}

impl Table {
    /// The table as CSV: a header line, then one line per variant; missing values empty,
    /// text quoted when it holds a comma, a quote or a line break.
    pub fn to_csv(&self) -> String {
        let mut s = self.columns.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(",");
        s.push('\n');
        for r in 0..self.rows {
            for (i, c) in self.columns.iter().enumerate() {
                if i > 0 {
                    s.push(',');
                }
                match &c.values {
                    Values::Text(v) => {
                        if let Some(t) = &v[r] {
                            if t.contains([',', '"', '\n', '\r']) || c.name == "error" {
                                let _ = write!(s, "\"{}\"", t.replace('"', "\"\""));
                            } else {
                                s.push_str(t);
                            }
                        }
                    }
                    Values::Float(v, d) => match (v[r], d) {
                        (Some(x), None) => s.push_str(&num(x)),
                        (Some(x), Some(d)) => {
                            let _ = write!(s, "{x:.d$}", d = *d);
                        }
                        (None, _) => {}
                    },
                    Values::Int(v) => {
                        if let Some(x) = v[r] {
                            let _ = write!(s, "{x}");
                        }
                    }
                    Values::Bool(v) => {
                        if let Some(x) = v[r] {
                            let _ = write!(s, "{x}");
                        }
                    }
                }
            }
            s.push('\n');
        }
        s
    }
}

/// Every variant: id, the parameter values, state, the seam maxima of the written
/// document, control points, rewritten faces and curves, volume and area, step times and
/// the error of failed ones. Pending variants have empty result columns.
pub fn table(space: &DesignSpace, manifest: &Manifest) -> Table {
    let states = states(space, manifest);
    let rows = manifest.variants.len();
    let mut columns = Vec::new();
    let text = |name: &str, f: &dyn Fn(usize) -> Option<String>| Column {
        name: name.into(),
        values: Values::Text((0..rows).map(f).collect()),
    };
    columns.push(text("id", &|r| Some(manifest.variants[r].id.clone())));
    for (j, p) in manifest.parameters.iter().enumerate() {
        columns.push(Column {
            name: p.clone(),
            values: Values::Float(manifest.variants.iter().map(|v| Some(v.values[j])).collect(), None),
        });
    }
    columns
        .push(text("state", &|r| serde_json::to_value(states[r].0).ok().and_then(|x| x.as_str().map(str::to_owned))));
    let report = |r: usize| states[r].1.as_ref();
    columns.push(Column {
        name: "in_tolerance".into(),
        values: Values::Bool((0..rows).map(|r| report(r).map(|x| x.in_tolerance)).collect()),
    });
    let float = |name: &str, decimals: Option<usize>, f: &dyn Fn(&Report) -> Option<f64>| Column {
        name: name.into(),
        values: Values::Float((0..rows).map(|r| report(r).and_then(f)).collect(), decimals),
    };
    let int = |name: &str, f: &dyn Fn(&Report) -> usize| Column {
        name: name.into(),
        values: Values::Int((0..rows).map(|r| report(r).map(|x| f(x) as i64)).collect()),
    };
    columns.push(float("max_gap_closest", None, &|x| x.seams.as_ref().map(|s| s.max_gap_closest)));
    columns.push(float("max_gap_matched", None, &|x| x.seams.as_ref().map(|s| s.max_gap_matched)));
    columns.push(float("max_g1_angle_deg", None, &|x| x.seams.as_ref().map(|s| s.max_g1_angle_deg)));
    columns.push(float("max_c1_mismatch", None, &|x| x.seams.as_ref().map(|s| s.max_c1_mismatch)));
    columns.push(int("control_points", &|x| x.control_points));
    columns.push(int("faces_rewritten", &|x| x.faces_rewritten));
    columns.push(int("curves_rewritten", &|x| x.curves_rewritten));
    columns.push(float("volume", None, &|x| x.measures.as_ref().and_then(|m| m.volume)));
    columns.push(float("area", None, &|x| x.measures.as_ref().and_then(|m| m.area)));
    columns.push(float("morph_ms", Some(3), &|x| Some(x.timings.morph_ms)));
    columns.push(float("write_ms", Some(3), &|x| Some(x.timings.write_ms)));
    columns.push(float("verify_ms", Some(3), &|x| Some(x.timings.verify_ms)));
    columns.push(float("measure_ms", Some(3), &|x| Some(x.timings.measure_ms)));
    columns.push(float("total_ms", Some(3), &|x| Some(x.timings.total_ms)));
    columns.push(text("error", &|r| report(r).and_then(|x| x.error.clone())));
    Table { columns, rows }
}

/// [`table`] as CSV (see [`Table::to_csv`]).
pub fn collect(space: &DesignSpace, manifest: &Manifest) -> String {
    table(space, manifest).to_csv()
}
