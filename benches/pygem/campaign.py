"""The bow-dome campaign of issue 16 written as a PyGeM script loop, side by side with
`cadmorph campaign run` in one run (benches/pygem/README.md, "Campaign").

PyGeM's CAD path is `pygem.cad.FFD`: OCCT reads the IGES file, each face is converted to
a B-spline surface (`BRepBuilderAPI_NurbsConvert`), its poles and its wires' poles are
moved by the FFD, the faces are rebuilt and written by `IGESControl_Writer`. The loop is
what a PyGeM user writes: for each row of the campaign's manifest, set the lattice
displacements the campaign's parameters name and call `ffd(input, dst=output)`.

PyGeM is written for pythonocc; it runs here on OCP (the OCCT venv) through
`benches/blade/occ_shim/` (OCC.Core.X -> OCP.X), completed below with the few
pythonocc spellings PyGeM's CAD module uses (static methods without OCP's `_s`, the
flat `geomconvert_...` and `Interface_Static_...` functions, `BRep_Tool.Curve` returning
a tuple).

    bash benches/blade/setup.sh        # the OCP venv with the shim, scipy
    cargo build --release -p cadmorph-cli
    PYGEM_DIR=/path/to/PyGeM benches/blade/.venv/bin/python benches/pygem/campaign.py --rounds 3

PYGEM_DIR is a checkout of GitHub mathLab/PyGeM (b482f27 was used), as for compare.py.

Each round runs cadmorph's whole campaign (a fresh output folder: refined base, 130
variants, each read back and its seams measured) and PyGeM's loop over the same 130
rows (sequential, as such loops are written, and with `--jobs N` in N processes).
"""
import argparse
import csv
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from multiprocessing import Pool

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _pythonocc_spellings():
    """What PyGeM's CAD module calls that OCP spells differently."""
    import OCP.BRep
    import OCP.BRepTools
    import OCP.GeomConvert
    import OCP.Interface
    import OCP.TopExp
    import OCP.TopoDS
    from OCP.TopAbs import TopAbs_ShapeEnum as kind
    # pythonocc down-casts shapes (an explorer's face is a TopoDS_Face, a converted
    # face's shape too); OCP gives a TopoDS_Shape.
    td = OCP.TopoDS.TopoDS
    casts = {kind.TopAbs_FACE: td.Face_s, kind.TopAbs_WIRE: td.Wire_s, kind.TopAbs_EDGE: td.Edge_s,
             kind.TopAbs_SHELL: td.Shell_s, kind.TopAbs_SOLID: td.Solid_s, kind.TopAbs_VERTEX: td.Vertex_s}

    def cast(shape):
        f = casts.get(shape.ShapeType())
        return f(shape) if f else shape

    # pythonocc's == on shapes is IsEqual (same TShape, location, orientation).
    OCP.TopoDS.TopoDS_Shape.__eq__ = lambda a, b: a.IsEqual(b)
    ex = OCP.TopExp.TopExp_Explorer
    current = ex.Current
    ex.Current = lambda self: cast(current(self))
    bt = OCP.BRep.BRep_Tool
    surface, degenerated, curve = bt.Surface_s, bt.Degenerated_s, bt.Curve_s
    bt.Surface = staticmethod(lambda f, *rest: surface(cast(f), *rest))
    bt.Degenerated = staticmethod(lambda e: degenerated(cast(e)))
    # pythonocc returns (curve, first, last); PyGeM takes [0].
    bt.Curve = staticmethod(lambda e: (curve(cast(e), 0.0, 0.0),))
    gc = OCP.GeomConvert.GeomConvert
    OCP.GeomConvert.geomconvert_SurfaceToBSplineSurface = gc.SurfaceToBSplineSurface_s
    OCP.Interface.Interface_Static_SetCVal = OCP.Interface.Interface_Static.SetCVal_s
    import OCP.IGESControl
    ctl = OCP.IGESControl.IGESControl_Controller
    ctl.Init = staticmethod(ctl.Init_s)
    tools = OCP.BRepTools.BRepTools
    outer = tools.OuterWire_s
    tools.OuterWire = staticmethod(lambda f: outer(cast(f)))


_CAD = None


def _pygem():
    """`pygem.cad`, with the shim and the spellings set up once per process."""
    global _CAD
    if _CAD is None:
        sys.path.insert(0, os.path.join(ROOT, "benches", "blade", "occ_shim"))
        _pythonocc_spellings()
        sys.path.insert(0, os.environ["PYGEM_DIR"])
        import pygem.cad
        _CAD = pygem.cad
    return _CAD


ENTRY = re.compile(r"^mu_([xyz])\[(\d+),(\d+),(\d+)\]$")


def _variant(job):
    """One PyGeM variant: (prm, entries, values, src, dst, scale) -> seconds."""
    prm, entries, values, src, dst, scale = job
    cad = _pygem()
    t0 = time.perf_counter()
    ffd = cad.FFD()
    ffd.read_parameters(prm)
    # OCCT reads the file into millimetres; the lattice box must follow (the
    # displacements are fractions of the box and stay).
    ffd.box_origin = ffd.box_origin * scale
    ffd.box_length = ffd.box_length * scale
    for (axis, i, j, k), x in zip(entries, values):
        getattr(ffd, "array_mu_" + axis)[i, j, k] = x
    ffd(src, dst=dst)
    return time.perf_counter() - t0


def occt_scale(binary, path):
    """Millimetres per file unit: OCCT's readers convert IGES and STEP to millimetres."""
    r = subprocess.run([binary, "info", path, "--json"], capture_output=True, text=True, check=True)
    return json.loads(r.stdout)["unit"]["metres_per_unit"] * 1000.0


def pygem_loop(space, manifest_csv, out, jobs, limit, scale):
    base = os.path.dirname(space["__path"])
    prm = os.path.normpath(os.path.join(base, space["deformation"]["ffd"]))
    src = os.path.normpath(os.path.join(base, space["base"]["geometry"]))
    entries = []
    for p in space["parameter"]:
        m = ENTRY.match(p["entry"])
        if not m:
            raise SystemExit(f"parameter {p['name']}: entry {p['entry']} is not an FFD mu entry")
        entries.append((m.group(1), int(m.group(2)), int(m.group(3)), int(m.group(4))))
    names = [p["name"] for p in space["parameter"]]
    with open(manifest_csv) as f:
        rows = list(csv.DictReader(f))[:limit]
    os.makedirs(out, exist_ok=True)
    # PyGeM's reader knows the extensions .iges and .step only.
    stem, ext = os.path.splitext(src)
    if ext not in (".iges", ".step"):
        renamed = os.path.join(out, "base" + {".igs": ".iges", ".stp": ".step"}.get(ext, ext))
        shutil.copyfile(src, renamed)
        src = renamed
    work = [(prm, entries, [float(r[n]) for n in names], src, os.path.join(out, r["id"] + ".iges"), scale)
            for r in rows]
    t0 = time.perf_counter()
    if jobs == 1:
        per = [_variant(w) for w in work]
    else:
        with Pool(jobs) as pool:
            per = pool.map(_variant, work, chunksize=1)
    return time.perf_counter() - t0, per, [w[4] for w in work]


def cadmorph_run(binary, campaign, out):
    shutil.rmtree(out, ignore_errors=True)
    args = [binary, "campaign", "run", campaign, "--out", out]
    t0 = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"cadmorph campaign run failed:\n{r.stdout}\n{r.stderr}")
    return wall, r.stdout.strip().splitlines()[-1]


def stats(xs):
    return f"{min(xs):.3f} / {statistics.median(xs):.3f} / {max(xs):.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--campaign", default=os.path.join(ROOT, "samples/campaigns/bow_dome.toml"))
    ap.add_argument("--cadmorph", default=os.path.join(ROOT, "target/release/cadmorph"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--jobs", type=int, default=os.cpu_count(), help="processes for the parallel PyGeM loop")
    ap.add_argument("--limit", type=int, default=None, help="PyGeM: only the first N variants (times scaled to all)")
    a = ap.parse_args()
    if not os.environ.get("PYGEM_DIR"):
        sys.exit("set PYGEM_DIR to a checkout of GitHub mathLab/PyGeM")
    with open(a.campaign, "rb") as f:
        space = tomllib.load(f)
    space["__path"] = a.campaign
    tmp = tempfile.mkdtemp(prefix="cadmorph-campaign-bench-")
    try:
        ours, seq, par = [], [], []
        n_all = None
        base = os.path.normpath(os.path.join(os.path.dirname(a.campaign), space["base"]["geometry"]))
        scale = occt_scale(a.cadmorph, base)
        for r in range(a.rounds):
            out = os.path.join(tmp, "cadmorph")
            wall, summary = cadmorph_run(a.cadmorph, a.campaign, out)
            ours.append(wall)
            manifest = os.path.join(out, "manifest.csv")
            with open(manifest) as f:
                n_all = sum(1 for _ in f) - 1
            n = min(n_all, a.limit or n_all)
            extra = n_all / n
            w1, per, files = pygem_loop(space, manifest, os.path.join(tmp, "pygem1"), 1, n, scale)
            seq.append(w1 * extra)
            wj, _, _ = pygem_loop(space, manifest, os.path.join(tmp, "pygemj"), a.jobs, n, scale)
            par.append(wj * extra)
            print(f"round {r + 1}: cadmorph {wall:.3f} s ({summary}); PyGeM sequential {w1:.2f} s for {n} "
                  f"(per variant {stats(per)} s), {a.jobs} processes {wj:.2f} s", flush=True)
            bad = [f for f in files if not os.path.exists(f) or os.path.getsize(f) == 0]
            if bad:
                raise SystemExit(f"PyGeM wrote no file for {bad[:3]}")
        print(f"\n{n_all} variants, {a.rounds} rounds, wall seconds min / median / max"
              + (f" (PyGeM: {n} variants measured, scaled to {n_all})" if n != n_all else ""))
        print(f"  cadmorph campaign run (refine, morph, write, read back, seams): {stats(ours)}")
        print(f"  PyGeM loop, sequential:                                         {stats(seq)}")
        print(f"  PyGeM loop, {a.jobs} processes:                                        {stats(par)}")
        ratios = [s / o for s, o in zip(seq, ours)]
        ratios_j = [s / o for s, o in zip(par, ours)]
        print(f"  ratio PyGeM sequential / cadmorph, same round: {stats(ratios)}")
        print(f"  ratio PyGeM {a.jobs} processes / cadmorph, same round: {stats(ratios_j)}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
