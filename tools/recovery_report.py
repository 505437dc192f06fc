#!/usr/bin/python3
# recovery_report.py — how a reflectance recovery (`obscura recover ... -o OUT`) compares with the
# answer key of a synthetic photo set (tools/cycles_photo_set.py), against issue 36's goals:
#
#   RMSE over every pixel that sees a surface, and over the pixels some shot lights directly
#   (recover.json's accuracy, from --truth);
#   on each large flat surface of uniform true colour (an object's pixels whose true reflectance
#   is within 3 % of that object's median, at least 1 % of the image): the mean ratio of recovered
#   to true reflectance, and the spread of that ratio over its pixels against the spread the
#   photographs' own noise implies.
#
# The implied spread: each repeat photograph (the same shot with another seed) gives the shot's
# per-pixel noise, sigma = |C - C'| / sqrt 2, relative to C. On the surface's pixels lit in that
# shot it is s = RMS(sigma / C); merged over N lit shots of similar noise it is s / sqrt(N), N the
# surface's mean sum of the paper's K_i (reflectance.exr's confidence.K). The recovery is speckled
# where its spread exceeds twice this.
#
# Needs numpy and OpenImageIO's Python bindings (Debian: python3-numpy python3-openimageio).
#   tools/recovery_report.py OUT PHOTOS/lights.json [--json report.json]
import argparse
import json
import os
import sys

import numpy as np

from exr_image import read_image


def read(path, channels=None):
    pixels, names = read_image(path)
    if channels is None:
        return pixels[:, :, :3]
    return {c: pixels[:, :, names.index(c)] for c in channels}


def luminance(rgb):
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def main():
    p = argparse.ArgumentParser()
    p.add_argument("recovered", help="the folder `obscura recover` wrote")
    p.add_argument("photos", help="the photo set's lights.json")
    p.add_argument("--json", help="also write the figures here")
    a = p.parse_args()
    with open(a.photos) as f:
        meta = json.load(f)
    folder = os.path.dirname(os.path.abspath(a.photos))
    with open(os.path.join(a.recovered, "recover.json")) as f:
        report = json.load(f)
    rec = read(os.path.join(a.recovered, "reflectance.exr"), ["R", "G", "B", "confidence.K", "object.id"])
    recovered = np.stack([rec["R"], rec["G"], rec["B"]], axis=-1)
    truth = read(os.path.join(folder, meta["albedo"]["image"]))
    objects = rec["object.id"].astype(int)
    surface = objects >= 0
    out = {"seconds": report.get("seconds"), "accuracy": report.get("accuracy"),
           "lit_pixels": report.get("lit_pixels"), "indirect_only_pixels": report.get("indirect_only_pixels"),
           "filled": (report.get("filled_from_surface", 0), report.get("filled_from_visibility", 0),
                      report.get("filled_from_object_mean", 0)),
           "surface_pixels": int(surface.sum())}
    d = recovered[surface] - truth[surface]
    out["rmse_all"] = float(np.sqrt(np.mean(d * d)))

    # The photographs' relative noise per shot with a repeat.
    noise = []
    for r in meta.get("repeats", []):
        c0 = luminance(read(os.path.join(folder, r["of"])))
        c1 = luminance(read(os.path.join(folder, r["image"])))
        mean = 0.5 * (c0 + c1)
        rel = np.where(mean > 0, np.abs(c0 - c1) / np.sqrt(2.0) / np.maximum(mean, 1e-12), np.nan)
        noise.append(rel)

    surfaces = []
    total = surface.sum()
    for o in np.unique(objects[surface]):
        mask = objects == o
        t = luminance(truth)
        median = np.median(t[mask])
        if median <= 0:
            continue
        uniform = mask & (np.abs(t - median) <= 0.03 * median)
        if uniform.sum() < 0.01 * total:
            continue
        ratio = luminance(recovered)[uniform] / np.maximum(t[uniform], 1e-6)
        entry = {"object": int(o), "pixels": int(uniform.sum()), "true": float(median),
                 "mean_ratio": float(luminance(recovered)[uniform].mean() / t[uniform].mean()),
                 "spread": float(np.std(ratio))}
        k = rec["confidence.K"][uniform]
        lit_shots = float(np.mean(k))
        rel = [np.sqrt(np.nanmean(n[uniform] ** 2)) for n in noise if np.isfinite(n[uniform]).any()]
        if rel and lit_shots > 0:
            entry["noise_implied_spread"] = float(np.mean(rel) / np.sqrt(lit_shots))
            entry["spread_over_implied"] = entry["spread"] / entry["noise_implied_spread"]
        entry["lit_shots"] = lit_shots
        surfaces.append(entry)
    out["surfaces"] = sorted(surfaces, key=lambda e: -e["pixels"])

    acc = out["accuracy"] or {}
    print(f"recovery_report: {a.recovered} against {meta['albedo']['image']}: {out['surface_pixels']} surface pixels, "
          f"{out['lit_pixels']} from lit estimates, {out['indirect_only_pixels']} from indirect light only, filled "
          f"{out['filled'][0]} (surface) + {out['filled'][1]} (visibility) + {out['filled'][2]} (object); "
          f"{out['seconds']:.1f} s")
    if acc:
        print(f"  RMSE all {acc['all']['rmse']:.4f} (goal 0.04), lit in some photo {acc['direct']['rmse']:.4f} "
              f"(goal 0.02), shadow {acc['shadow']['rmse']:.4f} ({acc['shadow']['pixels']} px)")
    print("  large uniform surfaces: object, pixels, true, mean ratio (goal within 2 %), spread / implied (goal <= 2)")
    for e in out["surfaces"]:
        implied = f"{e['spread']:.4f} / {e['noise_implied_spread']:.4f} = {e['spread_over_implied']:.2f}" \
            if "noise_implied_spread" in e else f"{e['spread']:.4f} / -"
        print(f"  {e['object']:4d} {e['pixels']:6d} {e['true']:.3f} {e['mean_ratio']:.4f} {implied}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)


main()
