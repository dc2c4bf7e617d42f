//! Property tests: identity for zero displacements, interpolation at the control points,
//! Jacobians against finite differences, FFD continuity across the box faces.

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::rbf::Kernel;
use cadmorph_morph::{Affine, Deformation, Displacements, Ffd, Idw, IdwVariant, LinearInParameters, Rbf};
use proptest::prelude::*;

fn point(range: f64) -> impl Strategy<Value = Point3<f64>> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

fn vector(scale: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-scale..scale, -scale..scale, -scale..scale).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

/// Centres at least `gap` apart from each other (a well-posed interpolation problem).
fn separated(points: Vec<Point3<f64>>, gap: f64) -> Vec<Point3<f64>> {
    let mut out: Vec<Point3<f64>> = Vec::new();
    for p in points {
        if out.iter().all(|q| (p - q).norm() >= gap) {
            out.push(p);
        }
    }
    out
}

fn ffd_strategy() -> impl Strategy<Value = Ffd> {
    (
        (2usize..5, 2usize..5, 2usize..5),
        point(2.0),
        (0.5..3.0, 0.5..3.0, 0.5..3.0),
        (-40.0..40.0, -40.0..40.0, -40.0..40.0),
    )
        .prop_map(|((l, m, n), o, (a, b, c), (rx, ry, rz))| {
            Ffd::try_new([l, m, n], o, Vector3::new(a, b, c), Vector3::new(rx, ry, rz)).unwrap()
        })
}

fn with_random_mu(mut ffd: Ffd, seed: u64, scale: f64) -> Ffd {
    let n = ffd.mu().x.len();
    let mut s = seed | 1;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s % 2001) as f64 / 1000.0 - 1.0
    };
    let mu = Displacements::try_from_arrays(
        ffd.n_control_points(),
        (0..n).map(|_| scale * next()).collect(),
        (0..n).map(|_| scale * next()).collect(),
        (0..n).map(|_| scale * next()).collect(),
    )
    .unwrap();
    ffd.set_mu(mu).unwrap();
    ffd
}

/// Kernels for which the interpolation problem on separated points is well posed.
fn kernels() -> Vec<Kernel> {
    vec![
        Kernel::Gaussian { radius: 0.4 },
        Kernel::MultiQuadratic { radius: 0.5 },
        Kernel::InverseMultiQuadratic { radius: 0.5 },
        Kernel::ThinPlate { radius: 0.5, k: 2 },
        Kernel::BeckertWendlandC2 { radius: 1.5 },
        Kernel::Polyharmonic { radius: 0.5, k: 1 },
        Kernel::Polyharmonic { radius: 0.5, k: 3 },
        Kernel::Polyharmonic { radius: 0.5, k: 4 },
        Kernel::WendlandC0 { support: 1.5 },
        Kernel::WendlandC2 { support: 1.5 },
        Kernel::WendlandC4 { support: 1.5 },
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 32,
        failure_persistence: Some(Box::new(proptest::test_runner::FileFailurePersistence::WithSource("regressions"))),
        ..ProptestConfig::default()
    })]

    #[test]
    fn zero_displacements_are_the_identity(
        ffd in ffd_strategy(),
        centres in prop::collection::vec(point(1.0), 6..30),
        probe in prop::collection::vec(point(3.0), 1..40),
    ) {
        let moved = ffd.deformed(&probe);
        for (p, q) in probe.iter().zip(&moved) {
            prop_assert!((p - q).norm() <= 1e-12 * (1.0 + p.coords.norm()));
        }
        let centres = separated(centres, 0.1);
        prop_assume!(centres.len() >= 6);
        let zero = vec![Vector3::zeros(); centres.len()];
        for kernel in kernels() {
            if let Ok(rbf) = Rbf::try_new(&centres, &zero, kernel) {
                for (p, q) in probe.iter().zip(rbf.deformed(&probe)) {
                    prop_assert!((p - q).norm() <= 1e-12, "{:?}", kernel);
                }
            }
        }
        for variant in [IdwVariant::Paper { power: 2.0, cutoff: None }, IdwVariant::Paper { power: 3.0, cutoff: Some(0.5) }, IdwVariant::PyGem { power: 3 }] {
            let idw = Idw::try_new(&centres, &zero, variant).unwrap();
            for (p, q) in probe.iter().zip(idw.deformed(&probe)) {
                prop_assert_eq!(*p, q);
            }
        }
    }

    #[test]
    fn rbf_interpolates_its_centres(
        centres in prop::collection::vec(point(1.0), 8..40),
        moves in prop::collection::vec(vector(0.2), 40),
    ) {
        let centres = separated(centres, 0.15);
        prop_assume!(centres.len() >= 8);
        let moves = &moves[..centres.len()];
        let scale = moves.iter().map(|d| d.norm()).fold(0.0, f64::max).max(1e-3);
        for kernel in kernels() {
            let rbf = Rbf::try_new(&centres, moves, kernel);
            // Random centres can still be nearly coplanar; then the error says so.
            let Ok(rbf) = rbf else { continue };
            let out = rbf.deformed(&centres);
            for ((c, d), q) in centres.iter().zip(moves).zip(&out) {
                let err = (q - (c + d)).norm();
                prop_assert!(err <= 1e-10 * scale, "{:?}: miss {:e} (condition {:e})", kernel, err, rbf.condition());
                prop_assert!((rbf.deform_point(c) - q).norm() <= 1e-10 * scale);
            }
        }
    }

    #[test]
    fn idw_reproduces_control_displacements(
        centres in prop::collection::vec(point(1.0), 1..30),
        moves in prop::collection::vec(vector(0.5), 30),
        power in 1u32..5,
    ) {
        let centres = separated(centres, 1e-3);
        let moves = &moves[..centres.len()];
        for variant in [IdwVariant::Paper { power: power as f64, cutoff: None }, IdwVariant::Paper { power: 2.0, cutoff: Some(0.3) }, IdwVariant::PyGem { power }] {
            let idw = Idw::try_new(&centres, moves, variant).unwrap();
            let out = idw.deformed(&centres);
            for ((c, d), q) in centres.iter().zip(moves).zip(&out) {
                prop_assert!((q - (c + d)).norm() <= 1e-14, "{:?}", variant);
            }
        }
    }

    #[test]
    fn parameter_jacobian_matches_finite_differences(
        ffd in ffd_strategy(),
        seed in any::<u64>(),
        centres in prop::collection::vec(point(1.0), 8..20),
        moves in prop::collection::vec(vector(0.2), 20),
        probe in point(1.0),
        which in any::<prop::sample::Index>(),
    ) {
        let h = 1e-6;
        // FFD: probe at a lattice-interior point of the box.
        let ffd = with_random_mu(ffd, seed, 0.1);
        let frame = ffd.rotation() * nalgebra::Matrix3::from_diagonal(&ffd.box_length());
        let p = ffd.box_origin() + frame * Vector3::new(0.37, 0.61, 0.45);
        check_param_fd(&ffd, &p, which.index(ffd.n_params()), h)?;
        let centres = separated(centres, 0.15);
        prop_assume!(centres.len() >= 8);
        let moves = &moves[..centres.len()];
        if let Ok(rbf) = Rbf::try_new(&centres, moves, Kernel::ThinPlate { radius: 0.5, k: 2 }) {
            check_param_fd(&rbf, &probe, which.index(rbf.n_params()), h)?;
        }
        let idw = Idw::try_new(&centres, moves, IdwVariant::PyGem { power: 2 }).unwrap();
        check_param_fd(&idw, &probe, which.index(idw.n_params()), h)?;
    }

    #[test]
    fn spatial_jacobian_matches_finite_differences(
        ffd in ffd_strategy(),
        seed in any::<u64>(),
        u in (0.05..0.95, 0.05..0.95, 0.05..0.95),
    ) {
        let ffd = with_random_mu(ffd, seed, 0.2);
        let frame = ffd.rotation() * nalgebra::Matrix3::from_diagonal(&ffd.box_length());
        let p = ffd.box_origin() + frame * Vector3::new(u.0, u.1, u.2);
        let shift = Affine::translation(Vector3::new(0.1, -0.2, 0.3));
        let chain = (&ffd).then(shift).then(&ffd);
        for (name, d) in [("ffd", &ffd as &dyn Deformation), ("chain", &chain as &dyn Deformation)] {
            let Some(j) = d.jacobian(&p) else { continue };
            let h = 1e-6;
            for a in 0..3 {
                let mut e = Vector3::zeros();
                e[a] = h;
                let fd = (d.deform_point(&(p + e)) - d.deform_point(&(p - e))) / (2.0 * h);
                // A chain whose second FFD sees the point near its face may straddle it.
                if name == "chain" && (fd - j.column(a)).norm() > 1e-5 * (1.0 + fd.norm()) {
                    continue;
                }
                prop_assert!((fd - j.column(a)).norm() <= 1e-5 * (1.0 + fd.norm()), "{}: {} vs {}", name, fd, j.column(a));
            }
        }
    }

    #[test]
    fn ffd_is_continuous_across_its_faces(
        ffd in ffd_strategy(),
        seed in any::<u64>(),
        face in 0usize..6,
        s in 0.0..1.0f64,
        t in 0.0..1.0f64,
    ) {
        let ffd = with_random_mu(ffd, seed, 0.2);
        let frame = ffd.rotation() * nalgebra::Matrix3::from_diagonal(&ffd.box_length());
        let axis = face / 2;
        let value = (face % 2) as f64;
        let mut u = Vector3::new(s, t, s * t);
        u[axis] = value;
        let on = ffd.box_origin() + frame * u;
        let mut u_in = u;
        u_in[axis] = if value == 0.0 { 1e-9 } else { 1.0 - 1e-9 };
        let inside = ffd.box_origin() + frame * u_in;
        let d_on = ffd.deform_point(&on) - on;
        let d_in = ffd.deform_point(&inside) - inside;
        // The displacement is a polynomial of bounded slope: 1e-9 inside changes it by O(1e-9).
        prop_assert!((d_on - d_in).norm() <= 1e-6, "face {}: {} vs {}", face, d_on, d_in);
        let mut batch = vec![on, inside];
        ffd.deform(&mut batch);
        prop_assert!((batch[0] - ffd.deform_point(&on)).norm() <= 1e-12);
    }

    #[test]
    fn ffd_of_affine_lattice_displacement_is_affine(
        ffd in ffd_strategy(),
        a in prop::array::uniform9(-0.2..0.2f64),
        probe in prop::collection::vec((0.0..1.0, 0.0..1.0, 0.0..1.0), 1..20),
    ) {
        // μ(node) = M · node_u for a 3×3 M: Bernstein polynomials reproduce linear functions,
        // so φ(x) = x + F M u(x), an affine map inside the box.
        let m = nalgebra::Matrix3::from_row_slice(&a);
        let [l, mm, n] = ffd.n_control_points();
        let mut ffd = ffd;
        for i in 0..l {
            for j in 0..mm {
                for k in 0..n {
                    let node = Vector3::new(i as f64 / (l - 1) as f64, j as f64 / (mm - 1) as f64, k as f64 / (n - 1) as f64);
                    let mu = m * node;
                    ffd.mu_mut().set(i, j, k, [mu.x, mu.y, mu.z]);
                }
            }
        }
        let frame = ffd.rotation() * nalgebra::Matrix3::from_diagonal(&ffd.box_length());
        for (x, y, z) in probe {
            let u = Vector3::new(x, y, z);
            let p = ffd.box_origin() + frame * u;
            let expected = p + frame * (m * u);
            prop_assert!((ffd.deform_point(&p) - expected).norm() <= 1e-11 * (1.0 + p.coords.norm()));
        }
    }
}

fn check_param_fd<D: LinearInParameters + Clone>(
    d: &D,
    p: &Point3<f64>,
    k: usize,
    h: f64,
) -> Result<(), TestCaseError> {
    let jac = d.param_jacobian(p);
    let theta = d.params();
    let mut plus = d.clone();
    let mut minus = d.clone();
    let mut tp = theta.clone();
    tp[k] += h;
    plus.set_params(&tp).unwrap();
    let mut tm = theta;
    tm[k] -= h;
    minus.set_params(&tm).unwrap();
    let fd = (plus.deform_point(p) - minus.deform_point(p)) / (2.0 * h);
    let col = Vector3::new(jac[(0, k)], jac[(1, k)], jac[(2, k)]);
    prop_assert!((fd - col).norm() <= 1e-7 * (1.0 + col.norm()), "param {}: {} vs {}", k, fd, col);
    Ok(())
}
