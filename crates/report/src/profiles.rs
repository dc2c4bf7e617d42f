//! Blade profiles (the 2D airfoil sections) as an SVG or PNG plot: each profile as its closed
//! outline (upper side from leading to trailing edge, lower side back), one colour per
//! profile with a legend, on axes of equal scale so that the shapes are not distorted.

use std::ops::Range;

use cadmorph_blade::Profile;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::{check_size, drawn, legend, render, Figure, Frame, Plot, PlotFormat};
use crate::radial::{padded, plot_error};
use crate::Result;

/// The colours of successive profiles (repeating).
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// The closed outline of `p`: the upper side as stored, then the lower side reversed.
pub fn outline(p: &Profile) -> Vec<(f64, f64)> {
    let up = p.xup.iter().zip(&p.yup).map(|(&x, &y)| (x, y));
    let down = p.xdown.iter().zip(&p.ydown).rev().map(|(&x, &y)| (x, y));
    up.chain(down).collect()
}

const X_LABELS: u32 = 36;
const Y_LABELS: u32 = 64;
const MARGIN: u32 = 10;
const CAPTION: u32 = 28;

struct Profiles<'a> {
    title: &'a str,
    names: Vec<&'a str>,
    outlines: Vec<Vec<(f64, f64)>>,
    xr: Range<f64>,
    yr: Range<f64>,
}

impl Figure for Profiles<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String> {
        let frame = Frame {
            caption: Some(self.title),
            margin: MARGIN,
            x_area: X_LABELS,
            y_area: Y_LABELS,
            x_desc: "x",
            y_desc: "y",
            ..Default::default()
        };
        let mut chart = frame.build(root, self.xr.clone(), self.yr.clone())?;
        for (k, (name, pts)) in self.names.iter().zip(&self.outlines).enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            chart
                .draw_series(LineSeries::new(
                    pts.iter().copied().filter(|q| q.0.is_finite() && q.1.is_finite()),
                    c.stroke_width(2),
                ))
                .map_err(drawn)?
                .label(*name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// A plot (`width × height` pixels, each 64..=8192) of the named `profiles`, as SVG or
/// PNG, each outline labelled with its name in the legend; the axis ranges are widened
/// so that one unit is as long along x as along y.
///
/// # Errors
///
/// [`Error::Plot`](crate::Error::Plot) when there is no profile or no finite point,
/// [`Error::ImageSize`](crate::Error::ImageSize), [`Error::Png`](crate::Error::Png).
pub fn profiles_plot(
    title: &str,
    profiles: &[(String, &Profile)],
    (width, height): (u32, u32),
    format: PlotFormat,
) -> Result<Plot> {
    check_size(width, height)?;
    let what = "profiles";
    if profiles.is_empty() {
        return Err(plot_error(what, "no profile to draw"));
    }
    let outlines: Vec<Vec<(f64, f64)>> = profiles.iter().map(|(_, p)| outline(p)).collect();
    let mut xr = padded(what, outlines.iter().flatten().map(|q| q.0))?;
    let mut yr = padded(what, outlines.iter().flatten().map(|q| q.1))?;
    // Equal scale: widen the range that has more units per pixel's worth of the other.
    let pw = f64::from(width.saturating_sub(Y_LABELS + 2 * MARGIN).max(1));
    let ph = f64::from(height.saturating_sub(X_LABELS + CAPTION + 2 * MARGIN).max(1));
    let (sx, sy) = ((xr.end - xr.start) / pw, (yr.end - yr.start) / ph);
    if sx > sy {
        let (c, h) = (0.5 * (yr.start + yr.end), 0.5 * sx * ph);
        yr = (c - h)..(c + h);
    } else {
        let (c, h) = (0.5 * (xr.start + xr.end), 0.5 * sy * pw);
        xr = (c - h)..(c + h);
    }
    let names = profiles.iter().map(|(n, _)| n.as_str()).collect();
    render(what, format, (width, height), &Profiles { title, names, outlines, xr, yr })
}

/// [`profiles_plot`] as SVG text.
///
/// # Errors
///
/// As [`profiles_plot`].
pub fn profiles_svg(title: &str, profiles: &[(String, &Profile)], width: u32, height: u32) -> Result<String> {
    Ok(profiles_plot(title, profiles, (width, height), PlotFormat::Svg)?.into_svg().expect("an SVG plot"))
}

/// [`profiles_plot`] as PNG bytes.
///
/// # Errors
///
/// As [`profiles_plot`].
pub fn profiles_png(title: &str, profiles: &[(String, &Profile)], width: u32, height: u32) -> Result<Vec<u8>> {
    Ok(profiles_plot(title, profiles, (width, height), PlotFormat::Png)?.into_png().expect("a PNG plot"))
}
