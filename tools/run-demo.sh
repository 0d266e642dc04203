#!/usr/bin/env bash
# The main job on its built-in default: the firmware in simulator mode (rendered stereo pairs of
# reference objects on a table, a simulated CAN bus) with an in-process PLC that triggers
# recognitions and prints every pose as it arrives over the bus. With `cartons` the scenes also
# hold the printed cartons of models/textured, whose feature database is learnt first.
#
#   tools/run-demo.sh [seconds] [cartons]      (default 15; installs its own dependencies)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-15}
tools/ci/install-deps.sh
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j "$(nproc)" --target stereohash-fw-sim stereohash
if [[ "${2:-}" == cartons ]]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  build/host-release/tools/stereohash tables build --models models/textured --out "$work/cartons.bin" >/dev/null
  printf 'backend = sim\nfeatures = %s\nsim_printed_models = models/textured\nsim_objects = 4\n' \
    "$work/cartons.bin" >"$work/cartons.conf"
  build/host-release/firmware/stereohash-fw-sim --config "$work/cartons.conf" --demo --run-seconds "$seconds"
else
  exec build/host-release/firmware/stereohash-fw-sim --demo --run-seconds "$seconds"
fi
