//! OCCT's verdict on the written blade solids (needs the OCCT venv: `bash
//! tests/occt/setup.sh`; run by `scripts/test`): read, one solid, BRepCheck valid, no
//! free edges, volume equal to cadmorph's own to 1e-6 relative.

use std::path::PathBuf;
use std::process::Command;

use cadmorph_blade::export::{iges_solids, step_solids, LengthUnit};
use cadmorph_blade::{naca, Blade, BladeSolid, NacaOptions, NacaSpacing, Propeller};

/// The claim: OCCT's volume equals cadmorph's to 1e-6 relative.
const VOLUME_MATCH: f64 = 1e-6;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn occt(files: &[PathBuf]) -> serde_json::Value {
    occt_args(&[], files)
}

fn occt_args(flags: &[&str], files: &[PathBuf]) -> serde_json::Value {
    let py = root().join("tests/occt/.venv/bin/python");
    assert!(py.exists(), "the OCCT venv is missing: run `bash tests/occt/setup.sh` (or `bash scripts/test`)");
    let out = Command::new(py).arg(root().join("tests/occt/blade_check.py")).args(flags).args(files).output().unwrap();
    // OCCT's IGES reader prints progress to stdout; the report is the last line.
    let text = String::from_utf8_lossy(&out.stdout);
    let last = text.lines().rev().find(|l| l.starts_with('[')).unwrap_or("");
    serde_json::from_str(last)
        .unwrap_or_else(|e| panic!("blade_check.py: {e}\n{}", String::from_utf8_lossy(&out.stderr)))
}

fn blade(code: &str, closed: bool) -> Blade {
    let o = NacaOptions { n_points: 240, spacing: NacaSpacing::Cosine, closed_trailing_edge: closed };
    let sections = (0..10).map(|_| naca(code, o).unwrap()).collect();
    Blade::try_new(
        sections,
        (0..10).map(|i| 0.4 + i as f64 * 0.1).collect(),
        vec![0.55, 0.7, 0.85, 1.0, 1.03, 1.0, 0.97, 0.94, 0.91, 0.3],
        vec![3.0, 3.2, 3.4, 3.6, 3.8, 4.1, 3.9, 3.7, 3.5, 3.3],
        vec![0.005, 0.015, 0.025, 0.035, 0.045, 0.055, 0.065, 0.075, 0.075, 0.045],
        vec![-4.0, -7.0, -7.0, -4.0, -1.0, 2.0, 5.0, 8.0, 11.0, 14.0],
    )
    .unwrap()
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn occt_accepts_blade_solids() {
    let dir = std::env::temp_dir().join(format!("cadmorph-blade-occt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut files = Vec::new();
    let mut volumes = Vec::new();
    for (code, closed, reflect) in [("0012", true, true), ("2412", true, false), ("23112", false, true)] {
        let b = blade(code, closed);
        let c = b.apply_transformations(reflect).unwrap();
        let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
        assert_eq!(s.trailing.is_some(), !closed);
        let stp = dir.join(format!("blade_{code}.stp"));
        std::fs::write(&stp, step_solids("blade", &[s.faces()], LengthUnit::M, 1e-9).unwrap()).unwrap();
        let igs = dir.join(format!("blade_{code}.igs"));
        std::fs::write(&igs, iges_solids(&[s.faces()], LengthUnit::M, 1e-9, Some("20260101.000000"))).unwrap();
        files.extend([stp, igs]);
        volumes.extend([s.volume(), s.volume()]);
    }
    let report = occt(&files);
    for (r, v) in report.as_array().unwrap().iter().zip(&volumes) {
        let f = r["file"].as_str().unwrap();
        assert_eq!(r["read"], true, "{f}: {r}");
        assert_eq!(r["solids"], 1, "{f}: {r}");
        assert_eq!(r["valid"], true, "{f}: {r}");
        assert_eq!(r["free_edges"], 0, "{f}: {r}");
        let occ = r["volume"].as_f64().unwrap();
        assert!(((occ - v) / v).abs() <= VOLUME_MATCH, "{f}: OCCT volume {occ} vs cadmorph {v}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn occt_accepts_a_propeller() {
    // Four blades and the cylinder hub in one file: five valid closed solids.
    let dir = std::env::temp_dir().join(format!("cadmorph-prop-occt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let s = BladeSolid::from_coordinates(&blade("0012", true).apply_transformations(true).unwrap(), 3, 3).unwrap();
    let p = Propeller::new(&s, 4, 0.4, -0.8, 0.8).unwrap();
    let stp = dir.join("propeller.stp");
    std::fs::write(&stp, step_solids("propeller", &p.solids(), LengthUnit::M, 1e-9).unwrap()).unwrap();
    let igs = dir.join("propeller.igs");
    std::fs::write(&igs, iges_solids(&p.solids(), LengthUnit::M, 1e-9, Some("20260101.000000"))).unwrap();
    let report = occt_args(&["--no-volume"], &[stp, igs]);
    for r in report.as_array().unwrap() {
        let f = r["file"].as_str().unwrap();
        assert_eq!(r["solids"], 5, "{f}: {r}");
        assert_eq!(r["valid"], true, "{f}: {r}");
        assert_eq!(r["free_edges"], 0, "{f}: {r}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
