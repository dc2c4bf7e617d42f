#!/usr/bin/env python3
"""trimmed_solid.py - a solid with a curved face trimmed inside its surface, made by OCCT.

OCCT 7.9.3 through OCP (tests/occt/setup.sh makes the venv). Command:

  make OUT.stp [OUT.igs]
      A bicubic B-spline "bump" surface z = 1 + bump(x, y) over [-2, 2]^2, swept down by
      4 (BRepPrimAPI_MakePrism) and intersected (BRepAlgoAPI_Common) with the box
      [-1, 1]^2 x [-2, 4] turned 30 degrees about z: the top face is the bump trimmed by
      four lines that are no iso-lines of it, the other faces are planes. Written as STEP
      (and IGES when a second name is given); prints the BRepGProp volume (Eps 1e-12)
      and centre of mass as JSON.

Exit codes: 0 fine, 1 OCCT failed, 3 bad usage.
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import occt_ref  # noqa: E402,F401  (quiet OCCT)


def build():
    from OCP.Geom import Geom_BSplineSurface
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfReal, TColStd_Array1OfInteger
    from OCP.gp import gp_Pnt, gp_Vec, gp_Trsf, gp_Ax1, gp_Dir
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Transform
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism, BRepPrimAPI_MakeBox
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    n = 6
    poles = TColgp_Array2OfPnt(1, n, 1, n)
    for i in range(n):
        for j in range(n):
            x = -2.0 + 4.0 * i / (n - 1)
            y = -2.0 + 4.0 * j / (n - 1)
            z = 1.0 + 0.4 * math.exp(-(x * x + 0.5 * y * y)) + 0.05 * x * y
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, y, z))

    def arr(vals, cls):
        a = cls(1, len(vals))
        for k, v in enumerate(vals):
            a.SetValue(k + 1, v)
        return a

    knots = arr([0.0, 0.5, 1.0], TColStd_Array1OfReal)
    mults = arr([4, 2, 4], TColStd_Array1OfInteger)
    surf = Geom_BSplineSurface(poles, knots, knots, mults, mults, 3, 3)
    face = BRepBuilderAPI_MakeFace(surf, 1e-7).Face()
    prism = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, -4)).Shape()
    box = BRepPrimAPI_MakeBox(gp_Pnt(-1, -1, -2), 2.0, 2.0, 6.0).Shape()
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.pi / 6)
    box = BRepBuilderAPI_Transform(box, t, True).Shape()
    common = BRepAlgoAPI_Common(prism, box)
    common.Build()
    if not common.IsDone():
        raise RuntimeError("BRepAlgoAPI_Common failed")
    return common.Shape()


def main(argv):
    if len(argv) not in (1, 2):
        print(__doc__, file=sys.stderr)
        return 3
    from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
    from OCP.IGESControl import IGESControl_Writer
    from OCP.GProp import GProp_GProps
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepCheck import BRepCheck_Analyzer
    shape = build()
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    if int(w.Write(argv[0])) != 1:
        return 1
    if len(argv) == 2:
        iw = IGESControl_Writer("MM", 1)
        iw.AddShape(shape)
        iw.ComputeModel()
        if not iw.Write(argv[1]):
            return 1
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-12)
    c = props.CentreOfMass()
    out = {"valid": bool(BRepCheck_Analyzer(shape).IsValid()), "volume": props.Mass(), "centre": [c.X(), c.Y(), c.Z()]}
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    real = os.dup(1)
    os.dup2(2, 1)
    sys.stdout = os.fdopen(real, "w")
    sys.exit(main(sys.argv[1:]))
