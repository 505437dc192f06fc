#!/bin/bash
# gpu_benchmarks_smoke.sh OBSCURA SCENES_DIR — tools/gpu/benchmarks.sh in its quick mode here (on
# lavapipe), with a bundle of links to this build's binary and to the shared scenes instead of
# make_bundle.sh's copies: every step must exit 0 and leave its files, so that the script a GPU
# session relies on keeps up with the commands it calls.
set -euo pipefail
obscura=${1:?usage: gpu_benchmarks_smoke.sh OBSCURA SCENES_DIR}
scenes=${2:?usage: gpu_benchmarks_smoke.sh OBSCURA SCENES_DIR}
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bundle/lib" "$work/bundle/scenes"
ln -s "$obscura" "$work/bundle/obscura"
ln -s "$scenes/modern-hall" "$scenes/sponza" "$work/bundle/scenes/"
mkdir -p "$work/bundle/photos"
ln -s "$source_dir/tests/data/photos/modern-hall" "$work/bundle/photos/"
"$source_dir/tools/gpu/benchmarks.sh" "$work/bundle" "$work/out" quick >/dev/null
log=$work/out/log.txt
steps=$(grep -c '^==== [a-z0-9-]*: exit ' "$log" || true)
passed=$(grep -c '^==== [a-z0-9-]*: exit 0 ' "$log" || true)
if [ "$steps" -ne 14 ] || [ "$passed" -ne 14 ]; then
  echo "benchmarks.sh: $passed of $steps steps exited 0 (14 expected; quick leaves out 4 of the 18):"
  cat "$log"
  exit 1
fi
for f in modern-hall.png modern-hall.metrics.json sponza.png sponza.metrics.json relight-last-frame.png view.png view.jsonl; do
  [ -s "$work/out/$f" ] || { echo "benchmarks.sh left no $f"; cat "$log"; exit 1; }
done
grep -q 'recover: RMSE against' "$log" || { echo "recover measured nothing against the answer key"; cat "$log"; exit 1; }
grep -q '0 mismatches' "$log" || { echo "bench-rays --verify found traversal errors"; cat "$log"; exit 1; }
echo "benchmarks.sh quick: 14 steps, all files"
