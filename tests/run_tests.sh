#!/bin/sh
# Runs each cmocka test binary, LMGI_TEST_JOBS at a time (default: one a core; 1: one after the other, in
# the order given), prints each one's output whole as it finishes, and closes with the totals of test
# cases: "N passed, N failed, N skipped", after the slowest binaries' wall times (the suite must stay well
# under 15 minutes on 2 cores). Exits non-zero if any binary failed or crashed.
#
# Why several at a time: the binaries keep about 1.6 of 2 cores busy on average (a reference's threads,
# then a stretch of one-threaded loading or a GL draw), so two side by side fill the gaps. Give the
# longest first (make test does): the last to finish is then a short one. No binary may depend on another
# running or not: each writes only into its own temporary folder (tests/support.c, lmt_tmpdir).
# Sanitizer builds: third-party leaks we cannot fix are listed in tests/lsan.supp.
LSAN_OPTIONS="suppressions=$(cd "$(dirname "$0")" && pwd)/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# The sanitizer runtime of GCC 12 (Debian 12's) takes a dynamic TLS block whose address ends at 16 bytes
# past a 4 KB boundary for a pre-2.25 glibc header, reads a bogus range from before it, and the leak check
# at exit dies scanning it ("Tracer caught signal 11"; google/sanitizers#1322, fixed after GCC 13): half
# the runs of `lmgi run` on test_run's far-from-origin scene. Not tracking __tls_get_addr avoids it; the
# static TLS and every thread's stack are still scanned.
ASAN_OPTIONS="intercept_tls_get_addr=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS ASAN_OPTIONS
jobs=${LMGI_TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}
case $jobs in '' | *[!0-9]* | 0) echo "run_tests.sh: LMGI_TEST_JOBS '$jobs' must be a positive number" >&2; exit 2 ;; esac
logs=$(mktemp -d "${TMPDIR:-/tmp}/lmgi-tests-XXXXXX") || exit 2
trap 'rm -rf "$logs"' EXIT
trap 'exit 130' INT TERM

# One binary (its number N in the list, its path T): output, exit status and seconds into $logs/N.*, then
# all of its output at once under a lock, so that two finishing together do not interleave.
run_one='
    n=$1 t=$2 logs=$0
    t0=$(date +%s%N)
    "$t" > "$logs/$n.out" 2>&1
    rc=$?
    echo $rc > "$logs/$n.rc"
    echo $(( ($(date +%s%N) - t0) / 1000000000 )) > "$logs/$n.secs"
    [ $rc -eq 0 ] && how="" || how=" (exit status $rc)"
    flock "$logs/lock" sh -c "echo \"=== \$1\"; cat \"\$2.out\"; echo \"--- \$1: \$(cat \"\$2.secs\") s\$3\"" \
        sh "$t" "$logs/$n" "$how"
'
n=0
for t in "$@"; do
    n=$((n + 1))
    printf '%d %s\n' "$n" "$t"
done | xargs -P "$jobs" -L 1 sh -c "$run_one" "$logs"

# Test cases cmocka counted on its closing line "[  WORD ] N test(s)" in output file $2 (WORD is $1, padded
# as cmocka pads it); 0 where there is none.
cases() { sed -n "s/^\[  $1\] \([0-9]*\) test.*/\1/p" "$2" 2>/dev/null | awk '{s+=$1} END {print s+0}'; }
passed=0; failed=0; skipped=0; bad=""; times=""; n=0
for t in "$@"; do
    n=$((n + 1))
    out="$logs/$n.out"
    rc=$(cat "$logs/$n.rc" 2>/dev/null || echo 1) # none: the runner was stopped before it ended
    times="$times$(cat "$logs/$n.secs" 2>/dev/null || echo 0) $t
"
    p=$(cases "PASSED  " "$out"); f=$(cases "FAILED  " "$out"); s=$(cases "SKIPPED " "$out")
    passed=$((passed + p)); failed=$((failed + f)); skipped=$((skipped + s))
    if [ "$rc" -ne 0 ]; then
        bad="$bad $t"
        [ "$f" -eq 0 ] && failed=$((failed + 1))
    fi
done
printf '%s' "$times" | sort -rn | head -8 | awk -v j="$jobs" 'BEGIN {print "slowest binaries (" j " at a time):"} {print "  " $1 " s  " $2}'
[ -n "$bad" ] && echo "failing test binaries:$bad"
echo "$passed passed, $failed failed, $skipped skipped"
[ -z "$bad" ]
