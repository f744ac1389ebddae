#!/usr/bin/env bash
# Installs the Debian 12 packages UnrealHaptics needs. As root it runs apt-get; otherwise it
# prints the command to run and fails if anything is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache
  libgtest-dev libgmock-dev libbenchmark-dev
  libeigen3-dev libassimp-dev libpng-dev
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev libreaderwriterqueue-dev
  libfcl-dev libbullet-dev libcairo2-dev
  libopenal-dev espeak-ng  # uh::audio: the blind player's sound (HRTF data in libopenal-data), speech from the espeak-ng program
  libboost-dev chromium python3-websockets
  clang libclang-rt-14-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
  g++-mingw-w64-x86-64-posix wine64
  godot3-server mono-mcs mono-runtime
  rt-tests  # cyclictest, the reference of scripts/bench-latency.sh
  help2man zip  # scripts/package.sh: uh's man page, the Windows and Godot archives
)

# the live view's build (npm ci, esbuild) needs node and npm: Debian's, unless another node is there
if ! command -v npm >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "install-deps: missing Debian packages: ${missing[*]}" >&2
  echo "install-deps: run as root:  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
  exit 1
fi
