"""The native API against PyGeM's own test data (samples/pygem), to 1e-10."""
import os

import numpy as np
import pytest

import cadmorph
from conftest import PYGEM_MATCH, cube_grid, pygem, reference_point


def test_ffd_sphere_matches_pygem():
    ffd = cadmorph.read_parameters(pygem("parameters_test_ffd_sphere.prm"))
    assert isinstance(ffd, cadmorph.Ffd)
    assert ffd.n_control_points == (3, 2, 2)
    np.testing.assert_array_equal(ffd.rot_angle, [0.0, 10.0, 15.0])
    points = np.load(pygem("meshpoints_sphere_orig.npy"))
    expected = np.load(pygem("meshpoints_sphere_mod.npy"))
    moved = ffd(points)
    assert moved.shape == points.shape and moved.dtype == np.float64
    assert np.abs(moved - expected).max() < PYGEM_MATCH
    # In place, through out=: the same numbers, in the same buffer.
    buf = points.copy()
    address = buf.ctypes.data
    assert ffd.deform(buf, out=buf) is buf
    assert buf.ctypes.data == address
    assert np.abs(buf - expected).max() < PYGEM_MATCH
    # Into another array.
    out = np.empty_like(points)
    ffd.deform(points, out=out)
    np.testing.assert_array_equal(out, moved)


def test_ffd_prm_writer_is_pygem_byte_for_byte(tmp_path):
    ffd = cadmorph.read_parameters(pygem("parameters_sphere.prm"))
    assert ffd.to_prm() == open(pygem("parameters_sphere_out_true.prm")).read()
    default = cadmorph.Ffd((3, 2, 2))
    assert default.to_prm() == open(pygem("parameters_default.prm")).read()
    path = tmp_path / "back.prm"
    ffd.write_parameters(str(path))
    assert cadmorph.read_parameters(path) == ffd
    toml = tmp_path / "back.toml"
    ffd.write_parameters(toml)
    assert cadmorph.read_parameters(toml) == ffd
    assert cadmorph.parameters_from_str(ffd.to_toml(), toml=True) == ffd


def test_ffd_built_in_python_equals_the_file():
    f = cadmorph.read_parameters(pygem("parameters_test_ffd_sphere.prm"))
    g = cadmorph.Ffd(f.n_control_points, box_origin=f.box_origin, box_length=f.box_length, rot_angle=f.rot_angle)
    g.mu_x, g.mu_y, g.mu_z = f.mu_x, f.mu_y, f.mu_z
    assert g == f
    assert f.mu_x.shape == (3, 2, 2)


def test_rbf_cube_weights_and_points_match_pygem():
    rbf = cadmorph.read_parameters(pygem("parameters_rbf_cube.prm"))
    assert isinstance(rbf, cadmorph.Rbf) and rbf.kernel == "gaussian_spline"
    assert np.abs(rbf.pygem_weights() - np.load(pygem("weights_rbf_cube.npy"))).max() < PYGEM_MATCH
    moved = rbf(cube_grid())
    assert np.abs(moved - np.load(pygem("meshpoints_cube_mod_rbf.npy"))).max() < PYGEM_MATCH
    assert rbf.to_prm() == open(pygem("parameters_rbf_cube_out_true.prm")).read()


def test_rbf_polyharmonic_k4_point_17_matches_pygem():
    rbf = cadmorph.read_parameters(pygem("parameters_rbf_extra.prm"))
    assert rbf.kernel == "polyharmonic_spline" and rbf.k == 4
    assert np.abs(rbf(cube_grid())[17] - reference_point("rbf_extra_point_17")).max() < PYGEM_MATCH
    # The same RBF built from arrays.
    again = cadmorph.Rbf(rbf.original_control_points, rbf.deformed_control_points, kernel="polyharmonic_spline",
                         radius=rbf.radius, k=4)
    assert np.abs(again(cube_grid()) - rbf(cube_grid())).max() < 1e-12


def test_idw_power_3_matches_pygem():
    idw = cadmorph.read_parameters(pygem("parameters_idw_deform.prm"))
    assert isinstance(idw, cadmorph.Idw) and idw.variant == "pygem" and idw.power == 3
    assert np.abs(idw(cube_grid())[-3] - reference_point("idw_deform_point_-3")).max() < PYGEM_MATCH
    default = cadmorph.read_parameters(pygem("parameters_idw_default.prm"))
    assert default.to_prm() == open(pygem("parameters_idw_default.prm")).read()


def test_affine_and_composition():
    pts = np.array([[1.0, 1.0, 1.0], [0.0, 2.0, -1.0]])
    shift = cadmorph.Affine.translation([1.0, 0.0, 0.0])
    scale = cadmorph.Affine.scaling([2.0, 2.0, 2.0])
    both = shift.then(scale)
    np.testing.assert_array_equal(both(pts), (pts + [1.0, 0.0, 0.0]) * 2.0)
    chain = cadmorph.compose(shift, scale, shift)
    assert len(chain) == 3
    np.testing.assert_array_equal(chain(pts), (pts + [1.0, 0.0, 0.0]) * 2.0 + [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(chain.jacobian([0.0, 0.0, 0.0]), 2.0 * np.eye(3))
    rot = cadmorph.Affine.rotation([0.0, 0.0, 90.0])
    assert np.abs(rot(np.array([[1.0, 0.0, 0.0]])) - [0.0, 1.0, 0.0]).max() < 1e-15
    assert np.abs(rot.inverse()(rot(pts)) - pts).max() < 1e-14


def test_python_function_deformation_and_its_errors():
    f = cadmorph.FromFunction(lambda p: p * [1.0, 1.0, 2.0])
    pts = np.random.default_rng(0).uniform(size=(10_000, 3))
    np.testing.assert_array_equal(f(pts), pts * [1.0, 1.0, 2.0])
    ffd = cadmorph.read_parameters(pygem("parameters_test_ffd_sphere.prm"))
    np.testing.assert_array_equal(f.then(ffd)(pts), ffd(pts * [1.0, 1.0, 2.0]))

    def boom(p):
        raise ZeroDivisionError("inside the user's function")

    with pytest.raises(ZeroDivisionError, match="user's function"):
        cadmorph.FromFunction(boom)(pts)
    with pytest.raises(ValueError, match="returned 1 points for 10000"):
        cadmorph.FromFunction(lambda p: p[:1])(pts)


def test_threads_are_reported():
    assert cadmorph.num_threads() >= 1
    with pytest.raises(ValueError, match="n must be at least 1"):
        cadmorph.set_num_threads(0)


def test_version_is_the_workspace_version():
    cargo = open(os.path.join(os.path.dirname(__file__), "..", "..", "Cargo.toml")).read()
    line = next(l for l in cargo.splitlines() if l.startswith("version = "))
    assert cadmorph.__version__ == line.split('"')[1]
