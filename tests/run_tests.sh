#!/bin/sh
# Runs each cmocka test binary, prints its output, and closes with the totals of test cases:
# "N passed, N failed, N skipped", after the slowest binaries' wall times (the suite must stay well under
# 15 minutes on 2 cores). Exits non-zero if any binary failed or crashed.
passed=0; failed=0; skipped=0; bad=""; times=""
# Sanitizer builds: third-party leaks we cannot fix are listed in tests/lsan.supp.
LSAN_OPTIONS="suppressions=$(cd "$(dirname "$0")" && pwd)/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# The sanitizer runtime of GCC 12 (Debian 12's) takes a dynamic TLS block whose address ends at 16 bytes
# past a 4 KB boundary for a pre-2.25 glibc header, reads a bogus range from before it, and the leak check
# at exit dies scanning it ("Tracer caught signal 11"; google/sanitizers#1322, fixed after GCC 13): half
# the runs of `lmgi run` on test_run's far-from-origin scene. Not tracking __tls_get_addr avoids it; the
# static TLS and every thread's stack are still scanned.
ASAN_OPTIONS="intercept_tls_get_addr=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS ASAN_OPTIONS
for t in "$@"; do
    echo "=== $t"
    t0=$(date +%s%N)
    out=$("$t" 2>&1); rc=$?
    secs=$(( ($(date +%s%N) - t0) / 1000000000 ))
    printf '%s\n' "$out"
    echo "--- $t: ${secs} s"
    times="$times$secs $t
"
    p=$(printf '%s\n' "$out" | sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' | awk '{s+=$1} END {print s+0}')
    f=$(printf '%s\n' "$out" | sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' | awk '{s+=$1} END {print s+0}')
    s=$(printf '%s\n' "$out" | sed -n 's/^\[  SKIPPED \] \([0-9]*\) test.*/\1/p' | awk '{s+=$1} END {print s+0}')
    passed=$((passed + p)); failed=$((failed + f)); skipped=$((skipped + s))
    if [ $rc -ne 0 ]; then
        bad="$bad $t"
        [ "$f" -eq 0 ] && failed=$((failed + 1))
    fi
done
printf '%s' "$times" | sort -rn | head -8 | awk 'BEGIN {print "slowest binaries:"} {print "  " $1 " s  " $2}'
[ -n "$bad" ] && echo "failing test binaries:$bad"
echo "$passed passed, $failed failed, $skipped skipped"
[ -z "$bad" ]
