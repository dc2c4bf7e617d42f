#!/usr/bin/env bash
# Create (or reuse) the Python package's test venv at tests/py/.venv and install the
# package from this checkout into it with `pip install .`, as a user of a clone would.
#
#   bash tests/py/setup.sh           # from anywhere; idempotent
#   PYTHON=python3.12 bash tests/py/setup.sh
#   CADMORPH_PY_PROFILE=release bash tests/py/setup.sh   # the optimised build (slower to make)
#
# The venv holds only tests/py/requirements.txt (maturin, numpy, pytest; installed once,
# again when the pins change). The package is built by pip through the maturin backend of
# the root pyproject.toml, in cargo's `dev` profile by default (the test suite checks
# numbers, not speed; a release build of the extension takes minutes on 2 cores), into the
# workspace's target directory, so it reuses what `cargo test --workspace` compiled and a
# second run only reinstalls. Prints the venv's python on the last line:
#   PY=$(bash tests/py/setup.sh | tail -1)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="$here/.venv"
req="$here/requirements.txt"
stamp="$venv/.cadmorph-requirements"
python="${PYTHON:-python3.11}"
profile="${CADMORPH_PY_PROFILE:-dev}"

start=$(date +%s)
if [ ! -x "$venv/bin/python" ]; then
    echo "creating venv $venv with $python" >&2
    "$python" -m venv "$venv"
fi
if ! { [ -f "$stamp" ] && cmp -s "$req" "$stamp"; }; then
    echo "installing $(grep -v '^#' "$req" | tr '\n' ' ')" >&2
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req" >&2
    cp "$req" "$stamp"
fi
# No build isolation: the venv already has the backend's tool (maturin) pinned above, and
# the build must not fetch another copy on every run.
echo "pip install . (cargo profile $profile)" >&2
(cd "$root" && PATH="$venv/bin:$PATH" "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-build-isolation \
    --config-settings=build-args="--profile $profile" . >&2)
"$venv/bin/python" -c 'import cadmorph, numpy; assert cadmorph.num_threads() >= 1' >&2
echo "python package ready in $(( $(date +%s) - start )) s: $venv" >&2
echo "$venv/bin/python"
