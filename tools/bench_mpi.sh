#!/bin/sh
# make bench-mpi: an MPI bake (build/lmgi-mpi) of each scene on 1, 2 and 4 ranks of this machine
# (--oversubscribe beyond its cores), each against the plain one-process bake: wall time, speed-up,
# efficiency, when each rank's part reached rank 0, whether the lightmap is the same bytes, and each
# rank's stages (photon trace, AIMs, gather) and the merge.
# Then the same with one core a rank (LP_NUM_THREADS=1 OMP_NUM_THREADS=1, each rank bound to a core of its
# own), against one process on one core: ranks as machines of one core each, up to this machine's cores.
# Usage: tools/bench_mpi.sh BUILD SCENE [OPTIONS...]; docs/farm.md has the numbers.
set -e
build=$1; scene=$2; shift 2
root=""; [ "$(id -u)" = 0 ] && root="--allow-run-as-root"
out=$(mktemp -d "${TMPDIR:-/tmp}/lmgi-bench-mpi-XXXXXX")
trap 'rm -rf "$out"' EXIT
now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }
start=$(now); "$build/lmgi" bake "$scene" "$@" --out "$out/one" -q; one=$(calc "$(now) - $start")
printf '%s %s\n%-6s %9s %9s %11s  %s\n' "$scene" "$*" ranks seconds speed-up efficiency "parts at rank 0 (s); same bytes"
printf '%-6s %9.2f %9s %11s\n' 1 "$one" 1.00 100%
for n in 2 4; do
    start=$(now)
    TMPDIR=$out mpirun $root --oversubscribe -n $n "$build/lmgi-mpi" bake "$scene" "$@" --out "$out/n$n" > "$out/log" 2>&1
    t=$(calc "$(now) - $start")
    parts=$(sed -n 's/^bake: part \([0-9]*\) of [0-9]* in (\(.*\) s)$/\2/p' "$out/log" | tr '\n' ' ')
    same=no; cmp -s "$out/one/lightmap.exr" "$out/n$n/lightmap.exr" && same=yes
    printf '%-6s %9.2f %9.2f %10.0f%%  %s; %s\n' $n "$t" "$(calc "$one / $t")" "$(calc "100 * $one / $t / $n")" \
        "$parts" "$same"
    sed -n '/^stages/,/^traffic/p' "$out/log" | sed 's/^/       /'
done
cores=$(nproc)
echo "one core a rank ($cores cores here)"
start=$(now)
LP_NUM_THREADS=1 OMP_NUM_THREADS=1 taskset -c 0 "$build/lmgi" bake "$scene" "$@" --out "$out/c1" -q
one=$(calc "$(now) - $start")
printf '%-6s %9.2f %9s %11s\n' 1 "$one" 1.00 100%
n=2
while [ $n -le "$cores" ]; do
    start=$(now)
    TMPDIR=$out mpirun $root --bind-to core -x LP_NUM_THREADS=1 -x OMP_NUM_THREADS=1 -n $n "$build/lmgi-mpi" \
        bake "$scene" "$@" --out "$out/c$n" > "$out/log" 2>&1
    t=$(calc "$(now) - $start")
    same=no; cmp -s "$out/c1/lightmap.exr" "$out/c$n/lightmap.exr" && same=yes
    printf '%-6s %9.2f %9.2f %10.0f%%  same bytes: %s\n' $n "$t" "$(calc "$one / $t")" "$(calc "100 * $one / $t / $n")" "$same"
    sed -n '/^stages/,/^traffic/p' "$out/log" | sed 's/^/       /'
    n=$((n * 2))
done
