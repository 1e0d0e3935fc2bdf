# Sourced by run_fuzzers.sh and run_long.sh: the sanitizers' settings and which targets check
# leaks per input, in one place. Expects $root (the repository) to be set.

# Defaults only: a caller's own settings win.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# tests/lsan.supp: leaks inside Debian's Assimp on broken files (not ours), documented there.
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$root/tests/lsan.supp}"

# fuzz_detect_leaks FORMAT: prints libFuzzer's -detect_leaks value for the target.
# Assimp leaks on most broken files (suppressed), and libFuzzer then scans the heap after every
# such input: the FBX target ran 13 times slower. For Assimp's formats leaks are checked once,
# when the target exits (AddressSanitizer's own check).
fuzz_detect_leaks() {
  case "$1" in
    ply | stl | dae | fbx | 3ds) echo 0 ;;
    *) echo 1 ;;
  esac
}
