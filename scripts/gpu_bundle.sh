#!/usr/bin/env bash
# Builds here and packs the GPU benchmark into one folder (default ./.gpu, which git
# ignores) for a machine with an NVIDIA GL driver and glvnd's libEGL but none of prtr's
# libraries (no OpenImageIO, Embree, OSMesa; TBB perhaps): render_bench_portable,
# bake_bench, bundle_inputs and prtr, every shared library they load that such a machine
# lacks, the bunny and the forest probe (.hdr), all in bundle.tar.xz; beside it run_gpu.sh,
# which runs everything there and writes the results table, gpu_table.py, which makes it,
# and view_timing.py, which times prtr view's frames.
#
#   bash scripts/gpu_bundle.sh [DIR]      # here; then, on the GPU machine:
#   bash DIR/run_gpu.sh RESULTS_DIR        # RESULTS_DIR/results.md and the logs
#
# The subdivided bunnies and their compressed sets are made there (bundle_inputs): the x2
# set alone is 32 MB of floats, which xz does not shrink, and the bundle must stay within
# 64 MiB. Debian 12's builds run on newer glibc (2.39 there); glibc, libstdc++ and libgcc_s
# are the target's own, and the GL stack must be the target's driver behind glvnd.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-.gpu}
bunny=/usr/share/glmark2/models/bunny.obj

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)" --target render_bench_portable bake_bench bundle_inputs prtr

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib" "$stage/data"
cp build/bench/render_bench_portable build/bench/bake_bench build/bench/bundle_inputs \
  build/prtr "$stage/bin/"
cp "$bunny" "$stage/data/bunny.obj"
# prtr view there lights the bunny with the forest probe as Radiance .hdr, which prtr reads
# itself: the image module (OpenImageIO's ~260 libraries) is not carried.
oiiotool /usr/share/blender/datafiles/studiolights/world/forest.exr -o "$stage/data/forest.hdr"
skip='^(linux-vdso|ld-linux-x86-64|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|libEGL|libGL|libOSMesa)\.'
for bin in "$stage"/bin/*; do
  ldd "$bin" | awk '$3 ~ /^\// {print $1, $3}'
done | sort -u | while read -r name path; do
  [[ $name =~ $skip ]] || cp -L "$path" "$stage/lib/$name"
done
# glvnd's dispatcher, for a machine whose driver brings its EGL vendor library
# (libEGL_nvidia) but not libEGL.so.1 itself; run_gpu.sh uses it only where the system has none.
mkdir -p "$stage/lib/glvnd"
for name in libEGL.so.1 libGLdispatch.so.0 libOpenGL.so.0; do
  cp -L "/usr/lib/x86_64-linux-gnu/$name" "$stage/lib/glvnd/$name"
done
if ldd build/bench/render_bench_portable | grep -Eq 'OpenImageIO|OSMesa|embree'; then
  echo "gpu_bundle: render_bench_portable links OpenImageIO, OSMesa or Embree" >&2
  exit 1
fi
if ldd build/prtr | grep -Eq 'OpenImageIO|OSMesa'; then
  echo "gpu_bundle: prtr links OpenImageIO or OSMesa (both must load at run time)" >&2
  exit 1
fi
rm -rf "$out"
mkdir -p "$out"
tar -C "$stage" -cf - bin lib data | xz -T0 -6 >"$out/bundle.tar.xz"
cp scripts/run_gpu.sh scripts/gpu_table.py scripts/view_timing.py "$out/"
ls -l "$stage/lib" >&2
echo "gpu_bundle: $out ready, $(du -sk "$out" | cut -f1) KiB" >&2
