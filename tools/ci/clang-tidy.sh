#!/usr/bin/env bash
# clang-tidy with the project's .clang-tidy on the C++ sources of a configured build (headers are
# checked through the sources that include them). Prints every finding and how many files had
# one; with STEREOHASH_TIDY_STRICT=1 any finding fails the run.
#
#   tools/ci/clang-tidy.sh BUILD_DIR            every source in BUILD_DIR/compile_commands.json
#   tools/ci/clang-tidy.sh BUILD_DIR REVISION   only the sources changed since REVISION (git)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:?usage: tools/ci/clang-tidy.sh BUILD_DIR [REVISION]}
base=${2:-}
tidy=$(command -v clang-tidy-14 || command -v clang-tidy)
jobs=$(nproc)

# Sources the build compiles (generated and third-party files are not in the repository).
mapfile -t compiled < <(python3 -c '
import json, os, sys
root = os.getcwd()
for e in json.load(open(sys.argv[1])):
    f = os.path.normpath(os.path.join(e["directory"], e["file"]))
    if f.startswith(root + "/") and f.endswith(".cpp"):
        print(os.path.relpath(f, root))
' "$build/compile_commands.json" | sort -u)
if [ -n "$base" ]; then
  mapfile -t changed < <(git diff --name-only --diff-filter=AMR "$base" -- '*.cpp' '*.hpp' | sort -u)
  # A changed header is checked through the compiled sources beside it.
  files=()
  for f in "${compiled[@]}"; do
    for c in "${changed[@]}"; do
      if [ "$f" = "$c" ] || [ "${f%.cpp}.hpp" = "$c" ]; then files+=("$f"); break; fi
    done
  done
else
  files=("${compiled[@]}")
fi
echo "clang-tidy: ${#files[@]} sources${base:+ changed since $base}"
[ "${#files[@]}" -eq 0 ] && exit 0
# The test programs compile with GCC's precompiled header (-include .../cmake_pch.hxx), which clang
# cannot read: clang-tidy gets the compile commands without it (the headers it stood for are
# included by the sources themselves).
commands=$(mktemp -d)
trap 'rm -rf "$commands"' EXIT
python3 -c '
import json, re, sys
entries = json.load(open(sys.argv[1]))
for e in entries:
    e["command"] = re.sub(r" -Winvalid-pch| -include \S*cmake_pch\.hxx", "", e["command"])
json.dump(entries, open(sys.argv[2], "w"))
' "$build/compile_commands.json" "$commands/compile_commands.json"
set +e
printf '%s\n' "${files[@]}" |
  xargs -P "$jobs" -n 1 "$tidy" -p "$commands" --quiet --warnings-as-errors='*' 2>&1 |
  { grep -v -E '^[0-9]+ warnings? (and [0-9]+ errors? )?generated\.$|^Suppressed [0-9]+ warnings' || true; }
status=${PIPESTATUS[1]}
set -e
if [ "$status" -eq 0 ]; then
  echo "clang-tidy: clean"
elif [ "${STEREOHASH_TIDY_STRICT:-0}" = 1 ]; then
  exit "$status"
else
  echo "clang-tidy: findings above (not fatal; STEREOHASH_TIDY_STRICT=1 makes them so)"
fi
