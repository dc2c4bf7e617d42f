"""Regenerates the PyGeM outputs the Python tests compare with (tests/py/data/*.npz).

CI has no PyGeM, so its numbers are stored. This script runs PyGeM itself (GitHub
mathLab/PyGeM, not the PyPI package of that name; commit b482f27 was used) on:

* ``tutorial1_pygem.npz``: PyGeM's tutorial 1 (FFD of a 2000-point Fibonacci sphere,
  ``FFD([2, 2, 2])`` with ``array_mu_x[1, 1, 1] = 2``, ``array_mu_z[1, 1, 1] = 0.8``):
  ``mesh``, ``new_mesh``, ``control_points`` (deformed) and ``control_points_orig``;
* ``hull3_bow_dome_pygem.npz``: what ``pygem.cad.FFD`` computes for
  ``samples/hull3.igs`` / ``.stp`` with ``samples/prm/bow_dome.prm``: PyGeM's CAD FFD moves
  every pole of every face's B-spline surface with its point FFD
  (``pygem/cad/cad_deformation.py``, ``_deform_bspline_surface``). The poles are the ones
  OCCT reads (``samples/hull3.*.ref.json``, made by tests/occt/occt_ref.py ``ref``), so
  neither side of the comparison comes from cadmorph: ``igs_in_<i>`` / ``igs_out_<i>``
  (and ``stp_...``) are face ``i``'s poles, (n_u·n_v, 3) in ``poles[i_u][i_v]`` order.

    python3 -m venv /tmp/pygem-venv && /tmp/pygem-venv/bin/pip install numpy scipy matplotlib
    PYGEM_DIR=/path/to/PyGeM /tmp/pygem-venv/bin/python tests/py/make_reference.py
"""
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.environ["PYGEM_DIR"])
import matplotlib  # noqa: E402

matplotlib.use("Agg")
from pygem import FFD  # noqa: E402


def mesh_points(num_pts=2000):
    """Tutorial 1's point cloud, verbatim."""
    indices = np.arange(0, num_pts, dtype=float) + 0.5
    phi = np.arccos(1 - 2 * indices / num_pts)
    theta = np.pi * (1 + 5**0.5) * indices
    return np.array([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)]).T


def tutorial1():
    mesh = mesh_points()
    ffd = FFD([2, 2, 2])
    ffd.array_mu_x[1, 1, 1] = 2
    ffd.array_mu_z[1, 1, 1] = 0.8
    new_mesh = ffd(mesh)
    np.savez(os.path.join(HERE, "data", "tutorial1_pygem.npz"), mesh=mesh, new_mesh=new_mesh,
             control_points=ffd.control_points(), control_points_orig=ffd.control_points(False))


def hull3():
    ffd = FFD()
    ffd.read_parameters(os.path.join(ROOT, "samples", "prm", "bow_dome.prm"))
    out = {}
    for ext in ("igs", "stp"):
        ref = json.load(open(os.path.join(ROOT, "samples", f"hull3.{ext}.ref.json")))
        assert ref["result_unit"] == "M"
        for face in ref["faces"]:
            assert face["class"] == "Geom_BSplineSurface", face["class"]
            poles = np.array(face["poles"], dtype=float).reshape(-1, 3)
            out[f"{ext}_in_{face['index']}"] = poles
            out[f"{ext}_out_{face['index']}"] = ffd(poles)
    np.savez(os.path.join(HERE, "data", "hull3_bow_dome_pygem.npz"), **out)


if __name__ == "__main__":
    tutorial1()
    hull3()
    print("wrote", os.path.join(HERE, "data"))
