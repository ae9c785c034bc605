#!/bin/sh
# make demo: the main job on our scenes, leaving pictures in demo/ (named in the README).
set -eu
LMGI=${1:-build/lmgi}
LMGI_DEV=$(dirname "$LMGI")/lmgi-dev # the developer's commands (tools/dev)
mkdir -p demo
# demo/ is the demo's own (make clean removes it). A folder an lmgi before output manifests wrote holds
# files today's lmgi cannot tell from a user's and will not replace: the demo clears its own such folders.
for d in demo/*/; do
    if [ -f "$d.lmgi" ] && ! head -n 1 "$d.lmgi" | grep -q '^lmgi output'; then
        rm -rf "$d"
    fi
done
for scene in scenes/cornell.glb scenes/two_rooms.glb ../shared/scenes/cornell-box/CornellBox.glb; do
    name=$(basename "$scene" | sed 's/\.[^.]*$//')
    if [ ! -r "$scene" ]; then
        echo "demo: skipped $scene (not found)"
        continue
    fi
    echo "== $scene"
    "$LMGI" info "$scene" | tee "demo/$name-info.txt"
    "$LMGI" charts "$scene" --out "demo/$name" --size 1024x768 --force
done
# The photon stage on the paper's scene: the cube and the mirror sphere move for 3 seconds.
if [ -r scenes/cornell.glb ]; then
    echo "== photons on scenes/cornell.glb"
    "$LMGI_DEV" photons scenes/cornell.glb --frames 90 --photons 50000 --out demo/cornell-photons --force
fi
# The whole frame loop on the same scene: composited frames (the mirror sphere reflecting the box, the glass
# sphere's caustic following it round the floor), the last frame's caustics alone (caustics.png), final
# lightmap atlases, per-stage times. 90 frames: 3 s of the animation.
if [ -r scenes/cornell.glb ]; then
    echo "== run on scenes/cornell.glb"
    "$LMGI" run scenes/cornell.glb --frames 90 --exr-every 30 --size 512x512 --out demo/cornell-run --force
fi
# The shared Cornell box (its double-sided lamp 0.9 mm under the ceiling) as `lmgi run` renders it, and that
# frame against the path-traced reference, per visible surface.
if [ -r ../shared/scenes/cornell-box/CornellBox.glb ]; then
    echo "== run and check on ../shared/scenes/cornell-box/CornellBox.glb"
    "$LMGI" run ../shared/scenes/cornell-box/CornellBox.glb --frames 1 --size 512x512 --out demo/cornellbox-run --force
    "$LMGI" check ../shared/scenes/cornell-box/CornellBox.glb --out demo/cornellbox-check --force -q | tee demo/cornellbox-check.txt
fi
# The same box with its indirect light gathered per pixel straight from the photons (--indirect tiled,
# docs/tiled.md) beside the lightmap path above, and that frame against the same reference.
if [ -r ../shared/scenes/cornell-box/CornellBox.glb ]; then
    echo "== run and check with --indirect tiled on ../shared/scenes/cornell-box/CornellBox.glb"
    "$LMGI" run ../shared/scenes/cornell-box/CornellBox.glb --indirect tiled --frames 1 --size 512x512 \
        --out demo/cornellbox-tiled-run --force
    "$LMGI" check ../shared/scenes/cornell-box/CornellBox.glb --indirect tiled --out demo/cornellbox-check-tiled \
        --force -q | tee demo/cornellbox-check-tiled.txt
fi
# A shared scene lit only by an emissive lamp, with a glossy Suzanne that reflects the room (its environment
# map) and textured blocks whose indirect light takes the texture per pixel.
if [ -r ../shared/scenes/cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf ]; then
    echo "== run on ../shared/scenes/cornell-suzanne"
    "$LMGI" run ../shared/scenes/cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf --frames 1 --size 512x512 \
        --out demo/cornell-suzanne-run --force
fi
# A real level (docs/levels.md): Godot 4's truck-town export (WebP textures), under its sun and a pale sky,
# baked at a texel budget the level can hold and then run for a frame at 1024 x 512. The bake sizes texels
# by worth as run does (--open-need 0.25): by area, the 2 km of outer ground took the atlas and left the
# town 8 m texels (docs/levels.md, "As baked: the town's texels").
if [ -r ../shared/scenes/truck-town/town_lit.gltf ]; then
    echo "== bake and run on ../shared/scenes/truck-town/town_lit.gltf under a sky"
    "$LMGI" bake ../shared/scenes/truck-town/town_lit.gltf --sky 0.2,0.25,0.35 --texels 65536 --open-need 0.25 \
        --out demo/truck-town-bake --force -q
    "$LMGI" run ../shared/scenes/truck-town/town_lit.gltf --sky 0.2,0.25,0.35 --texels 65536 --frames 1 \
        --size 1024x512 --out demo/truck-town-run --force -q
fi
echo "demo: pictures in demo/<scene>/atlas.png, demo/<scene>/surfaces.png, demo/cornell-photons/view.png,"
echo "      demo/cornell-run/frame_*.png and caustics.png, demo/cornellbox-run/frame_0000.png beside"
echo "      demo/cornellbox-tiled-run/frame_0000.png (--indirect tiled), demo/cornell-suzanne-run/frame_0000.png,"
echo "      demo/cornellbox-check/ and demo/cornellbox-check-tiled/ (check_ratio.png: frame / reference, red"
echo "      brighter, blue darker; demo/cornellbox-check.txt and -check-tiled.txt per surface),"
echo "      demo/truck-town-bake/lightmap.png and demo/truck-town-run/frame_0000.png (a real level under a sky)"
