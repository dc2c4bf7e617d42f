#!/usr/bin/env bash
# Create (or reuse) the OCCT oracle venv at tests/occt/.venv.
#
#   bash tests/occt/setup.sh          # from anywhere; idempotent
#   PYTHON=python3.11 bash tests/occt/setup.sh
#
# Installs the pinned packages of requirements.txt beside this script, then checks that
# OCCT loads (`from OCP.IGESControl import IGESControl_Reader`). Exits non-zero if it does not.
# A second run does nothing when the venv already holds exactly these pins.
# Prints the venv's python on the last line, so callers can do  PY=$(bash setup.sh | tail -1).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
req="$here/requirements.txt"
stamp="$venv/.cadmorph-requirements"
python="${PYTHON:-python3.11}"

probe() {
    "$venv/bin/python" -c 'from OCP.IGESControl import IGESControl_Reader; import numpy' 2>&1
}

if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && cmp -s "$req" "$stamp" && probe >/dev/null; then
    echo "occt venv up to date: $venv" >&2
else
    start=$(date +%s)
    if [ ! -x "$venv/bin/python" ]; then
        echo "creating venv $venv with $python" >&2
        "$python" -m venv "$venv"
    fi
    echo "installing $(grep -v '^#' "$req" | tr '\n' ' ')" >&2
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req" >&2
    if ! err=$(probe); then
        echo "error: OCCT does not load in $venv:" >&2
        echo "$err" >&2
        exit 1
    fi
    cp "$req" "$stamp"
    echo "occt venv ready in $(( $(date +%s) - start )) s: $venv" >&2
fi
echo "$venv/bin/python"
