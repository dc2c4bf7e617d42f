//! The blade and mesh SVG plots, checked by reading the SVG back: element counts, legend
//! strings, and polyline points mapped back through the axis transform to the plotted
//! values; the PNG plots decoded and checked against the SVG of the same plot.

use cadmorph_blade::{naca, LawParam, NacaOptions, RadialLaw};
use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::quality::Quality;
use cadmorph_mesh::{Cell, CellKind};
use cadmorph_morph::math::Point3;
use cadmorph_report::chart::decode_png;
use cadmorph_report::histogram::{bin_counts, common_range, histogram_png, histogram_svg, quality_samples};
use cadmorph_report::profiles::{outline, profiles_png, profiles_svg};
use cadmorph_report::radial::{radial_law_png, radial_law_svg, radial_laws_svg};

/// The value of attribute `name` in the SVG element `el`.
fn attr<'a>(el: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let i = el.find(&key)? + key.len();
    Some(&el[i..i + el[i..].find('"')?])
}

/// Every `<tag ...>` element of `svg` (its opening tag text).
fn elements<'a>(svg: &'a str, tag: &str) -> Vec<&'a str> {
    let open = format!("<{tag} ");
    svg.match_indices(&open).map(|(i, _)| &svg[i..i + svg[i..].find('>').unwrap_or(svg.len() - i)]).collect()
}

fn polyline_points(el: &str) -> Vec<(f64, f64)> {
    attr(el, "points")
        .unwrap_or("")
        .split_whitespace()
        .map(|p| {
            let (x, y) = p.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

fn text_lines(svg: &str) -> Vec<&str> {
    svg.lines().map(str::trim).collect()
}

const BLUE: &str = "#1F77B4";
const RED: &str = "#D62728";

#[test]
fn radial_law_curves_map_back_to_the_law_values() {
    let radii: Vec<f64> = (0..12).map(|i| 0.2 + 0.8 * i as f64 / 11.0).collect();
    let chord: Vec<f64> = radii.iter().map(|r| 0.2 + 0.3 * r - 0.2 * r * r).collect();
    let law = RadialLaw::fit(LawParam::Chord, &radii, &chord, 3, 6, 0).unwrap();
    let mut deformed = law.clone();
    deformed.deform(&[0.0, 0.02, 0.05, 0.03, 0.0, -0.01]).unwrap();
    let svg = radial_law_svg(&law, Some(&deformed), 640, 420).unwrap();
    assert!(svg.starts_with("<svg"));
    let lines = text_lines(&svg);
    for label in ["original", "original control points", "deformed", "deformed control points", "chord law", "radius"] {
        assert!(lines.contains(&label), "legend/label {label:?} missing");
    }
    // Original control points: one blue circle each, plus the legend's.
    let circles: Vec<(f64, f64)> = elements(&svg, "circle")
        .into_iter()
        .filter(|c| attr(c, "fill") == Some(BLUE))
        .map(|c| (attr(c, "cx").unwrap().parse().unwrap(), attr(c, "cy").unwrap().parse().unwrap()))
        .collect();
    assert_eq!(circles.len(), law.control_points.len() + 1);
    // Deformed control points: one red square each, plus the legend's.
    let squares = elements(&svg, "rect").into_iter().filter(|r| attr(r, "fill") == Some(RED)).count();
    assert_eq!(squares, deformed.control_points.len() + 1);

    // The axis transform from the control points (first/last for x, lowest/highest for y).
    let cp = &law.control_points;
    let n = cp.len();
    let bx = (circles[n - 1].0 - circles[0].0) / (cp[n - 1][0] - cp[0][0]);
    let ax = circles[0].0 - bx * cp[0][0];
    let (lo, hi) = (0..n).fold((0, 0), |(lo, hi), i| {
        (if cp[i][1] < cp[lo][1] { i } else { lo }, if cp[i][1] > cp[hi][1] { i } else { hi })
    });
    let by = (circles[hi].1 - circles[lo].1) / (cp[hi][1] - cp[lo][1]);
    let ay = circles[lo].1 - by * cp[lo][1];
    assert!(by < 0.0, "values grow upwards");

    let curves: Vec<&str> = elements(&svg, "polyline")
        .into_iter()
        .filter(|p| attr(p, "stroke-width") == Some("2") && polyline_points(p).len() > 50)
        .collect();
    assert_eq!(curves.len(), 2, "one curve each for the original and the deformed law");
    let mut moved = 0.0f64;
    for (el, l, colour) in [(curves[0], &law, BLUE), (curves[1], &deformed, RED)] {
        assert_eq!(attr(el, "stroke"), Some(colour));
        let pts = polyline_points(el);
        for &(px, py) in &pts[1..pts.len() - 1] {
            let r = (px - ax) / bx;
            let v = l.value_at(r.clamp(cp[0][0], cp[n - 1][0])).unwrap();
            let expect = ay + by * v;
            assert!((py - expect).abs() < 2.0, "{} at r = {r}: pixel {py}, law {expect}", l.param.name());
            if colour == RED {
                moved = moved.max((py - (ay + by * law.value_at(r).unwrap())).abs());
            }
        }
    }
    assert!(moved > 10.0, "the deformed curve is drawn away from the original ({moved} px)");

    // A mismatched pair is refused; all five of a set are drawn.
    let skew = RadialLaw::fit(LawParam::Skew, &radii, &chord, 3, 6, 0).unwrap();
    assert!(radial_law_svg(&law, Some(&skew), 640, 420).is_err());
    assert!(radial_law_svg(&law, None, 10, 420).is_err());
    let all = radial_laws_svg(&[law.clone(), skew], &[deformed], 400, 300).unwrap();
    assert_eq!(all.len(), 2);
    assert_eq!(elements(&all[1].1, "rect").into_iter().filter(|r| attr(r, "fill") == Some(RED)).count(), 0);
}

#[test]
fn profiles_are_closed_outlines_at_equal_scale() {
    let p = naca("0012", NacaOptions::default()).unwrap();
    let q = naca("4412", NacaOptions::default()).unwrap();
    let svg = profiles_svg("sections", &[("NACA 0012".into(), &p), ("NACA 4412".into(), &q)], 800, 400).unwrap();
    let lines = text_lines(&svg);
    assert!(lines.contains(&"NACA 0012") && lines.contains(&"NACA 4412") && lines.contains(&"sections"));
    let curves: Vec<Vec<(f64, f64)>> = elements(&svg, "polyline")
        .into_iter()
        .filter(|e| attr(e, "stroke-width") == Some("2"))
        .map(polyline_points)
        .filter(|pts| pts.len() > 2)
        .collect();
    assert_eq!(curves.len(), 2);
    let o = outline(&p);
    assert_eq!(curves[0].len(), o.len());
    // Equal scale: pixels per unit alike along x and y.
    let ext =
        |v: &mut dyn Iterator<Item = f64>| v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let (px0, px1) = ext(&mut curves[0].iter().map(|c| c.0));
    let (py0, py1) = ext(&mut curves[0].iter().map(|c| c.1));
    let (x0, x1) = ext(&mut o.iter().map(|c| c.0));
    let (y0, y1) = ext(&mut o.iter().map(|c| c.1));
    let (sx, sy) = ((px1 - px0) / (x1 - x0), (py1 - py0) / (y1 - y0));
    assert!((sx / sy - 1.0).abs() < 0.05, "x scale {sx} px/unit, y scale {sy} px/unit");
    assert!(profiles_svg("none", &[], 800, 400).is_err());
}

#[test]
fn histogram_bars_count_every_value() {
    let before: Vec<f64> = (0..500).map(|i| (i as f64 * 0.37).sin().abs() * 40.0).collect();
    let after: Vec<f64> = before.iter().map(|v| v * 1.3 + 2.0).chain([f64::NAN]).collect();
    let range = common_range(&[&before, &after]).unwrap();
    let (cb, ca) = (bin_counts(&before, &range, 20), bin_counts(&after, &range, 20));
    assert_eq!(cb.iter().sum::<usize>(), before.len());
    assert_eq!(ca.iter().sum::<usize>(), after.len() - 1, "NaN is left out");
    let svg = histogram_svg("non-orthogonality (deg)", &before, Some(&after), 20, 640, 400).unwrap();
    let lines = text_lines(&svg);
    assert!(lines.contains(&"before") && lines.contains(&"after") && lines.contains(&"count"));
    for (colour, counts) in [(BLUE, &cb), (RED, &ca)] {
        let bars: Vec<f64> = elements(&svg, "rect")
            .into_iter()
            .filter(|r| attr(r, "fill") == Some(colour))
            .map(|r| attr(r, "height").unwrap().parse().unwrap())
            .collect();
        let nonzero: Vec<usize> = counts.iter().copied().filter(|&n| n > 0).collect();
        assert_eq!(bars.len(), nonzero.len() + 1, "a bar per non-empty bin and the legend's");
        // Bar heights are proportional to the counts (pixel rounding aside).
        let big = (0..nonzero.len()).max_by_key(|&k| nonzero[k]).unwrap();
        let scale = bars[big] / nonzero[big] as f64;
        for (h, n) in bars.iter().zip(&nonzero) {
            assert!((h - scale * *n as f64).abs() <= 1.5, "bar of {n} is {h} px (scale {scale})");
        }
    }
    assert!(histogram_svg("x", &[f64::NAN], None, 10, 640, 400).is_err());
    assert!(histogram_svg("x", &before, None, 0, 640, 400).is_err());
}

fn hexes(shear: f64) -> PolyMesh {
    // Two unit hexahedra along x; the right-hand face is sheared by `shear` in y.
    let mut pts = Vec::new();
    for z in [0.0, 1.0] {
        for y in [0.0, 1.0] {
            for x in [0.0, 1.0, 2.0] {
                let dy = if x == 2.0 { shear } else { 0.0 };
                pts.push(Point3::new(x, y + dy, z));
            }
        }
    }
    let id = |x: usize, y: usize, z: usize| z * 6 + y * 3 + x;
    let hex = |x: usize| {
        Cell::new(
            CellKind::Hexahedron,
            vec![
                id(x, 0, 0),
                id(x + 1, 0, 0),
                id(x + 1, 1, 0),
                id(x, 1, 0),
                id(x, 0, 1),
                id(x + 1, 0, 1),
                id(x + 1, 1, 1),
                id(x, 1, 1),
            ],
        )
    };
    PolyMesh::from_cells(pts, &[hex(0), hex(1)]).unwrap()
}

#[test]
fn quality_samples_agree_with_check_mesh() {
    for shear in [0.0, 0.6] {
        let mesh = hexes(shear);
        let q = Quality::of(&mesh);
        let s = quality_samples(&mesh);
        let get = |name: &str| &s.iter().find(|(n, _)| *n == name).unwrap().1;
        let ortho = get("non-orthogonality (deg)");
        assert_eq!(ortho.len(), mesh.n_internal_faces());
        let max = ortho.iter().copied().fold(0.0, f64::max);
        assert!((max - q.max_non_orthogonality.value).abs() < 1e-9, "{max} vs {}", q.max_non_orthogonality.value);
        let aspect = get("aspect ratio");
        assert_eq!(aspect.len(), 2);
        assert!((aspect.iter().copied().fold(0.0, f64::max) - q.max_aspect_ratio.value).abs() < 1e-9);
        assert!((get("cell volume").iter().sum::<f64>() - q.total_volume).abs() < 1e-12);
        // Skewness per cell: its largest value is checkMesh's "Max skewness".
        let skew = get("skewness");
        assert_eq!(skew.len(), mesh.n_cells());
        let max_skew = skew.iter().copied().fold(0.0, f64::max);
        assert!((max_skew - q.max_skewness.value).abs() < 1e-12, "{max_skew} vs {}", q.max_skewness.value);
        if shear > 0.0 {
            assert!(max > 5.0, "the sheared cell is non-orthogonal: {max}");
            assert!(max_skew > 0.1, "the sheared cells are skew: {max_skew}");
        }
    }
}

/// Pixels of `rgb` (`w` wide) within 12 of `c` in every channel.
fn count_near(rgb: &[u8], c: [u8; 3]) -> usize {
    rgb.chunks(3).filter(|p| (0..3).all(|k| (p[k] as i32 - c[k] as i32).abs() <= 12)).count()
}

fn hex(c: &str) -> [u8; 3] {
    let v = |k: usize| u8::from_str_radix(&c[1 + 2 * k..3 + 2 * k], 16).unwrap();
    [v(0), v(1), v(2)]
}

/// A PNG histogram is the SVG one in pixels: every bar rectangle the SVG has is filled
/// with its colour in the PNG (checked at its centre), and the text (caption, labels,
/// legend) is drawn in dark pixels.
#[test]
fn png_histogram_draws_the_bars_of_the_svg() {
    let before: Vec<f64> = (0..500).map(|i| (i as f64 * 0.37).sin().abs() * 40.0).collect();
    let after: Vec<f64> = before.iter().map(|v| v * 1.3 + 2.0).collect();
    let (w, h) = (640, 400);
    let svg = histogram_svg("skewness", &before, Some(&after), 20, w, h).unwrap();
    let png = histogram_png("skewness", &before, Some(&after), 20, w, h).unwrap();
    let (pw, ph, rgb) = decode_png(&png).unwrap();
    assert_eq!((pw, ph), (w, h));
    let px = |x: f64, y: f64| {
        let i = (y as usize * w as usize + x as usize) * 3;
        [rgb[i], rgb[i + 1], rgb[i + 2]]
    };
    let mut checked = 0;
    for colour in [BLUE, RED] {
        for r in elements(&svg, "rect").into_iter().filter(|r| attr(r, "fill") == Some(colour)) {
            let f = |n: &str| attr(r, n).unwrap().parse::<f64>().unwrap();
            let (x, y, bw, bh) = (f("x"), f("y"), f("width"), f("height"));
            if bw < 3.0 || bh < 3.0 {
                continue;
            }
            let got = px(x + bw / 2.0, y + bh / 2.0);
            assert!((0..3).all(|k| (got[k] as i32 - hex(colour)[k] as i32).abs() <= 2), "bar {r}: {got:?}");
            checked += 1;
        }
    }
    assert!(checked > 20, "{checked} bars checked");
    let dark = rgb.chunks(3).filter(|c| c.iter().all(|&v| v < 90)).count();
    assert!(dark > 400, "text and axes drawn: {dark} dark pixels");
    assert!(histogram_png("x", &[f64::NAN], None, 10, 640, 400).is_err());
}

/// PNG radial laws and profiles: not blank, both curve colours drawn, text drawn.
#[test]
fn png_laws_and_profiles_are_drawn() {
    let radii: Vec<f64> = (0..12).map(|i| 0.2 + 0.8 * i as f64 / 11.0).collect();
    let chord: Vec<f64> = radii.iter().map(|r| 0.2 + 0.3 * r - 0.2 * r * r).collect();
    let law = RadialLaw::fit(LawParam::Chord, &radii, &chord, 3, 6, 0).unwrap();
    let mut deformed = law.clone();
    deformed.deform(&[0.0, 0.02, 0.05, 0.03, 0.0, -0.01]).unwrap();
    let (w, h, rgb) = decode_png(&radial_law_png(&law, Some(&deformed), 640, 420).unwrap()).unwrap();
    assert_eq!((w, h), (640, 420));
    assert!(count_near(&rgb, hex(BLUE)) > 300, "original law drawn");
    assert!(count_near(&rgb, hex(RED)) > 300, "deformed law drawn");
    assert!(rgb.chunks(3).filter(|c| c.iter().all(|&v| v < 90)).count() > 300, "text drawn");
    let a = naca("2412", NacaOptions::default()).unwrap();
    let b = naca("0012", NacaOptions::default()).unwrap();
    let png = profiles_png("sections", &[("2412".into(), &a), ("0012".into(), &b)], 800, 400).unwrap();
    let (_, _, rgb) = decode_png(&png).unwrap();
    assert!(count_near(&rgb, hex(BLUE)) > 300 && count_near(&rgb, hex(RED)) > 300);
}
