"""The model API: open, faces, edges, morph (seams kept), seams, save; checked by OCCT."""
import os

import numpy as np
import pytest

import cadmorph
from conftest import occt, sample

HULL_TOL = 1.45e-5  # 1e-7 of the hull's length, the README's main job


@pytest.mark.parametrize("ext", ["igs", "stp"])
def test_morph_keeps_seams_and_saves_a_file_occt_accepts(tmp_path, ext):
    m = cadmorph.open(sample(f"hull3.{ext}"))
    assert len(m) == 3 and m.format == ("iges" if ext == "igs" else "step") and m.unit in ("M", "METRE")
    faces = m.faces
    assert [f["u_degree"] for f in faces] == [3, 3, 3]
    assert all(f["face"].startswith("DE " if ext == "igs" else "#") for f in faces)
    assert sum(e["kind"] == "iso" for e in m.edges) == 2
    before = m.seams()
    assert len(before) >= 2 and max(e["gap_matched"]["max"] for e in before) < 1e-9
    original = m.to_bytes()
    bow = cadmorph.read_parameters(sample("prm", "bow_dome.prm"))
    outcome = m.morph(bow, refine_tol=HULL_TOL)
    assert outcome["refinement"]["converged"]
    assert outcome["control_points_after"] > outcome["control_points_before"]
    assert outcome["faces_rewritten"] >= 2
    after = m.seam_report()
    assert after["max_gap_matched"] <= HULL_TOL
    assert m.to_bytes() != original
    v = m.verify()
    assert v["seams"]["max_gap_matched"] <= HULL_TOL
    out = tmp_path / f"morphed.{ext}"
    m.save(str(out))
    check = occt("validate", str(out))
    assert check["read_ok"] and check["transfer_ok"] and check["valid"] and check["n_faces"] == 3
    back = cadmorph.open(out)
    for i in range(3):
        assert np.abs(back.control_points(i) - m.control_points(i)).max() <= max(v["max_deviation"], 1e-12)


def test_a_failed_morph_leaves_the_model_unchanged_and_names_the_face():
    m = cadmorph.open(sample("hull3.igs"))
    original = m.to_bytes()
    mirror = cadmorph.Affine.scaling([1.0, -1.0, 1.0])
    with pytest.raises(cadmorph.CadFileError) as e:
        m.morph(mirror)
    assert "folds space" in str(e.value) and e.value.entity is not None and e.value.entity.startswith("DE ")
    assert e.value.path.endswith("hull3.igs")
    nan = cadmorph.FromFunction(lambda p: p * np.nan)
    with pytest.raises(cadmorph.CadFileError, match="non-finite"):
        m.morph(nan)
    assert m.to_bytes() == original


def test_unreadable_files_raise_with_path_line_and_entity(tmp_path):
    with pytest.raises(FileNotFoundError):
        cadmorph.open(tmp_path / "missing.igs")
    text = open(sample("hull3.igs"), "rb").read()
    lines = text.split(b"\n")
    # Break the first parameter-data record: its entity type no longer matches its DE.
    k = next(i for i, l in enumerate(lines) if len(l) >= 73 and l[72:73] == b"P")
    lines[k] = b"XYZ" + lines[k][3:]
    bad = tmp_path / "bad.igs"
    bad.write_bytes(b"\n".join(lines))
    with pytest.raises(cadmorph.CadFileError) as e:
        cadmorph.open(bad)
    assert e.value.path == str(bad)
    assert e.value.line == k + 1, str(e.value)
    assert isinstance(e.value, ValueError)
    with pytest.raises(cadmorph.CadFileError, match="not an IGES or STEP file"):
        cadmorph.from_bytes(b"hello")
    m = cadmorph.open(sample("hull3.igs"))
    with pytest.raises(cadmorph.CadFileError, match="extension"):
        m.save(str(tmp_path / "out.txt"))
