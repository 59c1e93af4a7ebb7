# Shared by the CLI tests (cli_test.sh, cli_flags_test.sh), sourced after they set `prtr`,
# `tmp` (their own scratch directory, emptied here) and `json_check`: counting checks, running
# prtr with its output captured, and the summary line that decides the test's exit status.
rm -rf "$tmp" && mkdir -p "$tmp"
passed=0
failed=0

check() {  # check NAME CONDITION-RESULT
  if [[ $2 == 0 ]]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $1"; fi
}
run() {  # run ARGS...: sets out, err, code
  out=$("$prtr" "$@" 2>"$tmp/err"); code=$?; err=$(cat "$tmp/err")
  # Under the sanitizers, LeakSanitizer stops every thread with ptrace at exit and its tracer
  # can itself crash after the command has done its work: a fault of the checker, not a
  # finding. That command (not the whole test, many minutes there) runs once more, said
  # on stdout; a real report (ASan, a leak, UBSan) is never retried. The retry meets the
  # caches the first run wrote, so a check that wants a cold cache can still fail, and
  # scripts/sanitize.sh then reruns the whole test as before.
  if [[ $code != 0 && $err == *"LeakSanitizer has encountered a fatal error"* &&
        $err != *"ERROR: AddressSanitizer"* && $err != *"ERROR: LeakSanitizer: detected"* &&
        $err != *"runtime error:"* ]]; then
    echo "RETRY: LeakSanitizer's tracer crashed after prtr $*; running it once more"
    out=$("$prtr" "$@" 2>"$tmp/err"); code=$?; err=$(cat "$tmp/err")
  fi
}
expect_code() { [[ $code == "$1" ]]; }
skip() { echo "SKIP: $1"; }
# jget FILE|- POINTER: the value at a JSON pointer (strings unquoted); fails on invalid JSON.
jget() { "$json_check" "$@"; }
# media_info FILE: "width,height,frames" of the first video stream, decoded by ffprobe.
media_info() {
  ffprobe -v error -count_frames -select_streams v:0 \
    -show_entries stream=width,height,nb_read_frames -of csv=p=0 "$1" 2>/dev/null
}
# rmse A.exr B.exr: prtr compare's relative RMSE of two images (0.0 when they are equal).
rmse() { "$prtr" compare "$1" "$2" --json | jget - /relative_rmse; }
have_matplotlib() { /usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1; }
# write_cube FILE: a closed 8-vertex cube as OBJ, quads (any mesh would do for a bake).
write_cube() {
  cat >"$1" <<'OBJ'
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
OBJ
}
# finish NAME: the summary; the test's status is whether every check passed.
finish() {
  echo "$1: $passed passed, $failed failed"
  ((failed == 0))
}
