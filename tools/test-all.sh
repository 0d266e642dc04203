#!/usr/bin/env bash
# The whole test suite: the host release build with its end-to-end and peer tests (python-can,
# canmatrix, node-canopen, OpenCV, Chromium and Firefox); clang-tidy; every unit, pipeline and
# firmware test under AddressSanitizer with UndefinedBehaviorSanitizer, and every test that runs
# threads under ThreadSanitizer; the libFuzzer targets replaying and extending their committed
# corpora; the aarch64 board build, cross-compiled, with its tests run under qemu-aarch64. Every
# stage runs; none is skipped for time. Prints how long each stage took.
#
#   tools/test-all.sh             everything (installs its own dependencies)
#   tools/test-all.sh --quick     the everyday loop: incremental host release build and every
#                                 test in it, the unit tests included
#   tools/test-all.sh --no-cross  everything but the aarch64 stages
#   STEREOHASH_TIDY_BASE=REV      clang-tidy on the sources changed since REV (default HEAD~10, the
#                                 latest landings; "all": every source)
#   STEREOHASH_TIDY_STRICT=0|1    clang-tidy findings fail the run (default 1 on the changed
#                                 sources; 0, report only, when every source is checked)
#   STEREOHASH_FUZZ_SECONDS=S     how long each fuzz target extends its corpus (default 5; the
#                                 committed corpus is replayed in full first)
#   STEREOHASH_GUARD_S=S          the run fails, naming the stage it was in, once the whole run has
#                                 passed S seconds (default 4200, 70 minutes; CI allows 90)
set -euo pipefail
cd "$(dirname "$0")/.."

mode=all
case "${1:-}" in
  "") ;;
  --quick) mode=quick ;;
  --no-cross) mode=no-cross ;;
  *) echo "usage: tools/test-all.sh [--quick | --no-cross]" >&2; exit 2 ;;
esac
jobs=$(nproc)

if [ "$mode" = all ]; then tools/ci/install-deps.sh --cross; else tools/ci/install-deps.sh; fi

run_start=$(date +%s)
guard_s=${STEREOHASH_GUARD_S:-4200}
durations=()
over_guard=""
stage=""
stage_start=$run_start
# stage NAME: closes the stage before (its time goes into the table) and opens NAME.
stage() {
  local now
  now=$(date +%s)
  if [ -n "$stage" ]; then
    durations+=("$(printf '%-30s %6d s' "$stage" $((now - stage_start)))")
    if [ -z "$over_guard" ] && [ $((now - run_start)) -gt "$guard_s" ]; then over_guard=$stage; fi
  fi
  stage=$1
  stage_start=$now
  [ "$1" = done ] || printf '\n==== %s (%s)\n' "$1" "$(date -u +%H:%M:%S)"
}
finish() {
  stage done
  printf '\n==== stage times\n'
  printf '%s\n' "${durations[@]}"
  local total=$(($(date +%s) - run_start))
  printf '%-30s %6d s\n' total "$total"
  if [ -n "$over_guard" ]; then
    printf '\nFAILED: the run took %d s, over its %d s guard (STEREOHASH_GUARD_S); it passed the guard in the stage "%s". Find what grew in the table above.\n' \
      "$total" "$guard_s" "$over_guard" >&2
    exit 1
  fi
}

# The quick loop builds and runs every test in the release configuration. The full run builds the
# GoogleTest programs labelled unit in the configurations that check more than the release one
# can: ASan+UBSan (every one), TSan (those that run threads) and the board build under qemu; its
# release build is the programs, tools and benchmarks with the end-to-end tests that drive them
# (python-can, node-canopen, the browsers, the tool tests labelled host_only).
unit_in_release=OFF
[ "$mode" = quick ] && unit_in_release=ON
stage "host build"
cmake --preset host-release -DSTEREOHASH_UNIT_TESTS=$unit_in_release >/dev/null
cmake --build --preset host-release -j "$jobs"

stage "host tests"
ctest --preset host-release -j "$jobs" --timeout 900

if [ "$mode" = quick ]; then
  finish
  exit 0
fi

stage "clang-tidy"
tidy_base=${STEREOHASH_TIDY_BASE:-HEAD~10}
[ "$tidy_base" = all ] && tidy_base=""
git rev-parse --verify -q "${tidy_base:-HEAD}" >/dev/null || tidy_base=""
strict_default=1
[ -z "$tidy_base" ] && strict_default=0
STEREOHASH_TIDY_STRICT=${STEREOHASH_TIDY_STRICT:-$strict_default} \
  tools/ci/clang-tidy.sh build/host-release $tidy_base

# The sanitizer builds run the gtest suites: ASan+UBSan every one (label unit: unit, pipeline and
# firmware tests), TSan those that run threads (label ...-threads; the host build's thread guard
# fails a test that starts a thread without that mark). Each builds only the test programs it
# runs (aggregate targets in tests/CMakeLists.txt). They come right after the host stages, so
# that a race or a memory error shows early in a long run.
stage "TSan build"
cmake --preset host-tsan >/dev/null
cmake --build --preset host-tsan -j "$jobs" --target stereohash_threaded_tests
stage "TSan tests"
ctest --preset host-tsan -j "$jobs" --timeout 1800

stage "ASan+UBSan build"
cmake --preset host-asan >/dev/null
cmake --build --preset host-asan -j "$jobs" --target stereohash_unit_tests
stage "ASan+UBSan tests"
ctest --preset host-asan -j "$jobs" --timeout 1800

stage "fuzzers"
tools/ci/fuzz.sh "${STEREOHASH_FUZZ_SECONDS:-5}"

if [ "$mode" = all ]; then
  stage "aarch64 build"
  cmake --preset aarch64-release >/dev/null
  cmake --build --preset aarch64-release -j "$jobs"
  stage "aarch64 tests under qemu"
  ctest --preset aarch64-release -j "$jobs" --timeout 1800 -LE host_only
  stage "aarch64 sizes"
  for f in build/aarch64-release/firmware/stereohash-fw build/aarch64-release/tables/reference_hf5.bin; do
    [ -f "$f" ] && ls -l "$f"
  done
  [ -f build/aarch64-release/firmware/stereohash-fw ] && aarch64-linux-gnu-size build/aarch64-release/firmware/stereohash-fw
fi

finish
