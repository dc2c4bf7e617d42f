"""PyGeM, cadmorph from Python and cadmorph from Rust side by side, in one run.

Usage (from the workspace root; see README.md beside this file):

    cargo build --release -p cadmorph-morph --example morph_bench
    maturin build --release -o /tmp/wheels && pip install /tmp/wheels/cadmorph-*.whl   # in the venv below
    PYGEM_DIR=/path/to/PyGeM python benches/pygem/compare_py.py [--repeat 5] [--only CASE ...] [--no-pygem]

The cases and inputs are compare.py's (imported from it). For every case and round, three
fresh processes run on the same inputs: PyGeM (compare.py's worker), the Python package
(``cadmorph.pygem`` for the cases PyGeM runs: the same script with the other import; the
native ``cadmorph.read_parameters``/``Rbf``/``Idw`` otherwise) and the Rust ``morph_bench``
example. Each prints its build + deform time; the table gives min / median / max over the
rounds of the speed-ups PyGeM/Python and PyGeM/Rust, of the ratio Python/Rust, and the
largest coordinate difference of the Python output from PyGeM's and from Rust's.

``--overhead`` runs the FFD 3x3x3 case on 10^6 points only and compares the deformation
alone (no parsing): Rust ``morph_bench`` with ``CADMORPH_BENCH_REPEAT`` against the Python
package in place (``ffd(points, out=points)``) and into a new array (``ffd(points)``), the
fastest of ``--repeat`` runs of each, in the same run.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import compare  # noqa: E402  (the cases, inputs and PyGeM worker)


def python_worker(name, folder, repeat):
    """Runs in its own process: the Python package on the case; prints time and peak memory."""
    import resource

    import cadmorph

    cadmorph.set_num_threads()  # as morph_bench: the pool (main thread = worker 0) before the clock
    kind, s, _, pygem_ok = compare.CASES[name]
    points = np.load(os.path.join(folder, "points.npy"))
    t0 = time.perf_counter()
    if kind == "ffd":
        if pygem_ok:
            from cadmorph.pygem import FFD

            ffd = FFD([s["lattice"]] * 3)
            ffd.read_parameters(os.path.join(folder, "ffd.prm"))
            out = ffd(points)
        else:
            out = cadmorph.read_parameters(os.path.join(folder, "ffd.prm"))(points)
    else:
        centres = np.load(os.path.join(folder, "centres.npy"))
        deformed = np.load(os.path.join(folder, "deformed.npy"))
        if kind == "rbf":
            if pygem_ok:
                from cadmorph.pygem import RBF

                out = RBF(centres, deformed, func=s["kernel"], radius=s["radius"])(points)
            else:
                out = cadmorph.Rbf(centres, deformed, kernel=s["kernel"], radius=s["radius"])(points)
        else:
            from cadmorph.pygem import IDW

            out = IDW(centres, deformed, power=s["power"])(points)
    elapsed = time.perf_counter() - t0
    np.save(os.path.join(folder, "out_python.npy"), out)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"total_s={elapsed:.5f} peak_rss_mb={peak_mb:.1f}")


def overhead_worker(folder, repeat):
    """The FFD deformation alone, in place and into a new array, fastest of `repeat`."""
    import cadmorph

    cadmorph.set_num_threads()
    ffd = cadmorph.read_parameters(os.path.join(folder, "ffd.prm"))
    src = np.load(os.path.join(folder, "points.npy"))
    inplace, fresh = [], []
    # As morph_bench does: each run deforms a fresh copy of the input in memory that the
    # allocator recycles (Rust's `input.clone()` after the last copy was freed), here one
    # buffer refilled with np.copyto. (A new `src.copy()` per run is a new mapping each
    # time, which measured slower whatever deforms it.)
    pts = np.empty_like(src)
    for _ in range(repeat):
        np.copyto(pts, src)
        t = time.perf_counter()
        ffd(pts, out=pts)
        inplace.append(time.perf_counter() - t)
    for _ in range(repeat):
        t = time.perf_counter()
        out = ffd(src)
        fresh.append(time.perf_counter() - t)
        del out
    np.save(os.path.join(folder, "out_python.npy"), pts)
    print(f"inplace_min_s={min(inplace):.6f} inplace_median_s={statistics.median(inplace):.6f} "
          f"new_min_s={min(fresh):.6f} new_median_s={statistics.median(fresh):.6f}")


def run(cmd, env=None):
    res = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if res.returncode != 0:
        raise RuntimeError(f"{cmd[:3]} failed: {res.stderr.strip()[-500:]}")
    return compare.parse_kv(res.stdout.strip().splitlines()[-1])


def mmm(values, fmt):
    if not values:
        return ""
    return " / ".join(fmt.format(v) for v in (min(values), statistics.median(values), max(values)))


def main():
    if len(sys.argv) >= 4 and sys.argv[1] == "--python-worker":
        python_worker(sys.argv[2], sys.argv[3], 1)
        return
    if len(sys.argv) >= 4 and sys.argv[1] == "--overhead-worker":
        overhead_worker(sys.argv[2], int(sys.argv[3]))
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--no-pygem", action="store_true")
    ap.add_argument("--only", nargs="*", choices=sorted(compare.CASES))
    ap.add_argument("--repeat", type=int, default=3, help="rounds per case (fresh processes each)")
    ap.add_argument("--overhead", action="store_true", help="FFD 3x3x3 1e6: Python against Rust, deformation only")
    args = ap.parse_args()
    binary = compare.cadmorph_binary()
    import cadmorph

    commit = subprocess.run(["git", "-C", compare.ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    print(f"cadmorph {cadmorph.__version__} (commit {commit}), numpy {np.__version__}, python {sys.version.split()[0]}, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    if args.overhead:
        with tempfile.TemporaryDirectory(prefix="cadmorph-overhead-") as folder:
            compare.make_inputs("ffd_3x3x3_1e6", folder)
            rows = []
            for _ in range(args.repeat):
                env = dict(os.environ, CADMORPH_BENCH_REPEAT=str(args.repeat))
                r = run([binary, "ffd", folder], env=env)
                p = run([sys.executable, __file__, "--overhead-worker", folder, str(args.repeat)])
                a = np.load(os.path.join(folder, "out_cadmorph.npy"))
                b = np.load(os.path.join(folder, "out_python.npy"))
                rows.append((float(r["deform_min_s"]), float(p["inplace_min_s"]), float(p["new_min_s"]),
                             np.abs(a - b).max()))
            print()
            print("| round | Rust deform min s | Python in place min s | ratio | Python new array min s | ratio | max abs diff |")
            print("|---|---|---|---|---|---|---|")
            for i, (r, p, n, d) in enumerate(rows):
                print(f"| {i + 1} | {r:.6f} | {p:.6f} | {p / r:.3f} | {n:.6f} | {n / r:.3f} | {d:.1e} |")
            print(f"\nPython in place / Rust, min / median / max over rounds: {mmm([p / r for r, p, _, _ in rows], '{:.3f}')}")
            print(f"Python new array / Rust: {mmm([n / r for r, _, n, _ in rows], '{:.3f}')}")
            best_r, best_p, best_n = (min(x[i] for x in rows) for i in range(3))
            print(f"fastest of all rounds: Rust {best_r:.6f} s, Python in place {best_p:.6f} s ({best_p / best_r:.3f}), "
                  f"Python new array {best_n:.6f} s ({best_n / best_r:.3f})")
        return
    use_pygem = not args.no_pygem
    if use_pygem and not os.environ.get("PYGEM_DIR"):
        sys.exit("set PYGEM_DIR to a checkout of GitHub mathLab/PyGeM (or pass --no-pygem)")
    print()
    print("| case | rounds | PyGeM s (median) | Python s (median) | Rust s (median) | PyGeM/Python min/med/max | "
          "PyGeM/Rust min/med/max | Python/Rust min/med/max | max diff Python-PyGeM | max diff Python-Rust |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in args.only or compare.CASES:
        _, _, _, pygem_ok = compare.CASES[name]
        t_pg, t_py, t_rs, d_pg, d_rs = [], [], [], 0.0, 0.0
        with tempfile.TemporaryDirectory(prefix=f"cadmorph-{name}-") as folder:
            compare.make_inputs(name, folder)
            for _ in range(args.repeat):
                r = run([binary, compare.cadmorph_case(name), folder])
                p = run([sys.executable, __file__, "--python-worker", name, folder])
                t_rs.append(float(r["total_s"]))
                t_py.append(float(p["total_s"]))
                py_out = np.load(os.path.join(folder, "out_python.npy"))
                d_rs = max(d_rs, np.abs(py_out - np.load(os.path.join(folder, "out_cadmorph.npy"))).max())
                if use_pygem and pygem_ok:
                    g = run([sys.executable, compare.__file__, "--pygem-worker", name, folder])
                    t_pg.append(float(g["total_s"]))
                    d_pg = max(d_pg, np.abs(py_out - np.load(os.path.join(folder, "out_pygem.npy"))).max())
        med = lambda v: f"{statistics.median(v):.4f}" if v else "not run"  # noqa: E731
        print(f"| {name} | {args.repeat} | {med(t_pg)} | {med(t_py)} | {med(t_rs)} | "
              f"{mmm([g / p for g, p in zip(t_pg, t_py)], '{:.0f}x')} | {mmm([g / r for g, r in zip(t_pg, t_rs)], '{:.0f}x')} | "
              f"{mmm([p / r for p, r in zip(t_py, t_rs)], '{:.2f}')} | {f'{d_pg:.1e}' if t_pg else ''} | {d_rs:.1e} |",
              flush=True)


if __name__ == "__main__":
    main()
