//! The planing-hull chine law on the planing sample: the rotation measured on the
//! morphed file's own keel and chine lines, and (the OCCT test) on sections cut by OCCT.

use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph_hull::{chine, ChineLaw, Law, Side};
use cadmorph_model::Model;
use cadmorph_testkit::{harness, sample};

type StepModel = Model<cadmorph_step::Document>;
type IgesModel = Model<cadmorph_iges::Document>;

const LENGTH: f64 = 10.0;

/// θ along the length, degrees: 2° at the transom, 4° amidships, 0 at the stem (where
/// the sections close).
fn theta() -> Law {
    Law::new(&[2.0f64, 4.0, 4.5, 3.0, 0.0].map(f64::to_radians)).unwrap()
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-chine-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn angle(a: cadmorph_morph::math::Point3<f64>, b: cadmorph_morph::math::Point3<f64>) -> f64 {
    (b.z - a.z).atan2((b.y - a.y).abs())
}

const STATIONS: [f64; 7] = [0.0, 1.0, 2.5, 4.0, 5.5, 7.0, 8.5];

#[test]
fn chine_law_rotates_the_bottom_and_keeps_the_chines_joined() {
    let path = sample("planing_hull.stp");
    let mut m = StepModel::open(&path).unwrap();
    let original = ChineLaw::new(&m, Law::new(&[0.0]).unwrap(), None).unwrap();
    let law = ChineLaw::new(&m, theta(), None).unwrap();
    assert_eq!(law.lines().len(), 7, "keel, two chines and the deck edge per side");
    let r = chine(&mut m, &law, 1e-7 * LENGTH).unwrap();
    eprintln!(
        "rounds {}, control points {} -> {}, deviation {:.2e}, seams after: max gap {:.2e}, sharp {}",
        r.rounds,
        r.control_points_before,
        r.control_points_after,
        r.max_deviation,
        r.morph.seams_after.max_gap_closest,
        r.morph.seams_after.sharp_edges
    );
    assert!(r.morph.seams_after.max_gap_closest <= 1e-7 * LENGTH);
    assert_eq!(r.morph.seams_after.sharp_edges, r.morph.seams_before.sharp_edges);
    let d = dir("own");
    let out = d.join("chine.stp");
    m.save(&out).unwrap();
    // The written file's own lines, read back.
    let back = StepModel::open(&out).unwrap();
    let measured = ChineLaw::new(&back, Law::new(&[0.0]).unwrap(), None).unwrap();
    for x in STATIONS {
        for side in [Side::Starboard, Side::Port] {
            let a = original.section(x, side).unwrap();
            let b = measured.section(x, side).unwrap();
            let turned = angle(b.keel, b.inner_chine) - angle(a.keel, a.inner_chine);
            eprintln!("x {x}: bottom turned {:.9}°, law {:.9}°", turned.to_degrees(), law.theta(x).to_degrees());
            assert!((turned - law.theta(x)).abs() <= 1e-6, "x {x}: {turned} vs {}", law.theta(x));
            // The deck edge stays, the chine strip translates rigidly.
            assert!((b.deck_edge - a.deck_edge).norm() <= 1e-12 * LENGTH);
            let (ao, bo) = (a.outer_chine.unwrap(), b.outer_chine.unwrap());
            assert!(((bo - b.inner_chine) - (ao - a.inner_chine)).norm() <= 1e-7 * LENGTH);
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn iges_sample_takes_the_same_law() {
    let mut m = IgesModel::open(&sample("planing_hull.igs")).unwrap();
    let law = ChineLaw::new(&m, theta(), None).unwrap();
    // The deck edges are edges between the bare wall patches and the trimmed deck plane.
    assert_eq!(law.lines().len(), 7, "keel, two chines and the deck edge per side");
    let r = chine(&mut m, &law, 1e-7 * LENGTH).unwrap();
    eprintln!("IGES: rounds {}, seams after max gap {:.2e}", r.rounds, r.morph.seams_after.max_gap_closest);
    assert!(r.morph.seams_after.max_gap_closest <= 1e-7 * LENGTH);
}

#[test]
fn impossible_laws_fail_before_anything_moves() {
    let m = StepModel::open(&sample("planing_hull.stp")).unwrap();
    // Not zero at the stem, where the sections close.
    let e = ChineLaw::new(&m, Law::new(&[0.05]).unwrap(), None).unwrap_err().to_string();
    assert!(e.contains("closes"), "{e}");
    // So large that the chine crosses the centreline.
    let e = ChineLaw::new(&m, Law::new(&[1.5, 1.5, 0.0]).unwrap(), None).unwrap_err().to_string();
    eprintln!("{e}");
    assert!(e.contains("folds") || e.contains("centreline"), "{e}");
    // A model with no chines.
    let cyl = StepModel::open(&sample("nurbs_cylinder.stp")).unwrap();
    assert!(ChineLaw::new(&cyl, theta(), None).is_err());
}

fn occt_sections(path: &Path, xs: &[f64]) -> serde_json::Value {
    let out = Command::new(harness::python())
        .arg(harness::root().join("tests/occt/planing_hull.py"))
        .arg("sections")
        .arg(path)
        .arg("--x")
        .args(xs.iter().map(|x| x.to_string()))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn occt_valid(path: &Path) -> bool {
    harness::solid_properties(path).valid
}

type Edge = Vec<[f64; 3]>;

fn edges(section: &serde_json::Value) -> Vec<Edge> {
    section["edges"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_array().unwrap().iter().map(|p| [0, 1, 2].map(|k| p[k].as_f64().unwrap())).collect())
        .collect()
}

/// The starboard bottom edge of an OCCT section: from the keel (y = 0) outwards, low.
fn bottom(es: &[Edge]) -> (f64, [f64; 3], [f64; 3]) {
    let e = es
        .iter()
        .filter(|e| e.iter().all(|p| p[1] >= -1e-12) && e.iter().any(|p| p[1].abs() <= 1e-9))
        .filter(|e| e.iter().all(|p| p[2] < 1.99))
        .min_by(|a, b| a[0][2].total_cmp(&b[0][2]))
        .expect("a starboard bottom edge");
    let (a, b) = if e[0][1] < e[20][1] { (e[0], e[20]) } else { (e[20], e[0]) };
    ((b[2] - a[2]).atan2(b[1] - a[1]), a, b)
}

/// Largest distance of an edge's points from the chord of its ends.
fn straightness(e: &Edge) -> f64 {
    let (a, b) = (e[0], e[e.len() - 1]);
    let (dy, dz) = (b[1] - a[1], b[2] - a[2]);
    let l = dy.hypot(dz);
    e.iter().map(|p| ((p[1] - a[1]) * dz - (p[2] - a[2]) * dy).abs() / l).fold(0.0, f64::max)
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn chine_law_measured_by_occt() {
    let input = sample("planing_hull.stp");
    let mut m = StepModel::open(&input).unwrap();
    let law = ChineLaw::new(&m, theta(), None).unwrap();
    chine(&mut m, &law, 1e-7 * LENGTH).unwrap();
    let d = dir("occt");
    let out = d.join("chine.stp");
    m.save(&out).unwrap();
    assert!(occt_valid(&out), "OCCT finds the morphed hull invalid");
    let before = occt_sections(&input, &STATIONS);
    let after = occt_sections(&out, &STATIONS);
    let beam = 3.2;
    for (k, &x) in STATIONS.iter().enumerate() {
        let (eb, ea) = (edges(&before["sections"][k]), edges(&after["sections"][k]));
        assert_eq!(eb.len(), ea.len(), "x {x}: section edge count");
        let (a0, ..) = bottom(&eb);
        let (a1, ..) = bottom(&ea);
        eprintln!("OCCT x {x}: bottom turned {:.9}°, law {:.9}°", (a1 - a0).to_degrees(), law.theta(x).to_degrees());
        assert!(((a1 - a0) - law.theta(x)).abs() <= 1e-6, "x {x}");
        // Every section edge straight (bottom, chine strip, wall, deck).
        for e in &ea {
            assert!(straightness(e) <= 1e-9 * beam, "x {x}: an edge bends by {:.2e}", straightness(e));
        }
        // The deck's section (z = 2) is where it was.
        let deck = |es: &[Edge]| es.iter().find(|e| e.iter().all(|p| (p[2] - 2.0).abs() <= 1e-9)).cloned().unwrap();
        let (db, da) = (deck(&eb), deck(&ea));
        let ends = |e: &Edge| {
            let mut v = [e[0], e[e.len() - 1]];
            v.sort_by(|a, b| a[1].total_cmp(&b[1]));
            v
        };
        for (p, q) in ends(&db).iter().zip(ends(&da).iter()) {
            for c in 0..3 {
                assert!((p[c] - q[c]).abs() <= 1e-12 * LENGTH, "x {x}: deck edge moved {:?} -> {:?}", p, q);
            }
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}
