#!/usr/bin/env python3
"""topo_check.py - OCCT's shared edges of a file and its own measurement of their gaps.

    tests/occt/.venv/bin/python tests/occt/topo_check.py FILE [--samples 50] [--out X.json]

The oracle for issue 22 item 4 (edges from topology). OCCT reads FILE (numbers in the
file's own unit, as occt_ref.py does) and lists its faces in explorer order. Its shared
edges are those of its topology: every edge that two distinct faces use (seam edges of a
closed face, used by that one face twice, are not shared edges between faces). When the
file has no topology between faces (IGES 144 faces, bare surfaces: OCCT reads them as
separate faces), the shared edges are those OCCT's sewing (BRepBuilderAPI_Sewing at
1e-3 of the model size, the project's pairing tolerance) makes, mapped back to the faces
as read. In an IGES file with 408 subfigure instances each placed copy (each innermost
compound of faces OCCT makes) is sewn on its own: edges never join two placements.

Each shared edge is measured on the faces as read, by OCCT alone: N points along each
face's own curve of the edge (ends included; the shared edge itself when the topology
shares it) are measured to the other, trimmed face (the nearer of the projection onto
its surface, when that lies in or on the face, and BRepExtrema_DistShapeShape); the edge's
gap is the largest. This is the "gap closest" of `cadmorph seams`: how far the faces'
trimmed boundaries are from each other.

JSON: {"file", "unit", "size", "n_faces", "sewn", "edges": [{"faces": [a, b], "length",
"max_gap"}]} with a < b, sorted by faces then length.
"""
import argparse
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import occt_ref  # noqa: E402


def _shape_size(shape):
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    b = Bnd_Box()
    BRepBndLib.Add_s(shape, b)
    x0, y0, z0, x1, y1, z1 = b.Get()
    return math.dist((x0, y0, z0), (x1, y1, z1))


def _edge_faces(shape):
    """(edge, [distinct faces]) for every non-degenerate edge of `shape`."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape
    emap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, emap)
    out = []
    for k in range(1, emap.Extent() + 1):
        edge = TopoDS.Edge_s(emap.FindKey(k))
        if BRep_Tool.Degenerated_s(edge):
            continue
        uniq = []
        for f in emap.FindFromIndex(k):
            if not any(f.IsSame(g) for g in uniq):
                uniq.append(f)
        out.append((edge, [TopoDS.Face_s(f) for f in uniq]))
    return out


def _index_of(face, faces):
    for k, f in enumerate(faces):
        if f.IsSame(face):
            return k
    return None


def _instance_parts(shape):
    """The faces of each placed copy of an IGES file with 408 singular subfigure
    instances: the innermost compounds OCCT made that hold faces (a placed 308's 402
    group, one per placement), as lists of faces. Sewing them one by one keeps edges
    inside a placement, as cadmorph pairs them (never across instances); one sewing of
    everything at the model's tolerance would join different placements and copies of
    different scale."""
    from OCP.TopAbs import TopAbs_COMPOUND, TopAbs_FACE
    from OCP.TopoDS import TopoDS, TopoDS_Iterator
    from OCP.TopExp import TopExp_Explorer
    parts = []

    def walk(s, loc):
        it = TopoDS_Iterator(s)
        kids = []
        while it.More():
            kids.append(it.Value())
            it.Next()
        if any(k.ShapeType() == TopAbs_COMPOUND for k in kids):
            for k in kids:
                if k.ShapeType() == TopAbs_COMPOUND:
                    walk(k, loc)
            loose = [k for k in kids if k.ShapeType() != TopAbs_COMPOUND]
        else:
            loose = kids
        fs = []
        for k in loose:
            ex = TopExp_Explorer(k, TopAbs_FACE)
            while ex.More():
                fs.append(TopoDS.Face_s(ex.Current()))
                ex.Next()
        if fs:
            parts.append(fs)

    walk(shape, None)
    return parts


def shared_edges(faces, shape, size, parts=None):
    """[(edges of a, edges of b, a, b)]: each shared edge with the curves that stand for
    it on each face (the edge itself when the topology shares it; each face's own
    boundary edges that sewing merged into it otherwise), face indices into `faces`, and
    whether sewing made them."""
    pairs = []
    free = 0
    for edge, fs in _edge_faces(shape):
        if len(fs) == 1:
            free += 1
            continue
        idx = sorted(_index_of(f, faces) for f in fs)
        for i in range(len(idx)):
            for j in range(i + 1, len(idx)):
                pairs.append(([edge], [edge], idx[i], idx[j]))
    if pairs or free == 0:
        return pairs, False
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    if parts and len(parts) > 1:
        out = []
        for part in parts:
            idx = [_index_of(f, faces) for f in part]
            sub, _ = _sewn_pairs(part, size)
            for ea, eb, a, b in sub:
                out.append((ea, eb, idx[a], idx[b]) if idx[a] < idx[b] else (eb, ea, idx[b], idx[a]))
        return out, True
    return _sewn_pairs(faces, size)


def _sewn_pairs(faces, size):
    """Shared edges of `faces` after OCCT's sewing at 1e-3 of `size`, as in shared_edges."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    pairs = []
    sew = BRepBuilderAPI_Sewing(1e-3 * size)
    for f in faces:
        sew.Add(f)
    sew.Perform()
    sewn = sew.SewedShape()
    # Each face's own edges with the sewn edge each became.
    own = []
    for k, f in enumerate(faces):
        ex = TopExp_Explorer(f, TopAbs_EDGE)
        while ex.More():
            e = TopoDS.Edge_s(ex.Current())
            own.append((k, e, sew.Modified(e)))
            ex.Next()
    back = [(sew.Modified(f), k) for k, f in enumerate(faces)]
    for edge, fs in _edge_faces(sewn):
        if len(fs) < 2:
            continue
        idx = sorted({k for f in fs for g, k in back if g.IsSame(f)})
        for i in range(len(idx)):
            for j in range(i + 1, len(idx)):
                a, b = idx[i], idx[j]
                ea = [e for k, e, m in own if k == a and m.IsSame(edge)]
                eb = [e for k, e, m in own if k == b and m.IsSame(edge)]
                pairs.append((ea or [edge], eb or [edge], a, b))
    return pairs, True


_surfaces = {}


def _distance(point, face):
    """Distance from `point` to the trimmed `face`: the nearer of the projection onto its
    surface (GeomAPI_ProjectPointOnSurf), counted only when it lands in or on the face
    (BRepClass at the face's tolerance), and the nearest point BRepExtrema_DistShapeShape
    finds on the face. Both are distances to points of the face, so the smaller is the
    better answer (each alone is off by up to ~1e-5 of the size near the boundary of a
    surface of revolution)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepClass import BRepClass_FaceClassifier
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
    from OCP.TopAbs import TopAbs_IN, TopAbs_ON
    from OCP.gp import gp_Pnt2d
    key = id(face)
    if key not in _surfaces:
        _surfaces[key] = (face, BRep_Tool.Surface_s(face), BRep_Tool.Tolerance_s(face))
    _, surface, tol = _surfaces[key]
    best = math.inf
    proj = GeomAPI_ProjectPointOnSurf(point, surface)
    if proj.IsDone() and proj.NbPoints() > 0:
        u, v = proj.LowerDistanceParameters()
        # A periodic surface's face may lie a period away from the projection's answer.
        us = [u + k * surface.UPeriod() for k in (0, -1, 1, -2, 2)] if surface.IsUPeriodic() else [u]
        vs = [v + k * surface.VPeriod() for k in (0, -1, 1)] if surface.IsVPeriodic() else [v]
        if any(BRepClass_FaceClassifier(face, gp_Pnt2d(uu, vv), tol).State() in (TopAbs_IN, TopAbs_ON)
               for uu in us for vv in vs):
            best = proj.LowerDistance()
    d = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(point).Vertex(), face)
    if d.IsDone() and d.NbSolution() > 0:
        best = min(best, d.Value())
    return best


def _edge_points(edges, n):
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    pts = []
    for e in edges:
        c = BRepAdaptor_Curve(e)
        t0, t1 = c.FirstParameter(), c.LastParameter()
        pts.extend(c.Value(t0 + (t1 - t0) * k / (n - 1)) for k in range(n))
    return pts


def measure(ea, eb, fa, fb, n):
    """Largest distance from either face's own edge points to the other face, and the
    length of the first face's edge."""
    pa, pb = _edge_points(ea, n), _edge_points(eb, n)
    length = sum(pa[k].Distance(pa[k + 1]) for k in range(len(pa) - 1) if (k + 1) % n)
    gap = 0.0
    for points, other in ((pa, fb), (pb, fa)):
        for p in points:
            gap = max(gap, _distance(p, other))
    return gap, length


def check(path, n=50):
    loaded = occt_ref.Loaded(path)
    if not loaded.ok:
        raise SystemExit("%s: OCCT could not read it (%s)" % (path, loaded.info.get("read_status")))
    faces = loaded.faces()
    size = _shape_size(loaded.shape)
    parts = None
    if loaded.format == "IGES":
        model = loaded.reader.Model()
        if any(model.Value(i).TypeNumber() == 408 for i in range(1, model.NbEntities() + 1)):
            parts = _instance_parts(loaded.shape)
    pairs, sewn = shared_edges(faces, loaded.shape, size, parts)
    edges = []
    for ea, eb, a, b in pairs:
        gap, length = measure(ea, eb, faces[a], faces[b], n)
        edges.append({"faces": [a, b], "length": length, "max_gap": gap})
    edges.sort(key=lambda e: (e["faces"], e["length"]))
    return {"file": os.path.basename(path), "unit": loaded.info["result_unit"], "size": size,
            "n_faces": len(faces), "sewn": sewn, "samples": n, "edges": edges}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file")
    ap.add_argument("--samples", type=int, default=50)
    ap.add_argument("--out")
    a = ap.parse_args(argv)
    # OCCT prints to fd 1; keep the JSON clean.
    real = os.dup(1)
    os.dup2(2, 1)
    try:
        doc = check(a.file, max(a.samples, 2))
    finally:
        os.dup2(real, 1)
    text = json.dumps(doc, indent=1)
    if a.out:
        with open(a.out, "w") as fh:
            fh.write(text + "\n")
    else:
        sys.stdout.write(text + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
