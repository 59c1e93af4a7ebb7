#!/usr/bin/env bash
# Compression benchmark (docs/BENCHMARKS.md): clustering time, iterations, Average SE, relative error
# and compression ratio for 64/128/192/256 clusters x 8 PCs, with and without geometry
# coherence and the overdraw-aware reassignment, plus power iteration vs Eigen's solver.
# Usage: scripts/bench_compress.sh [TRANSFER.prtx] [MESH]   (defaults: the bunny bake in out/)
# Prints a Markdown table; the raw JSON lines go to out/bench_compress.jsonl.
set -euo pipefail
cd "$(dirname "$0")/.."
prtr=./build/prtr
mesh=${2:-/usr/share/glmark2/models/bunny.obj}
transfer=${1:-out/bunny.prtx}
mkdir -p out
if [[ ! -f $transfer ]]; then
  echo "baking $mesh -> $transfer (order 6 glossy, 1024 samples, 1 bounce)" >&2
  $prtr bake "$mesh" -o "$transfer" -q >&2
fi
log=out/bench_compress.jsonl
: >"$log"
row() {  # row LABEL ARGS...
  local label=$1; shift
  local json
  json=$($prtr compress "$transfer" --mesh "$mesh" -o out/bench_compress.prtc --pcs 8 --json -q "$@")
  echo "$json" >>"$log"
  python3 - "$label" "$json" <<'PY'
import json, sys
label, r = sys.argv[1], json.loads(sys.argv[2])
t = r["triangles_1"] + r["triangles_2"] + r["triangles_3"]
print(f'| {r["clusters"]} | {label} | {r["clustering_seconds"]:.1f} | {r["lbg_iterations"]}'
      f'{"+" + str(r["cpca_iterations"]) if r["cpca_iterations"] else ""} | {r["pca_seconds"]:.2f} |'
      f' {r["average_se"]:.4e} | {r["relative_error"]:.4e} | {r["ratio"]:.2f} |'
      f' {100.0 * (r["triangles_2"] + r["triangles_3"]) / t:.1f}% |')
PY
}
echo "| clusters | method | clustering s | iterations | PCA s | Average SE | relative error | ratio | multi-cluster triangles |"
echo "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for k in 64 128 192 256; do
  row "LBG (original CPCA)" --clusters $k
  row "LBG + coherence a=0.05" --clusters $k --alpha 0.05
  row "LBG + coherence a=2" --clusters $k --alpha 2
  row "LBG + overdraw reduction" --clusters $k --overdraw-reduction
  row "LBG + coherence a=2 + overdraw red." --clusters $k --alpha 2 --overdraw-reduction
done
row "LBG, PCA by Eigen solver" --clusters 256 --pca eigen
row "iterative CPCA" --clusters 256 --method iterative
