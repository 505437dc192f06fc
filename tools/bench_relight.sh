#!/usr/bin/env bash
# Relighting figures [issue: relighting]: per scene and size, the GPU ms and wall ms of a light
# edit (the fast light-mix path), of adding a point light (its shadow rays only), of removing it,
# of moving an object (dirty pixels only; the fraction retraced) and of adding an emissive quad
# (its light everywhere, its surface's dirty pixels; the fraction retraced), from
# `obscura relight SCENE --edits` (edits.jsonl), and the wall time of `obscura relight DIR` on a
# saved state. Usage: tools/bench_relight.sh [build/obscura] [spp] [WxH ...] > table.md
# (sizes default to 400x300 and 800x600)
set -euo pipefail
obscura=${1:-build/obscura}
spp=${2:-1}
shared="$(cd "$(dirname "$0")/../.." && pwd)/shared/scenes"
repo="$(cd "$(dirname "$0")/.." && pwd)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

bench() { # name scene light width height position object
  local name=$1 scene=$2 light=$3 width=$4 height=$5 position=$6 object=$7
  cat > "$work/edits.json" <<JSON
[{"light": "$light", "scale": 0.3},
 {"light": "$light", "color": [1.0, 0.6, 0.3]},
 {"add_light": {"type": "point", "name": "bench_bulb", "position": $position, "color": [1, 1, 1], "intensity": 5}},
 {"remove_light": "bench_bulb"},
 {"move": "$object", "translate": [0.1, 0.0, 0.1]},
 {"add_light": {"type": "quad", "name": "bench_panel", "corner": $position, "edge1": [0.5, 0, 0], "edge2": [0, 0, 0.5],
                "emission": [4, 4, 4]}}]
JSON
  "$obscura" relight "$scene" --edits "$work/edits.json" -o "$work/out" --width "$width" --height "$height" \
    --spp "$spp" >/dev/null 2>&1
  "$obscura" render "$scene" --width "$width" --height "$height" --spp "$spp" --save-state "$work/state" \
    -o "$work/r.png" >/dev/null 2>&1
  local start end
  start=$(date +%s%N)
  "$obscura" relight "$work/state" --light "$light=0.5" -o "$work/relit.png" >/dev/null 2>&1
  end=$(date +%s%N)
  python3 - "$work/out/edits.jsonl" "$name" "${width}x${height}" "$spp" $(((end - start) / 1000000)) <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
name, size, spp, state_ms = sys.argv[2:6]
def gpu(l): return sum(l["gpu_ms"].values())
def fmt(l): return "%.1f GPU / %.1f wall" % (gpu(l), l["total_ms"])
add, move, quad = lines[2], lines[4], lines[5]
w, h = map(int, size.split("x"))
print("| %s | %s | %s | %s | %s | %s (%d shadow rays) | %s | %s (%.0f %% retraced) | %s (%.0f %% retraced) | %s |" % (
    name, size, spp, fmt(lines[0]), fmt(lines[1]), fmt(add), add["rays"].get("shadow", 0), fmt(lines[3]), fmt(move),
    100.0 * move["pixels_retraced"] / (w * h), fmt(quad), 100.0 * quad["pixels_retraced"] / (w * h), state_ms))
PY
}

echo "| scene | size | spp | light scale (ms) | light colour (ms) | add point light (ms) | remove it (ms) | move an object (ms) | add an emissive quad (ms) | relight DIR wall (ms) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
sizes=("${@:3}")
((${#sizes[@]})) || sizes=(400x300 800x600)
for size in "${sizes[@]}"; do
  set -- ${size/x/ }
  bench cornell-box "$repo/scenes/cornell-box/cornell-box.gltf" light_rectangle_1 "$1" "$2" "[0.0, 1.0, 0.3]" cube_2
  bench modern-hall "$shared/modern-hall/modern-hall.gltf" light_rectangle_6 "$1" "$2" "[0.0, 3.0, 1.0]" Mesh017
done
