#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install dependencies, build (Release), then solve and
# render the built-in Cornell box to out/cornell.exr (linear HDR) and out/cornell.png (preview).
# Extra arguments go to `radiosity render`, e.g. scripts/run.sh --method progressive --spp 16.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
mkdir -p out
build/bin/radiosity render -o out/cornell.exr --png out/cornell.png "$@"
