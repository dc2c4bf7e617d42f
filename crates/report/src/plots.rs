//! Scatter plots as SVG or PNG (the `plotters` crate's SVG and bitmap backends): a campaign's parameters
//! against its results, failed and out-of-tolerance variants marked.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::{drawn, render, Figure, Frame, Plot, PlotFormat};

/// One point of a scatter plot and whether it is marked (out of tolerance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Abscissa.
    pub x: f64,
    /// Ordinate.
    pub y: f64,
    /// Drawn as a red cross instead of a blue dot.
    pub marked: bool,
}

struct Scatter<'a> {
    x_name: &'a str,
    y_name: &'a str,
    points: Vec<Point>,
}

impl Figure for Scatter<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String> {
        let pts = &self.points;
        let range = |f: fn(&Point) -> f64| {
            let lo = pts.iter().map(f).fold(f64::INFINITY, f64::min);
            let hi = pts.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
            let pad = if hi > lo { (hi - lo) * 0.05 } else { lo.abs().max(1.0) * 0.05 };
            (lo - pad)..(hi + pad)
        };
        let fmt = |v: &f64| format!("{v:.3e}");
        let frame = Frame {
            margin: 8,
            x_area: 34,
            y_area: 60,
            x_desc: self.x_name,
            y_desc: self.y_name,
            labels: 5,
            y_format: Some(&fmt),
            ..Default::default()
        };
        let mut chart = frame.build(root, range(|p| p.x), range(|p| p.y))?;
        chart
            .draw_series(pts.iter().filter(|p| !p.marked).map(|p| Circle::new((p.x, p.y), 3, BLUE.filled())))
            .map_err(drawn)?;
        chart
            .draw_series(pts.iter().filter(|p| p.marked).map(|p| Cross::new((p.x, p.y), 4, RED.stroke_width(2))))
            .map_err(drawn)?;
        Ok(())
    }
}

/// A scatter plot of `points` (`width × height` pixels, each 64..=8192) as SVG or PNG;
/// non-finite points are left out. `None` when no point is finite or the plot cannot
/// be drawn at that size.
pub fn scatter(
    x_name: &str,
    y_name: &str,
    points: &[Point],
    (width, height): (u32, u32),
    format: PlotFormat,
) -> Option<Plot> {
    let points: Vec<Point> = points.iter().copied().filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    if points.is_empty() {
        return None;
    }
    render("scatter", format, (width, height), &Scatter { x_name, y_name, points }).ok()
}

/// [`scatter`] as SVG text.
pub fn scatter_svg(x_name: &str, y_name: &str, points: &[Point], width: u32, height: u32) -> Option<String> {
    scatter(x_name, y_name, points, (width, height), PlotFormat::Svg)?.into_svg()
}

/// [`scatter`] as PNG bytes.
pub fn scatter_png(x_name: &str, y_name: &str, points: &[Point], width: u32, height: u32) -> Option<Vec<u8>> {
    scatter(x_name, y_name, points, (width, height), PlotFormat::Png)?.into_png()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_every_point_and_marks_the_marked() {
        let pts = [
            Point { x: 0.0, y: 1.0, marked: false },
            Point { x: 1.0, y: 2.0, marked: false },
            Point { x: 2.0, y: 0.5, marked: true },
            Point { x: f64::NAN, y: 0.0, marked: false },
        ];
        let svg = scatter_svg("a", "b", &pts, 300, 200).unwrap();
        assert!(svg.starts_with("<svg"));
        assert_eq!(svg.matches("<circle").count(), 2, "{svg}");
        // The axis names as text elements (plotters writes the text on its own line).
        assert!(svg.lines().any(|l| l.trim() == "a") && svg.lines().any(|l| l.trim() == "b"));
        // The marked point is a cross: two line segments, red.
        assert!(svg.contains("#FF0000"), "{svg}");
        assert!(scatter_svg("a", "b", &pts[3..], 300, 200).is_none());
        // The same plot as PNG: blue dots and a red cross drawn.
        let (w, h, rgb) = crate::chart::decode_png(&scatter_png("a", "b", &pts, 300, 200).unwrap()).unwrap();
        assert_eq!((w, h), (300, 200));
        assert!(rgb.chunks(3).filter(|c| c[2] > 200 && c[0] < 60 && c[1] < 60).count() > 20);
        assert!(rgb.chunks(3).filter(|c| c[0] > 200 && c[1] < 60 && c[2] < 60).count() > 8);
    }
}
