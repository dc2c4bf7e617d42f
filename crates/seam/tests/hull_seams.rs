//! Seams of the three-patch hull samples against OCCT's independent measurement
//! (`samples/*.check.json`) and the construction truth in `*.ref.json`'s `note`.

use cadmorph_nurbs::NurbsSurface;
use cadmorph_seam::{measure_boundary, shared_boundaries, Face, SeamReport};
use cadmorph_testkit::occt::reference;

/// The issue asks for agreement with OCCT's measurement within 1 %.
const OCCT_SEAM: f64 = 0.01;

fn patches(name: &str) -> Vec<NurbsSurface> {
    reference(name).faces.iter().map(|f| f.to_nurbs().expect("B-spline").expect("valid")).collect()
}

fn report(name: &str) -> SeamReport {
    let p = patches(name);
    let refs: Vec<&NurbsSurface> = p.iter().collect();
    // 1e-3 of the 145 m hull: above the 2.4 mm defect, far below any patch size.
    let edges = shared_boundaries(&refs, 0.145, 64, 0.9);
    let faces: Vec<Face> = p.iter().map(|s| Face { surface: s, reversed: false }).collect();
    SeamReport::new(edges.iter().map(|e| measure_boundary(&faces, e, 200)).collect())
}

fn check_json(name: &str) -> serde_json::Value {
    let path = cadmorph_testkit::sample(&format!("{name}.check.json"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn defect_seam_matches_occt() {
    let r = report("hull3_defect.igs");
    println!("{}", r.table());
    assert_eq!(r.edges.len(), 2, "stern/mid and mid/bow");
    let occt = check_json("hull3_defect.igs");
    let occt_gap = occt["seam_summary"]["max_gap"].as_f64().unwrap();
    let occt_angle = occt["seam_summary"]["max_normal_angle_deg"].as_f64().unwrap();
    let rel = |a: f64, b: f64| (a - b).abs() / b;
    assert!(rel(r.max_gap_closest, occt_gap) < OCCT_SEAM, "gap {} vs OCCT {occt_gap}", r.max_gap_closest);
    assert!(rel(r.max_g1_angle_deg, occt_angle) < OCCT_SEAM, "angle {} vs OCCT {occt_angle}", r.max_g1_angle_deg);
    // The matched (same-v) gap of the construction note: 32.7 mm.
    assert!(rel(r.max_gap_matched, 0.03272238011429939) < OCCT_SEAM, "matched gap {}", r.max_gap_matched);
}

#[test]
fn joined_hull_has_no_gap() {
    for name in ["hull3.igs", "hull3.stp", "hull3_bare.igs"] {
        let r = report(name);
        assert_eq!(r.edges.len(), 2, "{name}");
        let length = 145.0;
        assert!(r.max_gap_closest < 1e-12 * length, "{name}: {}", r.max_gap_closest);
        assert!(r.max_gap_matched < 1e-12 * length, "{name}: {}", r.max_gap_matched);
        assert!(r.max_g1_angle_deg < 1e-6, "{name}: {}", r.max_g1_angle_deg);
    }
}
