"""Shared paths and helpers of the Python tests (run by scripts/test through tests/py/setup.sh)."""
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PYGEM_DATA = os.path.join(ROOT, "samples", "pygem")
DATA = os.path.join(os.path.dirname(__file__), "data")
SCRIPTS = os.path.join(os.path.dirname(__file__), "scripts")

# PyGeM parity, as crates/morph/tests: absolute, on PyGeM's own data.
PYGEM_MATCH = 1e-10


def sample(*parts):
    return os.path.join(ROOT, "samples", *parts)


def pygem(name):
    return os.path.join(PYGEM_DATA, name)


def occt_python():
    """The OCCT oracle's interpreter (tests/occt/setup.sh makes it; scripts/test runs that first)."""
    py = os.environ.get("CADMORPH_OCCT_PYTHON", os.path.join(ROOT, "tests", "occt", ".venv", "bin", "python"))
    if not os.path.exists(py):
        pytest.fail(f"the OCCT oracle is not set up ({py}): run bash tests/occt/setup.sh")
    return py


def occt(command, path):
    """Run tests/occt/occt_ref.py COMMAND PATH and return its JSON."""
    import json

    out = subprocess.run([occt_python(), os.path.join(ROOT, "tests", "occt", "occt_ref.py"), command, path],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout)


def cube_grid():
    """PyGeM's test grid (tests/test_rbf.py, test_idw.py ``get_cube_mesh_points``), verbatim."""
    nx, ny, nz = (20, 20, 20)
    xv = np.linspace(0, 1, nx)
    yv = np.linspace(0, 1, ny)
    zv = np.linspace(0, 1, nz)
    z, y, x = np.meshgrid(zv, yv, xv)
    mesh = np.array([x.ravel(), y.ravel(), z.ravel()])
    return np.ascontiguousarray(mesh.T)


def reference_point(name):
    """A full-precision PyGeM value of samples/pygem/pygem_reference_points.txt."""
    for line in open(pygem("pygem_reference_points.txt")):
        parts = line.split()
        if parts and parts[0] == name:
            return np.array([float(v) for v in parts[1:4]])
    raise KeyError(name)


def run_script(path, *args, cwd=None):
    out = subprocess.run([sys.executable, path, *args], capture_output=True, text=True, cwd=cwd or ROOT, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout
