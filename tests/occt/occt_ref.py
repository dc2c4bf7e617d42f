#!/usr/bin/env python3
"""occt_ref.py - cadmorph's OpenCASCADE oracle for IGES and STEP files.

OCCT 7.9.3 through the OCP bindings (tests/occt/setup.sh makes the venv). Commands:

  ref FILE [--out X.json] [--check [REF.json]] [--tol 1e-9]
      Read FILE with OCCT and print its reference evaluation (the `samples/*.ref.json`
      schema: every face's surface data and 50 (u, v) samples; free curves with 50 t samples).
      With --check, compare it with REF.json (default FILE.ref.json) instead and print the
      comparison report.
  regen [--samples DIR] [--out-dir DIR] [--check] [--tol 1e-9]
      Rewrite F.ref.json for every IGES/STEP file F in the samples folder (default: the
      repository's samples/), into --out-dir (default: the samples folder itself).
      With --check, also compare each new file with the one already in the samples folder.
  validate FILE [--eval REQUEST.json] [--out X.json] [--strict]
      Check a file cadmorph wrote: read status, transfer, BRepCheck validity, topology counts,
      and, with --eval, OCCT's evaluation of every face at the requested (u, v) (see README.md).
  compare A.json B.json [--tol 1e-9]
      Compare two reference files (no OCCT needed), e.g. one cadmorph wrote in this schema.

JSON goes to stdout (or --out); OCCT's own chatter is sent to stderr. Exit codes: 0 fine,
1 read or transfer failed, 2 a comparison exceeded --tol (or, with validate --strict, the
shape is not BRepCheck-valid), 3 bad usage or request.

Numbers are in the file's own length unit unless --unit says otherwise (OCCT would otherwise
convert everything to millimetres).
"""
import argparse
import json
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SAMPLES = os.path.normpath(os.path.join(HERE, "..", "..", "samples"))

# Where the JSON goes. main() points fd 1 at stderr so that OCCT's C++ printing cannot
# corrupt the JSON, and keeps the real stdout here.
_json_stream = sys.stdout

# ---------------------------------------------------------------------------------------
# Reading with OCCT
# ---------------------------------------------------------------------------------------

# OCCT interface statics set before every read, recorded in each reference file.
#   read.iges.bspline.continuity = 0: keep the file's knot vectors. The default (1) lets the
#   IGES reader remove or split knots to reach C1, so poles and knots would differ from the file.
READ_PARAMS = {"read.iges.bspline.continuity": 0}

# Millimetres per unit, for the names xstep.cascade.unit accepts.
MM_PER_UNIT = {"IN": 25.4, "MM": 1.0, "FT": 304.8, "MI": 1609344.0, "M": 1000.0, "KM": 1.0e6,
               "MIL": 0.0254, "UM": 1.0e-3, "CM": 10.0, "UIN": 2.54e-5}
# IGES global parameter 14 (unit flag) -> unit name (IGES 5.3, section 2.2.4.4).
# Flag 3 means "see the unit name" (parameter 15).
IGES_UNIT_FLAG = {1: "IN", 2: "MM", 4: "FT", 5: "MI", 6: "M", 7: "KM", 8: "MIL", 9: "UM",
                  10: "CM", 11: "UIN"}
UNIT_ALIASES = {"INCH": "IN", "INCHES": "IN", "MILLIMETRE": "MM", "MILLIMETER": "MM",
                "METRE": "M", "METER": "M", "FOOT": "FT", "FEET": "FT", "MILE": "MI",
                "KILOMETRE": "KM", "KILOMETER": "KM", "MICROMETRE": "UM", "MICROMETER": "UM",
                "MICRON": "UM", "CENTIMETRE": "CM", "CENTIMETER": "CM", "MICROINCH": "UIN"}


def unit_name(name):
    """Normalise a unit name ('METRE', 'mm', 'INCH') to a key of MM_PER_UNIT, or None."""
    if not name:
        return None
    n = name.strip().strip("'").upper()
    n = UNIT_ALIASES.get(n, n)
    return n if n in MM_PER_UNIT else None


_occt_ready = False


def init_occt():
    """Register the IGES/STEP controllers, silence OCCT's messenger, set READ_PARAMS."""
    global _occt_ready
    if _occt_ready:
        return
    from OCP.IGESControl import IGESControl_Controller
    from OCP.STEPControl import STEPControl_Controller
    from OCP.Interface import Interface_Static
    from OCP.Message import Message, Message_Gravity
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    IGESControl_Controller.Init_s()
    STEPControl_Controller.Init_s()
    for key, value in READ_PARAMS.items():
        Interface_Static.SetIVal_s(key, value)
    _occt_ready = True


def file_format(path):
    """'STEP' when the file starts with ISO-10303-21 or has a STEP extension, else 'IGES'."""
    with open(path, "rb") as fh:
        head = fh.read(256).lstrip()
    if head.upper().startswith(b"ISO-10303-21"):
        return "STEP"
    if os.path.splitext(path)[1].lower() in (".stp", ".step", ".p21"):
        return "STEP"
    return "IGES"


def status_name(status):
    from OCP.IFSelect import IFSelect_ReturnStatus
    try:
        return IFSelect_ReturnStatus(status).name
    except (ValueError, TypeError):
        return str(status)


def _step_file_unit(reader, path):
    """Length unit of a STEP file: OCCT's FileUnits, else the SI_UNIT / CONVERSION_BASED_UNIT text."""
    try:
        from OCP.TColStd import TColStd_SequenceOfAsciiString
        lengths, angles, solids = (TColStd_SequenceOfAsciiString(), TColStd_SequenceOfAsciiString(),
                                   TColStd_SequenceOfAsciiString())
        reader.FileUnits(lengths, angles, solids)
        if lengths.Length() > 0:
            return unit_name(lengths.Value(1).ToCString())
    except Exception:  # noqa: BLE001 - older/newer OCP without the binding: fall back to the text
        pass
    with open(path, "r", errors="replace") as fh:
        text = fh.read()
    m = re.search(r"LENGTH_UNIT\(\)[^;]*?SI_UNIT\(\s*(\$|\.\w+\.)\s*,\s*\.METRE\.\s*\)", text) or \
        re.search(r"SI_UNIT\(\s*(\$|\.\w+\.)\s*,\s*\.METRE\.\s*\)[^;]*?LENGTH_UNIT\(\)", text)
    if m:
        prefix = m.group(1).upper()
        return {"$": "M", ".MILLI.": "MM", ".CENTI.": "CM", ".KILO.": "KM", ".MICRO.": "UM"}.get(prefix)
    m = re.search(r"CONVERSION_BASED_UNIT\(\s*'(\w+)'", text)
    return unit_name(m.group(1)) if m else None


class Loaded:
    """An IGES/STEP file read and transferred by OCCT: `shape` is None when that failed."""

    def __init__(self, path, unit="file"):
        from OCP.IGESControl import IGESControl_Reader
        from OCP.STEPControl import STEPControl_Reader
        from OCP.Interface import Interface_Static
        init_occt()
        self.path = path
        self.shape = None
        if not os.path.isfile(path):
            self.format = None
            self.info = {"file": os.path.basename(path), "format": None, "read_status": "no such file",
                         "read_ok": False, "transfer_ok": False}
            return
        self.format = file_format(path)
        self.info = {"file": os.path.basename(path), "format": self.format}
        reader = IGESControl_Reader() if self.format == "IGES" else STEPControl_Reader()
        self.reader = reader
        status = status_name(reader.ReadFile(path))
        self.info["read_status"] = status
        self.info["read_ok"] = status == "IFSelect_RetDone"
        self.info["transfer_ok"] = False
        if not self.info["read_ok"]:
            return
        model = reader.Model()
        if self.format == "IGES":
            gs = model.GlobalSection()
            flag = gs.UnitFlag()
            name = gs.UnitName()
            self.info["file_unit_flag"] = flag
            file_unit = IGES_UNIT_FLAG.get(flag) or unit_name(name.ToCString() if name is not None else None)
        else:
            file_unit = _step_file_unit(reader, path)
        self.info["file_unit"] = file_unit
        out_unit = (file_unit or "MM") if unit == "file" else unit_name(unit)
        if out_unit is None:
            raise ValueError("unknown unit %r" % unit)
        self.info["result_unit"] = out_unit
        # Unit quirks. OCCT converts to xstep.cascade.unit (default MM) during the transfer.
        # IGES: the model copies the static into its global section at ReadFile time, so the
        # static must be set *and* the global section's cascade unit changed after reading.
        # STEP: the reader's system length unit decides.
        Interface_Static.SetCVal_s("xstep.cascade.unit", out_unit)
        if self.format == "IGES":
            gs = model.GlobalSection()
            gs.SetCascadeUnit(MM_PER_UNIT[out_unit])
            model.SetGlobalSection(gs)
        else:
            reader.SetSystemLengthUnit(MM_PER_UNIT[out_unit])
        histogram = {}
        for i in range(1, model.NbEntities() + 1):
            ent = model.Value(i)
            if self.format == "IGES":
                key = str(ent.TypeNumber())
                if ent.FormNumber():
                    key += "/%d" % ent.FormNumber()
            else:
                key = ent.DynamicType().Name()
            histogram[key] = histogram.get(key, 0) + 1
        self.info["n_entities"] = model.NbEntities()
        self.info["entity_types"] = dict(sorted(histogram.items()))
        self.info["n_roots"] = reader.NbRootsForTransfer()
        self.info["n_roots_transferred"] = reader.TransferRoots()
        if self.info["n_roots_transferred"] > 0:
            shape = reader.OneShape()
            if shape is not None and not shape.IsNull():
                self.shape = shape
        self.info["transfer_ok"] = self.shape is not None

    @property
    def ok(self):
        return self.shape is not None

    def faces(self):
        """Faces in OCCT's explorer order (the entity order of the file)."""
        from OCP.TopExp import TopExp_Explorer
        from OCP.TopAbs import TopAbs_FACE
        from OCP.TopoDS import TopoDS
        out = []
        ex = TopExp_Explorer(self.shape, TopAbs_FACE)
        while ex.More():
            out.append(TopoDS.Face_s(ex.Current()))
            ex.Next()
        return out

    def free_curves(self):
        """(3D curve with location applied, first, last) of every edge; used for curve-only files."""
        from OCP.TopExp import TopExp_Explorer
        from OCP.TopAbs import TopAbs_EDGE
        from OCP.TopoDS import TopoDS
        from OCP.BRep import BRep_Tool
        from OCP.BRepAdaptor import BRepAdaptor_Curve
        out = []
        ex = TopExp_Explorer(self.shape, TopAbs_EDGE)
        while ex.More():
            edge = TopoDS.Edge_s(ex.Current())
            curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)  # OCP returns the curve only, location applied
            adaptor = BRepAdaptor_Curve(edge)
            if curve is not None:
                out.append((curve, adaptor.FirstParameter(), adaptor.LastParameter()))
            ex.Next()
        return out


# ---------------------------------------------------------------------------------------
# Evaluation
# ---------------------------------------------------------------------------------------

def radical_inverse(i, base):
    """Van der Corput radical inverse of i in `base` (the Halton coordinate)."""
    scale, result = 1.0, 0.0
    while i > 0:
        scale /= base
        result += scale * (i % base)
        i //= base
    return result


def surface_params(u0, u1, v0, v1, n=50):
    """The 4 corners, then Halton (2, 3) points 1, 2, ... until there are n."""
    out = [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
    i = 1
    while len(out) < n:
        out.append((u0 + (u1 - u0) * radical_inverse(i, 2), v0 + (v1 - v0) * radical_inverse(i, 3)))
        i += 1
    return out[:n]


def curve_params(t0, t1, n=50):
    """t0, t1, then the base-2 Halton points 2, 3, ... scaled to [t0, t1]."""
    out = []
    for i in range(n):
        if i == 0:
            out.append(t0)
        elif i == 1:
            out.append(t1)
        else:
            out.append(t0 + (t1 - t0) * radical_inverse(i, 2))
    return out


def xyz(p):
    return [p.X(), p.Y(), p.Z()]


def eval_surface(surface, u, v):
    """{u, v, p, du, dv, n} with n = normalize(du x dv), or null where du x dv vanishes."""
    from OCP.gp import gp_Pnt, gp_Vec
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    surface.D1(u, v, p, du, dv)
    n = du.Crossed(dv)
    mag = n.Magnitude()
    normal = [n.X() / mag, n.Y() / mag, n.Z() / mag] if mag > 1e-300 else None
    return {"u": u, "v": v, "p": xyz(p), "du": xyz(du), "dv": xyz(dv), "n": normal}


def eval_curve(curve, t):
    from OCP.gp import gp_Pnt, gp_Vec
    p, d1 = gp_Pnt(), gp_Vec()
    curve.D1(t, p, d1)
    return {"t": t, "p": xyz(p), "d1": xyz(d1)}


def _clamped(surface, periodic_as):
    """The non-periodic form of a B-spline surface that OCCT read as periodic.

    OCCT's IGES and STEP readers turn a closed, clamped B-spline (first pole row equal to the
    last) into its periodic form. The file stores the clamped form. SetU/VNotPeriodic alone
    gives an unclamped knot vector (for the blade: 0 with multiplicity 3 plus an extra knot
    below 0, the same at 1); the poles and the geometry on the domain are the same, but the
    knots are not the file's. Segment over the bounds restores the clamped end knots.
    periodic_as='unclamped' skips that step (what shared/reference/make_samples.py wrote).
    """
    copy = surface.Copy()
    if copy.IsUPeriodic():
        copy.SetUNotPeriodic()
    if copy.IsVPeriodic():
        copy.SetVNotPeriodic()
    if periodic_as == "clamped":
        copy.Segment(*surface.Bounds())
    return copy


def bspline_surface_data(b):
    nu, nv = b.NbUPoles(), b.NbVPoles()
    rational = bool(b.IsURational() or b.IsVRational())
    poles = [[xyz(b.Pole(i, j)) for j in range(1, nv + 1)] for i in range(1, nu + 1)]
    weights = [[b.Weight(i, j) for j in range(1, nv + 1)] for i in range(1, nu + 1)] if rational else None
    return {"u_degree": b.UDegree(), "v_degree": b.VDegree(), "n_u_poles": nu, "n_v_poles": nv,
            "u_knots": [b.UKnot(i) for i in range(1, b.NbUKnots() + 1)],
            "u_mults": [b.UMultiplicity(i) for i in range(1, b.NbUKnots() + 1)],
            "v_knots": [b.VKnot(i) for i in range(1, b.NbVKnots() + 1)],
            "v_mults": [b.VMultiplicity(i) for i in range(1, b.NbVKnots() + 1)],
            "u_periodic": bool(b.IsUPeriodic()), "v_periodic": bool(b.IsVPeriodic()),
            "rational": rational, "poles": poles, "weights": weights,
            "pole_layout": "poles[i_u][i_v] = [x,y,z]"}


def surface_ref(surface, n_samples=50, periodic_as="clamped"):
    """Reference data of one face surface (already carrying the face location)."""
    d = {"class": surface.DynamicType().Name(), "bounds": list(surface.Bounds())}
    basis = surface
    if d["class"] == "Geom_RectangularTrimmedSurface":
        basis = surface.BasisSurface()
        d["basis_class"] = basis.DynamicType().Name()
    if basis.DynamicType().Name() != "Geom_BSplineSurface":
        return d
    if basis.IsUPeriodic() or basis.IsVPeriodic():
        d["occt_read_as_periodic"] = [bool(basis.IsUPeriodic()), bool(basis.IsVPeriodic())]
        basis = _clamped(basis, periodic_as)
    d.update(bspline_surface_data(basis))
    u0, u1, v0, v1 = d["bounds"]
    # Samples are OCCT's evaluation of the surface exactly as read (periodic or trimmed).
    d["samples"] = [eval_surface(surface, u, v) for u, v in surface_params(u0, u1, v0, v1, n_samples)]
    d["normal_convention"] = ("n = normalize(dS/du x dS/dv), surface orientation "
                              "(face orientation not applied)")
    return d


def curve_ref(curve, t0, t1, n_samples=50):
    d = {"class": curve.DynamicType().Name(), "range": [t0, t1]}
    basis = curve
    if d["class"] == "Geom_TrimmedCurve":
        basis = curve.BasisCurve()
        d["basis_class"] = basis.DynamicType().Name()
    if basis.DynamicType().Name() != "Geom_BSplineCurve":
        return d
    n = basis.NbPoles()
    d.update({"degree": basis.Degree(), "n_poles": n,
              "knots": [basis.Knot(i) for i in range(1, basis.NbKnots() + 1)],
              "mults": [basis.Multiplicity(i) for i in range(1, basis.NbKnots() + 1)],
              "periodic": bool(basis.IsPeriodic()), "rational": bool(basis.IsRational()),
              "poles": [xyz(basis.Pole(i)) for i in range(1, n + 1)],
              "weights": [basis.Weight(i) for i in range(1, n + 1)] if basis.IsRational() else None})
    d["samples"] = [eval_curve(curve, t) for t in curve_params(t0, t1, n_samples)]
    return d


def reference(loaded, n_samples=50, note=None, periodic_as="clamped"):
    """The `*.ref.json` document of a loaded file."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_REVERSED
    import OCP
    ref = {"file": os.path.basename(loaded.path),
           "generator": "tests/occt/occt_ref.py (OCCT %s via OCP)" % ".".join(OCP.__version__.split(".")[:3]),
           "occt_reader": loaded.format, "result_unit": loaded.info["result_unit"],
           "read_params": dict(READ_PARAMS), "entity_types": loaded.info["entity_types"],
           "note": note, "faces": [], "free_curves": []}
    faces = loaded.faces()
    for k, face in enumerate(faces):
        d = {"index": k, "reversed": face.Orientation() == TopAbs_REVERSED}
        d.update(surface_ref(BRep_Tool.Surface_s(face), n_samples, periodic_as))
        ref["faces"].append(d)
    if not faces:
        for curve, t0, t1 in loaded.free_curves():
            ref["free_curves"].append(curve_ref(curve, t0, t1, n_samples))
    return ref


# ---------------------------------------------------------------------------------------
# Comparison of two reference documents
# ---------------------------------------------------------------------------------------

# Keys that describe provenance, not OCCT's numbers.
IGNORED_KEYS = {"generator", "note"}
# Leaf keys measured in parameter space; everything else numeric (poles, p, du, dv, d1) is
# measured against the model size, normals and weights absolutely.
PARAMETRIC_KEYS = {"u", "v", "t", "bounds", "range", "u_knots", "v_knots", "knots"}
ABSOLUTE_KEYS = {"n", "weights"}


def _points(doc):
    for entity in doc.get("faces", []) + doc.get("free_curves", []):
        for s in entity.get("samples", []):
            yield s["p"]
        poles = entity.get("poles") or []
        for row in poles:
            if row and isinstance(row[0], list):
                yield from row
            else:
                yield row


def model_size(doc):
    """Bounding-box diagonal of every pole and sample point, at least 1e-300."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for p in _points(doc):
        for k in range(3):
            lo[k] = min(lo[k], p[k])
            hi[k] = max(hi[k], p[k])
    if lo[0] == math.inf:
        return 1.0
    return max(math.dist(lo, hi), 1e-300)


def compare_refs(expected, actual, tol=1e-9):
    """Largest deviation of `actual` from `expected`, per kind of number.

    Geometric numbers (points, poles, derivatives) are divided by the model size, parametric
    ones by max(1, largest |parameter|); normals and weights count as they are. Integers,
    strings, booleans and list lengths must be equal (listed under "mismatches").
    """
    size = model_size(expected)
    pscale = [1.0]
    categories = {}
    mismatches = []

    def walk(a, b, path, cat, leaf):
        if isinstance(a, dict) and isinstance(b, dict):
            for key in sorted(set(a) | set(b)):
                if key in IGNORED_KEYS:
                    continue
                if key not in a or key not in b:
                    mismatches.append("%s.%s: only in %s" % (path, key, "expected" if key in a else "actual"))
                    continue
                walk(a[key], b[key], "%s.%s" % (path, key), "%s.%s" % (cat, key), key)
        elif isinstance(a, list) and isinstance(b, list):
            if len(a) != len(b):
                mismatches.append("%s: length %d != %d" % (path, len(a), len(b)))
                return
            for i, (x, y) in enumerate(zip(a, b)):
                walk(x, y, "%s[%d]" % (path, i), cat + ("" if cat.endswith("[]") else "[]"), leaf)
        elif isinstance(a, float) or isinstance(b, float):
            if isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, (int, float)) \
                    or not isinstance(b, (int, float)):
                mismatches.append("%s: %r != %r" % (path, a, b))
                return
            diff = 0.0 if a == b else abs(a - b)
            if leaf in PARAMETRIC_KEYS:
                scale = pscale[0]
            elif leaf in ABSOLUTE_KEYS:
                scale = 1.0
            else:
                scale = size
            c = categories.setdefault(cat, {"max_abs": 0.0, "max_rel": 0.0, "at": None, "n": 0})
            c["n"] += 1
            rel = diff / scale if math.isfinite(diff) else math.inf
            if rel > c["max_rel"]:
                c["max_rel"], c["max_abs"], c["at"] = rel, diff, path
        elif a != b:
            mismatches.append("%s: %r != %r" % (path, a, b))

    for entity in expected.get("faces", []) + expected.get("free_curves", []):
        for key in ("bounds", "range", "u_knots", "v_knots", "knots"):
            for x in entity.get(key) or []:
                if isinstance(x, (int, float)) and abs(x) < 1e99:
                    pscale[0] = max(pscale[0], abs(x))
    walk(expected, actual, "$", "", None)
    worst = max((c["max_rel"] for c in categories.values()), default=0.0)
    return {"ok": not mismatches and worst <= tol, "tol": tol, "model_size": size,
            "parameter_scale": pscale[0], "max_rel": worst,
            "max_abs": max((c["max_abs"] for c in categories.values()), default=0.0),
            "n_numbers": sum(c["n"] for c in categories.values()),
            "categories": {k.lstrip("."): v for k, v in sorted(categories.items())},
            "mismatches": mismatches[:50], "n_mismatches": len(mismatches)}


# ---------------------------------------------------------------------------------------
# validate
# ---------------------------------------------------------------------------------------

def _count(shape, kind):
    from OCP.TopTools import TopTools_IndexedMapOfShape
    from OCP.TopExp import TopExp
    m = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, kind, m)
    return m.Extent()


def _read_request(path):
    """The --eval request: {"uv": [[u, v], ...], "faces": {"<index>": [[u, v], ...]}, "t": [...]}."""
    with open(path) as fh:
        req = json.load(fh)
    if not isinstance(req, dict):
        raise ValueError("request must be a JSON object")
    unknown = set(req) - {"uv", "faces", "t", "normalized"}
    if unknown:
        raise ValueError("unknown request keys: %s" % ", ".join(sorted(unknown)))

    def pairs(x, where):
        if not isinstance(x, list) or not all(isinstance(p, list) and len(p) == 2 and
                                              all(isinstance(c, (int, float)) for c in p) for p in x):
            raise ValueError("%s must be a list of [u, v] pairs" % where)
        return [(float(u), float(v)) for u, v in x]

    out = {"uv": pairs(req.get("uv", []), "uv"), "faces": {}, "t": [float(t) for t in req.get("t", [])],
           "normalized": bool(req.get("normalized", False))}
    for key, value in (req.get("faces") or {}).items():
        out["faces"][int(key)] = pairs(value, "faces[%s]" % key)
    return out


def validate(loaded, request=None):
    """What OCCT thinks of a file: read/transfer status, validity, topology, evaluations."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import (TopAbs_REVERSED, TopAbs_SOLID, TopAbs_SHELL, TopAbs_FACE,
                            TopAbs_WIRE, TopAbs_EDGE, TopAbs_VERTEX)
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    out = dict(loaded.info)
    if not loaded.ok:
        out["valid"] = False
        return out
    shape = loaded.shape
    out["topology"] = {name: _count(shape, kind) for name, kind in
                       (("solids", TopAbs_SOLID), ("shells", TopAbs_SHELL), ("faces", TopAbs_FACE),
                        ("wires", TopAbs_WIRE), ("edges", TopAbs_EDGE), ("vertices", TopAbs_VERTEX))}
    faces = loaded.faces()
    out["n_faces"] = len(faces)
    out["valid"] = bool(BRepCheck_Analyzer(shape).IsValid())
    bad = [k for k, f in enumerate(faces) if not BRepCheck_Analyzer(f).IsValid()]
    out["invalid_faces"] = bad
    worst = {"face": 0.0, "edge": 0.0, "vertex": 0.0}
    for name, kind, cast in (("face", TopAbs_FACE, TopoDS.Face_s), ("edge", TopAbs_EDGE, TopoDS.Edge_s),
                             ("vertex", TopAbs_VERTEX, TopoDS.Vertex_s)):
        ex = TopExp_Explorer(shape, kind)
        while ex.More():
            worst[name] = max(worst[name], BRep_Tool.Tolerance_s(cast(ex.Current())))
            ex.Next()
    out["max_tolerance"] = worst
    # Area of every face and volume of every solid (Gauss integration over the faces).
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    out["area"] = props.Mass()
    volume = 0.0
    ex = TopExp_Explorer(shape, TopAbs_SOLID)
    while ex.More():
        vp = GProp_GProps()
        BRepGProp.VolumeProperties_s(ex.Current(), vp)
        volume += abs(vp.Mass())
        ex.Next()
    out["volume"] = volume
    out["face_areas"] = []
    for f in faces:
        fp = GProp_GProps()
        BRepGProp.SurfaceProperties_s(f, fp)
        out["face_areas"].append(fp.Mass())
    # The same with adaptive integration to 1e-12 relative (BRepGProp's Eps form): the
    # fixed Gauss order above is off by up to 0.2 % on rational faces (a NURBS cylinder).
    out["face_areas_exact"] = []
    for f in faces:
        fp = GProp_GProps()
        BRepGProp.SurfaceProperties_s(f, fp, 1e-12)
        out["face_areas_exact"].append(fp.Mass())
    out["area_exact"] = sum(out["face_areas_exact"])
    volume = 0.0
    ex = TopExp_Explorer(shape, TopAbs_SOLID)
    while ex.More():
        vp = GProp_GProps()
        BRepGProp.VolumeProperties_s(ex.Current(), vp, 1e-12)
        volume += abs(vp.Mass())
        ex.Next()
    out["volume_exact"] = volume
    out["faces"] = []
    for k, face in enumerate(faces):
        surface = BRep_Tool.Surface_s(face)
        d = {"index": k, "class": surface.DynamicType().Name(),
             "reversed": face.Orientation() == TopAbs_REVERSED,
             "bounds": list(surface.Bounds()), "uv_bounds": list(BRepTools.UVBounds_s(face))}
        if surface.DynamicType().Name() == "Geom_BSplineSurface":
            d.update({"u_degree": surface.UDegree(), "v_degree": surface.VDegree(),
                      "n_u_poles": surface.NbUPoles(), "n_v_poles": surface.NbVPoles(),
                      "rational": bool(surface.IsURational() or surface.IsVRational()),
                      "u_periodic": bool(surface.IsUPeriodic()), "v_periodic": bool(surface.IsVPeriodic())})
        if request is not None:
            params = request["uv"] + request["faces"].get(k, [])
            if request["normalized"]:
                u0, u1, v0, v1 = d["uv_bounds"]
                params = [(u0 + (u1 - u0) * u, v0 + (v1 - v0) * v) for u, v in params]
            d["evals"] = [eval_surface(surface, u, v) for u, v in params]
        out["faces"].append(d)
    missing = sorted(set(request["faces"]) - set(range(len(faces)))) if request else []
    if missing:
        out["request_errors"] = ["no face %d" % k for k in missing]
    if request is not None and request["t"] and not faces:
        out["free_curves"] = []
        for k, (curve, t0, t1) in enumerate(loaded.free_curves()):
            ts = [t0 + (t1 - t0) * t for t in request["t"]] if request["normalized"] else request["t"]
            out["free_curves"].append({"index": k, "class": curve.DynamicType().Name(), "range": [t0, t1],
                                       "evals": [eval_curve(curve, t) for t in ts]})
    return out


# ---------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------

def emit(doc, out=None):
    text = json.dumps(doc, indent=1) + "\n"
    if out:
        with open(out, "w") as fh:
            fh.write(text)
    else:
        _json_stream.write(text)
        _json_stream.flush()


def write_ref(doc, path):
    with open(path, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")


def load_json(path):
    with open(path) as fh:
        return json.load(fh)


def log(msg):
    sys.stderr.write(msg + "\n")
    sys.stderr.flush()


def sample_files(folder):
    return sorted(f for f in os.listdir(folder)
                  if os.path.splitext(f)[1].lower() in (".igs", ".iges", ".stp", ".step"))


def cmd_ref(a):
    loaded = Loaded(a.file, a.unit)
    if not loaded.ok:
        emit(loaded.info, a.out)
        return 1
    check_path = a.check if a.check != "" else a.file + ".ref.json"
    note = None
    if a.check is not None and os.path.exists(check_path):
        note = load_json(check_path).get("note")
    doc = reference(loaded, a.samples, note, a.periodic_as)
    if a.check is None:
        emit(doc, a.out)
        return 0
    report = compare_refs(load_json(check_path), doc, a.tol)
    report = {"file": a.file, "ref": check_path, **report}
    emit(report, a.out)
    log("%s: max rel %.3e, max abs %.3e, %d mismatches -> %s" % (
        os.path.basename(a.file), report["max_rel"], report["max_abs"], report["n_mismatches"],
        "OK" if report["ok"] else "FAIL"))
    return 0 if report["ok"] else 2


def cmd_regen(a):
    samples = os.path.abspath(a.samples)
    out_dir = os.path.abspath(a.out_dir or samples)
    os.makedirs(out_dir, exist_ok=True)
    results, failed = [], False
    for name in sample_files(samples):
        path = os.path.join(samples, name)
        old_path = path + ".ref.json"
        old = load_json(old_path) if os.path.exists(old_path) else None
        loaded = Loaded(path, a.unit)
        if not loaded.ok:
            log("%-24s read/transfer FAILED: %s" % (name, loaded.info["read_status"]))
            results.append({"file": name, "ok": False, "read": loaded.info})
            failed = True
            continue
        doc = reference(loaded, a.samples_per_face, old.get("note") if old else None, a.periodic_as)
        write_ref(doc, os.path.join(out_dir, name + ".ref.json"))
        row = {"file": name, "ok": True, "faces": len(doc["faces"]), "free_curves": len(doc["free_curves"])}
        if a.check:
            if old is None:
                row.update({"ok": False, "compare": "no shipped reference"})
            else:
                rep = compare_refs(old, doc, a.tol)
                row.update({"ok": rep["ok"], "max_rel": rep["max_rel"], "max_abs": rep["max_abs"],
                            "n_numbers": rep["n_numbers"], "n_mismatches": rep["n_mismatches"],
                            "mismatches": rep["mismatches"][:10]})
                worst_cat = max(rep["categories"].items(), key=lambda kv: kv[1]["max_rel"],
                                default=(None, None))[0]
                row["worst_category"] = worst_cat
            log("%-24s faces %3d curves %2d  max rel %.3e  max abs %.3e  mismatches %d  %s" % (
                name, row["faces"], row["free_curves"], row.get("max_rel", math.nan),
                row.get("max_abs", math.nan), row.get("n_mismatches", 0), "OK" if row["ok"] else "FAIL"))
        else:
            log("%-24s faces %3d curves %2d  -> %s" % (name, row["faces"], row["free_curves"],
                                                      os.path.join(out_dir, name + ".ref.json")))
        results.append(row)
    summary = {"samples": samples, "out_dir": out_dir, "files": results,
               "ok": all(r["ok"] for r in results)}
    if a.check:
        summary["max_rel"] = max((r.get("max_rel", 0.0) for r in results), default=0.0)
        summary["max_abs"] = max((r.get("max_abs", 0.0) for r in results), default=0.0)
        log("worst: max rel %.3e, max abs %.3e over %d files -> %s" % (
            summary["max_rel"], summary["max_abs"], len(results), "OK" if summary["ok"] else "FAIL"))
    emit(summary, a.out)
    if failed:
        return 1
    return 0 if summary["ok"] else 2


def cmd_validate(a):
    try:
        request = _read_request(a.eval) if a.eval else None
    except (OSError, ValueError) as e:
        log("bad --eval request: %s" % e)
        return 3
    loaded = Loaded(a.file, a.unit)
    doc = validate(loaded, request)
    emit(doc, a.out)
    if not loaded.ok:
        return 1
    if a.strict and (not doc["valid"] or doc.get("request_errors")):
        return 2
    return 0


def cmd_compare(a):
    report = compare_refs(load_json(a.expected), load_json(a.actual), a.tol)
    emit({"expected": a.expected, "actual": a.actual, **report}, a.out)
    log("max rel %.3e, max abs %.3e, %d mismatches -> %s" % (
        report["max_rel"], report["max_abs"], report["n_mismatches"], "OK" if report["ok"] else "FAIL"))
    return 0 if report["ok"] else 2


def parser():
    ap = argparse.ArgumentParser(prog="occt_ref.py", description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.split("\n")[2:]))
    sub = ap.add_subparsers(dest="command", required=True)

    def common(p, samples=True):
        p.add_argument("--out", help="write the JSON here instead of stdout")
        p.add_argument("--unit", default="file",
                       help="length unit of the results: 'file' (the file's own, default), MM, M, IN, ...")
        if samples:
            p.add_argument("--periodic-as", choices=("clamped", "unclamped"), default="clamped",
                           help="form in which to report a surface OCCT read as periodic: 'clamped' "
                                "(the file's knots and poles, default) or 'unclamped' (OCCT's "
                                "SetNotPeriodic form, as shared/reference/make_samples.py wrote)")
        p.add_argument("--tol", type=float, default=1e-9,
                       help="largest relative deviation a comparison accepts (default 1e-9)")

    p = sub.add_parser("ref", help="reference evaluation of one file (or --check it)")
    p.add_argument("file")
    p.add_argument("--samples", type=int, default=50, help="samples per face / curve (default 50)")
    p.add_argument("--check", nargs="?", const="", default=None, metavar="REF",
                   help="compare with REF (default FILE.ref.json) and print the report instead")
    common(p)
    p.set_defaults(func=cmd_ref)

    p = sub.add_parser("regen", help="regenerate F.ref.json for every sample file F")
    p.add_argument("--samples", default=DEFAULT_SAMPLES, help="samples folder (default: repo samples/)")
    p.add_argument("--out-dir", help="where to write (default: the samples folder)")
    p.add_argument("--check", action="store_true", help="compare with the references in --samples")
    p.add_argument("--samples-per-face", type=int, default=50)
    common(p)
    p.set_defaults(func=cmd_regen)

    p = sub.add_parser("validate", help="does OCCT accept a file; optional evaluations")
    p.add_argument("file")
    p.add_argument("--eval", metavar="REQUEST.json", help="(u, v) / t points to evaluate, see README.md")
    p.add_argument("--strict", action="store_true",
                   help="exit 2 when BRepCheck finds the shape invalid or the request names missing faces")
    common(p, samples=False)
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("compare", help="compare two reference JSON files (no OCCT)")
    p.add_argument("expected")
    p.add_argument("actual")
    p.add_argument("--out")
    p.add_argument("--tol", type=float, default=1e-9)
    p.set_defaults(func=cmd_compare)
    return ap


def main(argv=None):
    global _json_stream
    args = parser().parse_args(argv)
    # Keep the real stdout for JSON; anything OCCT prints from C++ goes to stderr instead.
    sys.stdout.flush()
    _json_stream = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    try:
        return args.func(args)
    except BrokenPipeError:  # e.g. piped into `head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), _json_stream.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
