#!/usr/bin/env bash
# The scale paths of the prtr binary against the one-process results, byte for byte:
#   blocks  prtr compress out of core with tiny blocks equals the default block size, and
#           prtr --threads 1 equals every core (bake with a bounce, compress).
#   mpi     mpirun -np 2 and -np 3 (oversubscribed, localhost only) prtr bake (0, 1 or 2
#           bounces) and prtr compress equal the one-process results byte for byte; a failing
#           rank fails the job and leaves no output; mpirun -np 5 prtr slf equals one process
#           too. Exit 77 (skip) when prtr was built without MPI.
# Usage: scale_cli_test.sh blocks|mpi PRTR TMPDIR [MPIEXEC]
set -u
mode=$1
prtr=$2
tmp=$3
mpiexec=${4:-}
rm -rf "$tmp" && mkdir -p "$tmp"
failed=0
check() {  # check NAME STATUS
  if [[ $2 == 0 ]]; then echo "ok: $1"; else failed=$((failed + 1)); echo "FAIL: $1"; fi
}

# A floor of n x n vertices under a box: occlusion, so the transfer varies across vertices.
# Both tests need several 256-row blocks (n = 30: 908 vertices): the blocks test to split the
# passes, the MPI test to give each of 3 ranks rows of its own (ranks own multiples of 256).
n=30
mesh=$tmp/scene.obj
{
  for ((y = 0; y < n; ++y)); do for ((x = 0; x < n; ++x)); do
    echo "v $x 0 $y"
  done; done
  for ((y = 0; y + 1 < n; ++y)); do for ((x = 0; x + 1 < n; ++x)); do
    a=$((y * n + x + 1)); echo "f $a $((a + n)) $((a + n + 1)) $((a + 1))"
  done; done
  lo=$((n / 2 - 1)) hi=$((n / 2 + 1))
  echo "v $lo 1 $lo"; echo "v $hi 1 $lo"; echo "v $hi 1 $hi"; echo "v $lo 1 $hi"
  echo "v $lo 3 $lo"; echo "v $hi 3 $lo"; echo "v $hi 3 $hi"; echo "v $lo 3 $hi"
  b=$((n * n))
  echo "f $((b + 1)) $((b + 2)) $((b + 3)) $((b + 4))"; echo "f $((b + 8)) $((b + 7)) $((b + 6)) $((b + 5))"
  echo "f $((b + 1)) $((b + 5)) $((b + 6)) $((b + 2))"; echo "f $((b + 2)) $((b + 6)) $((b + 7)) $((b + 3))"
  echo "f $((b + 3)) $((b + 7)) $((b + 8)) $((b + 4))"; echo "f $((b + 4)) $((b + 8)) $((b + 5)) $((b + 1))"
} >"$mesh"
bake=(bake "$mesh" --order 3 --samples 32 --bounces 0 -q)
bounced=(bake "$mesh" --order 3 --samples 32 -q)  # --bounces given per run

if [[ $mode == blocks ]]; then
  "$prtr" "${bake[@]}" -o "$tmp/one.prtx" >/dev/null; check "bake" $?
  "$prtr" compress "$tmp/one.prtx" --mesh "$mesh" -o "$tmp/default.prtc" --clusters 24 --pcs 2 \
    -q >/dev/null
  check "compress, default blocks" $?
  "$prtr" compress "$tmp/one.prtx" --mesh "$mesh" -o "$tmp/tiny.prtc" --clusters 24 --pcs 2 \
    -q --block-vertices 1 >/dev/null
  check "compress, --block-vertices 1" $?
  cmp "$tmp/default.prtc" "$tmp/tiny.prtc"; check "out-of-core compress equals default" $?
  # One worker thread gives the same bytes as every core: no sum depends on the scheduling.
  "$prtr" "${bounced[@]}" --bounces 1 -o "$tmp/all.prtx" >/dev/null; check "bake, 1 bounce" $?
  "$prtr" --threads 1 "${bounced[@]}" --bounces 1 -o "$tmp/serial.prtx" >/dev/null
  check "prtr --threads 1 bake" $?
  cmp "$tmp/all.prtx" "$tmp/serial.prtx"; check "--threads 1 bake equals every core" $?
  "$prtr" --threads 1 compress "$tmp/one.prtx" --mesh "$mesh" -o "$tmp/serial.prtc" \
    --clusters 24 --pcs 2 -q >/dev/null
  cmp "$tmp/default.prtc" "$tmp/serial.prtc"; check "--threads 1 compress equals every core" $?
  "$prtr" --threads -1 bake "$mesh" -o "$tmp/bad.prtx" >/dev/null 2>"$tmp/threads.err"
  [[ $? == 2 ]] && grep -q -- "--threads" "$tmp/threads.err"
  check "--threads -1 is a usage error naming the flag" $?
  exit $((failed > 0))
fi

if [[ -z $mpiexec ]]; then
  echo "SKIP: prtr was built without MPI (install libopenmpi-dev and reconfigure)"
  exit 77
fi
# Open MPI refuses root unless told; CI runs as a normal user, where these are not set.
if [[ $(id -u) == 0 ]]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fi
# Open MPI's runtime keeps allocations until exit; in the sanitizer build those are not ours.
# Its plugins stay loaded to the end, so leak reports name their library and the
# suppressions match rather than an "<unknown module>" of a closed plugin.
export LSAN_OPTIONS=suppressions=$(dirname "$0")/lsan_openmpi.supp:print_suppressions=0
export OMPI_MCA_mca_base_component_disable_dlclose=1
mpi() {  # mpi RANKS ARGS...: prtr under mpirun on this host only, shared-memory transport
  local n=$1; shift
  # Open MPI's libraries keep no frame pointers: the sanitizer's fast unwinder stops in them
  # and a leak report names no library; the slow one gives whole stacks the suppressions match.
  ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0 \
    "$mpiexec" -np "$n" --oversubscribe --host "localhost:$n" --mca btl self,vader "$prtr" "$@"
}

"$prtr" "${bake[@]}" -o "$tmp/one.prtx" >/dev/null; check "one-process bake" $?
for ranks in 2 3; do
  mpi "$ranks" "${bake[@]}" -o "$tmp/mpi$ranks.prtx" >"$tmp/mpi$ranks.log" 2>&1
  check "mpirun -np $ranks bake exits 0" $?
  cmp "$tmp/one.prtx" "$tmp/mpi$ranks.prtx"; check "mpirun -np $ranks bake equals one process" $?
  left=$(ls "$tmp" | grep -c -e prtshard -e '\.partial$')
  [[ $left == 0 ]]; check "no partial file left after -np $ranks" $?
done
# Ranks that cannot write the shared partial file (a directory in the way) fail the job, with
# no output.
mkdir -p "$tmp/fail.prtx.partial"
mpi 2 "${bake[@]}" -o "$tmp/fail.prtx" >"$tmp/fail.log" 2>&1
[[ $? != 0 ]]; check "a failing rank fails the job" $?
[[ ! -e $tmp/fail.prtx ]]; check "a failed job leaves no output" $?
grep -q "rank [01] of 2" "$tmp/fail.log"; check "the failing rank is named" $?
rmdir "$tmp/fail.prtx.partial"
# A partial file a crashed run left behind, longer than the output: every byte is rewritten
# and the file cut to size, so it changes nothing.
head -c $(($(stat -c %s "$tmp/one.prtx") + 4096)) /dev/urandom >"$tmp/fail.prtx.partial"
mpi 2 "${bake[@]}" -o "$tmp/fail.prtx" >"$tmp/rerun.log" 2>&1; check "a rerun succeeds" $?
cmp "$tmp/one.prtx" "$tmp/fail.prtx"; check "the rerun equals one process" $?

# Bounces: every rank writes its slice of each pass to OUT.pass0/1 and reads the pass after a
# barrier; any block size (37: blocks straddle the 64-vertex hit chunks).
# Each mpirun start costs ~20 s in the sanitizer build, so each rank count meets one bounce
# count (both pass files alternate with 2 bounces; 3 ranks split the rows unevenly).
for bounces in 1 2; do
  "$prtr" "${bounced[@]}" --bounces $bounces -o "$tmp/one-b$bounces.prtx" >/dev/null
  check "one-process bake, $bounces bounces" $?
  if [[ $bounces == 1 ]]; then
    # Past the 128-byte header (which records the bounces): the payload itself changes.
    ! cmp -s -i 128 "$tmp/one.prtx" "$tmp/one-b1.prtx"; check "the bounce changes the transfer" $?
  fi
  for ranks in $((4 - bounces)); do
    out=$tmp/mpi$ranks-b$bounces.prtx
    if [[ $bounces == 2 ]]; then
      # Pass files a crashed run left behind, one longer and one shorter than a pass: every
      # byte a pass reads is rewritten first, so they change nothing.
      head -c 4000000 /dev/urandom >"$out.pass0"; head -c 1000 /dev/urandom >"$out.pass1"
    fi
    mpi "$ranks" "${bounced[@]}" --bounces $bounces --block-vertices 37 -o "$out" \
      >"$tmp/b$ranks.log" 2>&1
    check "mpirun -np $ranks bake --bounces $bounces exits 0" $?
    cmp "$tmp/one-b$bounces.prtx" "$out"; check "mpirun -np $ranks, $bounces bounces, equals one process" $?
    left=$(ls "$tmp" | grep -c -e prtshard -e '\.partial$' -e '\.pass[01]$')
    [[ $left == 0 ]]; check "no partial or pass files left after -np $ranks" $?
  done
done

# Compression: chained LBG sums and PCA spread over the ranks give the one-process bytes, for
# any block size (--block-vertices 1: 256-row blocks inside each rank's rows).
compress=(compress "$tmp/one.prtx" --mesh "$mesh" --clusters 24 --pcs 2 -q)
"$prtr" "${compress[@]}" -o "$tmp/one.prtc" --json >"$tmp/one.json"; check "one-process compress" $?
grep -q '"splits":[1-9]' "$tmp/one.json"; check "the compression splits null clusters" $?
for ranks in 2 3; do
  for blocks in $((ranks - 2)); do  # 2 ranks whole, 3 ranks in 256-row blocks
    out=$tmp/mpi$ranks-$blocks.prtc
    mpi "$ranks" "${compress[@]}" --block-vertices $blocks -o "$out" >"$tmp/c$ranks.log" 2>&1
    check "mpirun -np $ranks compress --block-vertices $blocks exits 0" $?
    cmp "$tmp/one.prtc" "$out"; check "mpirun -np $ranks compress equals one process" $?
  done
done
mpi 2 "${compress[@]}" --method iterative -o "$tmp/it.prtc" >"$tmp/it.log" 2>&1
[[ $? == 2 ]]; check "mpirun compress refuses --method iterative (exit 2)" $?
grep -q "method lbg" "$tmp/it.log"; check "the refusal says what runs" $?
# A folder that does not exist: only rank 0's write finds out (a directory at -o is refused
# by every rank before any work, as a usage error).
mpi 2 "${compress[@]}" -o "$tmp/no_such_dir/x.prtc" >"$tmp/cfail.log" 2>&1
[[ $? != 0 ]]; check "a compress whose rank 0 cannot write fails the job" $?
grep -q "rank 0 of 2" "$tmp/cfail.log"; check "the failing compress rank is named" $?

# prtr slf: each rank path traces its range of the matrix's rows into OUT.part<r>, rank 0 joins
# them and compresses; every row's random numbers are its own, so the file is the one-process
# file byte for byte (5 ranks: the cube's 516 rows split unevenly). The cube under a small generated sky (Radiance
# RGBE, flat scanlines: a gradient in every channel, so each row of the matrix differs).
sky=$tmp/sky.hdr
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16 +X 32\n'
  LC_ALL=C awk 'BEGIN { for (y = 0; y < 16; ++y) for (x = 0; x < 32; ++x)
                          printf "%c%c%c%c", 64 + 8 * y, 64 + 4 * x, 160 - 4 * y, 129 }'; } >"$sky"
printf 'v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n' >"$tmp/cube.obj"
slf=(slf "$tmp/cube.obj" --probe "$sky" --samples 30x30 --directions 8x4 --spp 2 --clusters 6 --pcs 2 --no-cache -q)
"$prtr" "${slf[@]}" -o "$tmp/one.slfc" >/dev/null; check "one-process slf" $?
mpi 5 "${slf[@]}" -o "$tmp/mpi5.slfc" >"$tmp/slf5.log" 2>&1; check "mpirun -np 5 slf exits 0" $?
cmp "$tmp/one.slfc" "$tmp/mpi5.slfc"; check "mpirun -np 5 slf equals one process" $?
left=$(ls "$tmp" | grep -c '\.part[0-9]*$')
[[ $left == 0 ]]; check "no .part files left after mpirun slf" $?
# A rank that cannot write its part (a directory in the way) fails the job, with no output.
mkdir -p "$tmp/fail.slfc.part1"
mpi 2 "${slf[@]}" -o "$tmp/fail.slfc" >"$tmp/slffail.log" 2>&1
[[ $? != 0 && ! -e $tmp/fail.slfc ]]; check "a failing slf rank fails the job, no output" $?
grep -q "rank 1 of 2" "$tmp/slffail.log"; check "the failing slf rank is named" $?
mpi 2 "${slf[@]}" --rows 0:100 -o "$tmp/rows.slfc" >"$tmp/slfrows.log" 2>&1
[[ $? == 2 ]] && grep -q -- "--rows" "$tmp/slfrows.log"; check "mpirun slf --rows is a usage error naming it" $?
exit $((failed > 0))
