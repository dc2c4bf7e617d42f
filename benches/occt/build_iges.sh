#!/usr/bin/env bash
# Build the OCCT side of the IGES benchmark into benches/occt/build/ (git-ignored).
#
#   bash benches/occt/install.sh        # once: Debian's OCCT 7.6 headers and libraries
#   bash benches/occt/build_iges.sh     # prints the binary's path on its last line
#   benches/occt/build/iges_occt [--repeat N] FILE...
#
# OCCT_INCLUDE (default /usr/include/opencascade) and CXX (default g++) can be overridden.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
include="${OCCT_INCLUDE:-/usr/include/opencascade}"
cxx="${CXX:-g++}"
out="$here/build/iges_occt"

if [ ! -f "$include/IGESControl_Reader.hxx" ]; then
    echo "error: OCCT headers not found in $include; run benches/occt/install.sh" >&2
    exit 1
fi
mkdir -p "$here/build"
if [ ! -x "$out" ] || [ "$here/iges_occt.cpp" -nt "$out" ] || [ "$0" -nt "$out" ]; then
    "$cxx" -O2 -std=c++17 -Wall -Wextra -isystem "$include" "$here/iges_occt.cpp" -o "$out" \
        -lTKIGES -lTKXSBase -lTKShHealing -lTKTopAlgo -lTKGeomAlgo -lTKBRep -lTKGeomBase -lTKG3d -lTKG2d \
        -lTKMath -lTKernel
    echo "built $out" >&2
else
    echo "up to date: $out" >&2
fi
echo "$out"
