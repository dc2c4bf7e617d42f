#!/usr/bin/env bash
# Install Debian's OCCT 7.6 development files needed by benches/occt/build.sh
# (Geom_BSplineSurface lives in TKG3d = libocct-modeling-data; TKMath and TKernel in
# libocct-foundation). About 5 MB to download, 22 MB installed. Idempotent.
set -euo pipefail

packages=(libocct-modeling-data-dev libocct-foundation-dev)
if dpkg -s "${packages[@]}" >/dev/null 2>&1; then
    echo "already installed: ${packages[*]}" >&2
    exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q "${packages[@]}"
