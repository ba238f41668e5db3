#!/usr/bin/env bash
# The twelve test meshes, for a clone without ../shared beside it:
#   bash scripts/test-meshes.sh [DEST]      (default target/test-meshes)
# leaves DEST/meshes/ as the tests read it (TOPOVOX_SHARED=DEST).
# scripts/test-all.sh calls it when neither $TOPOVOX_SHARED nor
# ../shared/meshes exists.
#
# They are not copied into this repository: most state no licence. Ten
# are downloaded from the public collection alecjacobson/common-3d-test-models
# at a pinned commit and checked against their SHA-256 (byte for byte the
# files ../shared holds); the cow (Viewpoint Animation Engineering / Sun
# Microsystems, via that collection) and Keenan Crane's Spot (CC0, with its
# texture) come from examples/meshes/. Sources, as that collection lists them:
#   alligator: Alec Jacobson · beetle: Ivan Sutherland (1972) ·
#   cheburashka: Ilya Baran · fandisk: Pratt & Whitney / Hugues Hoppe ·
#   homer: unlisted · rocker-arm: INRIA (AIM@SHAPE) ·
#   stanford-bunny: Stanford 3D Scanning Repository · suzanne: Blender ·
#   teapot: Martin Newell · woody: Scott Schaefer.
# TOPOVOX_MESH_BASE overrides where the ten come from (any URL curl reads,
# file:// included). All or nothing: DEST is replaced only when every file
# arrived and matched.
set -euo pipefail
cd "$(dirname "$0")/.."
COMMIT=8a4f8642acaf43f9cd7b67858a1502e1055ef202
BASE="${TOPOVOX_MESH_BASE:-https://raw.githubusercontent.com/alecjacobson/common-3d-test-models/$COMMIT/data}"
DEST="${1:-target/test-meshes}"
declare -A SHA256=(
    [alligator.obj]=108a1f4319e4a069b2bfbee3b5f278551501d75c473bb705c62e2bef872ad544
    [beetle.obj]=46ee9dcbec84b8d1b8f0d743ab1c91b1ed81378672fc0516e7afff5172d7c9b7
    [cheburashka.obj]=b2ac59bc1112f1b3e086ac0285d9be7fdefef278a32151a79e650414b2244f3f
    [fandisk.obj]=ea5bab2fbf545b1915f0d9faf6cc61ff8c18e0d8174ad61f8e35de15d8f6e3f8
    [homer.obj]=b20b1391fd62964f65703d748514d86d747d1202d38e55e0f1addac7a5a10e8b
    [rocker-arm.obj]=590257e6d01e689354821d807854306c3bfbb02d9cca73404d5a4924f105c287
    [stanford-bunny.obj]=1eb35d1e21ce99e5ce911353b6be278990713448dd9e8f5c9387f9de39b32205
    [suzanne.obj]=d8684326f9bd8cfc24d3d302c1042fa16f63d2e66e49ed56b413fa20bed271e6
    [teapot.obj]=1b5396fedd74b577e32cef41146582c2f2e1a050d5b4915193c0ac1ad4187ed4
    [woody.obj]=8f9c1657fd4ed2e5d5cc0f65ae35ff49d338cf09ae51f57c496353c0b2c53209
)
part="$DEST.part-$$"
trap 'rm -rf "$part"' EXIT
rm -rf "$part"
mkdir -p "$part/meshes"
for name in $(printf '%s\n' "${!SHA256[@]}" | sort); do
    if ! curl -fsSL --retry 2 "$BASE/$name" -o "$part/meshes/$name"; then
        echo "test-meshes: cannot download $BASE/$name (set TOPOVOX_SHARED to a folder holding meshes/)" >&2
        exit 1
    fi
    got=$(sha256sum "$part/meshes/$name" | cut -c1-64)
    if [ "$got" != "${SHA256[$name]}" ]; then
        echo "test-meshes: $name from $BASE has SHA-256 $got, not ${SHA256[$name]}" >&2
        exit 1
    fi
done
cp examples/meshes/cow.obj examples/meshes/spot/spot-textured.obj examples/meshes/spot/spot.mtl examples/meshes/spot/spot_texture.png "$part/meshes/"
rm -rf "$DEST"
mv "$part" "$DEST"
echo "$DEST/meshes: $(ls "$DEST/meshes" | wc -l) files"
