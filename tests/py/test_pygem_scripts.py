"""PyGeM-style scripts run with one changed import and give PyGeM's numbers.

CI has no PyGeM: the numbers are PyGeM's own, stored in samples/pygem (its test data) and
tests/py/data (made by tests/py/make_reference.py with PyGeM b482f27). With PYGEM_DIR set
to a PyGeM checkout (and scipy installed), the tutorial script also runs under PyGeM
itself, with the import changed back, and the two outputs are compared directly.
"""
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import PYGEM_MATCH, DATA, ROOT, SCRIPTS, occt, pygem, run_script, sample

SPHERE_PRM = pygem("parameters_test_ffd_sphere.prm")
SPHERE = pygem("meshpoints_sphere_orig.npy")


def test_tutorial_1_gives_pygems_numbers(tmp_path):
    out = tmp_path / "out.npz"
    printed = run_script(os.path.join(SCRIPTS, "tutorial_1_ffd.py"), SPHERE_PRM, SPHERE, str(out))
    assert "Movements of point[1, 1, 1] along x: 2.0" in printed
    assert "<class 'numpy.ndarray'> (2000, 3)" in printed
    got = np.load(out)
    ref = np.load(os.path.join(DATA, "tutorial1_pygem.npz"))
    assert np.abs(got["new_mesh"] - ref["new_mesh"]).max() < PYGEM_MATCH
    assert np.abs(got["control_points"] - ref["control_points"]).max() < PYGEM_MATCH
    assert np.abs(got["new_sphere"] - np.load(pygem("meshpoints_sphere_mod.npy"))).max() < PYGEM_MATCH


def test_tutorial_1_under_pygem_itself(tmp_path):
    pygem_dir = os.environ.get("PYGEM_DIR")
    if not pygem_dir:
        pytest.skip("PYGEM_DIR not set (PyGeM's stored numbers are checked by the test above)")
    pytest.importorskip("scipy")
    text = open(os.path.join(SCRIPTS, "tutorial_1_ffd.py")).read()
    assert text.count("from cadmorph") == 1, "the script differs from PyGeM's by its import only"
    script = tmp_path / "pygem_tutorial_1.py"
    script.write_text(text.replace("from cadmorph.pygem import FFD", "from pygem import FFD"))
    env = dict(os.environ, PYTHONPATH=pygem_dir, MPLBACKEND="Agg")
    res = subprocess.run([sys.executable, str(script), SPHERE_PRM, SPHERE, str(tmp_path / "p.npz")], env=env,
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    ours = tmp_path / "c.npz"
    run_script(os.path.join(SCRIPTS, "tutorial_1_ffd.py"), SPHERE_PRM, SPHERE, str(ours))
    a, b = np.load(tmp_path / "p.npz"), np.load(ours)
    for k in a.files:
        assert np.abs(a[k] - b[k]).max() < PYGEM_MATCH, k


@pytest.mark.parametrize("ext", ["igs", "stp"])
def test_cad_tutorial_on_hull3_gives_pygems_poles_and_a_valid_file(tmp_path, ext):
    out = tmp_path / f"hull3_bow.{ext}"
    printed = run_script(os.path.join(SCRIPTS, "tutorial_2_cad.py"), sample("prm", "bow_dome.prm"),
                         sample(f"hull3.{ext}"), str(out))
    assert " | " in printed  # the tutorial's diff shows changed lines
    # OCCT reads the written file: valid, and its poles are what PyGeM's CAD FFD computes
    # (each face's poles moved by the point FFD), face by face.
    check = occt("validate", str(out))
    assert check["read_ok"] and check["transfer_ok"] and check["valid"], check.get("invalid_faces")
    ref = occt("ref", str(out))
    pg = np.load(os.path.join(DATA, "hull3_bow_dome_pygem.npz"))
    assert len(ref["faces"]) == 3
    moved = 0.0
    for face in ref["faces"]:
        i = face["index"]
        poles = np.array(face["poles"], dtype=float).reshape(-1, 3)
        expected = pg[f"{ext}_out_{i}"]
        assert poles.shape == expected.shape
        assert np.abs(poles - expected).max() < PYGEM_MATCH, (i, np.abs(poles - expected).max())
        moved = max(moved, np.abs(expected - pg[f"{ext}_in_{i}"]).max())
    assert moved > 0.1  # the bow really moved (0.37 m)
