#!/usr/bin/env bash
# Installs what building and testing stereohash needs on Debian 12: the host toolchain and
# libraries, the python peers used by the tests, clang for the fuzzers, universal-ctags for the
# function size check and, with --cross, the aarch64 cross toolchain with arm64 multiarch
# libraries and qemu to run the board build, node-canopen (npm `canopen`, pinned) for the CANopen
# manager tests, Chromium with playwright-core (npm, pinned) for the web page's browser test and
# Firefox for its smoke load.
# Does nothing for packages already installed. Without network access to the npm registry the
# node tests skip.
set -euo pipefail

cross=0
[ "${1:-}" = "--cross" ] && cross=1

host_packages=(cmake ninja-build g++ pkg-config libeigen3-dev libpng-dev libgtest-dev libgmock-dev
  libbenchmark-dev libcamera-dev libgpiod-dev libopencv-dev libmicrohttpd-dev libassimp-dev python3 python3-can
  python3-canmatrix python3-opencv opencv-doc clang clang-tidy libclang-rt-14-dev universal-ctags
  chromium firefox-esr openssl)
cross_packages=(g++-aarch64-linux-gnu qemu-user libpng-dev:arm64 libcamera-dev:arm64 libgpiod-dev:arm64
  libgtest-dev:arm64 libbenchmark-dev:arm64 libmicrohttpd-dev:arm64)

sudo_cmd=()
if [ "$(id -u)" != 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi

# Node.js for the node-canopen peer: Debian's nodejs and npm unless a node is already there (a
# NodeSource node ships its own npm and conflicts with Debian's).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  host_packages+=(nodejs npm)
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
else
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# npm_pinned PACKAGE VERSION DIR WHAT: PACKAGE@VERSION into DIR/node_modules unless it is there and
# loads; a failure (npm registry unreachable) is a warning: the tests of WHAT skip.
npm_pinned() {
  local package=$1 version=$2 dir=$3 what=$4 installed
  installed=$(node -p "require('$dir/node_modules/$package/package.json').version" 2>/dev/null || true)
  if [ "$installed" = "$version" ] && node -e "require('$dir/node_modules/$package')" 2>/dev/null; then
    echo "install-deps: $package $version present in $dir"
    return
  fi
  mkdir -p "$dir"
  if npm install --prefix "$dir" --no-save --no-audit --no-fund "$package@$version" &&
     node -e "require('$dir/node_modules/$package')"; then
    echo "install-deps: $package $version installed in $dir"
  else
    echo "install-deps: WARNING: $package $version could not be installed (npm registry" \
         "unreachable?); $what will skip" >&2
  fi
}

# node-canopen, pinned, into the folder tests/node/CMakeLists.txt reads (STEREOHASH_NODE_MODULES).
# Its dependency node-crc compiles a small addon with node-gyp (g++ and the node headers).
npm_pinned canopen 6.2.1 "${STEREOHASH_NODE_DIR:-$HOME/.cache/stereohash/node}" \
  "the node-canopen tests"

# playwright-core, pinned, drives the Debian chromium in the web page's browser test; into a folder
# of its own (tests/web/CMakeLists.txt reads STEREOHASH_WEB_TEST_MODULES), since an npm install
# with --no-save into node-canopen's folder would remove the packages installed there.
npm_pinned playwright-core 1.65.2 "${STEREOHASH_WEB_TEST_DIR:-$HOME/.cache/stereohash/web-test}" \
  "the browser test"
