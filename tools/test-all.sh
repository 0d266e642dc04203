#!/usr/bin/env bash
# The whole test suite: host build with every unit, integration and peer (python-can,
# canmatrix, OpenCV) test; the libFuzzer targets replaying and extending their corpora; and the
# aarch64 board build, cross-compiled, with its tests run under qemu-aarch64.
#
#   tools/test-all.sh            everything (installs its own dependencies)
#   tools/test-all.sh --no-cross skip the aarch64 part
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

cross=1
[ "${1:-}" = "--no-cross" ] && cross=0
jobs=$(nproc)

if [ "$cross" = 1 ]; then tools/ci/install-deps.sh --cross; else tools/ci/install-deps.sh; fi

section() { printf '\n==== %s (%s)\n' "$1" "$(date -u +%H:%M:%S)"; }

section "host build"
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j "$jobs"

section "host tests"
ctest --preset host-release -j "$jobs" --timeout 900

section "fuzzers"
cmake --preset fuzz >/dev/null
targets=()
for corpus in tests/fuzz/corpus/*/; do targets+=("$(basename "$corpus")_fuzz"); done
cmake --build --preset fuzz -j "$jobs" --target "${targets[@]}"
fuzz_seconds=${STEREOHASH_FUZZ_SECONDS:-20}
for corpus in tests/fuzz/corpus/*/; do
  name=$(basename "$corpus")
  target=build/fuzz/tests/fuzz/${name}_fuzz
  [ -x "$target" ] || { echo "no fuzz target for corpus $name" >&2; exit 1; }
  work=$(mktemp -d)
  cp -r "$corpus". "$work"/
  echo "fuzzing $name for ${fuzz_seconds}s"
  "$target" -max_total_time="$fuzz_seconds" -print_final_stats=1 "$work" 2>&1 | tail -n 3
  rm -rf "$work"
done

if [ "$cross" = 1 ]; then
  section "aarch64 build"
  cmake --preset aarch64-release >/dev/null
  cmake --build --preset aarch64-release -j "$jobs"
  section "aarch64 tests under qemu"
  ctest --preset aarch64-release -j "$jobs" --timeout 1800 -LE host_only
  section "aarch64 sizes"
  for f in build/aarch64-release/firmware/stereohash-fw build/aarch64-release/tables/reference_hf5.bin; do
    [ -f "$f" ] && ls -l "$f"
  done
  [ -f build/aarch64-release/firmware/stereohash-fw ] && aarch64-linux-gnu-size build/aarch64-release/firmware/stereohash-fw
fi
section "done"
