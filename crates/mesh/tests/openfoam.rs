//! OpenFOAM itself as the oracle (Debian `openfoam` v1912, installed by
//! `tests/mesh/setup.sh`): `blockMesh` makes a channel with a bump, cadmorph reads it,
//! checks it, morphs it (FFD) and writes it; `checkMesh` on each mesh reports the same cell
//! count, "Mesh OK." and the same max non-orthogonality and skewness as cadmorph's check.
//! A folding morph is refused, and `checkMesh` confirms it folds when written anyway.
//!
//! `#[ignore]`d in a plain `cargo test`; `scripts/test` runs it.

use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::morph::morph_checked;
use cadmorph_mesh::quality::Quality;
use cadmorph_mesh::Error;
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::Ffd;

/// checkMesh prints with `writePrecision` 17 (set in the case's controlDict); the same
/// formulas in the same order agree to rounding, far inside this relative tolerance.
const CHECKMESH_MATCH: f64 = 1e-6;

const BASHRC: &str = "/usr/share/openfoam/etc/bashrc";

fn foam(case: &Path, cmd: &str) -> String {
    let out = Command::new("bash")
        .arg("-c")
        .arg(format!("source {BASHRC} >/dev/null 2>&1; cd '{}' && {cmd} 2>&1", case.display()))
        .output()
        .expect("bash runs");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

const CONTROL: &str = "FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }
application icoFoam; startFrom startTime; startTime 0; stopAt endTime; endTime 1; deltaT 1;
writeControl timeStep; writeInterval 1; purgeWrite 0; writeFormat ascii; writePrecision 17;
writeCompression off; timeFormat general; timePrecision 6; runTimeModifiable true;
";

/// A channel 3 × 1 × 0.3 whose bottom bulges up to y = 0.25 in the middle (arc edges),
/// 30 × 12 × 3 cells graded towards the bottom.
const BLOCK_MESH: &str = "FoamFile { version 2.0; format ascii; class dictionary; object blockMeshDict; }
convertToMeters 1;
vertices ( (0 0 0) (3 0 0) (3 1 0) (0 1 0) (0 0 0.3) (3 0 0.3) (3 1 0.3) (0 1 0.3) );
blocks ( hex (0 1 2 3 4 5 6 7) (30 12 3) simpleGrading (1 4 1) );
edges ( arc 0 1 (1.5 0.25 0) arc 4 5 (1.5 0.25 0.3) );
boundary
(
    inlet { type patch; faces ((0 4 7 3)); }
    outlet { type patch; faces ((1 2 6 5)); }
    bump { type wall; faces ((0 1 5 4)); }
    top { type wall; faces ((3 7 6 2)); }
    sides { type wall; faces ((0 3 2 1) (4 5 6 7)); }
);
";

/// checkMesh builds the finite-volume schemes, so they must exist.
const FV_SCHEMES: &str = "FoamFile { version 2.0; format ascii; class dictionary; object fvSchemes; }
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }
divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; } snGradSchemes { default corrected; }
";

fn make_case(dir: &Path) {
    std::fs::create_dir_all(dir.join("system")).unwrap();
    std::fs::write(dir.join("system/controlDict"), CONTROL).unwrap();
    std::fs::write(dir.join("system/blockMeshDict"), BLOCK_MESH).unwrap();
    std::fs::write(dir.join("system/fvSchemes"), FV_SCHEMES).unwrap();
    std::fs::write(
        dir.join("system/fvSolution"),
        "FoamFile { version 2.0; format ascii; class dictionary; object fvSolution; }\n",
    )
    .unwrap();
    let log = foam(dir, "blockMesh");
    assert!(log.contains("End"), "blockMesh failed:\n{log}");
}

/// The numbers of a checkMesh log.
struct CheckMesh {
    cells: usize,
    ok: bool,
    max_non_orth: f64,
    skewness: f64,
    min_volume: f64,
    log: String,
}

fn number_after<'a>(log: &'a str, key: &str) -> Option<&'a str> {
    let at = log.find(key)? + key.len();
    log[at..].split_whitespace().next().map(|s| s.trim_end_matches([',', '.']).trim_end_matches('.'))
}

fn check_mesh(case: &Path) -> CheckMesh {
    let log = foam(case, "checkMesh");
    let num = |key: &str| -> f64 {
        number_after(&log, key)
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no {key:?} in checkMesh log:\n{log}"))
    };
    CheckMesh {
        cells: num("    cells:") as usize,
        ok: log.contains("\nMesh OK."),
        max_non_orth: num("Mesh non-orthogonality Max:"),
        skewness: num("Max skewness = "),
        min_volume: num("Min volume = "),
        log,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

fn compare(case: &Path, what: &str) -> Quality {
    let mesh = PolyMesh::read(case).unwrap();
    let q = Quality::of(&mesh);
    let cm = check_mesh(case);
    assert_eq!(q.cells, cm.cells, "{what}: cell count");
    assert!(cm.ok, "{what}: checkMesh does not say Mesh OK:\n{}", cm.log);
    assert!(q.ok(), "{what}: cadmorph fails the mesh:\n{}", q.table());
    let (no, sk) = (rel(q.max_non_orthogonality.value, cm.max_non_orth), rel(q.max_skewness.value, cm.skewness));
    eprintln!(
        "{what}: max non-orthogonality cadmorph {} checkMesh {} (rel {no:e}); max skewness cadmorph {} checkMesh {} (rel {sk:e}); min volume {} vs {}",
        q.max_non_orthogonality.value, cm.max_non_orth, q.max_skewness.value, cm.skewness, q.min_volume.value, cm.min_volume
    );
    assert!(
        no <= CHECKMESH_MATCH,
        "{what}: non-orthogonality {} vs {}",
        q.max_non_orthogonality.value,
        cm.max_non_orth
    );
    assert!(sk <= CHECKMESH_MATCH, "{what}: skewness {} vs {}", q.max_skewness.value, cm.skewness);
    assert!(rel(q.min_volume.value, cm.min_volume) <= CHECKMESH_MATCH);
    q
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-mesh-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn copy_case(from: &Path, to: &Path) {
    let st = Command::new("cp").arg("-r").arg(from).arg(to).status().unwrap();
    assert!(st.success());
}

/// An FFD over the channel that raises the middle of the lattice by `lift` box heights.
fn lift_ffd(lift: f64) -> Ffd {
    let mut ffd =
        Ffd::try_new([3, 3, 2], Point3::new(-0.01, -0.01, -0.01), Vector3::new(3.02, 1.02, 0.32), Vector3::zeros())
            .unwrap();
    for k in 0..2 {
        ffd.mu_mut().set(1, 1, k, [0.0, lift, 0.0]);
    }
    ffd
}

#[test]
#[ignore = "needs OpenFOAM (tests/mesh/setup.sh)"]
fn checkmesh_agrees_before_and_after_a_morph() {
    let base = temp("bump");
    make_case(&base);
    let before = compare(&base, "blockMesh channel");
    assert_eq!(before.cells, 30 * 12 * 3);
    assert!(before.max_non_orthogonality.value > 1.0, "the bump makes the mesh non-orthogonal");

    // Unchanged read → write keeps every byte of the polyMesh.
    let mesh = PolyMesh::read(&base).unwrap();
    let same = temp("same");
    mesh.write(&same).unwrap();
    for f in ["points", "faces", "owner", "neighbour", "boundary"] {
        assert_eq!(
            std::fs::read(same.join(f)).unwrap(),
            std::fs::read(base.join("constant/polyMesh").join(f)).unwrap(),
            "{f}"
        );
    }

    // A moderate morph: written, and checkMesh agrees.
    let morphed = temp("morphed");
    copy_case(&base, &morphed);
    let mut mesh = PolyMesh::read(&morphed).unwrap();
    let report = morph_checked(&mut mesh, &lift_ffd(0.1), false).unwrap();
    assert!(report.after.ok());
    mesh.write(&morphed.join("constant/polyMesh")).unwrap();
    let after = compare(&morphed, "after FFD lift 0.1");
    assert!(after.max_non_orthogonality.value != before.max_non_orthogonality.value);
    assert_eq!(after, report.after);

    // A folding morph (the middle of the lattice pushed far below the bump) is refused and
    // leaves the mesh as it was.
    let mut mesh = PolyMesh::read(&base).unwrap();
    let points = mesh.points.clone();
    match morph_checked(&mut mesh, &lift_ffd(-4.0), false) {
        Err(Error::Degraded { summary, .. }) => eprintln!("refused: {summary}"),
        other => panic!("folding morph not refused: {other:?}"),
    }
    assert_eq!(mesh.points, points);
    // Written anyway, checkMesh finds it broken too.
    let folded = temp("folded");
    copy_case(&base, &folded);
    let report = morph_checked(&mut mesh, &lift_ffd(-4.0), true).unwrap();
    assert!(report.after.negative_volumes > 0);
    mesh.write(&folded.join("constant/polyMesh")).unwrap();
    let log = foam(&folded, "checkMesh");
    assert!(log.contains("Failed") && !log.contains("\nMesh OK."), "checkMesh accepts the folded mesh:\n{log}");
    let negative: usize = number_after(&log, "Number of negative volume cells:")
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{log}"));
    eprintln!("folded: checkMesh negative volume cells {negative}, cadmorph {}", report.after.negative_volumes);
    assert_eq!(negative, report.after.negative_volumes);
    for d in [base, same, morphed, folded] {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// The same mesh converted by OpenFOAM's `foamFormatConvert` to binary, and to binary with
/// the files gzipped (v1912's converter leaves the polyMesh uncompressed, so `gzip` does
/// it; OpenFOAM reads `points.gz` transparently): cadmorph reads the same points and faces, writes a morph back in the same format
/// (binary, gzipped), and checkMesh reads that and agrees with cadmorph's check.
#[test]
#[ignore = "needs OpenFOAM (tests/mesh/setup.sh)"]
fn binary_and_compressed_polymesh() {
    let base = temp("ascii");
    make_case(&base);
    let ascii = PolyMesh::read(&base).unwrap();
    for (name, compression) in [("binary", "off"), ("binarygz", "on")] {
        let case = temp(name);
        copy_case(&base, &case);
        let cd = CONTROL.replace("writeFormat ascii", "writeFormat binary");
        std::fs::write(case.join("system/controlDict"), cd).unwrap();
        let log = foam(&case, "foamFormatConvert -constant");
        assert!(log.contains("End"), "{log}");
        let poly = case.join("constant/polyMesh");
        if compression == "on" {
            let st = Command::new("gzip")
                .current_dir(&poly)
                .args(["points", "faces", "owner", "neighbour"])
                .status()
                .unwrap();
            assert!(st.success());
        }
        let points_file = if compression == "on" { poly.join("points.gz") } else { poly.join("points") };
        assert!(points_file.is_file(), "{name}: no {}", points_file.display());
        let mesh = PolyMesh::read(&case).unwrap();
        assert_eq!(mesh.points, ascii.points, "{name}: points");
        assert_eq!(mesh.n_faces(), ascii.n_faces());
        assert!((0..mesh.n_faces()).all(|f| mesh.face(f) == ascii.face(f)), "{name}: faces");
        assert_eq!(mesh.owner(), ascii.owner());
        assert_eq!(mesh.neighbour(), ascii.neighbour());
        // Unchanged write keeps the bytes, compressed or not.
        let files = mesh.to_files().unwrap();
        for (rel, bytes) in &files {
            assert_eq!(bytes, &std::fs::read(poly.join(rel)).unwrap(), "{name}: {}", rel.display());
        }
        let mut mesh = mesh;
        morph_checked(&mut mesh, &lift_ffd(0.1), false).unwrap();
        mesh.write(&poly).unwrap();
        assert!(points_file.is_file());
        compare(&case, &format!("{name} after FFD lift 0.1"));
        let _ = std::fs::remove_dir_all(case);
    }
    let _ = std::fs::remove_dir_all(base);
}

/// Boundary → interior: only the bump patch moves (the FFD applied to its nodes), the top,
/// inlet and outlet are fixed, the side planes slide; the Wendland RBF with greedy
/// centres carries the motion inside. checkMesh on the written mesh agrees with cadmorph.
#[test]
#[ignore = "needs OpenFOAM (tests/mesh/setup.sh)"]
fn rbf_volume_morph_of_the_bump_passes_checkmesh() {
    use cadmorph_mesh::volume::{morph_volume, patch_constraints, BoundaryMorph, Constraint, PatchMotion};
    use cadmorph_morph::Deformation;
    let case = temp("volume");
    make_case(&case);
    let mut mesh = PolyMesh::read(&case).unwrap();
    let original = mesh.points.clone();
    let ffd = lift_ffd(0.15);
    let cons = patch_constraints(
        &mesh,
        &[("bump", PatchMotion::Follow(&ffd)), ("top", PatchMotion::Fixed), ("sides", PatchMotion::Slip)],
    )
    .unwrap();
    let (report, br) = morph_volume(&mut mesh, &cons, &BoundaryMorph::wendland(1.5), false).unwrap();
    eprintln!(
        "volume morph: {} constrained nodes, {} centres, {} rounds, max miss {:e}",
        br.constrained, br.centres, br.rounds, br.max_relative_error
    );
    assert!(br.centres < br.constrained, "greedy selection uses a subset");
    assert!(report.after.ok(), "{}", report.after.table());
    for (i, c) in cons.iter().enumerate() {
        match c {
            Constraint::Moved(_) => assert!((mesh.points[i] - ffd.deform_point(&original[i])).norm() < 1e-12),
            Constraint::Fixed => assert_eq!(mesh.points[i], original[i]),
            Constraint::Slip(n) => assert!((mesh.points[i] - original[i]).dot(n).abs() < 1e-12),
            Constraint::Free => {}
        }
    }
    let interior_moved =
        cons.iter().enumerate().filter(|(i, c)| **c == Constraint::Free && mesh.points[*i] != original[*i]).count();
    assert!(interior_moved > 0);
    mesh.write(&case.join("constant/polyMesh")).unwrap();
    compare(&case, "after RBF volume morph");
    let _ = std::fs::remove_dir_all(case);
}

/// The same boundary → interior morph with the multilevel interpolation
/// (`BoundaryMorph::wendland_multilevel`): every constrained node where it was sent, the
/// written mesh passes checkMesh and checkMesh agrees with cadmorph.
#[test]
#[ignore = "needs OpenFOAM (tests/mesh/setup.sh)"]
fn multilevel_rbf_volume_morph_passes_checkmesh() {
    use cadmorph_mesh::volume::{morph_volume, patch_constraints, BoundaryMorph, Constraint, PatchMotion};
    use cadmorph_morph::Deformation;
    let case = temp("volume-multilevel");
    make_case(&case);
    let mut mesh = PolyMesh::read(&case).unwrap();
    let original = mesh.points.clone();
    let ffd = lift_ffd(0.15);
    let cons = patch_constraints(
        &mesh,
        &[("bump", PatchMotion::Follow(&ffd)), ("top", PatchMotion::Fixed), ("sides", PatchMotion::Slip)],
    )
    .unwrap();
    let (report, br) = morph_volume(&mut mesh, &cons, &BoundaryMorph::wendland_multilevel(1.5), false).unwrap();
    eprintln!(
        "multilevel volume morph: {} constrained nodes, {} centres in levels {:?}, max miss {:e}",
        br.constrained, br.centres, br.level_centres, br.max_relative_error
    );
    assert!(br.max_relative_error <= 1e-3);
    assert!(report.after.ok(), "{}", report.after.table());
    for (i, c) in cons.iter().enumerate() {
        match c {
            Constraint::Moved(_) => assert!((mesh.points[i] - ffd.deform_point(&original[i])).norm() < 1e-12),
            Constraint::Fixed => assert_eq!(mesh.points[i], original[i]),
            Constraint::Slip(n) => assert!((mesh.points[i] - original[i]).dot(n).abs() < 1e-12),
            Constraint::Free => {}
        }
    }
    mesh.write(&case.join("constant/polyMesh")).unwrap();
    let q = compare(&case, "after multilevel RBF volume morph");
    assert_eq!(q.negative_volumes, 0);
    let _ = std::fs::remove_dir_all(case);
}

/// OpenFOAM's own VTK XML writer (`foamToVTK`: single-quoted attributes, inline base64,
/// `UInt64` headers, Float32 points) read by cadmorph: the same points as the polyMesh (to
/// f32) and one hexahedron per cell; a morph written back is read again exactly.
#[test]
#[ignore = "needs OpenFOAM (tests/mesh/setup.sh)"]
fn foam_to_vtk_output_reads() {
    use cadmorph_mesh::format::vtu::Vtu;
    use cadmorph_mesh::CellKind;
    let case = temp("vtk");
    make_case(&case);
    let log = foam(&case, "foamToVTK -noZero");
    assert!(log.contains("End"), "{log}");
    let vtu = std::fs::read_dir(case.join("VTK"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.is_dir())
        .map(|d| d.join("internal.vtu"))
        .unwrap();
    let bytes = std::fs::read(&vtu).unwrap();
    let mut v = Vtu::parse(&bytes).unwrap();
    let mesh = PolyMesh::read(&case).unwrap();
    assert_eq!(v.points.len(), mesh.points.len());
    for (p, q) in v.points.iter().zip(&mesh.points) {
        assert_eq!(*p, q.map(|x| x as f32 as f64));
    }
    assert_eq!(v.cells.iter().filter(|c| c.kind == CellKind::Hexahedron).count(), mesh.n_cells());
    assert_eq!(v.write(), bytes);
    for p in &mut v.points {
        p.y *= 1.5;
    }
    let back = Vtu::parse(&v.write()).unwrap();
    assert_eq!(back.points, v.points.iter().map(|p| p.map(|x| x as f32 as f64)).collect::<Vec<_>>());
    assert_eq!(back.cells, v.cells);
    let _ = std::fs::remove_dir_all(case);
}
