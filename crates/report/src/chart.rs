//! What every plot shares: the font, a drawing area on either backend (SVG text, or an
//! RGB bitmap encoded as PNG), the chart frame (caption, margins, label areas, mesh) and
//! the legend box. [`histogram`](crate::histogram), [`profiles`](crate::profiles),
//! [`radial`](crate::radial) and [`plots`](crate::plots) draw through it, so that every
//! plot comes as SVG or PNG from one drawing code.
//!
//! Text is set in DejaVu Sans (`assets/DejaVuSans.ttf`, Bitstream Vera licence,
//! `assets/DejaVuSans.LICENSE`), compiled in and registered with `plotters`' `ab_glyph`
//! renderer: the PNG plots need a font to draw their labels, and compiling one in keeps
//! the pictures the same on every machine (no system font lookup). SVG plots name the
//! family `sans-serif` and are laid out with the same font's metrics.

use std::ops::Range;
use std::sync::Once;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::{Error, Result};

/// The font the plots are set in.
const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// A plot's picture format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlotFormat {
    /// Scalable vector graphics (text).
    Svg,
    /// PNG (8-bit RGB).
    Png,
}

/// A drawn plot.
#[derive(Debug, Clone, PartialEq)]
pub enum Plot {
    /// SVG text.
    Svg(String),
    /// PNG bytes.
    Png(Vec<u8>),
}

impl Plot {
    /// The SVG text (`None` for a PNG).
    pub fn svg(&self) -> Option<&str> {
        match self {
            Plot::Svg(s) => Some(s),
            Plot::Png(_) => None,
        }
    }

    /// The PNG bytes (`None` for an SVG).
    pub fn png(&self) -> Option<&[u8]> {
        match self {
            Plot::Png(p) => Some(p),
            Plot::Svg(_) => None,
        }
    }

    /// The SVG text, consuming the plot (`None` for a PNG).
    pub fn into_svg(self) -> Option<String> {
        match self {
            Plot::Svg(s) => Some(s),
            Plot::Png(_) => None,
        }
    }

    /// The PNG bytes, consuming the plot (`None` for an SVG).
    pub fn into_png(self) -> Option<Vec<u8>> {
        match self {
            Plot::Png(p) => Some(p),
            Plot::Svg(_) => None,
        }
    }

    /// The plot as an HTML fragment: the SVG element itself (without its XML namespace
    /// attribute, which HTML implies, so the page names no URL), or an `<img>` with the
    /// PNG as a `data:` URL (`alt` escaped), so a page that holds it needs no other file.
    pub fn html(&self, alt: &str) -> String {
        match self {
            Plot::Svg(s) => {
                let start = s.find("<svg").unwrap_or(0);
                s[start..].replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1)
            }
            Plot::Png(p) => {
                format!("<img alt=\"{}\" src=\"{}\">", crate::page::escape(alt), crate::page::png_data_url(p))
            }
        }
    }
}

/// Something drawn on a plotters drawing area of any backend.
pub(crate) trait Figure {
    /// Draws on `root` (already filled white); errors as text.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String>;
}

/// Registers the compiled-in font as `sans-serif` (once per process).
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font (a unit test reads them).
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// The error of a failed drawing call.
pub(crate) fn drawn<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
    e.to_string()
}

/// Draws `fig` on a white `width × height` picture in `format`.
///
/// # Errors
///
/// [`Error::ImageSize`] outside 64..=8192 pixels a side, [`Error::Plot`] when drawing
/// fails (named `what`), [`Error::Png`].
pub(crate) fn render(what: &str, format: PlotFormat, (width, height): (u32, u32), fig: &impl Figure) -> Result<Plot> {
    check_size(width, height)?;
    register_font();
    let e = |r: String| Error::Plot { what: what.to_owned(), reason: r };
    match format {
        PlotFormat::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
                root.fill(&WHITE).map_err(drawn).map_err(e)?;
                fig.draw(&root).map_err(e)?;
                root.present().map_err(drawn).map_err(e)?;
            }
            Ok(Plot::Svg(svg))
        }
        PlotFormat::Png => {
            let mut rgb = vec![255u8; width as usize * height as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
                root.fill(&WHITE).map_err(drawn).map_err(e)?;
                fig.draw(&root).map_err(e)?;
                root.present().map_err(drawn).map_err(e)?;
            }
            let mut out = Vec::new();
            {
                let mut enc = png::Encoder::new(&mut out, width, height);
                enc.set_color(png::ColorType::Rgb);
                enc.set_depth(png::BitDepth::Eight);
                let mut w = enc.write_header()?;
                w.write_image_data(&rgb)?;
                w.finish()?;
            }
            Ok(Plot::Png(out))
        }
    }
}

/// Plot sizes are 64..=8192 pixels a side.
pub(crate) fn check_size(width: u32, height: u32) -> Result<()> {
    if !(64..=8192).contains(&width) || !(64..=8192).contains(&height) {
        return Err(Error::ImageSize { width, height });
    }
    Ok(())
}

/// The frame every plot uses: optional caption (18 px), `margin`, label areas of
/// `x_area` and `y_area` pixels, axes over `xr × yr`, and the mesh with axis names and
/// `labels` labels per axis (`x_labels` on x when given; `x_format`, `y_format` for
/// the labels when given).
pub(crate) struct Frame<'a> {
    pub caption: Option<&'a str>,
    pub margin: u32,
    pub x_area: u32,
    pub y_area: u32,
    pub x_desc: &'a str,
    pub y_desc: &'a str,
    pub labels: usize,
    pub x_labels: Option<usize>,
    pub x_format: Option<&'a dyn Fn(&f64) -> String>,
    pub y_format: Option<&'a dyn Fn(&f64) -> String>,
}

impl Default for Frame<'_> {
    fn default() -> Self {
        Self {
            caption: None,
            margin: 10,
            x_area: 36,
            y_area: 64,
            x_desc: "",
            y_desc: "",
            labels: 6,
            x_labels: None,
            x_format: None,
            y_format: None,
        }
    }
}

/// A chart on `root` in `frame` over `xr × yr`.
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

impl Frame<'_> {
    /// Builds the chart and draws its mesh.
    pub(crate) fn build<'a, DB: DrawingBackend>(
        &self,
        root: &'a DrawingArea<DB, Shift>,
        xr: Range<f64>,
        yr: Range<f64>,
    ) -> std::result::Result<Chart<'a, DB>, String> {
        let mut b = ChartBuilder::on(root);
        if let Some(c) = self.caption {
            b.caption(c, ("sans-serif", 18));
        }
        let mut chart = b
            .margin(self.margin)
            .x_label_area_size(self.x_area)
            .y_label_area_size(self.y_area)
            .build_cartesian_2d(xr, yr)
            .map_err(drawn)?;
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(self.x_desc)
            .y_desc(self.y_desc)
            .x_labels(self.x_labels.unwrap_or(self.labels))
            .y_labels(self.labels);
        if let Some(f) = self.x_format {
            mesh.x_label_formatter(f);
        }
        if let Some(f) = self.y_format {
            mesh.y_label_formatter(f);
        }
        mesh.draw().map_err(drawn)?;
        Ok(chart)
    }
}

/// The legend box every plot uses: translucent white, black border, at `position`.
pub(crate) fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    position: SeriesLabelPosition,
) -> std::result::Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(position)
        .draw()
        .map_err(drawn)
}

/// Width, height and RGB pixels of PNG bytes (for tests and checks of drawn plots).
///
/// # Errors
///
/// [`Error::Plot`] for bytes that are not an 8-bit RGB or RGBA PNG.
pub fn decode_png(png: &[u8]) -> Result<(u32, u32, Vec<u8>)> {
    let bad = |r: String| Error::Plot { what: "PNG".into(), reason: r };
    let mut reader = png::Decoder::new(png).read_info().map_err(|e| bad(e.to_string()))?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).map_err(|e| bad(e.to_string()))?;
    buf.truncate(info.buffer_size());
    let rgb = match (info.color_type, info.bit_depth) {
        (png::ColorType::Rgb, png::BitDepth::Eight) => buf,
        (png::ColorType::Rgba, png::BitDepth::Eight) => buf.chunks(4).flat_map(|c| [c[0], c[1], c[2]]).collect(),
        (c, d) => return Err(bad(format!("{c:?} {d:?} PNG, not 8-bit RGB"))),
    };
    Ok((info.width, info.height, rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Line;
    impl Figure for Line {
        fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String> {
            let frame = Frame { caption: Some("a line"), x_desc: "x", y_desc: "y", ..Default::default() };
            let mut chart = frame.build(root, 0.0..1.0, 0.0..1.0)?;
            chart.draw_series(LineSeries::new([(0.0, 0.0), (1.0, 1.0)], RED.stroke_width(3))).map_err(drawn)?;
            Ok(())
        }
    }

    #[test]
    fn the_font_is_a_font() {
        assert!(ab_glyph_font_ok());
    }

    fn ab_glyph_font_ok() -> bool {
        plotters::style::register_font("test-font", FontStyle::Normal, FONT).is_ok()
    }

    #[test]
    fn one_figure_as_svg_and_as_png() {
        let svg = render("line", PlotFormat::Svg, (200, 150), &Line).unwrap();
        let s = svg.svg().unwrap();
        assert!(s.starts_with("<svg") && s.contains("a line"));
        assert!(svg.html("x").starts_with("<svg") && !svg.html("x").contains("http"));
        let png = render("line", PlotFormat::Png, (200, 150), &Line).unwrap();
        let (w, h, rgb) = decode_png(png.png().unwrap()).unwrap();
        assert_eq!((w, h), (200, 150));
        // The red line and dark text (caption, labels) are drawn.
        let red = rgb.chunks(3).filter(|c| c[0] > 200 && c[1] < 60 && c[2] < 60).count();
        let dark = rgb.chunks(3).filter(|c| c.iter().all(|&v| v < 100)).count();
        assert!(red > 100, "{red} red pixels");
        assert!(dark > 100, "{dark} dark pixels");
        assert!(png.html("a line").starts_with("<img alt=\"a line\" src=\"data:image/png;base64,"));
        assert!(matches!(render("line", PlotFormat::Png, (10, 150), &Line), Err(Error::ImageSize { .. })));
    }
}
