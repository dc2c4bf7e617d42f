//! FFD: parity with PyGeM's sphere case, `.prm` reading and byte-exact writing, the
//! offline/online split, points on the box faces, Jacobians.

mod common;

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{prm, Deformation, Displacements, Error, Ffd, LinearInParameters, Parameters};
use common::*;

#[test]
fn sphere_matches_pygem() {
    let ffd = Ffd::from_prm(&read_text("parameters_test_ffd_sphere.prm")).unwrap();
    let mut pts = read_points("meshpoints_sphere_orig.npy");
    let expected = read_points("meshpoints_sphere_mod.npy");
    assert_eq!(pts.len(), 7200);
    let original = pts.clone();
    ffd.deform(&mut pts);
    let err = max_abs_diff(&pts, &expected);
    assert!(err < PYGEM_MATCH, "max deviation from PyGeM {err:e}");
    // The case is not trivial: points really move.
    assert!(max_abs_diff(&pts, &original) > 0.1);
    // The per-point path agrees with the batched one.
    for (p, q) in original.iter().zip(&pts).step_by(97) {
        assert!((ffd.deform_point(p) - q).norm() < 1e-12);
    }
}

#[test]
fn bound_ffd_reproduces_deform_for_new_mu() {
    let mut ffd = Ffd::from_prm(&read_text("parameters_test_ffd_sphere.prm")).unwrap();
    let pts = read_points("meshpoints_sphere_orig.npy");
    let bound = ffd.bind(&pts);
    let mut out = vec![Point3::origin(); pts.len()];
    bound.deform_with(ffd.mu(), &mut out).unwrap();
    assert!(max_abs_diff(&out, &read_points("meshpoints_sphere_mod.npy")) < PYGEM_MATCH);
    // A second μ: online product vs full evaluation.
    let shape = ffd.n_control_points();
    let mut mu = Displacements::zeros(shape);
    mu.set(1, 1, 0, [0.05, -0.02, 0.1]);
    mu.set(0, 0, 1, [0.0, 0.3, 0.0]);
    bound.deform_with(&mu, &mut out).unwrap();
    ffd.set_mu(mu).unwrap();
    let direct = ffd.deformed(&pts);
    assert!(max_abs_diff(&out, &direct) < 1e-12);
    // Shape errors are reported, not panicked on.
    let mut short = vec![Point3::origin(); 3];
    assert!(matches!(bound.deform_with(ffd.mu(), &mut short), Err(Error::CountMismatch { .. })));
    assert!(matches!(bound.deform_with(&Displacements::zeros([2, 2, 2]), &mut out), Err(Error::CountMismatch { .. })));
}

#[test]
fn reads_pygem_sphere_parameters() {
    let ffd = Ffd::from_prm(&read_text("parameters_sphere.prm")).unwrap();
    assert_eq!(ffd.n_control_points(), [3, 2, 2]);
    assert_eq!(ffd.box_length(), Vector3::new(45.0, 90.0, 90.0));
    assert_eq!(ffd.box_origin(), Point3::new(-20.0, -55.0, -45.0));
    assert_eq!(ffd.rot_angle(), Vector3::new(20.3, 11.0, 0.0));
    // Values PyGeM's test_ffd.py expects for this file.
    assert_eq!(ffd.mu().get(0, 0, 0)[0], 0.2);
    assert_eq!(ffd.mu().get(2, 0, 0)[1], -1.0);
    assert_eq!(ffd.mu().get(0, 1, 1)[2], -0.456229852);
    // test_read_parameters_rotation_matrix
    let r = ffd.rotation();
    let expected =
        [[0.98162718, 0.0, 0.190809], [0.06619844, 0.93788893, -0.34056147], [-0.17895765, 0.34693565, 0.92065727]];
    for i in 0..3 {
        for j in 0..3 {
            assert!((r[(i, j)] - expected[i][j]).abs() < 1e-8, "R[{i}][{j}] = {}", r[(i, j)]);
        }
    }
}

#[test]
fn writer_is_byte_identical_to_pygem() {
    let ffd = Ffd::from_prm(&read_text("parameters_sphere.prm")).unwrap();
    assert_eq!(ffd.to_prm(), read_text("parameters_sphere_out_true.prm"));
    // PyGeM writes its defaults for FFD([3, 2, 2]) (test_read_parameters_filename_default).
    assert_eq!(Ffd::unit([3, 2, 2]).to_prm(), read_text("parameters_default.prm"));
    // Read → write → read is the identity on every FFD file we ship.
    for name in [
        "parameters_sphere.prm",
        "parameters_test_ffd_sphere.prm",
        "parameters_test_ffd_identity.prm",
        "parameters_test_ffd_iges.prm",
        "parameters_test_ffd_pipe_unv_C0.prm",
        "parameters_test_ffd_pipe_unv_C1.prm",
    ] {
        let a = Ffd::from_prm(&read_text(name)).unwrap();
        let b = Ffd::from_prm(&a.to_prm()).unwrap();
        assert_eq!(a, b, "{name}");
        assert!(matches!(prm::read(&read_text(name)).unwrap(), Parameters::Ffd(_)));
    }
}

#[test]
fn identity_file_is_identity() {
    let ffd = Ffd::from_prm(&read_text("parameters_test_ffd_identity.prm")).unwrap();
    let pts = read_points("meshpoints_sphere_orig.npy");
    assert!(max_abs_diff(&ffd.deformed(&pts), &pts) < 1e-12);
}

/// PyGeM issue 272: points on the box faces must move like their neighbours just inside.
#[test]
fn face_points_move_like_neighbours_issue_272() {
    let mut ffd = Ffd::from_prm(&read_text("parameters_sphere.prm")).unwrap();
    ffd.mu_mut().set(2, 1, 1, [0.1, 0.2, -0.3]);
    let frame = ffd.rotation() * nalgebra::Matrix3::from_diagonal(&ffd.box_length());
    let o = ffd.box_origin();
    let h = 1e-9;
    for u in [
        Vector3::new(1.0, 1.0, 1.0),
        Vector3::new(1.0, 0.5, 0.3),
        Vector3::new(0.2, 1.0, 0.7),
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.6, 0.4, 1.0),
    ] {
        let on = o + frame * u;
        let inside = o + frame
            * u.map(|c| {
                if c >= 1.0 {
                    c - h
                } else if c <= 0.0 {
                    c + h
                } else {
                    c
                }
            });
        let d_on = ffd.deform_point(&on) - on;
        let d_in = ffd.deform_point(&inside) - inside;
        assert!((d_on - d_in).norm() < 1e-6, "{u}: {d_on} vs {d_in}");
        let mut batch = [on];
        ffd.deform(&mut batch);
        assert!((batch[0] - ffd.deform_point(&on)).norm() < 1e-12);
    }
    // Clearly outside does not move.
    let out = o + frame * Vector3::new(1.01, 0.5, 0.5);
    assert_eq!(ffd.deform_point(&out), out);
}

#[test]
fn spatial_jacobian_matches_central_differences() {
    let mut ffd = Ffd::from_prm(&read_text("parameters_test_ffd_sphere.prm")).unwrap();
    ffd.mu_mut().set(1, 0, 1, [0.3, -0.1, 0.2]);
    let pts = read_points("meshpoints_sphere_orig.npy");
    let h = 1e-5;
    let mut checked = 0;
    for p in pts.iter().step_by(331) {
        let j = ffd.jacobian(p).unwrap();
        for a in 0..3 {
            let mut e = Vector3::zeros();
            e[a] = h;
            let fd = (ffd.deform_point(&(p + e)) - ffd.deform_point(&(p - e))) / (2.0 * h);
            if (fd - j.column(a)).norm() > 1e-6 * (1.0 + fd.norm()) {
                // A difference straddling the box face is not a derivative; skip those.
                assert!(ffd.deform_point(&(p + e)) == p + e || ffd.deform_point(&(p - e)) == p - e);
                continue;
            }
            checked += 1;
        }
    }
    assert!(checked > 20);
}

#[test]
fn param_jacobian_gives_exact_linear_model() {
    let mut ffd = Ffd::from_prm(&read_text("parameters_test_ffd_sphere.prm")).unwrap();
    let pts = read_points("meshpoints_sphere_orig.npy");
    let theta0 = ffd.params();
    for p in pts.iter().step_by(500) {
        let jac = ffd.param_jacobian(p);
        let moved = p.coords + &jac * nalgebra::DVector::from_vec(theta0.clone());
        assert!((ffd.deform_point(p).coords - moved).norm() < 1e-10);
    }
    let bound = ffd.bind(&pts);
    for i in (0..pts.len()).step_by(700) {
        assert_eq!(bound.param_weights(i).to_dense(), ffd.param_jacobian(&pts[i]));
    }
    assert!(ffd.set_params(&[0.0; 5]).is_err());
}

#[test]
fn malformed_ffd_files_name_the_line() {
    let good = read_text("parameters_sphere.prm");
    type Check = Box<dyn Fn(&Error) -> bool>;
    let cases: Vec<(String, Check)> = vec![
        (
            good.replace("n control points x: 3", "n control points x: three"),
            Box::new(|e| matches!(e, Error::Syntax { line: 7, .. })),
        ),
        (
            good.replace("n control points x: 3", "n control points x: 1"),
            Box::new(|e| matches!(e, Error::InvalidParameter { line: Some(7), .. })),
        ),
        (
            good.replace("box length y: 90.0\n", ""),
            Box::new(|e| matches!(e, Error::MissingKey { key: "box length y", .. })),
        ),
        (
            good.replace("box length x: 45.0", "box length x: -45.0"),
            Box::new(|e| matches!(e, Error::InvalidParameter { line: Some(14), .. })),
        ),
        (
            good.replace("parameter x: 0   0   0    .2", "parameter x: 3   0   0    .2"),
            Box::new(|e| matches!(e, Error::IndexOutOfRange { line: 48, index: [3, 0, 0], .. })),
        ),
        (
            good.replace("parameter x: 0   0   0    .2", "parameter x: 0   0   0"),
            Box::new(|e| matches!(e, Error::Syntax { line: 48, .. })),
        ),
        (
            good.replace("             0   0   1   0.0\n", "             0   0   0   0.0\n"),
            Box::new(|e| matches!(e, Error::Duplicate { line: 49, first: 48, .. })),
        ),
        (
            good.replace("[Parameters weights]", "[Parameter weights]"),
            Box::new(|e| matches!(e, Error::MissingSection { section: "Parameters weights" })),
        ),
        ("garbage".to_string(), Box::new(|e| matches!(e, Error::Syntax { line: 1, .. }))),
        (String::new(), Box::new(|e| matches!(e, Error::MissingSection { .. }))),
    ];
    for (text, check) in cases {
        let e = Ffd::from_prm(&text).unwrap_err();
        assert!(check(&e), "unexpected error: {e}");
    }
}
