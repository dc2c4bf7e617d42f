#!/usr/bin/env python3
"""Side-by-side benchmark: one 10-section blade (BladeX tutorial 3: NACA 0012, radii
1..10, chord 2..6.5, pitch 1..10, rake 0.1..1, skew 1..19 deg, 240 points per side)
built and exported to IGES by BladeX (its own source checkout at 0c84eab, on OCP through
occ_shim/) and by cadmorph (`cargo bench -p cadmorph-blade --bench build`, in memory),
in one run; prints min/median/max of each and the ratio of the medians.

    bash benches/blade/setup.sh
    benches/blade/.venv/bin/python benches/blade/bench.py [--runs 5]
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import types

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))


def bladex_runs(runs):
    # Load the bladex package without its __init__ (which imports Propeller and with it
    # the `smithers` package the blade does not need).
    src = os.environ.get("BLADEX", os.path.join(HERE, ".bladex"))
    pkg = types.ModuleType("bladex")
    pkg.__path__ = [os.path.join(src, "bladex")]
    sys.modules["bladex"] = pkg
    import numpy as np
    from bladex.blade import Blade
    from bladex.profile import NacaProfile

    out, build, export = [], [], []
    with tempfile.TemporaryDirectory() as d:
        for _ in range(runs):
            t0 = time.perf_counter()
            sections = np.asarray([NacaProfile(digits="0012") for _ in range(10)])
            b = Blade(sections=sections, radii=np.arange(1.0, 11.0, 1.0),
                      chord_lengths=np.arange(2.0, 7.0, 0.5), pitch=np.arange(1.0, 11.0),
                      rake=np.arange(0.1, 1.1, 0.1), skew_angles=np.arange(1.0, 21, 2.0))
            devnull = open(os.devnull, "w")
            old = sys.stdout
            sys.stdout = devnull  # InterpolatedFace prints array shapes
            try:
                b.build(reflect=True)
                t1 = time.perf_counter()
                b.export_iges(os.path.join(d, "blade.iges"))
            finally:
                sys.stdout = old
            t2 = time.perf_counter()
            build.append(1e3 * (t1 - t0))
            export.append(1e3 * (t2 - t1))
            out.append(1e3 * (t2 - t0))
    return out, build, export


def stats(v):
    v = sorted(v)
    return [v[0], v[len(v) // 2], v[-1]]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    env = dict(os.environ)
    cm = subprocess.run(["cargo", "bench", "-q", "-p", "cadmorph-blade", "--bench", "build"],
                        cwd=ROOT, env=env, capture_output=True, text=True)
    line = [l for l in cm.stdout.splitlines() if l.startswith("{")]
    if cm.returncode != 0 or not line:
        sys.exit("cargo bench failed:\n" + cm.stderr[-2000:])
    cad = json.loads(line[-1])
    total, build, export = bladex_runs(a.runs)
    cm2 = subprocess.run(["cargo", "bench", "-q", "-p", "cadmorph-blade", "--bench", "build"],
                         cwd=ROOT, env=env, capture_output=True, text=True)
    cad2 = json.loads([l for l in cm2.stdout.splitlines() if l.startswith("{")][-1])
    rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    bx = stats(total)
    report = {
        "machine": platform.node() + " " + platform.machine() + f" {os.cpu_count()} cpus",
        "commit": rev.stdout.strip(),
        "bladex_build_and_iges_ms": bx,
        "bladex_build_ms": stats(build),
        "bladex_iges_ms": stats(export),
        "cadmorph_iges_ms_before": cad["iges_ms"],
        "cadmorph_iges_ms_after": cad2["iges_ms"],
        "cadmorph_step_ms": cad["step_ms"],
        "ratio_median": bx[1] / cad["iges_ms"][1],
        "ratio_median_after": bx[1] / cad2["iges_ms"][1],
        "ratio_min": bx[0] / min(cad["iges_ms"][0], cad2["iges_ms"][0]),
    }
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
