#!/usr/bin/env bash
# End-to-end tests of the prtr binary: exit codes (0 ok, 1 failure, 2 usage), error messages
# that name the input, and values parsed from the output (a pattern that matches nothing is
# a failure, never a pass). JSON is parsed by json_check (nlohmann, as prtr writes it); the
# MP4 is checked when ffmpeg is installed, as scripts/setup.sh does, and reported as SKIP
# otherwise.
# Usage: cli_test.sh PRTR TMPDIR JSON_CHECK
set -u
prtr=$1
tmp=$2
json_check=$3
# The numeric flag sweep (cli_flags_test.sh) and prtr overdraw (cli_overdraw_test.sh) are tests
# of their own, so that they run side by side with this one.
source "$(dirname "$0")/cli_lib.sh"

# Usage.
run --help; expect_code 0; check "--help exits 0" $?
run; expect_code 2; check "no subcommand exits 2" $?
run frobnicate; expect_code 2; check "unknown subcommand exits 2" $?
run probe x.exr --order 11; expect_code 2; check "order 11 is a usage error" $?
run probe x.exr --order 0; expect_code 2; check "order 0 is a usage error" $?
run mesh a.obj --bogus; expect_code 2; check "unknown flag exits 2" $?


# Image I/O lives in a module loaded on first use: prtr itself links no OpenImageIO, commands
# that touch no image run without the module, and one that needs it says what is missing.
if command -v readelf >/dev/null; then
  ! readelf -d "$prtr" | grep -q 'NEEDED.*OpenImageIO'; check "prtr links no OpenImageIO" $?
else
  skip "prtr links no OpenImageIO (no readelf)"
fi
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/tri.obj"
out=$(PRTR_IMAGE_MODULE=/nonexistent/libprtr_oiio.so "$prtr" mesh "$tmp/tri.obj" 2>&1); code=$?
expect_code 0; check "a command without images runs without the image module" $?
: >"$tmp/missing_module.exr"
out=$(PRTR_IMAGE_MODULE=/nonexistent/libprtr_oiio.so "$prtr" probe "$tmp/missing_module.exr" 2>&1)
code=$?
expect_code 1 && [[ $out == *"image module /nonexistent/libprtr_oiio.so"*PRTR_IMAGE_MODULE* ]]
check "a missing image module exits 1 naming it and the fix" $?

# Failures name the input.
run mesh "$tmp/missing.obj"; expect_code 1 && [[ $err == *missing.obj* ]]; check "missing mesh exits 1 naming it" $?
: >"$tmp/empty.obj"
run mesh "$tmp/empty.obj"; expect_code 1 && [[ $err == *empty.obj* ]]; check "empty mesh exits 1 naming it" $?
run probe "$tmp/missing.exr"; expect_code 1 && [[ $err == *missing.exr* ]]; check "missing probe exits 1 naming it" $?
echo "not an image" >"$tmp/garbage.exr"
run probe "$tmp/garbage.exr"; expect_code 1 && [[ $err == *garbage.exr* ]]; check "corrupt probe exits 1 naming it" $?

# A quad written as OBJ: 4 vertices, 2 triangles, 1 polygon triangulated.
printf 'v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n' >"$tmp/quad.obj"
run mesh "$tmp/quad.obj"; expect_code 0; check "quad loads" $?
[[ $out =~ result\ +4\ vertices,\ 2\ triangles ]]; check "quad: 4 vertices, 2 triangles" $?
[[ $out =~ \(1\ polygons\ triangulated\) ]]; check "quad: 1 polygon triangulated" $?
[[ $out =~ area\ +1($|[^0-9]) ]]; check "quad: area 1" $?

# Bake: a closed cube (inward-facing faces would also work; any mesh does).
write_cube "$tmp/cube.obj"
run bake "$tmp/cube.obj" -o "$tmp/cube.prtx" --order 3 --samples 64 --bounces 1 --quiet
expect_code 0; check "bake exits 0" $?
[[ $(head -c 8 "$tmp/cube.prtx" 2>/dev/null) == PRTRXFER ]]; check "bake writes a .prtx file" $?
size=$(stat -c %s "$tmp/cube.prtx" 2>/dev/null || echo 0)
((size == 128 + 8 * 81 * 4)); check "bake file size: header + 8 vertices x 81 floats ($size)" $?
[[ $out =~ rays\ +[0-9.]+\ M ]]; check "bake reports rays" $?
run info "$tmp/cube.prtx" --mesh "$tmp/cube.obj" --verify
expect_code 0 && [[ $out =~ order\ 3 ]] && [[ $out == *current* ]]; check "info: order 3, current against its mesh" $?
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/tri.obj"
run info "$tmp/cube.prtx" --mesh "$tmp/tri.obj"
expect_code 1 && [[ $out == *STALE* ]] && [[ $err == *cube.prtx* ]]; check "info: stale against another mesh exits 1" $?
head -c 100 "$tmp/cube.prtx" >"$tmp/cut.prtx"
run info "$tmp/cut.prtx"; expect_code 1 && [[ $err == *cut.prtx* ]]; check "info: truncated file exits 1 naming it" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --order 11; expect_code 2; check "bake --order 11 is a usage error" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --material lambert --exponent 8
expect_code 2 && [[ $err == *--exponent* ]]; check "bake: --exponent with lambert is a usage error" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --albedo 0.5,0.5; expect_code 2; check "bake: --albedo with two values is a usage error" $?
run info "$tmp/cube.prtx"
expect_code 0 && [[ $out =~ view\ fit\ +least-squares ]]; check "info: the default view fit is least-squares" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --view-fit hsh; expect_code 2; check "bake: --view-fit hsh (benchmarks only) is a usage error" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --kind diffuse --view-fit even
expect_code 2 && [[ $err == *--view-fit* ]]; check "bake: --view-fit with --kind diffuse is a usage error" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --material phong --masking v-groove
expect_code 2 && [[ $err == *--masking* ]]; check "bake: --masking with phong is a usage error" $?
run bake "$tmp/cube.obj" -o "$tmp/ct.prtx" --order 2 --samples 16 --bounces 0 --material cook-torrance --masking v-groove --view-fit hemisphere --quiet
run info "$tmp/ct.prtx"
expect_code 0 && [[ $out == *"masking v-groove"* ]] && [[ $out =~ view\ fit\ +hemisphere ]]; check "info: masking and view fit as baked" $?
# A version-1 file (the thesis's projection) is refused, not re-read: patch the version and
# reseal nothing (the version check comes first).
cp "$tmp/ct.prtx" "$tmp/v1.prtx" && printf '\x01' | dd of="$tmp/v1.prtx" bs=1 seek=8 conv=notrunc status=none
run info "$tmp/v1.prtx"
expect_code 1 && [[ $err == *v1.prtx* ]] && [[ $err == *"older prtr version"* ]]; check "info: a version 1 .prtx is refused naming it" $?
run bake "$tmp/cube.obj" -o "$tmp/x.prtx" --albedo 0.9 --specular 0.5
expect_code 2 && [[ $err == *--specular* || $err == *--albedo* ]]; check "bake: albedo + specular > 1 is a usage error" $?
run bake "$tmp/missing.obj" -o "$tmp/x.prtx"; expect_code 1 && [[ $err == *missing.obj* ]]; check "bake: missing mesh exits 1 naming it" $?
run bake "$tmp/cube.obj" -o "$tmp/no/such/dir/x.prtx" --order 2 --samples 16 --quiet
expect_code 1 && [[ $err == *x.prtx* ]]; check "bake: missing output directory exits 1 naming it" $?
leftovers=$(find "$tmp" -name '*.tmp-*' | wc -l)
((leftovers == 0)); check "bake leaves no temporary files ($leftovers)" $?
[[ ! -e $tmp/x.prtx ]]; check "failed bakes leave no output" $?

# Compress the cube bake (8 vertices, 81 numbers each) and describe the result.
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/cube.prtc" --clusters 2 --pcs 2 -q
expect_code 0; check "compress exits 0" $?
[[ $(head -c 8 "$tmp/cube.prtc" 2>/dev/null) == PRTRCMPR ]]; check "compress writes a .prtc file" $?
[[ $out =~ Average\ SE\ [0-9.e+-]+ ]]; check "compress reports the Average SE" $?
[[ $out =~ clusters\ 2\ x\ 2\ PCs ]]; check "compress reports clusters x PCs" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/cube8.prtc" --clusters 8 --pcs 1 --json -q
# One vertex per cluster reconstructs exactly and the energy is summed in double, so the
# error is exactly zero, not merely small.
errors=$(jget - /average_se /relative_error /clusters /method <<<"$out" | tr '\n' ' ')
[[ $errors == "0.0 0.0 8 "* ]]; check "compress --json parses: clusters = vertices gives exactly zero error ($errors)" $?
run info "$tmp/cube.prtc" --mesh "$tmp/cube.obj" --transfer "$tmp/cube.prtx" --verify
expect_code 0 && [[ $out == *current* && $out != *STALE* ]]; check "info: .prtc current against its mesh and bake" $?
run info "$tmp/cube.prtc" --mesh "$tmp/quad.obj"; expect_code 1 && [[ $out == *STALE* ]]; check "info: .prtc stale against another mesh" $?
run info "$tmp/cube.prtc" --mesh "$tmp/quad.obj" --json
expect_code 1 && [[ $(jget - /format /checks/0/status <<<"$out" | tr '\n' ' ') == "prtc stale " ]]; check "info --json: .prtc stale against another mesh, as JSON" $?

# An output never destroys an input, another output or a special file (common/output_path.h):
# usage errors naming the flag, before any work, and the input is left as it was.
before=$(cksum <"$tmp/cube.obj")
run bake "$tmp/cube.obj" -o "$tmp/cube.obj" --order 2 --samples 16 -q
expect_code 2 && [[ $err == *"-o"*"is the input MESH"* ]] && [[ $(cksum <"$tmp/cube.obj") == "$before" ]]
check "bake -o MESH is refused and the mesh is kept" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/cube.prtx" --clusters 2 --pcs 2 -q
expect_code 2 && [[ $err == *"is the input TRANSFER"* ]] && [[ $(head -c 8 "$tmp/cube.prtx") == PRTRXFER ]]
check "compress -o TRANSFER is refused and the bake is kept" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/cube.obj" --clusters 2 --pcs 2 -q
expect_code 2 && [[ $err == *"is the input --mesh"* ]]; check "compress -o MESH is refused" $?
run bake "$tmp/cube.obj" -o /dev/null --order 2 --samples 16 -q
expect_code 2 && [[ $err == *"character device"* ]] && [[ -c /dev/null ]]; check "bake -o /dev/null is refused and /dev/null stays a device" $?
mkfifo "$tmp/fifo" && run bake "$tmp/cube.obj" -o "$tmp/fifo" --order 2 --samples 16 -q
expect_code 2 && [[ $err == *FIFO* ]] && [[ -p $tmp/fifo ]]; check "bake -o FIFO is refused and the FIFO stays" $?
ln -sf "$tmp/elsewhere.prtx" "$tmp/link.prtx" && run bake "$tmp/cube.obj" -o "$tmp/link.prtx" --order 2 --samples 16 -q
expect_code 2 && [[ $err == *"symbolic link"* ]] && [[ -L $tmp/link.prtx ]]; check "bake -o SYMLINK is refused and the link stays" $?
run render "$tmp/cube.prtc" --mesh "$tmp/cube.obj" --probe x.exr -o "$tmp/r.exr" --png "$tmp/r.exr"
expect_code 2 && [[ $err == *"--png and -o both name"* ]]; check "render -o X --png X is refused" $?
run mesh "$tmp/cube.obj" -o "$tmp/cube.obj"; expect_code 2; check "mesh -o MESH is refused" $?
for bad in nan,0,0 0,inf,0 1e300,0,0; do
  run render "$tmp/cube.prtc" --mesh "$tmp/cube.obj" --probe x.exr -o "$tmp/r.exr" --background "$bad"
  expect_code 2 && [[ $err == *--background* ]]; check "render --background $bad is a usage error" $?
done
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 9
expect_code 2 && [[ $err == *--clusters* ]]; check "compress: more clusters than vertices is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --pcs 81
expect_code 2 && [[ $err == *--pcs* ]]; check "compress: PCs >= dimension is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --method kmeans; expect_code 2; check "compress: unknown method is a usage error" $?
for m in patch-first joint patch-joint; do
  run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/pf.prtc" --clusters 4 --pcs 1 --method $m --clusters-per-pass 2 -q
  expect_code 0 && [[ $(head -c 8 "$tmp/pf.prtc" 2>/dev/null) == PRTRCMPR ]]; check "compress --method $m writes a .prtc" $?
done
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --lambda 1
expect_code 2 && [[ $err == *--lambda* ]]; check "compress: --lambda without a joint method is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --method joint --lambda nan
expect_code 2 && [[ $err == *--lambda* ]]; check "compress: --lambda nan is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --overdraw-cap 1.2
expect_code 2 && [[ $err == *--overdraw-cap* ]]; check "compress: --overdraw-cap without a joint method is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --method joint --overdraw-cap 0.5
expect_code 2 && [[ $err == *--overdraw-cap* ]]; check "compress: --overdraw-cap below 1 is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/pc.prtc" --clusters 4 --pcs 1 --method patch-joint --clusters-per-pass 2 --lambda 0.5 --overdraw-cap 1.1 -q
expect_code 0 && [[ $(head -c 8 "$tmp/pc.prtc" 2>/dev/null) == PRTRCMPR ]]; check "compress --method patch-joint --overdraw-cap writes a .prtc" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --method joint --alpha 1
expect_code 2 && [[ $err == *--alpha* ]]; check "compress: joint with --alpha is a usage error" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --clusters 2 --clusters-per-pass 2
expect_code 2 && [[ $err == *--clusters-per-pass* ]]; check "compress: --clusters-per-pass with lbg is a usage error" $?
run compress "$tmp/missing.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc"
expect_code 1 && [[ $err == *missing.prtx* ]]; check "compress: missing transfer exits 1 naming it" $?
run compress "$tmp/cube.prtx" --mesh "$tmp/quad.obj" -o "$tmp/y.prtc" --clusters 2
expect_code 1 && [[ $err == *quad.obj* ]]; check "compress: the wrong mesh exits 1 naming it" $?
[[ ! -e $tmp/y.prtc ]]; check "failed compressions leave no output" $?
head -c 100 "$tmp/cube.prtc" >"$tmp/short.prtc"
run info "$tmp/short.prtc"; expect_code 1 && [[ $err == *short.prtc* ]]; check "info: truncated .prtc exits 1 naming it" $?

# The real inputs, when installed.
bunny=/usr/share/glmark2/models/bunny.obj
if [[ -f $bunny ]]; then
  run mesh "$bunny"; expect_code 0; check "bunny loads" $?
  [[ $out =~ result\ +([0-9]+)\ vertices,\ ([0-9]+)\ triangles ]]; check "bunny: counts printed" $?
  v=${BASH_REMATCH[1]:-0}; t=${BASH_REMATCH[2]:-0}
  ((v > 34000 && v <= 34835)); check "bunny: ~34.8k vertices (got $v)" $?
  ((t > 69000 && t <= 69666)); check "bunny: ~69.7k triangles (got $t)" $?
fi
forest=/usr/share/blender/datafiles/studiolights/world/forest.exr
if [[ -f $forest ]]; then
  run probe "$forest" --order 6; expect_code 0; check "forest loads" $?
  rows=$(grep -cE '^ +[0-9]+ +-?[0-9]+ +[-0-9.e+]+ +[-0-9.e+]+ +[-0-9.e+]+$' <<<"$out")
  [[ $rows == 36 ]]; check "forest: 36 coefficient rows (got $rows)" $?
  dc=$(awk '$1 == 0 && $2 == 0 {print $3}' <<<"$out")
  awk -v x="${dc:-0}" 'BEGIN { exit !(x > 0) }'; check "forest: positive DC term ($dc)" $?
  [[ $out =~ 1024\ x\ 512 ]]; check "forest: 1024 x 512" $?
fi

run gl-info; expect_code 0 && [[ $out == *"Core"* || $out == *"core profile"* ]]; check "gl-info: core context" $?
run gl-info --gl egl; expect_code 0 && [[ $out == *"egl device  0"* && $out == *"backend     egl device"* ]]
check "gl-info --gl egl: lists EGL devices and renders on one" $?
run gl-info --gl foo; expect_code 2 && [[ $err == *"--gl"* ]]; check "--gl foo exits 2 naming the flag" $?
run gl-info --gl egl --gl-device 99; expect_code 2 && [[ $err == *"--gl-device 99"* ]]
check "an EGL device out of range exits 2 naming it" $?
out=$(PRTR_GL=foo "$prtr" gl-info 2>&1); [[ $? == 2 && $out == *PRTR_GL* ]]; check "PRTR_GL=foo exits 2 naming it" $?

# prtr relight on the cube at 64 x 32 (2:1, so prtr probe can decode the frames as lat-long
# maps and report their mean): outputs exist, decode, are lit; the second run is cached.
if [[ -f $forest ]]; then
  rl=(relight "$tmp/cube.obj" --probe "$forest" --order 2 --samples 32 --bounces 0 --clusters 2
      --pcs 2 --frames 3 --width 64 --height 32 --background black --cache "$tmp/rl_cache"
      --out "$tmp/rl" -q)
  run "${rl[@]}"; expect_code 0; check "relight: exits 0 ($err)" $?
  # The animations, decoded by another program than the one that wrote them.
  if command -v ffprobe >/dev/null; then
    info=$(media_info "$tmp/rl/relight.gif"); [[ $info == 64,32,3 ]]; check "relight: GIF is 64 x 32, 3 frames ($info)" $?
    info=$(media_info "$tmp/rl/relight.mp4"); [[ $info == 64,32,3 ]]; check "relight: MP4 is 64 x 32, 3 frames ($info)" $?
  else
    skip "relight animations decoded (ffmpeg is not installed)"
    [[ $(head -c 6 "$tmp/rl/relight.gif") == GIF89a && $out == *"apt-get install ffmpeg"* ]]; check "relight: GIF without ffmpeg, and how to get the MP4" $?
  fi
  [[ -z $(find "$tmp/rl" -name '.*tmp-*') ]]; check "relight: no temporary files left" $?
  [[ $out == *"bake        baked"* && $out == *"compress    compressed"* ]]; check "relight: first run bakes and compresses" $?
  [[ $out =~ contact\ sheet:\ (.*contact_sheet.png) && -s ${BASH_REMATCH[1]} ]]; check "relight: prints the contact sheet's path" $?
  [[ $(head -c 8 "$tmp/rl/contact_sheet.png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]]; check "relight: contact sheet is a PNG" $?
  for f in 0 1 2; do
    run probe "$tmp/rl/frame_000$f.exr" --order 1; expect_code 0; check "relight: frame $f EXR decodes" $?
    [[ $out =~ mean\ +\(([0-9.e+-]+), ]] && awk -v m="${BASH_REMATCH[1]}" 'BEGIN { exit !(m > 0.001) }'; check "relight: frame $f is lit (mean ${BASH_REMATCH[1]:-none})" $?
    run probe "$tmp/rl/frame_000$f.png" --order 1; expect_code 0; check "relight: frame $f PNG decodes" $?
  done
  [[ ! -e $tmp/rl/frame_0003.exr ]]; check "relight: exactly 3 frames" $?
  run "${rl[@]}"; expect_code 0 && [[ $out == *"bake        cached"* && $out == *"compress    cached"* ]]; check "relight: second run uses the cache" $?
  for entry in "$tmp"/rl_cache/cpca-*.prtc; do head -c 200 "$entry" >"$entry.cut" && mv "$entry.cut" "$entry"; done
  run "${rl[@]}"; expect_code 0 && [[ $err == *unusable* && $out == *"compress    compressed"* ]]; check "relight: a damaged cache entry is reported and rebuilt" $?
  # Payload damage (one flipped byte past the header) is found by the full read, reported,
  # removed and rebuilt, in every combination of entries; the run succeeds, and the next one
  # finds a sound cache.
  flip() {  # flip FILE OFFSET: invert one byte in place
    local b; b=$(od -An -tu1 -j "$2" -N1 "$1" | tr -d ' ')
    printf "\\$(printf %03o $((b ^ 255)))" | dd of="$1" bs=1 seek="$2" conv=notrunc status=none
  }
  for entry in "$tmp"/rl_cache/cpca-*.prtc; do flip "$entry" $(($(stat -c %s "$entry") - 3)); done
  run "${rl[@]}"; expect_code 0 && [[ $err == *unusable*payload* && $out == *"bake        cached"* && $out == *"compress    compressed"* ]]; check "relight: a damaged .prtc payload is rebuilt ($err)" $?
  run "${rl[@]}"; expect_code 0 && [[ $out == *"compress    cached"* && $err != *unusable* ]]; check "relight: the rebuilt .prtc is used" $?
  # The summary beside a cached compression is one JSON object, read back with the JSON
  # library: a hostile one is damage like any other, reported and rebuilt. First valid JSON
  # whose value is a string of quotes, backslashes and a control character, then raw control
  # and non-UTF-8 bytes that are no JSON at all.
  summaries=("$tmp"/rl_cache/cpca-*.summary)
  v=$(jget "${summaries[0]}" /relative_error) && awk -v v="$v" 'BEGIN { exit !(v > 0) }'; check "relight: the cached .summary is JSON ($v)" $?
  printf '{"clustering_seconds": "\\"\\\\\\u0001", "average_se": 1, "relative_error": 1}' >"${summaries[0]}"
  run "${rl[@]}"; expect_code 0 && [[ $err == *unusable*summary*clustering_seconds* && $out == *"compress    compressed"* ]]; check "relight: a .summary holding a hostile string is reported and rebuilt ($err)" $?
  printf '{"clustering_seconds": "\001\377\376", "average_se": 1, "relative_error": 1}' >"${summaries[0]}"
  run "${rl[@]}"; expect_code 0 && [[ $err == *unusable*summary* && $out == *"compress    compressed"* ]]; check "relight: a .summary of raw control and non-UTF-8 bytes is reported and rebuilt ($err)" $?
  v=$(jget "${summaries[0]}" /average_se) && awk -v v="$v" 'BEGIN { exit !(v > 0) }'; check "relight: the rebuilt .summary is JSON again ($v)" $?
  run "${rl[@]}"; expect_code 0 && [[ $out == *"compress    cached"* && $err != *unusable* ]]; check "relight: the rebuilt .summary is used" $?
  # A bake of other settings copied over the entry's name (the name is only a hash) is
  # reported and rebaked, not used.
  "$prtr" bake "$tmp/cube.obj" -o "$tmp/other16.prtx" --order 2 --samples 16 --bounces 0 -q >/dev/null
  bakes=("$tmp"/rl_cache/bake-*.prtx)
  cp "$tmp/other16.prtx" "${bakes[0]}"
  run "${rl[@]}"; expect_code 0 && [[ $err == *unusable*"16 samples"* && $out == *"bake        baked"* ]]; check "relight: a cached bake whose header differs from its key is rebaked ($err)" $?
  # A damaged bake payload is not read while its compression is cached (the compression's key
  # holds the bake's checksum), and is found and rebaked when the compression is rebuilt.
  for entry in "$tmp"/rl_cache/bake-*.prtx; do flip "$entry" 200; done
  run "${rl[@]}"; expect_code 0 && [[ $out == *"bake        cached"* && $out == *"compress    cached"* && $err != *unusable* ]]; check "relight: a damaged .prtx payload is not read while its .prtc is cached" $?
  rm -f "$tmp"/rl_cache/cpca-*
  run "${rl[@]}"; expect_code 0 && [[ $err == *unusable*payload* && $out == *"bake        baked"* && $out == *"compress    compressed"* ]]; check "relight: a damaged .prtx payload without its .prtc is rebuilt ($err)" $?
  run "${rl[@]}"; expect_code 0 && [[ $out == *"bake        cached"* && $out == *"compress    cached"* && $err != *unusable* ]]; check "relight: the repaired cache is used without complaint" $?

  # Temporaries of a killed run: those of a process that is gone are swept at the start, from
  # the cache and from the folder an output is written to; a live writer's are left alone.
  bash -c 'exit 0' & gone=$!; wait $gone
  printf 'partial' >"$tmp/rl_cache/.bake-0123.prtx.tmp-$gone-77"
  printf 'partial' >"$tmp/rl_cache/.cpca-0123.prtc.tmp-$$-78"
  run "${rl[@]}"; expect_code 0 && [[ ! -e $tmp/rl_cache/.bake-0123.prtx.tmp-$gone-77 && -e $tmp/rl_cache/.cpca-0123.prtc.tmp-$$-78 && $err == *"interrupted run"* ]]; check "relight: stale cache temporaries swept, live ones kept" $?
  rm -f "$tmp/rl_cache/.cpca-0123.prtc.tmp-$$-78"
  # Image temporaries (named with the writer's pid and the extension) in the --out folder.
  printf 'partial' >"$tmp/rl/.frame_0000.exr.tmp-$gone-5.exr"
  printf 'partial' >"$tmp/rl/.frame_0001.png.tmp-$$-6.png"
  run "${rl[@]}"; expect_code 0 && [[ ! -e $tmp/rl/.frame_0000.exr.tmp-$gone-5.exr && -e $tmp/rl/.frame_0001.png.tmp-$$-6.png && $err == *".frame_0000.exr.tmp-$gone-5.exr, left by an interrupted run"* ]]; check "relight: stale image temporaries in --out swept at start, live ones kept ($err)" $?
  rm -f "$tmp/rl/.frame_0001.png.tmp-$$-6.png"
  mkdir -p "$tmp/outdir" && printf 'partial' >"$tmp/outdir/.old.prtx.tmp-$gone-5"
  run bake "$tmp/cube.obj" -o "$tmp/outdir/cube.prtx" --order 2 --samples 16 --bounces 0 --quiet
  expect_code 0 && [[ ! -e $tmp/outdir/.old.prtx.tmp-$gone-5 && -s $tmp/outdir/cube.prtx ]]; check "bake: stale temporaries in the output folder swept" $?
  run relight "$tmp/missing.obj" --probe "$forest" --out "$tmp/rl2"; expect_code 1 && [[ $err == *missing.obj* ]]; check "relight: missing mesh exits 1 naming it" $?
  run relight "$tmp/cube.obj" --probe "$tmp/garbage.exr" --clusters 2 --out "$tmp/rl2"; expect_code 1 && [[ $err == *garbage.exr* ]]; check "relight: unreadable probe exits 1 naming it" $?
  ! ls "$tmp"/rl2/frame_* >/dev/null 2>&1; check "relight: failures leave no frames" $?
  run relight "$tmp/cube.obj" --probe "$forest" --clusters 9 --order 2; expect_code 2 && [[ $err == *--clusters* ]]; check "relight: clusters > vertices is a usage error" $?
  run relight "$tmp/cube.obj" --probe "$forest" --clusters 2 --order 2 --pcs 16; expect_code 2 && [[ $err == *--pcs* ]]; check "relight: PCs >= dimension is a usage error" $?
  run relight "$tmp/cube.obj" --probe "$forest" --order 0; expect_code 2; check "relight: order 0 is a usage error" $?
  run relight "$tmp/cube.obj" --probe "$forest" --order 11; expect_code 2; check "relight: order 11 is a usage error" $?
  run relight "$tmp/cube.obj" --probe "$forest" --axis 0,0,0; expect_code 2 && [[ $err == *--axis* ]]; check "relight: zero axis is a usage error" $?
  # --camera-orbit: the camera turns about --axis (default vertical) through the mesh's centre
  # under fixed lighting, a quarter turn a frame here: frame 1 is prtr render of the same
  # compressed set from the eye turned by 90 degrees (right-handed: (0,1,5) to (5,1,0)).
  run relight "$tmp/cube.obj" --probe "$forest" --camera-orbit --eye 0,1,5 --order 2 --samples 32 --bounces 0 \
    --clusters 2 --pcs 2 --frames 4 --width 32 --height 24 --background black --exr-pixels float \
    --cache "$tmp/orbit_cache" --out "$tmp/orbit" --no-video -q
  expect_code 0 && [[ $out == *"camera orbits"* ]]; check "relight --camera-orbit exits 0 ($err)" $?
  orbit_set=("$tmp"/orbit_cache/cpca-*.prtc)
  run render "${orbit_set[0]}" --probe "$forest" --mode decoupled --strategy greedy-refine --eye 5,1,0 \
    --width 32 --height 24 --background black --frames 1 --warmup 0 -o "$tmp/orbit1.exr" -q
  [[ $(rmse "$tmp/orbit/frame_0001.exr" "$tmp/orbit1.exr") == 0.0 ]]; check "relight --camera-orbit: frame 1 is the render from the turned eye" $?
  [[ $(rmse "$tmp/orbit/frame_0000.exr" "$tmp/orbit1.exr") != 0.0 ]]; check "relight --camera-orbit: frame 0 differs from it" $?
fi

# JSON from every --json output, with names no JSON writer may pass through raw: a quote, a
# backslash, a newline and a control character in every path, and bytes that are not UTF-8
# in the probe's name (each becomes U+FFFD). Not in the mesh's: .prtc files record the mesh
# path and refuse what is not UTF-8.
if [[ -f $forest ]]; then
  hostile=$'ho"st\\ile\n\x01'
  dir="$tmp/$hostile"
  mkdir -p "$dir"
  cp "$tmp/cube.obj" "$dir/m$hostile.obj"
  cp "$tmp/cube.prtx" "$dir/m$hostile.prtx"
  probe="$dir/p$hostile"$'\xff\xfe.exr'
  cp "$forest" "$probe"
  run compress "$dir/m$hostile.prtx" --mesh "$dir/m$hostile.obj" -o "$dir/c$hostile.prtc" --clusters 2 --pcs 2 --json -q
  expect_code 0 && jget - /clusters <<<"$out" >/dev/null; check "hostile names: compress --json parses ($err)" $?
  run render "$dir/c$hostile.prtc" --mesh "$dir/m$hostile.obj" --probe "$probe" -o "$dir/r$hostile.exr" --width 32 --height 24 --frames 2 --warmup 0 --json -q
  expect_code 0 && [[ $(jget - /mode /width <<<"$out" | tr '\n' ' ') == "multipass 32 " ]]; check "hostile names: render --json parses ($err)" $?
  run overdraw "$dir/m$hostile.obj" --probe "$probe" --order 2 --samples 16 --bounces 0 --clusters 2 --pcs 2 --rows original --strategies order --budgets thesis --no-modes --frames 1 --warmup 0 --width 32 --height 24 --cache "$dir/cache" --out "$dir/od" --json -q
  expect_code 0 && [[ $(jget - /mesh <<<"$out") == "$dir/m$hostile.obj" ]]; check "hostile names: overdraw --json parses, names intact ($err)" $?
  [[ $(jget "$dir/od/overdraw.json" /probe) == "$dir/p$hostile"$'\xef\xbf\xbd\xef\xbf\xbd.exr' ]]; check "hostile names: overdraw.json parses, invalid bytes replaced" $?
fi

# Cube-map probes through the commands: a 4:3 render read back as a horizontal cross, and six
# square renders as a face set (a folder, or a {face} name); prtr probe projects the cube,
# render lights with it, a missing face is named.
if [[ -f $forest && -s $tmp/cube.prtc ]]; then
  rr=(render "$tmp/cube.prtc" --mesh "$tmp/cube.obj" --frames 1 --warmup 0 -q)
  run "${rr[@]}" --probe "$forest" -o "$tmp/cross.exr" --width 48 --height 36
  run probe "$tmp/cross.exr" --order 2; expect_code 0 && [[ $out == *"cube cross layout (horizontal)"* && $out == *"lat-long    48 x 24"* && $out == *"exact solid angles"* && $out == *"differs by at most"* ]]; check "probe: a 4:3 EXR is a horizontal cross, projected per texel ($err)" $?
  run "${rr[@]}" --probe "$tmp/cross.exr" -o "$tmp/lit_by_cross.exr" --width 32 --height 24; expect_code 0 && [[ -s $tmp/lit_by_cross.exr ]]; check "render: lights with a cross probe ($err)" $?
  mkdir -p "$tmp/faces" && run "${rr[@]}" --probe "$forest" -o "$tmp/face.exr" --width 16 --height 16
  for f in px nx py ny pz nz; do cp "$tmp/face.exr" "$tmp/faces/$f.exr"; done
  run probe "$tmp/faces" --order 1; expect_code 0 && [[ $out == *"cube faces layout"* && $out == *"lat-long    64 x 32"* ]]; check "probe: a folder of six faces ($err)" $?
  run probe "$tmp/faces/{face}.exr" --order 1; expect_code 0 && [[ $out == *"cube faces layout"* ]]; check "probe: a {face} name ($err)" $?
  rm "$tmp/faces/nz.exr"
  run probe "$tmp/faces"; expect_code 1 && [[ $err == *faces* && $err == *nz* ]]; check "probe: a missing face is named ($err)" $?
fi

# Floating-point flags refuse NaN and infinity where they are parsed (CLI::Range alone lets
# NaN through), naming the flag: exit 2, before any file is read.
run compress "$tmp/cube.prtx" --mesh "$tmp/cube.obj" -o "$tmp/y.prtc" --alpha nan
expect_code 2 && [[ $err == *--alpha* ]]; check "compress: --alpha nan is a usage error naming it" $?
run render "$tmp/cube.prtc" --mesh "$tmp/cube.obj" --probe x.exr -o "$tmp/y.exr" --rotate-deg nan
expect_code 2 && [[ $err == *--rotate-deg* ]]; check "render: --rotate-deg nan is a usage error naming it" $?
run relight "$tmp/cube.obj" --probe x.exr --degrees inf
expect_code 2 && [[ $err == *--degrees* ]]; check "relight: --degrees inf is a usage error naming it" $?
run relight "$tmp/cube.obj" --probe x.exr --exposure nan
expect_code 2 && [[ $err == *--exposure* ]]; check "relight: --exposure nan is a usage error naming it" $?
run overdraw "$tmp/cube.obj" --probe x.exr --alpha inf
expect_code 2 && [[ $err == *--alpha* ]]; check "overdraw: --alpha inf is a usage error naming it" $?

# prtr slf and prtr path-trace on the cube under the forest probe: the report's figures and
# the .slfc magic; an atlas too small for the mesh and a malformed --samples are usage errors.
if [[ -f $forest ]]; then
  run slf "$tmp/cube.obj" --probe "$forest" --samples 32x32 --directions 8x4 --spp 2 --clusters 4 --pcs 2 -o "$tmp/cube.slfc" --no-cache -q
  expect_code 0 && [[ $out == *"data generation"* && $out == *"compression ratio"* && $out == *"RMS error"* ]]; check "slf: exits 0 and reports times, ratio and error" $?
  [[ $(head -c 8 "$tmp/cube.slfc" 2>/dev/null) == PRTRSLFC ]]; check "slf writes a .slfc file" $?
  # prtr info on both SLF files: the settings as made, and the compression ratio against its
  # definition (V x 3 Z W raw floats over V N + K (N + 1) 3 Z W) from the rows it reports.
  run info "$tmp/cube.slfc" --mesh "$tmp/cube.obj"
  expect_code 0 && [[ $out =~ atlas\ +32\ x\ 32 && $out =~ directions\ +8\ x\ 4 && $out =~ clusters\ +4,\ 2\ PCs && $out =~ probe\ +forest.exr && $out == *"current against"* ]]; check "info: a .slfc's atlas, directions, clusters and probe ($err)" $?
  run info "$tmp/cube.slfc" --json
  read -r rows cols k pcs spp ratio < <(jget - /rows /columns /clusters /components /spp /compression_ratio <<<"$out" | tr '\n' ' ')
  awk -v r="$rows" -v c="$cols" -v k="$k" -v n="$pcs" -v q="$ratio" 'BEGIN { e = r * c / (r * n + k * (n + 1) * c); exit !(c == 96 && k == 4 && n == 2 && r > 0 && q > 1 && (q - e) ^ 2 < 1e-12) }'
  check "info --json: a .slfc's rows $rows x $cols, K $k, N $pcs, ratio $ratio" $?
  [[ $spp == 2 && $(jget - /probe /format <<<"$out" | tr '\n' ' ') == "forest.exr slfc " ]]; check "info --json: a .slfc's spp, probe and format" $?
  [[ $(jget - /direction_space <<<"$out") == reflected ]]; check "info --json: a .slfc's grid holds reflected directions by default" $?
  run info "$tmp/cube.slfc" --mesh "$tmp/quad.obj"; expect_code 1 && [[ $out == *STALE* ]]; check "info: a .slfc stale against another mesh exits 1" $?
  run slf "$tmp/cube.obj" --probe "$forest" --samples 32x32 --directions 8x4 --spp 2 --clusters 4 --pcs 2 -o "$tmp/cached.slfc" --cache "$tmp/slf_cache" -q
  slfs=("$tmp"/slf_cache/slf-*.slf)
  run info "${slfs[0]}" --json --verify
  expect_code 0 && [[ $(jget - /format /rows /rows_stored /directions <<<"$out" | tr '\n' ' ') == "slf $rows $rows 32 " ]]; check "info --json: the raw bake (.slf) has the .slfc's rows ($err)" $?
  head -c 300 "$tmp/cube.slfc" >"$tmp/cut.slfc"
  run info "$tmp/cut.slfc"; expect_code 1 && [[ $err == *cut.slfc* ]]; check "info: a truncated .slfc exits 1 naming it" $?
  run slf "$tmp/cube.obj" --probe "$forest" --samples 4x4 -o "$tmp/x.slfc" --no-cache -q
  expect_code 2 && [[ $err == *"too small"* ]]; check "slf: an atlas too small for the mesh is a usage error" $?
  run slf "$tmp/cube.obj" --probe "$forest" --samples 32 -o "$tmp/x.slfc" -q
  expect_code 2 && [[ $err == *--samples* ]]; check "slf: --samples without WxH is a usage error naming it" $?
  # The chart method travels in the file: a per-triangle .slfc says so, and every command that
  # rebuilds its atlas (render, view, relight) rebuilds that one, not the default.
  run slf "$tmp/cube.obj" --probe "$forest" --charts per-triangle --samples 32x32 --directions 8x4 --spp 2 --clusters 4 --pcs 2 -o "$tmp/tri.slfc" --no-cache -q
  expect_code 0; check "slf --charts per-triangle exits 0" $?
  run info "$tmp/tri.slfc" --json
  expect_code 0 && [[ $(jget - /atlas_charts <<<"$out") == per-triangle ]]; check "info: a per-triangle .slfc says so" $?
  run render "$tmp/tri.slfc" --probe "$forest" --width 16 --height 12 --frames 1 --warmup 0 -o "$tmp/tri.exr" -q
  expect_code 0 && [[ -s $tmp/tri.exr ]]; check "render: a per-triangle .slfc renders with its own atlas ($err)" $?
  run slf "$tmp/cube.obj" --probe "$forest" --direction-space view --samples 32x32 --directions 8x4 --spp 2 --clusters 4 --pcs 2 -o "$tmp/view.slfc" --no-cache --json -q
  expect_code 0 && [[ $(jget - /direction_space <<<"$out") == view ]]; check "slf --direction-space view: the paper's grid, reported ($err)" $?
  run slf "$tmp/cube.obj" --probe "$forest" --direction-space local --samples 32x32 --directions 8x4 --spp 2 --clusters 4 --pcs 2 -o "$tmp/local.slfc" --no-cache --json -q
  expect_code 0 && [[ $(jget - /direction_space <<<"$out") == local ]]; check "slf --direction-space local: each texel's hemisphere, reported ($err)" $?
  run render "$tmp/local.slfc" --probe "$forest" --width 16 --height 12 --frames 1 --warmup 0 -o "$tmp/local.exr" -q
  expect_code 0 && [[ -s $tmp/local.exr ]]; check "render: a .slfc of local directions renders ($err)" $?
  run info "$tmp/local.slfc"
  expect_code 0 && [[ $out == *"hemisphere"* ]]; check "info: a local grid is named as views over each texel's hemisphere" $?
  run slf "$tmp/cube.obj" --probe "$forest" --direction-space sideways -o "$tmp/x.slfc" --no-cache -q
  expect_code 2 && [[ $err == *--direction-space* ]]; check "slf: an unknown --direction-space is a usage error naming it" $?
  run path-trace "$tmp/cube.obj" --probe "$forest" --width 16 --height 12 --spp 2 -o "$tmp/pt.exr" -q
  expect_code 0 && [[ -s $tmp/pt.exr ]]; check "path-trace writes an EXR" $?
  # prtr render shows the .slfc in one pass; PRT's lighting flags and another probe are refused.
  run render "$tmp/cube.slfc" --probe "$forest" --width 16 --height 12 --frames 2 --warmup 0 -o "$tmp/slf.exr" --json -q
  expect_code 0 && [[ $out == *'"mode":"slf"'* && $out == *'"passes":1'* && -s $tmp/slf.exr ]]; check "render: a .slfc renders in one pass" $?
  for shading in one-pass deferred texture-space; do
    run render "$tmp/cube.slfc" --probe "$forest" --width 16 --height 12 --frames 1 --warmup 0 --slf-shading $shading -o "$tmp/slf_$shading.exr" --json -q
    expect_code 0 && [[ $out == *"\"shading\":\"$shading\""* && -s $tmp/slf_$shading.exr ]]; check "render: --slf-shading $shading shades that way" $?
  done
  run render "$tmp/cube.slfc" --probe "$forest" --slf-shading sideways -o "$tmp/x.exr" -q
  expect_code 2 && [[ $err == *--slf-shading* ]]; check "render: an unknown --slf-shading is a usage error naming it" $?
  run render "$tmp/cube.prtc" --mesh "$tmp/cube.obj" --probe "$forest" --slf-shading deferred -o "$tmp/x.exr" -q
  expect_code 2 && [[ $err == *--slf-shading* && $err == *--mode* ]]; check "render: --slf-shading on a .prtc is a usage error pointing to --mode" $?
  run render "$tmp/cube.slfc" --probe "$forest" --rotate-deg 30 -o "$tmp/x.exr" -q
  expect_code 2 && [[ $err == *--rotate-deg* && $err == *"surface light field"* ]]; check "render: --rotate-deg on a .slfc is a usage error naming it" $?
  run render "$tmp/cube.slfc" --probe "${forest%forest.exr}city.exr" -o "$tmp/x.exr" -q
  expect_code 2 && [[ $err == *--probe* && $err == *forest.exr* ]]; check "render: a .slfc under another probe is a usage error naming the baked one" $?
  # prtr relight --kind slf: prtr slf's cached pipeline, the camera orbiting the mesh; frame 0
  # is prtr render of the .slfc prtr slf makes with the same settings (the same cached bake),
  # frame 1 the render from the eye turned by a quarter turn; all of relight's outputs.
  slf_settings=(--directions 8x4 --spp 2 --clusters 4 --pcs 2 --cache "$tmp/slf_cache")
  run relight "$tmp/cube.obj" --probe "$forest" --kind slf --camera-orbit --slf-samples 32x32 "${slf_settings[@]}" \
    --eye 0,1,5 --frames 4 --width 32 --height 24 --background black --exr-pixels float --out "$tmp/slfrl" -q
  expect_code 0 && [[ $out == *"render      slf"* && $out == *"bake        cached"* ]]; check "relight --kind slf exits 0, its bake cached by prtr slf ($err)" $?
  for f in frame_0000.exr frame_0003.exr frame_0003.png contact_sheet.png relight.gif; do
    [[ -s $tmp/slfrl/$f ]]; check "relight --kind slf wrote $f" $?
  done
  if command -v ffprobe >/dev/null; then
    info=$(media_info "$tmp/slfrl/relight.mp4"); [[ $info == 32,24,4 ]]; check "relight --kind slf: MP4 is 32 x 24, 4 frames ($info)" $?
  fi
  "$prtr" slf "$tmp/cube.obj" --probe "$forest" --samples 32x32 "${slf_settings[@]}" -o "$tmp/orbit.slfc" -q >/dev/null
  slf_render=(render "$tmp/orbit.slfc" --probe "$forest" --width 32 --height 24 --background black --frames 1 --warmup 0 -q)
  "$prtr" "${slf_render[@]}" --eye 0,1,5 -o "$tmp/slf0.exr"
  "$prtr" "${slf_render[@]}" --eye 5,1,0 -o "$tmp/slf1.exr"
  [[ $(rmse "$tmp/slfrl/frame_0000.exr" "$tmp/slf0.exr") == 0.0 ]]; check "relight --kind slf: frame 0 equals prtr render of the .slfc" $?
  [[ $(rmse "$tmp/slfrl/frame_0001.exr" "$tmp/slf1.exr") == 0.0 ]]; check "relight --kind slf: frame 1 equals the render from the turned eye" $?
  [[ $(rmse "$tmp/slfrl/frame_0000.exr" "$tmp/slf1.exr") != 0.0 ]]; check "relight --kind slf: the frames differ" $?
  run relight "$tmp/cube.obj" --probe "$forest" --kind slf --out "$tmp/x"
  expect_code 2 && [[ $err == *--camera-orbit* ]]; check "relight --kind slf without --camera-orbit (a turning environment) is a usage error naming it" $?
  run relight "$tmp/cube.obj" --probe "$forest" --kind slf --camera-orbit --mode cpu --out "$tmp/x"
  expect_code 2 && [[ $err == *--mode* ]]; check "relight --kind slf: a PRT flag is a usage error naming it" $?
  run relight "$tmp/cube.obj" --probe "$forest" --spp 4 --out "$tmp/x"
  expect_code 2 && [[ $err == *--spp* ]]; check "relight: an SLF flag without --kind slf is a usage error naming it" $?
  # prtr view serves a .slfc too (tests/view_slf_browser_test.py opens one); another probe and
  # PRT's flags are refused before it listens (the timeout stops one that serves instead).
  view_slf() {
    out=$(timeout 60 "$prtr" view "$tmp/cube.slfc" --port 0 -q "$@" 2>"$tmp/err"); code=$?; err=$(cat "$tmp/err")
  }
  view_slf --probe "${forest%forest.exr}city.exr"
  expect_code 2 && [[ $err == *--probe* && $err == *forest.exr* ]]; check "view: a .slfc under another probe is a usage error naming the baked one" $?
  for flag in "--mode cpu" "--strategy order" "--register-budget 64" "--clusters 8" "--order 4" "--axis 1,0,0" "--cache $tmp"; do
    view_slf --probe "$forest" $flag
    expect_code 2 && [[ $err == *"${flag%% *} applies to meshes"* && $err == *"surface light field"* ]]; check "view: ${flag%% *} with a .slfc is a usage error naming it" $?
  done
  view_slf --probe "$forest" --mesh "$tmp/missing.obj"
  expect_code 1 && [[ $err == *missing.obj* ]]; check "view: a .slfc's --mesh is the mesh it loads" $?
  run view "$tmp/cube.obj" --probe "$forest" --mesh "$tmp/cube.obj"
  expect_code 2 && [[ $err == *--mesh* ]]; check "view: --mesh beside a mesh is a usage error" $?
  # prtr compare: an image against itself is exact; against the path-traced one it is not.
  run compare "$tmp/slf.exr" "$tmp/slf.exr" --json
  expect_code 0 && [[ $out == *'"relative_rmse":0'* ]]; check "compare: an image against itself has no error" $?
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --json
  expect_code 0 && [[ $out == *'"relative_rmse":0.'* ]]; check "compare: the SLF against the path tracer reports a relative RMSE" $?
  run path-trace "$tmp/cube.obj" --probe "$forest" --width 8 --height 6 --spp 1 -o "$tmp/pt2.exr" -q
  run compare "$tmp/slf.exr" "$tmp/pt2.exr"
  expect_code 1 && [[ $err == *"differ in size"* ]]; check "compare: images of different sizes are refused naming both" $?
  # A second reference of another seed: its noise is reported and taken out of the error.
  run path-trace "$tmp/cube.obj" --probe "$forest" --width 16 --height 12 --spp 2 --seed 9 -o "$tmp/pt9.exr" -q
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --second-reference "$tmp/pt9.exr" --json
  expect_code 0 && [[ $out == *'"reference_noise":0.'* && $out == *'"corrected_relative_rmse":'* ]]; check "compare: a second reference reports the references' noise and the corrected error" $?
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --second-reference "$tmp/pt.exr"
  expect_code 2 && [[ $err == *--second-reference* && $err == *"the reference itself"* ]]; check "compare: the reference as its own second reference is a usage error" $?
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --second-reference "$tmp/pt2.exr"
  expect_code 1 && [[ $err == *pt2.exr* && $err == *"differ in size"* ]]; check "compare: a second reference of another size is refused naming it" $?
  # --erode leaves the outline out: fewer pixels, and none at all when the band is wider
  # than the mesh's image.
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --json; all=$(jget - /pixels <<<"$out")
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --json --erode 1; inner=$(jget - /pixels <<<"$out")
  expect_code 0 && ((inner > 0 && inner < all)); check "compare --erode 1 compares fewer pixels ($inner of $all)" $?
  run compare "$tmp/slf.exr" "$tmp/pt.exr" --erode 1000
  expect_code 1 && [[ $err == *"inside the outline"* ]]; check "compare --erode wider than the mesh fails saying so" $?
fi

finish cli
