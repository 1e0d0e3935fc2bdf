#!/usr/bin/env bash
# Reads every file of a fuzz corpus under valgrind's memcheck (docs/FUZZING.md, "valgrind sweep").
#
#   tests/fuzz/valgrind_sweep.sh BUILD_DIR FOLDER EXTENSION
#
# BUILD_DIR: a build with the tests (its bin/radiosity_read_files; Release, not a sanitizer
# build). FOLDER: the files, e.g. a fuzz build's fuzz/corpus/ply, whose names have no
# extension: each is read as FOLDER/NAME.EXTENSION (copied to a temporary folder). Prints
# valgrind's reports, if any, and exits 1 when there are some.
set -u
build="$(cd "$1" && pwd)"
folder="$2"
extension="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for f in "$folder"/*; do
  [ -f "$f" ] || continue
  name="$(basename "$f")"
  case "$name" in *."$extension") cp "$f" "$work/$name" ;; *) cp "$f" "$work/$name.$extension" ;; esac
done
valgrind -q --error-limit=no --error-exitcode=9 "$build/bin/radiosity_read_files" "$work"/* 2> "$work.log"
rc=$?
reports="$(grep -v '^FILE ' "$work.log")"
rm -f "$work.log"
if [ -n "$reports" ] || [ "$rc" -ne 0 ]; then
  printf '%s\n' "$reports"
  echo "valgrind_sweep: reports above (exit $rc)"
  exit 1
fi
echo "valgrind_sweep: $(ls "$work" | wc -l) files, no report"
