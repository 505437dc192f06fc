# cycles_photo_set.py — a whole set of synthetic "photographs" of a glTF room for reflectance
# recovery, made with Blender Cycles by the recipe of shared/photos/cornell-box/README.md and
# tools/cycles_photo.py (one small spherical lamp per shot, the room's own emitters off, every
# material a Lambertian diffuser of its base colour or base-colour texture, box filter, black
# world, no Russian roulette before the bounce limit, no clamping, no denoising, CPU), in one
# Blender process:
#
#   DIR/lights.json            the set as `obscura recover --photos` reads it (photo_set.h), with
#                              the chosen positions, each lamp's coverage and the render settings
#   DIR/photo-00k.exr          the shots (RGB half float, ZIP, linear radiance)
#   DIR/albedo.exr             Cycles' Diffuse Color pass (the answer key: tests only)
#   DIR/new-lamp.exr           the same room lit by one more lamp where no shot's lamp was (for
#                              remodel's round trip), its position in lights.json "new_lamp"
#   DIR/repeat/photo-00k.exr   shots 0 and 1 again with other seeds: the photographs' own noise
#   DIR/noisy/lights.json, DIR/noisy/photo-00k.exr   (with --noisy-spp N) every shot at N samples
#
# Bounces: 16 by default, where the light has converged (the recipe of the Cornell box's photographs
# stops at 6). A room lit mostly by bounces loses a lot to 6: the staircase's new-lamp photograph at
# 16 bounces is 2.5 % brighter overall and 8.4 % where the lamp lights nothing directly (32 bounces
# add nothing more within 0.5 %), and the recovery and remodel model every bounce, so a truncated
# photograph reads as their error (BENCHMARKS, "The photographs' bounces").
# --positions-from OLD/lights.json renders the lamps that set chose (the choice takes minutes).
#
# Lamp positions are chosen as for the Cornell box's photographs: a 13 x 13 grid over the middle
# 70 % of the extent of the floor the camera sees, at 70 / 77.5 / 85 % of the floor-to-ceiling
# height above each grid point; a candidate is kept if it stays at least 8 % of that height from
# every surface; its coverage is the fraction of the surface points the camera sees that its
# centre lights directly. Candidates lighting at least half of them are preferred (the best third
# by coverage where none does), and the shots are picked by farthest-point sampling starting from
# the one that lights the most; the new lamp is the next farthest point.
#
# Needs Blender 3.4 (Debian 12: apt-get install blender):
#   blender -b -P tools/cycles_photo_set.py -- SCENE.gltf -o DIR [--width 320] [--height 180]
#       [--spp 512] [--shots 6] [--noisy-spp 64] [--power 30] [--radius 0.04] [--threads 2]
#       [--bounces 16] [--positions-from OLD/lights.json] [--shots-only]
import argparse
import json
import math
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_photo  # noqa: E402  (the recipe's importer, materials and render settings)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender -b -P tools/cycles_photo_set.py --")
    p.add_argument("scene", help="the glTF room")
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=180)
    p.add_argument("--spp", type=int, default=512)
    p.add_argument("--shots", type=int, default=6)
    p.add_argument("--noisy-spp", type=int, default=0, help="also render every shot at this many samples")
    p.add_argument("--power", type=float, default=30.0, help="Blender point-light power, W")
    p.add_argument("--radius", type=float, default=0.04, help="lamp radius")
    p.add_argument("--bounces", type=int, default=16, help="light bounces (16: converged)")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--camera", type=int, default=0, help="the glTF camera")
    p.add_argument("--dry-run", action="store_true", help="choose the lamps and write lights.json only")
    p.add_argument("--positions-from", help="a set's lights.json: its lamps (and their coverages) instead of choosing")
    p.add_argument("--new-lamp-only", action="store_true", help="render new-lamp.exr only (with --positions-from: "
                   "what another bounce count or sample count changes)")
    p.add_argument("--shots-only", action="store_true", help="the shots and albedo.exr only, no new lamp or "
                   "repeats (a set's accuracy at another sample count, for a fraction of the time)")
    return p.parse_args(argv)


def to_gltf(v):
    """Blender (x, y, z) with Z up is glTF (x, z, -y) with Y up."""
    return [v.x, v.z, -v.y]


def from_gltf(p):
    return Vector((p[0], -p[2], p[1]))


def cast(scene, depsgraph, origin, direction, distance=1.0e9):
    hit, location, normal, _, _, _ = scene.ray_cast(depsgraph, origin, direction, distance=distance)
    return (location, normal) if hit else None


def visible_points(scene, depsgraph, camera, width, height, columns):
    """Surface points and camera-facing normals seen through a grid of the image."""
    rows = max(1, round(columns * height / width))
    frame = [camera.matrix_world @ v for v in camera.data.view_frame(scene=scene)]
    # view_frame: top-right, bottom-right, bottom-left, top-left
    top_right, bottom_right, bottom_left, top_left = frame
    origin = camera.matrix_world.translation
    points = []
    for j in range(rows):
        for i in range(columns):
            u, v = (i + 0.5) / columns, (j + 0.5) / rows
            top = top_left.lerp(top_right, u)
            bottom = bottom_left.lerp(bottom_right, u)
            target = top.lerp(bottom, v)
            d = (target - origin).normalized()
            h = cast(scene, depsgraph, origin, d)
            if h is None:
                continue
            p, n = h
            if n.dot(d) > 0.0:
                n = -n
            points.append((p, n))
    return points


def lamp_candidates(scene, depsgraph, points):
    floors = [p for p, n in points if n.z > 0.9]
    if not floors:
        sys.exit("no floor seen by the camera: cannot place lamps")
    xs = sorted(p.x for p in floors)
    ys = sorted(p.y for p in floors)
    lo = lambda v: v[int(0.05 * (len(v) - 1))]
    hi = lambda v: v[int(0.95 * (len(v) - 1))]
    x0, x1, y0, y1 = lo(xs), hi(xs), lo(ys), hi(ys)
    cx, cy, hx, hy = (x0 + x1) / 2, (y0 + y1) / 2, 0.35 * (x1 - x0), 0.35 * (y1 - y0)
    floor_z = min(p.z for p in floors)
    directions = [Vector((a, b, c)).normalized() for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)
                  if (a, b, c) != (0, 0, 0)]
    out = []
    for j in range(13):
        for i in range(13):
            x = cx - hx + 2 * hx * i / 12
            y = cy - hy + 2 * hy * j / 12
            up = cast(scene, depsgraph, Vector((x, y, floor_z + 1e-3)), Vector((0, 0, 1)))
            if up is None:
                continue
            ceiling = up[0].z
            down = cast(scene, depsgraph, Vector((x, y, ceiling - 1e-3)), Vector((0, 0, -1)))
            if down is None:
                continue
            floor = down[0].z
            height = ceiling - floor
            if height <= 0.0:
                continue
            clearance = 0.08 * height
            for f in (0.70, 0.775, 0.85):
                c = Vector((x, y, floor + f * height))
                if all(cast(scene, depsgraph, c, d, clearance) is None for d in directions):
                    out.append(c)
    return out


def coverage(scene, depsgraph, lamp, points):
    lit = 0
    for p, n in points:
        to_lamp = lamp - p
        d = to_lamp.length
        if d <= 0.0 or n.dot(to_lamp) <= 0.0:
            continue
        origin = p + n * 1e-3
        if cast(scene, depsgraph, origin, (lamp - origin).normalized(), (lamp - origin).length) is None:
            lit += 1
    return lit / max(1, len(points))


def choose_lamps(candidates, coverages, count):
    order = sorted(range(len(candidates)), key=lambda k: -coverages[k])
    good = [k for k in order if coverages[k] >= 0.5]
    if len(good) < count:
        good = order[:max(count, len(order) // 3)]
    chosen = [good[0]]
    while len(chosen) < min(count, len(good)):
        best = max((k for k in good if k not in chosen),
                   key=lambda k: min((candidates[k] - candidates[c]).length for c in chosen))
        chosen.append(best)
    return chosen


def render(scene, path, seed, spp, albedo=None):
    scene.cycles.seed = seed
    scene.cycles.samples = spp
    tree = scene.node_tree
    for node in [n for n in tree.nodes if n.type == "OUTPUT_FILE"]:
        tree.nodes.remove(node)
    view_layer = scene.view_layers[0]
    view_layer.use_pass_diffuse_color = bool(albedo)
    if albedo:
        layers = next(n for n in tree.nodes if n.type == "R_LAYERS")
        out = tree.nodes.new("CompositorNodeOutputFile")
        out.base_path = os.path.dirname(os.path.abspath(albedo))
        out.format.file_format = "OPEN_EXR"
        out.format.color_depth = "16"
        out.format.exr_codec = "ZIP"
        out.format.color_mode = "RGB"
        out.file_slots[0].path = os.path.basename(albedo) + "_"
        tree.links.new(layers.outputs["DiffCol"], out.inputs[0])
    scene.render.filepath = os.path.abspath(path)
    bpy.ops.render.render(write_still=True)
    if albedo:
        written = os.path.join(os.path.dirname(os.path.abspath(albedo)), os.path.basename(albedo) + "_0001")
        os.replace(written, os.path.abspath(albedo))
    print(f"cycles_photo_set: wrote {path}", flush=True)


def shot_entry(image, lamp, a, seed, cov):
    intensity = a.power / (4.0 * math.pi)
    return {"image": image, "type": "sphere", "position": to_gltf(lamp), "radius": a.radius, "power_w": a.power,
            "intensity_w_per_sr": intensity, "radiance": intensity / (math.pi * a.radius ** 2),
            "color": [1.0, 1.0, 1.0],
            "gltf_light": {"type": "point", "color": [1.0, 1.0, 1.0], "intensity": intensity},
            "coverage": round(cov, 4), "seed": seed}


def main():
    a = parse_args()
    os.makedirs(a.output, exist_ok=True)
    scene, lamp = cycles_photo.setup_scene(a.scene, a.camera, a.power, a.radius, a.bounces, a.threads, a.spp, 0)
    scene.render.resolution_x = a.width
    scene.render.resolution_y = a.height
    if a.positions_from:
        # The lamps of another set, in its order (its shots, then its new lamp).
        with open(a.positions_from) as f:
            old = json.load(f)
        entries = old["shots"] + [old["new_lamp"]]
        candidates = [from_gltf(e["position"]) for e in entries]
        coverages = [e["coverage"] for e in entries]
        chosen = list(range(len(entries)))
        a.shots = len(old["shots"])
        visible = old["visible_points"]
    else:
        depsgraph = bpy.context.evaluated_depsgraph_get()
        lamp.hide_render = True  # the lamp is no occluder while the positions are chosen
        depsgraph.update()
        points = visible_points(scene, depsgraph, scene.camera, a.width, a.height, 64)
        candidates = lamp_candidates(scene, depsgraph, points)
        if len(candidates) < a.shots + 1:
            sys.exit(f"{a.scene}: only {len(candidates)} lamp positions clear of the surfaces")
        coverages = [coverage(scene, depsgraph, c, points) for c in candidates]
        chosen = choose_lamps(candidates, coverages, a.shots + 1)
        if len(chosen) < a.shots + 1:
            sys.exit(f"{a.scene}: only {len(chosen)} lamp positions to choose from")
        lamp.hide_render = False
        visible = len(points)
    print(f"cycles_photo_set: {visible} visible points, {len(candidates)} candidates, coverage of the chosen "
          + ", ".join(f"{coverages[k]:.2f}" for k in chosen), flush=True)

    # The vertical field of view Cycles renders with at this size (the importer's sensor fit).
    corner = scene.camera.data.view_frame(scene=scene)[0]
    yfov = 2.0 * math.atan(abs(corner.y) / abs(corner.z))
    meta = {
        "about": "Synthetic photographs for reflectance recovery (Loscos et al. 1999, section 4): fixed camera, the "
                 "scene's own emitters off, one small spherical lamp moved between shots. Rendered with Blender "
                 "Cycles by tools/cycles_photo_set.py.",
        "scene": os.path.relpath(os.path.abspath(a.scene), os.path.abspath(a.output)),
        "coordinates": "glTF world coordinates of the scene file (Y up, scene units)",
        "camera": {"gltf_camera": a.camera, "yfov": yfov, "width": a.width, "height": a.height},
        "albedo": {"image": "albedo.exr", "meaning": "Cycles Diffuse Color pass (0 where no surface)"},
        "renderer": {"blender": bpy.app.version_string, "engine": "Cycles (CPU)", "spp": a.spp,
                     "cycles_bounces": a.bounces, "materials": "diffuse (base colour or its texture)",
                     "seed": "shot index; repeats 100 + shot index; noisy set 200 + shot index",
                     "lamp_visible_to_camera": False},
        "positions_chosen": "tools/cycles_photo_set.py: 13x13 grid over the middle 70 % of the visible floor, heights "
                            "0.7/0.775/0.85 of floor-to-ceiling, clearance >= 8 % of that height, coverage >= 0.5 "
                            "preferred, farthest-point spread; new_lamp is the next farthest point",
        "visible_points": visible,
        "shots": [shot_entry(f"photo-{k:03d}.exr", candidates[c], a, k, coverages[c]) for k, c in enumerate(chosen[:-1])],
        "new_lamp": shot_entry("new-lamp.exr", candidates[chosen[-1]], a, 99, coverages[chosen[-1]]),
        "repeats": [{"image": f"repeat/photo-{k:03d}.exr", "of": f"photo-{k:03d}.exr", "seed": 100 + k}
                    for k in range(min(2, a.shots))],
    }
    with open(os.path.join(a.output, "lights.json"), "w") as f:
        json.dump(meta, f, indent=1)
    if a.dry_run:
        return
    if a.new_lamp_only:
        lamp.location = candidates[chosen[-1]]
        render(scene, os.path.join(a.output, "new-lamp.exr"), 99, a.spp)
        return

    for k, c in enumerate(chosen[:-1]):
        lamp.location = candidates[c]
        render(scene, os.path.join(a.output, f"photo-{k:03d}.exr"), k, a.spp,
               os.path.join(a.output, "albedo.exr") if k == 0 else None)
    if a.shots_only:
        return
    lamp.location = candidates[chosen[-1]]
    render(scene, os.path.join(a.output, "new-lamp.exr"), 99, a.spp)
    os.makedirs(os.path.join(a.output, "repeat"), exist_ok=True)
    for r in meta["repeats"]:
        k = int(r["of"][6:9])
        lamp.location = candidates[chosen[k]]
        render(scene, os.path.join(a.output, r["image"]), r["seed"], a.spp)
    if a.noisy_spp > 0:
        noisy = os.path.join(a.output, "noisy")
        os.makedirs(noisy, exist_ok=True)
        noisy_meta = dict(meta)
        noisy_meta["scene"] = os.path.relpath(os.path.abspath(a.scene), os.path.abspath(noisy))
        noisy_meta["renderer"] = dict(meta["renderer"], spp=a.noisy_spp)
        noisy_meta["albedo"] = dict(meta["albedo"], image="../albedo.exr")
        noisy_meta["new_lamp"] = dict(meta["new_lamp"], image="../new-lamp.exr")
        noisy_meta["repeats"] = []
        noisy_meta["shots"] = [dict(s, seed=200 + k) for k, s in enumerate(meta["shots"])]
        with open(os.path.join(noisy, "lights.json"), "w") as f:
            json.dump(noisy_meta, f, indent=1)
        for k, c in enumerate(chosen[:-1]):
            lamp.location = candidates[c]
            render(scene, os.path.join(noisy, f"photo-{k:03d}.exr"), 200 + k, a.noisy_spp)


main()
