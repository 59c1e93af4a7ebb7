#!/usr/bin/env bash
# Every numeric flag of every prtr command: bad values are usage errors (exit 2) that name
# the flag. Apart from cli_test.sh because it starts prtr some 700 times, which under the
# sanitizers is a third of that test's run; apart, the two run side by side.
# Usage: cli_flags_test.sh PRTR TMPDIR JSON_CHECK
set -u
prtr=$1
tmp=$2
json_check=$3
source "$(dirname "$0")/cli_lib.sh"

# Every numeric flag of every command, read off --help: an empty value, a negative or
# unparsable one and one past any range are usage errors that name the flag, and no message
# holds a number longer than 15 digits (CLI11's own ranges printed DBL_MAX in full). Each flag
# gets every value: the empty one (which CLI11 alone would read as 0) and the other four. A
# process start is a few milliseconds (image libraries load only when an image is touched,
# common/image_codec.h).
numeric_flags=0
others=("-1" "abc" "1e400" "99999999999999999999999")
subcommands=(bake compress merge mesh probe info render relight overdraw view gl-info slf path-trace compare)
for sub in "${subcommands[@]}"; do
  while read -r flag; do
    numeric_flags=$((numeric_flags + 1))
    for bad in "" "${others[@]}"; do
      run "$sub" "$flag" "$bad"
      # "-1" is a valid value of flags whose range holds it (angles, exposure, weld
      # tolerance): the flag is then accepted and only the missing arguments are reported.
      [[ $bad == -1 && $err != *"$flag"* ]] && continue
      shown=${err//"'$bad'"/}  # the value itself, echoed back, may be long
      if ! { expect_code 2 && [[ $err == *"$flag"* ]] && ! [[ $shown =~ [0-9]{16} ]]; }; then
        echo "  $sub $flag '$bad': exit $code: $err"; false
      fi
      check "$sub $flag '$bad' is a usage error naming the flag" $?
    done
  done < <("$prtr" "$sub" --help 2>/dev/null | grep -oE '^ +(-[a-z], ?)?--[a-z0-9-]+ (INT|UINT|FLOAT)' | grep -oE -- '--[a-z0-9-]+')
done
((numeric_flags > 40)); check "numeric flags found in --help: $numeric_flags" $?

finish cli.flag_sweep
