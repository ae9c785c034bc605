#!/bin/bash
# device_egl_check.sh: lmgi's EGL backend on a machine with a GPU, side by side with llvmpipe here.
#
# It answers: does LMGI_GL=egl (and auto) make an OpenGL 4.5 core context on the GPU's EGL device
# platform, which renderer and version does it report, do the same commands give the same pictures and
# lightmaps as on llvmpipe, how long does a level's bake take there, and do test_gl_guest (lmgi in an
# EGL host's share group), test_gather (a texel's gathered bits whatever it is gathered with) and
# test_bake_after_edits (a bake after edits is a fresh one's, to the bit) pass there. Written for a bare GPU machine that cannot reach the network (the
# NVIDIA H200 machines lent to sessions): everything it needs travels in one folder, the bundle.
#
# 1. Build here for the architecture's baseline, so that the binaries run on another x86-64 CPU:
#      make ARCH=-march=x86-64-v3 build/lmgi build/tests/test_gl_guest build/tests/test_gather \
#           build/tests/test_bake_after_edits
#    (or into another folder, BUILD=build/x86-64-v3 for make and for the bundle step below)
# 2. Make the bundle (the binaries, the shared libraries they need from this machine except glibc and
#    GL's own -- libEGL, libGL, libGLX, libGLdispatch come from the GPU machine's glvnd, so that its
#    vendor library is used --, this script as run.sh, tools/dev/device/exr_diff.c built here, and the
#    scenes):
#      tools/dev/device_egl_check.sh bundle DIR [SHARED_SCENES]
#    SHARED_SCENES (default ../shared/scenes) gives cornell-box/CornellBox.glb and
#    occlusion-room/room_lit.glb; lmgi's own scenes/cornell.glb and two_rooms.glb are copied too (the tests
#    run in the bundle's folder and find them in its scenes/). The libraries are packed
#    in DIR/libs.tar.xz (Embree alone is 43 MB unpacked); about 16 MB in all.
# 3. Run it on the GPU machine (and the same here, for llvmpipe):
#      DIR/run.sh OUT [BACKENDS]    there: DIR/run.sh /tmp/out "egl auto";   here: DIR/run.sh /tmp/here egl
#    (here LMGI_GL=egl is llvmpipe on Mesa's surfaceless platform, and the steps get the same names).
#    The first backend runs everything; the others only the Cornell run (their GL line and frames).
#    It writes OUT/summary.txt (facts, each command's GL line and times, the check's ratios, the bakes'
#    gather times, test_gl_guest's result), OUT/results_*.tar.gz (the EXRs, logs and frames.csv, as
#    results/STEP/..., each well under the device tool's 16 MB a file) and a few PNGs; its work folder
#    is DEVCHECK_WORK (default /tmp/lmgi_devcheck). DEVCHECK_REFERENCE=DIR (the results/ folder of a
#    run elsewhere, e.g. here on llvmpipe, carried along) adds each EXR's difference from it to the
#    summary. A machine with glvnd but no vendor file for its driver: set __EGL_VENDOR_LIBRARY_FILENAMES
#    (the script sets it to NVIDIA's file under /usr/local/nvidia when that exists and nothing set it).
#    Each command runs under `timeout` (DEVCHECK_TIMEOUT seconds, default 150), no command starts once
#    DEVCHECK_BUDGET seconds (default 0: no limit) have passed, and the summary is written as it goes,
#    so a hang costs one step, not the results. On the H200 machines, through the device tool, with the
#    glvnd .debs in .gl (its README's recipe) and the bundle in .devcheck, both carried (about 50 s
#    there, the machine's start aside; docs/bench.md, "The same commands on an H200 and on llvmpipe"):
#      for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig;
#      DEVCHECK_TIMEOUT=60 DEVCHECK_BUDGET=200 DEVCHECK_REFERENCE=.devcheck/here \
#          .devcheck/run.sh $OUT "egl auto"
# 4. Compare the two runs' EXRs (same names on both sides), B taken as the reference:
#      tools/dev/device_egl_check.sh compare OUT_GPU/results OUT_HERE/results
#    (unpack each side's results_*.tar.gz first; prints exr_diff's line per file: rel_l1, mean_rel, ...),
#    or carry the llvmpipe run's results/ in the bundle and name it in DEVCHECK_REFERENCE (step 3).
set -u

here=$(cd "$(dirname "$0")" && pwd)

die() { echo "device_egl_check: $*" >&2; exit 1; }

# ---------------------------------------------------------------------------------------------------
bundle() {
    local dir=$1 shared=${2:-../shared/scenes} b=${BUILD:-build}
    [ -x "$b/lmgi" ] || die "run from the repository root after make ($b/lmgi missing; BUILD names another build folder)"
    [ -f "$shared/cornell-box/CornellBox.glb" ] || die "no $shared/cornell-box/CornellBox.glb"
    mkdir -p "$dir/bin" "$dir/scenes" "$dir/.libs" || exit 1
    strip -o "$dir/bin/lmgi" "$b/lmgi"
    for t in test_gl_guest test_gather test_bake_after_edits; do
        [ -x "$b/tests/$t" ] && strip -o "$dir/bin/$t" "$b/tests/$t"
    done
    cc -O2 -o "$dir/bin/exr_diff" tools/dev/device/exr_diff.c -ltinyexr -lm || die "exr_diff did not build"
    cp "$0" "$dir/run.sh" && chmod +x "$dir/run.sh"
    cp scenes/cornell.glb scenes/two_rooms.glb "$shared/cornell-box/CornellBox.glb" "$shared/occlusion-room/room_lit.glb" "$dir/scenes/"
    # every library the binaries load but glibc's and GL's (the GPU machine's glvnd and driver give those)
    ldd "$dir"/bin/* | awk '$3 ~ /^\// {print $3}' | sort -u |
        grep -Ev '/(libc|libm|libdl|librt|libpthread|ld-linux-x86-64|libEGL|libGL|libGLX|libGLdispatch|libOpenGL)\.so' |
        while read -r lib; do cp -L "$lib" "$dir/.libs/"; done
    tar -C "$dir/.libs" -cJf "$dir/libs.tar.xz" . && rm -rf "$dir/.libs"
    du -sh "$dir"
}

# ---------------------------------------------------------------------------------------------------
compare() {
    local a=$1 b=$2 diff=${EXR_DIFF:-$here/bin/exr_diff} built=
    if [ ! -x "$diff" ]; then # from the repository: build it
        diff=${TMPDIR:-/tmp}/exr_diff.$$ built=1
        cc -O2 -o "$diff" "$here/device/exr_diff.c" -ltinyexr -lm || die "exr_diff did not build"
    fi
    (cd "$a" && find . -name '*.exr' | sort) | while read -r f; do
        [ -f "$b/$f" ] && printf '%-44s %s\n' "$f" "$("$diff" "$a/$f" "$b/$f")"
    done
    [ -n "$built" ] && rm -f "$diff"
    return 0
}

# ---------------------------------------------------------------------------------------------------
run_all() {
    local out=$1 backends=${2:-egl auto}
    local B=$here W=${DEVCHECK_WORK:-/tmp/lmgi_devcheck} limit=${DEVCHECK_TIMEOUT:-150}
    local budget=${DEVCHECK_BUDGET:-0}
    SECONDS=0
    mkdir -p "$out" && rm -rf "$W" && mkdir -p "$W/results" "$W/lib" || exit 1
    local S=$out/summary.txt
    : > "$S"
    say() { echo "$*" | tee -a "$S"; }

    # the libraries: the bundle's, except those the machine has itself (its libstdc++, libgomp, ... are
    # as new or newer, and its GL driver may need them)
    tar -C "$W/lib" -xJf "$B/libs.tar.xz"
    for f in "$W"/lib/*; do
        n=$(basename "$f")
        case $n in libstdc++*|libgcc_s*|libgomp*|libz.*|libX*|libxcb*|libbsd*|libmd.*)
            ldconfig -p | grep -q "^[[:space:]]*$n " && rm -f "$f" ;;
        esac
    done
    export LD_LIBRARY_PATH=$W/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    local nv_json=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && [ -f "$nv_json" ]; then
        export __EGL_VENDOR_LIBRARY_FILENAMES=$nv_json
    fi
    if [ -d /usr/local/nvidia/lib64 ] && ! ldconfig -p | grep -q libEGL_nvidia; then
        export LD_LIBRARY_PATH=$LD_LIBRARY_PATH:/usr/local/nvidia/lib64
    fi

    say "== facts ($(date -u +%FT%TZ))"
    say "host: $(uname -srm), $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-)"
    command -v nvidia-smi >/dev/null &&
        say "nvidia-smi: $(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>&1)"
    say "__EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-(unset)}"
    say "vendor files: $(ls /usr/share/glvnd/egl_vendor.d /usr/local/nvidia/share/glvnd/egl_vendor.d 2>/dev/null | tr '\n' ' ')"
    say "ldconfig: $(ldconfig -p | grep -Eo '(libEGL[^ ]*|libnvidia-glcore[^ ]*|libOSMesa[^ ]*)' | sort -u | tr '\n' ' ')"
    say "bundle libs used: $(ls "$W/lib" | tr '\n' ' ')"
    ls /dev/dri 2>/dev/null | tr '\n' ' ' | sed 's/^/\/dev\/dri: /' >> "$S"; echo >> "$S"

    # one command: its wall time, status, GL line and the lines worth keeping
    step() { # name, backend, command...
        local name=$1 be=$2; shift 2
        local log=$W/results/$name.log t0 t1 rc
        if [ "$budget" -gt 0 ] && [ "$SECONDS" -ge "$budget" ]; then
            say "== $name (LMGI_GL=$be): skipped, ${SECONDS} s of the DEVCHECK_BUDGET $budget s spent"
            return
        fi
        t0=$(date +%s.%N)
        if [ "$be" = default ]; then
            (cd "$W/results" && timeout "$limit" "$@") > "$log" 2>&1
        else
            (cd "$W/results" && LMGI_GL=$be timeout "$limit" "$@") > "$log" 2>&1
        fi
        rc=$?
        t1=$(date +%s.%N)
        say "== $name (LMGI_GL=$be): exit $rc, $(echo "$t1 - $t0" | bc 2>/dev/null || awk "BEGIN{print $t1-$t0}") s wall"
        say "   \$ ${*#$B/}"
        tr '\r' '\n' < "$log" | grep -E '^(gl |gather |atlas |setup |mean frame|median|baked |frame |relative RMSE|  [a-z0-9(].* [01]\.[0-9]{3} |lmgi: error|lmgi: warning|.*EGL|\[ *(OK|FAILED|PASSED|SKIPPED) *\]|.*skipped|.*FAIL)' |
            sed 's/^/   /' | head -40 | tee -a "$S"
    }

    local first=1 be
    for be in $backends; do
        step "run_$be" "$be" "$B/bin/lmgi" run "$B/scenes/cornell.glb" --frames 10 --in-order --exr-every 9 --out "run_$be"
        if [ $first = 1 ]; then
            step "check_$be" "$be" "$B/bin/lmgi" check "$B/scenes/CornellBox.glb" --out "check_$be"
            step "bake_$be" "$be" "$B/bin/lmgi" bake "$B/scenes/room_lit.glb" --out "bake_$be"
            step "bake_rays_$be" "$be" "$B/bin/lmgi" bake "$B/scenes/room_lit.glb" --gather-scheme rays --out "bake_rays_$be"
            step "bake_viewports_$be" "$be" "$B/bin/lmgi" bake "$B/scenes/room_lit.glb" --gather-scheme viewports --out "bake_viewports_$be"
            for t in test_gl_guest test_gather test_bake_after_edits; do # the guest test makes its own host
                [ -x "$B/bin/$t" ] && step "$t" "$([ $t = test_gl_guest ] && echo default || echo "$be")" \
                    bash -c 'cd "$0" && exec "bin/$1"' "$B" "$t"
            done
            step "bake4x_rays_$be" "$be" "$B/bin/lmgi" bake "$B/scenes/room_lit.glb" --texels 262144 --gather-scheme rays --out "bake4x_rays_$be"
            step "bake4x_viewports_$be" "$be" "$B/bin/lmgi" bake "$B/scenes/room_lit.glb" --texels 262144 --gather-scheme viewports --out "bake4x_viewports_$be"
            first=0
        fi
        say "== $be against the first backend"
        [ -d "$W/results/run_$be" ] && [ "$be" != "${backends%% *}" ] &&
            compare "$W/results/run_$be" "$W/results/run_${backends%% *}" | sed 's/^/   /' | tee -a "$S"
    done
    say "== done $(date -u +%FT%TZ)"

    # the same steps elsewhere (DEVCHECK_REFERENCE: the results folder of this script's run on llvmpipe)
    if [ -n "${DEVCHECK_REFERENCE:-}" ] && [ -d "$DEVCHECK_REFERENCE" ]; then
        say "== against $DEVCHECK_REFERENCE (the reference; per file: exr_diff A=here B=there)"
        compare "$W/results" "$DEVCHECK_REFERENCE" | sed 's/^/   /' | tee -a "$S"
    fi

    # back: the summary, the EXRs and logs in three archives (each well under 16 MB: no PNG frames, no
    # AIMs of the large bakes, no checkpoints or reference cache), a few pictures to look at
    (cd "$W" && rm -rf results/build results/*/bake.checkpoint results/bake4x_*/aim.exr results/*/frame_000[1-8].png
     tar -czf "$out/results_run_check.tar.gz" results/*.log results/run_* results/check_* 2>/dev/null
     tar -czf "$out/results_bake.tar.gz" results/bake_* 2>/dev/null
     tar -czf "$out/results_bake4x.tar.gz" results/bake4x_* 2>/dev/null)
    local first_be=${backends%% *}
    cp "$W/results/run_$first_be/frame_0009.png" "$out/run_frame9_$first_be.png" 2>/dev/null
    cp "$W/results/check_$first_be/check_ratio.png" "$out/check_ratio_$first_be.png" 2>/dev/null
    cp "$W/results/bake_$first_be/lightmap.png" "$out/bake_lightmap_$first_be.png" 2>/dev/null
    ls -la "$out"
}

case ${1:-} in
    bundle) shift; bundle "$@" ;;
    compare) shift; compare "$@" ;;
    ""|-h|--help) sed -n '2,/^set -u/p' "$0" | sed '$d' ;;
    *) run_all "$@" ;;
esac
