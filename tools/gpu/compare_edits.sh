#!/bin/bash
# compare_edits.sh BUNDLE_DIR BASELINE_BINARY OUT_DIR [quick] — the edits' figures of two obscura
# binaries on the same device in one run: `relight --edits tools/gpu/bench_edits.json` (modern-hall
# 800x600, 1 spp) and the offscreen window loop (tools/gpu/view_benchmark_script.json, 1280x720,
# 1 spp, denoised), each binary twice, alternating (new, baseline, new, baseline), so that a
# host or a GPU clock that drifts during the run shows as spread, not as a difference. Prints the
# median wall ms per edit of each binary (and the new one's host CPU ms) and the window's frames/s
# per segment. BASELINE_BINARY runs with BUNDLE_DIR's libraries (build it with make_bundle.sh
# from the baseline commit). "quick" shrinks every size, to try the script on lavapipe first.
set -u
bundle=$(cd "${1:?usage: compare_edits.sh BUNDLE_DIR BASELINE_BINARY OUT_DIR [quick]}" && pwd)
baseline=$(realpath "${2:?baseline binary}")
out=${3:?output folder}
mkdir -p "$out"
out=$(cd "$out" && pwd)
tools=$(cd "$(dirname "$0")" && pwd)
export LD_LIBRARY_PATH=$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
scene=$bundle/scenes/modern-hall/modern-hall.gltf
hall=(800 600) view=(1280 720)
[ "${4:-}" = quick ] && hall=(80 60) view=(64 36)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
{
  echo "date $(date -u +%FT%TZ)"
  command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
  for round in 1 2; do
    for who in new baseline; do
      binary=$bundle/obscura
      [ $who = baseline ] && binary=$baseline
      timeout 120 "$binary" relight "$scene" --edits "$tools/bench_edits.json" -o "$work/$who-$round" \
        --width "${hall[0]}" --height "${hall[1]}" --spp 1 >/dev/null 2>"$work/$who-$round.err" ||
        { echo "$who round $round: relight failed"; cat "$work/$who-$round.err"; }
      timeout 120 "$binary" view "$scene" --offscreen --width "${view[0]}" --height "${view[1]}" --spp 1 \
        --script "$tools/view_benchmark_script.json" --log "$work/view-$who-$round.jsonl" >/dev/null 2>&1 ||
        echo "$who round $round: view failed"
    done
  done
  python3 - "$work" <<'PY'
import json, statistics, sys, os
work = sys.argv[1]
def edits(who):
    runs = []
    for r in (1, 2):
        path = os.path.join(work, f"{who}-{r}", "edits.jsonl")
        if os.path.exists(path):
            runs.append([json.loads(l) for l in open(path)])
    return runs
new, base = edits("new"), edits("baseline")
print("| edit | kind | new wall ms (runs) | baseline wall ms (runs) | new host CPU ms | new reach ms |")
print("|---|---|---|---|---|---|")
for i, e in enumerate(new[0] if new else []):
    nw = [run[i]["total_ms"] for run in new]
    bw = [run[i]["total_ms"] for run in base if i < len(run)]
    cpu = [run[i].get("cpu_ms", 0.0) for run in new]
    reach = [run[i].get("reach", {}).get("ms", 0.0) for run in new]
    fmt = lambda v: " / ".join(f"{x:.1f}" for x in v)
    print(f"| {i} | {e['kind']} | {fmt(nw)} | {fmt(bw)} | {fmt(cpu)} | {fmt(reach)} |")
PY
  for who in new baseline; do
    for round in 1 2; do
      echo "== view, $who, round $round"
      python3 "$tools/../view_log_summary.py" "$work/view-$who-$round.jsonl" | grep -E "^\| (segment|camera|light drag|object move|light edit)"
    done
  done
} 2>&1 | tee "$out/compare.txt"
