#!/usr/bin/env python3
"""writer_solids.py - solids as OCCT's own writers make them, for the seam checks.

OCCT 7.9.3 through OCP (tests/occt/setup.sh makes the venv). Command:

  make DIR
      Writes into DIR, each as STEP (AP214) and as IGES in B-rep mode (186/514/510
      faces on 190-198 analytic surfaces, write.iges.brep.mode 1) and face mode (144):
      * fillet_box: a 40 x 30 x 20 box with every edge filleted (r 3), turned 0.7 rad
        about (1, 1, 1) and moved: planes, quarter cylinders and sphere octants whose
        poles lie on the fillets' edges and which reach their surfaces' seams;
      * torus: a whole torus (R 20, r 5) about a tilted axis, closed in both directions;
      * closed_extrusion: a periodic B-spline profile through six points
        (GeomAPI_Interpolate, periodic) extruded by 15: an extrusion of a closed curve
        whose seam its face wraps across.
      Prints {"files": [...]} as JSON on its last line (OCCT's writers print their
      progress to stdout before it).

  make DIR --more
      The three above and, in the same three forms, solids whose faces straddle their
      closed surfaces' seams or end at poles (for the volume checks):
      * capsule: a cylinder (r 5, h 20) fused with a sphere at each end, tilted: two
        hemispheres bounded by a circle and a seam edge used twice;
      * cone: a cone (r 8, apex at height 12) about a tilted axis;
      * nose: a B-spline profile from the axis to the axis revolved a whole turn (a
        surface of revolution with two poles), turned and moved;
      * ring_sector: a 6 x 4 rectangle 10 from the axis revolved by 270 degrees, turned
        so that its faces cross the surfaces' u = 0.

  make DIR --pierced
      Only these, in the same three forms: solids with a face across its closed
      surface's seam, as booleans leave them (for the conversion checks):
      * cross_hole: a shaft (r 10, h 60) bored across by a hole (r 3) along x, which
        goes through the shaft's seam on one side;
      * tee: the shaft fused with a branch (r 5) along x, meeting it on its seam;
      * notch: the shaft cut by a box that takes a slot out of it across its seam;
      * torus_band: a torus (R 20, r 6) about a tilted axis cut to a box: a band
        around the tube bounded by a plane section and its seam edge.

Exit codes: 0 fine, 1 OCCT failed, 3 bad usage.
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import occt_ref  # noqa: E402,F401  (quiet OCCT)


def shapes():
    from OCP.gp import gp_Pnt, gp_Dir, gp_Ax1, gp_Ax2, gp_Vec, gp_Trsf
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeTorus, BRepPrimAPI_MakePrism
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire,
                                    BRepBuilderAPI_MakeFace, BRepBuilderAPI_Transform)
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopoDS import TopoDS
    from OCP.TColgp import TColgp_HArray1OfPnt
    from OCP.GeomAPI import GeomAPI_Interpolate

    box = BRepPrimAPI_MakeBox(40, 30, 20).Shape()
    fillet = BRepFilletAPI_MakeFillet(box)
    ex = TopExp_Explorer(box, TopAbs_EDGE)
    while ex.More():
        fillet.Add(3.0, TopoDS.Edge_s(ex.Current()))
        ex.Next()
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 1, 1)), 0.7)
    t.SetTranslationPart(gp_Vec(100, -50, 20))
    out = {"fillet_box": BRepBuilderAPI_Transform(fillet.Shape(), t, True).Shape()}
    out["torus"] = BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 1, 1)), 20, 5).Shape()
    pts = TColgp_HArray1OfPnt(1, 6)
    for i, (x, y) in enumerate([(0, 0), (10, -3), (20, 2), (30, 0), (25, 10), (10, 12)]):
        pts.SetValue(i + 1, gp_Pnt(x, y, 0))
    ip = GeomAPI_Interpolate(pts, True, 1e-9)
    ip.Perform()
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(ip.Curve()).Edge()).Wire()
    face = BRepBuilderAPI_MakeFace(wire).Face()
    out["closed_extrusion"] = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 15)).Shape()
    return out


def more_shapes():
    from OCP.gp import gp_Pnt, gp_Dir, gp_Ax1, gp_Ax2, gp_Vec, gp_Trsf
    from OCP.BRepPrimAPI import (BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeSphere,
                                 BRepPrimAPI_MakeCone, BRepPrimAPI_MakeRevol)
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire,
                                    BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon,
                                    BRepBuilderAPI_Transform)
    from OCP.TColgp import TColgp_HArray1OfPnt
    from OCP.GeomAPI import GeomAPI_Interpolate

    def placed(shape, axis, angle, move):
        t = gp_Trsf()
        t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(*axis)), angle)
        t.SetTranslationPart(gp_Vec(*move))
        return BRepBuilderAPI_Transform(shape, t, True).Shape()

    out = {}
    body = BRepPrimAPI_MakeCylinder(5, 20).Shape()
    for z in (0, 20):
        body = BRepAlgoAPI_Fuse(body, BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, z), 5).Shape()).Shape()
    out["capsule"] = placed(body, (1, -2, 0.5), 0.9, (7, 3, -4))
    out["cone"] = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(2, 1, 0), gp_Dir(1, 1, 2)), 8, 0, 12).Shape()
    # A profile in the xz-plane from the axis (x = 0) out and back, closed by the axis.
    prof = [(0, 0), (4, 1), (6, 5), (5, 10), (2, 14), (0, 15)]
    pts = TColgp_HArray1OfPnt(1, len(prof))
    for i, (x, z) in enumerate(prof):
        pts.SetValue(i + 1, gp_Pnt(x, 0, z))
    ip = GeomAPI_Interpolate(pts, False, 1e-9)
    ip.Perform()
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(ip.Curve()).Edge(),
                                   BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 15), gp_Pnt(0, 0, 0)).Edge()).Wire()
    nose = BRepPrimAPI_MakeRevol(BRepBuilderAPI_MakeFace(wire).Face(),
                                 gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2 * math.pi).Shape()
    out["nose"] = placed(nose, (0.3, 1, 0.2), 2.2, (-5, 8, 1))
    rect = BRepBuilderAPI_MakePolygon(gp_Pnt(10, 0, 0), gp_Pnt(16, 0, 0), gp_Pnt(16, 0, 4),
                                      gp_Pnt(10, 0, 4), True).Wire()
    ring = BRepPrimAPI_MakeRevol(BRepBuilderAPI_MakeFace(rect).Face(),
                                 gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.5 * math.pi).Shape()
    out["ring_sector"] = placed(ring, (0, 0, 1), -2.5, (0, 0, 0))
    return out


def pierced_shapes():
    from OCP.gp import gp_Pnt, gp_Dir, gp_Ax2
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeBox, BRepPrimAPI_MakeTorus
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse, BRepAlgoAPI_Common

    def cylinder(origin, axis, r, h):
        return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(*origin), gp_Dir(*axis)), r, h).Shape()

    shaft = cylinder((0, 0, 0), (0, 0, 1), 10, 60)
    torus = BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0.2, 0.1, 1)), 20, 6).Shape()
    return {
        "cross_hole": BRepAlgoAPI_Cut(shaft, cylinder((-20, 0, 30), (1, 0, 0), 3, 40)).Shape(),
        "tee": BRepAlgoAPI_Fuse(shaft, cylinder((0, 0, 30), (1, 0, 0), 5, 25)).Shape(),
        "notch": BRepAlgoAPI_Cut(shaft, BRepPrimAPI_MakeBox(gp_Pnt(5, -3, 20), 10, 6, 10).Shape()).Shape(),
        "torus_band": BRepAlgoAPI_Common(torus, BRepPrimAPI_MakeBox(gp_Pnt(-30, -30, -3), 60, 35, 20).Shape()).Shape(),
    }


def main(argv):
    if len(argv) not in (2, 3) or argv[0] != "make" or argv[2:] not in ([], ["--more"], ["--pierced"]):
        print(__doc__, file=sys.stderr)
        return 3
    from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
    from OCP.IGESControl import IGESControl_Writer
    from OCP.Interface import Interface_Static
    from OCP.IFSelect import IFSelect_RetDone
    out = argv[1]
    os.makedirs(out, exist_ok=True)
    files = []
    solids = pierced_shapes() if argv[2:] == ["--pierced"] else shapes()
    if argv[2:] == ["--more"]:
        solids.update(more_shapes())
    for name, s in solids.items():
        Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
        w = STEPControl_Writer()
        w.Transfer(s, STEPControl_AsIs)
        path = os.path.join(out, name + ".stp")
        if w.Write(path) != IFSelect_RetDone:
            return 1
        files.append(path)
        for mode, tag in [(1, "brep"), (0, "faces")]:
            iw = IGESControl_Writer("MM", mode)
            iw.AddShape(s)
            iw.ComputeModel()
            path = os.path.join(out, "%s_%s.igs" % (name, tag))
            if not iw.Write(path):
                return 1
            files.append(path)
    print(json.dumps({"files": files}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
