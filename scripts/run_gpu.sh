#!/usr/bin/env bash
# Runs the GPU benchmark from a bundle made by scripts/gpu_bundle.sh, on the machine it was
# carried to, and writes RESULTS/results.md (the tables) beside the raw logs. Every step has
# its own time limit and a failed step is logged and skipped, so one run always ends with a
# table of what it measured. The same script is tested on Debian with Mesa's EGL:
#
#   bash run_gpu.sh RESULTS                       # everything, on the GPU
#   PRTR_GPU_ROUNDS=0 PRTR_GPU_FRAMES=2 PRTR_GPU_MESHES=bunny_x0 PRTR_GPU_BAKE_THREADS=2 \
#     PRTR_GPU_BAKE_SAMPLES=16 bash run_gpu.sh RESULTS   # a quick check elsewhere
#
# It unpacks bundle.tar.xz into a scratch folder, makes the inputs there (bundle_inputs: the
# bunny subdivided 0, 1 and 2 times, baked with 64 samples and compressed, 256 x 8), runs
# render_bench_portable on each mesh, then bake_bench at each thread count, then prtr view
# end to end.
set -uo pipefail
bundle=$(cd "$(dirname "$0")" && pwd)
res=$(mkdir -p "${1:?usage: run_gpu.sh RESULTS_DIR}" && cd "$1" && pwd)
here=$(mktemp -d "${TMPDIR:-/tmp}/prtr_gpu.XXXXXX")
trap 'rm -rf "$here"' EXIT
unpack() {  # xz where installed, else Python's lzma (a minimal image may lack xz-utils)
  if command -v xz >/dev/null; then
    xz -dc "$bundle/bundle.tar.xz" | tar -C "$here" -xf -
  else
    python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1], "r:xz").extractall(sys.argv[2])' \
      "$bundle/bundle.tar.xz" "$here"
  fi
}
unpack || { echo "run_gpu: cannot unpack $bundle/bundle.tar.xz" >&2; exit 1; }
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# A driver without glvnd's libEGL.so.1 (its vendor library alone): the bundle's dispatcher.
glvnd_note="system"
if ! /sbin/ldconfig -p 2>/dev/null | grep -q 'libEGL.so.1 '; then
  export LD_LIBRARY_PATH="$here/lib/glvnd:$LD_LIBRARY_PATH"
  glvnd_note="bundled (the system has no libEGL.so.1)"
fi
# glvnd finds NVIDIA's EGL vendor through this file where the driver is mounted outside /usr.
nv_json=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
if [[ -z ${__EGL_VENDOR_LIBRARY_FILENAMES:-} && -f $nv_json &&
      ! -f /usr/share/glvnd/egl_vendor.d/10_nvidia.json ]]; then
  export __EGL_VENDOR_LIBRARY_FILENAMES=$nv_json
fi
gl=${PRTR_GL:-egl}
frames=${PRTR_GPU_FRAMES:-12}
meshes=${PRTR_GPU_MESHES:-bunny_x0 bunny_x1 bunny_x2}
threads=${PRTR_GPU_BAKE_THREADS:-16 8 4 2 1}
samples=${PRTR_GPU_BAKE_SAMPLES:-1024}
rounds=${PRTR_GPU_ROUNDS:-2}

{
  echo "date: $(date -u +%FT%TZ)"
  echo "host: $(uname -srm), $(nproc) CPUs"
  command -v nvidia-smi >/dev/null &&
    nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader |
    sed 's/^/gpu: /'
  grep -m1 'model name' /proc/cpuinfo | sed 's/.*: /cpu: /'
  echo "gl: $gl; frames: $frames; bake samples: $samples"
  echo "egl vendor files: ${__EGL_VENDOR_LIBRARY_FILENAMES:-default}; glvnd: $glvnd_note"
  ldd "$here/bin/render_bench_portable" | grep -E 'not found|libEGL' || true
} >"$res/env.txt" 2>&1
cat "$res/env.txt"

# Everything ends by PRTR_GPU_DEADLINE seconds after the start (default 480): each step gets
# at most its own cap and what is left less what later steps are promised, and the table is
# rewritten after every step, so a run stopped from outside still leaves one.
deadline=${PRTR_GPU_DEADLINE:-480}
cap() {  # cap MAX [RESERVE]: seconds for a step
  local c=$1 left=$((deadline - SECONDS - ${2:-0}))
  ((left < c)) && c=$left
  ((c < 5)) && c=5
  echo "$c"
}
table() {
  python3 "$bundle/gpu_table.py" "$res/env.txt" "$res/render_bench.log" "$res/bake_bench.log" \
    "$res/inputs.log" >"$res/results.md" 2>>"$res/inputs.log"
  if [[ -s $res/view.md ]]; then
    { echo; echo "## prtr view end to end ($gl)"; echo; cat "$res/view.md"; } >>"$res/results.md"
  fi
}
: >"$res/render_bench.log"
: >"$res/bake_bench.log"

# The bunny's inputs first (seconds), so that a machine whose EGL does not start is told
# before the minutes of the subdivided ones.
timeout "$(cap 60 300)" "$here/bin/bundle_inputs" "$here/data/bunny.obj" "$here/data" 64 0 \
  >"$res/inputs.log" 2>&1
echo "inputs: bunny exit $? at $SECONDS s" | tee -a "$res/inputs.log"

# One small EGL start before the benchmarks: where glvnd finds no vendor, point it at the
# driver's own file and say so in env.txt (a 1-frame bunny run at 64 x 48).
egl_check() {
  timeout "$(cap 30 100)" "$here/bin/render_bench_portable" "$here/data/bunny_x0.prtc" \
    --mesh "$here/data/bunny_x0.ply" --probe procedural --gl "$gl" --frames 1 --width 64 \
    --height 48 2>&1 | grep -m1 -E 'render_bench|EGL'
}
check=$(egl_check)
if [[ $gl == egl && $check == *"EGL failed"* && -z ${__EGL_VENDOR_LIBRARY_FILENAMES:-} ]]; then
  json=$(find /usr /etc -name '10_nvidia.json' -path '*egl_vendor.d*' 2>/dev/null | head -1)
  if [[ -n $json ]]; then
    export __EGL_VENDOR_LIBRARY_FILENAMES=$json
    echo "EGL failed ($check); retrying with __EGL_VENDOR_LIBRARY_FILENAMES=$json" >>"$res/env.txt"
    check=$(egl_check)
  fi
fi
echo "first start: $check" >>"$res/env.txt"
table
if [[ $check != "render_bench: $gl"* ]]; then
  echo "run_gpu: no $gl context: $check" | tee -a "$res/env.txt" >&2
  exit 1
fi

# The subdivided bunnies, on all cores (the x2 compression is most of it).
if ((rounds > 0)); then
  timeout "$(cap 170 150)" "$here/bin/bundle_inputs" "$here/data/bunny.obj" "$here/data" 64 \
    "$rounds" 1 >>"$res/inputs.log" 2>&1
  echo "inputs: subdivided exit $? at $SECONDS s" | tee -a "$res/inputs.log"
fi

# One render_bench run: LABEL MESH CAP [ARGS...]. The label heads its table (gpu_table.py).
bench_run() {
  local label=$1 m=$2 limit
  limit=$(cap "$3" 40)
  shift 3
  [[ -f $here/data/$m.prtc ]] || return 0
  echo "== $label (at $SECONDS s, limit $limit s)" | tee -a "$res/render_bench.log"
  timeout "$limit" "$here/bin/render_bench_portable" "$here/data/$m.prtc" \
    --mesh "$here/data/$m.ply" --probe procedural --gl "$gl" --frames "$frames" "$@" \
    >>"$res/render_bench.log" 2>&1
  echo "== exit $? at $SECONDS s" | tee -a "$res/render_bench.log"
  table
}

# Most wanted first, so a run cut short still answers the targets: the thesis configuration
# as the device would choose it, then the previous choice (constants on the CPU, RGBA32F) in
# the same run, then the bake's scaling, then the larger meshes and the overdraw sweeps.
for m in $meshes; do
  [[ $m == bunny_x0 ]] || continue
  bench_run bunny_x0 bunny_x0 60
  bench_run bunny_x0-cpu-constants-rgba32f bunny_x0 60 --constants cpu --accumulation rgba32f
done
bake_runs() {
  for t in $threads; do
    if ((deadline - SECONDS < 10)); then
      echo "== threads $t skipped: out of time" | tee -a "$res/bake_bench.log"
      continue
    fi
    echo "== threads $t (at $SECONDS s)" | tee -a "$res/bake_bench.log"
    timeout "$(cap 120)" "$here/bin/bake_bench" "$here/data/bunny_x0.ply" "$samples" "$t" \
      >>"$res/bake_bench.log" 2>&1
    echo "== exit $? at $SECONDS s" | tee -a "$res/bake_bench.log"
    table
  done
}
bake_runs
# prtr view on this machine's GL: the bunny under the bundled probe (a Radiance .hdr, which
# prtr reads without OpenImageIO), baked here through its cache, then frames requested over
# loopback at 1280 x 948 by view_timing.py (no browser here): where a frame's time goes.
view_run() {
  [[ -x $here/bin/prtr && -f $here/data/forest.hdr ]] || return 0
  local limit log=$res/view_server.log url=""
  limit=$(cap 120 30)
  echo "== view (at $SECONDS s, limit $limit s)" | tee -a "$log"
  timeout "$limit" "$here/bin/prtr" view "$here/data/bunny_x0.ply" --probe "$here/data/forest.hdr" \
    --gl "$gl" --host 127.0.0.1 --port 0 --cache "$here/view_cache" -q >>"$log" 2>&1 &
  local server=$!
  for _ in $(seq 1 "$limit"); do
    url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$log" | head -1)
    [[ -n $url ]] && break
    kill -0 "$server" 2>/dev/null || break
    sleep 1
  done
  if [[ -n $url ]]; then
    timeout "$(cap 60 20)" python3 "$bundle/view_timing.py" "$url" --frames "${PRTR_GPU_VIEW_FRAMES:-100}" \
      --size 1280x948 >"$res/view.md" 2>>"$log"
    echo "== view timing exit $? at $SECONDS s" | tee -a "$log"
  fi
  kill "$server" 2>/dev/null
  wait "$server" 2>/dev/null
  table
}
[[ " $meshes " == *" bunny_x0 "* ]] && view_run
# The two changes apart: constants as the device chooses, RGBA32F accumulation.
[[ " $meshes " == *" bunny_x0 "* ]] && bench_run bunny_x0-rgba32f bunny_x0 50 --accumulation rgba32f
# The largest mesh before the middle one: its 16-a-pass row is a target.
for m in bunny_x0 bunny_x2 bunny_x1; do
  [[ " $meshes " == *" $m "* ]] || continue
  case $m in
    bunny_x0) bench_run bunny_x0-sweep bunny_x0 40 --rows sweep ;;
    bunny_x1) bench_run bunny_x1 bunny_x1 90 ;;
    *)
      bench_run "$m" "$m" 150
      bench_run "$m-sweep" "$m" 90 --rows sweep
      ;;
  esac
done
cat "$res/results.md"
echo "run_gpu: $SECONDS s"
