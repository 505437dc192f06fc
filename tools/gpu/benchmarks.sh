#!/bin/bash
# benchmarks.sh BUNDLE_DIR OUT_DIR [quick] — the traversal and frame figures (issue: traversal and
# frame speed) on whatever Vulkan device the bundle finds first by rank (a discrete GPU before a
# CPU), in one run that fits a 15-minute device lease. BUNDLE_DIR comes from make_bundle.sh.
# OUT_DIR gets log.txt (everything printed) and a few images and JSON files, at most 8 files.
# "quick" shrinks every size (and lets modern-hall stand in for Sponza, less the Sponza steps that
# would repeat a modern-hall one) so that the script itself can be tried on lavapipe first, as
# tests/scripts/gpu_benchmarks_smoke.sh does.
#
#   bench-rays, both scenes, with the device's own traversal and tree (render/scene_data/bvh_layout.h)
#     and with each other traversal (--traversal): closest-hit and shadow rays per second (4M random
#     rays, the best of 5 timed repeats, the first 100k checked against the CPU traversal, on
#     Sponza the first 1M), on modern-hall the paper's budget at 800x600 per pass (--passes) with
#     the device's traversal and the wide one; the device's traversal without spatial splits
#     (--spatial-splits 0), and on Sponza with its BVH read as an SSBO (--bvh-items storage),
#     with its cull on pop (--cull-on-pop) and through the refilling loop (--trace-shape)
#   render: the paper's budget (8 spp), modern-hall 800x600 (the device's traversal, then the
#     wide one) and Sponza 1920x1080 under a uniform sky (Sponza has no lights), --metrics
#   view --offscreen: the window's frame loop without a display, modern-hall 1280x720, 1 spp,
#     denoised, through tools/gpu/view_benchmark_script.json (camera moves, a light added and
#     dragged, a light's intensity dragged, an object dragged): view.jsonl, frames/s wall per
#     segment (tools/view_log_summary.py)
#   relight: modern-hall 800x600, 1 spp: a light's scale and colour, add and remove a point light,
#     move an object, add an emissive quad, each twice (edits.jsonl: GPU, wall and host CPU ms per
#     edit; the second round without first-use costs)
#   recover: the modern hall's six photographs (320x180, photos/modern-hall) to reflectance, its
#     gather traced on the device, against the answer key (--truth): RMSE and seconds per stage
# STEP_LIMIT (seconds, default 150) bounds each step, so that a hang cannot eat the lease.
set -u
bundle=$(cd "${1:?usage: benchmarks.sh BUNDLE_DIR OUT_DIR [quick]}" && pwd)
out=${2:?usage: benchmarks.sh BUNDLE_DIR OUT_DIR [quick]}
mkdir -p "$out"
out=$(cd "$out" && pwd)
quick=${3:-}
obscura=$bundle/obscura
scenes=$bundle/scenes
export LD_LIBRARY_PATH=$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

tools=$(cd "$(dirname "$0")" && pwd)
rays=4194304 verify=1000000 check=100000 passes=800x600 hall=(800 600) sponza=(1920 1080) view=(1280 720) repeats=5
limit=${STEP_LIMIT:-150}
hall_scene=$scenes/modern-hall/modern-hall.gltf sponza_scene=$scenes/sponza/sponza.gltf
if [ "$quick" = quick ]; then
  # Every step as the GPU runs it, but small: modern-hall stands in for Sponza (whose load and
  # BVH build alone take 3 s a step on 2 cores), and the Sponza steps that would repeat a
  # modern-hall one are left out (`full`).
  # One timed repeat: the figures are not read here, only that every step runs.
  rays=65536 verify=16384 check=16384 passes=80x60 hall=(80 60) sponza=(96 54) view=(64 36) limit=300 repeats=1
  sponza_scene=$hall_scene
fi

full() { # step ...: a step of the whole run only: in quick mode (modern-hall for Sponza) it would
  # repeat a bench-hall step exactly
  [ "$quick" = quick ] || "$@"
}

step() { # name command...: runs it under a time limit, everything into log.txt
  local name=$1 start rc
  shift
  echo "==== $name: $*"
  start=$(date +%s%N)
  timeout "$limit" stdbuf -oL -eL "$@" 2>&1
  rc=$?
  echo "==== $name: exit $rc after $((($(date +%s%N) - start) / 1000000)) ms"
}

{
  echo "date $(date -u +%FT%TZ), $(uname -m), $(nproc) cores"
  command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
  ldd "$obscura" | grep 'not found' && echo "LIBRARIES MISSING"
  step info "$obscura" info
  step bench-hall "$obscura" bench-rays "$hall_scene" --rays "$rays" --repeats "$repeats" --verify "$check" --passes "$passes"
  step bench-hall-wide "$obscura" bench-rays "$hall_scene" --rays "$rays" --repeats "$repeats" --verify "$check" \
    --passes "$passes" --traversal wide
  step bench-hall-binary "$obscura" bench-rays "$hall_scene" --rays "$rays" --repeats "$repeats" --verify "$check" \
    --traversal binary
  step bench-hall-no-splits "$obscura" bench-rays "$hall_scene" --rays "$rays" --repeats "$repeats" --spatial-splits 0
  full step bench-sponza "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --verify "$verify"
  full step bench-sponza-wide "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --verify "$check" \
    --traversal wide
  full step bench-sponza-binary "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --verify "$check" \
    --traversal binary
  full step bench-sponza-no-splits "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --spatial-splits 0
  step bench-sponza-storage "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --bvh-items storage
  step bench-sponza-cull "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --cull-on-pop
  # Several rays per invocation: the binary refilling loop (slower than one ray each on an H200).
  step bench-sponza-64x4 "$obscura" bench-rays "$sponza_scene" --rays "$rays" --repeats "$repeats" --traversal binary \
    --trace-shape 64x4 --verify "$check"
  step render-hall "$obscura" render "$hall_scene" --width "${hall[0]}" \
    --height "${hall[1]}" --spp 8 --shadow-rays 5 --obs-rays 5 -o "$out/modern-hall.png" --metrics "$out/modern-hall.metrics.json"
  step render-hall-wide "$obscura" render "$hall_scene" --width "${hall[0]}" \
    --height "${hall[1]}" --spp 8 --shadow-rays 5 --obs-rays 5 -o "$work/modern-hall-wide.png" --metrics "$work/modern-hall-wide.metrics.json" \
    --traversal wide
  cat "$work/modern-hall-wide.metrics.json"; echo
  step render-sponza "$obscura" render "$sponza_scene" --width "${sponza[0]}" --height "${sponza[1]}" \
    --spp 8 --shadow-rays 5 --obs-rays 5 --background 2,2,2 -o "$out/sponza.png" --metrics "$out/sponza.metrics.json"
  step view-offscreen "$obscura" view "$hall_scene" --offscreen --width "${view[0]}" --height "${view[1]}" --spp 1 \
    --script "$tools/view_benchmark_script.json" --log "$out/view.jsonl" --screenshot "$out/view.png"
  python3 "$tools/../view_log_summary.py" "$out/view.jsonl"
  step relight-hall "$obscura" relight "$hall_scene" --edits "$tools/bench_edits.json" \
    -o "$work/relight" --width "${hall[0]}" --height "${hall[1]}" --spp 1 --png
  cat "$work/relight/edits.jsonl"
  cp "$work/relight/frame-012.png" "$out/relight-last-frame.png"
  step recover-hall "$obscura" recover "$hall_scene" --photos "$bundle/photos/modern-hall/lights.json" \
    -o "$work/recover" --truth "$bundle/photos/modern-hall/albedo.exr"
  cat "$work/recover/recover.json"; echo
} > "$out/log.txt" 2>&1
cat "$out/log.txt"
