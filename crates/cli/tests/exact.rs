//! `cadmorph morph --exact` end to end: the exact FFD of the solid sample, the refusal of
//! a lattice that would need degree 30 (nothing written, non-zero exit), and the flags it
//! does not combine with.

use std::process::Command;

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cadmorph-cli-exact-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn exact_ffd_of_the_solid_keeps_its_seams() {
    let out = temp("solid.stp");
    let o = out.to_str().unwrap();
    let r = cadmorph(&[
        "morph",
        "samples/mixed_solid.stp",
        "--ffd",
        "samples/prm/solid_trilinear.toml",
        "--exact",
        "-o",
        o,
        "--json",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let json: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(json["exact"]["exact_faces"], 14, "{json}");
    assert_eq!(json["exact"]["other_faces"], 0);
    assert_eq!(json["faces_rewritten"], 14);
    let before = json["seams_before"]["summary"]["max_gap_closest"].as_f64().unwrap();
    let after = json["seams_after"]["summary"]["max_gap_closest"].as_f64().unwrap();
    // Size of the solid: 60 mm; the largest input gap (3.3e-8 mm) is mapped by the FFD.
    assert!(after <= 1.2 * before + 1e-12 * 60.0, "after {after:e}, before {before:e}");
    // The same edges as the input's (29 between faces, and the cylinder's closing seam).
    let edges = |k: &str| json[k]["edges"].as_array().unwrap().len();
    assert_eq!(edges("seams_after"), edges("seams_before"));
    assert!(edges("seams_after") >= 29, "{}", edges("seams_after"));
    assert!(out.exists());
}

#[test]
fn a_lattice_needing_degree_30_is_refused_and_nothing_is_written() {
    // bow_dome.prm's 5 x 4 x 4 lattice on a box holding the whole hull.
    let prm = std::fs::read_to_string(root().join("samples/prm/bow_dome.prm")).unwrap();
    let prm = prm
        .replace("box length x: 62.0", "box length x: 149.0")
        .replace("box length y: 12.0", "box length y: 14.0")
        .replace("box length z: 12.0", "box length z: 16.5")
        .replace("box origin x: 88.0", "box origin x: -2.0")
        .replace("box origin z: -3.0", "box origin z: -2.0");
    let p = temp("big_dome.prm");
    std::fs::write(&p, prm).unwrap();
    let out = temp("refused.igs");
    let r =
        cadmorph(&["morph", "samples/hull3.igs", "--ffd", p.to_str().unwrap(), "--exact", "-o", out.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("degree 30 x 30") && err.contains("25"), "{err}");
    assert!(!out.exists(), "a refused run wrote its output");
}

#[test]
fn exact_needs_an_ffd_and_takes_no_repair() {
    let out = temp("x.igs");
    let o = out.to_str().unwrap();
    let r = cadmorph(&["morph", "samples/hull3.igs", "--rbf", "samples/prm/bow_dome.prm", "--exact", "-o", o]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("--exact composes an FFD"));
    let r =
        cadmorph(&["morph", "samples/hull3.igs", "--ffd", "samples/prm/bow_dome.prm", "--exact", "--repair", "-o", o]);
    assert_eq!(r.status.code(), Some(2));
    let r =
        cadmorph(&["morph", "samples/hull3.igs", "--ffd", "samples/prm/bow_dome.prm", "--exact-tol", "1e-9", "-o", o]);
    assert_eq!(r.status.code(), Some(2), "--exact-tol needs --exact");
    assert!(!out.exists());
}
