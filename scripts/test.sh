#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine, in three builds:
# 1. Release with g++ and warnings as errors: every test (including the installed-package
#    consumer, the Python bindings' pytest suite, label `python`, and with OpenMPI the MPI tests,
#    label mpi, under mpirun).
# 2. clang with AddressSanitizer + UndefinedBehaviorSanitizer (and -Werror): the unit tests and
#    the CLI tests once more (the tools are built there too), then every reader's libFuzzer target
#    for FUZZ_SECONDS seconds each (default 10; tests/fuzz/run_fuzzers.sh, docs/FUZZING.md).
# 3. clang with ThreadSanitizer: the tests of the modules that run in parallel (form factors,
#    solvers, renderers, the photon map, lightmaps, core).
# The sanitizer builds leave the heaviest physics checks (marked test::release_only in
# tests/support/build.hpp) to the Release build: lighter tests of their modules run the same
# code paths there, and the whole command stays within CI's time.
# The Python bindings are part of the first build only: Python under a sanitizer would need its
# runtime preloaded.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"
# Each phase's start in seconds since the script began, to see where the time goes. Every ctest
# run has a 600 s limit per test, so a hang fails the run instead of eating CI's time.
phase() { echo "== $1 (at ${SECONDS} s) =="; }
scripts/install-deps.sh

phase "build (Release, -Werror)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DRADIOSITY_WERROR=ON
cmake --build build -j"$jobs"
phase "tests"
ctest --test-dir build --output-on-failure --timeout 600 -j"$jobs"

phase "build (clang: ASan + UBSan, fuzz targets)"
# Without MPI: OpenMPI's own allocations and busy-waiting processes would only slow it down and
# report leaks that are not ours; the split code's single-process parts are tested there anyway.
# -g1 (line tables): the sanitizers' reports keep file and line, and the build takes about a
# quarter less time than with full debug information. clang, because libFuzzer is clang's; the
# library is compiled with coverage feedback for the fuzzers (RADIOSITY_FUZZ). The command and
# the fuzz targets at -O0 (RADIOSITY_NON_LIBRARY_FLAGS): half their compile time; the library
# keeps -O2, compiled in unity batches (RADIOSITY_UNITY_BUILD: a third less time; the Release
# build above compiles each file alone).
sanitizer_flags=(-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DRADIOSITY_WERROR=ON
  -DRADIOSITY_BUILD_EXAMPLES=OFF -DRADIOSITY_BUILD_BENCHMARKS=OFF -DRADIOSITY_PYTHON=OFF -DRADIOSITY_MPI=OFF
  -DRADIOSITY_NON_LIBRARY_FLAGS=-O0 -DRADIOSITY_UNITY_BUILD=ON)
cmake -S . -B build-sanitize "${sanitizer_flags[@]}" -DRADIOSITY_SANITIZE=ON -DRADIOSITY_FUZZ=ON -DRADIOSITY_BUILD_TOOLS=ON
cmake --build build-sanitize -j"$jobs"
phase "tests under ASan + UBSan"
# tests/lsan.supp: leaks inside Debian's Assimp on broken files (not ours), documented there.
export LSAN_OPTIONS=suppressions="$PWD/tests/lsan.supp"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --output-on-failure --timeout 600 -j"$jobs"
phase "fuzzing every reader (${FUZZ_SECONDS:-10} s each)"
tests/fuzz/run_fuzzers.sh build-sanitize "${FUZZ_SECONDS:-10}"

phase "build (clang: ThreadSanitizer, the parallel modules' tests)"
cmake -S . -B build-tsan "${sanitizer_flags[@]}" -DRADIOSITY_SANITIZE_THREAD=ON -DRADIOSITY_BUILD_TOOLS=OFF
cmake --build build-tsan -j"$jobs"
phase "tests under ThreadSanitizer"
# tests/tsan.supp: allocations inside Debian's Embree and oneTBB (not instrumented), documented there.
# atexit_sleep_ms=0: ThreadSanitizer otherwise sleeps 1 s before every process exits (to catch
# races with threads still running at exit; ours are joined or TBB's), which was 1 s of each of
# about 150 tests: a quarter of this phase's core-seconds.
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:atexit_sleep_ms=0:suppressions="$PWD/tests/tsan.supp" \
  ctest --test-dir build-tsan --output-on-failure --timeout 600 -j"$jobs"
phase "done"
