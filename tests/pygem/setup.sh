#!/usr/bin/env bash
# Create (or reuse) the PyGeM oracle venv at tests/pygem/.venv (numpy, scipy: PyGeM's own
# dependencies; PyGeM itself is run from a source tree, see cffd_oracle.py).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
python="${PYTHON:-python3.11}"
[ -x "$here/.venv/bin/python" ] || "$python" -m venv "$here/.venv"
"$here/.venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt" >&2
"$here/.venv/bin/python" -c 'import numpy, scipy' 
echo "$here/.venv/bin/python"
