//! The model pipeline on the samples: seams against OCCT's measurement, the bow-dome
//! morph of the hull with and without refinement, zero morphs, and OCCT reading the
//! written files.

use cadmorph_model::{CadDocument, Model, MorphOptions};
use cadmorph_morph::math::Vector3;
use cadmorph_morph::{Affine, Ffd};
use cadmorph_nurbs::Surface;
use cadmorph_seam::SeamRefineOptions;
use cadmorph_testkit::sample;

/// The document of `bytes`, IGES or STEP by the file name's extension.
fn doc(name: &str, bytes: &[u8]) -> Box<dyn CadDocument> {
    if name.ends_with(".stp") {
        Box::new(cadmorph_step::Document::parse(bytes).unwrap())
    } else {
        Box::new(cadmorph_iges::Document::parse(bytes).unwrap())
    }
}

fn open(name: &str) -> Model {
    open_path(&sample(name))
}

fn open_path(path: &std::path::Path) -> Model {
    let name = path.to_string_lossy().into_owned();
    Model::new(doc(&name, &std::fs::read(path).unwrap())).unwrap()
}

/// The model of what `m` wrote, read back.
fn reread(m: &Model) -> Model {
    Model::new(m.document().read_back().unwrap()).unwrap()
}

fn bow_dome() -> Ffd {
    Ffd::from_prm(&std::fs::read_to_string(sample("prm/bow_dome.prm")).unwrap()).unwrap()
}

const HULL_LENGTH: f64 = 145.0;

#[test]
fn defect_seams_agree_with_occt_in_both_formats() {
    for name in ["hull3_defect.igs", "hull3_defect.stp"] {
        let r = open(name).seams(200);
        let check: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(sample(&format!("{name}.check.json"))).unwrap()).unwrap();
        let gap = check["seam_summary"]["max_gap"].as_f64().unwrap();
        let angle = check["seam_summary"]["max_normal_angle_deg"].as_f64().unwrap();
        assert_eq!(r.edges.len(), 2, "{name}");
        assert!((r.max_gap_closest - gap).abs() < 0.01 * gap, "{name}: {} vs {gap}", r.max_gap_closest);
        assert!((r.max_g1_angle_deg - angle).abs() < 0.01 * angle, "{name}: {} vs {angle}", r.max_g1_angle_deg);
        assert!((r.max_gap_matched - 0.0327224).abs() < 0.01 * 0.0327224, "{name}: {}", r.max_gap_matched);
    }
    for name in ["hull3.igs", "hull3.stp", "hull3_bare.igs"] {
        let r = open(name).seams(200);
        assert!(r.max_gap_closest < 1e-12 * HULL_LENGTH, "{name}: {}", r.max_gap_closest);
    }
}

/// Edges from the file's topology (STEP B-rep, IGES 186/514/510 over 504 edges) and,
/// for the IGES file without B-rep, from trimming curves that lie on each other: the same
/// face pairs as OCCT's shared edges of the STEP solid, with OCCT's normal angles (the
/// oriented angle, so the face orientations agree too) and gaps at OCCT's level.
#[test]
fn mixed_solid_edges_from_topology_agree_with_occt() {
    let check: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(sample("mixed_solid.stp.check.json")).unwrap()).unwrap();
    let mut occt: Vec<((u64, u64), f64, f64)> = check["seams"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let f = s["faces"].as_array().unwrap();
            let (a, b) = (f[0].as_u64().unwrap(), f[1].as_u64().unwrap());
            ((a.min(b), a.max(b)), s["max_normal_angle_deg"].as_f64().unwrap(), s["edge_length"].as_f64().unwrap())
        })
        .collect();
    occt.sort_by_key(|x| x.0);
    assert_eq!(occt.len(), 29);
    for name in ["mixed_solid.stp", "mixed_solid_brep.igs", "mixed_solid.igs"] {
        let m = open(name);
        // OCCT's own check takes 50 samples per edge, evenly spaced in the edge parameter.
        let r = m.seams(50);
        // OCCT's check lists edges between two faces; the cylinder's own closing seam
        // (one face on both sides) is measured too, and left out here.
        let mut ours: Vec<((u64, u64), f64, f64, f64)> = r
            .edges
            .iter()
            .filter(|e| e.a.patch != e.b.patch)
            .map(|e| {
                let (a, b) = (e.a.patch as u64, e.b.patch as u64);
                ((a.min(b), a.max(b)), e.g1_angle_deg.max, e.length, e.gap_matched.max)
            })
            .collect();
        ours.sort_by_key(|x| x.0);
        assert_eq!(
            ours.iter().map(|o| o.0).collect::<Vec<_>>(),
            occt.iter().map(|o| o.0).collect::<Vec<_>>(),
            "{name}: face pairs"
        );
        for (o, c) in ours.iter().zip(&occt) {
            assert!((o.1 - c.1).abs() < 0.02, "{name} {:?}: angle {} vs OCCT {}", o.0, o.1, c.1);
            assert!((o.2 - c.2).abs() < 1e-3 * c.2, "{name} {:?}: length {} vs OCCT {}", o.0, o.2, c.2);
            assert!(o.3 < 1e-6, "{name} {:?}: gap {}", o.0, o.3);
        }
        // The loft's one smooth edge is the only one not sharp.
        assert_eq!(r.sharp_edges, 28, "{name}");
        assert!(r.max_g1_angle_deg < 1e-6, "{name}: {}", r.max_g1_angle_deg);
    }
}

#[test]
fn zero_morph_writes_the_input_unchanged() {
    let zero = Affine::identity();
    for name in ["hull3.igs", "mixed_solid.igs", "hull3.stp", "mixed_solid.stp"] {
        let bytes = std::fs::read(sample(name)).unwrap();
        let mut m = Model::new(doc(name, &bytes)).unwrap();
        m.morph(&zero, &MorphOptions::default()).unwrap();
        assert!(m.to_bytes() == bytes, "{name} changed under the identity");
    }
}

#[test]
fn bow_dome_with_seam_refinement_meets_the_target() {
    let ffd = bow_dome();
    for name in ["hull3.igs", "hull3.stp"] {
        let mut plain = open(name);
        let none = plain.morph(&ffd, &MorphOptions::default()).unwrap();
        let mut refined = open(name);
        let tol = 1e-7 * HULL_LENGTH;
        let opts = MorphOptions { refine: Some(SeamRefineOptions::new(tol, 0.01)), ..Default::default() };
        let r = refined.morph(&ffd, &opts).unwrap();
        let mut uniform = open(name);
        let u = uniform.morph(&ffd, &MorphOptions { uniform_knots: Some(30), ..Default::default() }).unwrap();
        for (what, o) in [("none", &none), ("refined", &r), ("uniform 30", &u)] {
            println!(
                "{name} {what}: +{} control points, max gap {:.3e}, max G1 {:.4} deg",
                o.control_points_after - o.control_points_before,
                o.seams_after.max_gap_closest,
                o.seams_after.max_g1_angle_deg
            );
        }
        assert_eq!(none.faces_rewritten, 2, "{name}: the bow dome reaches the mid and bow patches, not the stern");
        assert!(none.seams_after.max_g1_angle_deg > 0.01, "{name}: without refinement the seams kink");
        assert!(r.seams_after.max_gap_closest <= tol, "{name}: {}", r.seams_after.max_gap_closest);
        assert!(r.seams_after.max_g1_angle_deg <= 0.01, "{name}: {}", r.seams_after.max_g1_angle_deg);
        assert!(
            r.control_points_after < u.control_points_after,
            "{name}: {} vs {}",
            r.control_points_after,
            u.control_points_after
        );
    }
}

#[test]
fn repair_closes_the_defect_after_a_morph() {
    let ffd = bow_dome();
    for name in ["hull3_defect.igs", "hull3_defect.stp"] {
        let mut m = open(name);
        let o = m.morph(&ffd, &MorphOptions { repair: true, ..Default::default() }).unwrap();
        println!("{name}:\n{}", o.seams_after.table());
        // The file keeps about 9 (IGES) or 12 (STEP) digits of metres: 1e-12 × L is below
        // what IGES text holds, so the read-back gap is held to 1e-9 m.
        assert!(o.seams_after.max_gap_matched <= 1e-9, "{name}: {}", o.seams_after.max_gap_matched);
        assert!(o.seams_before.max_gap_closest > 2e-3);
    }
}

/// A non-affine 3×3×3 FFD over the whole model's box.
fn solid_ffd(m: &Model) -> Ffd {
    let size = m.size();
    let b = cadmorph_nurbs::Aabb::from_points(m.patches().iter().flat_map(|p| p.surface.control_points())).unwrap();
    let origin = b.min - Vector3::repeat(0.05 * size);
    let mut ffd =
        Ffd::try_new([3, 3, 3], origin, (b.max - b.min) + Vector3::repeat(0.1 * size), Vector3::zeros()).unwrap();
    ffd.mu_mut().set(1, 1, 2, [0.05, 0.04, 0.08]);
    ffd.mu_mut().set(2, 1, 1, [0.06, -0.03, 0.02]);
    ffd
}

#[test]
fn every_face_of_the_mixed_solid_moves() {
    // A non-affine FFD over the whole solid: planes and cylinders must move too.
    for name in ["mixed_solid.igs", "mixed_solid.stp"] {
        let mut m = open(name);
        let before: Vec<_> = m.patches().iter().map(|p| p.surface.clone()).collect();
        let size = m.size();
        let b = cadmorph_nurbs::Aabb::from_points(before.iter().flat_map(|s| s.control_points())).unwrap();
        let mut ffd = Ffd::try_new(
            [3, 3, 3],
            b.min - Vector3::repeat(0.05 * size),
            (b.max - b.min) + Vector3::repeat(0.1 * size),
            Vector3::zeros(),
        )
        .unwrap();
        ffd.mu_mut().set(1, 1, 2, [0.05, 0.04, 0.08]);
        ffd.mu_mut().set(2, 1, 1, [0.06, -0.03, 0.02]);
        m.morph(&ffd, &MorphOptions::default()).unwrap();
        assert_eq!(m.patches().len(), before.len(), "{name}");
        for (i, (p, s)) in m.patches().iter().zip(&before).enumerate() {
            let (ud, vd) = s.domain();
            let mid = s.eval((ud.start() + ud.end()) / 2.0, (vd.start() + vd.end()) / 2.0);
            let moved = cadmorph_morph::Deformation::deform_point(&ffd, &mid);
            assert!((moved - mid).norm() > 1e-6 * size, "{name} face {i}: the FFD does not move it");
            assert!(p.surface != *s, "{name} face {i} ({}) was left behind", p.type_name);
        }
    }
}

/// Under a non-affine FFD, moving control points of coarse patches (planes are 2x2) opens
/// the solid's trim edges; refinement along the topology edges, carried over to the
/// B-splines the analytic faces become, keeps every side within the tolerance of the
/// exact morph, and the seams stay closed.
#[test]
fn mixed_solid_refinement_keeps_topology_edges_closed() {
    for name in ["mixed_solid.stp", "mixed_solid_brep.igs", "mixed_solid.igs"] {
        let m = open(name);
        let ffd = solid_ffd(&m);
        let size = m.size();
        let tol = 1e-4 * size;
        let mut plain = open(name);
        let none = plain.morph(&ffd, &MorphOptions::default()).unwrap();
        let mut refined = open(name);
        let opts = MorphOptions { refine: Some(SeamRefineOptions::new(tol, 0.5)), ..Default::default() };
        let r = refined.morph(&ffd, &opts).unwrap();
        let refinement = r.refinement.as_ref().unwrap();
        assert!(refinement.converged, "{name}: {refinement:?}");
        // Unrefined, the seams open by more than tol (by more than 10 tol where the file
        // names its edges; the IGES trims alone pair fewer edges, 0.043 mm at most).
        let factor = if name == "mixed_solid.igs" { 1.0 } else { 10.0 };
        assert!(none.seams_after.max_gap_closest > factor * tol, "{name}: {}", none.seams_after.max_gap_closest);
        assert!(r.seams_after.max_gap_closest <= tol, "{name}: {}", r.seams_after.max_gap_closest);
        assert!(r.control_points_after > none.control_points_after, "{name}");
        // 29 edges between two faces and the cylinder's closing seam.
        assert_eq!(r.seams_after.edges.len(), 30, "{name}: {}\n{}", r.seams_after.table(), r.seams_before.table());
        assert_eq!(r.seams_after.edges.iter().filter(|e| e.a.patch == e.b.patch).count(), 1, "{name}");
        // The written edge curves lie on the morphed faces: measured afresh from the
        // file, edges found from its curves, the seams are as closed
        let fresh = reread(&refined).seams(50);
        assert_eq!(fresh.edges.len(), 30, "{name}: {}", fresh.table());
        assert!(fresh.max_gap_closest <= tol, "{name}: {}", fresh.max_gap_closest);
    }
}

/// An offset surface (IGES 140) is a face like any other: a non-affine morph moves it,
/// writing it as the B-spline it converts to, and the written file reads back.
#[test]
fn offset_surface_faces_move_too() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../iges/tests/data/conics_offset.igs");
    let mut m = open_path(&path);
    let offsets = m.patches().iter().filter(|p| p.type_name == "IGES 140").count();
    assert!(offsets > 0, "the sample has offset faces");
    let before: Vec<_> = m.patches().iter().map(|p| p.surface.clone()).collect();
    let ffd = solid_ffd(&m);
    m.morph(&ffd, &MorphOptions::default()).unwrap();
    assert_eq!(m.patches().len(), before.len());
    for (p, s) in m.patches().iter().zip(&before) {
        assert!(p.surface != *s, "{} was left behind", p.entity);
    }
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn occt_reads_morphed_files() {
    let ffd = bow_dome();
    let scratch = cadmorph_testkit::Scratch::new("model");
    let dir = scratch.dir();
    for (name, opts) in [
        (
            "hull3.igs",
            MorphOptions { refine: Some(SeamRefineOptions::new(1e-7 * HULL_LENGTH, 0.01)), ..Default::default() },
        ),
        (
            "hull3.stp",
            MorphOptions { refine: Some(SeamRefineOptions::new(1e-7 * HULL_LENGTH, 0.01)), ..Default::default() },
        ),
        ("hull3_defect.stp", MorphOptions { repair: true, ..Default::default() }),
        ("hull3_defect.igs", MorphOptions { repair: true, ..Default::default() }),
    ] {
        let mut m = open(name);
        m.morph(&ffd, &opts).unwrap();
        let out = dir.join(name);
        m.save(&out).unwrap();
        let (code, json) = cadmorph_testkit::harness::validate(&out, None);
        assert_eq!(code, 0, "{name}: {json}");
        assert_eq!(json["valid"], true, "{name}: {json}");
        assert_eq!(json["n_faces"].as_u64(), Some(3), "{name}: {json}");
    }
    for (name, refine) in
        ["mixed_solid.igs", "mixed_solid.stp", "mixed_solid_brep.igs"].into_iter().flat_map(|n| [(n, false), (n, true)])
    {
        let mut m = open(name);
        let ffd = solid_ffd(&m);
        let refine = refine.then(|| SeamRefineOptions::new(1e-4 * m.size(), 0.5));
        m.morph(&ffd, &MorphOptions { refine, ..Default::default() }).unwrap();
        let out = dir.join(format!("{}{name}", if refine.is_some() { "refined_" } else { "" }));
        m.save(&out).unwrap();
        let (code, json) = cadmorph_testkit::harness::validate(&out, None);
        assert_eq!(code, 0, "{name}: {json}");
        assert_eq!(json["transfer_ok"], true, "{name}: {json}");
        assert_eq!(json["valid"], true, "{name}: OCCT finds the morphed solid invalid: {json}");
    }
}
