#!/usr/bin/env python3
"""make_instance_samples.py - the placed-instance samples of issue 22 item 4.

    tests/occt/.venv/bin/python tests/occt/make_instance_samples.py [--out-dir samples]

Writes, deterministically (fixed header dates and authors):

  mapped_item.stp
      The plate of make_topo_samples.py (planes and a cylinder, millimetres), placed five
      times by MAPPED_ITEM (ISO 10303-43 §4.5.6 representation_map, §4.5.7 mapped_item), the
      way CATIA- and NX-style "representation map" files place repeated geometry:
      the product's shape representation `assembly` holds three MAPPED_ITEMs, two of a
      sub-representation `pair` (itself holding two MAPPED_ITEMs of the part's
      ADVANCED_BREP_SHAPE_REPRESENTATION) and one of the part directly; 2 x 2 + 1 = 5
      placements. The part's REPRESENTATION_MAP has a mapping origin that is not the
      identity, so target ∘ origin⁻¹ is exercised. The part's representation has no
      SHAPE_DEFINITION_REPRESENTATION of its own: only the maps reach it.
  mapped_item_root.stp
      The same, except that the part's representation keeps the SHAPE_DEFINITION_REPRESENTATION
      OCCT wrote for it (so its product is a root too), and a second product carries the
      `assembly` representation: does OCCT read the part once more, unplaced?
  mapped_item_inch.stp
      mapped_item.stp with the top representation in an inch context (a copy of OCCT's
      millimetre context with a CONVERSION_BASED_UNIT inch): the MAPPED_ITEM targets of
      `assembly` are inches, the origins of the maps millimetres.

No OCCT writer emits MAPPED_ITEM for placed parts (STEPCAFControl_Writer writes
NEXT_ASSEMBLY_USAGE_OCCURRENCE / CONTEXT_DEPENDENT_SHAPE_REPRESENTATION), so both files are
made by rewriting the STEP text OCCT writes for the single part (STEPControl_Writer,
AP214): the new entities are appended after OCCT's own, and the product's
SHAPE_DEFINITION_REPRESENTATION is pointed at the new top representation.

  subfigure.igs
      IGES 5.3 §4.74 (308 subfigure definition) and §4.137 (408 singular subfigure
      instance), as a writer that keeps repeated parts as subfigures makes them: the plate
      in IGES faces mode (OCCT's 402 group of 144 trimmed surfaces on 108 planes and a 120
      surface of revolution, 142 curves on surface, millimetres) is the content of a 308
      `PART` (depth 0); a 308 `PAIR` (depth 1) holds two 408 instances of `PART` (one
      carrying a 124 rotation and translation, one with scale 0.5 and a translation), and
      two 408s of `PAIR` at the top (one with a 124 rotation about a diagonal, one with
      scale 2) make 4 placed copies, 28 faces. Built with OCCT's own IGES entity classes
      (IGESBasic_SubfigureDef, IGESBasic_SingularSubfigure, IGESGeom_TransformationMatrix)
      added to the model IGESControl_Writer made for the plate, so OCCT's writer computes
      the directory entries and the physically dependent status of the definitions' content.
  subfigure_uninstanced.igs
      The plate's 308 `PART` alone, instanced by no 408: OCCT reads it (a root of the
      reference graph) as 7 unplaced faces.
  subfigure_brep.igs
      The plate as OCCT's IGES B-rep (write.iges.brep.mode 1: a 402 group holding a 186
      manifold solid of 514 shell, 510 faces, 508 loops, 504 edges, 502 vertices) as the
      content of a 308 `PART` placed by two 408s (one with a 124 rotation and translation,
      one translated): 14 faces.

The OCCT references (F.ref.json) are made afterwards with `occt_ref.py regen`, the seam
references with `topo_check.py`.
"""
import argparse
import os
import re
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_topo_samples as topo  # noqa: E402

from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer  # noqa: E402
from OCP.Interface import Interface_Static  # noqa: E402
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Controller, STEPControl_Writer  # noqa: E402
from OCP.TCollection import TCollection_HAsciiString  # noqa: E402


# ---------------------------------------------------------------------------------------
# STEP: MAPPED_ITEM
# ---------------------------------------------------------------------------------------

def write_part_step(path):
    STEPControl_Controller.Init_s()
    assert Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    assert Interface_Static.SetCVal_s("write.step.unit", "MM")
    w = STEPControl_Writer()
    assert w.Transfer(topo.plate(), STEPControl_AsIs).name == "IFSelect_RetDone"
    assert w.Write(path).name == "IFSelect_RetDone"


class StepText:
    """OCCT's STEP text with entities appended after the last instance."""

    def __init__(self, text):
        self.text = text
        self.next = max(int(m) for m in re.findall(r"^#(\d+)\s*=", text, re.M)) + 1
        self.new = []

    def add(self, body):
        k = self.next
        self.next += 1
        self.new.append("#%d = %s;" % (k, body))
        return k

    def placement(self, origin, z=(0.0, 0.0, 1.0), x=(1.0, 0.0, 0.0)):
        f = lambda v: "(%s)" % ",".join(repr(float(c)) for c in v)  # noqa: E731
        p = self.add("CARTESIAN_POINT('',%s)" % f(origin))
        dz = self.add("DIRECTION('',%s)" % f(z))
        dx = self.add("DIRECTION('',%s)" % f(x))
        return self.add("AXIS2_PLACEMENT_3D('',#%d,#%d,#%d)" % (p, dz, dx))

    def product(self, name, rep):
        """A product with a definition and a SHAPE_DEFINITION_REPRESENTATION for `rep`."""
        app = re.search(r"^#(\d+)\s*=\s*APPLICATION_CONTEXT\(", self.text, re.M).group(1)
        pc = self.add("PRODUCT_CONTEXT('',#%s,'mechanical')" % app)
        pr = self.add("PRODUCT('%s','%s','',(#%d))" % (name, name, pc))
        pdf = self.add("PRODUCT_DEFINITION_FORMATION('','',#%d)" % pr)
        pdc = self.add("PRODUCT_DEFINITION_CONTEXT('part definition',#%s,'design')" % app)
        pd = self.add("PRODUCT_DEFINITION('design','',#%d,#%d)" % (pdf, pdc))
        pds = self.add("PRODUCT_DEFINITION_SHAPE('','',#%d)" % pd)
        return self.add("SHAPE_DEFINITION_REPRESENTATION(#%d,#%d)" % (pds, rep))

    def result(self):
        i = self.text.rindex("ENDSEC;", 0, self.text.index("END-ISO-10303-21"))
        return self.text[:i] + "\n".join(self.new) + "\n" + self.text[i:]


def inch_context(t, ctx):
    """A copy of context `ctx` (OCCT's millimetre context) in inches."""
    m = re.search(r"^#%s\s*=\s*\(.*?GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT\(\(#(\d+)\)\)\s*"
                  r"GLOBAL_UNIT_ASSIGNED_CONTEXT\s*\(\(#(\d+),#(\d+),#(\d+)\)\)" % ctx, t.text, re.M | re.S)
    unc, mm, angle, solid = m.groups()
    exps = t.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)")
    measure = t.add("LENGTH_MEASURE_WITH_UNIT(25.4,#%s)" % mm)
    inch = t.add("( CONVERSION_BASED_UNIT('INCH',#%d) LENGTH_UNIT() NAMED_UNIT(#%d) )" % (measure, exps))
    return t.add("( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#%s)) "
                 "GLOBAL_UNIT_ASSIGNED_CONTEXT((#%d,#%s,#%s)) REPRESENTATION_CONTEXT('inch','') )"
                 % (unc, inch, angle, solid))


def mapped_item_text(part_text, part_is_root, inch_top=False):
    t = StepText(part_text)
    sdr = re.search(r"^#(\d+)\s*=\s*SHAPE_DEFINITION_REPRESENTATION\(#(\d+),#(\d+)\);", t.text, re.M)
    part = sdr.group(3)
    ctx = re.search(r"^#%s\s*=\s*ADVANCED_BREP_SHAPE_REPRESENTATION\('',\(.*\),#(\d+)\);" % part,
                    t.text, re.M).group(1)
    top_ctx = inch_context(t, ctx) if inch_top else ctx
    # The part's map: origin not the identity (a frame at (10, 5, 0) turned 90° about z).
    part_map = t.add("REPRESENTATION_MAP(#%d,#%s)" % (t.placement((10.0, 5.0, 0.0), x=(0.0, 1.0, 0.0)), part))
    sub_axis = t.placement((0.0, 0.0, 0.0))
    mi1 = t.add("MAPPED_ITEM('pin 1',#%d,#%d)" % (part_map, t.placement((0.0, 0.0, 0.0))))
    mi2 = t.add("MAPPED_ITEM('pin 2',#%d,#%d)" % (
        part_map, t.placement((150.0, 20.0, 30.0), z=(0.0, 1.0, 0.0), x=(1.0, 0.0, 0.0))))
    sub = t.add("SHAPE_REPRESENTATION('pair',(#%d,#%d,#%d),#%s)" % (sub_axis, mi1, mi2, ctx))
    sub_map = t.add("REPRESENTATION_MAP(#%d,#%d)" % (t.placement((0.0, -20.0, 0.0)), sub))
    top_axis = t.placement((0.0, 0.0, 0.0))
    mi3 = t.add("MAPPED_ITEM('pair 1',#%d,#%d)" % (sub_map, t.placement((0.0, 0.0, 0.0))))
    mi4 = t.add("MAPPED_ITEM('pair 2',#%d,#%d)" % (
        sub_map, t.placement((0.0, 300.0, 100.0), z=(0.6, 0.0, 0.8), x=(0.8, 0.0, -0.6))))
    mi5 = t.add("MAPPED_ITEM('single',#%d,#%d)" % (
        part_map, t.placement((-200.0, 0.0, 0.0), z=(0.0, 0.0, -1.0), x=(0.0, 1.0, 0.0))))
    top = t.add("SHAPE_REPRESENTATION('assembly',(#%d,#%d,#%d,#%d),#%s)" % (top_axis, mi3, mi4, mi5, top_ctx))
    if part_is_root:
        t.product("assembly", top)
    else:
        t.text = t.text.replace(sdr.group(0), "#%s = SHAPE_DEFINITION_REPRESENTATION(#%s,#%d);"
                                % (sdr.group(1), sdr.group(2), top))
    return t.result()


def write_mapped_items(out_dir):
    with tempfile.TemporaryDirectory() as d:
        part = os.path.join(d, "part.stp")
        write_part_step(part)
        with open(part, newline="") as fh:
            text = fh.read()
    for name, root, inch in (("mapped_item.stp", False, False), ("mapped_item_root.stp", True, False),
                             ("mapped_item_inch.stp", False, True)):
        path = os.path.join(out_dir, name)
        with open(path, "w", newline="") as fh:
            fh.write(mapped_item_text(text, root, inch))
        topo.fix_step_header(path)


# ---------------------------------------------------------------------------------------
# IGES: 308 / 408
# ---------------------------------------------------------------------------------------

def _matrix(t):
    from OCP.IGESGeom import IGESGeom_TransformationMatrix
    from OCP.TColStd import TColStd_HArray2OfReal
    a = TColStd_HArray2OfReal(1, 3, 1, 4)
    for i in range(3):
        for j in range(4):
            a.SetValue(i + 1, j + 1, t.Value(i + 1, j + 1))
    m = IGESGeom_TransformationMatrix()
    m.Init(a)
    return m


def _subfigure(name, depth, members):
    from OCP.IGESBasic import IGESBasic_SubfigureDef
    from OCP.IGESData import IGESData_HArray1OfIGESEntity
    arr = IGESData_HArray1OfIGESEntity(1, len(members))
    for k, e in enumerate(members):
        arr.SetValue(k + 1, e)
    d = IGESBasic_SubfigureDef()
    d.Init(depth, TCollection_HAsciiString(name), arr)
    return d


def _instance(definition, move, scale=None, trsf=None):
    from OCP.IGESBasic import IGESBasic_SingularSubfigure
    from OCP.gp import gp_XYZ
    i = IGESBasic_SingularSubfigure()
    i.Init(definition, gp_XYZ(*move), scale is not None, 1.0 if scale is None else scale)
    if trsf is not None:
        i.InitTransf(_matrix(trsf))
    return i


def write_subfigures(path, instanced=True, brep=False):
    IGESControl_Controller.Init_s()
    Interface_Static.SetCVal_s("write.iges.header.author", "occref")
    Interface_Static.SetCVal_s("write.iges.header.company", "occref")
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1 if brep else 0)
    w = IGESControl_Writer("MM", 1 if brep else 0)
    gs = w.Model().GlobalSection()
    gs.SetAuthorName(TCollection_HAsciiString("occref"))
    gs.SetCompanyName(TCollection_HAsciiString("occref"))
    w.Model().SetGlobalSection(gs)
    w.AddShape(topo.plate())
    m = w.Model()
    groups = [m.Value(i) for i in range(1, m.NbEntities() + 1) if m.Value(i).TypeNumber() == 402]
    assert len(groups) == 1, "OCCT writes the plate's faces as one 402 group"
    part = _subfigure("PART", 0, groups)
    entities = [part]
    if brep:
        a = _instance(part, (0.0, 0.0, 0.0), trsf=topo.trsf((0, 0, 1), 30.0, (5.0, 10.0, 0.0)))
        b = _instance(part, (0.0, 120.0, 0.0))
        entities += [a, b]
    elif instanced:
        a = _instance(part, (0.0, 0.0, 0.0), trsf=topo.trsf((0, 0, 1), 30.0, (5.0, 10.0, 0.0)))
        b = _instance(part, (0.0, 80.0, 0.0), scale=0.5)
        pair = _subfigure("PAIR", 1, [a, b])
        c = _instance(pair, (0.0, 0.0, 0.0), trsf=topo.trsf((1, 1, 0), 90.0, (200.0, 0.0, 50.0)))
        d = _instance(pair, (-300.0, 20.0, 0.0), scale=2.0)
        entities += [a, b, pair, c, d]
    for e in entities:
        w.AddEntity(e)
    w.ComputeModel()
    assert w.Write(path), path
    topo.fix_iges_header(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out-dir", default=os.path.normpath(os.path.join(HERE, "..", "..", "samples")))
    a = ap.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    write_mapped_items(a.out_dir)
    write_subfigures(os.path.join(a.out_dir, "subfigure.igs"))
    write_subfigures(os.path.join(a.out_dir, "subfigure_uninstanced.igs"), instanced=False)
    write_subfigures(os.path.join(a.out_dir, "subfigure_brep.igs"), brep=True)


if __name__ == "__main__":
    main()
