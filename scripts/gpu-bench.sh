#!/usr/bin/env bash
# The GPU benchmark in one call, for whoever has a machine with a hardware
# GPU at hand: prints one Markdown table for BENCHMARKS.md.
#
#   bash scripts/gpu-bench.sh            # the full table, under 8 minutes on a hardware GPU
#   QUICK=1 bash scripts/gpu-bench.sh    # small sizes: checks the script (lavapipe, CI)
#
# Measured, each the median of REPEATS runs (default 3), all on this machine:
# - voxelize the bunny at 1024 and 2048, cover/sep26/sep6 by the compute and
#   raster GPU paths and by the CPU's fast path, and the solid by GPU parity
#   and the CPU's parity: the voxelization time inside the run (voxelize_s:
#   device setup, upload, GPU, download) and, for the GPU, the passes' GPU
#   time by timestamps where the driver writes them;
# - render --gpu of the city at 1920x1080 for each culling setting: GPU ms
#   per frame (cull + depth + Hi-Z + shade), the median of 20 frames;
# - spray of 1 M rays into the city (CPU; rays per second);
# - 64 meshes at 64 and 128 (cover) in one `voxelize_many(method="gpu")`
#   dispatch, one GPU call per mesh, and the CPU (needs the Python package:
#   PYTHON, default python3, with topovox installed; else the row says so).
# Needs a built `topovox` (TOPOVOX_BIN, else target/release/topovox, else
# it builds one) and python3 for reading the JSON summaries.
set -euo pipefail
cd "$(dirname "$0")/.."

BIN="${TOPOVOX_BIN:-target/release/topovox}"
if [ ! -x "$BIN" ]; then
    cargo build --release -p topovox-cli >&2
fi
REPEATS="${REPEATS:-3}"
MESHES="${MESHES:-../shared/meshes}"
BUNNY="$MESHES/stanford-bunny.obj"
if [ -n "${QUICK:-}" ]; then
    RES="64 128"; SIZE="320x180"; FRAMES=3; RAYS=20000; BATCH=8; BATCH_RES="32 64"
else
    RES="1024 2048"; SIZE="1920x1080"; FRAMES=20; RAYS=1000000; BATCH=64; BATCH_RES="64 128"
fi
[ -f "$BUNNY" ] || { echo "gpu-bench: $BUNNY not found (set MESHES)" >&2; exit 1; }
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

# json_field KEY.PATH: a field of the JSON object on stdin ('' when absent).
json_field() { python3 -c "import json,sys
d=json.load(sys.stdin)
for k in sys.argv[1].split('.'):
    d = d[int(k)] if isinstance(d, list) else (d or {}).get(k)
print('' if d is None else d)" "$1"; }

# median_ms SECONDS...: the median in milliseconds ('' when none is given).
median_ms() { python3 -c "import sys
v=sorted(float(x) * 1e3 for x in sys.argv[1:] if x)
print('%.1f' % v[len(v) // 2] if v else '')" "$@"; }

adapter="$("$BIN" voxelize "$BUNNY" -o "$WORK/a.vdb" --resolution 32 --method gpu --json | json_field gpu.adapter)"
echo "## GPU benchmark: $adapter, $(nproc) CPU threads, $(date -u +%F)"
echo
echo "| job | path | ms (in the run) | GPU ms (timestamps), or rate |"
echo "|---|---|---|---|"

# voxelize RES MODE LABEL ARGS...: one table row, medians over REPEATS.
voxelize_row() {
    local res="$1" mode="$2" label="$3"; shift 3
    local run=() gpu=()
    for _ in $(seq "$REPEATS"); do
        local out
        out="$("$BIN" voxelize "$BUNNY" -o "$WORK/v.vdb" --resolution "$res" --mode "$mode" --json --quiet "$@" 2>/dev/null || true)"
        [ -n "$out" ] || { echo "| bunny $mode $res | $label | failed | |"; return; }
        run+=("$(echo "$out" | json_field voxelize_s)")
        gpu+=("$(echo "$out" | json_field gpu.gpu_time_s)")
        rm -f "$WORK/v.vdb"
    done
    echo "| bunny $mode $res | $label | $(median_ms "${run[@]}") | $(median_ms "${gpu[@]}") |"
}

for res in $RES; do
    for mode in cover sep26 sep6; do
        voxelize_row "$res" "$mode" "CPU fast" --method fast
        voxelize_row "$res" "$mode" "GPU compute" --method gpu --gpu-path compute
        voxelize_row "$res" "$mode" "GPU raster" --method gpu --gpu-path raster
    done
    voxelize_row "$res" solid "CPU parity" --method parity
    voxelize_row "$res" solid "GPU parity" --method gpu
done

"$BIN" scene city -o "$WORK/city.obj" >/dev/null
for culling in none frustum occlusion occlusion-two-pass; do
    out="$("$BIN" render "$WORK/city.obj" --gpu -o "$WORK/city.png" --size "$SIZE" --culling "$culling" --repeat "$FRAMES" --json)"
    ms="$(echo "$out" | python3 -c "import json,sys
f=json.load(sys.stdin)['frames'][0]['frame_ms']
parts=[f.get(k) for k in ('gpu_cull','gpu_depth_pass','gpu_hiz','gpu_shade')]
print('%.2f' % sum(p for p in parts if p) if any(parts) else 'n/a')")"
    cpu="$(echo "$out" | json_field frames.0.frame_ms.cpu | python3 -c "import sys; print('%.2f' % float(sys.stdin.read()))")"
    echo "| render --gpu city $SIZE, culling $culling | GPU | $cpu (CPU side of a frame) | $ms |"
done

out="$("$BIN" spray "$WORK/city.obj" -o "$WORK/cloud.ply" --rays "$RAYS" --json)"
rate="$(echo "$out" | python3 -c "import json,sys; print('%.2f M rays/s' % (json.load(sys.stdin)['rays_per_s'] / 1e6))")"
echo "| spray $RAYS rays into the city | CPU | $(median_ms "$(echo "$out" | json_field spray_s)") | $rate |"

PY="${PYTHON:-python3}"
if "$PY" -c "import topovox" 2>/dev/null; then
    "$PY" scripts/gpu_batch_bench.py "$MESHES" "$BATCH" "$BATCH_RES" "$REPEATS"
else
    echo "| $BATCH meshes, voxelize_many | skipped: no topovox Python package for $PY (pip install ./python) | | |"
fi
