"""Side-by-side timing of PyGeM and cadmorph-morph on the same inputs, in one run.

Usage (from the workspace root):

    cargo build --release -p cadmorph-morph --example morph_bench
    PYGEM_DIR=/path/to/PyGeM python3 benches/pygem/compare.py [--no-pygem] [--only CASE ...]

PYGEM_DIR is a checkout of GitHub mathLab/PyGeM (not the PyPI package of that name);
PyGeM needs numpy, scipy and matplotlib. The cadmorph binary is taken from
$CADMORPH_BENCH or target*/release/examples/morph_bench. See README.md beside this file.

For every case the script writes the inputs (seeded numpy RNG) to a temporary folder,
runs PyGeM in a fresh Python process and cadmorph's `morph_bench` example in another, and
prints wall time (build + deform), peak resident memory of each process, the ratio, and
the largest coordinate difference between the two outputs.
"""
import argparse
import glob
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))

# name: (kind, settings, n_points, run_pygem)
CASES = {
    "ffd_3x3x3_1e6": ("ffd", {"lattice": 3}, 1_000_000, True),
    "ffd_6x6x6_1e6": ("ffd", {"lattice": 6}, 1_000_000, True),
    "rbf_tps_1000_1e5": ("rbf", {"kernel": "thin_plate_spline", "radius": 0.5, "nc": 1000}, 100_000, True),
    "rbf_tps_4000_1e6": ("rbf", {"kernel": "thin_plate_spline", "radius": 0.5, "nc": 4000}, 1_000_000, False),
    "rbf_wendland_c2_50k_1e6": ("rbf", {"kernel": "wendland_c2", "radius": 0.08, "nc": 50_000}, 1_000_000, False),
    # Four times the centres at the same ~105 neighbours per centre (support 0.08 / 4^(1/3)).
    "rbf_wendland_c2_200k_1e6": ("rbf", {"kernel": "wendland_c2", "radius": 0.0504, "nc": 200_000}, 1_000_000, False),
    "idw_p2_100_1e5": ("idw", {"power": 2, "nc": 100}, 100_000, True),
}


def write_ffd_prm(path, n, mu):
    """A PyGeM-readable FFD .prm: unit box, n^3 lattice, displacements mu[3, n, n, n]."""
    lines = ["[Box info]"]
    for a in "xyz":
        lines.append(f"n control points {a}: {n}")
    for a in "xyz":
        lines.append(f"box length {a}: 1.0")
    for a in "xyz":
        lines.append(f"box origin {a}: 0.0")
    for a in "xyz":
        lines.append(f"rotation angle {a}: 0.0")
    lines.append("")
    lines.append("[Parameters weights]")
    for c, a in enumerate("xyz"):
        rows = [f"{i}   {j}   {k}   {float(mu[c, i, j, k])!r}" for i in range(n) for j in range(n) for k in range(n)]
        lines.append(f"parameter {a}: " + rows[0])
        lines.extend("             " + r for r in rows[1:])
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def make_inputs(name, folder):
    kind, s, n_points, _ = CASES[name]
    rng = np.random.default_rng(0)
    if kind == "ffd":
        # 10% margin around the unit box, so some points lie outside it.
        points = rng.uniform(-0.1, 1.1, size=(n_points, 3))
        n = s["lattice"]
        write_ffd_prm(os.path.join(folder, "ffd.prm"), n, rng.uniform(-0.1, 0.1, size=(3, n, n, n)))
    else:
        points = rng.uniform(0.0, 1.0, size=(n_points, 3))
        centres = rng.uniform(0.0, 1.0, size=(s["nc"], 3))
        np.save(os.path.join(folder, "centres.npy"), centres)
        np.save(os.path.join(folder, "deformed.npy"), centres + rng.uniform(-0.05, 0.05, size=centres.shape))
    np.save(os.path.join(folder, "points.npy"), points)


def pygem_worker(name, folder):
    """Runs in its own process: PyGeM on the case, prints time and peak memory."""
    sys.path.insert(0, os.environ["PYGEM_DIR"])
    import matplotlib

    matplotlib.use("Agg")
    from pygem import FFD, IDW, RBF

    kind, s, _, _ = CASES[name]
    points = np.load(os.path.join(folder, "points.npy"))
    t0 = time.perf_counter()
    if kind == "ffd":
        ffd = FFD([s["lattice"]] * 3)
        ffd.read_parameters(os.path.join(folder, "ffd.prm"))
        out = ffd(points)
    else:
        centres = np.load(os.path.join(folder, "centres.npy"))
        deformed = np.load(os.path.join(folder, "deformed.npy"))
        if kind == "rbf":
            out = RBF(centres, deformed, func=s["kernel"], radius=s["radius"])(points)
        else:
            out = IDW(centres, deformed, power=s["power"])(points)
    elapsed = time.perf_counter() - t0
    np.save(os.path.join(folder, "out_pygem.npy"), out)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"total_s={elapsed:.4f} peak_rss_mb={peak_mb:.1f}")


def parse_kv(line):
    return dict(kv.split("=", 1) for kv in line.split())


def cadmorph_binary():
    if os.environ.get("CADMORPH_BENCH"):
        return os.environ["CADMORPH_BENCH"]
    found = sorted(glob.glob(os.path.join(ROOT, "target*", "release", "examples", "morph_bench")), key=os.path.getmtime)
    if not found:
        sys.exit("build it first: cargo build --release -p cadmorph-morph --example morph_bench")
    return found[-1]


def cadmorph_case(name):
    kind, s, _, _ = CASES[name]
    if kind == "ffd":
        return "ffd"
    if kind == "rbf":
        return f"rbf:{s['kernel']}:{s['radius']}"
    return f"idw:pygem:{s['power']}"


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--pygem-worker":
        pygem_worker(sys.argv[2], sys.argv[3])
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--no-pygem", action="store_true", help="run cadmorph only")
    ap.add_argument("--only", nargs="*", choices=sorted(CASES), help="cases to run")
    args = ap.parse_args()
    use_pygem = not args.no_pygem
    if use_pygem and not os.environ.get("PYGEM_DIR"):
        sys.exit("set PYGEM_DIR to a checkout of GitHub mathLab/PyGeM (or pass --no-pygem)")
    binary = cadmorph_binary()
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
    print(f"machine: {cpu}, {os.cpu_count()} cores; cadmorph commit {commit}; numpy {np.__version__}; {time.strftime('%Y-%m-%d')}")
    print()
    print("| case | PyGeM s | PyGeM peak MB | cadmorph s | cadmorph peak MB | point array MB | speed-up | max abs diff |")
    print("|---|---|---|---|---|---|---|---|")
    for name in args.only or CASES:
        _, _, _, pygem_ok = CASES[name]
        with tempfile.TemporaryDirectory(prefix=f"cadmorph-{name}-") as folder:
            make_inputs(name, folder)
            ours = subprocess.run([binary, cadmorph_case(name), folder], capture_output=True, text=True)
            if ours.returncode != 0:
                print(f"| {name} | cadmorph failed: {ours.stderr.strip().splitlines()[-1:]} |")
                continue
            c = parse_kv(ours.stdout.strip().splitlines()[-1])
            py_s, py_mb, ratio, diff = "not run", "", "", ""
            if use_pygem and pygem_ok:
                theirs = subprocess.run([sys.executable, __file__, "--pygem-worker", name, folder], capture_output=True, text=True)
                if theirs.returncode != 0:
                    py_s = "failed: " + (theirs.stderr.strip().splitlines() or ["?"])[-1]
                else:
                    p = parse_kv(theirs.stdout.strip().splitlines()[-1])
                    py_s, py_mb = p["total_s"], p["peak_rss_mb"]
                    ratio = f"{float(p['total_s']) / float(c['total_s']):.0f}x"
                    a = np.load(os.path.join(folder, "out_pygem.npy"))
                    b = np.load(os.path.join(folder, "out_cadmorph.npy"))
                    diff = f"{np.abs(a - b).max():.1e}"
            elif not pygem_ok:
                py_s = "not feasible"
            print(f"| {name} | {py_s} | {py_mb} | {c['total_s']} (build {c['build_s']}) | {c['peak_rss_mb']} | {c['points_mb']} | {ratio} | {diff} |", flush=True)


if __name__ == "__main__":
    main()
