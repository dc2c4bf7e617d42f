//! Principal dimensions of the planing-hull sample: length by its parallel middle body
//! (the volume grows by the mid-section area times the added length, closed form; the
//! bow and stern keep their shape), beam and draft by scaling, block coefficient by a
//! section shift; the stretch also measured by OCCT.

use std::process::Command;

use cadmorph_hull::{change_dimensions, dimensions, ChineLaw, DimsChange, Law, Side};
use cadmorph_model::Model;
use cadmorph_testkit::{harness, sample};

type StepModel = Model<cadmorph_step::Document>;

const LENGTH: f64 = 10.0;

/// The sample's sections are all the same for x ≤ 2 (tests/occt/planing_hull.py: its
/// cubic faces have control sections at the Greville abscissae, knots 0 .2 .4 .6 .8 1 of
/// u = x / 10, and the first four sections, all with width 1 and no keel rise, alone
/// span u ≤ 0.2): keel (0, 0), inner chine (1.2, 0.45), outer chine (1.35, 0.55), deck
/// edge (1.6, 2), deck at z = 2, mirrored. Shoelace area of that section.
fn mid_section_area() -> f64 {
    let p = [(0.0, 0.0), (1.2, 0.45), (1.35, 0.55), (1.6, 2.0), (0.0, 2.0)];
    let half: f64 = (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        / 2.0;
    2.0 * half
}

fn lines(m: &StepModel) -> ChineLaw {
    ChineLaw::new(m, Law::new(&[0.0]).unwrap(), None).unwrap()
}

fn lengthened() -> (StepModel, f64, f64) {
    let mut m = StepModel::open(&sample("planing_hull.stp")).unwrap();
    let v0 = dimensions(&m, None).unwrap().volume;
    let added = 1.5;
    let c = DimsChange { length: Some(LENGTH + added), middle_body: Some((0.5, 1.8)), ..Default::default() };
    let r = change_dimensions(&mut m, &c, 1e-7 * LENGTH).unwrap();
    eprintln!(
        "stretch: knots at bends {}, refined {:?}, length {} -> {}, V {} -> {}, gap {:.2e}",
        r.knots_at_bends, r.refined, r.before.length, r.after.length, r.before.volume, r.after.volume, r.max_gap_after
    );
    assert!(r.max_gap_after <= 1e-9 * LENGTH);
    assert!((r.after.length - (LENGTH + added)).abs() <= 1e-12 * LENGTH);
    (m, v0, added)
}

#[test]
fn lengthening_by_the_middle_body_adds_its_section_and_keeps_bow_and_stern() {
    let before = lines(&StepModel::open(&sample("planing_hull.stp")).unwrap());
    let (m, v0, added) = lengthened();
    let v = dimensions(&m, None).unwrap().volume;
    let expected = v0 + mid_section_area() * added;
    eprintln!("volume {v} expected {expected} ({:.2e})", (v - expected).abs() / expected);
    assert!((v - expected).abs() <= 1e-10 * expected);
    let after = lines(&m);
    for side in [Side::Starboard, Side::Port] {
        // The stern (aft of the middle body) stays, the bow translates by the added length.
        for (x, shift) in [(0.0, 0.0), (0.4, 0.0), (1.9, added), (4.5, added), (6.0, added), (8.0, added), (9.5, added)]
        {
            let a = before.section(x, side).unwrap();
            let b = after.section(x + shift, side).unwrap();
            for (p, q) in [(a.keel, b.keel), (a.inner_chine, b.inner_chine), (a.deck_edge, b.deck_edge)] {
                let d = (q - p - cadmorph_morph::math::Vector3::new(shift, 0.0, 0.0)).norm();
                assert!(d <= 1e-12 * LENGTH, "x {x}: moved by {d:e}");
            }
        }
    }
}

#[test]
fn beam_draft_and_block_coefficient() {
    let mut m = StepModel::open(&sample("planing_hull.stp")).unwrap();
    let d0 = dimensions(&m, None).unwrap();
    eprintln!("{d0:?}");
    assert!((d0.length - 10.0).abs() < 1e-12 && (d0.beam - 3.2).abs() < 1e-12 && (d0.draft - 2.0).abs() < 1e-12);
    let c = DimsChange { beam: Some(3.2 * 1.1), draft: Some(2.0 * 0.9), ..Default::default() };
    let r = change_dimensions(&mut m, &c, 1e-7 * LENGTH).unwrap();
    assert!((r.after.volume - d0.volume * 1.1 * 0.9).abs() <= 1e-12 * d0.volume);
    eprintln!("after {:?}", r.after);
    assert!((r.after.block_coefficient - d0.block_coefficient).abs() <= 1e-12);
    assert!((r.after.lcb - d0.lcb).abs() <= 1e-12 * LENGTH);
    assert!((r.after.beam - 3.52).abs() < 1e-12 && (r.after.draft - 1.8).abs() < 1e-12);
    // A fuller hull by a section shift, the LCB kept.
    let mut m = StepModel::open(&sample("planing_hull.stp")).unwrap();
    let cb = d0.block_coefficient * 1.003;
    let r = change_dimensions(&mut m, &DimsChange { block_coefficient: Some(cb), ..Default::default() }, 1e-7).unwrap();
    eprintln!(
        "Cb {} -> {} (asked {cb}), LCB {} -> {}",
        r.before.block_coefficient, r.after.block_coefficient, r.before.lcb, r.after.lcb
    );
    assert!((r.after.block_coefficient - cb).abs() <= 1e-9 * cb);
    assert!((r.after.lcb - d0.lcb).abs() <= 1e-9 * LENGTH);
    assert!((r.after.length - d0.length).abs() <= 1e-12);
    // Bad requests.
    let mut m = StepModel::open(&sample("planing_hull.stp")).unwrap();
    let bad = [
        DimsChange { length: Some(-1.0), ..Default::default() },
        DimsChange { length: Some(5.0), middle_body: Some((1.0, 4.0)), ..Default::default() },
        DimsChange { length: Some(12.0), middle_body: Some((4.0, 11.0)), ..Default::default() },
    ];
    for c in bad {
        let e = change_dimensions(&mut m, &c, 1e-7).unwrap_err();
        eprintln!("{e}");
    }
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn lengthened_hull_measured_by_occt() {
    let (m, v0, added) = lengthened();
    let dir = std::env::temp_dir().join(format!("cadmorph-hull-dims-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("long.stp");
    m.save(&path).unwrap();
    let out = Command::new(harness::python())
        .arg(harness::root().join("tests/occt/planing_hull.py"))
        .arg("volume")
        .arg(&path)
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["valid"], true, "OCCT finds the lengthened hull invalid");
    let v = j["volume"].as_f64().unwrap();
    let expected = v0 + mid_section_area() * added;
    eprintln!("OCCT volume {v}, expected {expected}");
    assert!((v - expected).abs() <= 1e-8 * expected);
    std::fs::remove_dir_all(&dir).unwrap();
}
