"""Bad arguments raise TypeError/ValueError naming the argument; the input array is not copied."""
import os
import tracemalloc

import numpy as np
import pytest

import cadmorph
import cadmorph.pygem as pygem_compat
from conftest import pygem

FFD_PRM = pygem("parameters_test_ffd_sphere.prm")
POINTS = np.load(pygem("meshpoints_sphere_orig.npy"))


def deformations():
    c = np.random.default_rng(1).uniform(-50, 50, size=(8, 3))
    return {
        "ffd": cadmorph.read_parameters(FFD_PRM),
        "rbf": cadmorph.Rbf(c, c + 0.1, kernel="thin_plate_spline", radius=10.0),
        "idw": cadmorph.Idw(c, c + 0.1),
        "affine": cadmorph.Affine.scaling([1.0, 2.0, 3.0]),
        "function": cadmorph.FromFunction(lambda p: p),
    }


@pytest.mark.parametrize("kind", ["ffd", "rbf", "idw", "affine", "function"])
def test_bad_points_name_the_argument(kind):
    d = deformations()[kind]
    with pytest.raises(TypeError, match=r"points must be a numpy.ndarray.*got list"):
        d([[0.0, 0.0, 0.0]])
    with pytest.raises(TypeError, match=r"points must have dtype float64, got float32"):
        d(POINTS.astype(np.float32))
    with pytest.raises(TypeError, match=r"points must have dtype float64"):
        d(POINTS.astype(np.int64))
    with pytest.raises(ValueError, match=r"points must have shape \(n, 3\), got \(7200, 2\)"):
        d(np.ascontiguousarray(POINTS[:, :2]))
    with pytest.raises(ValueError, match=r"points must have shape \(n, 3\), got \(21600,\)"):
        d(POINTS.ravel())
    with pytest.raises(ValueError, match=r"points must be C-contiguous"):
        d(np.asfortranarray(POINTS))
    with pytest.raises(ValueError, match=r"points must be C-contiguous"):
        d(np.ascontiguousarray(np.repeat(POINTS, 2, axis=0))[::2])
    for bad in (np.nan, np.inf, -np.inf):
        p = POINTS.copy()
        p[4321, 2] = bad
        p[6500, 1] = bad  # a later one, in another chunk: the first is named
        with pytest.raises(ValueError, match=r"points\[4321, 2\] is (NaN|inf|-inf)"):
            d(p)
        with pytest.raises(ValueError, match=r"points\[4321, 2\]"):
            d(p, out=p)
        small = POINTS[:100].copy()
        small[7, 0] = bad
        before = small.copy()
        with pytest.raises(ValueError, match=r"points\[7, 0\]"):
            d(small, out=small)
        # The bad point is left as it was; the finite ones are unmoved (one chunk checked
        # before it moves) or, for the FFD (its check is in its kernel), all moved.
        np.testing.assert_array_equal(small[7], before[7])
        finite = np.ones(100, bool)
        finite[7] = False
        moved = d(np.ascontiguousarray(before[finite]))
        if kind == "ffd":
            np.testing.assert_array_equal(small[finite], moved)
        else:
            np.testing.assert_array_equal(small, before)
    with pytest.raises(ValueError, match=r"out must have the shape of points"):
        d(POINTS, out=np.empty((5, 3)))
    with pytest.raises(TypeError, match=r"out must have dtype float64"):
        d(POINTS, out=np.empty((7200, 3), dtype=np.float32))
    with pytest.raises(ValueError, match=r"readonly|writeable|not writeable|read-only"):
        ro = POINTS.copy()
        ro.flags.writeable = False
        d(ro, out=ro)


def test_bad_constructor_arguments_name_the_argument():
    c = np.random.default_rng(1).uniform(-50, 50, size=(8, 3))
    with pytest.raises(ValueError, match="original_control_points must have shape"):
        cadmorph.Rbf(c[:, :2].copy(), c)
    bad = c.copy()
    bad[3, 0] = np.nan
    with pytest.raises(ValueError, match=r"deformed_control_points\[3, 0\] is NaN"):
        cadmorph.Rbf(c, bad)
    with pytest.raises(ValueError, match="deformed_control_points must have as many rows"):
        cadmorph.Idw(c, c[:5].copy())
    with pytest.raises(ValueError, match="kernel: unknown \"gaussian_splines\""):
        cadmorph.Rbf(c, c, kernel="gaussian_splines")
    with pytest.raises(ValueError, match="variant must be"):
        cadmorph.Idw(c, c, variant="shepard")
    with pytest.raises(ValueError, match="box_length must hold exactly three values"):
        cadmorph.Ffd((2, 2, 2), box_length=[1.0, 1.0])
    with pytest.raises(ValueError, match="box_origin must be finite"):
        cadmorph.Ffd((2, 2, 2), box_origin=[0.0, np.nan, 0.0])
    with pytest.raises(cadmorph.ParameterError, match="box length"):
        cadmorph.Ffd((2, 2, 2), box_length=[1.0, -1.0, 1.0])
    with pytest.raises(cadmorph.ParameterError, match="at least 2"):
        cadmorph.Ffd((1, 2, 2))
    ffd = cadmorph.Ffd((2, 2, 2))
    with pytest.raises(ValueError, match=r"mu_x must have shape \[2, 2, 2\]"):
        ffd.mu_x = np.zeros((3, 2, 2))
    with pytest.raises(ValueError, match="mu_y must be finite"):
        ffd.mu_y = np.full((2, 2, 2), np.nan)
    with pytest.raises(TypeError, match="deformation must be a cadmorph deformation"):
        cadmorph.open(os.path.join(os.path.dirname(__file__), "..", "..", "samples", "hull3.igs")).morph("ffd.prm")
    with pytest.raises(TypeError, match="func must be callable"):
        cadmorph.FromFunction(3)


def test_parameter_files_name_path_and_line(tmp_path):
    with pytest.raises(cadmorph.ParameterError) as e:
        cadmorph.read_parameters(pygem("parameters_rbf_bugged_02.prm"))
    assert e.value.line == 9 and e.value.path.endswith("parameters_rbf_bugged_02.prm")
    assert "gaussian_splines" in str(e.value) and isinstance(e.value, ValueError)
    with pytest.raises(cadmorph.ParameterError) as e:
        cadmorph.read_parameters(pygem("parameters_rbf_bugged_01.prm"))
    assert e.value.line == 30
    bad = tmp_path / "bad.toml"
    bad.write_text("[ffd]\nn_control_points = [2, 2, 2]\nbox_origin = [0, 0, 0]\nbox_length = [1, 1]\n")
    with pytest.raises(cadmorph.ParameterError) as e:
        cadmorph.read_parameters(bad)
    assert e.value.line == 4
    with pytest.raises(FileNotFoundError):
        cadmorph.read_parameters(tmp_path / "missing.prm")


def rss_peak_mb():
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmHWM")


def reset_peak():
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")


def test_the_input_array_is_not_copied():
    """The morph reads the caller's buffer: the process's peak memory grows by the one
    output array (24 MB for 10^6 points), not by a second copy of the input, and not at all
    in place. numpy allocations are traced by tracemalloc: a copy made on the Python side
    (the PyGeM layer's ascontiguousarray) would show there."""
    ffd = cadmorph.read_parameters(FFD_PRM)
    rng = np.random.default_rng(0)
    pts = rng.uniform(-60, 60, size=(1_000_000, 3))
    size_mb = pts.nbytes / 2**20
    ffd(pts[:10])  # warm up (pool, pages of the code)
    reset_peak()
    base = rss_peak_mb()
    out = ffd(pts)
    grew = rss_peak_mb() - base
    assert grew < 1.5 * size_mb, f"peak grew by {grew:.1f} MB for a {size_mb:.1f} MB input"
    assert not np.shares_memory(out, pts)
    del out
    reset_peak()
    base = rss_peak_mb()
    address = pts.ctypes.data
    same = ffd(pts, out=pts)
    assert same is pts and pts.ctypes.data == address
    assert rss_peak_mb() - base < 0.2 * size_mb
    # The PyGeM layer passes the caller's array through (tracemalloc sees numpy's allocations).
    compat = pygem_compat.FFD()
    compat.read_parameters(FFD_PRM)
    tracemalloc.start()
    compat(pts)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 0.1 * pts.nbytes, f"tracemalloc peak {peak} bytes"
