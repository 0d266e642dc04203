#!/usr/bin/env bash
# The whole test suite: host build with every unit, integration and peer (python-can,
# canmatrix, OpenCV) test; the unit, pipeline and firmware tests again under AddressSanitizer with
# UndefinedBehaviorSanitizer and under ThreadSanitizer; clang-tidy; the libFuzzer targets
# replaying and extending their corpora; and the aarch64 board build, cross-compiled, with its
# tests run under qemu-aarch64. Prints how long each part took.
#
#   tools/test-all.sh            everything (installs its own dependencies)
#   tools/test-all.sh --no-cross skip the aarch64 part
#   STEREOHASH_TIDY_BASE=REV     clang-tidy on the sources changed since REV (default HEAD~10, the
#                                latest landings; "all": every source)
#   STEREOHASH_TIDY_STRICT=0|1   clang-tidy findings fail the run (default 1 on the changed sources;
#                                0, report only, when every source is checked)
#   STEREOHASH_CI_BUDGET_S=S     time budget (default 4500): a sanitizer part starts only while
#                                the time it takes is left (ASan+UBSan 25 minutes, TSan 20)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

cross=1
[ "${1:-}" = "--no-cross" ] && cross=0
jobs=$(nproc)

if [ "$cross" = 1 ]; then tools/ci/install-deps.sh --cross; else tools/ci/install-deps.sh; fi

run_start=$(date +%s)
durations=()
part=""
part_start=$(date +%s)
section() {
  local now
  now=$(date +%s)
  [ -n "$part" ] && durations+=("$(printf '%-28s %5d s' "$part" $((now - part_start)))")
  part=$1
  part_start=$now
  printf '\n==== %s (%s)\n' "$1" "$(date -u +%H:%M:%S)"
}

section "host build"
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j "$jobs"

section "host tests"
ctest --preset host-release -j "$jobs" --timeout 900

section "clang-tidy"
tidy_base=${STEREOHASH_TIDY_BASE:-HEAD~10}
[ "$tidy_base" = all ] && tidy_base=""
git rev-parse --verify -q "${tidy_base:-HEAD}" >/dev/null || tidy_base=""
strict_default=1
[ -z "$tidy_base" ] && strict_default=0
STEREOHASH_TIDY_STRICT=${STEREOHASH_TIDY_STRICT:-$strict_default} \
  tools/ci/clang-tidy.sh build/host-release $tidy_base

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
# The sanitizer builds run the gtest suites: ASan+UBSan every one (label unit: unit, pipeline and
# firmware tests), TSan those that run threads (label ...-threads: the worker pool, the firmware's
# loops, the simulated bus and cameras). Each builds only the test programs it runs (aggregate
# targets in tests/CMakeLists.txt). They come last, each only while the run stays inside its time
# budget (75 minutes; CI allows 90).
budget_s=${STEREOHASH_CI_BUDGET_S:-4500}
# sanitized PRESET NAME TARGET RESERVE_S: starts only while RESERVE_S (the part's time on a loaded
# 2-core machine, build from cold and tests, with a margin) of the budget are left.
sanitized() {
  local elapsed=$(($(date +%s) - run_start))
  if [ "$elapsed" -gt $((budget_s - $4)) ]; then
    printf '\n==== %s skipped: %d s of the %d s budget used\n' "$2" "$elapsed" "$budget_s"
    durations+=("$(printf '%-28s %5s' "$2" skipped)")
    return
  fi
  section "$2 build"
  cmake --preset "$1" >/dev/null
  cmake --build --preset "$1" -j "$jobs" --target "$3"
  section "$2 tests"
  ctest --preset "$1" -j "$jobs" --timeout 1800
}
sanitized host-asan "ASan+UBSan" stereohash_unit_tests 1500
sanitized host-tsan "TSan" stereohash_threaded_tests 1200

section "done"
printf '%s\n' "${durations[@]}"
