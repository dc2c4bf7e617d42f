#!/usr/bin/env bash
# Side-by-side STEP read benchmark, same files, same run, the two programs alternating:
#   cadmorph: Document::parse + Document::faces_nurbs of every face
#             (crates/step/examples/step_bench.rs, file read untimed);
#   OCCT 7.6: STEPControl_Reader ReadFile + TransferRoots (benches/occt/step_occt.cpp)
# on the generated 3-patch hull (200x150 poles per patch, 8.75 MB) and 300-face files.
# Prints, per file, the ratio OCCT / cadmorph of each pair and its min / median / max.
#
#   bash benches/step_vs_occt.sh [--pairs P] [--repeat N]   # installs Debian's OCCT 7.6 data exchange
#
# CARGO_TARGET_DIR defaults to target-step; CXX and OCCT_INCLUDE can be overridden.
set -euo pipefail

pairs=5
repeat=3
while [ $# -gt 0 ]; do
    case "$1" in
        --pairs) pairs="$2"; shift 2 ;;
        --repeat) repeat="$2"; shift 2 ;;
        *) echo "unknown option $1" >&2; exit 2 ;;
    esac
done

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
include="${OCCT_INCLUDE:-/usr/include/opencascade}"
cxx="${CXX:-g++}"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target-step}"
files="$CARGO_TARGET_DIR/step-bench-files"
out="$root/benches/occt/build/step_occt"

mkdir -p "$root/benches/occt/build" "$files"
bash "$root/benches/occt/install.sh" >&2
if ! dpkg -s libocct-data-exchange-dev >/dev/null 2>&1; then
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q libocct-data-exchange-dev >&2
fi
if [ ! -x "$out" ] || [ "$root/benches/occt/step_occt.cpp" -nt "$out" ]; then
    "$cxx" -O2 -std=c++17 -isystem "$include" "$root/benches/occt/step_occt.cpp" -o "$out" \
        -lTKSTEP -lTKSTEPBase -lTKSTEPAttr -lTKSTEP209 -lTKXSBase -lTKShHealing -lTKTopAlgo -lTKGeomAlgo \
        -lTKBRep -lTKGeomBase -lTKG3d -lTKG2d -lTKMath -lTKernel
fi
cargo build --release -q -p cadmorph-step --example step_bench
ours="$CARGO_TARGET_DIR/release/examples/step_bench"
"$ours" --write "$files" >/dev/null
inputs=("$files/hull3_200x150.stp" "$files/faces300.stp")

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "commit:  $(git -C "$root" rev-parse --short HEAD)"
echo "pairs $pairs, best of $repeat per program per file per pair"
echo "start:   $(date -u '+%F %T') UTC, $(uptime)"
: > "$files/cadmorph.jsonl"
: > "$files/occt.jsonl"
for ((p = 0; p < pairs; p++)); do
    "$ours" --repeat "$repeat" "${inputs[@]}" >> "$files/cadmorph.jsonl"
    "$out" --repeat "$repeat" "${inputs[@]}" >> "$files/occt.jsonl"
done
echo "end:     $(date -u '+%F %T') UTC, $(uptime)"
echo
python3 - "$files" <<'PY'
import json, pathlib, statistics, sys
d = pathlib.Path(sys.argv[1])
ours = [json.loads(l) for l in (d / "cadmorph.jsonl").read_text().splitlines()]
occt = [json.loads(l) for l in (d / "occt.jsonl").read_text().splitlines()]
by = {}
for o, c in zip(ours, occt):
    key = pathlib.Path(o["file"]).stem
    assert key == pathlib.Path(c["file"]).stem
    by.setdefault(key, []).append((o, c))
print("ratio = OCCT ReadFile+TransferRoots / cadmorph parse+world NURBS, per pair")
print(f"{'file':15s} {'MB':>6s} {'OCCT ms':>9s} {'cadmorph ms':>12s} {'MB/s':>7s}   ratio min / median / max")
for key, runs in by.items():
    r = [c["total_s"] / o["parse_world_s"] for o, c in runs]
    mb = runs[0][0]["bytes"] / 1e6
    best_o = min(o["parse_world_s"] for o, _ in runs)
    best_c = min(c["total_s"] for _, c in runs)
    print(f"{key:15s} {mb:6.2f} {best_c*1e3:9.1f} {best_o*1e3:12.2f} {mb/best_o:7.1f}   "
          f"{min(r):5.1f} / {statistics.median(r):5.1f} / {max(r):5.1f}")
PY
