#!/usr/bin/env bash
# Installs everything Pointillist needs to build, test and benchmark, from Debian packages.
# Idempotent: packages already installed are left alone. Uses sudo when not run as root.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libnanoflann-dev libeigen3-dev libcli11-dev libspng-dev zlib1g-dev
  nlohmann-json3-dev
  # pointillist view: SDL 2 for the window, SDL_ttf and DejaVu for its help overlay; Xvfb (and
  # xauth for xvfb-run) to test it headless
  libsdl2-dev libsdl2-ttf-dev fonts-dejavu-core xvfb xauth
  jq
  # convert under mpirun: chunk jobs on several processes or machines (CMake's POINTILLIST_MPI,
  # on when OpenMPI is found)
  openmpi-bin libopenmpi-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  # make fuzz: clang 14, its libFuzzer and sanitizer runtimes (libclang-rt-14-dev), and
  # llvm-symbolizer (llvm-14) for stacks with file and line
  clang-14 libclang-rt-14-dev llvm-14
  nodejs npm
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# nodejs/npm are only needed to fetch the sample models; a machine that already has `npm`
# (from another source) does not need Debian's.
if command -v npm >/dev/null 2>&1; then
  filtered=()
  for p in "${missing[@]}"; do [[ "$p" == nodejs || "$p" == npm ]] || filtered+=("$p"); done
  missing=("${filtered[@]+"${filtered[@]}"}")
fi

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all dependencies are installed"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo="sudo"
  else
    echo "setup: need root to install: ${missing[*]}; run as root or install sudo" >&2
    exit 1
  fi
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
