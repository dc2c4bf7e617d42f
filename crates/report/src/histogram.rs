//! Histograms of mesh quality before and after a morph, as SVG or PNG: for each metric the
//! values of the original mesh (blue bars, left half of each bin) and of the morphed
//! mesh (red bars, right half) over common bins, with a legend. [`quality_samples`]
//! gives the per-face and per-cell values plotted: face non-orthogonality, cell aspect
//! ratio, cell volume and cell skewness, computed as OpenFOAM's `checkMesh` computes them.

use std::ops::Range;

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::quality::{cell_skewness, Geometry};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::{check_size, drawn, legend, render, Figure, Frame, Plot, PlotFormat};
use crate::radial::plot_error;
use crate::Result;

/// Bins over `range` (`bins` of equal width) and the number of finite `values` in each;
/// a value at the top of the range is counted in the last bin, values outside the range
/// and non-finite ones are not counted.
pub fn bin_counts(values: &[f64], range: &Range<f64>, bins: usize) -> Vec<usize> {
    let mut counts = vec![0; bins];
    let w = range.end - range.start;
    if bins == 0 || w.is_nan() || w <= 0.0 {
        return counts;
    }
    for &v in values.iter().filter(|v| v.is_finite() && range.start <= **v && **v <= range.end) {
        let k = (((v - range.start) / w) * bins as f64) as usize;
        counts[k.min(bins - 1)] += 1;
    }
    counts
}

/// The common range of the finite values of `sets` (widened to ±0.5 when flat), `None`
/// when there is none.
pub fn common_range(sets: &[&[f64]]) -> Option<Range<f64>> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in sets.iter().flat_map(|s| s.iter()).filter(|v| v.is_finite()) {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    if lo > hi {
        return None;
    }
    if hi == lo {
        let pad = (lo.abs() * 0.05).max(0.5);
        return Some((lo - pad)..(hi + pad));
    }
    Some(lo..hi)
}

/// The colour of the "before" bars.
pub const BEFORE: RGBColor = RGBColor(31, 119, 180);
/// The colour of the "after" bars.
pub const AFTER: RGBColor = RGBColor(214, 39, 40);

struct Histogram<'a> {
    metric: &'a str,
    range: Range<f64>,
    before: Vec<usize>,
    after: Option<Vec<usize>>,
}

impl Figure for Histogram<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> std::result::Result<(), String> {
        let top = self.before.iter().chain(self.after.iter().flatten()).copied().max().unwrap_or(0).max(1);
        let bins = self.before.len();
        let bw = (self.range.end - self.range.start) / bins as f64;
        let frame = Frame {
            caption: Some(self.metric),
            y_area: 56,
            x_desc: self.metric,
            y_desc: "count",
            ..Default::default()
        };
        let mut chart = frame.build(root, self.range.clone(), 0.0..(top as f64 * 1.08))?;
        let bars = |counts: &[usize], half: f64, c: RGBColor| {
            let start = self.range.start;
            counts
                .iter()
                .enumerate()
                .filter(|(_, n)| **n > 0)
                .map(move |(k, &n)| {
                    let x0 = start + (k as f64 + half) * bw;
                    Rectangle::new([(x0, 0.0), (x0 + 0.5 * bw, n as f64)], c.filled())
                })
                .collect::<Vec<_>>()
        };
        let (half_b, half_a) = if self.after.is_some() { (0.0, 0.5) } else { (0.25, 0.5) };
        chart
            .draw_series(bars(&self.before, half_b, BEFORE))
            .map_err(drawn)?
            .label("before")
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], BEFORE.filled()));
        if let Some(ca) = &self.after {
            chart
                .draw_series(bars(ca, half_a, AFTER))
                .map_err(drawn)?
                .label("after")
                .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], AFTER.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// A histogram (`width × height` pixels, each 64..=8192) of `metric` over `bins`
/// (1..=1000) common bins, as SVG or PNG: one bar per non-empty bin of `before` (legend
/// "before") and, when given, of `after` (legend "after"). Non-finite values are left out.
///
/// # Errors
///
/// [`Error::Plot`](crate::Error::Plot) when no value is finite or `bins` is out of
/// range, [`Error::ImageSize`](crate::Error::ImageSize), [`Error::Png`](crate::Error::Png).
pub fn histogram(
    metric: &str,
    before: &[f64],
    after: Option<&[f64]>,
    bins: usize,
    (width, height): (u32, u32),
    format: PlotFormat,
) -> Result<Plot> {
    check_size(width, height)?;
    if !(1..=1000).contains(&bins) {
        return Err(plot_error(metric, format!("{bins} bins (1..=1000)")));
    }
    let mut sets = vec![before];
    sets.extend(after);
    let range = common_range(&sets).ok_or_else(|| plot_error(metric, "no finite value to plot"))?;
    let fig = Histogram {
        metric,
        before: bin_counts(before, &range, bins),
        after: after.map(|a| bin_counts(a, &range, bins)),
        range,
    };
    render(metric, format, (width, height), &fig)
}

/// [`histogram`] as SVG text.
///
/// # Errors
///
/// As [`histogram`].
pub fn histogram_svg(
    metric: &str,
    before: &[f64],
    after: Option<&[f64]>,
    bins: usize,
    width: u32,
    height: u32,
) -> Result<String> {
    Ok(histogram(metric, before, after, bins, (width, height), PlotFormat::Svg)?.into_svg().expect("an SVG plot"))
}

/// [`histogram`] as PNG bytes.
///
/// # Errors
///
/// As [`histogram`].
pub fn histogram_png(
    metric: &str,
    before: &[f64],
    after: Option<&[f64]>,
    bins: usize,
    width: u32,
    height: u32,
) -> Result<Vec<u8>> {
    Ok(histogram(metric, before, after, bins, (width, height), PlotFormat::Png)?.into_png().expect("a PNG plot"))
}

/// The per-face and per-cell quality values of `mesh`, named as the histograms title
/// them: "non-orthogonality (deg)" of each internal face (the angle between the face
/// area vector and the owner-to-neighbour centre vector, `checkFaceOrthogonality`),
/// "aspect ratio" of each cell (`checkClosedCells`, all three directions solved),
/// "cell volume", and "skewness" of each cell (the largest `checkFaceSkewness` value of
/// its faces, [`cell_skewness`]: its maximum is `checkMesh`'s "Max skewness").
pub fn quality_samples(mesh: &PolyMesh) -> Vec<(&'static str, Vec<f64>)> {
    let g = Geometry::of(mesh);
    let (own, nei) = (mesh.owner(), mesh.neighbour());
    let ortho = nei
        .iter()
        .enumerate()
        .map(|(f, &n)| {
            let d = g.cell_centres[n as usize] - g.cell_centres[own[f] as usize];
            let s = g.face_areas[f];
            let c = d.dot(&s) / (d.norm() * s.norm() + 1e-300);
            c.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .collect();
    let nc = mesh.n_cells();
    let mut smc = vec![[0.0f64; 3]; nc];
    for (f, &c) in own.iter().enumerate() {
        for k in 0..3 {
            smc[c as usize][k] += g.face_areas[f][k].abs();
        }
    }
    for (f, &c) in nei.iter().enumerate() {
        for k in 0..3 {
            smc[c as usize][k] += g.face_areas[f][k].abs();
        }
    }
    let aspect = (0..nc)
        .map(|c| {
            let s = smc[c];
            let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
            let v = g.cell_volumes[c].max(1e-150);
            (hi / (lo + 1e-150)).max((s[0] + s[1] + s[2]) / 6.0 / v.powf(2.0 / 3.0))
        })
        .collect();
    let skew = cell_skewness(mesh, &g);
    vec![
        ("non-orthogonality (deg)", ortho),
        ("aspect ratio", aspect),
        ("cell volume", g.cell_volumes),
        ("skewness", skew),
    ]
}
