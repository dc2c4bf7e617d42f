#!/usr/bin/env bash
# Side-by-side IGES benchmark: cadmorph-iges (parse + convert every face to NURBS) and
# OCCT 7.6 C++ (IGESControl_Reader ReadFile + TransferRoots) on the same generated files,
# in one run, alternating the two programs so that machine load hits both alike.
#
#   bash benches/iges_vs_occt.sh [--repeat N] [--rounds R] [--keep DIR] [--threads T]
#
# cadmorph reads records in parallel (rayon, all cores by default); --threads 1 gives its
# single-threaded figure (RAYON_NUM_THREADS for the cadmorph side only; OCCT's reader is
# single-threaded either way).
# Files (written by crates/iges/examples/iges_bench.rs, the generator of the criterion
# bench crates/iges/benches/parse.rs): hull3_200x150.igs, 3 trimmed bicubic patches of
# 200 x 150 poles (~5.6 MB, metres), and faces300.igs, 300 trimmed bicubic 8 x 8 faces.
# Prints both programs' JSON lines, the ratio OCCT time / cadmorph time (best over
# rounds), and min / median / max of the per-round ratios (each round runs OCCT then
# cadmorph, each the best of --repeat runs). Face counts must agree, or the script
# fails. OCCT prints progress messages on stdout; only its JSON lines are kept.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
repeat=5
rounds=3
keep=""
threads=""
while [ $# -gt 0 ]; do
    case "$1" in
        --repeat) repeat="$2"; shift 2 ;;
        --rounds) rounds="$2"; shift 2 ;;
        --keep) keep="$2"; shift 2 ;;
        --threads) threads="$2"; shift 2 ;;
        *) echo "unknown argument $1" >&2; exit 2 ;;
    esac
done
bash "$here/occt/install.sh" >&2
if ! dpkg -s libocct-data-exchange-dev >/dev/null 2>&1; then
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q libocct-data-exchange-dev >&2
fi
occt="$(bash "$here/occt/build_iges.sh" | tail -n 1)"
(cd "$root" && cargo build --release -q -p cadmorph-iges --example iges_bench)
target="${CARGO_TARGET_DIR:-$root/target}"
ours="$target/release/examples/iges_bench"
dir="${keep:-$(mktemp -d)}"
out="$(mktemp)"
trap 'rm -f "$out"; [ -z "$keep" ] && rm -rf "$dir"' EXIT
"$ours" --write "$dir"
files=("$dir/hull3_200x150.igs" "$dir/faces300.igs")
for r in $(seq "$rounds"); do
    "$occt" --repeat "$repeat" "${files[@]}" | grep "^{" | sed "s/^/occt /" | tee -a "$out"
    env ${threads:+RAYON_NUM_THREADS="$threads"} "$ours" --repeat "$repeat" "${files[@]}" | sed 's/^/cadmorph /' | tee -a "$out"
done
echo "cadmorph threads: ${threads:-all ($(nproc) cores)};$(uptime | sed 's/.*,  *load/ load/')"
python3 - "$out" <<'PY'
import json, os, statistics, sys
rows = {}
for line in open(sys.argv[1]):
    who, js = line.split(" ", 1)
    d = json.loads(js)
    rows.setdefault(os.path.basename(d["file"]), {}).setdefault(who, []).append(d)
print(f"{'file':<20}{'MB':>7}{'faces':>7}{'OCCT s':>10}{'OCCT MB/s':>11}{'cadmorph s':>12}{'MB/s':>8}{'ratio':>9}   pairs: min / median / max")
for name, r in rows.items():
    o = min(r["occt"], key=lambda d: d["read_transfer_s"])
    c = min(r["cadmorph"], key=lambda d: d["parse_convert_s"])
    if o["faces"] != c["faces"]:
        sys.exit(f"{name}: OCCT has {o['faces']} faces, cadmorph {c['faces']}")
    ratio = o["read_transfer_s"] / c["parse_convert_s"]
    # Round k's OCCT run against round k's cadmorph run (each the best of --repeat).
    pairs = [a["read_transfer_s"] / b["parse_convert_s"] for a, b in zip(r["occt"], r["cadmorph"])]
    print(f"{name:<20}{c['bytes'] / 1e6:>7.2f}{c['faces']:>7}{o['read_transfer_s']:>10.4f}{o['mb_per_s']:>11.1f}"
          f"{c['parse_convert_s']:>12.4f}{c['mb_per_s']:>8.1f}{ratio:>8.1f}x   "
          f"{min(pairs):.1f} / {statistics.median(pairs):.1f} / {max(pairs):.1f}x ({len(pairs)} pairs)")
PY
