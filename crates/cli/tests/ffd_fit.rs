//! `cadmorph ffd fit` around the hull's bow face gives a box that holds it with the asked
//! margin, and a morph with that box moves the bow and leaves every control point outside
//! the box where it was (the stern exactly; the mid body except the seam it shares with
//! the bow, which moves with the bow so the seam stays closed). The oracle is the input
//! read by the library, not the command's own output.

mod common;

use cadmorph::nurbs::{Aabb, Surface};
use common::{cadmorph, root, stderr, Scratch};

/// The bow of `samples/hull3.igs`: face 2, entity DE 11 (`cadmorph info`).
const BOW: usize = 2;

fn read_box(path: &str) -> ([f64; 3], [f64; 3], [usize; 3]) {
    let text = std::fs::read_to_string(path).unwrap();
    let t: toml::Table = toml::from_str(&text).unwrap();
    let f = t["ffd"].as_table().unwrap();
    let three = |k: &str| -> [f64; 3] {
        let a = f[k].as_array().unwrap();
        [0, 1, 2].map(|i| a[i].as_float().unwrap_or_else(|| a[i].as_integer().unwrap() as f64))
    };
    let n = f["n_control_points"].as_array().unwrap();
    (three("box_origin"), three("box_length"), [0, 1, 2].map(|i| n[i].as_integer().unwrap() as usize))
}

#[test]
fn the_fitted_box_holds_the_bow_with_the_margin_and_the_morph_moves_only_what_it_holds() {
    let s = Scratch::new("ffd-fit");
    let fitted = s.path("bow.toml");
    let out = cadmorph(&[
        "ffd",
        "fit",
        "samples/hull3.igs",
        "--lattice",
        "4x3x3",
        "--margin",
        "5%",
        "--around",
        "DE 11",
        "-o",
        &fitted,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (origin, length, lattice) = read_box(&fitted);
    assert_eq!(lattice, [4, 3, 3]);
    // The same face by index gives the same box.
    let by_index = s.path("bow2.toml");
    assert!(cadmorph(&["ffd", "fit", "samples/hull3.igs", "--lattice", "4x3x3", "--around", "2", "-o", &by_index])
        .status
        .success());
    assert_eq!(read_box(&by_index).0, origin);

    let hull = cadmorph::open(&root().join("samples/hull3.igs")).unwrap();
    let bow = &hull.patches()[BOW];
    let cp = Aabb::from_points(bow.surface.control_points()).unwrap();
    let extent = cp.max - cp.min;
    for a in 0..3 {
        let margin = 0.05 * extent[a];
        let (lo, hi) = (origin[a], origin[a] + length[a]);
        // Each side is the asked margin away from the bow's control points (and so from
        // the surface, which lies in their hull).
        assert!((cp.min[a] - lo - margin).abs() <= 1e-9 * extent.norm(), "axis {a}: {lo} vs {}", cp.min[a]);
        assert!((hi - cp.max[a] - margin).abs() <= 1e-9 * extent.norm(), "axis {a}: {hi} vs {}", cp.max[a]);
    }
    let inside = |p: &cadmorph::nurbs::math::Point3<f64>, slack: f64| {
        (0..3).all(|a| p[a] >= origin[a] - slack && p[a] <= origin[a] + length[a] + slack)
    };
    for (u, v) in cadmorph_testkit::grid(&bow.surface, 15) {
        let p = bow.surface.eval(u, v);
        assert!(
            (0..3).all(|a| p[a] >= origin[a] + 0.05 * extent[a] * 0.999 - 1e-9
                && p[a] <= origin[a] + length[a] - 0.05 * extent[a] * 0.999 + 1e-9),
            "surface point {p} within the margin"
        );
    }

    // Morph with two inner lattice nodes moved.
    let morphed = s.path("bow.igs");
    let out = cadmorph(&[
        "morph",
        "samples/hull3.igs",
        "-o",
        &morphed,
        &fitted,
        "--set",
        "mu_y[1,1,1]=0.05",
        "--set",
        "mu_z[2,1,1]=-0.04",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "inner nodes only, a box that holds the bow: {}", stderr(&out));
    let after = cadmorph::open(std::path::Path::new(&morphed)).unwrap();
    let mut moved = [0usize; 3];
    let mut largest = [0f64; 3];
    for (f, (p, q)) in hull.patches().iter().zip(after.patches()).enumerate() {
        for (a, b) in p.surface.control_points().iter().zip(q.surface.control_points()) {
            let d = (a - b).norm();
            if d > 0.0 {
                moved[f] += 1;
                largest[f] = largest[f].max(d);
                assert!(inside(a, 1e-9), "face {f}: a control point outside the box moved: {a}");
            }
        }
    }
    assert_eq!(moved[0], 0, "the stern is untouched");
    assert!(largest[BOW] > 0.01, "the bow moves (by {} m)", largest[BOW]);
    let bow_points = bow.surface.control_points().len();
    assert!(moved[BOW] > bow_points / 3, "most of the bow moves: {} of {bow_points}", moved[BOW]);
    // The mid body moves only where it lies in the box: at most its two foremost columns.
    let mid = &hull.patches()[1].surface;
    assert!(moved[1] <= 2 * mid.n_v(), "mid body: {} control points moved", moved[1]);
    // The seams stay closed.
    let out = cadmorph(&["seams", &morphed, "--tol", "1e-6"]);
    assert_eq!(out.status.code(), Some(0), "{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
}

#[test]
fn fit_refuses_what_it_cannot_do_and_writes_nothing() {
    let s = Scratch::new("ffd-fit-bad");
    let target = s.path("box.prm");
    for (args, says) in [
        (vec!["--around", "7"], "there is no face 7"),
        (vec!["--around", "DE 12"], "names no face"),
        (vec!["--lattice", "1x3x3"], "2 to 64"),
        (vec!["--margin", "lots"], "not a margin"),
    ] {
        let mut full = vec!["ffd", "fit", "samples/hull3.igs", "-o", &target];
        full.extend(args.iter().copied());
        let out = cadmorph(&full);
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
        assert!(!std::path::Path::new(&target).exists());
    }
    let out = cadmorph(&["ffd", "fit", "samples/hull3.igs", "-o", &s.path("box.txt")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains(".prm (PyGeM) or .toml"));
    // A box of the curve-only sample: no faces to fit.
    let out = cadmorph(&["ffd", "fit", "samples/bspline_curve.igs", "-o", &target]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("no faces"), "{}", stderr(&out));
}

#[test]
fn show_prints_the_lattice_and_the_boundary_nodes() {
    let out = cadmorph(&["ffd", "show", "samples/prm/bow_dome.prm"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // bow_dome.prm: 5x4x4, 12 inner nodes move (samples/prm/README.md), none on the faces.
    assert!(
        text.contains("FFD lattice 5x4x4 (80 nodes, 12 with a displacement, 0 of them on the box faces)"),
        "{text}"
    );
    assert_eq!(text.lines().filter(|l| l.trim_start().chars().next().is_some_and(|c| c.is_ascii_digit())).count(), 80);
    let out = cadmorph(&["ffd", "show", "samples/pygem/parameters_idw_default.prm"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("holds idw parameters"), "{}", stderr(&out));
}

#[test]
fn morph_warns_of_a_box_that_misses_and_of_moving_boundary_nodes() {
    let s = Scratch::new("ffd-warn");
    let out = cadmorph(&[
        "morph",
        "samples/hull3.igs",
        "-o",
        &s.path("o.igs"),
        "samples/prm/bow_dome.prm",
        "--set",
        "box_origin[0]=1000",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("holds no control point of any of the 3 faces"), "{err}");
    assert!(err.contains("0 faces rewritten"), "{err}");
    let out = cadmorph(&[
        "morph",
        "samples/hull3.igs",
        "-o",
        &s.path("o2.igs"),
        "samples/prm/bow_dome.prm",
        "--set",
        "mu_y[0,1,1]=0.02",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("1 of the FFD's lattice nodes on the box faces move ([0,1,1])"), "{}", stderr(&out));
    // A parameter of another kind is refused with the names there are, and nothing is written.
    let out = cadmorph(&[
        "morph",
        "samples/hull3.igs",
        "-o",
        &s.path("o3.igs"),
        "samples/prm/bow_dome.prm",
        "--set",
        "radius=3",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("ffd parameters have no \"radius\""), "{}", stderr(&out));
    assert!(!std::path::Path::new(&s.path("o3.igs")).exists());
}
