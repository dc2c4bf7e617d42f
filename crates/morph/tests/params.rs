//! TOML form of the parameters: round trips and errors with lines.

mod common;

use cadmorph_morph::{Deformation, Error, Ffd, IdwParameters, Parameters, RbfParameters};
use common::*;

#[test]
fn every_pygem_file_round_trips_through_toml() {
    for name in [
        "parameters_sphere.prm",
        "parameters_test_ffd_sphere.prm",
        "parameters_rbf_cube.prm",
        "parameters_rbf_extra.prm",
        "parameters_idw_deform.prm",
        "parameters_idw_cube.prm",
    ] {
        let p = Parameters::from_prm(&read_text(name)).unwrap();
        let toml = p.to_toml();
        let back = Parameters::from_toml(&toml).unwrap_or_else(|e| panic!("{name}: {e}\n{toml}"));
        assert_eq!(back, p, "{name}");
        // And back to the same .prm text.
        assert_eq!(back.to_prm().unwrap(), p.to_prm().unwrap());
    }
}

#[test]
fn toml_ffd_deforms_like_the_prm_one() {
    let ffd = Ffd::from_prm(&read_text("parameters_test_ffd_sphere.prm")).unwrap();
    let via_toml = Parameters::from_toml(&Parameters::Ffd(ffd.clone()).to_toml()).unwrap().build().unwrap();
    let pts = read_points("meshpoints_sphere_orig.npy");
    assert!(max_abs_diff(&via_toml.deformed(&pts), &read_points("meshpoints_sphere_mod.npy")) < PYGEM_MATCH);
}

#[test]
fn minimal_toml_uses_defaults() {
    let p = Parameters::from_toml(
        "[ffd]\nn_control_points = [2, 3, 4]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 2.0, 3.0]\n",
    )
    .unwrap();
    let Parameters::Ffd(f) = p else { panic!() };
    assert_eq!(f.n_control_points(), [2, 3, 4]);
    assert!(f.mu().x.iter().all(|&v| v == 0.0));
    let r = Parameters::from_toml(
        "[rbf]\nkernel = \"wendland_c2\"\nradius = 0.3\noriginal_control_points = [[0.0, 0.0, 0.0]]\ndeformed_control_points = [[0.0, 0.0, 1.0]]\n",
    )
    .unwrap();
    assert!(matches!(r, Parameters::Rbf(RbfParameters { .. })));
    let i = Parameters::from_toml("[idw]\nvariant = \"paper\"\npower = 2.5\ncutoff = 0.4\noriginal_control_points = [[0.0, 0.0, 0.0]]\ndeformed_control_points = [[1.0, 0.0, 0.0]]\n").unwrap();
    assert!(matches!(i, Parameters::Idw(IdwParameters { .. })));
}

#[test]
fn bad_toml_names_the_line() {
    let ffd = "[ffd]\nn_control_points = [2, 2, 2]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 1.0, 1.0]\nmu_x = [0.0, 0.1]\n";
    assert!(matches!(Parameters::from_toml(ffd), Err(Error::CountMismatch { line: 5, expected: 8, found: 2, .. })));
    let syntax = "[ffd]\nn_control_points = [2, 2, 2\n";
    assert!(matches!(Parameters::from_toml(syntax), Err(Error::Toml { line: 2.., .. })));
    let unknown = "[ffd]\nn_control_points = [2, 2, 2]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 1.0, 1.0]\nbox_lenght = 3\n";
    assert!(matches!(Parameters::from_toml(unknown), Err(Error::Toml { line: 5, .. })));
    let small = "[ffd]\nn_control_points = [1, 2, 2]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 1.0, 1.0]\n";
    assert!(matches!(Parameters::from_toml(small), Err(Error::InvalidParameter { line: Some(_), .. })));
    let kernel = "[rbf]\nkernel = \"gaussian_splines\"\nradius = 0.5\noriginal_control_points = []\ndeformed_control_points = []\n";
    assert!(matches!(Parameters::from_toml(kernel), Err(Error::UnknownKernel { line: 2, .. })));
    let counts = "[rbf]\nkernel = \"gaussian_spline\"\nradius = 0.5\noriginal_control_points = [[0.0, 0.0, 0.0]]\ndeformed_control_points = []\n";
    assert!(matches!(Parameters::from_toml(counts), Err(Error::CountMismatch { line: 5, .. })));
    let variant = "[idw]\nvariant = \"shepard\"\npower = 2.0\noriginal_control_points = [[0.0, 0.0, 0.0]]\ndeformed_control_points = [[0.0, 0.0, 0.0]]\n";
    assert!(matches!(Parameters::from_toml(variant), Err(Error::Syntax { line: 2, .. })));
    let power = "[idw]\nvariant = \"paper\"\npower = -1.0\noriginal_control_points = [[0.0, 0.0, 0.0]]\ndeformed_control_points = [[0.0, 0.0, 0.0]]\n";
    assert!(matches!(Parameters::from_toml(power), Err(Error::InvalidParameter { line: Some(3), .. })));
    assert!(matches!(Parameters::from_toml(""), Err(Error::Toml { .. })));
}
