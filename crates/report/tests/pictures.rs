//! The static pictures: before/after renders of the README's main job differ where the
//! bow moved and nowhere else (the difference masked by the projected FFD box), the
//! defect seam of hull3_defect is drawn in the "bad" colour where its gap is largest,
//! and the page of the main job stays small and needs no network.

mod common;

use cadmorph_report::camera::VIEWS;
use cadmorph_report::colour::{BAD, GOOD};
use cadmorph_report::render::{camera, render, Layers};
use cadmorph_testkit::sample;
use common::{main_job, scene};

/// Whether pixel `(x, y)` lies in the convex polygon `hull` (counter-clockwise or not)
/// grown by `grow` pixels.
fn inside(hull: &[[f64; 2]], x: f64, y: f64, grow: f64) -> bool {
    let n = hull.len();
    let area: f64 = (0..n).map(|i| hull[i][0] * hull[(i + 1) % n][1] - hull[(i + 1) % n][0] * hull[i][1]).sum();
    let s = area.signum();
    (0..n).all(|i| {
        let (a, b) = (hull[i], hull[(i + 1) % n]);
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len = (ex * ex + ey * ey).sqrt().max(1e-12);
        // Signed distance of (x, y) to the edge, positive inside.
        s * (ex * (y - a[1]) - ey * (x - a[0])) / len >= -grow
    })
}

/// Convex hull (monotone chain) of 2D points.
fn convex_hull(mut p: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    p.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut lower: Vec<[f64; 2]> = Vec::new();
    for &q in &p {
        while lower.len() >= 2 && cross(lower[lower.len() - 2], lower[lower.len() - 1], q) <= 0.0 {
            lower.pop();
        }
        lower.push(q);
    }
    let mut upper: Vec<[f64; 2]> = Vec::new();
    for &q in p.iter().rev() {
        while upper.len() >= 2 && cross(upper[upper.len() - 2], upper[upper.len() - 1], q) <= 0.0 {
            upper.pop();
        }
        upper.push(q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

/// A pixel counts as changed when a channel moved by more than 12 of 255 levels: moving
/// the control points inside the box also moves the B-spline surface a little beyond it
/// (up to 6.2 cm with normals turned by 3°, at z = 9.01 m just above the box; the
/// pixels are 0.2 m), which shifts the head-lit shade there by up to about 7 levels.
#[test]
fn before_and_after_differ_only_inside_the_ffd_box() {
    let (before, after, _, ffd) = main_job();
    let sc = scene(&before, Some(&after), Some(&ffd));
    let lattice = sc.lattice.as_ref().unwrap();
    for view in &VIEWS {
        let cam = camera(&sc, view, 800, 400).unwrap();
        let a = render(&sc, &sc.before, &cam, Layers::FACES).unwrap();
        let b = render(&sc, sc.after.as_ref().unwrap(), &cam, Layers::FACES).unwrap();
        let hull = convex_hull(
            lattice
                .corners()
                .iter()
                .map(|&c| {
                    let p = cam.project(c);
                    [p[0], p[1]]
                })
                .collect(),
        );
        let (mut inside_diff, mut outside_diff, mut covered) = (0usize, Vec::new(), 0usize);
        for y in 0..cam.height {
            for x in 0..cam.width {
                let (pa, pb) = (a.pixel(x, y), b.pixel(x, y));
                if pa != cadmorph_report::raster::BACKGROUND {
                    covered += 1;
                }
                if (0..3).all(|k| (pa[k] as i32 - pb[k] as i32).abs() <= 12) {
                    continue;
                }
                // Four pixels (0.8 m) of slack: the surface moves a little beyond the box
                // (see above), which flips the odd pixel of an outline running nearly
                // along it; a move anywhere else (the stern, the deck aft) still shows.
                if inside(&hull, x as f64 + 0.5, y as f64 + 0.5, 4.0) {
                    inside_diff += 1;
                } else {
                    outside_diff.push((x, y));
                }
            }
        }
        assert!(covered > 2000, "{}: the hull covers {covered} pixels", view.name);
        assert!(
            outside_diff.is_empty(),
            "{}: {} pixels outside the FFD box changed, first {:?}",
            view.name,
            outside_diff.len(),
            &outside_diff[..outside_diff.len().min(5)]
        );
        // The bow moves down and out by decimetres and its faces turn: many
        // hundreds of pixels change shade or coverage in every view.
        assert!(inside_diff > 200, "{}: only {inside_diff} pixels changed inside the box", view.name);
        println!("{}: {inside_diff} pixels changed inside the box, none outside ({covered} covered)", view.name);
    }
}

#[test]
fn defect_seam_is_bad_where_it_opens_and_the_good_seam_is_good() {
    let m = cadmorph::open(&sample("hull3_defect.igs")).unwrap();
    let sc = scene(&m, None, None);
    let cam = camera(&sc, &VIEWS[0], 1200, 400).unwrap();
    let img = render(&sc, &sc.before, &cam, Layers::SEAMS).unwrap();
    let near = |p: [f64; 3], colour: [u8; 3]| {
        let [x, y, _] = cam.project(p);
        (-3..=3).flat_map(|dy| (-3..=3).map(move |dx| (dx, dy))).any(|(dx, dy)| {
            let (px, py) = (x as i64 + dx, y as i64 + dy);
            px >= 0 && py >= 0 && px < 1200 && py < 400 && img.pixel(px as u32, py as u32) == colour
        })
    };
    let r = m.seams(200);
    // The mid/bow seam (patches 1 and 2) opens by 2.4 mm: red where the gap is largest;
    // the stern/mid seam is closed: green at its middle, no red.
    let bad = r.edges.iter().find(|e| (e.a.patch, e.b.patch) == (1, 2)).unwrap();
    assert!(bad.gap_closest.max > 2e-3);
    assert!(near(bad.gap_closest.at, BAD), "no bad colour at {:?}", bad.gap_closest.at);
    let good = sc.before.seams.iter().find(|s| s.patches == [0, 1]).unwrap();
    let mid = good.points[good.points.len() / 2];
    assert!(near(mid, GOOD) && !near(mid, BAD));
}

#[test]
fn main_job_page_is_small_and_offline() {
    let (before, after, outcome, ffd) = main_job();
    let sc = scene(&before, Some(&after), Some(&ffd));
    let pics = cadmorph_report::render::pictures(&sc, 640, 320).unwrap();
    assert_eq!(pics.len(), 8);
    let info = cadmorph_report::html::PageInfo {
        title: "t".into(),
        refinement: outcome.refinement.clone(),
        control_points: Some((outcome.control_points_before, outcome.control_points_after)),
        timings: vec![],
        refine_tolerances: None,
    };
    let html = cadmorph_report::html::report_html(&sc, &info, &pics).unwrap();
    assert!(html.len() < 5_000_000, "{} bytes", html.len());
    // Nothing is fetched: no URL of any scheme but data: in src or href attributes.
    for attr in ["src=\"", "href=\""] {
        for (i, _) in html.match_indices(attr) {
            assert!(html[i + attr.len()..].starts_with("data:"), "{}", &html[i..i + 60]);
        }
    }
    assert!(!html.contains("http://") && !html.contains("https://"));
    // Refinement growth: one table row per round, the last the refinement's own final
    // count, which is the morph's count of control points after (every face refined).
    let r = outcome.refinement.as_ref().unwrap();
    assert!(r.rounds >= 1, "the main job refines: {r:?}");
    let table = &html[html.find("<table class=\"growth\">").expect("the growth table")..];
    let table = &table[..table.find("</table>").unwrap()];
    let rows: Vec<Vec<&str>> = table
        .split("<tr><td>")
        .skip(1)
        .map(|row| row.split("</td>").map(|c| c.trim_start_matches("<td>")).collect())
        .collect();
    assert_eq!(rows.len(), r.rounds + 1);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[0], k.to_string());
        assert_eq!(row[1], r.per_round[k].control_points.to_string());
    }
    assert_eq!(rows[0][1], outcome.control_points_before.to_string());
    assert_eq!(rows.last().unwrap()[1], r.control_points_after.to_string());
    assert_eq!(r.control_points_after, outcome.control_points_after);
    // The growth plot is inline SVG: one point per round on the control-point curve.
    let fig = &html[html.find("<figure class=\"plot\" id=\"growth-plot\"><svg").expect("inline growth plot")..];
    let fig = &fig[..fig.find("</figure>").unwrap()];
    assert!(fig.contains("control points per round") && fig.contains("</svg>"));
    assert!(fig.matches("<circle").count() >= 3 * (r.rounds + 1), "points of the three curves");
    println!("main job page: {} bytes, {} refinement rounds: {:?}", html.len(), r.rounds, rows);
}
