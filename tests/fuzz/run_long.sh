#!/usr/bin/env bash
# A long fuzz run of one reader (docs/FUZZING.md, "Long runs"), in runs of a million inputs.
#
#   tests/fuzz/run_long.sh BUILD_DIR FORMAT MILLIONS [FIRST]
#
# BUILD_DIR as for run_fuzzers.sh (which must have run once, for the seeds and the corpus).
# Runs chunks FIRST .. FIRST + MILLIONS - 1 (FIRST defaults to 1), each a million executions
# with its own -seed, on the corpus of the earlier runs, at the lowest priority (nice 19), and
# appends one line per chunk to BUILD_DIR/fuzz/long/FORMAT.summary (exit code, executions,
# time); logs are in BUILD_DIR/fuzz/long/FORMAT.CHUNK.log. Stops at the first finding: the
# input is in BUILD_DIR/fuzz/artifacts/FORMAT/.
# Why chunks: the targets of Assimp's formats run without a leak check per input (13 times
# faster), and Assimp's leaks on broken files (suppressed: tests/lsan.supp) then pile up to
# libFuzzer's 2 GB RSS limit after about a million inputs (FBX: after 272 034 in session 23;
# FUZZ_CHUNK=200000 runs chunks of that many inputs instead of a million). FUZZ_TIMEOUT=30 gives
# each input 30 s instead of 10: OpenEXR takes 3-4 s under AddressSanitizer on some broken
# headers (session 29), which a 2-thread load beside it stretches past 10 s.
# Do not pause a run (SIGSTOP): libFuzzer's timeout is wall-clock, so the input being run when
# it resumes is reported as a timeout. Stop it with SIGINT and start again from the next chunk.
set -u
build="$(cd "$1" && pwd)"
format="$2"
millions="$3"
first="${4:-1}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
source "$root/tests/fuzz/fuzz_env.sh"
leaks="$(fuzz_detect_leaks "$format")"
work="$build/fuzz"
chunk="${FUZZ_CHUNK:-1000000}"
mkdir -p "$work/long" "$work/artifacts/$format" "$work/corpus/$format"
for ((k = first; k < first + millions; ++k)); do
  log="$work/long/$format.$k.log"
  nice -n 19 "$build/bin/radiosity_fuzz_$format" -seed=$((100 + k)) -runs="$chunk" -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb=2048 \
    -print_final_stats=1 -detect_leaks="$leaks" -artifact_prefix="$work/artifacts/$format/" \
    "$work/corpus/$format" "$work/seeds/$format" > "$log" 2>&1
  rc=$?
  echo "$format chunk $k rc $rc $(grep -h 'number_of_executed_units' "$log" | head -1) $(date +%T)" >> "$work/long/$format.summary"
  # A chunk that ran all its inputs can still end on the RSS limit as libFuzzer exits, from
  # Assimp's leaks piled up over the chunk (the "input" it then writes is empty): not a finding.
  if [ "$rc" -ne 0 ] && grep -q "^Done $chunk runs" "$log"; then
    rm -f "$work/artifacts/$format/oom-da39a3ee5e6b4b0d3255bfef95601890afd80709"  # the empty input
    continue
  fi
  if [ "$rc" -ne 0 ]; then
    echo "run_long: $format chunk $k stopped (exit $rc): see $log and $work/artifacts/$format/" >&2
    exit 1
  fi
done
