#!/usr/bin/env bash
# Side-by-side mesh benchmarks (not run in CI):
#   * cadmorph's quality check against OpenFOAM's checkMesh on the same blockMesh case;
#   * polyMesh read + write (cadmorph) and VTU read + write (cadmorph and meshio) of the
#     same mesh (meshio has no OpenFOAM reader, so it is timed on foamToVTK's .vtu);
#   * the RBF boundary → interior morph (multilevel Wendland C², support 0.6 on level 0,
#     at most CENTRES centres over all levels), R times, with wall time and peak memory.
#
#   bash benches/mesh/run.sh [--cells N] [--rounds R] [--centres C]
#
# N is the cells per direction of the channel (default 100: 10^6 cells), R the number of
# alternated rounds (default 3). Prints min/median/max seconds and the ratios.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$here/../.."
n=100; rounds=3; centres=20000
while [ $# -gt 0 ]; do
    case "$1" in
        --cells) n=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --centres) centres=$2; shift 2 ;;
        *) echo "unknown option $1" >&2; exit 2 ;;
    esac
done
py=$(bash "$root/tests/mesh/setup.sh" | tail -1)
set +eu; source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1; set -eu
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
cargo build -q --release -p cadmorph-mesh --example mesh_bench
bench="$CARGO_TARGET_DIR/release/examples/mesh_bench"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
case="$work/case"
mkdir -p "$case/system"
cat > "$case/system/controlDict" <<EOD
FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }
application icoFoam; startFrom startTime; startTime 0; stopAt endTime; endTime 1; deltaT 1;
writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 17; writeCompression off;
timeFormat general; timePrecision 6;
EOD
cat > "$case/system/fvSchemes" <<EOD
FoamFile { version 2.0; format ascii; class dictionary; object fvSchemes; }
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; } divSchemes { default none; }
laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; } snGradSchemes { default corrected; }
EOD
echo 'FoamFile { version 2.0; format ascii; class dictionary; object fvSolution; }' > "$case/system/fvSolution"
cat > "$case/system/blockMeshDict" <<EOD
FoamFile { version 2.0; format ascii; class dictionary; object blockMeshDict; }
convertToMeters 1;
vertices ( (0 0 0) (3 0 0) (3 1 0) (0 1 0) (0 0 1) (3 0 1) (3 1 1) (0 1 1) );
blocks ( hex (0 1 2 3 4 5 6 7) ($n $n $n) simpleGrading (1 4 1) );
edges ( arc 0 1 (1.5 0.25 0) arc 4 5 (1.5 0.25 1) );
boundary
(
    inlet { type patch; faces ((0 4 7 3)); }
    outlet { type patch; faces ((1 2 6 5)); }
    bump { type wall; faces ((0 1 5 4)); }
    top { type wall; faces ((3 7 6 2)); }
    sides { type wall; faces ((0 3 2 1) (4 5 6 7)); }
);
EOD
(cd "$case" && blockMesh > log.blockMesh 2>&1)
(cd "$case" && foamToVTK -noZero -noFaceZones -noPointValues > log.foamToVTK 2>&1) || true
vtu=$(find "$case/VTK" -name '*.vtu' | head -1)
echo "case: $n^3 = $((n*n*n)) cells; vtu: ${vtu:-none}"

now() { date +%s.%N; }
declare -a cq cqr fq crw vrw mrw
for r in $(seq 1 "$rounds"); do
    out=$("$bench" quality "$case")
    cq+=("$(echo "$out" | sed 's/.*"seconds":\([0-9.e-]*\).*/\1/')")
    cqr+=("$(echo "$out" | sed 's/.*"read_and_check_seconds":\([0-9.e-]*\).*/\1/')")
    t0=$(now); (cd "$case" && checkMesh > "$work/log.checkMesh" 2>&1); t1=$(now)
    fq+=("$(echo "$t1 - $t0" | bc -l)")
    crw+=("$("$bench" readwrite "$case" "$work/out_polyMesh" | sed 's/.*"seconds":\([0-9.e-]*\).*/\1/')")
    if [ -n "$vtu" ]; then
        vrw+=("$("$bench" vtu "$vtu" "$work/out_cadmorph.vtu" | sed 's/.*"seconds":\([0-9.e-]*\).*/\1/')")
        mrw+=("$("$py" -c "
import time, meshio, sys
t = time.perf_counter(); m = meshio.read(sys.argv[1]); m.points[0, 2] += 1e-12; meshio.write(sys.argv[2], m)
print(time.perf_counter() - t)" "$vtu" "$work/out_meshio.vtu")")
    fi
done
stats() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {printf "min %.4f  median %.4f  max %.4f", a[1], a[int((NR+1)/2)], a[NR]}'; }
ratio() { # median(a) / median(b)
    local ma mb
    ma=$(printf '%s\n' "${@:2:$1}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    mb=$(printf '%s\n' "${@:$(( $1 + 2 ))}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    echo "scale=2; $ma / $mb" | bc -l
}
echo "checkMesh (whole run)          : $(stats "${fq[@]}")"
echo "cadmorph read + quality check   : $(stats "${cqr[@]}")"
echo "cadmorph quality check alone    : $(stats "${cq[@]}")"
echo "  ratio checkMesh / cadmorph read+check (median): $(ratio ${#fq[@]} "${fq[@]}" "${cqr[@]}")x"
grep -E "cells:|Mesh OK|non-orthogonality Max|Max skewness" "$work/log.checkMesh" | sed 's/^/  checkMesh: /'
"$bench" quality "$case" | sed 's/^/  cadmorph: /'
echo "cadmorph polyMesh read+write    : $(stats "${crw[@]}")"
if [ -n "$vtu" ]; then
    echo "cadmorph VTU read+write         : $(stats "${vrw[@]}")"
    echo "meshio VTU read+write           : $(stats "${mrw[@]}")"
    echo "  ratio meshio / cadmorph VTU (median): $(ratio ${#mrw[@]} "${mrw[@]}" "${vrw[@]}")x"
fi
if [ -z "${SKIP_RBF:-}" ]; then
    declare -a rbf
    for r in $(seq 1 "$rounds"); do
        /usr/bin/time -v "$bench" rbf "$case" "$centres" 2> "$work/time.rbf" > "$work/rbf.json"
        sed 's/^/RBF volume morph: /' "$work/rbf.json"
        grep -E "Maximum resident|Elapsed" "$work/time.rbf" | sed 's/^/  /'
        rbf+=("$(sed 's/.*"seconds":\([0-9.e-]*\).*/\1/' "$work/rbf.json")")
    done
    echo "cadmorph RBF volume morph (solve): $(stats "${rbf[@]}")"
fi
