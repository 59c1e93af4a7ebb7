#!/usr/bin/env bash
# Writes hostile and damaged inputs, runs prtr on each, and regenerates docs/ROBUSTNESS.md:
# the table of what prtr answers (exit code, first line of the message, time). Every file is
# made here, from bytes; nothing binary is committed. Needs a built prtr (default
# build/prtr) and the real inputs for the damaged-copy rows (blender-data).
#
#   bash scripts/bad_inputs.sh [PRTR] [OUTPUT.md]
set -uo pipefail
cd "$(dirname "$0")/.."
prtr=$(realpath "${1:-build/prtr}")
doc=${2:-docs/ROBUSTNESS.md}
[[ -x $prtr ]] || { echo "bad_inputs: $prtr is not built (cmake --build build --target prtr)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
probe=/usr/share/blender/datafiles/studiolights/world/studio.exr

# le FORMAT VALUES...: little-endian binary through perl's pack (perl-base is essential in
# Debian); values may be written in hex.
le() { perl -e 'my $f = shift; print pack($f, map { /^0x/ ? hex($_) : $_ } @ARGV)' "$@"; }

# --- The inputs: file name, command, what it is. -----------------------------------------
rows=()
add() { rows+=("$1|$2|$3"); }  # add FILE SUBCOMMAND DESCRIPTION

printf 'f /0' >slash_zero.obj
add slash_zero.obj mesh "OBJ face corner without a vertex number (4 bytes)"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf /0\n' >late_slash.obj
add late_slash.obj mesh "the same after valid geometry"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n' >zero_index.obj
add zero_index.obj mesh "OBJ face with vertex number 0"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' >bad_index.obj
add bad_index.obj mesh "OBJ face naming a vertex that does not exist"
printf 'v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n' >nan.obj
add nan.obj mesh "OBJ vertex 'nan'"
printf 'v -3e38 -3e38 0\nv 3e38 -3e38 0\nv -3e38 3e38 0\nf 1 2 3\n' >huge_triangle.obj
add huge_triangle.obj mesh "finite triangle at +-3e38 (its bounding-box diagonal overflows float)"
: >empty.obj
add empty.obj mesh "empty file"
add missing.obj mesh "no such file"
mkdir -p folder.obj
add folder.obj mesh "a directory"
printf '0 0 0\n' >points.xyz
add points.xyz mesh "unknown extension"

printf 'OFF\n20000 20000 0\n0 0 0\n' >claims_20k.off
add claims_20k.off mesh "OFF header claiming 20,000 vertices and faces, one vertex line"
printf 'OFF\n4000000000 4000000000 0\n0 0 0\n' >claims_4e9.off
add claims_4e9.off mesh "OFF header claiming 4e9 elements"
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n' >corners.off
add corners.off mesh "OFF face claiming 4e9 corners"
printf 'OFF BINARY\n' >binary.off
add binary.off mesh "binary OFF"

ply_header='ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
printf "${ply_header}0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n" >nan.ply
add nan.ply mesh "ASCII PLY with a 'nan' coordinate"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >claims_4e9.ply
add claims_4e9.ply mesh "PLY header claiming 4e9 vertices"
{ printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
  head -c 36 /dev/zero; printf '\xff'; head -c 12 /dev/zero; } >list.ply
add list.ply mesh "PLY face list claiming 255 corners, 3 present"
printf 'this is not a mesh\n' >garbage.ply
add garbage.ply mesh "text that is not PLY"

{ le vV 0x4d4d 66; le vV 0x3d3d 60; le vV 0x4000 54; printf 'x\0'; le vV 0x4100 46
  le vV 0x4110 40; le v 9; head -c 32 /dev/zero; } >short_vertices.3ds
add short_vertices.3ds mesh "3DS vertex list claiming 9 vertices, with room for 2"
perl -e 'my $n = 20000; for my $d (0..$n) { print pack("vV", 0x4d4d, 6 * ($n + 1 - $d)) }' >deep.3ds
add deep.3ds mesh "3DS with 20,000 nested main chunks (120 KB)"
{ le vV 0x4d4d 38; le vV 0xb000 32; le vV 0xb002 26; le vV 0xb020 20; head -c 10 /dev/zero; le V 2147483647; } >track.3ds
add track.3ds mesh "3DS keyframe track claiming 2^31 keys in 38 bytes"
{ le vV 0x4d4d 1000; } >past_end.3ds
add past_end.3ds mesh "3DS main chunk longer than the file"
gltf_head='{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],'
printf '%s"accessors":[{"bufferView":0,"componentType":5126,"type":"VEC3","count":4000000000}],"bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}' "$gltf_head" >claims_4e9.gltf
add claims_4e9.gltf mesh "glTF accessor claiming 4e9 vertices in a 36-byte buffer"
printf '%s"accessors":[],"bufferViews":[],"buffers":[{"byteLength":36,"uri":"../../etc/passwd"}]}' "$gltf_head" >escape.gltf
add escape.gltf mesh "glTF buffer URI leaving the file's folder"
{ printf '{"asset":{"version":"2.0"},"x":'; head -c 100000 /dev/zero | tr '\0' '['; } >deep.gltf
add deep.gltf mesh "glTF JSON nested 100,000 levels deep"
printf '%s"skins":[{"joints":[0]}],"accessors":[],"bufferViews":[],"buffers":[]}' "$gltf_head" >skinned.gltf
add skinned.gltf mesh "glTF with a skin"
# Found by a hostile-input round: Assimp crashed (SIGSEGV) on a LINE_LOOP whose indices name
# the float VEC3 position accessor.
printf '%s' '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":0,"mode":2}]}],"buffers":[{"byteLength":72,"uri":"data:application/octet-stream;base64,AAAAAAAiYnl0ZUxlbmd0aCI6IDcyfV0sICJidWZmZXJWaWV3cwAED6AAAAAAAIA/AAACAAEAAAABAAMAAAADAAIAAQECAAMA"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":24}],"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},{"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}]}' >float_indices.gltf
add float_indices.gltf mesh "glTF line loop whose indices are the float positions (crashed Assimp)"
rm -f mtl.fifo && mkfifo mtl.fifo
printf 'mtllib mtl.fifo\nmtllib ../../../../../../../../dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >mtllib.obj
add mtllib.obj mesh "OBJ whose mtllib names a FIFO and ../../dev/zero (materials are never opened)"
# A second hostile-input round: out-of-range indices, instancing, URIs, STL coordinates.
tri_b64=AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAQD//wAA
printf '%s' '{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"buffers":[{"byteLength":48,"uri":"data:application/octet-stream;base64,'"$tri_b64"'"}],"bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}]}' >index_65535.gltf
add index_65535.gltf mesh "glTF index 65535 into 3 vertices (Assimp dropped the face silently)"
le f9 0 0 0 1 0 0 0 1 0 >tet.bin
rm -f 't%65t.bin' && mkfifo 't%65t.bin'
printf '%s"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],"bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":"t%%65t.bin"}]}' "$gltf_head" >escaped_uri.gltf
add escaped_uri.gltf mesh "glTF buffer URI t%65t.bin: tet.bin is a file, t%65t.bin a FIFO (the checked file is the one read)"
head -c 120024 /dev/zero >grid.bin
perl -e 'print q({"asset":{"version":"2.0"},"scenes":[{"nodes":[), join(",", (0) x 2000),
  q(]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":120024,"uri":"grid.bin"}],"bufferViews":[{"buffer":0,"byteLength":120024}],"accessors":[{"bufferView":0,"componentType":5126,"count":10002,"type":"VEC3","min":[0,0,0],"max":[0,0,0]}]})' >roots_2000.gltf
add roots_2000.gltf mesh "glTF scene naming one 10,002-vertex root 2,000 times (20 M vertices from 126 KB)"
perl -e 'print q({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[),
  join(",", (q({"attributes":{"POSITION":0}})) x 70000),
  q(]}],"buffers":[{"byteLength":36,"uri":"tet.bin"}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})' >primitives_70k.gltf
add primitives_70k.gltf mesh "glTF mesh repeating one primitive 70,000 times"
{ le vV 0x4d4d 86; le vV 0x3d3d 80; le vV 0x4000 74; printf 'q\0'; le vV 0x4100 66
  le vV 0x4110 44; le v 3; le f9 0 0 0 1 0 0 0 1 0; le vV 0x4120 16; le v 1; le v4 0 1 60000 7; } >index_60000.3ds
add index_60000.3ds mesh "3DS face (0, 1, 60000) in a 3-vertex mesh (Assimp replaced the index)"
{ le vV 0x4d4d 38; le vV 0x3d3d 32; le vV 0x4000 26; printf 'l\0'; le vV 0x4600 18; head -c 12 /dev/zero; } >light_only.3ds
add light_only.3ds mesh "3DS holding only a light (Assimp leaks 1,132 bytes on it)"
stl_facet() { printf 'solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex %s\nendloop\nendfacet\nendsolid t\n' "$1"; }
stl_facet '1 2' >two_coordinates.stl
add two_coordinates.stl mesh "ASCII STL 'vertex 1 2' (was left unset: a different mesh each run)"
stl_facet 'abc 0 0' >word.stl
add word.stl mesh "ASCII STL 'vertex abc 0 0'"
stl_facet '0 0 inf' >inf.stl
add inf.stl mesh "ASCII STL 'vertex 0 0 inf' (was read as 0)"
{ head -c 80 /dev/zero; le V 1; le f12 0 0 1 0 0 0 1 0 0 0 nan 0; le v 0; } >nan_binary.stl
add nan_binary.stl mesh "binary STL with a NaN vertex"
printf 'v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r' >cr_only.obj
add cr_only.obj mesh "OBJ with classic-Mac CR line ends"
{ printf 'v '; head -c 2000000 /dev/zero | tr '\0' '1'; printf ' 0 0\n'; } >long_line.obj
add long_line.obj mesh "OBJ 'v' line of 2 MB (a 300 MB one took 4.6 GB)"
printf "${ply_header%%element face*}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0\n" >zero_corners.ply
add zero_corners.ply mesh "PLY whose only face has 0 corners"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >duplicate_x.ply
add duplicate_x.ply mesh "PLY declaring property x twice"
{ printf 'glTF'; le VVVV 2 1000 100 0x4e4f534a; } >short.glb
add short.glb mesh "GLB whose header claims 1000 bytes, 20 present"
{ head -c 80 /dev/zero; le V 5; head -c 100 /dev/zero; } >short.stl
add short.stl mesh "binary STL claiming 5 triangles, holding 2"

printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 20000 +X 40000\n' >huge.hdr
add huge.hdr probe "53-byte HDR claiming 40000 x 20000"
printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1000000000 +X 2000000000\n' >huger.hdr
add huger.hdr probe "HDR claiming 2e9 x 1e9"
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n\002\002\000\010'; printf '\211\007'; } >overrun.hdr
add overrun.hdr probe "HDR whose first run-length run is 9 bytes long in an 8-pixel line"
printf '#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 2 +X 4\n' >xyze.hdr
add xyze.hdr probe "HDR of CIE XYZ pixels (XYZE)"
{ printf '\x76\x2f\x31\x01'; le V 2; printf 'comments\0string\0'; le V 1900000000; head -c 1000 /dev/zero | tr '\0' x; } >attribute.exr
add attribute.exr probe "1 KB EXR whose string attribute claims 1.9 GB"
{ printf '\x76\x2f\x31\x01'; le V 2; printf 'owner\0string\0'; le l -5; printf 'abc'; } >negative.exr
add negative.exr probe "EXR attribute with a negative size"
{ printf '\x76\x2f\x31\x01'; le V 2; printf 'channels\0chlist\0'; le V 1; printf 'R\0'; head -c 17 /dev/zero
  printf 'x\0string\0'; le V 1900000000; head -c 100 /dev/zero | tr '\0' x; } >desync.exr
add desync.exr probe "EXR channel list declaring 1 byte for 19, then an attribute claiming 1.9 GB"
# Found by fuzz_probe_exr: a data window 16.5 M texels wide, whose 16-line ZIP blocks OpenEXR
# sized (1.5 GB) while opening the file.
perl -e 'my $ch = join("", map { "$_\0" . pack("lCx3ll", 1, 0, 1, 1) } qw(B G R)) . "\0";
  my $win = pack("l4", 0, 0, 16514823, 3);
  sub attr { my ($n, $t, $v) = @_; "$n\0$t\0" . pack("l", length $v) . $v }
  print "\x76\x2f\x31\x01", pack("V", 2), attr("channels", "chlist", $ch),
    attr("compression", "compression", "\x03"), attr("dataWindow", "box2i", $win),
    attr("displayWindow", "box2i", $win), attr("lineOrder", "lineOrder", "\0"), "\0", "\0" x 1800' >wide.exr
add wide.exr probe "2 KB EXR whose data window is 16.5 M texels wide (ZIP blocks of 1.5 GB)"
echo "not an image" >garbage.exr
add garbage.exr probe "text that is not an image"
if [[ -f $probe ]]; then
  head -c 2000 "$probe" >truncated.exr
  add truncated.exr probe "real EXR cut to 2,000 bytes"
fi
add missing.exr probe "no such file"
{ printf 'PF\n2 1\n-1.0\n'; perl -e 'print pack("f<", 1e38) x 6'; } >huge.pfm
add huge.pfm probe "2 x 1 PFM of 1e38 (its SH projection overflows single precision)"

# Transfer and compressed files: a real one, then damaged copies.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' >tet.obj
"$prtr" bake tet.obj -o good.prtx --order 2 --samples 16 --bounces 0 --quiet >/dev/null 2>&1
"$prtr" compress good.prtx --mesh tet.obj -o good.prtc --clusters 1 --pcs 1 --quiet >/dev/null 2>&1
flip() { local b; b=$(od -An -tu1 -j "$2" -N1 "$1" | tr -d ' '); printf "\\$(printf %03o $((b ^ 255)))" | dd of="$1" bs=1 seek="$2" conv=notrunc status=none; }
if [[ -f good.prtx ]]; then
  head -c 100 good.prtx >short.prtx; add short.prtx info "transfer file cut inside its header"
  cp good.prtx magic.prtx; flip magic.prtx 0; add magic.prtx info "transfer file with a damaged magic number"
  cp good.prtx payload.prtx; flip payload.prtx 140; add payload.prtx "info --verify" "transfer file with one payload byte flipped"
  head -c 200 good.prtx >cut.prtx; add cut.prtx info "transfer file cut inside its payload"
  cp good.prtx v1.prtx; printf '\x01' | dd of=v1.prtx bs=1 seek=8 conv=notrunc status=none
  add v1.prtx info "version-1 transfer file (the thesis's view projection)"
fi
# Outputs that would destroy an input or replace a special file (refused before any work).
rm -f out.fifo && mkfifo out.fifo && ln -sf tet.obj link.prtx
add tet.obj "bake -o tet.obj" "bake whose output is its own input mesh"
add tet.obj "bake -o /dev/null" "bake whose output is /dev/null (a rename would replace the device)"
add tet.obj "bake -o out.fifo" "bake whose output is a FIFO"
add tet.obj "bake -o link.prtx" "bake whose output is a symbolic link"
if [[ -f good.prtx ]]; then
  add good.prtx "compress --mesh tet.obj -o good.prtx" "compress whose output is its input"
  add good.prtx "compress --mesh tet.obj -o tet.obj" "compress whose output is the mesh"
fi
if [[ -f good.prtc ]]; then
  cp good.prtc payload.prtc; flip payload.prtc $(($(stat -c %s good.prtc) - 3)); add payload.prtc "info --verify" "compressed file with one payload byte flipped"
  head -c 150 good.prtc >cut.prtc; add cut.prtc info "compressed file cut after its header"
fi

# --- Run and tabulate. ----------------------------------------------------------------------
measure=()
[[ -x /usr/bin/time ]] && measure=(/usr/bin/time -f '%e %M' -o "$work/time")
{
  echo "# Robustness: what prtr does with bad inputs"
  echo
  echo "Generated by \`scripts/bad_inputs.sh\` (do not edit by hand): each input is written by"
  echo "the script from bytes, then given to the command shown. Exit codes: 0 success, 1 failure"
  echo "(the message names the file and says what to do), 2 usage error. A crash would show as"
  echo "128 + the signal. Seconds and peak memory (MB) are for the whole command, so they are"
  echo "mostly process start-up (OpenImageIO and Mesa load only when an image or a GL context is"
  echo "needed, common/image_codec.h): what matters is that no row stands out."
  echo
  echo "Size limits behind these answers: mesh readers check every count a header claims"
  echo "against the bytes left in the file before allocating; probe loading refuses an image"
  echo "whose decoded size exceeds 4096 times the file size (above 64 MiB) or the free memory,"
  echo "any EXR header attribute larger than the file, and any EXR header whose data window"
  echo "sizes OpenEXR's buffers (one block of scan lines or one tile past the same limit, an"
  echo "offset table longer than the file) before OpenEXR reads it (\`probes/src/exr_guard.cpp\`)."
  echo
  echo "Which reader does what: OFF and PLY are read by our own strict readers"
  echo "(\`meshes/src/read_strict.cpp\` and \`read_ply.cpp\`; OpenMesh's OFF and PLY readers size buffers from"
  echo "unchecked counts and read values they never set after a parse error, which no guard in"
  echo "front of them can fix), and so is STL (binary or ASCII, decided by the file's size). OBJ"
  echo "still goes through OpenMesh, behind a strict pre-pass over its lines and face records."
  echo "glTF 2.0 and 3DS go through Assimp behind \`meshes/src/asset_guard.cpp\` and"
  echo "\`asset_guard_3ds.cpp\`, which check"
  echo "every size, URI and nesting depth Assimp would trust (the table of guards is in"
  echo "docs/ARCHITECTURE.md, \"Mesh assets\"). Radiance .hdr probes are read by our own bounded"
  echo "reader (\`probes/src/rgbe_file.cpp\`: header size, resolution range, every run checked"
  echo "against its line); other images go through OpenImageIO behind the checks above."
  echo
  echo "The same loaders are fuzzed by \`scripts/fuzz.sh [seconds]\` (libFuzzer, ASan, UBSan;"
  echo "targets in \`fuzz/\`) and the whole test suite runs under ASan, UBSan and LSan with"
  echo "\`scripts/sanitize.sh\`."
  echo
  echo "| Input | Command | Exit | Seconds | MB | Message (first line) |"
  echo "|---|---|---|---|---|---|"
  for row in "${rows[@]}"; do
    IFS='|' read -r file command what <<<"$row"
    read -ra sub <<<"$command"
    rm -f "$work/time"
    start=$(date +%s.%N)
    "${measure[@]}" "$prtr" "${sub[@]}" "$file" >/dev/null 2>"$work/err"
    code=$?
    end=$(date +%s.%N)
    seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')
    mb=-
    if [[ -s $work/time ]]; then
      mb=$(tail -1 "$work/time" | awk '{ printf "%.0f", $2 / 1024 }')
      # /usr/bin/time reports a signal on its first line instead of the exit status.
      grep -q "terminated by signal" "$work/time" && code="$code ($(head -1 "$work/time"))"
    fi
    message=$(grep -v '^$' "$work/err" | head -1 | sed "s|$work/||g; s|$work|.|g; s/|/\\\\|/g")
    ((${#message} > 300)) && message="${message:0:300}..."
    [[ -z $message ]] && message="(no message)"
    echo "| $what (\`$file\`) | \`prtr $command\` | $code | $seconds | $mb | $message |"
  done
} >"$work/table.md"
cd - >/dev/null
mkdir -p "$(dirname "$doc")"
cp "$work/table.md" "$doc"
echo "bad_inputs: ${#rows[@]} inputs tabled in $doc" >&2
