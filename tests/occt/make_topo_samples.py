#!/usr/bin/env python3
"""make_topo_samples.py - the topology samples of issue 22 item 4, written by OCCT.

    tests/occt/.venv/bin/python tests/occt/make_topo_samples.py [--out-dir samples]

Writes, deterministically (fixed header dates and authors):

  assembly_ap203.stp, assembly_ap214.stp
      An inch assembly written the way cadquery's Assembly export writes one (an XCAF
      document through STEPCAFControl_Writer): a plate with a hole (planes, a cylinder),
      placed twice with different rotations, and a sub-assembly of two pins (cylinders,
      planes, a cone) that is itself placed twice, rotated. Every placed face comes from a
      NEXT_ASSEMBLY_USAGE_OCCURRENCE with a CONTEXT_DEPENDENT_SHAPE_REPRESENTATION and an
      ITEM_DEFINED_TRANSFORMATION; the same part's faces appear at several places.
      Unit: inch (write.step.unit = INCH), the numbers in the file are inches.
  assembly_catia.stp
      assembly_ap214.stp in the layout CATIA and NX write a part: the product's
      SHAPE_DEFINITION_REPRESENTATION names an axis-only SHAPE_REPRESENTATION, a
      SHAPE_REPRESENTATION_RELATIONSHIP(that, the ADVANCED_BREP_SHAPE_REPRESENTATION)
      joins the solid to it (the named one first, where OCCT writes no such pair), and the
      assembly's transformations place the named one. Made by rewriting OCCT's text.
  assembly_colors.stp
      assembly_ap214.stp with XCAF colours, as cadquery writes an assembly whose parts have
      colours: the plate red, the pin blue (STYLED_ITEMs of the parts' solids listed by a
      MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION), and one face of the plate
      (the cylinder of its hole) green.
  shaft.igs
      A stepped shaft revolved about an axis that is neither x, y nor z (so every surface
      carries a 124 transformation), with a fillet (torus) and a chamfer (cone), written
      in IGES faces mode: 144 trimmed surfaces with 142 curves on surface, analytic
      surfaces as OCCT writes them (120 surfaces of revolution, 190/192/194 planes and
      cylinders where OCCT uses them), metres.

The OCCT references (F.ref.json) are made afterwards with `occt_ref.py regen`, and the
seam references with `topo_check.py`.
"""
import argparse
import math
import os
import re

from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon, BRepBuilderAPI_MakeFace, BRepBuilderAPI_Transform
from OCP.BRepFilletAPI import BRepFilletAPI_MakeChamfer, BRepFilletAPI_MakeFillet
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeRevol
from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
from OCP.Interface import Interface_Static
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Controller
from OCP.TCollection import TCollection_ExtendedString, TCollection_HAsciiString
from OCP.TDataStd import TDataStd_Name
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.Quantity import Quantity_Color, Quantity_TOC_RGB
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from OCP.XCAFDoc import XCAFDoc_ColorSurf, XCAFDoc_DocumentTool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec

HERE = os.path.dirname(os.path.abspath(__file__))
FIXED_DATE_IGES = "20250101.000000"
FIXED_DATE_STEP = "2025-01-01T00:00:00"
INCH = 25.4


def trsf(axis=(0.0, 0.0, 1.0), deg=0.0, move=(0.0, 0.0, 0.0)):
    """A rotation by `deg` about `axis` through the origin, then a translation."""
    r = gp_Trsf()
    if deg:
        r.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(*axis)), math.radians(deg))
    t = gp_Trsf()
    t.SetTranslation(gp_Vec(*move))
    return t.Multiplied(r)


def plate():
    """A 4 x 2 x 0.25 in plate with a 0.5 in hole (mm numbers, written as inches)."""
    box = BRepPrimAPI_MakeBox(4 * INCH, 2 * INCH, 0.25 * INCH).Shape()
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1 * INCH, 1 * INCH, -1.0), gp_Dir(0, 0, 1)),
                                    0.25 * INCH, 0.25 * INCH + 2.0).Shape()
    return BRepAlgoAPI_Cut(box, hole).Shape()


def pin():
    """A 0.24 in radius, 1.5 in pin with a chamfered top (cylinder, cone, planes)."""
    cyl = BRepPrimAPI_MakeCylinder(0.24 * INCH, 1.5 * INCH).Shape()
    ch = BRepFilletAPI_MakeChamfer(cyl)
    ex = TopExp_Explorer(cyl, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge_s(ex.Current())
        c = BRepAdaptor_Curve(e)
        p = c.Value(c.FirstParameter())
        if abs(p.Z() - 1.5 * INCH) < 1e-6 and c.GetType().name == "GeomAbs_Circle":
            ch.Add(0.05 * INCH, e)
        ex.Next()
    return ch.Shape()


def fix_step_header(path):
    with open(path, "r", newline="") as f:
        txt = f.read()
    txt = re.sub(r"FILE_NAME\('([^']*)','[0-9T:\-]+'",
                 lambda m: "FILE_NAME('%s','%s'" % (m.group(1), FIXED_DATE_STEP), txt, count=1)
    with open(path, "w", newline="") as f:
        f.write(txt)


def fix_iges_header(path):
    with open(path, "r", newline="") as f:
        lines = f.read().split("\n")
    out = []
    for ln in lines:
        if len(ln) >= 73 and ln[72] == "G":
            ln = re.sub(r"15H\d{8}\.\d{6}", "15H" + FIXED_DATE_IGES, ln)
        out.append(ln)
    with open(path, "w", newline="") as f:
        f.write("\n".join(out))


def write_assembly(path, schema, colors=False):
    """The assembly through XCAF, as cadquery's `Assembly.save(..., "STEP")` does; with
    `colors`, the parts and one face coloured."""
    STEPControl_Controller.Init_s()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())

    def named(label, name):
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))

    plate_l = tool.AddShape(plate(), False)
    named(plate_l, "plate")
    pin_l = tool.AddShape(pin(), False)
    named(pin_l, "pin")
    pair_l = tool.NewShape()
    named(pair_l, "pin_pair")
    tool.AddComponent(pair_l, pin_l, TopLoc_Location(trsf(move=(0.5 * INCH, 0.5 * INCH, 0.0))))
    tool.AddComponent(pair_l, pin_l, TopLoc_Location(trsf((1, 0, 0), 180.0, (3.0 * INCH, 1.5 * INCH, 0.25 * INCH))))
    top = tool.NewShape()
    named(top, "assembly")
    tool.AddComponent(top, plate_l, TopLoc_Location(trsf()))
    tool.AddComponent(top, plate_l, TopLoc_Location(trsf((0, 0, 1), 30.0, (1.0 * INCH, 3.0 * INCH, 0.5 * INCH))))
    tool.AddComponent(top, pair_l, TopLoc_Location(trsf((0, 0, 1), 0.0, (0.0, 0.0, 0.25 * INCH))))
    tool.AddComponent(top, pair_l, TopLoc_Location(trsf((1, 1, 0), 90.0, (6.0 * INCH, 0.0, 1.0 * INCH))))
    if colors:
        ctool = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
        rgb = lambda r, g, b: Quantity_Color(r, g, b, Quantity_TOC_RGB)  # noqa: E731
        ctool.SetColor(plate_l, rgb(0.8, 0.1, 0.1), XCAFDoc_ColorSurf)
        ctool.SetColor(pin_l, rgb(0.1, 0.2, 0.9), XCAFDoc_ColorSurf)
        ex = TopExp_Explorer(tool.GetShape_s(plate_l), TopAbs_FACE)
        while ex.More():
            if BRepAdaptor_Surface(TopoDS.Face_s(ex.Current())).GetType().name == "GeomAbs_Cylinder":
                face_l = tool.AddSubShape(plate_l, ex.Current())
                ctool.SetColor(face_l, rgb(0.1, 0.7, 0.2), XCAFDoc_ColorSurf)
                break
            ex.Next()
    tool.UpdateAssemblies()
    assert Interface_Static.SetCVal_s("write.step.schema", schema)
    assert Interface_Static.SetCVal_s("write.step.unit", "INCH")
    Interface_Static.SetIVal_s("write.step.assembly", 1)
    w = STEPCAFControl_Writer()
    assert w.Transfer(doc, STEPControl_AsIs), path
    assert w.Write(path).name == "IFSelect_RetDone", path
    fix_step_header(path)


def catia_layout(text):
    """`text` (an OCCT assembly) with each part's solid behind an axis-only
    SHAPE_REPRESENTATION that the product names and the assembly places."""
    top = max(int(m) for m in re.findall(r"^#(\d+) =", text, re.M))
    absr = dict(re.findall(r"^#(\d+) = ADVANCED_BREP_SHAPE_REPRESENTATION\('',\(#(\d+),", text, re.M))
    ctx = dict(re.findall(r"^#(\d+) = ADVANCED_BREP_SHAPE_REPRESENTATION\(.*,#(\d+)\);", text, re.M))
    added = []
    for rep, axis in sorted(absr.items(), key=lambda kv: int(kv[0])):
        sr, srr = top + 1, top + 2
        top += 2
        added.append("#%d = SHAPE_REPRESENTATION('',(#%s),#%s);" % (sr, axis, ctx[rep]))
        added.append("#%d = SHAPE_REPRESENTATION_RELATIONSHIP('','',#%d,#%s);" % (srr, sr, rep))
        text = re.sub(r"(SHAPE_DEFINITION_REPRESENTATION\(#\d+,)#%s\)" % rep, r"\g<1>#%d)" % sr, text)
        text = text.replace("REPRESENTATION_RELATIONSHIP('','',#%s," % rep, "REPRESENTATION_RELATIONSHIP('','',#%d," % sr)
    return text.replace("ENDSEC;\nEND-ISO", "\n".join(added) + "\nENDSEC;\nEND-ISO", 1)


def shaft():
    """A stepped shaft (metres): profile in the xz plane revolved about x, with a fillet
    at a shoulder and a chamfer at one end, then placed on a tilted axis."""
    pts = [(0.0, 0.0), (0.0, 0.03), (0.12, 0.03), (0.12, 0.045), (0.30, 0.045),
           (0.30, 0.035), (0.42, 0.035), (0.42, 0.0)]
    poly = BRepBuilderAPI_MakePolygon()
    for x, r in pts:
        poly.Add(gp_Pnt(x, 0.0, r))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire()).Face()
    solid = BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), 2 * math.pi).Shape()
    fil = BRepFilletAPI_MakeFillet(solid)
    cha = []
    ex = TopExp_Explorer(solid, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge_s(ex.Current())
        c = BRepAdaptor_Curve(e)
        if c.GetType().name == "GeomAbs_Circle":
            p = c.Value(c.FirstParameter())
            r = math.hypot(p.Y(), p.Z())
            if abs(p.X() - 0.12) < 1e-9 and abs(r - 0.03) < 1e-9:
                fil.Add(0.006, e)
            if abs(p.X() - 0.42) < 1e-9:
                cha.append(e)
        ex.Next()
    solid = fil.Shape()
    ch = BRepFilletAPI_MakeChamfer(solid)
    ex = TopExp_Explorer(solid, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge_s(ex.Current())
        c = BRepAdaptor_Curve(e)
        if c.GetType().name == "GeomAbs_Circle":
            p = c.Value(c.FirstParameter())
            if abs(p.X() - 0.42) < 1e-9 and abs(math.hypot(p.Y(), p.Z()) - 0.035) < 1e-9:
                ch.Add(0.004, e)
        ex.Next()
    solid = ch.Shape()
    t = trsf((1.0, 2.0, 3.0), 37.0, (0.1, -0.2, 0.05))
    return BRepBuilderAPI_Transform(solid, t, True).Shape()


def write_shaft(path):
    IGESControl_Controller.Init_s()
    Interface_Static.SetCVal_s("write.iges.header.author", "occref")
    Interface_Static.SetCVal_s("write.iges.header.company", "occref")
    Interface_Static.SetIVal_s("write.iges.brep.mode", 0)
    Interface_Static.SetCVal_s("xstep.cascade.unit", "M")
    w = IGESControl_Writer("M", 0)
    gs = w.Model().GlobalSection()
    gs.SetCascadeUnit(1000.0)
    gs.SetAuthorName(TCollection_HAsciiString("occref"))
    gs.SetCompanyName(TCollection_HAsciiString("occref"))
    w.Model().SetGlobalSection(gs)
    w.AddShape(shaft())
    w.ComputeModel()
    assert w.Write(path), path
    fix_iges_header(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out-dir", default=os.path.normpath(os.path.join(HERE, "..", "..", "samples")))
    a = ap.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    write_assembly(os.path.join(a.out_dir, "assembly_ap203.stp"), "AP203")
    write_assembly(os.path.join(a.out_dir, "assembly_ap214.stp"), "AP214IS")
    write_assembly(os.path.join(a.out_dir, "assembly_colors.stp"), "AP214IS", colors=True)
    with open(os.path.join(a.out_dir, "assembly_ap214.stp")) as f:
        catia = catia_layout(f.read())
    with open(os.path.join(a.out_dir, "assembly_catia.stp"), "w", newline="") as f:
        f.write(catia)
    write_shaft(os.path.join(a.out_dir, "shaft.igs"))


if __name__ == "__main__":
    main()
