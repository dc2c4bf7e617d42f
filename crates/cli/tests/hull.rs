//! `cadmorph hull volume|dims` and `cadmorph morph --keep-volume/--keep-barycentre` on
//! the planing-hull sample. The OCCT volume 40.41889533333262 m³ is the sample's
//! (`tests/occt/planing_hull.py volume samples/planing_hull.stp`).

use std::path::{Path, PathBuf};
use std::process::Command;

const OCCT_VOLUME: f64 = 40.41889533333262;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-cli-hull-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn volume(path: &Path) -> (f64, f64) {
    let out = cadmorph(&["hull", "volume", path.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    (j["volume"].as_f64().unwrap(), j["centroid"][0].as_f64().unwrap())
}

#[test]
fn keep_volume_keeps_it_and_impossible_constraints_write_nothing() {
    let (v0, _) = volume(Path::new("samples/planing_hull.stp"));
    assert!((v0 - OCCT_VOLUME).abs() <= 1e-12 * OCCT_VOLUME, "{v0}");
    let out = tmp("kept.stp");
    let o = cadmorph(&[
        "morph",
        "samples/planing_hull.stp",
        "--ffd",
        "crates/cli/tests/data/hull_bulb.prm",
        "--keep-volume",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (v, _) = volume(&out);
    assert!((v - v0).abs() <= 1e-12 * v0, "{v} vs {v0}");
    // A lattice over the transom (a trimmed plane): refused, nothing written.
    let bad = tmp("bad.stp");
    let o = cadmorph(&[
        "morph",
        "samples/planing_hull.stp",
        "--ffd",
        "crates/cli/tests/data/hull_transom.prm",
        "--keep-volume",
        "-o",
        bad.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("nothing written"), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!bad.exists());
    // With refinement: refused by the parser.
    let o = cadmorph(&[
        "morph",
        "samples/planing_hull.stp",
        "--ffd",
        "crates/cli/tests/data/hull_bulb.prm",
        "--keep-volume",
        "--refine-tol",
        "1e-6",
        "-o",
        bad.to_str().unwrap(),
    ]);
    assert!(!o.status.success() && !bad.exists());
}

#[test]
fn dims_shifts_the_lcb() {
    let (v0, x0) = volume(Path::new("samples/planing_hull.stp"));
    let out = tmp("lcb.stp");
    let o =
        cadmorph(&["hull", "dims", "samples/planing_hull.stp", "--lcb-shift", "-0.01", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (v, x) = volume(&out);
    assert!((x - x0 + 0.01).abs() <= 1e-9, "{}", x - x0);
    assert!((v - v0).abs() <= 1e-12 * v0);
    let too_far = tmp("far.stp");
    let o =
        cadmorph(&["hull", "dims", "samples/planing_hull.stp", "--lcb-shift", "3", "-o", too_far.to_str().unwrap()]);
    assert!(!o.status.success() && !too_far.exists());
}

#[test]
fn hull_chine_writes_the_law_and_refuses_an_open_stem() {
    let out = tmp("chine.stp");
    let o = cadmorph(&[
        "hull",
        "chine",
        "samples/planing_hull.stp",
        "--theta",
        "2,4,4.5,3,0",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["lines"].as_array().unwrap().len(), 7);
    assert!(j["max_deviation"].as_f64().unwrap() <= 1e-7 * 10.69);
    assert!(j["max_gap_after"].as_f64().unwrap() <= 1e-9);
    assert_eq!(j["sharp_edges_before"], j["sharp_edges_after"]);
    assert!((j["sections"][0]["theta_deg"].as_f64().unwrap() - 2.0).abs() < 1e-12);
    // The written file holds the same closed hull: the chine law changes its volume, the
    // volume is still measured (the file is closed and valid for cadmorph).
    let (v, _) = volume(&out);
    assert!(v > 0.0 && (v - OCCT_VOLUME).abs() > 1e-6, "{v}");
    // A bottom rotation where the sections close at the stem: refused, nothing written.
    let bad = tmp("chine_bad.stp");
    let o = cadmorph(&["hull", "chine", "samples/planing_hull.stp", "--theta", "3", "-o", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("closes") && e.contains("nothing written"), "{e}");
    assert!(!bad.exists());
    let o = cadmorph(&["hull", "chine", "samples/planing_hull.stp", "--theta", "1,x", "-o", bad.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("value 2"));
    assert!(!bad.exists());
}
