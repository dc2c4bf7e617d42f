//! The radial laws of a blade as SVG plots (BladeX paper, Figure 7): each law (chord,
//! pitch, rake, skew, camber against radius) as its B-spline curve with its control
//! polygon and control points, the original in blue (dots) and the deformed law in red
//! (squares), with a legend.

use std::ops::Range;

use cadmorph_blade::{LawParam, RadialLaw};
use plotters::prelude::*;

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

pub(crate) fn check_size(width: u32, height: u32) -> Result<()> {
    if !(64..=8192).contains(&width) || !(64..=8192).contains(&height) {
        return Err(Error::ImageSize { width, height });
    }
    Ok(())
}

/// An SVG plot (`width × height` pixels, each 64..=8192) of the law `original` and, when
/// given, `deformed` (the same parameter): curve, control polygon and control points of
/// each, legend entries "original", "original control points", "deformed", "deformed
/// control points".
///
/// # Errors
///
/// [`Error::Plot`] when the two laws are of different parameters or nothing is finite,
/// [`Error::Blade`] when a law cannot be sampled, [`Error::ImageSize`].
pub fn radial_law_svg(original: &RadialLaw, deformed: Option<&RadialLaw>, width: u32, height: u32) -> Result<String> {
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
    let mut svg = String::new();
    draw_law(&mut svg, (width, height), original.param, xr, yr, &orig, original, def.as_deref().zip(deformed))
        .map_err(|e| plot_error(what, e))?;
    Ok(svg)
}

type Drawn = std::result::Result<(), String>;

#[allow(clippy::too_many_arguments)]
fn draw_law(
    svg: &mut String,
    size: (u32, u32),
    param: LawParam,
    xr: Range<f64>,
    yr: Range<f64>,
    orig: &[[f64; 2]],
    original: &RadialLaw,
    deformed: Option<(&[[f64; 2]], &RadialLaw)>,
) -> Drawn {
    let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let root = SVGBackend::with_string(svg, size).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{} law", param.name()), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(xr, yr)
        .map_err(e)?;
    chart.configure_mesh().x_desc("radius").y_desc(law_label(param)).x_labels(6).y_labels(6).draw().map_err(e)?;
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);
    let xy = |p: &[f64; 2]| (p[0], p[1]);
    chart
        .draw_series(LineSeries::new(orig.iter().map(xy), blue.stroke_width(2)))
        .map_err(e)?
        .label("original")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(original.control_points.iter().map(xy), blue.mix(0.5).stroke_width(1)))
        .map_err(e)?;
    chart
        .draw_series(original.control_points.iter().map(|p| Circle::new(xy(p), 4, blue.filled())))
        .map_err(e)?
        .label("original control points")
        .legend(move |(x, y)| Circle::new((x + 10, y), 4, blue.filled()));
    if let Some((def, law)) = deformed {
        chart
            .draw_series(LineSeries::new(def.iter().map(xy), red.stroke_width(2)))
            .map_err(e)?
            .label("deformed")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(law.control_points.iter().map(xy), red.mix(0.5).stroke_width(1)))
            .map_err(e)?;
        chart
            .draw_series(
                law.control_points
                    .iter()
                    .map(|p| EmptyElement::at(xy(p)) + Rectangle::new([(-4, -4), (4, 4)], red.filled())),
            )
            .map_err(e)?
            .label("deformed control points")
            .legend(move |(x, y)| Rectangle::new([(x + 6, y - 4), (x + 14, y + 4)], red.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)?;
    Ok(())
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
