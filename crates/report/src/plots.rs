//! Scatter plots as SVG (the `plotters` crate's SVG backend): a campaign's parameters
//! against its results, failed and out-of-tolerance variants marked.

use plotters::prelude::*;

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

/// An SVG scatter plot of `points` (`width × height` pixels); non-finite points are left
/// out. `None` when no point is finite.
pub fn scatter_svg(x_name: &str, y_name: &str, points: &[Point], width: u32, height: u32) -> Option<String> {
    let pts: Vec<Point> = points.iter().copied().filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    if pts.is_empty() {
        return None;
    }
    let range = |f: fn(&Point) -> f64| {
        let lo = pts.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        let pad = if hi > lo { (hi - lo) * 0.05 } else { lo.abs().max(1.0) * 0.05 };
        (lo - pad)..(hi + pad)
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).ok()?;
        let mut chart = ChartBuilder::on(&root)
            .margin(8)
            .x_label_area_size(34)
            .y_label_area_size(60)
            .build_cartesian_2d(range(|p| p.x), range(|p| p.y))
            .ok()?;
        chart
            .configure_mesh()
            .x_desc(x_name)
            .y_desc(y_name)
            .x_labels(5)
            .y_labels(5)
            .y_label_formatter(&|v| format!("{v:.3e}"))
            .draw()
            .ok()?;
        chart.draw_series(pts.iter().filter(|p| !p.marked).map(|p| Circle::new((p.x, p.y), 3, BLUE.filled()))).ok()?;
        chart
            .draw_series(pts.iter().filter(|p| p.marked).map(|p| Cross::new((p.x, p.y), 4, RED.stroke_width(2))))
            .ok()?;
        root.present().ok()?;
    }
    Some(svg)
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
    }
}
