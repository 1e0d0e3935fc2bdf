#!/usr/bin/env bash
# Installs everything radiosity needs to build, test and benchmark, from Debian 12 packages.
# Idempotent: packages already present are left alone. Uses sudo when not run as root.
set -euo pipefail

packages=(
  build-essential cmake
  clang libclang-rt-14-dev
  libglm-dev doctest-dev libopenexr-dev libembree-dev libtbb-dev
  libstb-dev nlohmann-json3-dev libcli11-dev
  libnanoflann-dev libbenchmark-dev
  libtinygltf-dev libassimp-dev
  libzip-dev pkg-config
  python3-dev pybind11-dev python3-numpy python3-scipy python3-pytest
  libopenmpi-dev openmpi-bin
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
