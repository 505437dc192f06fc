#!/usr/bin/env python3
"""Frames per second of an `obscura view --log FILE` run (window or --offscreen), from each frame's
wall_ms (the whole frame on the host's clock, waits included), overall and per segment. A frame's
segment is what it applied, from its "actions" (first match wins):

    object move   move_object                   (an object dragged: dirty pixels retraced)
    light drag    move_light, add_light, remove_light (a light's own rays traced again)
    light edit    light_scale, light_color      (compose only)
    camera        camera_move, camera, load_view (the accumulation restarts with a preview)
    other         any other action (exposure, AOV, method, rays, ...)
    progressive   no action, GPU work: one more sample accumulated
    idle          no action, no GPU work: every sample (--spp) done, nothing changed

"busy" is every frame but the idle ones: with --spp 1, a still view's frames are idle and cost
next to nothing, so "all" alone would flatter the loop.

For each: frames, frames/s at the median frame, the median and the 95th-percentile frame wall ms
(the 5th percentile of frames/s: the slow frames a person notices), the median GPU ms
(frame_gpu_ms: the renderer's passes and the denoiser, by timestamps) and the median host CPU ms
of the frame's edits (edit_cpu_ms; 0 in logs older than it). Frame 0 (kernels and
buffers warming up) is left out unless --keep-first.

Usage: tools/view_log_summary.py LOG [--keep-first] [--json]
tools/gpu/view_benchmark_script.json is the benchmark these segments were made for.
"""
import argparse
import json
import math
import statistics
import sys

SEGMENTS = [
    ("object move", {"move_object"}),
    ("light drag", {"move_light", "add_light", "remove_light"}),
    ("light edit", {"light_scale", "light_color"}),
    ("camera", {"camera_move", "camera", "load_view"}),
]


def segment_of(frame):
    actions = set(frame.get("actions", []))
    for name, kinds in SEGMENTS:
        if actions & kinds:
            return name
    if actions:
        return "other"
    return "progressive" if frame.get("frame_gpu_ms", 0.0) > 0.0 else "idle"


def percentile(values, p):
    """The p-th percentile, nearest rank (a frame that happened, not an interpolation)."""
    ordered = sorted(values)
    rank = max(1, math.ceil(p / 100.0 * len(ordered)))
    return ordered[rank - 1]


def per_second(ms):
    return 1000.0 / ms if ms > 0 else float("inf")


def summary(frames):
    wall = [f["wall_ms"] for f in frames]
    median = statistics.median(wall)
    slow = percentile(wall, 95)
    return {
        "frames": len(frames),
        "fps_median": per_second(median),
        "fps_5th_percentile": per_second(slow),
        "fps_mean": per_second(sum(wall) / len(frames)),
        "wall_ms_median": median,
        "wall_ms_95th_percentile": slow,
        "gpu_ms_median": statistics.median(f.get("frame_gpu_ms", 0.0) for f in frames),
        "edit_cpu_ms_median": statistics.median(f.get("edit_cpu_ms", 0.0) for f in frames),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("log")
    parser.add_argument("--keep-first", action="store_true", help="count frame 0 too")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    args = parser.parse_args()
    with open(args.log) as f:
        frames = [json.loads(line) for line in f if line.strip()]
    if not args.keep_first:
        frames = [f for f in frames if f["frame"] != 0]
    if not frames:
        sys.exit(f"{args.log}: no frames to summarise")
    missing = [f["frame"] for f in frames if "wall_ms" not in f]
    if missing:
        sys.exit(f"{args.log}: frames without wall_ms (an older obscura?), first {missing[0]}")
    rows = {"all": summary(frames)}
    busy = [f for f in frames if segment_of(f) != "idle"]
    if busy:
        rows["busy"] = summary(busy)
    for name in [s for s, _ in SEGMENTS] + ["other", "progressive", "idle"]:
        part = [f for f in frames if segment_of(f) == name]
        if part:
            rows[name] = summary(part)
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(f"{args.log}: frames/s from each frame's wall_ms" + ("" if args.keep_first else " (frame 0 left out)"))
    print("| segment | frames | frames/s (median) | frames/s (5th pct) | frames/s (mean) | wall ms median "
          "| wall ms 95th pct | GPU ms median | edit CPU ms median |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, r in rows.items():
        print(f"| {name} | {r['frames']} | {r['fps_median']:.1f} | {r['fps_5th_percentile']:.1f} | {r['fps_mean']:.1f} | "
              f"{r['wall_ms_median']:.2f} | {r['wall_ms_95th_percentile']:.2f} | {r['gpu_ms_median']:.2f} | "
              f"{r['edit_cpu_ms_median']:.2f} |")


if __name__ == "__main__":
    main()
