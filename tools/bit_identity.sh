#!/bin/sh
# Behaviour unchanged, to the bit: `lmgi run` on three scenes (the generated Cornell box with its
# animation, two rooms, the shared Cornell box; the first also on the tiled photon path), every frame,
# the IIM, the AIM and the caustics as EXR, and a bake of the generated box; one SHA-256 per file. Run it before and after a change that must not change what lmgi computes
# and compare the two lists:
#   tools/bit_identity.sh build/lmgi > before.txt   (on the old commit)
#   tools/bit_identity.sh build/lmgi > after.txt && diff before.txt after.txt
set -e
LMGI=${1:-build/lmgi}
FRAMES=${FRAMES:-20}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for scene in scenes/cornell.glb scenes/two_rooms.glb ../shared/scenes/cornell-box/CornellBox.glb; do
  [ -f "$scene" ] || { echo "bit_identity: $scene is missing" >&2; exit 1; }
  name=$(basename "$scene" .glb)
  "$LMGI" run "$scene" --out "$OUT/$name" --frames "$FRAMES" --exr-every 1 >/dev/null
  (cd "$OUT/$name" && sha256sum -- *.exr | sed "s|  |  $name/|")
done
"$LMGI" run scenes/cornell.glb --out "$OUT/tiled" --frames 8 --exr-every 1 --indirect tiled >/dev/null
"$LMGI" bake scenes/cornell.glb --out "$OUT/bake" >/dev/null
for d in tiled bake; do (cd "$OUT/$d" && sha256sum -- *.exr | sed "s|  |  $d/|"); done
