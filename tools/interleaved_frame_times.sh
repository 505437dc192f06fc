#!/bin/bash
# tools/interleaved_frame_times.sh OUTDIR — frame times (render --metrics gpu_ms) of the methods
# docs/BENCHMARKS.md ("Emission rays and the split of shading rays") compares, at 8 spp, 256 wide,
# measured in turn for three rounds so that a change of the shared machine's load hits each alike.
# Prints "name round ms" lines to OUTDIR/times.txt; take the median per name, and feed it to
# tools/speedup_from_curves.py with a converge CSV.
set -e
cd "$(dirname "$0")/.."
out=${1:?usage: tools/interleaved_frame_times.sh OUTDIR}
C=scenes/cornell-box/cornell-box.gltf; H=../shared/scenes/modern-hall/modern-hall.gltf
mkdir -p "$out"
for round in 1 2 3; do
  for cfg in "cb-ob-k1|$C|--ambient seen --emission-samples 1" "cb-ob-k16|$C|--ambient seen --emission-samples 16" \
             "cb-pt-k1|$C|--method pathtrace --emission-samples 1" "cb-pt-k4|$C|--method pathtrace --emission-samples 4" \
             "mh-ob-55|$H|--ambient seen" "mh-ob-82|$H|--ambient seen --shadow-rays 8 --obs-rays 2" \
             "mh-ob-55-k4|$H|--ambient seen --emission-samples 4" "mh-pt-k1|$H|--method pathtrace"; do
    IFS='|' read -r name scene opts <<< "$cfg"
    # shellcheck disable=SC2086
    nice ./build/obscura render "$scene" -o "$out/$name.exr" --width 256 --spp 8 --seed $round $opts \
      --metrics "$out/$name-r$round.json" > /dev/null 2>&1
    python3 -c "import json,sys; print(sys.argv[1], sys.argv[2], round(json.load(open(sys.argv[3]))['gpu_ms'], 1))" \
      "$name" $round "$out/$name-r$round.json" >> "$out/times.txt"
  done
done
