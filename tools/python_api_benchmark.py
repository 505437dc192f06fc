#!/usr/bin/env python3
"""What the Python API costs beside the command line, on one scene: wall ms of a render from the
command line (a process of its own), the first render in a Python process (its Vulkan context and
kernels made), later renders (the context kept), relight() per call, the light stack's first
access, and a session's light edit; with the largest difference between the API's frame and the
command line's EXR (0 when they agree to the bit).

    PYTHONPATH=build/python python3 tools/python_api_benchmark.py SCENE [--width W] [--spp N] [--repeats R]
"""
import argparse
import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import obscura


def ms(start):
    return (time.perf_counter() - start) * 1e3


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--binary", default=str(pathlib.Path(__file__).resolve().parents[1] / "build" / "obscura"))
    args = parser.parse_args()
    settings = dict(width=args.width, spp=args.spp)

    with tempfile.TemporaryDirectory() as temp:
        exr = os.path.join(temp, "frame.exr")
        start = time.perf_counter()
        subprocess.run([args.binary, "render", args.scene, "-o", exr, "--width", str(args.width), "--spp",
                        str(args.spp)], check=True, capture_output=True)
        cli_ms = ms(start)
        cli = obscura.read_image(exr)

    start = time.perf_counter()
    scene = obscura.Scene(args.scene)
    first = obscura.render(scene, **settings)
    first_ms = ms(start)
    later = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        r = obscura.render(scene, **settings)
        later.append(ms(start))
    difference = max(float(np.abs(r.aovs[name] - cli[name]).max()) for name in r.aovs)

    start = time.perf_counter()
    stack = r.light_stack
    stack_ms = ms(start)
    scales = {name: (1.0 + i % 3, 1.0, 0.5) for i, name in enumerate(r.light_names)}
    relight = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        r.relight(scales)
        relight.append(ms(start))
    numpy_ms = []
    factors = np.array([scales[n] for n in r.light_names], np.float32)
    for _ in range(args.repeats):
        start = time.perf_counter()
        np.einsum("lhwc,lc->hwc", stack, factors)
        numpy_ms.append(ms(start))

    with obscura.Session(scene, **settings) as s:
        edit = []
        for i in range(args.repeats):
            start = time.perf_counter()
            s.apply({"light": r.light_names[0], "scale": 0.5 + 0.1 * i})
            edit.append(ms(start))

    print(f"scene {args.scene}, {r.width}x{r.height}, {args.spp} spp, {len(r.light_names)} lights, "
          f"device {r.stats['device']}")
    print(f"command line render (own process, EXR written): {cli_ms:.0f} ms")
    print(f"python first render (context and kernels made): {first_ms:.0f} ms")
    print(f"python later renders: median {np.median(later):.0f} ms (of {args.repeats})")
    print(f"largest |python - command line EXR| over every AOV: {difference:g}")
    print(f"light_stack first access ({stack.shape[0]} x {stack.shape[1]} x {stack.shape[2]} x 3): {stack_ms:.1f} ms")
    print(f"relight(): median {np.median(relight):.1f} ms; NumPy einsum over the stack: median "
          f"{np.median(numpy_ms):.1f} ms")
    print(f"Session light edit (apply, composed for display): median {np.median(edit):.1f} ms")


if __name__ == "__main__":
    main()
