//! Blade profiles (the 2D airfoil sections) as an SVG plot: each profile as its closed
//! outline (upper side from leading to trailing edge, lower side back), one colour per
//! profile with a legend, on axes of equal scale so that the shapes are not distorted.

use cadmorph_blade::Profile;
use plotters::prelude::*;

use crate::radial::{check_size, padded, plot_error};
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

/// An SVG plot (`width × height` pixels, each 64..=8192) of the named `profiles`, each
/// outline labelled with its name in the legend; the axis ranges are widened so that one
/// unit is as long along x as along y.
///
/// # Errors
///
/// [`Error::Plot`](crate::Error::Plot) when there is no profile or no finite point,
/// [`Error::ImageSize`](crate::Error::ImageSize).
pub fn profiles_svg(title: &str, profiles: &[(String, &Profile)], width: u32, height: u32) -> Result<String> {
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
    let mut svg = String::new();
    {
        let e = |e: DrawingAreaErrorKind<std::io::Error>| plot_error(what, e);
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(MARGIN)
            .x_label_area_size(X_LABELS)
            .y_label_area_size(Y_LABELS)
            .build_cartesian_2d(xr, yr)
            .map_err(e)?;
        chart.configure_mesh().x_desc("x").y_desc("y").x_labels(6).y_labels(6).draw().map_err(e)?;
        for (k, ((name, _), pts)) in profiles.iter().zip(&outlines).enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            chart
                .draw_series(LineSeries::new(
                    pts.iter().copied().filter(|q| q.0.is_finite() && q.1.is_finite()),
                    c.stroke_width(2),
                ))
                .map_err(e)?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}
