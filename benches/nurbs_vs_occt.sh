#!/usr/bin/env bash
# Side-by-side NURBS benchmark: OCCT 7.6 (C++, Geom_BSplineSurface) and cadmorph-nurbs
# on the same bicubic 10x10 surface, the same 1e6 points and the same 100+100 knots,
# in one run, alternating the two programs so that machine load hits both alike.
#
#   bash benches/nurbs_vs_occt.sh [--repeat N] [--rounds R]
#
# Prints both JSON lines per round and the per-core ratios (OCCT time / cadmorph time,
# best over rounds). Checksums must agree, or the script fails.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
repeat=7
rounds=3
while [ $# -gt 0 ]; do
    case "$1" in
        --repeat) repeat="$2"; shift 2 ;;
        --rounds) rounds="$2"; shift 2 ;;
        *) echo "unknown argument $1" >&2; exit 2 ;;
    esac
done
bash "$here/occt/install.sh" >&2
occt="$(bash "$here/occt/build.sh" | tail -n 1)"
(cd "$root" && cargo build --release -q -p cadmorph-nurbs --example nurbs_bench)
target="${CARGO_TARGET_DIR:-$root/target}"
ours="$target/release/examples/nurbs_bench"
out="$(mktemp)"
trap 'rm -f "$out"' EXIT
for r in $(seq "$rounds"); do
    echo "occt $("$occt" --repeat "$repeat")" | tee -a "$out"
    echo "cadmorph $("$ours" --repeat "$repeat")" | tee -a "$out"
done
python3 - "$out" <<'PY'
import json, sys
rows = {"occt": [], "cadmorph": []}
for line in open(sys.argv[1]):
    who, js = line.split(" ", 1)
    rows[who].append(json.loads(js))
best = {w: {k: min(r[k] for r in rs) for k in ("eval_1e6_s", "d1_1e6_s", "refine_100_s")} for w, rs in rows.items()}
o, c = rows["occt"][0], rows["cadmorph"][0]
for k in ("checksum_eval", "checksum_d1", "checksum_refine_poles"):
    rel = abs(o[k] - c[k]) / abs(o[k])
    print(f"{k}: occt {o[k]!r} cadmorph {c[k]!r} (relative difference {rel:.1e})")
    if rel > 1e-12:
        sys.exit(f"checksum {k} differs")
print(f"{'case':<14}{'OCCT s':>12}{'cadmorph s':>14}{'ratio':>9}   same-round ratios min / median / max")
for k, name in (("eval_1e6_s", "Value 1e6"), ("d1_1e6_s", "D1 1e6"), ("refine_100_s", "refine 100")):
    pairs = sorted(o[k] / c[k] for o, c in zip(rows["occt"], rows["cadmorph"]))
    med = pairs[len(pairs) // 2] if len(pairs) % 2 else 0.5 * (pairs[len(pairs) // 2 - 1] + pairs[len(pairs) // 2])
    print(f"{name:<14}{best['occt'][k]:>12.4g}{best['cadmorph'][k]:>14.4g}{best['occt'][k] / best['cadmorph'][k]:>8.2f}x"
          f"   {pairs[0]:.2f} / {med:.2f} / {pairs[-1]:.2f} over {len(pairs)} rounds")
print("load average:", open("/proc/loadavg").read().split()[:3])
PY
