#!/bin/sh
# make fuzz: runs FUZZER over INPUTS inputs (fuzz_pipeline: scenes; fuzz_api: call sequences) split across
# JOBS processes (seeds 1..JOBS), each logging to DIR/seed-N.log, and closes with the summed counts. Exits
# non-zero if any process failed or crashed.
set -u
fuzzer=$1; inputs=$2; jobs=$3; dir=$4
mkdir -p "$dir"
LSAN_OPTIONS="suppressions=$(cd "$(dirname "$0")" && pwd)/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export LSAN_OPTIONS
per=$(( (inputs + jobs - 1) / jobs ))
pids=""
for seed in $(seq 1 "$jobs"); do
    LMGI_FUZZ_INPUTS=$per LMGI_FUZZ_API_SEQUENCES=$per LMGI_FUZZ_SEED=$seed "$fuzzer" > "$dir/seed-$seed.log" 2>&1 &
    pids="$pids $!"
done
rc=0
for p in $pids; do wait "$p" || rc=1; done
if grep -q "fuzz_api:" "$dir"/seed-*.log; then
    grep -h "fuzz_api:" "$dir"/seed-*.log
    grep -h "fuzz_api:" "$dir"/seed-*.log | awk '{q+=$2; c+=$4; f+=$6} END {printf "fuzz: %d call sequences, %d calls, %d refused with a message\n", q, c, f}'
else
    grep -h "finite frame" "$dir"/seed-*.log
    grep -h "finite frame" "$dir"/seed-*.log | awk '{n+=$5; r+=$7; f+=$12; s+=$17} END {printf "fuzz: %d inputs, %d rendered, %d refused with a message, %d over 10 s\n", n, r, f, s}'
fi
grep -l "ERROR: AddressSanitizer\|ERROR: LeakSanitizer\|runtime error\|FAILED" "$dir"/seed-*.log && rc=1
[ $rc -eq 0 ] && echo "fuzz: 0 aborts, 0 sanitizer reports" || echo "fuzz: FAILED (see $dir)"
exit $rc
