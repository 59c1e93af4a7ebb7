#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang in build-fuzz (ASan + UBSan, coverage) and
# runs each for SECONDS (default 60). Fails when any target crashes, leaks, times out on one
# input, or allocates past the limits below; the input that did it is kept in
# build-fuzz/artifacts/<target>/ and the log in build-fuzz/logs/<target>.log.
#
#   bash scripts/fuzz.sh [SECONDS]
#
# Seeds are regenerated from the real inputs (glmark2-data, blender-data) by fuzz/make_seeds,
# and small bakes and compressions by the Release build's prtr (build/, which
# scripts/setup.sh makes; built here when missing). The corpus each target grows is kept in
# build-fuzz/corpus/<target> between runs.
# Environment: PRTR_FUZZ_PARALLEL (targets run at once, default one per core: each target is
# one single-threaded process, so on 2 cores the 18 targets take half the wall time of
# running them in turn), PRTR_JOBS (build), PRTR_FUZZ_SKIP (targets to leave out, see below).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/apt_install.sh

seconds=${1:-60}
[[ $seconds =~ ^[0-9]+$ && $seconds -gt 0 ]] || { echo "usage: fuzz.sh [SECONDS]" >&2; exit 2; }
parallel=${PRTR_FUZZ_PARALLEL:-$(nproc)}
jobs=${PRTR_JOBS:-$(nproc)}
dir=build-fuzz

# Limits: a loader that needs more than this for a 64 KB input is the bug being looked for.
rss_mb=2048
malloc_mb=1024
timeout_s=10
max_len=65536

if ! command -v clang++ >/dev/null ||
   ! dpkg-query -W -f='${Status}' libclang-rt-14-dev 2>/dev/null | grep -q "install ok installed"; then
  echo "fuzz: installing clang libclang-rt-14-dev" >&2
  apt_install fuzz clang libclang-rt-14-dev
fi

CC=clang CXX=clang++ cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPRTR_FUZZ=ON \
  -DPRTR_BUILD_TESTS=OFF -DPRTR_BUILD_BENCH=OFF >/dev/null
cmake --build "$dir" -j "$jobs" --target fuzzers

# intercept_tls_get_addr=0: see scripts/sanitize.sh (the leak checker's tracer crash, clang < 17).
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0:intercept_tls_get_addr=0
# Assimp's own leaks only; see the file.
export LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
rm -rf "$dir/seeds"
"$dir/fuzz/make_seeds" "$dir/seeds" /usr/share/glmark2/models/bunny.obj \
  /usr/share/glmark2/models /usr/share/blender/datafiles/studiolights/world

# A small bake of each kind and one compression of each, the way prtr writes them.
if [[ ! -x build/prtr ]]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j "$jobs" --target prtr
fi
mkdir -p "$dir/seeds/prtx" "$dir/seeds/prtc"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 5\nf 2 5 4\nf 3 4 5\n' \
  >"$dir/seeds/solid.obj"
for kind in diffuse glossy; do
  build/prtr bake "$dir/seeds/solid.obj" -o "$dir/seeds/prtx/$kind.prtx" --kind "$kind" \
    --order 2 --samples 16 --bounces 0 --quiet >/dev/null
  build/prtr compress "$dir/seeds/prtx/$kind.prtx" --mesh "$dir/seeds/solid.obj" \
    -o "$dir/seeds/prtc/$kind.prtc" --clusters 2 --pcs 1 --quiet >/dev/null
done

# A surface light field of the solid, baked (.slf, from the cache) and compressed (.slfc).
mkdir -p "$dir/seeds/slf" "$dir/seeds/slfc"
build/prtr slf "$dir/seeds/solid.obj" --probe /usr/share/blender/datafiles/studiolights/world/forest.exr \
  --samples 24x24 --directions 4x2 --spp 1 --clusters 2 --pcs 1 --cache "$dir/seeds/slf-cache" \
  -o "$dir/seeds/slfc/solid.slfc" --quiet >/dev/null
cp "$dir"/seeds/slf-cache/*.slf "$dir/seeds/slf/"
rm -rf "$dir/seeds/slf-cache"

# HTTP request heads as prtr view receives them: pipelined, with a body, half-sent.
mkdir -p "$dir/seeds/http"
printf 'GET /frame?w=64&h=48&client=a&seq=1 HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nAccept: */*\r\n\r\nGET /api/info HTTP/1.1\r\nHost: localhost:8080\r\n\r\n' \
  >"$dir/seeds/http/pipelined.txt"
printf 'POST /frame HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nContent-Length: 5\r\nConnection: close\r\n\r\nhello' \
  >"$dir/seeds/http/body.txt"
printf '\r\nHEAD / HTTP/1.0\nConnection: keep-alive\nTransfer-Encoding: chunked\n\n' >"$dir/seeds/http/lf.txt"
printf 'GET /favicon.ico HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nX: a' >"$dir/seeds/http/partial.txt"

declare -A seeds=(
  [fuzz_prtx]=prtx [fuzz_prtx_resealed]=prtx [fuzz_prtc]=prtc [fuzz_prtc_resealed]=prtc
  [fuzz_mesh_obj]=mesh_obj [fuzz_mesh_ply]=mesh_ply [fuzz_mesh_off]=mesh_off
  [fuzz_mesh_stl]=mesh_stl [fuzz_mesh_3ds]=mesh_3ds [fuzz_mesh_gltf]=mesh_gltf [fuzz_mesh_glb]=mesh_glb
  [fuzz_probe_hdr]=probe_hdr [fuzz_probe_exr]=probe_exr [fuzz_http_request]=http
  [fuzz_slf]=slf [fuzz_slf_resealed]=slf [fuzz_slfc]=slfc [fuzz_slfc_resealed]=slfc
)
targets=(fuzz_prtx fuzz_prtx_resealed fuzz_prtc fuzz_prtc_resealed fuzz_mesh_obj fuzz_mesh_ply
         fuzz_mesh_off fuzz_mesh_stl fuzz_mesh_3ds fuzz_mesh_gltf fuzz_mesh_glb fuzz_probe_hdr
         fuzz_probe_exr fuzz_http_request fuzz_slf fuzz_slf_resealed fuzz_slfc
         fuzz_slfc_resealed)
# PRTR_FUZZ_SKIP: targets to leave out (names separated by spaces), e.g. one with an open
# finding that is being fixed; each is named in the output, so a skip is never silent.
if [[ -n ${PRTR_FUZZ_SKIP:-} ]]; then
  kept=()
  for t in "${targets[@]}"; do
    if [[ " $PRTR_FUZZ_SKIP " == *" $t "* ]]; then
      echo "fuzz: $t skipped (PRTR_FUZZ_SKIP)" >&2
    else
      kept+=("$t")
    fi
  done
  targets=("${kept[@]}")
fi
mkdir -p "$dir/logs"

run_one() {
  local t=$1
  mkdir -p "$dir/corpus/$t" "$dir/artifacts/$t"
  "$dir/fuzz/$t" -max_total_time="$seconds" -rss_limit_mb=$rss_mb -malloc_limit_mb=$malloc_mb \
    -timeout=$timeout_s -max_len=$max_len -print_final_stats=1 \
    -artifact_prefix="$dir/artifacts/$t/" "$dir/corpus/$t" "$dir/seeds/${seeds[$t]}" \
    >"$dir/logs/$t.log" 2>&1
}

failed=()
pids=()
names=()
for t in "${targets[@]}"; do
  run_one "$t" &
  pids+=($!)
  names+=("$t")
  if ((${#pids[@]} >= parallel)); then
    wait "${pids[0]}" || failed+=("${names[0]}")
    pids=("${pids[@]:1}")
    names=("${names[@]:1}")
  fi
done
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || failed+=("${names[$i]}")
done

printf '%-20s %12s %10s %8s %s\n' target executions exec/s rss_mb result
for t in "${targets[@]}"; do
  log=$dir/logs/$t.log
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  result=ok
  [[ " ${failed[*]} " == *" $t "* ]] && result="FAILED (see $log)"
  printf '%-20s %12s %10s %8s %s\n' "$t" "${runs:-?}" "${rate:-?}" "${rss:-?}" "$result"
done
if ((${#failed[@]})); then
  echo "fuzz: ${#failed[@]} target(s) failed: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: all ${#targets[@]} targets ran ${seconds} s each without a finding" >&2
