//! The radial laws of a blade as SVG or PNG plots (BladeX paper, Figure 7): each law (chord,
//! pitch, rake, skew, camber against radius) as its B-spline curve with its control
//! polygon and control points, the original in blue (dots) and the deformed law in red
//! (squares), with a legend.

use std::ops::Range;

use cadmorph_blade::{LawParam, RadialLaw};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::{check_size, drawn, legend, render, Figure, Frame, Plot, PlotFormat};
use crate::{Error, Result};

/// Samples of each curve drawn (BladeX samples its laws with 1000 points; 200 is
/// smooth at plot resolution).
pub const CURVE_SAMPLES: usize = 200;

/// The name of a law with its unit as the plots label it.
pub fn law_label(p: LawParam) -> &'static str {
    match p {
        LawParam::Chord => "chord",
        LawParam::Pitch => "pitch",
        LawParam::Rake => "rake",
        LawParam::Skew => "skew (deg)",
        LawParam::Camber => "max camber",
    }
}

pub(crate) fn plot_error(what: &str, reason: impl std::fmt::Display) -> Error {
    Error::Plot { what: what.to_owned(), reason: reason.to_string() }
}

/// `lo..hi` of `values` padded by 5 % (a flat range gets ±5 % of its magnitude, or ±0.05).
///
/// # Errors
///
/// [`Error::Plot`] when no value is finite.
pub(crate) fn padded(what: &str, values: impl Iterator<Item = f64>) -> Result<Range<f64>> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return Err(plot_error(what, "no finite value to plot"));
    }
    let pad = if hi > lo { (hi - lo) * 0.05 } else { lo.abs().max(1.0) * 0.05 };
    Ok((lo - pad)..(hi + pad))
}

/// A plot (`width × height` pixels, each 64..=8192) of the law `original` and, when
/// given, `deformed` (the same parameter), as SVG or PNG: curve, control polygon and
/// control points of each, legend entries "original", "original control points",
/// "deformed", "deformed control points".
///
/// # Errors
///
/// [`Error::Plot`] when the two laws are of different parameters or nothing is finite,
/// [`Error::Blade`] when a law cannot be sampled, [`Error::ImageSize`], [`Error::Png`].
pub fn radial_law_plot(
    original: &RadialLaw,
    deformed: Option<&RadialLaw>,
    (width, height): (u32, u32),
    format: PlotFormat,
) -> Result<Plot> {
    check_size(width, height)?;
    let what = original.param.name();
    if let Some(d) = deformed {
        if d.param != original.param {
            return Err(plot_error(what, format!("the deformed law is of {}", d.param.name())));
        }
    }
    let orig = original.samples(CURVE_SAMPLES)?;
    let def = deformed.map(|d| d.samples(CURVE_SAMPLES)).transpose()?;
    let all = || {
        orig.iter()
            .chain(def.iter().flatten())
            .chain(original.control_points.iter())
            .chain(deformed.iter().flat_map(|d| d.control_points.iter()))
    };
    let xr = padded(what, all().map(|p| p[0]))?;
    let yr = padded(what, all().map(|p| p[1]))?;
    let fig = Law { xr, yr, orig: &orig, original, deformed: def.as_deref().zip(deformed) };
    render(what, format, (width, height), &fig)
}

/// [`radial_law_plot`] as SVG text.
///
/// # Errors
///
/// As [`radial_law_plot`].
pub fn radial_law_svg(original: &RadialLaw, deformed: Option<&RadialLaw>, width: u32, height: u32) -> Result<String> {
    Ok(radial_law_plot(original, deformed, (width, height), PlotFormat::Svg)?.into_svg().expect("an SVG plot"))
}

/// [`radial_law_plot`] as PNG bytes.
///
/// # Errors
///
/// As [`radial_law_plot`].
pub fn radial_law_png(original: &RadialLaw, deformed: Option<&RadialLaw>, width: u32, height: u32) -> Result<Vec<u8>> {
    Ok(radial_law_plot(original, deformed, (width, height), PlotFormat::Png)?.into_png().expect("a PNG plot"))
}

struct Law<'a> {
    xr: Range<f64>,
    yr: Range<f64>,
    orig: &'a [[f64; 2]],
    original: &'a RadialLaw,
    deformed: Option<(&'a [[f64; 2]], &'a RadialLaw)>,
}

impl Figure for Law<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String> {
        let param = self.original.param;
        let caption = format!("{} law", param.name());
        let frame = Frame { caption: Some(&caption), x_desc: "radius", y_desc: law_label(param), ..Default::default() };
        let mut chart = frame.build(root, self.xr.clone(), self.yr.clone())?;
        let blue = RGBColor(31, 119, 180);
        let red = RGBColor(214, 39, 40);
        let xy = |p: &[f64; 2]| (p[0], p[1]);
        let original = self.original;
        chart
            .draw_series(LineSeries::new(self.orig.iter().map(xy), blue.stroke_width(2)))
            .map_err(drawn)?
            .label("original")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(original.control_points.iter().map(xy), blue.mix(0.5).stroke_width(1)))
            .map_err(drawn)?;
        chart
            .draw_series(original.control_points.iter().map(|p| Circle::new(xy(p), 4, blue.filled())))
            .map_err(drawn)?
            .label("original control points")
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, blue.filled()));
        if let Some((def, law)) = self.deformed {
            chart
                .draw_series(LineSeries::new(def.iter().map(xy), red.stroke_width(2)))
                .map_err(drawn)?
                .label("deformed")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
            chart
                .draw_series(LineSeries::new(law.control_points.iter().map(xy), red.mix(0.5).stroke_width(1)))
                .map_err(drawn)?;
            chart
                .draw_series(
                    law.control_points
                        .iter()
                        .map(|p| EmptyElement::at(xy(p)) + Rectangle::new([(-4, -4), (4, 4)], red.filled())),
                )
                .map_err(drawn)?
                .label("deformed control points")
                .legend(move |(x, y)| Rectangle::new([(x + 6, y - 4), (x + 14, y + 4)], red.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// One SVG per law of `original` (by [`LawParam`]), each with the deformed law of the
/// same parameter from `deformed` when there is one; see [`radial_law_svg`].
///
/// # Errors
///
/// As [`radial_law_svg`].
pub fn radial_laws_svg(
    original: &[RadialLaw],
    deformed: &[RadialLaw],
    width: u32,
    height: u32,
) -> Result<Vec<(LawParam, String)>> {
    original
        .iter()
        .map(|o| {
            let d = deformed.iter().find(|d| d.param == o.param);
            Ok((o.param, radial_law_svg(o, d, width, height)?))
        })
        .collect()
}
