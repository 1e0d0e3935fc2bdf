#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine: install dependencies, build with warnings as
# errors, run every test (including the installed-package consumer), then build again with
# AddressSanitizer + UndefinedBehaviorSanitizer and run the unit tests and the CLI tests once more
# (the tools are built there too: about two more minutes of compiling on two cores). The Python
# bindings (and their pytest suite, ctest label `python`) are part of the first build only: Python
# under ASan would need the sanitizer runtime preloaded. The first build has MPI when OpenMPI is
# installed (RADIOSITY_MPI): its tests (label mpi) run under mpirun.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"
# Each phase's start in seconds since the script began, to see where the time goes.
phase() { echo "== $1 (at ${SECONDS} s) =="; }
scripts/install-deps.sh

phase "build (Release, -Werror)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DRADIOSITY_WERROR=ON
cmake --build build -j"$jobs"
phase "tests"
ctest --test-dir build --output-on-failure -j"$jobs"

phase "build (ASan + UBSan)"
# Without MPI: OpenMPI's own allocations and busy-waiting processes would only slow it down and
# report leaks that are not ours; the split code's single-process parts are tested there anyway.
# -g1 (line tables): the sanitizers' reports keep file and line, and the build takes about a
# quarter less time than with full debug information.
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DRADIOSITY_WERROR=ON -DRADIOSITY_SANITIZE=ON \
  -DRADIOSITY_BUILD_TOOLS=ON -DRADIOSITY_BUILD_EXAMPLES=OFF -DRADIOSITY_BUILD_BENCHMARKS=OFF -DRADIOSITY_PYTHON=OFF \
  -DRADIOSITY_MPI=OFF
cmake --build build-sanitize -j"$jobs"
phase "tests under ASan + UBSan"
# tests/lsan.supp: leaks inside Debian's Assimp on broken files (not ours), documented there.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS=suppressions="$PWD/tests/lsan.supp" \
  ctest --test-dir build-sanitize --output-on-failure -j"$jobs"
phase "done"
