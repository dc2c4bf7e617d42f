#!/usr/bin/env bash
# Side-by-side STEP parse benchmark against Foxtrot (Formlabs' Rust STEP viewer), same
# files, same run, alternated:
#   cadmorph: Document::parse + world NURBS of every face (crates/step/examples/step_bench.rs),
#             and Document::parse alone, each best of --repeat runs
#   Foxtrot:  StepFile::strip_flatten + StepFile::parse (parse only), best of --repeat runs,
#             by a timing binary built by hand from Foxtrot's public source (see
#             benches/README.md); nothing of Foxtrot is in this repository.
# Files: samples/*.stp and the generated hull3_200x150.stp (~8.75 MB) and faces300.stp
# (~2.76 MB) of the criterion bench crates/step/benches/parse.rs.
#
#   FOXTROT_BENCH=/path/to/foxtrot-bench bash benches/step_vs_foxtrot.sh [--pairs P] [--repeat N] [--keep DIR]
#
# The Foxtrot binary is called as `$FOXTROT_BENCH --repeat N FILE...` and must print one
# JSON line per file with at least "file", "bytes" and "best_s" (seconds). The file read is
# untimed on both sides. Each pair runs both programs on every file, the order swapped
# from one pair to the next; the ratio of a pair is Foxtrot's parse time over cadmorph's
# parse + NURBS time (above 1: cadmorph faster). Prints per file the min / median / max
# of the ratios over the pairs, the parse-only ratios beside, and `uptime` before and after.
# CARGO_TARGET_DIR defaults to target-step.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
pairs=5
repeat=5
keep=""
while [ $# -gt 0 ]; do
    case "$1" in
        --pairs) pairs="$2"; shift 2 ;;
        --repeat) repeat="$2"; shift 2 ;;
        --keep) keep="$2"; shift 2 ;;
        *) echo "unknown argument: $1" >&2; exit 2 ;;
    esac
done
fox="${FOXTROT_BENCH:?set FOXTROT_BENCH to a Foxtrot timing binary (see benches/README.md)}"
[ -x "$fox" ] || { echo "FOXTROT_BENCH=$fox is not executable" >&2; exit 2; }
if [ "$pairs" -lt 5 ]; then echo "note: fewer than 5 pairs" >&2; fi

export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target-step}"
if [ -n "$keep" ]; then work="$keep"; mkdir -p "$work"; else work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi

cargo build --release --quiet -p cadmorph-step --example step_bench --manifest-path "$root/Cargo.toml"
ours="$CARGO_TARGET_DIR/release/examples/step_bench"
"$ours" --write "$work/files"
files=("$root"/samples/*.stp "$work/files/hull3_200x150.stp" "$work/files/faces300.stp")

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "commit:  $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- crates || echo ' (crates/ modified)')"
echo "foxtrot: $fox"
echo "pairs $pairs, best of $repeat per program per file per pair"
echo "start:   $(date -u '+%F %T UTC'), uptime: $(uptime)"
: > "$work/foxtrot.jsonl"
: > "$work/cadmorph.jsonl"
for p in $(seq "$pairs"); do
    run_fox() { "$fox" --repeat "$repeat" "${files[@]}" | sed "s/^{/{\"pair\": $p, /" >> "$work/foxtrot.jsonl"; }
    run_ours() { "$ours" --repeat "$repeat" "${files[@]}" | sed "s/^{/{\"pair\": $p, /" >> "$work/cadmorph.jsonl"; }
    if [ $((p % 2)) -eq 1 ]; then run_fox; run_ours; else run_ours; run_fox; fi
done
echo "end:     $(date -u '+%F %T UTC'), uptime: $(uptime)"
echo
python3 - "$work" <<'PY'
import json, sys, pathlib, statistics
d = pathlib.Path(sys.argv[1])
def load(name):
    out = {}
    for line in (d / name).read_text().splitlines():
        o = json.loads(line)
        out[(o["pair"], pathlib.Path(o["file"]).name)] = o
    return out
fox, ours = load("foxtrot.jsonl"), load("cadmorph.jsonl")
names = []
for (_, n) in ours:
    if n not in names:
        names.append(n)
print("ratio = Foxtrot parse / cadmorph parse+world NURBS, per pair (min / median / max); "
      "parse-only ratio = Foxtrot parse / cadmorph parse")
print(f"{'file':24s} {'KB':>8s} {'Foxtrot ms':>10s} {'cad parse ms':>12s} {'cad +NURBS ms':>13s} "
      f"{'ratio min/med/max':>20s} {'parse-only min/med/max':>23s}  >=2x")
for n in names:
    ps = sorted(p for (p, m) in ours if m == n and (p, m) in fox)
    r = [fox[(p, n)]["best_s"] / ours[(p, n)]["parse_world_s"] for p in ps]
    q = [fox[(p, n)]["best_s"] / ours[(p, n)]["parse_s"] for p in ps]
    fb = min(fox[(p, n)]["best_s"] for p in ps)
    cp = min(ours[(p, n)]["parse_s"] for p in ps)
    cw = min(ours[(p, n)]["parse_world_s"] for p in ps)
    kb = ours[(ps[0], n)]["bytes"] / 1e3
    verdict = "yes" if min(r) >= 2 else ("median" if statistics.median(r) >= 2 else "no")
    print(f"{n:24s} {kb:8.1f} {fb*1e3:10.3f} {cp*1e3:12.3f} {cw*1e3:13.3f} "
          f"{min(r):6.2f} /{statistics.median(r):5.2f} /{max(r):5.2f} "
          f"{min(q):7.2f} /{statistics.median(q):5.2f} /{max(q):5.2f}  {verdict}")
PY
