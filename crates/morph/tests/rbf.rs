//! RBF: parity with PyGeM's cube and polyharmonic cases, `.prm` reading and writing, every
//! kernel, conditioning errors, the sparse solver.

mod common;

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::rbf::{Kernel, RbfOptions, Solver};
use cadmorph_morph::{prm, Deformation, Error, LinearInParameters, Parameters, Rbf, RbfParameters};
use common::*;
use rand::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

fn cube_rbf() -> Rbf {
    Rbf::from_parameters(&RbfParameters::from_prm(&read_text("parameters_rbf_cube.prm")).unwrap()).unwrap()
}

#[test]
fn cube_weights_match_pygem() {
    let rbf = cube_rbf();
    let (shape, w) = read_npy("weights_rbf_cube.npy");
    assert_eq!(shape, vec![12, 3]);
    let ours = rbf.pygem_weights();
    assert_eq!(ours.len(), 12);
    for (i, row) in ours.iter().enumerate() {
        for c in 0..3 {
            let e = w[3 * i + c];
            assert!((row[c] - e).abs() < PYGEM_MATCH, "weights[{i}][{c}]: {} vs {e}", row[c]);
        }
    }
}

#[test]
fn cube_points_match_pygem() {
    let rbf = cube_rbf();
    let mut pts = cube_grid();
    let original = pts.clone();
    rbf.deform(&mut pts);
    let expected = read_points("meshpoints_cube_mod_rbf.npy");
    assert_eq!(expected.len(), 8000);
    let err = max_abs_diff(&pts, &expected);
    assert!(err < PYGEM_MATCH, "max deviation from PyGeM {err:e}");
    assert!(max_abs_diff(&pts, &original) > 0.1);
    for (p, q) in original.iter().zip(&pts).step_by(61) {
        assert!((rbf.deform_point(p) - q).norm() < 1e-13);
    }
}

#[test]
fn polyharmonic_k4_point_17_matches_pygem() {
    let params = RbfParameters::from_prm(&read_text("parameters_rbf_extra.prm")).unwrap();
    assert_eq!(params.kernel, Kernel::Polyharmonic { radius: 0.5, k: 4 });
    let rbf = Rbf::from_parameters(&params).unwrap();
    let p = rbf.deform_point(&cube_grid()[17]);
    let full = pygem_reference("rbf_extra_point_17");
    assert!((p - full).amax() < PYGEM_MATCH, "{p} vs {full}");
    // The 7-digit value in PyGeM's tests/test_rbf.py.
    let printed = Point3::new(8.947368e-01, 5.353524e-17, 8.845331e-03);
    assert!((p - printed).amax() < 1e-6);
    let mut batch = cube_grid();
    rbf.deform(&mut batch);
    assert!((batch[17] - full).amax() < PYGEM_MATCH);
}

#[test]
fn default_file_is_identity_and_radius_is_read() {
    let params = RbfParameters::from_prm(&read_text("parameters_rbf_default.prm")).unwrap();
    assert_eq!(params.kernel, Kernel::Gaussian { radius: 0.5 });
    let rbf = Rbf::from_parameters(&params).unwrap();
    let pts = cube_grid();
    assert!(max_abs_diff(&rbf.deformed(&pts), &pts) < 1e-14);
    let radius = RbfParameters::from_prm(&read_text("parameters_rbf_radius.prm")).unwrap();
    assert_eq!(radius.kernel.radius(), 2.0);
}

#[test]
fn bugged_files_are_rejected_with_the_line() {
    match RbfParameters::from_prm(&read_text("parameters_rbf_bugged_01.prm")) {
        Err(Error::CountMismatch { line, expected: 8, found: 9, .. }) => assert_eq!(line, 30),
        other => panic!("{other:?}"),
    }
    match prm::read(&read_text("parameters_rbf_bugged_02.prm")) {
        Err(e @ Error::UnknownKernel { line: 9, .. }) => assert!(e.to_string().contains("gaussian_splines")),
        other => panic!("{other:?}"),
    }
    let good = read_text("parameters_rbf_extra.prm");
    let bad_k = good.replace("k: 4", "k: four");
    assert!(matches!(RbfParameters::from_prm(&bad_k), Err(Error::Syntax { line: 16, .. })));
    let extra = good.replace("k: 4", "q: 4");
    assert!(matches!(RbfParameters::from_prm(&extra), Err(Error::UnknownParameter { line: 16, .. })));
    let gauss_k = good.replace("polyharmonic_spline", "gaussian_spline");
    assert!(matches!(RbfParameters::from_prm(&gauss_k), Err(Error::UnknownParameter { line: 16, .. })));
    let short_row = good.replace("1.0   1.0   2.0", "1.0   2.0");
    assert!(matches!(RbfParameters::from_prm(&short_row), Err(Error::Syntax { line: 39, .. })));
    let neg = good.replace("radius: 0.5", "radius: -0.5");
    assert!(matches!(RbfParameters::from_prm(&neg), Err(Error::InvalidParameter { line: Some(13), .. })));
    let no_cp = good.replace("[Control points]", "[Control]");
    assert!(matches!(RbfParameters::from_prm(&no_cp), Err(Error::MissingSection { section: "Control points" })));
}

#[test]
fn writer_matches_pygem_files_byte_for_byte() {
    let cube = RbfParameters::from_prm(&read_text("parameters_rbf_cube.prm")).unwrap();
    assert_eq!(cube.to_prm(), read_text("parameters_rbf_cube_out_true.prm"));
    for name in ["parameters_rbf_default.prm", "parameters_rbf_extra.prm", "parameters_rbf_cube_out_true.prm"] {
        let text = read_text(name);
        let p = RbfParameters::from_prm(&text).unwrap();
        assert_eq!(p.to_prm(), text, "{name}");
        assert!(matches!(Parameters::from_prm(&text).unwrap(), Parameters::Rbf(_)));
    }
}

fn random_points(n: usize, seed: u64) -> Vec<Point3<f64>> {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    (0..n).map(|_| Point3::new(rng.gen(), rng.gen(), rng.gen())).collect()
}

fn random_moves(n: usize, seed: u64, scale: f64) -> Vec<Vector3<f64>> {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    (0..n)
        .map(|_| Vector3::new(rng.gen::<f64>() - 0.5, rng.gen::<f64>() - 0.5, rng.gen::<f64>() - 0.5) * scale)
        .collect()
}

/// PyGeM solves this silently and misses its own control points by 4.0; we refuse it.
#[test]
fn gaussian_with_huge_radius_is_ill_conditioned() {
    let c = random_points(1000, 1);
    let d = random_moves(1000, 2, 0.1);
    match Rbf::try_new(&c, &d, Kernel::Gaussian { radius: 0.5 }) {
        Err(Error::IllConditioned { condition, .. }) | Err(Error::SingularSystem { condition }) => {
            assert!(condition > 1e12, "{condition:e}")
        }
        other => panic!("expected a conditioning error, got {:?}", other.map(|r| r.condition())),
    }
}

#[test]
fn duplicate_centres_are_named_and_coplanar_ones_singular() {
    let mut c = random_points(20, 3);
    c[7] = c[3];
    let d = random_moves(20, 4, 0.1);
    for kernel in [
        Kernel::ThinPlate { radius: 0.5, k: 2 },
        Kernel::MultiQuadratic { radius: 0.1 },
        Kernel::WendlandC2 { support: 0.8 },
    ] {
        for solver in [Solver::Dense, Solver::Sparse, Solver::Iterative] {
            if solver != Solver::Dense && kernel.support().is_none() {
                continue;
            }
            let e = Rbf::try_new_with(&c, &d, kernel, RbfOptions { solver, ..Default::default() }).unwrap_err();
            assert_eq!(
                e,
                Error::CoincidentCentres { first: 3, second: 7, point: [c[3].x, c[3].y, c[3].z] },
                "{kernel:?} {solver:?}"
            );
        }
    }
    // All centres in the plane z = 0: the linear term is undetermined.
    let flat: Vec<Point3<f64>> = random_points(20, 5).into_iter().map(|p| Point3::new(p.x, p.y, 0.0)).collect();
    let e = Rbf::try_new(&flat, &d, Kernel::MultiQuadratic { radius: 0.5 }).unwrap_err();
    assert!(matches!(e, Error::SingularSystem { .. } | Error::IllConditioned { .. }), "{e}");
    assert!(matches!(
        Rbf::try_new(&c[..3], &d[..3], Kernel::MultiQuadratic { radius: 0.5 }),
        Err(Error::CountMismatch { .. })
    ));
    assert!(matches!(
        Rbf::try_new(&c, &d[..5], Kernel::MultiQuadratic { radius: 0.5 }),
        Err(Error::CountMismatch { .. })
    ));
    assert!(matches!(Rbf::try_new(&c, &d, Kernel::Gaussian { radius: 0.0 }), Err(Error::InvalidParameter { .. })));
}

#[test]
fn sparse_and_dense_solvers_agree() {
    let c = random_points(400, 6);
    let d = random_moves(400, 7, 0.05);
    for kernel in [
        Kernel::WendlandC2 { support: 0.35 },
        Kernel::WendlandC4 { support: 0.35 },
        Kernel::BeckertWendlandC2 { radius: 0.35 },
    ] {
        let sparse =
            Rbf::try_new_with(&c, &d, kernel, RbfOptions { solver: Solver::Sparse, ..Default::default() }).unwrap();
        assert!(sparse.is_sparse());
        let dense =
            Rbf::try_new_with(&c, &d, kernel, RbfOptions { solver: Solver::Dense, ..Default::default() }).unwrap();
        assert!(!dense.is_sparse());
        let probe = random_points(300, 8);
        let a = sparse.deformed(&probe);
        let b = dense.deformed(&probe);
        assert!(max_abs_diff(&a, &b) < 1e-10, "{kernel:?}: {:e}", max_abs_diff(&a, &b));
        // Interpolation at the centres.
        let moved = sparse.deformed(&c);
        for i in (0..c.len()).step_by(37) {
            assert!((moved[i] - (c[i] + d[i])).norm() < 1e-10);
        }
    }
    // Auto picks the sparse solver for many centres of a compact kernel.
    let c = random_points(1200, 15);
    let auto = Rbf::try_new(&c, &random_moves(1200, 16, 0.05), Kernel::WendlandC2 { support: 0.15 }).unwrap();
    assert!(auto.is_sparse());
    assert!(Rbf::try_new_with(
        &c,
        &random_moves(1200, 16, 0.05),
        Kernel::ThinPlate { radius: 0.5, k: 2 },
        RbfOptions { solver: Solver::Sparse, ..Default::default() }
    )
    .is_err());
}

#[test]
fn conjugate_gradients_agree_with_direct_solves() {
    let c = random_points(3000, 21);
    let d = random_moves(3000, 22, 0.05);
    let probe = random_points(500, 23);
    for kernel in
        [Kernel::WendlandC2 { support: 0.2 }, Kernel::WendlandC0 { support: 0.2 }, Kernel::WendlandC4 { support: 0.2 }]
    {
        let with = |solver| Rbf::try_new_with(&c, &d, kernel, RbfOptions { solver, ..Default::default() }).unwrap();
        let (cg, direct) = (with(Solver::Iterative), with(Solver::Sparse));
        assert!(cg.is_iterative() && cg.is_sparse() && !direct.is_iterative());
        // Bulk evaluation (cell grid) and point by point (k-d tree) against the direct solve.
        let a = cg.deformed(&probe);
        let b = direct.deformed(&probe);
        assert!(max_abs_diff(&a, &b) < 1e-10, "{kernel:?}: {:e}", max_abs_diff(&a, &b));
        let single: Vec<Point3<f64>> = probe.iter().map(|p| cg.deform_point(p)).collect();
        assert!(max_abs_diff(&a, &single) < 1e-13);
        let moved = cg.deformed(&c);
        for i in 0..c.len() {
            assert!((moved[i] - (c[i] + d[i])).norm() < 1e-10);
        }
        // Both condition estimates see a moderately conditioned matrix.
        assert!(cg.condition() > 1.0 && cg.condition() < 1e8 && direct.condition() < 1e8);
        // Re-solving with new displacements and the Jacobian weights.
        let mut cg2 = cg.clone();
        let d2 = random_moves(3000, 24, 0.02);
        let theta: Vec<f64> = (0..3).flat_map(|k| d2.iter().map(move |v| v[k])).collect();
        cg2.set_params(&theta).unwrap();
        let mut direct2 = direct.clone();
        direct2.set_params(&theta).unwrap();
        assert!(max_abs_diff(&cg2.deformed(&probe), &direct2.deformed(&probe)) < 1e-10);
        let (wa, wb) = (cg.param_weights(&probe[0]), direct.param_weights(&probe[0]));
        let dense = |w: &cadmorph_morph::ParamWeights| {
            let mut v = vec![0.0; c.len()];
            for &(j, x) in &w.weights {
                v[j] = x;
            }
            v
        };
        let (va, vb) = (dense(&wa), dense(&wb));
        assert!(va.iter().zip(&vb).all(|(x, y)| (x - y).abs() < 1e-9));
    }
    // Points far outside the centres' box only get the linear term.
    let rbf = Rbf::try_new_with(
        &c,
        &d,
        Kernel::WendlandC2 { support: 0.2 },
        RbfOptions { solver: Solver::Iterative, ..Default::default() },
    )
    .unwrap();
    let far = [Point3::new(5.0, -3.0, 0.5), Point3::new(f64::MAX, 0.0, 0.0)];
    let bulk = rbf.deformed(&far);
    assert!((bulk[0] - rbf.deform_point(&far[0])).norm() < 1e-13);
}

#[test]
fn jacobians_match_finite_differences() {
    let c = random_points(40, 9);
    let d = random_moves(40, 10, 0.1);
    let probe = random_points(10, 11);
    let h = 1e-5;
    for kernel in [
        Kernel::Gaussian { radius: 0.7 },
        Kernel::MultiQuadratic { radius: 0.1 },
        Kernel::InverseMultiQuadratic { radius: 0.1 },
        Kernel::ThinPlate { radius: 0.5, k: 2 },
        Kernel::Polyharmonic { radius: 0.5, k: 3 },
        Kernel::BeckertWendlandC2 { radius: 0.9 },
        Kernel::WendlandC2 { support: 0.9 },
        Kernel::WendlandC4 { support: 0.9 },
    ] {
        let rbf = Rbf::try_new(&c, &d, kernel).unwrap();
        for p in &probe {
            let j = rbf.jacobian(p).unwrap();
            for a in 0..3 {
                let mut e = Vector3::zeros();
                e[a] = h;
                let fd = (rbf.deform_point(&(p + e)) - rbf.deform_point(&(p - e))) / (2.0 * h);
                assert!((fd - j.column(a)).norm() < 1e-6 * (1.0 + fd.norm()), "{kernel:?}");
            }
        }
        // Parameter Jacobian: φ is exactly p + J θ.
        let theta = rbf.params();
        for p in probe.iter().take(3) {
            let jac = rbf.param_jacobian(p);
            let lin = p.coords + &jac * nalgebra::DVector::from_vec(theta.clone());
            assert!((rbf.deform_point(p).coords - lin).norm() < 1e-9, "{kernel:?}");
        }
    }
    // A kernel with a corner at its centres has no Jacobian there.
    let rbf = Rbf::try_new(&c, &d, Kernel::Polyharmonic { radius: 0.5, k: 1 }).unwrap();
    assert!(rbf.jacobian(&c[0]).is_none());
    assert!(rbf.jacobian(&probe[0]).is_some());
}

#[test]
fn set_params_resolves_with_stored_factorisation() {
    let c = random_points(300, 12);
    for kernel in [Kernel::ThinPlate { radius: 0.5, k: 2 }, Kernel::WendlandC2 { support: 0.4 }] {
        let options = RbfOptions {
            solver: if kernel.support().is_some() { Solver::Sparse } else { Solver::Dense },
            ..Default::default()
        };
        let mut rbf = Rbf::try_new_with(&c, &vec![Vector3::zeros(); 300], kernel, options).unwrap();
        let d = random_moves(300, 13, 0.02);
        let theta: Vec<f64> = (0..3).flat_map(|k| d.iter().map(move |v| v[k])).collect();
        rbf.set_params(&theta).unwrap();
        let fresh = Rbf::try_new_with(&c, &d, kernel, options).unwrap();
        let probe = random_points(100, 14);
        assert!(max_abs_diff(&rbf.deformed(&probe), &fresh.deformed(&probe)) < 1e-11);
        assert!(rbf.set_params(&theta[1..]).is_err());
    }
}

#[test]
fn vectorised_evaluation_matches_scalar_sum() {
    // `deform` runs the vectorised sums (16 points per block, fast logarithm, in parallel);
    // `deform_point` sums centre by centre with `Kernel::eval` (f64::ln, f64::sqrt).
    let mut rng = XorShiftRng::seed_from_u64(11);
    let centres: Vec<Point3<f64>> =
        (0..200).map(|_| Point3::new(rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>())).collect();
    let moves: Vec<Vector3<f64>> =
        (0..200).map(|_| Vector3::new(rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()) * 0.1).collect();
    // Points around the cube (enough for the parallel path), a ragged tail, and the
    // centres themselves (r = 0).
    let mut pts: Vec<Point3<f64>> = (0..1403)
        .map(|_| Point3::new(rng.gen_range(-0.2..1.2), rng.gen_range(-0.2..1.2), rng.gen_range(-0.2..1.2)))
        .collect();
    pts.extend_from_slice(&centres[..40]);
    for kernel in [
        Kernel::ThinPlate { radius: 0.5, k: 2 },
        Kernel::ThinPlate { radius: 2.0, k: 3 },
        Kernel::Polyharmonic { radius: 0.5, k: 2 },
        Kernel::Polyharmonic { radius: 0.5, k: 3 },
        Kernel::MultiQuadratic { radius: 0.1 },
        Kernel::InverseMultiQuadratic { radius: 0.1 },
        Kernel::Gaussian { radius: 0.1 },
    ] {
        let rbf = Rbf::try_new(&centres, &moves, kernel).unwrap();
        let gamma = rbf.pygem_weights();
        let fast = rbf.deformed(&pts);
        for (p, q) in pts.iter().zip(&fast) {
            let r = rbf.deform_point(p);
            // Relative to the size of the terms summed, Σⱼ |γⱼ φⱼ| (the weights of the
            // cubic kernel are large and cancel), or to the coordinates. Measured: ≤ 4·10⁻¹⁶.
            let terms: f64 = centres
                .iter()
                .zip(&gamma)
                .map(|(c, g)| kernel.eval((p - c).norm()).abs() * g.iter().fold(0.0, |a: f64, v| a.max(v.abs())))
                .sum();
            let rel = (q - r).amax() / terms.max(p.coords.amax()).max(1.0);
            assert!(rel <= 1e-12, "{kernel:?} at {p}: {q} vs {r}");
        }
        for (c, d) in centres.iter().zip(&moves).take(40) {
            assert!((rbf.deform_point(c) - (c + d)).amax() < 1e-9, "{kernel:?}: centre missed");
        }
    }
}
