#!/usr/bin/env python3
"""planing_hull.py - the planing-hull sample and OCCT's measurements of hull files.

OCCT 7.9.3 through OCP (tests/occt/setup.sh makes the venv). Commands:

  make [--out-dir DIR]
      Build samples/planing_hull.igs and samples/planing_hull.stp (deterministic bytes):
      a closed double-chine planing hull of length 10 m, x from the transom (x = 0) to the
      stem (x = 10), y to starboard, z up. Per side three B-spline faces joined at sharp
      chines: V bottom (keel to inner chine), narrow chine strip (inner to outer chine),
      flared straight wall (outer chine to deck edge); plus a planar transom and a planar
      deck. Every side face is cubic along x (8 poles, knots 0 .2 .4 .6 .8 1, poles at
      the Greville abscissae so x(u) = 10 u exactly) and linear across, so every
      transverse section of a side face is a straight segment.
  volume FILE
      BRepGProp volume (adaptive Gauss, Eps 1e-12) and centre of mass of every solid, the
      BRepCheck validity and the bounding box, as JSON.
  sections FILE --x X [X ...]
      Cut the shape with the planes x = X (BRepAlgoAPI_Section) and print, per plane, the
      section's edges sampled at 21 points each, as JSON.

Exit codes: 0 fine, 1 read or transfer failed, 3 bad usage.
"""
import argparse
import json
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import occt_ref  # noqa: E402  (reader, quiet OCCT)

SAMPLES = os.path.normpath(os.path.join(HERE, "..", "..", "samples"))
FIXED_DATE_IGES = "20250101.000000"
FIXED_DATE_STEP = "2025-01-01T00:00:00"

LENGTH = 10.0
U_KNOTS = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]
U_MULTS = [4, 1, 1, 1, 1, 4]
U_DEGREE = 3


def greville():
    flat = []
    for k, m in zip(U_KNOTS, U_MULTS):
        flat += [k] * m
    n = len(flat) - U_DEGREE - 1
    return [sum(flat[i + 1:i + 1 + U_DEGREE]) / U_DEGREE for i in range(n)]


def width(t):
    """Half-breadth factor: 1 over the aft half, a parabola closing to 0 at the stem."""
    return 1.0 if t <= 0.5 else 1.0 - ((t - 0.5) / 0.5) ** 2


def keel_rise(t):
    return 0.0 if t <= 0.6 else 0.6 * ((t - 0.6) / 0.4) ** 2


def section_points(t):
    """Keel, inner chine, outer chine and deck edge (starboard) of the control section at t."""
    w = width(t)
    x = LENGTH * t
    zk = keel_rise(t)
    z1 = zk + 0.45 * w + 0.3 * (1.0 - w)
    keel = (x, 0.0, zk)
    inner = (x, 1.2 * w, z1)
    outer = (x, 1.35 * w, z1 + 0.1)
    deck = (x, 1.6 * w, 2.0)
    return keel, inner, outer, deck


def mirror(p):
    return (p[0], -p[1], p[2])


def build():
    from OCP.Geom import Geom_BSplineSurface, Geom_BSplineCurve
    from OCP.TColgp import TColgp_Array2OfPnt, TColgp_Array1OfPnt
    from OCP.TColStd import TColStd_Array1OfReal, TColStd_Array1OfInteger
    from OCP.gp import gp_Pnt
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing, BRepBuilderAPI_MakeEdge,
                                    BRepBuilderAPI_MakeWire, BRepBuilderAPI_MakePolygon, BRepBuilderAPI_MakeSolid)
    from OCP.TopoDS import TopoDS
    from OCP.ShapeFix import ShapeFix_Solid
    from OCP.BRepCheck import BRepCheck_Analyzer

    def arr1(vals, kind):
        a = (TColStd_Array1OfReal if kind is float else TColStd_Array1OfInteger)(1, len(vals))
        for i, v in enumerate(vals):
            a.SetValue(i + 1, v)
        return a

    sections = [section_points(g) for g in greville()]
    n = len(sections)

    def surface(a, b):
        """Cubic x linear surface from row a to row b of the sections (v = 0 on a)."""
        poles = TColgp_Array2OfPnt(1, n, 1, 2)
        for i, s in enumerate(sections):
            pa, pb = a(s), b(s)
            poles.SetValue(i + 1, 1, gp_Pnt(*pa))
            poles.SetValue(i + 1, 2, gp_Pnt(*pb))
        return Geom_BSplineSurface(poles, arr1(U_KNOTS, float), arr1([0.0, 1.0], float),
                                   arr1(U_MULTS, int), arr1([2, 2], int), U_DEGREE, 1)

    def curve(a):
        poles = TColgp_Array1OfPnt(1, n)
        for i, s in enumerate(sections):
            poles.SetValue(i + 1, gp_Pnt(*a(s)))
        return Geom_BSplineCurve(poles, arr1(U_KNOTS, float), arr1(U_MULTS, int), U_DEGREE)

    rows = [lambda s: s[0], lambda s: s[1], lambda s: s[2], lambda s: s[3]]
    faces = []
    for side in (lambda p: p, mirror):
        for k in range(3):
            a, b = rows[k], rows[k + 1]
            faces.append(BRepBuilderAPI_MakeFace(surface(lambda s, a=a: side(a(s)), lambda s, b=b: side(b(s))),
                                                 1e-7).Face())
    # Transom: the polygon through the x = 0 section points.
    k0, i0, o0, d0 = sections[0]
    poly = BRepBuilderAPI_MakePolygon()
    for p in (k0, i0, o0, d0, mirror(d0), mirror(o0), mirror(i0)):
        poly.Add(gp_Pnt(*p))
    poly.Close()
    faces.append(BRepBuilderAPI_MakeFace(poly.Wire(), True).Face())
    # Deck: bounded by the two deck edges and the transom's top edge.
    wire = BRepBuilderAPI_MakeWire()
    wire.Add(BRepBuilderAPI_MakeEdge(curve(lambda s: s[3])).Edge())
    wire.Add(BRepBuilderAPI_MakeEdge(curve(lambda s: mirror(s[3]))).Edge())
    wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(*d0), gp_Pnt(*mirror(d0))).Edge())
    faces.append(BRepBuilderAPI_MakeFace(wire.Wire(), True).Face())
    sew = BRepBuilderAPI_Sewing(tol)
    for f in faces:
        sew.Add(f)
    sew.Perform()
    shell = TopoDS.Shell_s(sew.SewedShape())
    solid = BRepBuilderAPI_MakeSolid(shell).Solid()
    fix = ShapeFix_Solid(solid)
    fix.Perform()
    solid = fix.Solid()
    if not BRepCheck_Analyzer(solid).IsValid():
        raise SystemExit("error: the planing hull is not a valid OCCT solid")
    return solid


def _fix_iges_header(path):
    with open(path, "r", newline="") as f:
        lines = f.read().split("\n")
    out = []
    for ln in lines:
        if len(ln) >= 73 and ln[72] == "G":
            ln = re.sub(r"15H\d{8}\.\d{6}", "15H" + FIXED_DATE_IGES, ln)
        out.append(ln)
    with open(path, "w", newline="") as f:
        f.write("\n".join(out))


def _fix_step_header(path):
    with open(path, "r", newline="") as f:
        txt = f.read()
    txt = re.sub(r"FILE_NAME\('([^']*)','[0-9T:\-]+'",
                 lambda m: "FILE_NAME('%s','%s'" % (m.group(1), FIXED_DATE_STEP), txt, count=1)
    with open(path, "w", newline="") as f:
        f.write(txt)


def cmd_make(a):
    from OCP.IGESControl import IGESControl_Writer
    from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
    from OCP.Interface import Interface_Static
    from OCP.TCollection import TCollection_HAsciiString
    occt_ref.init_occt()
    solid = build()
    os.makedirs(a.out_dir, exist_ok=True)
    igs = os.path.join(a.out_dir, "planing_hull.igs")
    stp = os.path.join(a.out_dir, "planing_hull.stp")
    Interface_Static.SetCVal_s("write.iges.header.author", "occref")
    Interface_Static.SetCVal_s("write.iges.header.company", "occref")
    Interface_Static.SetIVal_s("write.iges.brep.mode", 0)
    w = IGESControl_Writer("M", 0)
    gs = w.Model().GlobalSection()
    gs.SetCascadeUnit(1000.0)
    gs.SetAuthorName(TCollection_HAsciiString("occref"))
    gs.SetCompanyName(TCollection_HAsciiString("occref"))
    w.Model().SetGlobalSection(gs)
    w.AddShape(solid)
    w.ComputeModel()
    if not w.Write(igs):
        raise SystemExit("error: cannot write " + igs)
    _fix_iges_header(igs)
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "M")
    Interface_Static.SetIVal_s("write.step.assembly", 0)
    Interface_Static.SetCVal_s("xstep.cascade.unit", "M")
    sw = STEPControl_Writer()
    if occt_ref.status_name(sw.Transfer(solid, STEPControl_AsIs)) != "IFSelect_RetDone":
        raise SystemExit("error: STEP transfer failed")
    if occt_ref.status_name(sw.Write(stp)) != "IFSelect_RetDone":
        raise SystemExit("error: cannot write " + stp)
    _fix_step_header(stp)
    print(json.dumps({"written": [igs, stp]}))


def _solids_or_sewn(shape, tol=1e-6):
    """The solids of a shape; a closed shell (IGES faces mode) is sewn (tolerance `tol`)
    and made solid first."""
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopAbs import TopAbs_SOLID, TopAbs_FACE
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing, BRepBuilderAPI_MakeSolid
    from OCP.TopoDS import TopoDS
    from OCP.ShapeFix import ShapeFix_Solid
    from OCP.TopAbs import TopAbs_SHELL
    solids = []
    ex = TopExp_Explorer(shape, TopAbs_SOLID)
    while ex.More():
        solids.append(ex.Current())
        ex.Next()
    if solids:
        return solids, False
    sew = BRepBuilderAPI_Sewing(tol)
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        sew.Add(ex.Current())
        ex.Next()
    sew.Perform()
    sewn = sew.SewedShape()
    ex = TopExp_Explorer(sewn, TopAbs_SHELL)
    while ex.More():
        fix = ShapeFix_Solid(BRepBuilderAPI_MakeSolid(TopoDS.Shell_s(ex.Current())).Solid())
        fix.Perform()
        solids.append(fix.Solid())
        ex.Next()
    return solids, True


def cmd_volume(a):
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    loaded = occt_ref.Loaded(a.file)
    out = dict(loaded.info)
    if not loaded.ok:
        print(json.dumps(out))
        return 1
    out["valid"] = bool(BRepCheck_Analyzer(loaded.shape).IsValid())
    solids, sewn = _solids_or_sewn(loaded.shape, a.sew_tol)
    out["sewn"] = sewn
    out["solids"] = []
    total = 0.0
    for s in solids:
        p = GProp_GProps()
        err = BRepGProp.VolumeProperties_s(s, p, 1e-12, True)
        c = p.CentreOfMass()
        out["solids"].append({"volume": p.Mass(), "error": err, "centre": [c.X(), c.Y(), c.Z()],
                              "valid": bool(BRepCheck_Analyzer(s).IsValid())})
        total += p.Mass()
    out["volume"] = total
    # The area of every face of the shape (sewn or not), adaptive Gauss like the volume.
    ap = GProp_GProps()
    out["area_error"] = BRepGProp.SurfaceProperties_s(loaded.shape, ap, 1e-12, True)
    out["area"] = ap.Mass()
    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(loaded.shape, box, False, False)
    out["bbox"] = list(box.Get())
    print(json.dumps(out, indent=1))
    return 0


def cmd_sections(a):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
    from OCP.gp import gp_Pln, gp_Pnt, gp_Dir
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopoDS import TopoDS
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    loaded = occt_ref.Loaded(a.file)
    out = dict(loaded.info)
    if not loaded.ok:
        print(json.dumps(out))
        return 1
    out["sections"] = []
    for x in a.x:
        sec = BRepAlgoAPI_Section(loaded.shape, gp_Pln(gp_Pnt(x, 0, 0), gp_Dir(1, 0, 0)))
        sec.Build()
        edges = []
        ex = TopExp_Explorer(sec.Shape(), TopAbs_EDGE)
        while ex.More():
            c = BRepAdaptor_Curve(TopoDS.Edge_s(ex.Current()))
            t0, t1 = c.FirstParameter(), c.LastParameter()
            pts = []
            for k in range(21):
                p = c.Value(t0 + (t1 - t0) * k / 20.0)
                pts.append([p.X(), p.Y(), p.Z()])
            edges.append(pts)
            ex.Next()
        out["sections"].append({"x": x, "done": bool(sec.IsDone()), "edges": edges})
    print(json.dumps(out))
    return 0


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("make")
    m.add_argument("--out-dir", default=SAMPLES)
    v = sub.add_parser("volume")
    v.add_argument("file")
    v.add_argument("--sew-tol", type=float, default=1e-6,
                   help="sewing tolerance for faces that come without a solid (model units)")
    s = sub.add_parser("sections")
    s.add_argument("file")
    s.add_argument("--x", type=float, nargs="+", required=True)
    a = p.parse_args(argv)
    # OCCT prints to fd 1; keep the JSON clean.
    real = os.dup(1)
    os.dup2(2, 1)
    sys.stdout = os.fdopen(real, "w")
    return {"make": cmd_make, "volume": cmd_volume, "sections": cmd_sections}[a.cmd](a) or 0


if __name__ == "__main__":
    sys.exit(main())
