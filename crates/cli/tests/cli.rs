//! End-to-end tests of the `cadmorph` binary.

mod common;

use common::{cadmorph, root, Scratch};

#[test]
fn eval_reports_occt_agreement_for_every_hull_face() {
    let out = cadmorph(&["eval", "samples/hull3.igs.ref.json", "--grid", "4", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let faces = doc["faces"].as_array().expect("a list");
    assert_eq!(faces.len(), 3);
    for f in faces {
        assert!(f["max_point_difference_relative"].as_f64().unwrap() < 1e-9, "{f}");
        assert_eq!(f["grid"].as_array().unwrap().len(), 16);
    }
}

#[test]
fn eval_table_names_each_face() {
    let out = cadmorph(&["eval", "samples/nurbs_cylinder.stp.ref.json"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("face 0: degree 2x1, 3x2 poles, rational"), "{text}");
}

#[test]
fn missing_and_malformed_files_fail_with_the_reason() {
    let out = cadmorph(&["eval", "samples/no_such_file.ref.json"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("reading samples/no_such_file.ref.json"));
    let out = cadmorph(&["eval", "samples/hull3.igs"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a JSON document"));
    let out = cadmorph(&["eval", "samples/hull3.igs.ref.json", "--grid", "1"]);
    assert_eq!(out.status.code(), Some(2), "clap rejects a grid of 1");
}

#[test]
fn info_lists_faces_of_iges_and_step() {
    for (name, faces) in [("samples/mixed_solid.igs", 14), ("samples/mixed_solid.stp", 14), ("samples/hull3.stp", 3)] {
        let out = cadmorph(&["info", name, "--json"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(info["faces"].as_array().unwrap().len(), faces, "{name}");
    }
}

#[test]
fn sample_gives_grid_points_per_face() {
    let out = cadmorph(&["sample", "samples/hull3.igs", "--grid", "3", "--json"]);
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let faces = doc["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 3);
    assert_eq!(faces[0]["grid"].as_array().unwrap().len(), 9);
}

#[test]
fn seams_of_the_defect_hull_match_occt() {
    let out = cadmorph(&["seams", "samples/hull3_defect.igs", "--json"]);
    assert!(out.status.success());
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let gap = r["summary"]["max_gap_closest"].as_f64().unwrap();
    // OCCT's independent measurement (samples/hull3_defect.igs.check.json): 2.4442e-3 m.
    assert!((gap - 2.4442325e-3).abs() < 0.01 * 2.4442325e-3, "{gap}");
}

#[test]
fn morph_writes_a_file_and_reports_seams() {
    let scratch = Scratch::new("morph");
    let dir = scratch.dir();
    let out_file = dir.join("hull3_morphed.igs");
    let report = dir.join("report.json");
    let out = cadmorph(&[
        "morph",
        "samples/hull3.igs",
        "--ffd",
        "samples/prm/bow_dome.prm",
        "--refine-tol",
        "1.45e-5",
        "-o",
        out_file.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert!(r["seams_after"]["max_gap_closest"].as_f64().unwrap() <= 1.45e-5);
    assert!(r["seams_after"]["max_g1_angle_deg"].as_f64().unwrap() <= 0.01);
    // The written file reads back, and its seams are what the report says.
    let again = cadmorph(&["seams", out_file.to_str().unwrap(), "--json"]);
    assert!(again.status.success());
    // A parameter file of the wrong kind is refused and nothing is written.
    let bad = dir.join("never.igs");
    let out =
        cadmorph(&["morph", "samples/hull3.igs", "--rbf", "samples/prm/bow_dome.prm", "-o", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("holds ffd parameters"));
    assert!(!bad.exists());
}

#[test]
fn refine_writes_step_and_iges_with_the_same_geometry() {
    let scratch = Scratch::new("refine");
    let dir = scratch.dir();
    for name in ["hull3.stp", "hull3.igs"] {
        let out_file = dir.join(name);
        let input = format!("samples/{name}");
        let out = cadmorph(&["refine", &input, "-o", out_file.to_str().unwrap(), "--knots", "4"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let before = cadmorph::open(&root().join(&input)).unwrap();
        let after = cadmorph::open(&out_file).unwrap();
        for (p, q) in before.patches().iter().zip(after.patches()) {
            // 4 knots per direction on each bicubic patch: 4 more poles each way.
            assert_eq!((q.surface.n_u(), q.surface.n_v()), (p.surface.n_u() + 4, p.surface.n_v() + 4), "{name}");
            for (u, v) in cadmorph_testkit::grid(&p.surface, 7) {
                let d = (cadmorph::nurbs::Surface::eval(&p.surface, u, v)
                    - cadmorph::nurbs::Surface::eval(&q.surface, u, v))
                .norm();
                assert!(d < 1e-9, "{name}: refinement moved the surface by {d}");
            }
        }
    }
}

#[test]
fn inputs_of_no_format_and_outputs_of_no_writer_are_refused() {
    let scratch = Scratch::new("refuse");
    let dir = scratch.dir();
    let text = dir.join("notes.txt");
    std::fs::write(&text, "not a CAD file\n").unwrap();
    let empty = dir.join("empty.stp");
    std::fs::write(&empty, "").unwrap();
    for (file, says) in
        [(&text, "notes.txt: not an IGES or STEP file"), (&empty, "empty.stp is empty: not an IGES or STEP file")]
    {
        let out = cadmorph(&["info", file.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{err}");
        assert!(!err.contains("IGES:") && !err.contains("section"), "an empty .stp is not read as IGES: {err}");
    }
    // A missing file names the file once, with the system's reason.
    let out = cadmorph(&["info", "samples/no_such.igs"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("samples/no_such.igs").count(), 1, "{err}");
    // An output extension of no format is refused and nothing is written.
    let bad = dir.join("out.txt");
    let out =
        cadmorph(&["morph", "samples/hull3.igs", "--ffd", "samples/prm/bow_dome.prm", "-o", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("extension"), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!bad.exists());
}

/// Each cause of an error is printed once: a malformed IGES file's message appears a
/// single time on the error line.
#[test]
fn errors_print_each_cause_once() {
    let scratch = Scratch::new("once");
    let dir = scratch.dir();
    let mut bytes = std::fs::read(root().join("samples/hull3.igs")).unwrap();
    // Break the column-73 section letter of a directory entry line.
    let line = bytes.split(|&b| b == b'\n').position(|l| l.get(72) == Some(&b'D')).unwrap();
    let start: usize = bytes.split(|&b| b == b'\n').take(line).map(|l| l.len() + 1).sum();
    bytes[start + 72] = b'X';
    let bad = dir.join("broken.igs");
    std::fs::write(&bad, bytes).unwrap();
    let out = cadmorph(&["info", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(err.matches("expected S, G, D, P or T").count(), 1, "{err}");
    assert!(err.contains("reading ") && err.contains("broken.igs"), "{err}");
}

#[test]
fn convert_writes_the_format_of_the_extension() {
    let scratch = Scratch::new("convert");
    let dir = scratch.dir();
    for (input, output, format) in [
        ("samples/hull3.igs", "hull3.stp", cadmorph::Format::Step),
        ("samples/hull3.stp", "hull3.igs", cadmorph::Format::Iges),
    ] {
        let out_file = dir.join(output);
        let out = cadmorph(&["convert", input, "-o", out_file.to_str().unwrap()]);
        assert!(out.status.success(), "{input}: {}", String::from_utf8_lossy(&out.stderr));
        let a = cadmorph::open(&root().join(input)).unwrap();
        let b = cadmorph::open(&out_file).unwrap();
        assert_eq!(b.format(), format);
        assert_eq!(a.patches().len(), b.patches().len());
        for (p, q) in a.patches().iter().zip(b.patches()) {
            for (u, v) in cadmorph_testkit::grid(&p.surface, 7) {
                let d = (cadmorph::nurbs::Surface::eval(&p.surface, u, v)
                    - cadmorph::nurbs::Surface::eval(&q.surface, u, v))
                .norm();
                assert!(d < 1e-9, "{input} -> {output}: {d}");
            }
        }
        // The seams are the same in the converted file.
        let (sa, sb) = (a.seams(50), b.seams(50));
        assert_eq!(sa.edges.len(), sb.edges.len(), "{input} -> {output}");
    }
    // A solid of trimmed faces is a 186 B-rep by default, trimmed surfaces on request
    // (OCCT's measure of both is in tests/convert.rs).
    for (form, solids, trimmed) in [("brep", 1, 0), ("trimmed", 0, 4)] {
        let solid = dir.join(format!("solid_{form}.igs"));
        let out =
            cadmorph(&["convert", "samples/mixed_solid.stp", "--iges-faces", form, "-o", solid.to_str().unwrap()]);
        assert!(out.status.success(), "{form}: {}", String::from_utf8_lossy(&out.stderr));
        let d = cadmorph::iges::Document::parse(&std::fs::read(&solid).unwrap()).unwrap();
        let count = |t: u32| d.entities().filter(|e| e.entity_type() == t).count();
        assert_eq!((count(186), count(144)), (solids, trimmed), "{form}");
        assert_eq!(cadmorph::open(&solid).unwrap().patches().len(), 14, "{form}");
    }
    // Wireframe is refused, not written without its curves, and nothing is left behind.
    let wire = dir.join("curve.stp");
    let out = cadmorph(&["convert", "samples/bspline_curve.igs", "-o", wire.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("curves outside faces"));
    assert!(!wire.exists());
}
