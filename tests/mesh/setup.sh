#!/usr/bin/env bash
# Set up (or reuse) the oracles of the cadmorph-mesh tests; idempotent.
#
#   bash tests/mesh/setup.sh
#
# 1. Debian's `openfoam` package (v1912 in bookworm): blockMesh and checkMesh. Installed
#    with apt-get when `/usr/share/openfoam/etc/bashrc` is missing; apt is
#    retried while another process holds the dpkg lock.
# 2. A venv at tests/mesh/.venv with the pins of requirements.txt (meshio, gmsh; pyarrow
#    for the campaign table) and, without their declared dependencies, those of
#    requirements-nodeps.txt (PyDyna's LS-DYNA keyword reader).
#
# Prints the venv's python on the last line (PY=$(bash setup.sh | tail -1)). The OpenFOAM
# environment is sourced by the tests themselves from the bashrc above.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
req="$here/requirements.txt"
req_nodeps="$here/requirements-nodeps.txt"
stamp="$venv/.cadmorph-requirements"
python="${PYTHON:-python3.11}"
foam_bashrc=/usr/share/openfoam/etc/bashrc

start=$(date +%s)
if [ ! -f "$foam_bashrc" ] || ! command -v checkMesh >/dev/null; then
    echo "installing Debian openfoam (blockMesh, checkMesh)" >&2
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo=sudo
    # A new machine may have no package lists yet: read them once when apt knows no
    # openfoam candidate.
    if ! apt-cache policy openfoam 2>/dev/null | grep -q 'Candidate: [0-9]'; then
        $sudo apt-get update -q >&2 || true
    fi
    for attempt in $(seq 1 60); do
        if $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q openfoam >&2; then
            break
        fi
        echo "apt-get failed (dpkg lock held?), retry $attempt in 10 s" >&2
        sleep 10
    done
    [ -f "$foam_bashrc" ] || { echo "error: $foam_bashrc missing after install" >&2; exit 1; }
fi

probe() {
    "$venv/bin/python" -c 'import meshio, gmsh, numpy, pyarrow.parquet; from ansys.dyna.core import Deck' 2>&1
}
if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && cat "$req" "$req_nodeps" | cmp -s - "$stamp" && probe >/dev/null; then
    echo "mesh venv up to date: $venv" >&2
else
    if [ ! -x "$venv/bin/python" ]; then
        echo "creating venv $venv with $python" >&2
        "$python" -m venv "$venv"
    fi
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req" >&2
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps -r "$req_nodeps" >&2
    if ! err=$(probe); then
        echo "error: meshio/gmsh/pyarrow/PyDyna do not load in $venv:" >&2
        echo "$err" >&2
        exit 1
    fi
    cat "$req" "$req_nodeps" > "$stamp"
fi
echo "mesh oracles ready in $(( $(date +%s) - start )) s" >&2
echo "$venv/bin/python"
