#!/usr/bin/env python3
"""edge_check.py - OpenCASCADE's view of a written B-rep's edges and shape.

Usage: edge_check.py FILE [--samples N]

Prints one JSON object: read status, BRepCheck_Analyzer validity, topology counts
(solids, shells, faces, edges; edges counted once however many faces use them), the
area (BRepGProp's adaptive integration to a relative error of 1e-10, `area_error` its
own estimate: its fixed-order Gauss rule misses the area of faces of degree 8-24 by up to
3e-5) and, over every edge that has a 3D curve, the largest distance from N
evenly spaced points of that curve to each face using the edge (GeomAPI_ProjectPointOnSurf
onto the face's surface, and ShapeAnalysis_Surface's projection, the nearer kept):
`edge_to_face_max`, with the worst edge's index, and the
number of edges used by two different faces (`shared_edges`).
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import occt_ref  # noqa: E402


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(prog="edge_check.py")
    ap.add_argument("file")
    ap.add_argument("--samples", type=int, default=50)
    a = ap.parse_args(argv)

    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
    from OCP.GProp import GProp_GProps
    from OCP.ShapeAnalysis import ShapeAnalysis_Surface
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp, TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

    loaded = occt_ref.Loaded(a.file)
    out = dict(loaded.info)
    if not loaded.ok:
        out["valid"] = False
        print(json.dumps(out))
        return 1
    shape = loaded.shape
    out["valid"] = bool(BRepCheck_Analyzer(shape).IsValid())

    def count(kind):
        m = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(shape, kind, m)
        return m.Extent()

    out["topology"] = {"solids": count(TopAbs_SOLID), "shells": count(TopAbs_SHELL),
                       "faces": count(TopAbs_FACE), "edges": count(TopAbs_EDGE)}
    props = GProp_GProps()
    out["area_error"] = BRepGProp.SurfaceProperties_s(shape, props, 1e-10)
    out["area"] = props.Mass()

    users = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, users)
    worst, worst_edge, shared, measured = 0.0, None, 0, 0
    per_edge = []
    for i in range(1, users.Extent() + 1):
        edge = TopoDS.Edge_s(users.FindKey(i))
        if BRep_Tool.Degenerated_s(edge):
            continue
        faces = []
        for f in users.FindFromIndex(i):
            face = TopoDS.Face_s(f)
            if not any(face.IsSame(g) for g in faces):
                faces.append(face)
        if len(faces) >= 2:
            shared += 1
        curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)
        if curve is None:
            continue
        ad = BRepAdaptor_Curve(edge)
        t0, t1 = ad.FirstParameter(), ad.LastParameter()
        d_edge = 0.0
        for face in faces:
            surface = BRep_Tool.Surface_s(face)
            sas = ShapeAnalysis_Surface(surface)
            for k in range(a.samples):
                p = ad.Value(t0 + (t1 - t0) * k / (a.samples - 1))
                # Two projections, the nearer kept: GeomAPI's extrema can settle on a
                # farther extremum of a high-degree surface; ShapeAnalysis' (used by
                # ShapeFix) searches from a grid.
                ds = []
                proj = GeomAPI_ProjectPointOnSurf(p, surface)
                if proj.NbPoints() > 0:
                    ds.append(proj.LowerDistance())
                uv = sas.ValueOfUV(p, 1e-12)
                ds.append(surface.Value(uv.X(), uv.Y()).Distance(p))
                d_edge = max(d_edge, min(ds))
        measured += 1
        per_edge.append(d_edge)
        if d_edge > worst:
            worst, worst_edge = d_edge, i - 1
    out["shared_edges"] = shared
    out["edges_measured"] = measured
    out["edge_to_face_max"] = worst
    out["edge_to_face_worst_edge"] = worst_edge
    out["edge_to_face"] = per_edge

    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
