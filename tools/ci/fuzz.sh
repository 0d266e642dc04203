#!/usr/bin/env bash
# Builds the libFuzzer targets (preset fuzz: clang, ASan+UBSan) and runs each on a copy of its
# committed corpus under tests/fuzz/corpus/<name>/: the whole corpus is replayed first, then the
# target mutates it for SECONDS. As many targets run at once as there are cores. Fails if a target
# is missing or finds a crash, a leak or undefined behaviour (its output is printed in full then).
#
#   tools/ci/fuzz.sh [SECONDS]    default 10
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-10}
jobs=$(nproc)

cmake --preset fuzz >/dev/null
targets=()
for corpus in tests/fuzz/corpus/*/; do targets+=("$(basename "$corpus")_fuzz"); done
cmake --build --preset fuzz -j "$jobs" --target "${targets[@]}"

logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
# fuzz_one NAME: one target on a scratch copy of its corpus; its output goes to $logs/NAME.log.
fuzz_one() {
  local name=$1 target=build/fuzz/tests/fuzz/$1_fuzz work
  [ -x "$target" ] || { echo "no fuzz target for corpus $name" >"$logs/$name.log"; return 1; }
  work=$(mktemp -d)
  cp -r "tests/fuzz/corpus/$name/." "$work"/
  "$target" -max_total_time="$seconds" -print_final_stats=1 "$work" >"$logs/$name.log" 2>&1
  local status=$?
  rm -rf "$work"
  return $status
}
export -f fuzz_one
export seconds logs

printf '%s\n' tests/fuzz/corpus/*/ | xargs -n 1 basename |
  xargs -P "$jobs" -I{} bash -c 'if fuzz_one {}; then echo "fuzzed {} for ${seconds}s: $(grep -h "stat::number_of_executed_units" "$logs/{}.log" | tr -s " " | cut -d" " -f2) runs"; else echo "FAILED {}"; fi' |
  tee "$logs/summary"
if grep -q '^FAILED' "$logs/summary"; then
  for name in $(grep '^FAILED' "$logs/summary" | cut -d' ' -f2); do
    printf '\n---- %s\n' "$name"
    cat "$logs/$name.log"
  done
  exit 1
fi
