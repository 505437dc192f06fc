#!/usr/bin/env python3
"""Renders modern-hall once, relights it three ways without a ray, and writes a matplotlib
figure of the three side by side with their light scales.

    PYTHONPATH=build/python python3 python/examples/relight_modern_hall.py [OUT.png] [--width N]

The scene is ../shared/scenes/modern-hall (see its SOURCES.md); the figure goes to
modern-hall-relit.png by default.
"""
import argparse
import pathlib
import time

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import obscura

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENE = REPO.parent / "shared" / "scenes" / "modern-hall" / "modern-hall.gltf"

# The hall's lights (obscura.info or Scene.lights): five ceiling disks, four small panels, and
# four large windows and panels (light_rectangle_5..8) that light most of the room.
DISKS = [f"light_disk_{i}" for i in range(1, 6)]
WINDOWS = ["light_rectangle_6", "light_rectangle_7"]
PANELS = ["light_rectangle_5", "light_rectangle_8"]


def tonemap(radiance, exposure=0.0):
    """Linear radiance to sRGB for display, as the renderer's PNGs (exposure, clamp, sRGB curve)."""
    x = np.clip(radiance * 2.0 ** exposure, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", nargs="?", default="modern-hall-relit.png")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--exposure", type=float, default=-1.0, help="stops, for display (the hall is bright)")
    args = parser.parse_args()

    scene = obscura.Scene(str(SCENE))
    start = time.perf_counter()
    frame = obscura.render(scene, width=args.width, spp=args.spp)
    rendered = time.perf_counter() - start

    looks = {
        "as modelled": {},
        "evening: windows off, panels x0.3,\nceiling disks x4":
            {**{w: 0.0 for w in WINDOWS}, **{p: 0.3 for p in PANELS}, **{d: 4.0 for d in DISKS}},
        "blue windows (0.25, 0.45, 1.6),\norange panels (1.6, 0.8, 0.4)":
            {**{w: (0.25, 0.45, 1.6) for w in WINDOWS}, **{p: (1.6, 0.8, 0.4) for p in PANELS}},
    }
    images, times = [], []
    for scales in looks.values():
        start = time.perf_counter()
        images.append(frame.relight(scales))
        times.append(time.perf_counter() - start)
        # The relit frame is the sum of the per-light layers with the same scales.
        factors = np.array([np.broadcast_to(np.asarray(scales.get(n, 1.0), np.float32), (3,))
                            for n in frame.light_names])
        assert np.allclose(images[-1], np.einsum("lhwc,lc->hwc", frame.light_stack, factors), rtol=1e-4, atol=1e-5)

    fig, axes = plt.subplots(1, 3, figsize=(15, 3.9), constrained_layout=True)
    for ax, (title, scales), image, seconds in zip(axes, looks.items(), images, times):
        ax.imshow(tonemap(image, args.exposure))
        ax.set_title(f"{title}\nrelit in {seconds * 1e3:.0f} ms, no ray", fontsize=10)
        ax.axis("off")
    fig.suptitle(f"modern-hall, {frame.width}x{frame.height}, {args.spp} spp: rendered once in {rendered:.1f} s "
                 f"({frame.stats['device']}), {len(frame.light_names)} lights relit from its light stack, "
                 f"exposure {args.exposure:+g}",
                 fontsize=11)
    fig.savefig(args.output, dpi=100)
    print(f"{args.output}: {len(looks)} relightings of one render ({rendered:.1f} s); relit in "
          + ", ".join(f"{t * 1e3:.0f} ms" for t in times))


if __name__ == "__main__":
    main()
