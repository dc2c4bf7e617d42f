#!/usr/bin/env python3
"""cffd_oracle.py - PyGeM's CFFD, BFFD and VFFD on the inputs of PyGeM's own tests.

    bash tests/pygem/setup.sh            # venv with numpy and scipy (PyGeM's dependencies)
    tests/pygem/.venv/bin/python tests/pygem/cffd_oracle.py --pygem DIR > crates/morph/tests/data/pygem_cffd.json

DIR is a PyGeM source tree (the `pygem/` package inside it), e.g. the mathLab/PyGeM commit
b482f27 exported with `git archive`. Each case rebuilds the inputs exactly as
tests/test_cffd.py, test_bffd.py and test_vffd.py do (np.random.seed(0), the same draws in
the same order, tests/test_datasets/parameters_test_cffd.prm), runs adjust_control_points,
and records the inputs, the adjusted lattice displacements and the deformed points.
Floats are written with repr, so the JSON holds the exact doubles.
"""
import argparse
import json
import os
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pygem", required=True, help="PyGeM source tree")
    a = ap.parse_args()
    sys.path.insert(0, a.pygem)
    import numpy as np
    from pygem import CFFD, BFFD, VFFD
    from pygem.vffd import _volume
    prm = os.path.join(a.pygem, "tests", "test_datasets", "parameters_test_cffd.prm")

    def mu(f):
        return {"x": f.array_mu_x.ravel().tolist(), "y": f.array_mu_y.ravel().tolist(),
                "z": f.array_mu_z.ravel().tolist()}

    def moves(f, pts):
        """Which points PyGeM's FFD moves: psi's rounding puts some face points a hair
        outside the unit box (PyGeM issue 272), and those stay where they are."""
        r = f.psi(pts - f.box_origin)
        return np.all(np.logical_and(r >= 0.0, r <= 1.0), axis=1).tolist()

    def box(f):
        return {"n_control_points": [int(n) for n in f.n_control_points], "box_length": f.box_length.tolist(),
                "box_origin": f.box_origin.tolist(), "rot_angle": f.rot_angle.tolist()}

    cases = []
    for read in (False, True):
        # test_cffd.py: linear constraint A @ x.ravel() = b.
        np.random.seed(0)
        pts = np.random.rand(100, 3)
        A = np.random.rand(3, pts.reshape(-1).shape[0])
        fun = lambda x: A @ x.reshape(-1)  # noqa: E731
        b = fun(pts) + (0.02 * np.random.rand(3) if read else 0.0)
        f = CFFD(b, fun)
        if read:
            f.read_parameters(prm)
        before = mu(f)
        f.adjust_control_points(pts)
        cases.append({"name": "cffd_" + ("constraint" if read else "nothing_happens"), "kind": "linear",
                      "points": pts.tolist(), "matrix": A.tolist(), "fixval": np.atleast_1d(b).tolist(),
                      "mu_before": before, "box": box(f), "moves": moves(f, pts), "mu_after": mu(f), "deformed": f.ffd(pts).tolist(),
                      "achieved": np.atleast_1d(fun(f.ffd(pts))).tolist()})
        # test_bffd.py: barycentre.
        np.random.seed(0)
        pts = np.random.rand(100, 3)
        A = np.random.rand(3, pts.reshape(-1).shape[0])
        b = np.mean(pts, axis=0) + (0.02 * np.random.rand(3) if read else 0.0)
        f = BFFD(b)
        if read:
            f.read_parameters(prm)
        before = mu(f)
        f.adjust_control_points(pts)
        cases.append({"name": "bffd_" + ("constraint" if read else "nothing_happens"), "kind": "barycentre",
                      "points": pts.tolist(), "fixval": np.atleast_1d(b).tolist(), "mu_before": before,
                      "box": box(f), "moves": moves(f, pts), "mu_after": mu(f), "deformed": f.ffd(pts).tolist(),
                      "achieved": np.atleast_1d(f.fun(f.ffd(pts))).tolist()})
        # test_vffd.py: volume of a closed triangulated cube.
        np.random.seed(0)
        pts = 0.5 * np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 0.0, 0.0],
                              [1.0, 0.0, 1.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0]])
        tri = np.array([[0, 1, 2], [3, 1, 0], [4, 5, 6], [4, 7, 5], [7, 4, 3], [3, 4, 1], [6, 5, 0], [6, 0, 2],
                        [0, 5, 3], [3, 5, 7], [6, 2, 1], [6, 1, 4]])
        b = _volume(pts, tri) + (0.02 * np.random.rand() if read else 0.0)
        f = VFFD(tri, b)
        if read:
            f.read_parameters(prm)
        before = mu(f)
        f.adjust_control_points(pts)
        cases.append({"name": "vffd_" + ("constraint" if read else "nothing_happens"), "kind": "volume",
                      "points": pts.tolist(), "triangles": tri.tolist(), "fixval": np.atleast_1d(b).tolist(),
                      "mu_before": before, "box": box(f), "moves": moves(f, pts), "mu_after": mu(f), "deformed": f.ffd(pts).tolist(),
                      "achieved": np.atleast_1d(f.fun(f.ffd(pts))).tolist()})
    json.dump({"generator": "tests/pygem/cffd_oracle.py", "pygem_commit": "b482f27",
               "numpy": np.__version__, "cases": cases}, sys.stdout, indent=0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
