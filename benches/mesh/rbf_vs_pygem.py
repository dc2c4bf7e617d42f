"""The RBF volume morph of the 10^6-cell blockMesh channel: cadmorph's multilevel Wendland
interpolation against PyGeM's dense RBF on the same boundary data, in one run (not run
in CI; see README.md beside this file).

Usage (from the workspace root; CASE made by `benches/mesh/run.sh`'s blockMesh step or
`bash /tmp/mkcase.sh 100 DIR`):

    cargo build --release -p cadmorph-mesh --example mesh_bench
    cargo build --release -p cadmorph-morph --example morph_bench
    PYGEM_DIR=/path/to/PyGeM VENV/bin/python benches/mesh/rbf_vs_pygem.py CASE \
        [--pygem-centres 100 200 400] [--rounds 3] [--pygem-gb 12]

1. `mesh_bench rbf-export CASE DIR` writes the mesh nodes and the constrained (fixed and
   moved) nodes with their displacements (the bump lift of `mesh_bench rbf`).
2. PyGeM: for each centre count N, N of the constrained nodes (farthest-point sample,
   seeded at the largest displacement) are the original control points, moved by their
   displacement as the deformed ones; `RBF(..., func='beckert_wendland_c2_basis',
   radius=0.6)` (the same function as cadmorph's `wendland_c2`, support 0.6) deforms all
   10^6 nodes. PyGeM assembles the full (N+4)^2 system and an n_points x (N+4) matrix, so
   its memory grows as 8 N n_points bytes several times over; the worker runs under an
   address-space limit of --pygem-gb GB and a count that does not fit is reported as such.
   Its wall time (build + deform), peak RSS and largest miss at the constrained nodes
   (relative to the largest displacement) are printed.
3. cadmorph on the same N centres and kernel (`morph_bench rbf:beckert_wendland_c2_basis:0.6`,
   the same interpolant: the largest coordinate difference is printed), and cadmorph's
   multilevel morph (`mesh_bench rbf CASE 20000`), --rounds times each, alternating.

The ratio reported is PyGeM's median over cadmorph's median, for the same interpolant and
for the multilevel morph (which matches every constrained node to 1e-3).
"""
import argparse
import glob
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))


def binary(name):
    found = sorted(glob.glob(os.path.join(ROOT, "target*", "release", "examples", name)), key=os.path.getmtime)
    if os.environ.get("CARGO_TARGET_DIR"):
        own = os.path.join(os.environ["CARGO_TARGET_DIR"], "release", "examples", name)
        if os.path.exists(own):
            return own
    if not found:
        sys.exit(f"build it first: cargo build --release --example {name}")
    return found[-1]


def farthest_points(p, n, first):
    """n indices of p by farthest-point sampling from `first` (O(n len(p)))."""
    chosen = [first]
    d = np.sum((p - p[first]) ** 2, axis=1)
    for _ in range(1, n):
        j = int(np.argmax(d))
        chosen.append(j)
        d = np.minimum(d, np.sum((p - p[j]) ** 2, axis=1))
    return np.array(chosen)


def pygem_worker(folder, gb):
    """Own process: PyGeM's RBF on folder's inputs under an address-space limit."""
    limit = int(gb * 2**30)
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    sys.path.insert(0, os.environ["PYGEM_DIR"])
    import matplotlib

    matplotlib.use("Agg")
    from pygem import RBF

    points = np.load(os.path.join(folder, "points.npy"))
    centres = np.load(os.path.join(folder, "centres.npy"))
    deformed = np.load(os.path.join(folder, "deformed.npy"))
    t0 = time.perf_counter()
    try:
        out = RBF(centres, deformed, func="beckert_wendland_c2_basis", radius=0.6)(points)
    except MemoryError:
        print("memory=exceeded")
        return
    elapsed = time.perf_counter() - t0
    np.save(os.path.join(folder, "out_pygem.npy"), out)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"total_s={elapsed:.4f} peak_rss_mb={peak_mb:.1f}")


def kv(line):
    return dict(x.split("=", 1) for x in line.split())


def stats(xs):
    xs = sorted(xs)
    return f"min {xs[0]:.3f}  median {statistics.median(xs):.3f}  max {xs[-1]:.3f}"


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--pygem-worker":
        return pygem_worker(sys.argv[2], float(sys.argv[3]))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--pygem-centres", type=int, nargs="*", default=[100, 200, 400])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--pygem-gb", type=float, default=12.0)
    ap.add_argument("--centres", type=int, default=20000, help="cadmorph multilevel centre budget")
    args = ap.parse_args()
    if not os.environ.get("PYGEM_DIR"):
        sys.exit("set PYGEM_DIR to a checkout of GitHub mathLab/PyGeM")
    mesh_bench, morph_bench = binary("mesh_bench"), binary("morph_bench")
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"machine: {cpu}, {os.cpu_count()} cores; cadmorph {commit}; numpy {np.__version__}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; load {os.getloadavg()}")
    with tempfile.TemporaryDirectory(prefix="cadmorph-rbf-pygem-") as folder:
        subprocess.run([mesh_bench, "rbf-export", args.case, folder], check=True, capture_output=True)
        points = np.load(os.path.join(folder, "points.npy"))
        cons = np.load(os.path.join(folder, "constrained.npy"))
        disp = np.load(os.path.join(folder, "displacements.npy"))
        dmax = np.linalg.norm(disp, axis=1).max()
        print(f"{len(points)} nodes, {len(cons)} constrained, largest displacement {dmax}")
        multi = []
        for n in args.pygem_centres:
            idx = farthest_points(points[cons], n, int(np.argmax(np.linalg.norm(disp, axis=1))))
            c = points[cons[idx]]
            np.save(os.path.join(folder, "centres.npy"), c)
            np.save(os.path.join(folder, "deformed.npy"), c + disp[idx])
            py, ours = [], []
            py_mb = our_mb = miss_py = diff = None
            for _ in range(args.rounds):
                w = subprocess.run([sys.executable, __file__, "--pygem-worker", folder, str(args.pygem_gb)],
                                   capture_output=True, text=True)
                line = (w.stdout.strip().splitlines() or ["failed"])[-1]
                if w.returncode != 0 or "memory=exceeded" in line or "total_s" not in line:
                    print(f"N={n}: PyGeM does not fit in {args.pygem_gb} GB ({line}{w.stderr.strip()[-200:]})")
                    py = None
                    break
                p = kv(line)
                py.append(float(p["total_s"]))
                py_mb = p["peak_rss_mb"]
                o = subprocess.run([morph_bench, "rbf:beckert_wendland_c2_basis:0.6", folder],
                                   capture_output=True, text=True, check=True)
                q = kv(o.stdout.strip().splitlines()[-1])
                ours.append(float(q["total_s"]))
                our_mb = q["peak_rss_mb"]
                m = json.loads(subprocess.run([mesh_bench, "rbf", args.case, str(args.centres)],
                                              capture_output=True, text=True, check=True).stdout)
                multi.append(m)
            if py is None:
                continue
            a = np.load(os.path.join(folder, "out_pygem.npy"))
            b = np.load(os.path.join(folder, "out_cadmorph.npy"))
            diff = np.abs(a - b).max()
            miss_py = np.linalg.norm(a[cons] - points[cons] - disp, axis=1).max() / dmax
            print(f"N={n} centres at 10^6 nodes, same interpolant:")
            print(f"  PyGeM RBF    : {stats(py)} s, peak {py_mb} MB, max miss at constrained nodes {miss_py:.3e}")
            print(f"  cadmorph Rbf : {stats(ours)} s, peak {our_mb} MB; max |PyGeM - cadmorph| {diff:.1e}")
            print(f"  ratio of medians PyGeM / cadmorph (same interpolant): {statistics.median(py) / statistics.median(ours):.0f}x")
            ms = [x["seconds"] for x in multi[-len(py):]]
            print(f"  cadmorph multilevel ({args.centres} budget), same rounds: {stats(ms)} s; "
                  f"ratio PyGeM(N={n}) / multilevel: {statistics.median(py) / statistics.median(ms):.1f}x")
        if multi:
            ms = [x["seconds"] for x in multi]
            last = multi[-1]
            print(f"cadmorph multilevel, all {len(ms)} runs: {stats(ms)} s; centres {last['centres']}, "
                  f"levels {last['level_centres']}, max miss {last['max_rel_error']:.3e}, "
                  f"negative volumes {last['negative_volumes']}, peak {last['peak_mb']:.0f} MB")


if __name__ == "__main__":
    main()
