//! `cadmorph mesh from-cad` (issue 15, item 5): the watertight tessellation of the open
//! sample hull, the trimmed solid `mixed_solid.stp` and a blade solid built by
//! `cadmorph blade build`. Read back (merging vertices by their exact coordinates, as
//! the STL holds them) and by meshio: every edge has two triangles on the closed models,
//! one or two on the open hull; OpenCASCADE measures every vertex on the CAD faces and
//! every triangle centroid within the chordal tolerance of them; OpenFOAM's
//! `surfaceCheck` finds no illegal triangle, one region per face and one consistently
//! oriented zone, and the solids closed with their normals out.
//!
//! `#[ignore]`d in a plain `cargo test`; `scripts/test` runs it with the OCCT and mesh
//! venvs set up.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph_testkit::Scratch;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

/// An ASCII STL read back: vertices merged by their exact text, triangles, solids.
struct StlBack {
    points: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    solids: usize,
}

fn read_stl(path: &Path) -> StlBack {
    let text = std::fs::read_to_string(path).unwrap();
    let (mut index, mut points, mut triangles, mut solids) = (HashMap::new(), Vec::new(), Vec::new(), 0);
    let mut corner = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"solid") => solids += 1,
            Some(&"vertex") => {
                let key = w[1..4].join(" ");
                let n = index.len();
                let i = *index.entry(key).or_insert(n);
                if i == points.len() {
                    points.push([w[1].parse().unwrap(), w[2].parse().unwrap(), w[3].parse().unwrap()]);
                }
                corner.push(i);
                if corner.len() == 3 {
                    triangles.push([corner[0], corner[1], corner[2]]);
                    corner.clear();
                }
            }
            _ => {}
        }
    }
    StlBack { points, triangles, solids }
}

fn python(venv: &str, args: &[&str]) -> serde_json::Value {
    let out = Command::new(root().join(venv)).args(args).output().expect("run scripts/test's setup first");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
#[ignore = "needs the OCCT and mesh venvs (tests/occt/setup.sh, tests/mesh/setup.sh)"]
fn from_cad_meshes_are_watertight_and_on_the_cad() {
    let scratch = Scratch::new("cli-from-cad");
    let blade = scratch.dir().join("blade.stp");
    let built = cadmorph(&["blade", "build", "samples/blade/tutorial.toml", "-o", blade.to_str().unwrap()]);
    assert!(built.status.success(), "{}", String::from_utf8_lossy(&built.stderr));
    for (input, closed) in [
        (root().join("samples/hull3.igs"), false),
        (root().join("samples/mixed_solid.stp"), true),
        (blade.clone(), true),
    ] {
        let name = input.file_name().unwrap().to_string_lossy().into_owned();
        let stl = scratch.dir().join(format!("{name}.stl"));
        let out = cadmorph(&["mesh", "from-cad", input.to_str().unwrap(), "-o", stl.to_str().unwrap(), "--json"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let back = read_stl(&stl);
        assert_eq!(back.points.len() as u64, report["points"].as_u64().unwrap(), "{name}: no two vertices coincide");
        assert_eq!(back.triangles.len() as u64, report["triangles"].as_u64().unwrap(), "{name}");
        assert_eq!(back.solids as u64, report["faces"].as_u64().unwrap(), "{name}: a solid per face");
        // Every edge two triangles (closed), one or two (open), never more.
        let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
        for t in &back.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let border = uses.values().filter(|&&n| n == 1).count();
        assert!(uses.values().all(|&n| n == 1 || n == 2), "{name}: an edge with more than two triangles");
        if closed {
            assert_eq!(border, 0, "{name}: closed model with border edges");
        } else {
            assert!(border > 0, "{name}: the open hull has no border");
        }
        assert_eq!(border as u64, report["border_edges"].as_u64().unwrap());
        // OpenFOAM's own surface check: no illegal triangle, a region per face, one
        // consistently oriented zone, closed where the model is.
        let cmd = format!("source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1; surfaceCheck '{}'", stl.display());
        let out = Command::new("bash").args(["-c", &cmd]).output().unwrap();
        let log = String::from_utf8_lossy(&out.stdout);
        assert!(log.contains("Surface has no illegal triangles."), "{name}: surfaceCheck\n{log}");
        let regions = format!("in {} region(s)", report["faces"].as_u64().unwrap());
        assert!(log.contains(&regions), "{name}: surfaceCheck regions\n{log}");
        assert!(log.contains("consistent normal) : 1"), "{name}: surfaceCheck zones\n{log}");
        if closed {
            assert!(log.contains("Surface is closed. All edges connected to two faces."), "{name}:\n{log}");
            // Normals out: the divergence theorem gives a positive volume.
            let volume: f64 = back
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| back.points[i]);
                    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                        + a[2] * (b[0] * c[1] - b[1] * c[0]))
                        / 6.0
                })
                .sum();
            assert!(volume > 0.0, "{name}: normals point in (volume {volume})");
        }
        // meshio reads the same mesh.
        let m = python(
            "tests/mesh/.venv/bin/python",
            &[root().join("tests/mesh/oracle.py").to_str().unwrap(), "read", stl.to_str().unwrap()],
        );
        assert_eq!(m["cells"]["triangle"].as_u64().unwrap(), back.triangles.len() as u64, "{name}: meshio");
        assert_eq!(m["points"].as_array().unwrap().len(), back.points.len(), "{name}: meshio points");
        // OCCT: vertices on the faces, centroids within the chordal tolerance (at most
        // 1500 of each, evenly spread).
        let chord = report["chord_tolerance"].as_f64().unwrap();
        let spread = |n: usize| (n / 1500).max(1);
        let vertices: Vec<[f64; 3]> = back.points.iter().step_by(spread(back.points.len())).copied().collect();
        let centroids: Vec<[f64; 3]> = back
            .triangles
            .iter()
            .step_by(spread(back.triangles.len()))
            .map(|t| {
                let p = t.map(|i| back.points[i]);
                std::array::from_fn(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0)
            })
            .collect();
        for (what, pts) in [("vertices", &vertices), ("centroids", &centroids)] {
            let file = scratch.dir().join(format!("{name}.{what}.json"));
            std::fs::write(&file, serde_json::to_vec(pts).unwrap()).unwrap();
            let r = python(
                "tests/occt/.venv/bin/python",
                &[
                    root().join("tests/occt/mesh_check.py").to_str().unwrap(),
                    input.to_str().unwrap(),
                    file.to_str().unwrap(),
                ],
            );
            let d = r["max_distance"].as_f64().unwrap();
            // Vertices are surface points (OCCT's and cadmorph's evaluations agree to
            // rounding); centroids lie within the chordal tolerance.
            let limit = if what == "vertices" { 1e-9 * r["size"].as_f64().unwrap() } else { chord };
            eprintln!("{name}: {} {what}: OCCT distance to the model ≤ {d:e} (limit {limit:e})", pts.len());
            assert!(
                d <= limit * (1.0 + 1e-9),
                "{name}: {what} off the CAD by {d:e} > {limit:e} (point {})",
                r["worst"]
            );
        }
    }
}
