#!/usr/bin/env bash
# A relit bunny frame as users first see it: anti-aliased by default (partly covered pixels
# along the silhouette), not with --supersample 1 (coverage only 0 or 1), and no fully
# covered pixel far darker than its covered neighbours (scripts/frame_quality.py). Small
# bake, compression and frame, so it runs in seconds.
# Usage: frame_quality_test.sh PRTR TMPDIR FRAME_QUALITY_PY (skips without the inputs)
set -euo pipefail
prtr=$1 tmp=$2 quality=$3
bunny=/usr/share/glmark2/models/bunny.obj
probe=/usr/share/blender/datafiles/studiolights/world/forest.exr
py=/usr/bin/python3  # Debian's, with numpy (python3-matplotlib pulls it in)
if [[ ! -f $bunny || ! -f $probe ]] || ! "$py" -c 'import numpy' 2>/dev/null; then
  echo "skipped: needs glmark2-data, blender-data and python3-numpy"
  exit 0
fi
rm -rf "$tmp" && mkdir -p "$tmp"
small=(--probe "$probe" --frames 1 --width 400 --height 300 --kind glossy --order 4
       --samples 128 --bounces 0 --clusters 32 --pcs 4 --no-video --quiet --cache "$tmp/cache")

field() { "$py" -c "import json,sys; print(json.load(sys.stdin)['$1'])"; }

"$prtr" relight "$bunny" "${small[@]}" --out "$tmp/aa" >"$tmp/aa.log"
aa=$("$py" "$quality" "$tmp/aa/frame_0000.exr")
echo "default:         $aa"
"$prtr" relight "$bunny" "${small[@]}" --out "$tmp/plain" --supersample 1 >"$tmp/plain.log"
plain=$("$py" "$quality" "$tmp/plain/frame_0000.exr")
echo "--supersample 1: $plain"

fail=0
# The bunny's outline at 400 x 300 is some 1,000 pixels long; most of them are cut by it.
(($(field partial <<<"$aa") >= 300)) || { echo "FAIL: too few anti-aliased pixels"; fail=1; }
(($(field partial <<<"$plain") == 0)) || { echo "FAIL: --supersample 1 still filters"; fail=1; }
for run in "$aa" "$plain"; do
  (($(field dots <<<"$run") <= 2)) || { echo "FAIL: dark dots on the bunny"; fail=1; }
done
grep -q '^anti-alias ' "$tmp/aa.log" || { echo "FAIL: no anti-alias line"; fail=1; }
exit $fail
