//! End-to-end tests of the `cadmorph` binary.

use std::process::Command;

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

#[test]
fn eval_reports_occt_agreement_for_every_hull_face() {
    let out = cadmorph(&["eval", "samples/hull3.igs.ref.json", "--grid", "4", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let faces: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let faces = faces.as_array().expect("a list");
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
