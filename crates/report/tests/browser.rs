//! The report in a real browser: Debian's headless Chromium (through playwright-core,
//! `tests/report/browser.js`) opens the page of `samples/hull3_defect.igs` with the
//! bow-dome lattice, offline. Needs `bash tests/report/setup.sh` (scripts/test runs it),
//! hence `#[ignore]`.

mod common;

use cadmorph_report::colour::{BAD, GOOD};
use cadmorph_report::html::{report_html, PageInfo};
use cadmorph_report::render::pictures;
use cadmorph_testkit::sample;
use common::{bow_dome, node, read_png, scene, scratch};

#[test]
#[ignore = "needs Chromium and playwright-core: bash tests/report/setup.sh"]
fn chromium_draws_the_defect_seam_bad_where_it_opens() {
    let dir = scratch("browser");
    let m = cadmorph::open(&sample("hull3_defect.igs")).unwrap();
    let ffd = bow_dome();
    let sc = scene(&m, None, Some(&ffd));
    let html = report_html(
        &sc,
        &PageInfo { title: "hull3_defect".into(), ..Default::default() },
        &pictures(&sc, 320, 160).unwrap(),
    )
    .unwrap();
    let page = dir.join("report.html");
    std::fs::write(&page, html).unwrap();
    // The known places: where the mid/bow seam (faces 1 and 2) opens most, and the middle
    // of the closed stern/mid seam (faces 0 and 1).
    let r = m.seams(200);
    let bad = r.edges.iter().find(|e| (e.a.patch, e.b.patch) == (1, 2)).unwrap();
    assert!(bad.gap_closest.max > 2e-3, "the sample's defect");
    let good = sc.before.seams.iter().find(|s| s.patches == [0, 1]).unwrap();
    let bad_line = sc.before.seams.iter().find(|s| s.patches == [1, 2]).unwrap();
    let mut points = vec![bad.gap_closest.at, good.points[good.points.len() / 2]];
    points.extend_from_slice(&bad_line.points);
    let pts = dir.join("points.json");
    std::fs::write(&pts, serde_json::to_string(&points).unwrap()).unwrap();
    node("browser.js", &[&page, &dir, &pts]);

    let result: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("result.json")).unwrap()).unwrap();
    assert_eq!(result["webgl"], true, "{result}");
    let errors: Vec<_> = result["console"].as_array().unwrap().iter().filter(|m| m["type"] == "error").collect();
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert!(result["pageErrors"].as_array().unwrap().is_empty(), "{result}");
    assert!(result["requests"].as_array().unwrap().is_empty(), "the page asked the network: {result}");

    let (w, h, initial) = read_png(&dir.join("initial.png"));
    let (w2, h2, lattice) = read_png(&dir.join("lattice.png"));
    assert_eq!((w, h), (w2, h2));
    let px = |img: &[u8], x: i64, y: i64| -> Option<[u8; 3]> {
        (x >= 0 && y >= 0 && x < w as i64 && y < h as i64).then(|| {
            let i = (y as usize * w as usize + x as usize) * 3;
            [img[i], img[i + 1], img[i + 2]]
        })
    };
    // Not blank: a good part of the canvas is neither white nor the border's grey.
    let drawn = initial.chunks(3).filter(|c| c.iter().any(|&v| v < 235)).count();
    assert!(drawn > (w * h) as usize / 50, "canvas nearly blank: {drawn} of {} pixels drawn", w * h);
    // Toggling the lattice changes pixels.
    let changed = initial.chunks(3).zip(lattice.chunks(3)).filter(|(a, b)| a != b).count();
    assert!(changed > 500, "the lattice changed only {changed} pixels");
    // The bad colour at the defect, the good colour (and no bad one) at the closed seam.
    let close = |c: [u8; 3], want: [u8; 3]| (0..3).all(|k| (c[k] as i32 - want[k] as i32).abs() <= 8);
    let near = |p: &serde_json::Value, want: [u8; 3]| {
        let (x, y) = (p[0].as_f64().unwrap().round() as i64, p[1].as_f64().unwrap().round() as i64);
        (-4..=4).any(|dy| (-4..=4).any(|dx| px(&initial, x + dx, y + dy).is_some_and(|c| close(c, want))))
    };
    let proj = result["projected"].as_array().unwrap();
    assert!(near(&proj[0], BAD), "no bad colour drawn at the defect {:?} (pixel {})", bad.gap_closest.at, proj[0]);
    assert!(near(&proj[1], GOOD), "no good colour at the closed seam (pixel {})", proj[1]);
    assert!(!near(&proj[1], BAD), "bad colour at the closed seam (pixel {})", proj[1]);
    // And the bad colour is drawn nowhere but along the defect seam.
    let line: Vec<(f64, f64)> = proj[2..].iter().map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap())).collect();
    let bad_px: Vec<(i64, i64)> = (0..h as i64)
        .flat_map(|y| (0..w as i64).map(move |x| (x, y)))
        .filter(|&(x, y)| close(px(&initial, x, y).unwrap(), BAD))
        .collect();
    assert!(!bad_px.is_empty());
    let far: Vec<_> = bad_px
        .iter()
        .filter(|&&(x, y)| line.iter().all(|&(lx, ly)| (lx - x as f64).hypot(ly - y as f64) > 6.0))
        .collect();
    assert!(far.is_empty(), "bad colour away from the defect seam at {:?}", &far[..far.len().min(5)]);
    println!("{drawn} pixels drawn, lattice toggle changed {changed}, {} bad pixels", bad_px.len());
    let _ = std::fs::remove_dir_all(&dir);
}
