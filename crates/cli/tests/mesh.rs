//! `cadmorph mesh check` and `cadmorph mesh morph` on a small polyMesh (crate
//! `cadmorph-mesh`, CLI in `crates/cli/src/mesh.rs`).

use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph::mesh::format::foam::PolyMesh;
use cadmorph::mesh::{Cell, CellKind};
use cadmorph::morph::math::Point3;

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).output().expect("cadmorph runs")
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-cli-mesh-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A 3 × 3 × 3 grid of unit hexahedra as a fresh ASCII polyMesh in `dir`.
fn grid(dir: &Path) -> PolyMesh {
    let n = 3;
    let id = |i: usize, j: usize, k: usize| i + (n + 1) * (j + (n + 1) * k);
    let mut pts = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                pts.push(Point3::new(i as f64, j as f64, k as f64));
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                cells.push(Cell::new(CellKind::Hexahedron, c.to_vec()));
            }
        }
    }
    let m = PolyMesh::from_cells(pts, &cells).unwrap();
    m.write(dir).unwrap();
    m
}

/// An FFD over the grid moving the middle lattice node up by `lift` box heights.
fn ffd_toml(dir: &Path, lift: f64) -> PathBuf {
    let mut mu_z = vec![0.0; 27];
    mu_z[13] = lift; // (1, 1, 1) in C order
    let zeros = vec![0.0; 27];
    let list = |v: &[f64]| v.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", ");
    let text = format!(
        "[ffd]\nn_control_points = [3, 3, 3]\nbox_origin = [-0.01, -0.01, -0.01]\nbox_length = [3.02, 3.02, 3.02]\nmu_x = [{}]\nmu_y = [{}]\nmu_z = [{}]\n",
        list(&zeros),
        list(&zeros),
        list(&mu_z)
    );
    let p = dir.join(format!("lift{lift}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn mesh_check_morph_and_refusal() {
    let dir = temp("grid");
    let poly = dir.join("polyMesh");
    let original = grid(&poly);
    let out = cadmorph(&["mesh", "check", poly.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let q: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(q["cells"], 27);
    assert!((q["total_volume"].as_f64().unwrap() - 27.0).abs() < 1e-12);

    let moved = dir.join("moved");
    let out = cadmorph(&[
        "mesh",
        "morph",
        poly.to_str().unwrap(),
        "-o",
        moved.to_str().unwrap(),
        "--ffd",
        ffd_toml(&dir, 0.1).to_str().unwrap(),
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["after"]["failed"].as_array().unwrap().len(), 0);
    let m = PolyMesh::read(&moved).unwrap();
    assert_ne!(m.points, original.points);
    assert_eq!(std::fs::read(moved.join("faces")).unwrap(), std::fs::read(poly.join("faces")).unwrap());

    // A folding morph: refused, exit code 1, nothing written.
    let folded = dir.join("folded");
    let out = cadmorph(&[
        "mesh",
        "morph",
        poly.to_str().unwrap(),
        "-o",
        folded.to_str().unwrap(),
        "--ffd",
        ffd_toml(&dir, -8.0).to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("negative"), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!folded.exists());
    // With --allow-degrade it is written, and `mesh check` then fails.
    let out = cadmorph(&[
        "mesh",
        "morph",
        poly.to_str().unwrap(),
        "-o",
        folded.to_str().unwrap(),
        "--ffd",
        ffd_toml(&dir, -8.0).to_str().unwrap(),
        "--allow-degrade",
    ]);
    assert!(out.status.success());
    assert_eq!(cadmorph(&["mesh", "check", folded.to_str().unwrap()]).status.code(), Some(1));
    let _ = std::fs::remove_dir_all(dir);
}
