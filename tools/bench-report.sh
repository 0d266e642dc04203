#!/usr/bin/env bash
# The benchmark log: runs the benchmarks of a Release build, appends one record (JSON line) to
# docs/benchmarks/log.jsonl and renders docs/benchmarks.md with its plots from the whole log.
#
#   tools/bench-report.sh [options] [RECORDED_SET_DIR...]
#
# Parts, each named as in docs/benchmarks.md:
#   every recorded set under $STEREOHASH_SCENES (default ../shared/scenes) and each DIR given:
#     polyhedra   stereohash bench recorded DIR --json OUT
#     colour      the same with --tables of models/colour's model set (views), built first
#     textured    stereohash bench textured --recorded DIR --json OUT (with the OpenCV peer when
#                 stereohash-cv is built, except with --quick)
#   rendered      stereohash bench scenes --json OUT (our renderer, thesis table 5.4 grid)
#   noise         the clean polyhedral sets (thesis-camera, wide-camera and each DIR given that
#                 is neither a factory floor nor colour or textured) with sensor noise added:
#                 stereohash bench recorded DIR --noise 0,1.5,3,4.5,6: sets noise-NAME
#   memory        resident memory of stereohash recognize on a thesis-camera pair and of the
#                 firmware simulator's demo, unlocked and with mlock (needs ../shared/scenes)
#   web-latency   trigger-to-result latency of the firmware simulator with the commissioning page
#                 closed, open, and open four times (tools/bench_web_latency.py, python-can)
#   micro         the Google Benchmark programs build/host-release/tests/**/*_bench
#                 (or name one, e.g. image_bench), --benchmark_format=json
#
# Options:
#   --quick         the recorded sets only (no rendered bench, noise sweep, micro-benchmarks, peer)
#   --sets A,B      only these parts (set folder names, rendered, noise, micro, a *_bench name)
#   --threads N     pass --threads N to the recognition benches (default: the programs' own, all
#                   cores); recorded in the log
#   --callgrind     count instructions with valgrind's callgrind where perf cannot (slow: about
#                   50 times the run time); perf stat is used whenever it can count
#   --render-only   render docs/benchmarks.md from the existing log, run nothing
#   --build DIR     the build folder (default build/host-release)
#   --log FILE      the log (default docs/benchmarks/log.jsonl)
#   --md FILE       the page rendered from it (default docs/benchmarks.md; its plots go into the
#                   folder of the same name without .md)
#   --keep DIR      keep the working files (JSON of every part) in DIR instead of a temporary folder
#
# Run it on an otherwise idle machine for frame times that mean something; the record names the
# machine and its load average before and after. Instruction counts do not depend on the load.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

build=build/host-release
log=docs/benchmarks/log.jsonl
md=docs/benchmarks.md
scenes_root=${STEREOHASH_SCENES:-../shared/scenes}
quick=0
render_only=0
callgrind=0
threads=""
only=""
keep=""
extra_sets=()

usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'; }

while (($#)); do
  case "$1" in
    --quick) quick=1 ;;
    --render-only) render_only=1 ;;
    --callgrind) callgrind=1 ;;
    --sets) only=",${2:?--sets needs a list},"; shift ;;
    --threads) threads=${2:?--threads needs a number}; shift ;;
    --build) build=${2:?}; shift ;;
    --log) log=${2:?}; shift ;;
    --md) md=${2:?}; shift ;;
    --keep) keep=${2:?}; shift ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "bench-report: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) [[ -d "$1" ]] || { echo "bench-report: $1 is not a folder" >&2; exit 2; }
       extra_sets+=("$(cd "$1" && pwd)") ;;
  esac
  shift
done

plots=${md%.md}
render() { python3 tools/bench_report.py render --log "$log" --md "$md" --plots "$plots"; }
if ((render_only)); then
  render
  exit 0
fi

sh_bin=$build/tools/stereohash
if [[ ! -x $sh_bin ]]; then
  echo "bench-report: no $sh_bin; build it first: cmake --preset host-release &&" \
       "cmake --build --preset host-release" >&2
  exit 1
fi

if [[ -n $keep ]]; then
  mkdir -p "$keep"
  work=$(cd "$keep" && pwd)
  rm -f "$work/manifest.jsonl"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
mode=full
((quick)) && mode=quick
[[ -n $only ]] && mode="$mode; parts ${only:1:${#only}-2}"

wanted() { [[ -z $only || $only == *",$1,"* ]]; }

perf_ok=0
if command -v perf >/dev/null && perf stat -x, -e instructions:u true 2>&1 | grep -q '^[0-9]'; then
  perf_ok=1
fi
failed=0

# The command as the log shows it: the program by name, the working folder as $WORK.
shown() {
  local s="$*"
  s=${s//$root\/$build\/tools\//}
  s=${s//$build\/tools\//}
  s=${s//$work/\$WORK}
  s=${s//$root\//}
  printf '%s' "$s"
}

# run_part NAME KIND JSON [note options --] COMMAND...: runs it, counts its instructions when it
# can, notes it in the manifest.
run_part() {
  local name=$1 kind=$2 json=$3
  shift 3
  local notes=()
  while [[ $1 != -- ]]; do notes+=("$1"); shift; done
  shift
  local count="" tool="" rc=0 start end
  echo "== $name: $(shown "$@")"
  start=$(date +%s.%N)
  if [[ $kind == memory || $kind == web ]]; then
    "$@" >"$work/$name.out" 2>&1 || rc=$?
  elif ((perf_ok)); then
    perf stat -x, -e instructions:u -o "$work/$name.perf" -- "$@" >"$work/$name.out" 2>&1 || rc=$?
    count=$(awk -F, '/instructions/ && $1 ~ /^[0-9]+$/ {print $1}' "$work/$name.perf" | head -1)
    tool=perf
  elif ((callgrind)); then
    valgrind --tool=callgrind --trace-children=yes \
      --callgrind-out-file="$work/$name.cg.%p" "$@" >"$work/$name.out" 2>&1 || rc=$?
    count=$(cat "$work/$name".cg.* 2>/dev/null | awk '/^(summary|totals):/ {s += $2} END {print s+0}')
    tool=callgrind
    rm -f "$work/$name".cg.*
  else
    "$@" >"$work/$name.out" 2>&1 || rc=$?
  fi
  end=$(date +%s.%N)
  tail -n 4 "$work/$name.out" | sed 's/^/   /'
  if ((rc != 0)); then
    echo "   exit $rc (output: $work/$name.out)"
    failed=1
  fi
  python3 tools/bench_report.py note --work "$work" --name "$name" --kind "$kind" \
    --command "$(shown "$@")" --json "$json" --exit "$rc" \
    --wall "$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.2f", b - a}')" \
    ${count:+--instructions "$count" --tool "$tool"} ${threads:+--threads "$threads"} \
    ${notes[@]+"${notes[@]}"}
}

thread_opts=()
[[ -n $threads ]] && thread_opts=(--threads "$threads")

colour_tables=""
colour_views() {
  if [[ -z $colour_tables ]]; then
    colour_tables=$work/colour-views.bin
    echo "== model set of models/colour (view database) for the colour sets"
    "$sh_bin" tables build --models models/colour --out "$colour_tables" >"$work/colour-views.out"
  fi
}

bench_set() {
  local dir=$1 name kind
  name=$(basename "$dir")
  wanted "$name" || return 0
  kind=$(python3 -c 'import json,sys
try: print(json.load(open(sys.argv[1]))["kind"])
except Exception: print("polyhedra")' "$dir/scenes.json")
  case "$kind" in
    textured)
      local peer=(--no-peer)
      if ((!quick)) && [[ -x $build/tools/stereohash-cv ]]; then peer=(); fi
      run_part "$name" textured "$work/$name.json" -- \
        "$sh_bin" bench textured --recorded "$dir" ${peer[@]+"${peer[@]}"} --json "$work/$name.json"
      ;;
    colour)
      colour_views
      run_part "$name" colour "$work/$name.json" --truth "$dir" \
        --prepare "stereohash tables build --models models/colour --out \$WORK/colour-views.bin" -- \
        "$sh_bin" bench recorded "$dir" --tables "$colour_tables" ${thread_opts[@]+"${thread_opts[@]}"} \
        --json "$work/$name.json"
      ;;
    *)
      run_part "$name" recorded "$work/$name.json" --truth "$dir" -- \
        "$sh_bin" bench recorded "$dir" ${thread_opts[@]+"${thread_opts[@]}"} --json "$work/$name.json"
      ;;
  esac
}

if [[ -d $scenes_root ]]; then
  for dir in "$scenes_root"/*/; do
    dir=${dir%/}
    [[ -f $dir/calib.yaml ]] || continue
    bench_set "$dir"
  done
else
  echo "bench-report: no shared sets at $scenes_root (STEREOHASH_SCENES); only the folders given"
fi
for dir in ${extra_sets[@]+"${extra_sets[@]}"}; do
  bench_set "$dir"
done

if ((!quick)); then
  if wanted rendered; then
    run_part rendered scenes "$work/rendered.json" -- \
      "$sh_bin" bench scenes ${thread_opts[@]+"${thread_opts[@]}"} --json "$work/rendered.json"
  fi
  if wanted noise; then
    for dir in "$scenes_root/thesis-camera" "$scenes_root/wide-camera" ${extra_sets[@]+"${extra_sets[@]}"}; do
      [[ -f $dir/calib.yaml ]] || continue
      name=$(basename "$dir")
      case "$name" in hard-* | colour* | textured*) continue ;; esac
      run_part "noise-$name" sweep "$work/noise-$name.json" -- \
        "$sh_bin" bench recorded "$dir" --noise 0,1.5,3,4.5,6 ${thread_opts[@]+"${thread_opts[@]}"} \
        --json "$work/noise-$name.json"
    done
  fi
  if wanted memory && [[ -d $scenes_root/thesis-camera ]]; then
    run_part memory memory "$work/memory.json" -- \
      python3 tools/bench_report.py memory --work "$work" --out "$work/memory.json" \
      --stereohash "$sh_bin" --firmware "$build/firmware/stereohash-fw-sim" \
      --scene-set "$scenes_root/thesis-camera"
  fi
  if wanted web-latency && [[ -x $build/firmware/stereohash-fw-sim ]]; then
    run_part web-latency web "$work/web-latency.json" -- \
      /usr/bin/python3 tools/bench_web_latency.py --firmware "$build/firmware/stereohash-fw-sim" \
      --work "$work" --out "$work/web-latency.json" --triggers 200 --block 25 --period-ms 200
  fi
  while IFS= read -r prog; do
    name=$(basename "$prog")
    wanted micro || wanted "$name" || continue
    echo "== $name"
    rc=0
    # shellcheck disable=SC2086  # BENCH_MICRO_ARGS holds several options
    "$prog" --benchmark_format=json ${BENCH_MICRO_ARGS:-} >"$work/$name.json" 2>"$work/$name.err" || rc=$?
    ((rc == 0)) || { echo "   exit $rc"; failed=1; }
    # shellcheck disable=SC2086
    python3 tools/bench_report.py note --work "$work" --name "$name" --kind micro \
      --command "$(shown "$prog" --benchmark_format=json ${BENCH_MICRO_ARGS:-})" \
      --json "$work/$name.json" --exit "$rc"
  done < <(find "$build/tests" -name '*_bench' -type f -perm -u+x 2>/dev/null | sort)
fi

python3 tools/bench_report.py append --work "$work" --log "$log" --mode "$mode" \
  --load-start "$load_start"
render
exit "$failed"
