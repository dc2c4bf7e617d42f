//! Histograms of mesh quality before and after a morph, as SVG: for each metric the
//! values of the original mesh (blue bars, left half of each bin) and of the morphed
//! mesh (red bars, right half) over common bins, with a legend. [`quality_samples`]
//! gives the per-face and per-cell values plotted: face non-orthogonality, cell aspect
//! ratio and cell volume, computed as OpenFOAM's `checkMesh` computes them.

use std::ops::Range;

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::quality::Geometry;
use plotters::prelude::*;

use crate::radial::{check_size, plot_error};
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

/// An SVG histogram (`width × height` pixels, each 64..=8192) of `metric` over `bins`
/// (1..=1000) common bins: one bar per non-empty bin of `before` (legend "before") and,
/// when given, of `after` (legend "after"). Non-finite values are left out.
///
/// # Errors
///
/// [`Error::Plot`](crate::Error::Plot) when no value is finite or `bins` is out of
/// range, [`Error::ImageSize`](crate::Error::ImageSize).
pub fn histogram_svg(
    metric: &str,
    before: &[f64],
    after: Option<&[f64]>,
    bins: usize,
    width: u32,
    height: u32,
) -> Result<String> {
    check_size(width, height)?;
    if !(1..=1000).contains(&bins) {
        return Err(plot_error(metric, format!("{bins} bins (1..=1000)")));
    }
    let mut sets = vec![before];
    sets.extend(after);
    let range = common_range(&sets).ok_or_else(|| plot_error(metric, "no finite value to plot"))?;
    let cb = bin_counts(before, &range, bins);
    let ca = after.map(|a| bin_counts(a, &range, bins));
    let top = cb.iter().chain(ca.iter().flatten()).copied().max().unwrap_or(0).max(1);
    let bw = (range.end - range.start) / bins as f64;
    let mut svg = String::new();
    {
        let e = |e: DrawingAreaErrorKind<std::io::Error>| plot_error(metric, e);
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(metric, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(range.clone(), 0.0..(top as f64 * 1.08))
            .map_err(e)?;
        chart.configure_mesh().x_desc(metric).y_desc("count").x_labels(6).y_labels(6).draw().map_err(e)?;
        let bars = |counts: &[usize], half: f64, c: RGBColor| {
            let start = range.start;
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
        let (half_b, half_a) = if ca.is_some() { (0.0, 0.5) } else { (0.25, 0.5) };
        chart
            .draw_series(bars(&cb, half_b, BEFORE))
            .map_err(e)?
            .label("before")
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], BEFORE.filled()));
        if let Some(ca) = &ca {
            chart
                .draw_series(bars(ca, half_a, AFTER))
                .map_err(e)?
                .label("after")
                .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], AFTER.filled()));
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

/// The per-face and per-cell quality values of `mesh`, named as the histograms title
/// them: "non-orthogonality (deg)" of each internal face (the angle between the face
/// area vector and the owner-to-neighbour centre vector, `checkFaceOrthogonality`),
/// "aspect ratio" of each cell (`checkClosedCells`, all three directions solved), and
/// "cell volume".
pub fn quality_samples(mesh: &PolyMesh) -> Vec<(&'static str, Vec<f64>)> {
    let g = Geometry::of(mesh);
    let (own, nei) = (mesh.owner(), mesh.neighbour());
    let ortho = nei
        .iter()
        .enumerate()
        .map(|(f, &n)| {
            let d = g.cell_centres[n] - g.cell_centres[own[f]];
            let s = g.face_areas[f];
            let c = d.dot(&s) / (d.norm() * s.norm() + 1e-300);
            c.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .collect();
    let nc = mesh.n_cells();
    let mut smc = vec![[0.0f64; 3]; nc];
    for (f, &c) in own.iter().enumerate() {
        for k in 0..3 {
            smc[c][k] += g.face_areas[f][k].abs();
        }
    }
    for (f, &c) in nei.iter().enumerate() {
        for k in 0..3 {
            smc[c][k] += g.face_areas[f][k].abs();
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
    vec![("non-orthogonality (deg)", ortho), ("aspect ratio", aspect), ("cell volume", g.cell_volumes)]
}
