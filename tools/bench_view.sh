#!/usr/bin/env bash
# Window figures [issue: real-time window]: frames per second and ms per frame of `obscura view`
# at 640x480, progressive (one full sample per frame) and preview (the first frame after a camera
# move: one primary sample, one shadow and one obscurance ray), and of a light edit (one compose),
# from its per-frame log. Runs under xvfb-run when there is no display.
# Usage: tools/bench_view.sh [build/obscura] [width] [height] > table.md
set -euo pipefail
obscura=${1:-build/obscura}
width=${2:-640}
height=${3:-480}
shared="$(cd "$(dirname "$0")/../.." && pwd)/shared/scenes"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() { if [ -n "${DISPLAY:-}" ]; then "$@"; else xvfb-run -a -s "-screen 0 1280x1024x24" "$@"; fi; }

bench() { # name scene light [options...]
  local name=$1 scene=$2 light=$3
  shift 3
  # Frames 0-4 progressive, 5-8 dragged (previews). Then a light edit on a finished frame: one
  # sample (frame 0), the edit at frame 2, when nothing is traced any more.
  cat > "$work/move.json" <<JSON
[{"frame": 5, "drag": [4, 0]}, {"frame": 6, "drag": [4, 0]}, {"frame": 7, "drag": [4, 0]}, {"frame": 8, "drag": [4, 0]}]
JSON
  cat > "$work/edit.json" <<JSON
[{"frame": 2, "panel": {"light": "$light", "scale": 0.5}}]
JSON
  for denoise in --no-denoise ""; do
    run "$obscura" view "$scene" --width "$width" --height "$height" --frames 9 --no-panel $denoise \
      --script "$work/move.json" --log "$work/frames.jsonl" "$@" >/dev/null 2>&1
    run "$obscura" view "$scene" --width "$width" --height "$height" --frames 3 --spp 1 --no-panel $denoise \
      --script "$work/edit.json" --log "$work/edit.jsonl" "$@" >/dev/null 2>&1
    python3 - "$work/frames.jsonl" "$work/edit.jsonl" "$name" "${width}x${height}" "${denoise:-denoised}" <<'PY'
import json, statistics, sys
frames = [json.loads(l) for l in open(sys.argv[1])]
edit = [json.loads(l) for l in open(sys.argv[2])][2]
name, size, mode = sys.argv[3:6]
def med(rows, key): return statistics.median(r[key] for r in rows)
progressive = frames[1:5]
preview = [f for f in frames if f["preview"]]
def cell(rows):
    text = "%.0f ms (%.2f fps), GPU %.0f ms" % (med(rows, "frame_ms"), 1000.0 / med(rows, "frame_ms"), med(rows, "gpu_ms"))
    if med(rows, "denoise_ms") > 0: text += " + denoise %.0f ms" % med(rows, "denoise_ms")
    return text + ", %.2f Mrays/s" % (med(rows, "rays") / med(rows, "gpu_ms") / 1e3)
print("| %s | %s | %s | %s | %s | %.0f ms (%d rays) |" % (name, size, mode.replace("--no-denoise", "raw"),
      cell(progressive), cell(preview), edit["frame_ms"], edit["rays"]))
passes = sorted({p for f in progressive + preview for p in f["pass_ms"]})
def per_pass(rows): return ", ".join("%s %.0f" % (p, statistics.median(r["pass_ms"].get(p, 0.0) for r in rows)) for p in passes)
print("|  |  | GPU ms per pass |  %s | %s |  |" % (per_pass(progressive), per_pass(preview)))
PY
  done
}

echo "| scene | size | frames | progressive frame (median of 4) | preview frame (median of 4) | light edit frame |"
echo "|---|---|---|---|---|---|"
bench modern-hall "$shared/modern-hall/modern-hall.gltf" light_disk_1
bench sponza "$shared/sponza/sponza.gltf" background --background 2,2,2
