"""Print PyGeM's full-precision values for the single-point checks of cadmorph's morph tests.

Usage: PYGEM_DIR=/path/to/PyGeM python reference_points.py > samples/pygem/pygem_reference_points.txt

PYGEM_DIR is a checkout of GitHub mathLab/PyGeM (commit b482f27 for the committed file);
PyGeM needs numpy, scipy and matplotlib (imported by pygem.rbf) and nothing else here.
Each output line is `name x y z` with Python's repr of each coordinate.
"""
import os
import sys

import numpy as np

pygem_dir = os.environ.get("PYGEM_DIR")
if not pygem_dir:
    sys.exit("set PYGEM_DIR to a checkout of GitHub mathLab/PyGeM")
sys.path.insert(0, pygem_dir)
import matplotlib

matplotlib.use("Agg")
from pygem import IDW, RBF  # noqa: E402

data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "samples", "pygem")


def cube_mesh_points():
    """The 20^3 grid of PyGeM's tests/test_rbf.py and tests/test_idw.py."""
    xv = np.linspace(0, 1, 20)
    yv = np.linspace(0, 1, 20)
    zv = np.linspace(0, 1, 20)
    z, y, x = np.meshgrid(zv, yv, xv)
    return np.array([x.ravel(), y.ravel(), z.ravel()]).T


def emit(name, p):
    print(name, " ".join(repr(float(v)) for v in p))


mesh = cube_mesh_points()
rbf = RBF()
rbf.read_parameters(os.path.join(data, "parameters_rbf_extra.prm"))
emit("rbf_extra_point_17", rbf(mesh)[17])
idw = IDW()
idw.read_parameters(os.path.join(data, "parameters_idw_deform.prm"))
emit("idw_deform_point_-3", idw(mesh)[-3])
