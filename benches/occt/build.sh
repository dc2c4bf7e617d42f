#!/usr/bin/env bash
# Build the OCCT side of the NURBS benchmark into benches/occt/build/ (git-ignored).
#
#   bash benches/occt/install.sh     # once: Debian's OCCT 7.6 headers and libraries
#   bash benches/occt/build.sh       # prints the binary's path on its last line
#   benches/occt/build/nurbs_occt [--repeat N]
#
# OCCT_INCLUDE (default /usr/include/opencascade) and CXX (default g++) can be overridden.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
include="${OCCT_INCLUDE:-/usr/include/opencascade}"
cxx="${CXX:-g++}"
out="$here/build/nurbs_occt"

if [ ! -f "$include/Geom_BSplineSurface.hxx" ]; then
    echo "error: OCCT headers not found in $include; run benches/occt/install.sh" >&2
    exit 1
fi
mkdir -p "$here/build"
if [ ! -x "$out" ] || [ "$here/nurbs_occt.cpp" -nt "$out" ] || [ "$0" -nt "$out" ]; then
    # -O2 as Debian builds OCCT itself; no -march=native, so numbers compare across machines.
    "$cxx" -O2 -std=c++17 -Wall -Wextra -isystem "$include" "$here/nurbs_occt.cpp" -o "$out" \
        -lTKG3d -lTKMath -lTKernel
    echo "built $out" >&2
else
    echo "up to date: $out" >&2
fi
echo "$out"
