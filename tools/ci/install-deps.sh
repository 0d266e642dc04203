#!/usr/bin/env bash
# Installs what building and testing stereohash needs on Debian 12: the host toolchain and
# libraries, the python peers used by the tests, clang for the fuzzers and, with --cross, the
# aarch64 cross toolchain with arm64 multiarch libraries and qemu to run the board build.
# Does nothing for packages already installed.
set -euo pipefail

cross=0
[ "${1:-}" = "--cross" ] && cross=1

host_packages=(cmake ninja-build g++ pkg-config libeigen3-dev libgtest-dev libgmock-dev
  libbenchmark-dev libcamera-dev libgpiod-dev libopencv-dev python3 python3-can
  python3-canmatrix python3-opencv opencv-doc clang libclang-rt-14-dev)
cross_packages=(g++-aarch64-linux-gnu qemu-user libcamera-dev:arm64 libgpiod-dev:arm64
  libgtest-dev:arm64 libbenchmark-dev:arm64)

sudo_cmd=()
if [ "$(id -u)" != 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi

packages=("${host_packages[@]}")
if [ "$cross" = 1 ]; then
  if ! dpkg --print-foreign-architectures | grep -qx arm64; then
    "${sudo_cmd[@]}" dpkg --add-architecture arm64
  fi
  packages+=("${cross_packages[@]}")
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
