#!/usr/bin/env bash
# Set up (or reuse) the tools of the cadmorph-report browser and glTF tests; idempotent.
#
#   bash tests/report/setup.sh
#
# 1. Debian's `chromium` (headless, driven by playwright-core through its
#    executablePath: playwright's own browser download is not used). Installed with
#    apt-get when /usr/bin/chromium is missing; apt is retried while another process
#    holds the dpkg lock.
# 2. node_modules here (git-ignored) with the pins of package.json: playwright-core and
#    the Khronos glTF validator (gltf-validator), reinstalled when package.json changes.
#
# The tests find the tools at tests/report/node_modules and /usr/bin/chromium.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
start=$(date +%s)
if ! [ -x /usr/bin/chromium ]; then
    echo "installing Debian chromium" >&2
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo=sudo
    if ! apt-cache policy chromium 2>/dev/null | grep -q 'Candidate: [0-9]'; then
        $sudo apt-get update -q >&2 || true
    fi
    for attempt in $(seq 1 60); do
        if $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >&2; then
            break
        fi
        echo "apt-get failed (dpkg lock held?), retry $attempt in 10 s" >&2
        sleep 10
    done
    [ -x /usr/bin/chromium ] || { echo "error: /usr/bin/chromium missing after install" >&2; exit 1; }
fi
command -v node >/dev/null || { echo "error: node (Node.js) is needed for the report tests" >&2; exit 1; }
stamp="$here/node_modules/.cadmorph-package.json"
probe() {
    (cd "$here" && node -e 'require("playwright-core"); require("gltf-validator")') 2>&1
}
if [ -f "$stamp" ] && cmp -s "$here/package.json" "$stamp" && probe >/dev/null; then
    echo "report tools up to date: $here/node_modules" >&2
else
    (cd "$here" && npm install --no-audit --no-fund --no-save --loglevel=error >&2)
    if ! err=$(probe); then
        echo "error: playwright-core/gltf-validator do not load:" >&2
        echo "$err" >&2
        exit 1
    fi
    cp "$here/package.json" "$stamp"
fi
echo "report tools ready in $(( $(date +%s) - start )) s" >&2
