#!/usr/bin/env bash
# bench_split.sh OBSCURA SCENE OUTDIR [render options...] — the cost of splitting a render into a
# farm's parts on one machine: the frame rendered as 1, 4 and 16 parts (tools/farm/part_args.sh's
# numbering: 4 = 4 strips, 16 = 4 strips x 4 sample ranges; every part its own process, one after
# another), then merged. Prints a markdown table: the parts' summed wall time (each process from
# start to exit: scene load, BVH, the lights' reach, render, write), their summed GPU time, the
# merge's wall time, and the bytes of the part files. The options must include --spp.
# Example: tools/farm/bench_split.sh build/obscura ../shared/scenes/modern-hall/modern-hall.gltf \
#            /tmp/split --width 400 --height 300 --spp 8
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: bench_split.sh OBSCURA SCENE OUTDIR [render options, with --spp N]" >&2; exit 2; }
bin=$1 scene=$2 out=$3
shift 3
spp=""
args=("$@")
for ((i = 0; i < ${#args[@]}; ++i)); do [ "${args[i]}" = "--spp" ] && spp=${args[i + 1]}; done
[ -n "$spp" ] || { echo "bench_split.sh: give --spp N among the render options" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
now() { date +%s.%N; }
add() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.6f", a + b }'; }
echo "| parts | tiles x ranges | parts' wall s (sum) | parts' GPU ms (sum) | merge s | part files MiB |"
echo "|---:|---|---:|---:|---:|---:|"
for config in "1 1" "4 4" "16 4"; do
  read -r parts tiles <<<"$config"
  dir=$out/p$parts
  rm -rf "$dir" && mkdir -p "$dir"
  wall=0 gpu=0
  for ((k = 0; k < parts; ++k)); do
    read -r -a part <<<"$("$here/part_args.sh" "$k" "$parts" "$tiles" "$spp")"
    start=$(now)
    log=$("$bin" render "$scene" "$@" "${part[@]}" -o "$dir/$("$here/part_args.sh" --name "$k" "$parts" "$tiles" "$spp")" 2>&1)
    wall=$(add "$wall" "$(add "$(now)" "-$start")")
    ms=$(echo "$log" | sed -n 's/.*, \([0-9.]*\) ms GPU.*/\1/p' | tail -1)
    gpu=$(add "$gpu" "$ms")
  done
  start=$(now)
  "$bin" merge "$dir" -o "$dir/frame.exr" 2>/dev/null
  merge=$(add "$(now)" "-$start")
  bytes=$(du -cb "$dir"/part-*.exr | tail -1 | cut -f1)
  printf "| %d | %d x %d | %.2f | %.0f | %.2f | %.1f |\n" "$parts" "$tiles" $((parts / tiles)) "$wall" "$gpu" "$merge" \
    "$(awk -v b="$bytes" 'BEGIN { print b / 1048576 }')"
done
