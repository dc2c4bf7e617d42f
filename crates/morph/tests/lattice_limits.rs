//! FFD lattice limits (issue 13): a lattice within the memory budget but of a Bernstein
//! degree `f64` cannot hold, or with more nodes than a deformation sums per point, is
//! refused naming the parameter and the size. Its own test binary: `hostile.rs` changes
//! the process-wide memory budget while it runs, and these lattices need the default.

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{ffd, Deformation, Error, Ffd, Parameters};

/// A `.prm` FFD box of the given lattice with one node moved.
fn prm_lattice([l, m, n]: [usize; 3]) -> String {
    format!(
        "[Box info]\nn control points x: {l}\nn control points y: {m}\nn control points z: {n}\n\
         box length x: 1.0\nbox length y: 1.0\nbox length z: 1.0\nbox origin x: 0.0\nbox origin y: 0.0\n\
         box origin z: 0.0\nrotation angle x: 0.0\nrotation angle y: 0.0\nrotation angle z: 0.0\n\n\
         [Parameters weights]\nparameter x: 1 1 1 0.1\nparameter y: 0 0 0 0.0\nparameter z: 0 0 0 0.0\n"
    )
}

#[test]
fn lattices_of_too_high_a_degree_or_too_many_nodes_are_refused_naming_the_size() {
    // 200 x 200 x 200 fits the memory budget (192 MB) but would sum 8 million nodes per
    // deformed point.
    let err = Parameters::from_bytes(prm_lattice([200, 200, 200]).as_bytes(), false).unwrap_err();
    assert_eq!(
        err,
        Error::LatticeTooLarge { line: Some(4), shape: [200, 200, 200], axis: None, limit: ffd::MAX_NODES }
    );
    let msg = err.to_string();
    assert!(
        msg.starts_with("line 4: FFD lattice 200x200x200: nodes in all = 8000000, over the limit of 262144"),
        "{msg}"
    );
    // Degree 4999 along y: its binomials overflow f64 (every point came out NaN).
    let err = Parameters::from_bytes(prm_lattice([2, 5000, 2]).as_bytes(), false).unwrap_err();
    assert!(matches!(err, Error::LatticeTooLarge { line: Some(3), axis: Some(1), limit: 1024, .. }), "{err}");
    assert!(err.to_string().contains("FFD lattice 2x5000x2: n control points y = 5000"), "{err}");
    // The TOML form, at the line of the lattice size.
    let toml = "[ffd]\n\nn_control_points = [2, 2, 1025]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 1.0, 1.0]\n";
    let err = Parameters::from_toml(toml).unwrap_err();
    assert!(matches!(err, Error::LatticeTooLarge { line: Some(3), axis: Some(2), limit: 1024, .. }), "{err}");
    // The memory budget is still checked first: a petabyte lattice is TooLarge, not this.
    assert!(matches!(
        Ffd::try_new([100_000; 3], Point3::origin(), Vector3::repeat(1.0), Vector3::zeros()),
        Err(Error::TooLarge { .. })
    ));
}

#[test]
fn lattices_at_the_limits_are_accepted_and_deform_finitely() {
    // Degree 1023 along z: the Bernstein weights are finite and sum to one, so moving every
    // node by 0.1 of the box moves every inside point by exactly that.
    for shape in [[2, 2, ffd::MAX_NODES_PER_AXIS], [64, 64, 64]] {
        let mut f = Ffd::try_new(shape, Point3::origin(), Vector3::repeat(1.0), Vector3::zeros()).unwrap();
        let [l, m, n] = shape;
        for i in 0..l {
            for j in 0..m {
                for k in 0..n {
                    f.mu_mut().set(i, j, k, [0.1, 0.0, 0.0]);
                }
            }
        }
        for t in [0.0, 0.13, 0.5, 0.77, 1.0] {
            let p = Point3::new(0.3, 0.6, t);
            let q = f.deform_point(&p);
            assert!(
                (q.x - 0.4).abs() < 1e-12 && (q.y - 0.6).abs() < 1e-12 && (q.z - t).abs() < 1e-12,
                "{shape:?} at {t}: {q}"
            );
        }
    }
}
