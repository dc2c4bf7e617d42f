//! PyGeM's mesh-handler tests (GitHub mathLab/PyGeM, `tests/test_*handler.py`), reproduced:
//! the same input, the same points changed, and the expected output files of PyGeM's test
//! data (`../shared/pygem-testdata`). `write_pygem` must give PyGeM's file byte for byte;
//! the lossless `write` must give the same points to 1e-10 and every other line unchanged.

use std::path::PathBuf;

use cadmorph_mesh::format::{dyna::KeywordFile, elmer::ElmerNodes, foam::FoamPoints, mdpa::Mdpa, unv::Unv};
use cadmorph_morph::math::Point3;

/// PyGeM's expected outputs hold numbers with 10 to 17 significant digits; a point read
/// back from our output equals theirs to this (absolute, coordinates of order 1–300).
const PYGEM_MATCH: f64 = 1e-10;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/pygem-testdata").join(name)
}

fn text(name: &str) -> String {
    std::fs::read_to_string(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn set(points: &mut [Point3<f64>], idx: isize, p: [f64; 3]) {
    let i = if idx < 0 { (points.len() as isize + idx) as usize } else { idx as usize };
    points[i] = Point3::from(p);
}

fn set_component(points: &mut [Point3<f64>], i: usize, c: usize, v: f64) {
    points[i][c] = v;
}

fn assert_points_near(a: &[Point3<f64>], b: &[Point3<f64>]) {
    assert_eq!(a.len(), b.len());
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        assert!((p - q).norm() <= PYGEM_MATCH, "point {i}: {p} vs {q}");
    }
}

/// The edits of `test_*_write_comparison_2` in PyGeM's unv/k tests.
fn square_edits(points: &mut [Point3<f64>]) {
    set_component(points, 0, 0, 2.2);
    set_component(points, 5, 1, 4.3);
    set_component(points, 9, 2, 0.5);
    set_component(points, 45, 0, 7.2);
    set_component(points, 132, 1, -1.2);
    set_component(points, 255, 2, -3.6);
}

#[test]
fn openfoam_points_like_pygem() {
    let input = std::fs::read(data("test_openFOAM")).unwrap();
    let mut f = FoamPoints::parse(&input).unwrap();
    assert_eq!(f.points.len(), 21812);
    assert_eq!(f.write().unwrap(), input, "unchanged write is the input");
    let p = &mut f.points;
    set(p, 0, [-14., 1.55, 0.2]);
    set(p, 1, [-14.3, 2.55, 0.3]);
    set(p, 2, [-14.3, 2.55, 0.3]);
    set(p, 2000, [7.8, -42.8, 0.0]);
    set(p, 2001, [8.8, -41.8, 0.1]);
    set(p, 2002, [9.8, -40.8, 0.0]);
    set(p, -3, [236.3, 183.7, 0.06]);
    set(p, -2, [237.3, 183.7, 0.06]);
    set(p, -1, [236.3, 185.7, 0.06]);
    let expected = std::fs::read(data("test_openFOAM_out_true")).unwrap();
    assert!(f.write_pygem().unwrap() == expected, "PyGeM-style output differs from test_openFOAM_out_true");
    let ours = FoamPoints::parse(&f.write().unwrap()).unwrap();
    assert_points_near(&ours.points, &FoamPoints::parse(&expected).unwrap().points);
}

#[test]
fn unv_like_pygem() {
    let input = text("test_square.unv");
    let mut f = Unv::parse(&input).unwrap();
    assert_eq!(f.write(), input);
    assert_eq!(f.write_pygem(), input, "PyGeM's test_unv_write_comparison_1");
    square_edits(&mut f.points);
    let expected = text("test_square_out_true.unv");
    assert_eq!(f.write_pygem(), expected);
    assert_eq!(f.write(), expected);
    assert_points_near(&Unv::parse(&f.write()).unwrap().points, &Unv::parse(&expected).unwrap().points);
}

#[test]
fn mdpa_like_pygem() {
    let input = text("test_square.mdpa");
    let mut f = Mdpa::parse(&input).unwrap();
    assert_eq!(f.write(), input);
    assert_eq!(f.write_pygem(), input, "PyGeM's test_mdpa_write_comparison_1");
    let p = &mut f.points;
    set_component(p, 0, 0, 0.0);
    set_component(p, 5, 1, 1.0);
    set_component(p, 9, 2, 0.0);
    set_component(p, 44, 0, 0.0);
    set_component(p, 122, 1, 0.2);
    set_component(p, 255, 2, 0.0);
    let expected = text("test_square_out_true.mdpa");
    assert_eq!(f.write_pygem(), expected);
    assert_points_near(&Mdpa::parse(&f.write()).unwrap().points, &Mdpa::parse(&expected).unwrap().points);
    assert!(!f.cells.is_empty());
}

#[test]
fn elmer_like_pygem() {
    let input = text("test_elmer.nodes");
    let mut f = ElmerNodes::parse(&input).unwrap();
    assert_eq!(f.write(), input);
    let p = &mut f.points;
    set(p, 0, [0.1, 1.1, 0.1]);
    set(p, 1, [0.1, 1.2, 0.1]);
    set(p, 2, [0.1, 1.6, 0.1]);
    set(p, 149, [11.7910193185, 2.0, 0.1]);
    set(p, 150, [12.858303628, 0.0, 0.1]);
    set(p, 151, [12.858303628, 0.125, 0.1]);
    set(p, -3, [26.2, 1.6, 0.1]);
    set(p, -2, [26.2, 2.01666666667, 0.1]);
    set(p, -1, [26.2, 2.1, 0.1]);
    let expected = text("test_elmer_out_true.nodes");
    assert_eq!(f.write_pygem(), expected);
    assert_points_near(&ElmerNodes::parse(&f.write()).unwrap().points, &ElmerNodes::parse(&expected).unwrap().points);
}

fn k_case(input: &str, expected: &str) {
    let input = text(input);
    let mut f = KeywordFile::parse(&input).unwrap();
    assert_eq!(f.write(), input);
    square_edits(&mut f.points);
    let expected = text(expected);
    let ours = f.write();
    let e = KeywordFile::parse(&expected).unwrap();
    assert_points_near(&KeywordFile::parse(&ours).unwrap().points, &e.points);
    // Outside *NODE the files agree line for line.
    let keep = |t: &str| -> Vec<String> {
        let mut in_node = false;
        t.lines()
            .filter(|l| {
                if l.starts_with('*') {
                    in_node = l.starts_with("*NODE");
                    return true;
                }
                !in_node || l.starts_with('$')
            })
            .map(str::to_string)
            .collect()
    };
    assert_eq!(keep(&ours), keep(&expected));
    // Exactly the six edited nodes moved.
    let before = KeywordFile::parse(&input).unwrap().points;
    let changed: Vec<usize> = (0..f.points.len()).filter(|&i| f.points[i] != before[i]).collect();
    assert_eq!(changed.len(), 6);
}

#[test]
fn k_like_pygem() {
    k_case("test_square.k", "test_square_out_true.k");
}

#[test]
fn k_comma_like_pygem() {
    let f = KeywordFile::parse(&text("test_square_comma.k")).unwrap();
    // PyGeM's test_comma_seperated_parse.
    assert_points_near(&f.points[..1], &[Point3::new(-0.0500000007, -0.0250000004, -0.0250000004)]);
    k_case("test_square_comma.k", "test_square_comma_out_true.k");
}

/// The edits of PyGeM's `test_stl_write_comparison` (indices of VTK's merged points).
fn sphere_edits(p: &mut [Point3<f64>]) {
    for i in [0, 500, 1000] {
        set(p, i, [-40.2, -20.5, 60.9]);
        set(p, i + 1, [-40.2, -10.5, 60.9]);
        set(p, i + 2, [-40.2, -10.5, 60.9]);
    }
}

/// PyGeM compares all lines but the first (the header carries a date).
fn tail_lines(t: &str) -> Vec<&str> {
    t.lines().skip(1).collect()
}

#[test]
fn stl_like_pygem_from_ascii_and_binary() {
    use cadmorph_mesh::format::stl::Stl;
    let expected = text("test_sphere_out_true.stl");
    for name in ["test_sphere.stl", "test_sphere_bin.stl"] {
        let input = std::fs::read(data(name)).unwrap();
        let mut s = Stl::parse(&input).unwrap();
        assert_eq!(s.write(), input, "{name}: unchanged write");
        sphere_edits(&mut s.points);
        let ours = s.write_ascii_vtk();
        assert_eq!(tail_lines(&ours), tail_lines(&expected), "{name}");
        // The lossless writer gives the same triangles to the file's precision.
        let back = Stl::parse(&s.write()).unwrap();
        let e = Stl::parse(expected.as_bytes()).unwrap();
        assert_eq!(back.triangles.len(), e.triangles.len());
        for (t, u) in back.triangles.iter().zip(&e.triangles) {
            for k in 0..3 {
                // Expected vertices carry 6 significant digits (%g).
                assert!((back.points[t[k]] - e.points[u[k]]).norm() <= 1e-4 * 70.0, "{name}");
            }
        }
    }
}

#[test]
fn vtk_like_pygem() {
    use cadmorph_mesh::format::vtk::VtkLegacy;
    let input = text("test_red_blood_cell.vtk");
    let mut v = VtkLegacy::parse(&input).unwrap();
    assert_eq!(v.write(), input);
    assert_eq!(v.points.len(), 500);
    assert_eq!(v.cells.len(), 996);
    square_edits(&mut v.points);
    let expected = text("test_red_blood_cell_out_true.vtk");
    // PyGeM's cmp skips comment lines (the version line differs: VTK 4.0 wrote it).
    let body = |t: &str| t.lines().filter(|l| !l.starts_with('#')).map(str::to_string).collect::<Vec<_>>();
    assert_eq!(body(&v.write_vtk_style()), body(&expected));
    let ours = VtkLegacy::parse(&v.write()).unwrap();
    // Every point PyGeM edited is exact; the rest equal the %g text of both files.
    assert_points_near(&ours.points, &v.points);
    assert_points_near(
        &VtkLegacy::parse(&expected).unwrap().points,
        &VtkLegacy::parse(&v.write_vtk_style()).unwrap().points,
    );
}

/// PyGeM's `points_test_true_version6.vtp` (written by VTK 9: appended base64, zlib): the
/// point norms match the `RangeMin`/`RangeMax` VTK wrote beside the array; a morph is
/// written back (new compressed size, later offsets shifted) and reads back exactly.
#[test]
fn vtp_appended_base64_zlib() {
    use cadmorph_mesh::format::vtu::Vtu;
    let bytes = std::fs::read(data("points_test_true_version6.vtp")).unwrap();
    let mut v = Vtu::parse(&bytes).unwrap();
    assert_eq!(v.points.len(), 4);
    assert_eq!(v.cells.len(), 4, "four vertices");
    let norms: Vec<f64> = v.points.iter().map(|p| p.coords.norm()).collect();
    let (lo, hi) = norms.iter().fold((f64::MAX, 0.0f64), |a, &n| (a.0.min(n), a.1.max(n)));
    // VTK prints the range with 11 significant digits; the points are Float32.
    assert!((lo - 2.2360679775).abs() < 1e-6 && (hi - 17.378147197).abs() < 1e-6, "{lo} {hi}");
    assert_eq!(v.write(), bytes);
    for (i, p) in v.points.iter_mut().enumerate() {
        p.x += 0.125 * (i as f64 + 1.0);
        p.z -= 3.0;
    }
    let moved = v.points.clone();
    let back = Vtu::parse(&v.write()).unwrap();
    assert_eq!(back.points, moved.iter().map(|p| p.map(|x| x as f32 as f64)).collect::<Vec<_>>());
    assert_eq!(back.cells, v.cells);
}

/// The lattice and control-point files PyGeM writes beside its parameters (`box_*.vtk`,
/// VTK's `%g` of `f32` points): cadmorph's FFD lattice of `parameters_test_ffd_sphere.prm`
/// (C order as polydata, x fastest as a structured grid) and the RBF control points of
/// `parameters_rbf_cube.prm`, read with cadmorph's VTK reader, agree to every digit the
/// files hold.
#[test]
fn lattice_vtk_files_match_their_parameters() {
    use cadmorph_mesh::format::vtk::VtkLegacy;
    use cadmorph_morph::{prm, Ffd, Parameters};
    // The file holds %g of the f32 value; so must we.
    let digits = |x: f64| format!("{:.5e}", x as f32 as f64).parse::<f64>().unwrap();
    let same = |file: &str, ours: &[Point3<f64>]| {
        let v = VtkLegacy::parse(&text(file)).unwrap();
        assert_eq!(v.points.len(), ours.len(), "{file}");
        for (i, (p, q)) in v.points.iter().zip(ours).enumerate() {
            for k in 0..3 {
                let (a, b) = (p[k], digits(q[k]));
                assert!((a - b).abs() <= 1e-9 * (1.0 + b.abs()), "{file} point {i}: file {a}, ours {} ({b})", q[k]);
            }
        }
    };
    let ffd = Ffd::from_prm(&text("parameters_test_ffd_sphere.prm")).unwrap();
    let [l, m, n] = ffd.n_control_points();
    let fortran = |pts: Vec<Point3<f64>>| -> Vec<Point3<f64>> {
        let mut out = Vec::new();
        for k in 0..n {
            for j in 0..m {
                for i in 0..l {
                    out.push(pts[(i * m + j) * n + k]);
                }
            }
        }
        out
    };
    same("box_test_sphere.vtk", &ffd.control_points(false));
    same("box_test_sphere_deformed.vtk", &ffd.control_points(true));
    same("box_test_sphere_true_version5.vtk", &fortran(ffd.control_points(false)));
    same("box_test_sphere_true_version6.vtk", &fortran(ffd.control_points(false)));
    same("box_modified_test_sphere_true_version5.vtk", &fortran(ffd.control_points(true)));
    same("box_modified_test_sphere_true_version6.vtk", &fortran(ffd.control_points(true)));
    let Parameters::Rbf(rbf) = prm::read(&text("parameters_rbf_cube.prm")).unwrap() else { panic!("not RBF") };
    same("box_test_cube.vtk", &rbf.original);
    same("box_test_cube_deformed.vtk", &rbf.deformed);
}
