//! `cadmorph seams` on solids as OCCT's own writers make them (`tests/occt/writer_solids.py`:
//! a turned fillet box, a whole torus, an extruded closed B-spline, each as STEP, IGES
//! B-rep and IGES faces): the shared edges are those of OCCT's topology
//! (`tests/occt/topo_check.py`), and every one is closed as OCCT measures it. Before the
//! fixes these tests pin, the fillet corners' spheres (poles on their edges) read 0.55 mm
//! gaps from IGES, the torus's closing seams 50 mm, the extrusion 0.99 mm (OCCT: ≤ 1e-11).

mod common;

use std::collections::BTreeMap;
use std::process::Command;

use cadmorph_testkit::harness;
use common::{cadmorph, stderr, Scratch};
use serde_json::Value;

fn topo_check(file: &std::path::Path) -> Value {
    let out = Command::new(harness::python())
        .arg(harness::root().join("tests/occt/topo_check.py"))
        .arg(file)
        .output()
        .expect("topo_check.py starts");
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("topo_check.py {}: {e}\n{}", file.display(), String::from_utf8_lossy(&out.stderr)))
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn seams_of_occt_written_solids_are_occt_topology_and_closed() {
    let dir = Scratch::new("writer-solids");
    let out = Command::new(harness::python())
        .arg(harness::root().join("tests/occt/writer_solids.py"))
        .arg("make")
        .arg(dir.dir())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // OCCT's writers print their progress to stdout too: the JSON is the last line.
    let text = String::from_utf8_lossy(&out.stdout);
    let made: Value = serde_json::from_str(text.lines().rfind(|l| !l.trim().is_empty()).unwrap()).unwrap();
    let files: Vec<String> = made["files"].as_array().unwrap().iter().map(|f| f.as_str().unwrap().to_owned()).collect();
    assert_eq!(files.len(), 9);
    for file in &files {
        let occt = topo_check(std::path::Path::new(file));
        let size = occt["size"].as_f64().unwrap();
        let theirs: BTreeMap<(u64, u64), f64> = occt["edges"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| {
                ((e["faces"][0].as_u64().unwrap(), e["faces"][1].as_u64().unwrap()), e["max_gap"].as_f64().unwrap())
            })
            .collect();
        let r = cadmorph(&["seams", file, "--json"]);
        assert!(r.status.success(), "{file}: {}", stderr(&r));
        let json: Value = serde_json::from_slice(&r.stdout).unwrap();
        let mut ours: BTreeMap<(u64, u64), f64> = BTreeMap::new();
        for e in json["edges"].as_array().unwrap() {
            let (a, b) = (e["a"]["face"]["index"].as_u64().unwrap(), e["b"]["face"]["index"].as_u64().unwrap());
            let gap = e["gap_closest"]["max"].as_f64().unwrap();
            if a == b {
                // A closing seam (OCCT's topology lists no edge of a face with itself):
                // it must be closed all the same.
                assert!(gap <= 1e-9 * size, "{file}: closing seam of face {a}: gap {gap:e}");
                continue;
            }
            let g = ours.entry((a.min(b), a.max(b))).or_insert(0.0);
            *g = g.max(gap);
        }
        let keys = |m: &BTreeMap<(u64, u64), f64>| m.keys().copied().collect::<Vec<_>>();
        assert_eq!(keys(&ours), keys(&theirs), "{file}: the shared edges are OCCT's");
        for (k, gap) in &ours {
            // OCCT measures every edge of these files closed to 3e-11; cadmorph within
            // 1e-7 of the size (known: the turned fillet box's STEP sphere corners read
            // up to 2.2e-6 of 60 mm, see the closing note of issue 22).
            assert!(*gap <= 1e-7 * size, "{file}: edge {k:?}: gap {gap:e} where OCCT has {:e}", theirs[k]);
        }
    }
}
