#!/usr/bin/env bash
# Overdraw experiments at the thesis budget (3 clusters per pass) on meshes of different kinds,
# tuned on some and reported on the others (docs/BENCHMARKS.md, "Overdraw on meshes it was not
# tuned on"):
#   bunny      glmark2-data, a range scan (34,835 vertices)          tuning: patch-eps was set here
#   cat        glmark2-data, a character, Loop-subdivided once (29,027 vertices)   held out
#   horse      glmark2-data horse.3ds, welded on load (a low-poly model with creases) held out
#   asteroid   glmark2-data asteroid-high.3ds, a rock (procedural, faceted)         held out
# Each mesh: glossy Phong order 6, 1 bounce, forest probe, 8 PCs, alpha 0.05 for the coherence
# rows; K = 128 and 256; rows original, the thesis's overdraw reduction and "both", patch-joint
# (the fixed setting tuned on the bunny) and patch-eps (the epsilon constraint, --epsilon 0),
# the thesis's rows grouped by ILS (their best strategy), all at 640 x 474 to keep a run short
# on a shared machine. Every row reports its clustering time and its overdraw bound. One
# prtr overdraw run per mesh, under nice, so clustering times compare within a run only.
#
# Usage: scripts/overdraw_experiments.sh [OUT_DIR]   (default out/experiments)
# Knobs (environment): RUNS (bunny cat horse asteroid: a subset re-runs only those), CLUSTERS
# (128,256), ROWS, STRATEGIES (ils), ROUNDS (1), FRAMES (1), WIDTH (640), HEIGHT (474), PRTR
# (./build/prtr; a copy keeps a rebuild from replacing the binary mid-run), CACHE
# (out/cache), NICE (10). Bakes and compressions are cached, so a second
# run only re-times. Writes OUT_DIR/<run>.md (the tables), OUT_DIR/<run>/ (CSV, JSON, plots)
# and OUT_DIR/summary.md (scripts/overdraw_summary.py's condensed tables, then the full ones).
set -euo pipefail
cd "$(dirname "$0")/.."
prtr=${PRTR:-./build/prtr}
out=${1:-out/experiments}
probe=/usr/share/blender/datafiles/studiolights/world/forest.exr
models=/usr/share/glmark2/models
cat_mesh=out/meshes/cat-sub1.ply
for f in "$prtr" "$probe" "$models/bunny.obj" "$models/cat.3ds" "$models/horse.3ds" \
  "$models/asteroid-high.3ds"; do
  [[ -e $f ]] || { echo "overdraw_experiments: $f is missing; run scripts/setup.sh first" >&2; exit 1; }
done
mkdir -p "$out" out/meshes
[[ -f $cat_mesh ]] || nice -n "${NICE:-10}" $prtr mesh "$models/cat.3ds" --subdivide 1 -o "$cat_mesh" >&2

common=(--probe "$probe" --cache "${CACHE:-out/cache}" --clusters "${CLUSTERS:-128,256}" --pcs 8
        --alpha 0.05 --rows "${ROWS:-original,overdraw-reduction,both,patch-joint,patch-eps}"
        --strategies "${STRATEGIES:-ils}" --budgets thesis --material phong
        --rounds "${ROUNDS:-1}" --frames "${FRAMES:-1}" --warmup 1 --no-modes
        --width "${WIDTH:-640}" --height "${HEIGHT:-474}")
all=(bunny cat horse asteroid)
read -r -a runs <<<"${RUNS:-${all[*]}}"
run() {  # run NAME MESH
  local name=$1 mesh=$2
  [[ " ${runs[*]} " == *" $name "* ]] || return 0
  echo "overdraw_experiments: $name (load average $(cut -d' ' -f1-3 /proc/loadavg))" >&2
  nice -n "${NICE:-10}" $prtr overdraw "$mesh" "${common[@]}" --out "$out/$name" -q \
    >"$out/$name.md.tmp"
  mv "$out/$name.md.tmp" "$out/$name.md"
}
run bunny "$models/bunny.obj"
run cat "$cat_mesh"
run horse "$models/horse.3ds"
run asteroid "$models/asteroid-high.3ds"
summary=$out/summary.md
{
  echo "# Overdraw experiments (written $(date -u +%Y-%m-%dT%H:%MZ))"
  echo
  echo "Per K and method, the lowest-overdraw strategy (scripts/overdraw_summary.py):"
  echo
  present=()
  for name in "${all[@]}"; do [[ -f $out/$name/overdraw.json ]] && present+=("$out/$name"); done
  python3 scripts/overdraw_summary.py "${present[@]}" --budget thesis
  echo "# Full tables"
  for name in "${all[@]}"; do
    [[ -f $out/$name.md ]] && { echo; echo "## $name"; echo; cat "$out/$name.md"; }
  done
} >"$summary.tmp"
mv "$summary.tmp" "$summary"
echo "overdraw_experiments: wrote $summary" >&2
