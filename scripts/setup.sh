#!/usr/bin/env bash
# Installs every Debian package prtr needs (build tools, libraries, and the real inputs:
# glmark2-data for the Stanford bunny, blender-data for the HDR probes), then configures and
# builds in ./build. Idempotent and non-interactive: a second run installs nothing and
# rebuilds only what changed. Debian 12 (bookworm); runs apt-get as root or through sudo.
#
# The list is what a pristine Debian 12 root needs, proven by .ci/run on every submission.
# openimageio-tools looks optional but is not: Debian's OpenImageIO CMake config declares
# imported targets for its command-line tools, and find_package fails when they are absent.
# ffmpeg (the MP4 of prtr relight, and ffprobe for its test) and python3-matplotlib (the plot
# of prtr overdraw, scripts/plot_overdraw.py) are run, not linked: without them prtr still
# works and says how to get the missing output, but the tests that check it are skipped.
#
#   bash scripts/setup.sh          # everything: the test command's set-up
#   bash scripts/setup.sh --main   # only what `prtr relight` needs (the main job's set-up): no
#                                  # test or benchmark packages, and only the prtr target
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/apt_install.sh

main_only=false
case ${1:-} in
  "") ;;
  --main) main_only=true ;;
  *) echo "usage: setup.sh [--main]" >&2; exit 2 ;;
esac

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libopenmesh-dev libembree-dev libglm-dev libosmesa6-dev
  libegl-dev            # render/'s EGL backend (headers)
  libopenimageio-dev openimageio-tools libtbb-dev libcli11-dev
  libmetis-dev libmeshoptimizer-dev nlohmann-json3-dev
  libassimp-dev  # glTF 2.0 (.gltf, .glb) and 3DS import, meshes/src/read_assimp.cpp
  zlib1g-dev     # Debian's assimp CMake config links /usr/lib/.../libz.so, but libassimp-dev
                 # does not depend on zlib1g-dev (cpp-httplib's package brought it until the
                 # viewer dropped it; the test packages still do, so only the main job broke)
  ffmpeg                # the MP4 of prtr relight (and ffprobe for its test)
  libturbojpeg0-dev     # prtr view: JPEG frames
  glmark2-data blender-data
  fonts-dejavu-core     # prtr overdraw's plots and the picture legends: DejaVu Sans via OpenImageIO
)
# The tests, benchmarks and optional parts: the main job needs none of them.
$main_only || packages+=(
  libgtest-dev libbenchmark-dev
  libegl-mesa0          # Mesa's EGL for the .egl tests
  libopenmpi-dev openmpi-bin  # mpirun prtr bake (optional CMake component PRTR_MPI) and its test
  python3-matplotlib    # the plot of prtr overdraw (scripts/plot_overdraw.py)
  chromium              # prtr view's end-to-end test drives it headless (run, not linked)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  apt_install setup "${missing[@]}"
  echo "setup: installed ${#missing[@]} packages in $SECONDS s" >&2
else
  echo "setup: all ${#packages[@]} packages present" >&2
fi

build_type=${PRTR_BUILD_TYPE:-Release}
build_start=$SECONDS
if $main_only; then
  # A tree the test command configured keeps its settings; a fresh one leaves out the tests
  # and benchmarks, whose packages were not installed.
  if [[ -f build/CMakeCache.txt ]]; then
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE="$build_type" >/dev/null
  else
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE="$build_type" \
      -DPRTR_BUILD_TESTS=OFF -DPRTR_BUILD_BENCH=OFF >/dev/null
  fi
  cmake --build build -j "$(nproc)" --target prtr
else
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE="$build_type" \
    -DPRTR_BUILD_TESTS=ON -DPRTR_BUILD_BENCH=ON -DPRTR_MPI=ON >/dev/null
  cmake --build build -j "$(nproc)"
fi
echo "setup: configured and built ./build ($build_type) in $((SECONDS - build_start)) s" >&2
