#!/usr/bin/env python3
"""mesh_check.py - OpenCASCADE's distance from points to a CAD model.

Usage: mesh_check.py CAD_FILE POINTS_JSON

POINTS_JSON holds [[x, y, z], ...] in the file's own length unit (the unit cadmorph
works in). Prints one JSON object: the number of points, the largest distance from a
point to the model's faces (BRepExtrema_DistShapeShape of a vertex against the whole
shape, trims included) with the index of that point, and the model's size (the diagonal
of its bounding box). Used by the `mesh from-cad` tests to check that the triangles lie
within the chordal tolerance of the CAD.
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import occt_ref  # noqa: E402


def main(argv):
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.gp import gp_Pnt

    loaded = occt_ref.Loaded(argv[0])
    if not loaded.ok:
        print(json.dumps({"ok": False}))
        return 1
    shape = loaded.shape
    with open(argv[1]) as f:
        points = json.load(f)
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    x0, y0, z0, x1, y1, z1 = box.Get()
    worst, at = 0.0, -1
    for i, (x, y, z) in enumerate(points):
        v = BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, z)).Vertex()
        d = BRepExtrema_DistShapeShape(v, shape)
        dist = d.Value() if d.IsDone() else float("inf")
        if dist > worst:
            worst, at = dist, i
    size = ((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2) ** 0.5
    print(json.dumps({"ok": True, "points": len(points), "max_distance": worst, "worst": at, "size": size}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
