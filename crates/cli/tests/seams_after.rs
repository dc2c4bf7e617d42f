//! The "after" report of `morph` is the written file's: exactly what `cadmorph seams`
//! finds in it (same edges, same numbers), for IGES and STEP, B-rep edges included, and
//! when the output is converted to the other format.

use std::path::PathBuf;
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

struct Scratch(PathBuf);
impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn the_after_report_equals_a_fresh_seams_of_the_written_file() {
    let s = Scratch(std::env::temp_dir().join(format!("cadmorph-seams-after-{}", std::process::id())));
    std::fs::create_dir_all(&s.0).unwrap();
    let bow = "samples/prm/bow_dome.prm";
    let cases: [(&str, &str, &[&str], &str); 6] = [
        ("samples/hull3.igs", bow, &["--refine-tol", "1.45e-5"], "igs"),
        ("samples/hull3_defect.stp", bow, &["--refine-tol", "1.45e-5", "--repair"], "stp"),
        ("samples/hull3.igs", bow, &[], "stp"),
        ("samples/mixed_solid.stp", "tests/repro/box.toml", &[], "stp"),
        ("samples/mixed_solid.stp", "tests/repro/box.toml", &["--repair"], "stp"),
        ("samples/mixed_solid_brep.igs", "tests/repro/box.toml", &[], "igs"),
    ];
    for (k, (input, ffd, opts, ext)) in cases.iter().enumerate() {
        let out = s.0.join(format!("{k}.{ext}"));
        let out = out.to_str().unwrap();
        let mut args = vec!["morph", input, "--ffd", ffd, "-o", out, "--json"];
        args.extend(opts.iter());
        let o = cadmorph(&args);
        assert!(o.status.success(), "{input} {opts:?}: {}", String::from_utf8_lossy(&o.stderr));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let fresh = cadmorph(&["seams", out, "--json"]);
        assert!(fresh.status.success());
        let fresh: serde_json::Value = serde_json::from_slice(&fresh.stdout).unwrap();
        for part in ["edges", "summary"] {
            assert_eq!(r["seams_after"][part], fresh[part], "{input} {opts:?} -> .{ext}: {part}");
        }
        assert!(!fresh["edges"].as_array().unwrap().is_empty());
        // B-rep edges are among them, named by their entities.
        if input.contains("mixed_solid") {
            assert!(fresh["edges"].as_array().unwrap().iter().any(|e| !e["edge"].as_array().unwrap().is_empty()));
            assert_eq!(fresh["summary"]["sharp_edges"], 28, "{input} {opts:?}");
        }
    }
}
