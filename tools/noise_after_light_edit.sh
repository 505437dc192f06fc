#!/usr/bin/env bash
# Noise of a relit image after a large light edit, selection by power against per-light shadow
# sampling [issue: relighting §3]: renders SCENE with two seeds in each mode, saves the states,
# relights LIGHT by FACTOR, and prints the RMSE between the two seeds' relit images (sqrt(2) x
# the noise) and the same for two fresh renders without the edit, for scale.
# Usage: tools/noise_after_light_edit.sh SCENE LIGHT FACTOR [WIDTH] [SPP] [obscura]
set -euo pipefail
scene=$1 light=$2 factor=$3 width=${4:-200} spp=${5:-4} obscura=${6:-build/obscura}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for mode in selection per-light; do
  for seed in 1 2; do
    "$obscura" render "$scene" --width "$width" --spp "$spp" --seed "$seed" --shadow-sampling "$mode" \
      --save-state "$work/$mode-$seed" -o "$work/$mode-$seed.exr" >/dev/null 2>&1
    "$obscura" relight "$work/$mode-$seed" --light "$light=$factor" -o "$work/$mode-$seed-relit.exr" >/dev/null 2>&1
  done
  echo "$mode: before the edit $("$obscura" compare "$work/$mode-1.exr" "$work/$mode-2.exr");" \
       "after $light x $factor $("$obscura" compare "$work/$mode-1-relit.exr" "$work/$mode-2-relit.exr")"
done
