//! Cross-reads with independent readers and writers (`tests/mesh/setup.sh` venv): gmsh
//! meshes a box with a spherical hole into tetrahedra (MSH 2.2 and 4.1), meshio writes
//! the same mesh as legacy VTK, OBJ, STL (ASCII and binary) and Kratos MDPA. cadmorph
//! reads each with the same points and cells as meshio, writes it back unchanged byte for
//! byte, and after a morph writes files meshio reads back with cadmorph's points.
//!
//! UNV and LS-DYNA keyword files, which meshio does not read, are cross-read with gmsh
//! (its UNV reader and writer) and Ansys PyDyna's keyword deck (its reader and writer).
//!
//! `#[ignore]`d in a plain `cargo test`; `scripts/test` runs it.

use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph_mesh::quality::Quality;
use cadmorph_mesh::{CellKind, MeshFile};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{Affine, Deformation};

/// Text formats carry shortest round-trip (or 16-digit) numbers: equal to a few ulps.
const TEXT_MATCH: f64 = 1e-12;
/// Binary STL stores f32.
const F32_MATCH: f64 = 1e-6;

fn venv_python() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/mesh/.venv/bin/python")
}

fn oracle(args: &[&str]) -> String {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/mesh/oracle.py");
    let out = Command::new(venv_python()).arg(script).args(args).output().expect("run tests/mesh/setup.sh first");
    assert!(out.status.success(), "oracle {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// The 16-column cards of a `.k` file carry moved coordinates as `{:.10}` (PyGeM's form).
const DYNA_MATCH: f64 = 1e-10;

fn pygem_data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/pygem-testdata").join(name)
}

struct Meshio {
    points: Vec<Point3<f64>>,
    cells: serde_json::Map<String, serde_json::Value>,
}

fn meshio_read(path: &Path) -> Meshio {
    reader_read("read", path)
}

/// What the oracle's reader `op` (`read`: meshio, `gmsh`, `dyna`: PyDyna) finds in `path`.
fn reader_read(op: &str, path: &Path) -> Meshio {
    let v: serde_json::Value = serde_json::from_str(&oracle(&[op, path.to_str().unwrap()])).unwrap();
    let points = v["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| Point3::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap(), p[2].as_f64().unwrap()))
        .collect();
    Meshio { points, cells: v["cells"].as_object().unwrap().clone() }
}

/// Points in lexicographic order of their coordinates rounded to 1e-6 (so that values a
/// few ulps apart sort alike).
fn sorted(p: &[Point3<f64>]) -> Vec<Point3<f64>> {
    let mut v = p.to_vec();
    let key = |q: &Point3<f64>| q.map(|x| (x * 1e6).round() as i64);
    v.sort_by(|a, b| key(a).iter().cmp(key(b).iter()));
    v
}

fn assert_same_points(ours: &[Point3<f64>], theirs: &[Point3<f64>], tol: f64, unordered: bool, what: &str) {
    assert_eq!(ours.len(), theirs.len(), "{what}: point count");
    let (a, b) = if unordered { (sorted(ours), sorted(theirs)) } else { (ours.to_vec(), theirs.to_vec()) };
    for (i, (p, q)) in a.iter().zip(&b).enumerate() {
        assert!((p - q).norm() <= tol * (1.0 + q.coords.norm()), "{what}: point {i}: {p} vs {q}");
    }
}

fn count(file: &MeshFile, kind: CellKind) -> usize {
    file.cells().iter().filter(|c| c.kind == kind).count()
}

fn meshio_count(m: &Meshio, name: &str) -> usize {
    m.cells.get(name).and_then(|v| v.as_u64()).unwrap_or(0) as usize
}

#[test]
#[ignore = "needs the meshio/gmsh venv (tests/mesh/setup.sh)"]
fn formats_cross_read_with_meshio_and_gmsh() {
    let dir = std::env::temp_dir().join(format!("cadmorph-mesh-cross-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    oracle(&["make", dir.to_str().unwrap()]);
    // cadmorph's own VTU writer (appended raw).
    let msh = MeshFile::read(&dir.join("box41.msh")).unwrap();
    let tets: Vec<_> = msh.cells().into_iter().filter(|c| c.kind == CellKind::Tetra).collect();
    std::fs::write(dir.join("fresh.vtu"), cadmorph_mesh::format::vtu::Vtu::write_unstructured(msh.points(), &tets))
        .unwrap();
    let morph = Affine::translation(Vector3::new(0.1, -0.2, 0.3)).then(Affine::scaling(Vector3::new(1.5, 1.0, 0.5)));
    for (name, tol, unordered) in [
        ("box22.msh", TEXT_MATCH, false),
        ("box41.msh", TEXT_MATCH, false),
        ("box.vtk", TEXT_MATCH, false),
        ("box.obj", TEXT_MATCH, false),
        ("box_ascii.stl", TEXT_MATCH, true),
        ("box_bin.stl", F32_MATCH, true),
        ("box.mdpa", TEXT_MATCH, false),
        ("box_zlib.vtu", TEXT_MATCH, false),
        ("box_b64.vtu", TEXT_MATCH, false),
        ("box_ascii.vtu", TEXT_MATCH, false),
        ("fresh.vtu", TEXT_MATCH, false),
    ] {
        let path = dir.join(name);
        let file = MeshFile::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let theirs = meshio_read(&path);
        // STL stores unmerged corners; meshio and cadmorph both merge equal ones.
        assert_same_points(file.points(), &theirs.points, tol, unordered, name);
        for (kind, mname) in [(CellKind::Tetra, "tetra"), (CellKind::Triangle, "triangle")] {
            assert_eq!(count(&file, kind), meshio_count(&theirs, mname), "{name}: {mname} count");
        }
        // Unchanged write → the same bytes.
        let same = dir.join(format!("same_{name}"));
        file.write(&same).unwrap();
        assert!(std::fs::read(&same).unwrap() == std::fs::read(&path).unwrap(), "{name}: unchanged write differs");
        // Tetrahedra from gmsh are positively oriented in VTK's convention.
        if let Some(poly) = file.volume_mesh().unwrap() {
            let q = Quality::of(&poly);
            assert!(q.ok(), "{name}:\n{}", q.table());
            assert_eq!(q.cells, meshio_count(&theirs, "tetra"));
        }
        // Morph, write, meshio reads cadmorph's points.
        let mut moved = file.clone();
        morph.deform(moved.points_mut());
        let out = dir.join(format!("moved_{name}"));
        moved.write(&out).unwrap();
        let back = meshio_read(&out);
        assert_same_points(moved.points(), &back.points, tol, unordered, &format!("moved {name}"));
        eprintln!("{name}: {} points, {:?}: cross-read OK", file.points().len(), theirs.cells);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// UNV (I-DEAS 2411/2412) through gmsh and LS-DYNA `.k` through PyDyna: files each of
/// them wrote (gmsh's UNV of the box with a hole; PyDyna's deck of its tetrahedra as
/// degenerate hexahedra) and PyGeM's test squares. cadmorph reads the points and cells
/// the independent reader reads, writes an unchanged file back byte for byte, and after a
/// morph writes a file the independent reader reads with cadmorph's points.
#[test]
#[ignore = "needs the meshio/gmsh/PyDyna venv (tests/mesh/setup.sh)"]
fn unv_and_keyword_files_cross_read_with_gmsh_and_pydyna() {
    let scratch = cadmorph_testkit::Scratch::new("mesh-cross-unv-k");
    let dir = scratch.dir();
    oracle(&["make", dir.to_str().unwrap()]);
    let morph = Affine::translation(Vector3::new(0.1, -0.2, 0.3)).then(Affine::scaling(Vector3::new(1.5, 1.0, 0.5)));
    for (path, reader, tol) in [
        (dir.join("box.unv"), "gmsh", TEXT_MATCH),
        (pygem_data("test_square.unv"), "gmsh", TEXT_MATCH),
        (dir.join("box.k"), "dyna", DYNA_MATCH),
        (pygem_data("test_square.k"), "dyna", DYNA_MATCH),
    ] {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let file = MeshFile::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let theirs = reader_read(reader, &path);
        assert_same_points(file.points(), &theirs.points, TEXT_MATCH, false, &name);
        for (kind, rname) in [
            (CellKind::Tetra, "tetra"),
            (CellKind::Triangle, "triangle"),
            (CellKind::Quad, "quad"),
            (CellKind::Hexahedron, "hexahedron"),
        ] {
            assert_eq!(count(&file, kind), meshio_count(&theirs, rname), "{name}: {rname} count");
        }
        let same = dir.join(format!("same_{name}"));
        file.write(&same).unwrap();
        assert!(std::fs::read(&same).unwrap() == std::fs::read(&path).unwrap(), "{name}: unchanged write differs");
        let mut moved = file.clone();
        morph.deform(moved.points_mut());
        let out = dir.join(format!("moved_{name}"));
        moved.write(&out).unwrap();
        let back = reader_read(reader, &out);
        assert_same_points(moved.points(), &back.points, tol, false, &format!("moved {name}"));
        assert_eq!(back.cells, theirs.cells, "moved {name}: cells");
        eprintln!("{name}: {} points, {:?}: cross-read by {reader} OK", file.points().len(), theirs.cells);
    }
}

/// gmsh's unstructured tetrahedra around a sphere (the body): the sphere's nodes move by
/// an FFD that raises a dome on its top, the box stays; the RBF volume morph (Wendland
/// with greedy centres, and a global thin-plate spline) leaves no inverted cell, and the
/// body's nodes are where the FFD puts them to 1e-9 × the box size.
#[test]
#[ignore = "needs the meshio/gmsh venv (tests/mesh/setup.sh)"]
fn rbf_volume_morph_of_a_gmsh_tet_mesh() {
    use cadmorph_mesh::format::foam::PolyMesh;
    use cadmorph_mesh::volume::{morph_volume, BoundaryMorph, Constraint};
    use cadmorph_morph::rbf::Kernel;
    use cadmorph_morph::Ffd;
    const BODY_MATCH: f64 = 1e-9;
    let dir = std::env::temp_dir().join(format!("cadmorph-mesh-vol-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    oracle(&["make", dir.to_str().unwrap()]);
    let file = MeshFile::read(&dir.join("box41.msh")).unwrap();
    let mesh = file.volume_mesh().unwrap().unwrap();
    let centre = Point3::new(1.0, 0.5, 0.5);
    let on_body = |p: &Point3<f64>| ((p - centre).norm() - 0.25).abs() < 1e-6;
    let on_box = |p: &Point3<f64>| p.iter().zip([2.0, 1.0, 1.0]).any(|(&x, l)| x.abs() < 1e-9 || (x - l).abs() < 1e-9);
    // A dome: the top middle of a 3×3×3 lattice over the sphere raised by 0.4 box heights.
    let mut ffd =
        Ffd::try_new([3, 3, 3], Point3::new(0.7, 0.2, 0.2), Vector3::new(0.6, 0.6, 0.6), Vector3::zeros()).unwrap();
    ffd.mu_mut().set(1, 1, 2, [0.0, 0.0, 0.4]);
    let body: Vec<usize> = (0..mesh.points.len()).filter(|&i| on_body(&mesh.points[i])).collect();
    assert!(body.len() > 50);
    let cons: Vec<Constraint> = mesh
        .points
        .iter()
        .map(|p| {
            if on_body(p) {
                Constraint::Moved(ffd.deform_point(p) - p)
            } else if on_box(p) {
                Constraint::Fixed
            } else {
                Constraint::Free
            }
        })
        .collect();
    for options in [
        BoundaryMorph::wendland(1.0),
        BoundaryMorph {
            kernel: Kernel::ThinPlate { radius: 1.0, k: 2 },
            greedy_tol: None,
            initial_centres: 0,
            max_centres: usize::MAX,
            multilevel: None,
        },
    ] {
        let mut m: PolyMesh = mesh.clone();
        let (report, br) =
            morph_volume(&mut m, &cons, &options, false).unwrap_or_else(|e| panic!("{:?}: {e}", options.kernel));
        eprintln!(
            "{:?}: {} constrained, {} centres, {} rounds, min volume {:e}",
            options.kernel, br.constrained, br.centres, br.rounds, report.after.min_volume.value
        );
        assert_eq!(report.after.negative_volumes, 0);
        assert_eq!(report.after.pyramid_errors, 0);
        let lift = body.iter().map(|&i| m.points[i].z - mesh.points[i].z).fold(0.0, f64::max);
        assert!(lift > 0.05, "the dome rises ({lift})");
        for &i in &body {
            assert!((m.points[i] - ffd.deform_point(&mesh.points[i])).norm() <= BODY_MATCH * 2.0);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
