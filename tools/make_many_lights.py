#!/usr/bin/python3
"""make_many_lights.py — writes a many-light glTF scene for the light tree's benchmark (issue 8,
docs/BENCHMARKS.md "Light tree"): more lights than lights.glsl's flat selection takes (64).

    /usr/bin/python3 tools/make_many_lights.py OUTPUT.gltf

A 40 m floor with 24 grey boxes (shadows), 150 point lights and 30 small emissive quads facing
down: 140 dim lights (points of 0.5 to 3 cd, quads of radiance 2 to 6) within 8 m of the centre at
0.3 to 2.5 m, and 40 bright points (300 to 1200 cd) 40 to 80 m away, which selection by power
picks almost always although the dim ones light most of what the camera sees. Deterministic.
Uses make_hard_scenes.py's writer (buffers embedded as a data URI).
"""
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_hard_scenes import Gltf, box, quat_x  # noqa: E402


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_many_lights.py OUTPUT.gltf")
    rng = random.Random(8)
    g = Gltf()
    g.doc["asset"]["generator"] = "tools/make_many_lights.py"
    floor = g.material("floor", (0.6, 0.6, 0.6))
    grey = g.material("box", (0.5, 0.45, 0.4))
    g.mesh("floor", [(-20.0, 0.0, -20.0), (20.0, 0.0, -20.0), (20.0, 0.0, 20.0), (-20.0, 0.0, 20.0)],
           [(0, 2, 1), (0, 3, 2)], floor)
    for i in range(24):
        x, z = rng.uniform(-9, 9), rng.uniform(-9, 9)
        w, h, d = rng.uniform(0.3, 1.2), rng.uniform(0.3, 1.8), rng.uniform(0.3, 1.2)
        p, t = box((x - w, 0.0, z - d), (x + w, h, z + d))
        g.mesh("box%d" % i, p, t, grey)
    for i in range(110):
        r, phi = 8.0 * math.sqrt(rng.random()), 2 * math.pi * rng.random()
        g.light({"name": "near%d" % i, "type": "point", "intensity": rng.uniform(0.5, 3.0), "color": [1.0, 0.9, 0.8]},
                translation=(r * math.cos(phi), rng.uniform(0.3, 2.5), r * math.sin(phi)))
    for i in range(30):
        r, phi = 8.0 * math.sqrt(rng.random()), 2 * math.pi * rng.random()
        x, y, z, a = r * math.cos(phi), rng.uniform(1.0, 2.5), r * math.sin(phi), rng.uniform(0.05, 0.2)
        lamp = g.material("lamp%d" % i, (0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0), strength=rng.uniform(2.0, 6.0))
        # Counter-clockwise seen from below: the quad faces down (-y).
        g.mesh("lamp%d" % i, [(x - a, y, z - a), (x + a, y, z - a), (x + a, y, z + a), (x - a, y, z + a)],
               [(0, 1, 2), (0, 2, 3)], lamp)
    for i in range(40):
        r, phi = rng.uniform(40, 80), 2 * math.pi * rng.random()
        g.light({"name": "far%d" % i, "type": "point", "intensity": rng.uniform(300, 1200), "color": [0.8, 0.9, 1.0]},
                translation=(r * math.cos(phi), rng.uniform(5, 25), r * math.sin(phi)))
    g.camera((0.0, 9.0, 16.0), 0.9, rotation=quat_x(-0.55))
    g.write(sys.argv[1])


if __name__ == "__main__":
    main()
