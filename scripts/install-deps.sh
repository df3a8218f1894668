#!/usr/bin/env bash
# Installs foxi's build and test dependencies from Debian packages (run as root, or with sudo).
# Installs only what is missing, so a second run costs a few dpkg queries.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config
  # libraries
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev libtet1.5-dev libeigen3-dev
  qtbase5-dev libx11-dev libxext-dev libpng-dev zlib1g-dev libpugixml-dev libfreetype-dev libgif-dev libtoml11-dev
  # the API reference (scripts/docs.sh)
  doxygen
  # text in pictures (colour-bar legends): FreeType above, fontconfig to find the font, the DejaVu font
  libfontconfig-dev fonts-dejavu-core
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev xvfb xdotool x11-apps
  # the fuzz targets (scripts/fuzz.sh): clang with libFuzzer and its sanitizer runtimes
  clang-14 libclang-rt-14-dev
  # the sanitizer build links with lld: about half the CPU of ld.bfd per test program (measured 1.5 s
  # against 3.1 s), and it links about a hundred of them
  lld
  # scripts/check_format.sh (in test.sh): the one C++ format, .clang-format
  clang-format-14
  # outside programs the tests use as oracles
  gmsh tetgen calculix-ccx python3-meshio python3-numpy
  # optional: foxi movie writes MP4 through it, and the movie tests decode APNG/GIF/MP4 with it
  ffmpeg
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
