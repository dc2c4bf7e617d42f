#!/usr/bin/env bash
# Side-by-side STEP read benchmark, same files, same run:
#   cadmorph: Document::parse + world NURBS of every face (criterion bench crates/step/benches/parse.rs)
#   OCCT 7.6: STEPControl_Reader ReadFile + TransferRoots (benches/occt/step_occt.cpp)
# on the generated 3-patch hull (200x150 poles per patch, ~8 MB) and 300-face files.
#
#   bash benches/step_vs_occt.sh            # needs Debian's OCCT (benches/occt/install.sh)
#
# CARGO_TARGET_DIR defaults to target-step; CXX and OCCT_INCLUDE can be overridden.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
include="${OCCT_INCLUDE:-/usr/include/opencascade}"
cxx="${CXX:-g++}"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target-step}"
files="$CARGO_TARGET_DIR/step-bench-files"
out="$root/benches/occt/build/step_occt"

mkdir -p "$root/benches/occt/build" "$files"
if [ ! -x "$out" ] || [ "$root/benches/occt/step_occt.cpp" -nt "$out" ]; then
    "$cxx" -O2 -std=c++17 -isystem "$include" "$root/benches/occt/step_occt.cpp" -o "$out" \
        -lTKSTEP -lTKSTEPBase -lTKSTEPAttr -lTKSTEP209 -lTKXSBase -lTKShHealing -lTKTopAlgo -lTKGeomAlgo \
        -lTKBRep -lTKGeomBase -lTKG3d -lTKG2d -lTKMath -lTKernel
fi

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "commit:  $(git -C "$root" rev-parse --short HEAD)"
echo
echo "== cadmorph (criterion, parse + world NURBS of every face) =="
CADMORPH_STEP_BENCH_DIR="$files" cargo bench -p cadmorph-step --bench parse -- --noplot 2>&1 \
    | grep -E "^step/|time:|thrpt:" | tee "$files/cadmorph.txt"
echo
echo "== OCCT 7.6 STEPControl_Reader ReadFile + TransferRoots (best of 3) =="
"$out" --repeat 3 "$files/hull3_200x150.stp" "$files/faces300.stp" | tee "$files/occt.txt"
echo
python3 - "$files" <<'PY'
import json, re, sys, pathlib
d = pathlib.Path(sys.argv[1])
text = (d / "cadmorph.txt").read_text()
ours = {}
name = None
for line in text.splitlines():
    m = re.match(r"^step/parse_world/(\S+)", line)
    if m:
        name = m.group(1)
    m = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+)", line)
    if m and name and name not in ours:
        v, unit = float(m.group(1)), m.group(2)
        ours[name] = v * {"s": 1, "ms": 1e-3, "µs": 1e-6, "us": 1e-6}[unit]
for line in (d / "occt.txt").read_text().splitlines():
    o = json.loads(line)
    key = pathlib.Path(o["file"]).stem
    if key in ours:
        mb = o["bytes"] / 1e6
        print(f"{key:15s} {mb:6.2f} MB  cadmorph {ours[key]*1e3:8.2f} ms ({mb/ours[key]:7.1f} MB/s)  "
              f"OCCT {o['total_s']*1e3:8.1f} ms ({o['mb_per_s']:5.1f} MB/s)  speed-up {o['total_s']/ours[key]:5.1f}x")
PY
