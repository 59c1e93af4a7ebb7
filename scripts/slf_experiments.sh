#!/usr/bin/env bash
# Surface light field against PRT and an exact reference (docs/BENCHMARKS.md, "Surface light
# fields against a path-traced reference"): an icosphere (642 vertices, written here) in
# Cook-Torrance m 0.1 (specular 0.5, albedo 0.3) under the forest probe, seen by prtr's
# default camera at 320 x 240. Rows: prtr slf (256 x 256 texels, 32 x 16 directions, 16 paths
# a cell, reflected directions, K 256, k 8) shown by prtr render; PRT orders 6 and 10 (K 64, 8 PCs); a second
# 256-path reference (the reference's own noise). Each judged by prtr compare against a
# 4096-path prtr path-trace, over every covered pixel and over those 2 and 5 pixels inside
# the outline (prtr compare --erode: the grazing rim left out), and against the exact image: a
# second 4096-path reference of another seed takes the references' own noise out (prtr compare
# --second-reference). Writes OUT_DIR/table.md and OUT_DIR/side_by_side.png
# (reference | SLF | PRT 10 | PRT 6).
# Usage: [PROBE=PROBE] [MESH=MESH] scripts/slf_experiments.sh [OUT_DIR]  (default out/slf).
# PRTR: the binary. PROBE: the light probe (default the forest probe above). MESH: a mesh
# in place of the icosphere (e.g. /usr/share/glmark2/models/bunny.obj); its PRT rows use
# K 256 instead of 64, the SLF row is the same.
set -euo pipefail
cd "$(dirname "$0")/.."
prtr=${PRTR:-./build/prtr}
out=${1:-out/slf}
probe=${PROBE:-/usr/share/blender/datafiles/studiolights/world/forest.exr}
mkdir -p "$out"
material=(--material cook-torrance --roughness 0.1 --specular 0.5 --albedo 0.3)
view=(--width 320 --height 240)
mesh=${MESH:-}
clusters=256
if [[ -z $mesh ]]; then
  mesh=$out/sphere.obj
  clusters=64
  # An icosahedron split three times and pushed onto the unit sphere.
  python3 - "$mesh" <<'PY'
import math, sys
t = (1 + 5 ** 0.5) / 2
v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
     (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
unit = lambda p: tuple(c / math.sqrt(sum(x * x for x in p)) for c in p)
v = [unit(p) for p in v]
f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
     (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
     (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
for _ in range(3):
    middle, split = {}, []
    def mid(a, b):
        key = (min(a, b), max(a, b))
        if key not in middle:
            v.append(unit([(v[a][i] + v[b][i]) / 2 for i in range(3)]))
            middle[key] = len(v) - 1
        return middle[key]
    for a, b, c in f:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        split += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    f = split
with open(sys.argv[1], "w") as o:
    o.writelines("v %f %f %f\n" % p for p in v)
    o.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f)
PY
fi
name=$(basename "${mesh%.*}")
"$prtr" path-trace "$mesh" --probe "$probe" "${material[@]}" "${view[@]}" --spp 4096 --seed 3 \
  -o "$out/reference.exr" --png "$out/reference.png" -q
"$prtr" path-trace "$mesh" --probe "$probe" "${material[@]}" "${view[@]}" --spp 4096 --seed 4 \
  -o "$out/reference_seed4.exr" -q
"$prtr" path-trace "$mesh" --probe "$probe" "${material[@]}" "${view[@]}" --spp 256 --seed 2 \
  -o "$out/reference256.exr" -q
"$prtr" slf "$mesh" --probe "$probe" "${material[@]}" --samples 256x256 --directions 32x16 \
  --spp 16 --clusters 256 --pcs 8 --no-cache -o "$out/$name.slfc" -q | tee "$out/slf.txt"
"$prtr" render "$out/$name.slfc" --probe "$probe" "${view[@]}" -o "$out/slf.exr" \
  --png "$out/slf.png" -q
for n in 6 10; do
  "$prtr" bake "$mesh" "${material[@]}" --order $n --bounces 1 -o "$out/prt$n.prtx" -q
  "$prtr" compress "$out/prt$n.prtx" --mesh "$mesh" --clusters $clusters --pcs 8 -o "$out/prt$n.prtc" -q
  "$prtr" render "$out/prt$n.prtc" --probe "$probe" "${view[@]}" -o "$out/prt$n.exr" \
    --png "$out/prt$n.png" -q
done
{
  echo "| image | relative RMSE | 2 px inside the outline | 5 px inside | mean abs error | max abs error | against the exact image (all / 2 px / 5 px) |"
  echo "| --- | --- | --- | --- | --- | --- | --- |"
  for row in "slf:SLF, k 8, eta 256" "prt10:PRT order 10" "prt6:PRT order 6" \
             "reference256:path tracer, 256 paths"; do
    file=${row%%:*}; label=${row#*:}
    for erode in 0 2 5; do
      "$prtr" compare "$out/$file.exr" "$out/reference.exr" --erode $erode \
        --second-reference "$out/reference_seed4.exr" --json
    done |
      python3 -c 'import json,sys; d=[json.loads(l) for l in sys.stdin]; print("| %s | %.1f %% | %.1f %% | %.1f %% | %.4f | %.2f | %s %% |" % (sys.argv[1], *(100*e["relative_rmse"] for e in d), d[0]["mean_abs"], d[0]["max_abs"], " / ".join("%.1f" % (100*e["corrected_relative_rmse"]) for e in d)))' "$label"
  done
  for erode in 0 2 5; do
    "$prtr" compare "$out/reference.exr" "$out/reference.exr" --erode $erode \
      --second-reference "$out/reference_seed4.exr" --json
  done |
    python3 -c 'import json,sys; d=[json.loads(l) for l in sys.stdin]; print("\nOne 4096-path reference'"'"'s own noise (all / 2 px / 5 px): %s %%" % " / ".join("%.1f" % (100*e["reference_noise"]) for e in d))'
} | tee "$out/table.md"
oiiotool "$out/reference.png" "$out/slf.png" "$out/prt10.png" "$out/prt6.png" --mosaic 4x1 \
  -o "$out/side_by_side.png"
