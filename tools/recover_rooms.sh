#!/bin/bash
# recover_rooms.sh — reflectance recovery on every photo set against its answer key: the Cornell
# box (../shared/photos/cornell-box) and the rooms made by tools/cycles_photo_set.py
# (tests/data/photos/*), at the defaults and, with --first-design, also as the first design did
# it (the paper's merge, hidden surfaces at the mean indirect light, 64 gather rays, 3 iterations,
# spp 16).
# Prints recover's RMSE line and tools/recovery_report.py's table (issue 36's goals) per set.
#
#   tools/recover_rooms.sh [BUILD_DIR] [--first-design]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
first=${2:-}
shared=$(cd "$root/../shared" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

run() { # name scene photos.json truth [options...]
  local name=$1 scene=$2 photos=$3 truth=$4
  shift 4
  echo "== $name $*"
  /usr/bin/time -f "   wall %e s" "$build/obscura" recover "$scene" --photos "$photos" -o "$out/$name" --truth "$truth" "$@" \
    2>&1 | grep "RMSE\|gather:\|pixels from\|wall"
  /usr/bin/python3 "$root/tools/recovery_report.py" "$out/$name" "$photos" | tail -n +3
}

sets=("cornell-box|$shared/scenes/cornell-box/cornell-box.gltf|$shared/photos/cornell-box/lights.json")
for dir in "$root"/tests/data/photos/*/; do
  room=$(basename "$dir")
  sets+=("$room|$shared/scenes/$room/$room.gltf|$dir/lights.json")
  [ -f "$dir/noisy/lights.json" ] && sets+=("$room-noisy|$shared/scenes/$room/$room.gltf|$dir/noisy/lights.json")
done
for s in "${sets[@]}"; do
  IFS='|' read -r name scene photos <<<"$s"
  truth=$(dirname "$photos")/$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['albedo']['image'])" "$photos")
  run "$name" "$scene" "$photos" "$truth"
  if [ "$first" = "--first-design" ]; then
    run "$name-first" "$scene" "$photos" "$truth" --merge paper --hidden-bounces 0 --gather-rays 64 --iterations 3 --spp 16
  fi
done
