#!/usr/bin/env bash
# Runs every reader's libFuzzer target (tests/fuzz/fuzz_reader.cpp) for a bounded time.
#
#   tests/fuzz/run_fuzzers.sh BUILD_DIR [SECONDS_PER_TARGET] [FORMAT...]
#
# BUILD_DIR was configured with clang, -DRADIOSITY_FUZZ=ON and (for memory errors and undefined
# behaviour) -DRADIOSITY_SANITIZE=ON. Each target starts from seeds made of the test files
# (tests/data, examples/scenes; an OBJ and its MTL library as one input) and from the regression
# files of earlier findings (tests/data/fuzz/<format>/), and keeps what it finds in
# BUILD_DIR/fuzz/corpus/<format>, so a second run goes on where the first stopped. A crash,
# sanitizer report, leak, input slower than 10 s or allocation over 2 GiB stops the run: the
# input is left in BUILD_DIR/fuzz/artifacts/<format>/ and the script fails. Add it to
# tests/data/fuzz/<format>/ with the fix; the test suite reads every file there.
# Prints each target's executions and coverage (docs/FUZZING.md has the longer runs). Runs as
# many targets at a time as there are cores (FUZZ_JOBS to change it).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="$(cd "$1" && pwd)"
seconds="${2:-30}"
shift $(( $# >= 2 ? 2 : 1 ))
formats=("$@")
if [ ${#formats[@]} -eq 0 ]; then formats=(obj json gltf glb vs3 ply stl dae fbx 3ds exr merl); fi

work="$build/fuzz"
mkdir -p "$work"

# seeds FORMAT: fills $work/seeds/FORMAT from the repository's files of that format.
seeds() {
  local format="$1" dir="$work/seeds/$1"
  rm -rf "$dir" && mkdir -p "$dir"
  case "$format" in
    obj)
      local obj mtl name
      for obj in "$root"/tests/data/*.obj "$root"/tests/data/messy/*.obj "$root"/examples/scenes/*.obj; do
        cp "$obj" "$dir/"
        # The same OBJ with its first MTL library appended after the separator the target splits at.
        name="$(sed -n 's/^mtllib[[:space:]]\+\([^[:space:]]*\).*/\1/p' "$obj" | head -n 1 | tr -d '\r')"
        mtl="$(dirname "$obj")/$name"
        if [ -n "$name" ] && [ -f "$mtl" ]; then
          { sed 's/^mtllib[[:space:]].*/mtllib fuzz.mtl/' "$obj"; printf '\n#%%%%MTL%%%%\n'; cat "$mtl"; } \
            > "$dir/with_mtl_$(basename "$obj")"
        fi
      done ;;
    json) cp "$root"/examples/scenes/*.json "$dir/" ;;
    gltf) cp "$root"/tests/data/gltf/*.gltf "$dir/" ;;
    glb) cp "$root"/tests/data/gltf/*.glb "$dir/" ;;
    vs3) cp "$root"/tests/data/view3d/*.vs3 "$dir/" ;;
    ply) cp "$root"/tests/data/*.ply "$dir/" ;;
    stl) cp "$root"/tests/data/*.stl "$dir/" ;;
    # A room as Assimp's exporters write it (tests/data/assimp), for Assimp's other readers.
    dae | fbx | 3ds) cp "$root"/tests/data/assimp/*."$format" "$dir/" ;;
    exr) cp "$root"/tests/data/*.exr "$dir/" ;;
    merl)
      # A MERL header (90 x 90 x 180) and the first values: the real files are 33 MB.
      python3 -c 'import struct,sys; sys.stdout.buffer.write(struct.pack("<3i", 90, 90, 180) + struct.pack("<64d", *([0.5] * 64)))' \
        > "$dir/header.binary"
      python3 -c 'import struct,sys; sys.stdout.buffer.write(struct.pack("<3i", 90, 90, 180))' > "$dir/short.binary" ;;
    *) echo "run_fuzzers: unknown format '$format'" >&2; exit 2 ;;
  esac
  if [ -d "$root/tests/data/fuzz/$format" ]; then cp "$root/tests/data/fuzz/$format"/* "$dir/" 2>/dev/null || true; fi
}

source "$root/tests/fuzz/fuzz_env.sh"

# fuzz_one FORMAT: one target's run; prints its figures, returns 1 on a finding.
fuzz_one() {
  local format="$1" exe="$build/bin/radiosity_fuzz_$1" log="$work/$1.log" leaks
  leaks="$(fuzz_detect_leaks "$format")"
  mkdir -p "$work/corpus/$format" "$work/artifacts/$format"
  # -seed fixed: the same mutations each run on the same corpus.
  if "$exe" -seed=1 -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -detect_leaks="$leaks" \
      -artifact_prefix="$work/artifacts/$format/" "$work/corpus/$format" "$work/seeds/$format" > "$log" 2>&1; then
    local runs cov
    runs="$(sed -n 's/^stat::number_of_executed_units:[[:space:]]*//p' "$log")"
    cov="$(grep -o 'cov: [0-9]*' "$log" | tail -n 1)"
    echo "fuzz $format: ${runs:-?} executions in ${seconds} s, ${cov:-cov: ?} edges, $(ls "$work/corpus/$format" | wc -l) corpus files, no finding"
  else
    echo "fuzz $format: FOUND A PROBLEM (the input is in $work/artifacts/$format/):" >&2
    grep -E 'ERROR|SUMMARY|terminate|what\(\)|fuzz_reader:|Test unit written' "$log" | head -n 20 >&2 || tail -n 40 "$log" >&2
    return 1
  fi
}

for format in "${formats[@]}"; do
  [ -x "$build/bin/radiosity_fuzz_$format" ] || { echo "run_fuzzers: $build/bin/radiosity_fuzz_$format not built (configure with -DRADIOSITY_FUZZ=ON)" >&2; exit 2; }
  seeds "$format"
done
# One target per core at a time (each is one process), so the figures are per core.
jobs="${FUZZ_JOBS:-$(nproc)}"
status=0
running=0
for format in "${formats[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  fuzz_one "$format" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || status=1
  running=$((running - 1))
done
exit "$status"
