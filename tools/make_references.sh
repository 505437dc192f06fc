#!/usr/bin/env bash
# Regenerates the reference images of the image tests. Inspect them by eye before committing.
set -euo pipefail
cd "$(dirname "$0")/.."
./build/obscura render scenes/cornell-box/cornell-box.gltf -o tests/data/cornell_albedo_64.exr \
  --width 64 --height 64 --spp 16 --seed 1 --aov albedo
./build/obscura render scenes/cornell-box/cornell-box.gltf -o /tmp/cornell_albedo_64.png \
  --width 64 --height 64 --spp 16 --seed 1 --aov albedo
echo "wrote tests/data/cornell_albedo_64.exr (preview: /tmp/cornell_albedo_64.png)"
