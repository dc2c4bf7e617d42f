#!/usr/bin/env bash
# Bench venv for running BladeX side by side with cadmorph (benches/blade/README.md).
#
#   bash benches/blade/setup.sh     # idempotent
#
# 1. the OCCT venv (tests/occt/setup.sh) provides OCP (OpenCASCADE 7.9.3) and numpy;
# 2. this venv sees its packages (a .pth file) and adds what BladeX imports besides
#    OCC: scipy and matplotlib (pinned below);
# 3. BladeX itself is the checkout at $BLADEX (default: a git archive of mathLab/BladeX
#    0c84eab extracted to benches/blade/.bladex), imported through occ_shim/, which maps
#    pythonocc's `OCC.Core.X` modules onto OCP's `OCP.X`.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$here/../.."
bash "$root/tests/occt/setup.sh" >/dev/null
venv="$here/.venv"
python="${PYTHON:-python3.11}"
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
occt_site=$("$root/tests/occt/.venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
echo "$occt_site" > "$site/cadmorph-occt.pth"
echo "$here/occ_shim" > "$site/cadmorph-occ-shim.pth"
if ! "$venv/bin/python" -c 'import scipy, matplotlib' 2>/dev/null; then
    "$venv/bin/pip" install --quiet scipy==1.15.3 matplotlib==3.10.3
fi
"$venv/bin/python" -c 'import OCP, scipy, matplotlib, numpy' >&2
echo "$venv/bin/python"
