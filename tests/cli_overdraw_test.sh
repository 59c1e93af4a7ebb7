#!/usr/bin/env bash
# End-to-end tests of `prtr overdraw`: its tables, CSV, JSON, plots and pictures, the bake and
# compression caches, the pass-designing rows and the pooled image RMSE (recomputed with prtr
# render and prtr compare), and its usage errors. Apart from cli_test.sh because its runs are
# half of that test's time (a quarter of an hour under the sanitizers); apart, the two run
# side by side. The plot script is checked when python3-matplotlib is installed, as
# scripts/setup.sh does, and reported as SKIP otherwise.
# Usage: cli_overdraw_test.sh PRTR TMPDIR JSON_CHECK PLOT_SCRIPT
set -u
prtr=$1
tmp=$2
json_check=$3
plot_script=$4
source "$(dirname "$0")/cli_lib.sh"
write_cube "$tmp/cube.obj"
forest=/usr/share/blender/datafiles/studiolights/world/forest.exr
if [[ ! -f $forest ]]; then
  skip "prtr overdraw ($forest is absent: apt-get install blender-data)"
  exit 77
fi

# prtr overdraw on the 8-vertex cube with tiny settings: tables, CSV, JSON, plot, pictures,
# the bake cache, and usage errors.
od=(overdraw "$tmp/cube.obj" --probe "$forest" --order 2 --samples 32 --bounces 0
    --clusters 2,4 --pcs 2 --rows original,both --strategies order,ils --frames 1 --warmup 0
    --rounds 2 --width 64 --height 48 --cache "$tmp/od_cache" --out "$tmp/od" -q)
run "${od[@]}"; expect_code 0; check "overdraw: tiny run exits 0 ($err)" $?
[[ $out == *"baked now, cached as"* ]]; check "overdraw: first run bakes and says it caches" $?
[[ $out =~ \|\ both\ \|\ ils\ \|\ [0-9.]+\ s\ \|\ 1\.[0-9]{6}\ \| ]]; check "overdraw: a table row for both/ils" $?
[[ $out == *"4 clusters, thesis budget"* && $out == *"4 clusters, default budget"* ]]; check "overdraw: both budgets tabled" $?
rows=$(($(wc -l <"$tmp/od/overdraw.csv") - 1))
[[ $rows == 16 ]]; check "overdraw: 2 K x 2 methods x 2 budgets x 2 strategies CSV rows (got $rows)" $?
[[ $(jget "$tmp/od/overdraw.json" /rows/15/strategy /modes/0/mode | tr '\n' ' ') == "ils "* ]]; check "overdraw: overdraw.json parses, 16 rows" $?
[[ $out == *"FPS (IQR) | GL ms (IQR)"* && $out == *"in each of 2 rounds"* ]]; check "overdraw: median and IQR over 2 interleaved rounds" $?
[[ $out =~ Across\ all\ 16\ rows.*GL\ ms\ =.*R\^2\ =\ [0-9.]+ ]]; check "overdraw: the GL ms vs overdraw fit is printed" $?
[[ $(head -1 "$tmp/od/overdraw-fit.csv") == quantity,slope,intercept,r2,points && $(grep -c ',16$' "$tmp/od/overdraw-fit.csv") == 3 ]]; check "overdraw: overdraw-fit.csv has the three fits over 16 rows" $?
[[ -n $(jget "$tmp/od/overdraw.json" /fits/gl_ms/r2) && $(jget "$tmp/od/overdraw.json" /rounds) == 2 ]]; check "overdraw: JSON carries the fits and rounds" $?
# PNG width and height from the IHDR chunk: 2 K panels side by side (1120 x 454); 3 timing
# panels in two rows (1120 x 874).
[[ $(od -An -tx1 -j16 -N8 "$tmp/od/overdraw-pareto.png" | tr -d ' \n') == 00000460000001c6 ]]; check "overdraw: the Pareto plot is a 1120 x 454 PNG" $?
[[ $(od -An -tx1 -j16 -N8 "$tmp/od/overdraw-timing.png" | tr -d ' \n') == 000004600000036a ]]; check "overdraw: the timing plot is a 1120 x 874 PNG" $?
for f in clusters-K4-original.png clusters-K4-both.png; do
  [[ -s $tmp/od/$f ]]; check "overdraw: wrote $f" $?
done
if have_matplotlib; then
  [[ $out == *"plot $tmp/od/overdraw-plot.png"* ]]; check "overdraw: runs the plot script" $?
  [[ $(head -c 8 "$tmp/od/overdraw-plot.png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]]; check "overdraw: the plot is a PNG" $?
  rm -f "$tmp/od/by-hand.png"
  /usr/bin/python3 "$plot_script" "$tmp/od/overdraw.json" -o "$tmp/od/by-hand.png" --budget default >/dev/null
  [[ $? == 0 && -s $tmp/od/by-hand.png ]]; check "plot_overdraw.py: plots the JSON, default budget" $?
  /usr/bin/python3 "$plot_script" "$tmp/od/overdraw.csv" --budget none 2>"$tmp/err"
  [[ $? == 1 && $(cat "$tmp/err") == *"no rows for budget 'none'"* ]]; check "plot_overdraw.py: a budget without rows exits 1 naming it" $?
  /usr/bin/python3 "$plot_script" 2>/dev/null; [[ $? == 2 ]]; check "plot_overdraw.py: no input is a usage error" $?
else
  skip "overdraw plot (python3-matplotlib is not installed)"
  [[ $out == *"apt-get install python3-matplotlib"* ]]; check "overdraw: says how to get the plot" $?
fi
# Pipeline statistics of each row: every referenced vertex is shaded at least once, and every
# triangle the cost model counts is submitted.
read -r vs_per_vertex prims drawn < <(jget "$tmp/od/overdraw.json" /rows/3/vs_per_referenced_vertex /rows/3/primitives /rows/3/triangles_drawn | tr '\n' ' ')
awk -v v="$vs_per_vertex" -v p="$prims" -v d="$drawn" 'BEGIN { exit !(v >= 1 && p >= d && d > 0) }'
check "overdraw: row work counters (VS per vertex $vs_per_vertex >= 1, primitives $prims >= drawn $drawn)" $?
run "${od[@]}" --json; expect_code 0 && [[ $(jget - /rows/0/clusters <<<"$out") == 2 ]]; check "overdraw --json: stdout parses" $?
ls "$tmp"/od/overdraw-K4-original-*-thesis.png >/dev/null 2>&1; check "overdraw: wrote the K=4 overdraw picture" $?
run "${od[@]}"; expect_code 0 && [[ $out == *"(cached: "* && $out == *"came from the cache"* ]]; check "overdraw: second run uses the cached bake and compressions" $?
# Pass-designing rows on glmark2's cat (3,582 vertices): compressed per budget, drawn in
# cluster order; patch-first's designed passes overdraw less than LBG's clusters in order.
cat3ds=/usr/share/glmark2/models/cat.3ds
if [[ -f $cat3ds ]]; then
  run overdraw "$cat3ds" --probe "$forest" --order 2 --samples 32 --bounces 0 --clusters 16 --pcs 2 \
    --rows original,patch-first,patch-joint,patch-eps --strategies order --budgets thesis --frames 1 --warmup 0 \
    --rounds 1 --width 64 --height 48 --no-modes --cache "$tmp/od_cache" --out "$tmp/odp" -q --json
  expect_code 0; check "overdraw: patch-first and patch-joint rows run ($err)" $?
  read -r m1 s1 o0 o1 o2 < <(jget - /rows/1/method /rows/1/strategy /rows/0/average_overdraw /rows/1/average_overdraw /rows/2/average_overdraw <<<"$out" | tr '\n' ' ')
  [[ $m1 == patch-first && $s1 == order ]]; check "overdraw: the patch-first row is drawn in designed (cluster) order" $?
  awk -v a="$o0" -v b="$o1" -v c="$o2" 'BEGIN { exit !(b < a && c < a && b >= 1 && c >= 1) }'
  check "overdraw: patch-first ($o1) and patch-joint ($o2) overdraw below original in order ($o0)" $?
  read -r se0 se3 o3 b3 < <(jget - /rows/0/average_se /rows/3/average_se /rows/3/average_overdraw /rows/3/overdraw_bound <<<"$out" | tr '\n' ' ')
  awk -v a="$se0" -v b="$se3" -v o="$o3" -v l="$b3" 'BEGIN { exit !(b <= a * (1 + 1e-6) && l >= 1 && l <= o) }'
  check "overdraw: patch-eps keeps Average SE ($se3) within original's ($se0), overdraw $o3 >= its bound $b3" $?
  # The image RMSE is pooled over --image-rotations environment rotations (37 + 120 k deg
  # here): recomputed from prtr render and prtr compare at each rotation.
  transfer=$(jget - /transfer <<<"$out")
  run overdraw "$cat3ds" --probe "$forest" --transfer "$transfer" --clusters 16 --pcs 2 --rows original \
    --strategies order --budgets thesis --frames 1 --warmup 0 --rounds 1 --width 64 --height 48 \
    --no-modes --image-rotations 3 --cache "$tmp/odr_cache" --out "$tmp/odr" -q --json
  expect_code 0; check "overdraw --image-rotations 3 runs ($err)" $?
  rmse=$(jget - /rows/0/image_rmse <<<"$out")
  prtc=$(ls "$tmp"/odr_cache/cpca-*.prtc)
  # prtr overdraw frames the bounding box's sphere (render::frame_sphere): the same camera.
  read -r eye target < <("$prtr" mesh "$cat3ds" | python3 -c 'import math,re,sys
t=sys.stdin.read(); b=[float(x) for x in re.search(r"min \((.*)\)  max \((.*)\)", t).group(1,2)[0].split(", ")+re.search(r"max \((.*)\)", t).group(1).split(", ")]
c=[(b[i]+b[i+3])/2 for i in range(3)]; r=math.dist(b[:3],b[3:])/2; ty=math.tan(math.radians(20)); s=ty/math.sqrt(1+ty*ty)
print("%r,%r,%r %r,%r,%r"%(c[0],c[1],c[2]+1.05*r/s,*c))')
  pooled=0
  for deg in 37 157 277; do
    rr=(render "$prtc" --probe "$forest" --mesh "$cat3ds" --width 64 --height 48 --supersample 1
        --background black --frames 1 --warmup 0 --spin-deg 0 --rotate-deg $deg --eye "$eye" --target "$target" -q)
    "$prtr" "${rr[@]}" -o "$tmp/odr/m.exr" && "$prtr" "${rr[@]}" --mode uncompressed --transfer "$transfer" -o "$tmp/odr/u.exr"
    pooled="$pooled $("$prtr" compare "$tmp/odr/m.exr" "$tmp/odr/u.exr" --coverage 0.5 --json)"
  done
  python3 -c 'import json,math,sys; r=[json.loads(x) for x in sys.argv[2:]]; n=sum(x["pixels"] for x in r); p=math.sqrt(sum(x["rmse"]**2*x["pixels"] for x in r)/n); sys.exit(abs(p-float(sys.argv[1]))>1e-3*p)' "$rmse" ${pooled#0 }
  check "overdraw: image RMSE ($rmse) is the RMSE pooled over 3 rotations of prtr render" $?
fi
run overdraw "$tmp/cube.obj" --probe "$forest" --rows bogus; expect_code 2 && [[ $err == *--rows* ]]; check "overdraw: unknown row is a usage error" $?
run overdraw "$tmp/cube.obj" --probe "$forest" --strategies best; expect_code 2 && [[ $err == *--strategies* ]]; check "overdraw: unknown strategy is a usage error" $?
run overdraw "$tmp/cube.obj" --probe "$forest" --clusters 0; expect_code 2; check "overdraw: --clusters 0 is a usage error" $?
# The transfer file is never read: the conflicting flags are refused first.
run overdraw "$tmp/cube.obj" --probe "$forest" --transfer "$tmp/absent.prtx" --order 3; expect_code 2 && [[ $err == *--order* ]]; check "overdraw: bake flag with --transfer is a usage error" $?

finish cli.overdraw
