#!/usr/bin/env bash
# The main job on its built-in default: the firmware in simulator mode (rendered stereo pairs of
# reference objects on a table, a simulated CAN bus) with an in-process PLC that triggers
# recognitions and prints every pose as it arrives over the bus.
#
#   tools/run-demo.sh [seconds]      (default 15; installs its own dependencies)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-15}
tools/ci/install-deps.sh
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j "$(nproc)" --target stereohash-fw-sim stereohash
exec build/host-release/firmware/stereohash-fw-sim --demo --run-seconds "$seconds"
