//! `PolyMesh::read` streams the `faces`, `owner` and `neighbour` lists and keeps them on
//! disk instead of in memory: these tests hold it to the lossless contract of a reader
//! that keeps the bytes (every file written back as read, also when the mesh is written
//! over its own directory, again and again), and to the whole-file readers' values.

use std::path::{Path, PathBuf};

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::{Cell, CellKind};
use cadmorph_morph::math::Point3;

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-foam-streamed-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A block of `n`³ hexahedra written as a fresh ASCII polyMesh in `dir`.
fn block(dir: &Path, n: usize) {
    let id = |i: usize, j: usize, k: usize| (k * (n + 1) + j) * (n + 1) + i;
    let mut pts = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                pts.push(Point3::new(i as f64, j as f64 * 0.5, k as f64 * 0.25));
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)];
                cells.push(Cell::new(CellKind::Hexahedron, v.iter().map(|d| id(i + d.0, j + d.1, k + d.2)).collect()));
            }
        }
    }
    PolyMesh::from_cells(pts, &cells).unwrap().write(dir).unwrap();
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap())
        })
        .collect();
    v.sort();
    v
}

#[test]
fn streamed_lists_are_written_back_as_read_also_over_their_own_directory() {
    let dir = temp("inplace");
    block(&dir, 9);
    // An extra file and a comment in `faces` that only a byte-keeping writer preserves.
    std::fs::write(dir.join("cellZones"), "FoamFile { format ascii; class regIOobject; }\n0\n(\n)\n").unwrap();
    let faces = std::fs::read_to_string(dir.join("faces")).unwrap();
    std::fs::write(dir.join("faces"), format!("// written by hand\n{faces}")).unwrap();
    let before = files(&dir);

    let mut mesh = PolyMesh::read(&dir).unwrap();
    // Unchanged: every file as it was.
    let out = temp("copy");
    mesh.write(&out).unwrap();
    assert_eq!(files(&out), before);
    // Moved, written over its own directory twice: only `points` changes, and the
    // second write copies the topology files the first one put there.
    for step in 1..=2 {
        mesh.points[5].x += 0.01;
        mesh.write(&dir).unwrap();
        let now = files(&dir);
        assert_eq!(now.len(), before.len());
        for ((n, b), (n0, b0)) in now.iter().zip(&before) {
            assert_eq!(n, n0);
            assert_eq!(b == b0, n != "points", "step {step}: {n}");
        }
        let again = PolyMesh::read(&dir).unwrap();
        assert_eq!(again.points, mesh.points);
        assert!((0..mesh.n_faces()).all(|f| again.face(f) == mesh.face(f)));
        assert_eq!((again.owner(), again.neighbour()), (mesh.owner(), mesh.neighbour()));
    }
}

#[test]
fn files_changed_or_gone_under_a_read_mesh_are_written_afresh_from_it() {
    let dir = temp("changed");
    block(&dir, 3);
    let mut mesh = PolyMesh::read(&dir).unwrap();
    // Another owner list in place of the one read, and the faces file gone: writing the
    // mesh must not pair its points with the other list, nor fail.
    let owner = std::fs::read_to_string(dir.join("owner")).unwrap();
    let k = owner.rfind("\n0\n").unwrap();
    std::fs::write(dir.join("owner"), format!("{}\n1\n{}", &owner[..k], &owner[k + 3..])).unwrap();
    std::fs::remove_file(dir.join("faces")).unwrap();
    mesh.points[0].z -= 0.125;
    let out = temp("changed-out");
    mesh.write(&out).unwrap();
    let again = PolyMesh::read(&out).unwrap();
    assert_eq!(again.points, mesh.points);
    assert_eq!((again.owner(), again.neighbour()), (mesh.owner(), mesh.neighbour()));
    assert!((0..mesh.n_faces()).all(|f| again.face(f) == mesh.face(f)));
    // The points file gone too: written afresh as well.
    std::fs::remove_file(dir.join("points")).unwrap();
    let out2 = temp("changed-out2");
    mesh.write(&out2).unwrap();
    assert_eq!(PolyMesh::read(&out2).unwrap().points, mesh.points);
}
