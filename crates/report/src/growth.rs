//! Refinement growth: what seam refinement did round by round
//! ([`SeamRefinement::per_round`]), as a plot (SVG or PNG) and an HTML table. Round 0
//! is the input; each later round follows one pass of knot insertion.

use std::fmt::Write;

use cadmorph_seam::{RefineRound, SeamRefinement};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::{drawn, legend, render, Figure, Frame, Plot, PlotFormat};
use crate::page::{escape, num};
use crate::radial::{padded, plot_error};
use crate::Result;

/// The colour of the control-point curve.
pub const POINTS: RGBColor = RGBColor(31, 119, 180);
/// The colour of the gap-growth curve.
pub const GAP: RGBColor = RGBColor(214, 39, 40);
/// The colour of the angle-growth curve.
pub const ANGLE: RGBColor = RGBColor(44, 160, 44);

/// Smallest error drawn on the logarithmic axis: growths at or below zero (the morph
/// shrank the gap) are drawn there.
const FLOOR: f64 = 1e-16;

struct Growth<'a> {
    rounds: &'a [RefineRound],
    unit: &'a str,
    tol: Option<(f64, f64)>,
}

fn log(v: f64) -> f64 {
    v.max(FLOOR).log10()
}

impl Figure for Growth<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String> {
        let (left, right) = root.split_horizontally(root.dim_in_pixel().0 / 2);
        let last = self.rounds.len().saturating_sub(1) as f64;
        let xr = -0.2..(last + 0.2).max(1.0);
        let points: Vec<(f64, f64)> = self.rounds.iter().map(|r| (r.round as f64, r.control_points as f64)).collect();
        let yr = padded("refinement growth", points.iter().map(|p| p.1)).map_err(|e| e.to_string())?;
        let yr = yr.start.min(0.0)..yr.end;
        let int = |v: &f64| format!("{v:.0}");
        // Whole rounds only on the round axis.
        let round = |v: &f64| if (v - v.round()).abs() < 1e-9 { format!("{v:.0}") } else { String::new() };
        let frame = Frame {
            caption: Some("control points per round"),
            x_desc: "round",
            y_desc: "control points",
            y_area: 72,
            x_labels: Some((self.rounds.len() + 1).clamp(2, 8)),
            x_format: Some(&round),
            y_format: Some(&int),
            ..Default::default()
        };
        let mut chart = frame.build(&left, xr.clone(), yr)?;
        chart.draw_series(LineSeries::new(points.iter().copied(), POINTS.stroke_width(2))).map_err(drawn)?;
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, POINTS.filled()))).map_err(drawn)?;

        let gap: Vec<(f64, f64)> = self.rounds.iter().map(|r| (r.round as f64, log(r.max_gap_growth))).collect();
        let angle: Vec<(f64, f64)> =
            self.rounds.iter().map(|r| (r.round as f64, log(r.max_angle_growth_deg))).collect();
        let tols = self.tol.map(|(g, a)| [log(g), log(a)]);
        let all = gap.iter().chain(&angle).map(|p| p.1).chain(tols.into_iter().flatten());
        let lr = padded("refinement errors", all).map_err(|e| e.to_string())?;
        let exp = |v: &f64| format!("{:.0e}", 10f64.powf(*v));
        let gap_label = format!("gap growth ({})", self.unit);
        let frame = Frame {
            caption: Some("largest growth per round"),
            x_desc: "round",
            y_desc: "growth (log scale)",
            y_area: 72,
            x_labels: Some((self.rounds.len() + 1).clamp(2, 8)),
            x_format: Some(&round),
            y_format: Some(&exp),
            ..Default::default()
        };
        let mut chart = frame.build(&right, xr.clone(), lr)?;
        for (series, c, label) in [(&gap, GAP, gap_label.as_str()), (&angle, ANGLE, "angle growth (deg)")] {
            chart
                .draw_series(LineSeries::new(series.iter().copied(), c.stroke_width(2)))
                .map_err(drawn)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
            chart.draw_series(series.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(drawn)?;
        }
        if let Some([g, a]) = tols {
            for (v, c) in [(g, GAP), (a, ANGLE)] {
                chart
                    .draw_series(LineSeries::new([(xr.start, v), (xr.end, v)], c.mix(0.5).stroke_width(1)))
                    .map_err(drawn)?;
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// The growth of `r` as a plot (`width × height` pixels, each 64..=8192), SVG or PNG:
/// on the left the control points of all patches per round, on the right the largest
/// gap growth (model units `unit`) and angle growth (degrees) per round on a log10
/// axis, with the tolerances `tol = (gap, angle)` as thin lines when given.
///
/// # Errors
///
/// [`Error::Plot`](crate::Error::Plot) when `r` has no rounds,
/// [`Error::ImageSize`](crate::Error::ImageSize), [`Error::Png`](crate::Error::Png).
pub fn growth_plot(
    r: &SeamRefinement,
    unit: &str,
    tol: Option<(f64, f64)>,
    (width, height): (u32, u32),
    format: PlotFormat,
) -> Result<Plot> {
    if r.per_round.is_empty() {
        return Err(plot_error("refinement growth", "no rounds recorded"));
    }
    render("refinement growth", format, (width, height), &Growth { rounds: &r.per_round, unit, tol })
}

/// The rounds of `r` as an HTML table: round, control points (and their growth over the
/// round before), largest gap, gap growth, largest angle, angle growth.
pub fn growth_table(r: &SeamRefinement, unit: &str) -> String {
    let mut t = format!(
        "<table class=\"growth\"><thead><tr><th>round</th><th>control points</th><th>added</th>\
         <th>max gap ({u})</th><th>gap growth ({u})</th><th>max angle (deg)</th><th>angle growth (deg)</th>\
         </tr></thead><tbody>\n",
        u = escape(unit)
    );
    let mut prev = None;
    for x in &r.per_round {
        let added = prev.map_or_else(|| "–".to_string(), |p: usize| format!("+{}", x.control_points.saturating_sub(p)));
        let _ = writeln!(
            t,
            "<tr><td>{}</td><td>{}</td><td>{added}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            x.round,
            x.control_points,
            num(x.max_gap),
            num(x.max_gap_growth),
            num(x.max_angle_deg),
            num(x.max_angle_growth_deg)
        );
        prev = Some(x.control_points);
    }
    t.push_str("</tbody></table>\n");
    t
}
