#!/usr/bin/python3
# recovery_transport_report.py — the recovery's light transport per shot against Cycles' own:
# recover's direct light D and indirect light B per unit reflectance (`recover --debug`'s
# shot-NNN.exr) against the same photograph's, split by a direct-only render of the same lamps.
#
#   Cycles' direct light per unit reflectance   D_c = direct-only photo / true reflectance
#   Cycles' indirect light per unit reflectance B_c = (photo - direct-only photo) / true reflectance
#
# so that a bias of the recovery can be put on D (the lamp, its shadows) or on B (the gather, the
# hidden surfaces and their colours) and on the objects that carry it. Sums over pixels (noise
# averages out): D / D_c and B / B_c over the pixels the shot lights directly (D at least a fifth
# of D + B), B / B_c over the pixels it lights only indirectly (D = 0), and both per object
# (reflectance.exr's object.id, the six with most pixels).
#
# The direct-only set: the photo set's own lamps at zero bounces, for example
#   blender -b -P tools/cycles_photo_set.py -- SCENE -o DIRECT --positions-from PHOTOS/lights.json \
#       --width W --height H --spp 64 --bounces 0
# (the wooden staircase's six shots in 30 s on 2 cores).
#
# Needs numpy and OpenImageIO's Python bindings (Debian: python3-numpy python3-openimageio).
#   tools/recovery_transport_report.py REC PHOTOS/lights.json DIRECT/lights.json
import argparse
import json
import os
import sys

import numpy as np

from exr_image import read_channels


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"{path}: {e}")


def ratio(a, b, mask):
    below = b[mask].sum()
    return a[mask].sum() / below if below > 0 else float("nan")


def main():
    p = argparse.ArgumentParser(description="recover's D and B per shot against Cycles' direct and indirect light")
    p.add_argument("recovery", help="recover -o DIR, run with --debug")
    p.add_argument("photos", help="the photo set's lights.json")
    p.add_argument("direct", help="the direct-only set's lights.json (the same lamps, --bounces 0)")
    a = p.parse_args()
    photos, direct = load(a.photos), load(a.direct)
    base, direct_base = os.path.dirname(a.photos), os.path.dirname(a.direct)
    if len(photos["shots"]) != len(direct["shots"]):
        sys.exit(f"{a.direct}: {len(direct['shots'])} shots, {a.photos} has {len(photos['shots'])}")
    truth = read_channels(os.path.join(base, photos["albedo"]["image"]), ["R", "G", "B"])
    size = truth.shape[:2]
    objects = read_channels(os.path.join(a.recovery, "reflectance.exr"), ["object.id"], size)[..., 0].astype(int)
    # Pixels whose true reflectance is dark in a channel would turn its noise into large ratios.
    surface = (truth.min(-1) > 0.03) & (objects >= 0)
    rgb = ["R", "G", "B"]
    print("shot  lamp (glTF)               lit px: D/Dc  B/Bc   indirect-only px: B/Bc")
    for k, (shot, dshot) in enumerate(zip(photos["shots"], direct["shots"])):
        if not np.allclose(shot["position"], dshot["position"], atol=1e-5):
            sys.exit(f"{a.direct}: shot {k}'s lamp is at {dshot['position']}, not at {shot['position']}")
        photo = read_channels(os.path.join(base, shot["image"]), rgb, size)
        photo_direct = read_channels(os.path.join(direct_base, dshot["image"]), rgb, size)
        debug = os.path.join(a.recovery, f"shot-{k:03}.exr")
        d = read_channels(debug, [f"direct.{c}" for c in rgb], size)
        b = read_channels(debug, [f"indirect.{c}" for c in rgb], size)
        dc = photo_direct / np.maximum(truth, 1e-6)
        bc = (photo - photo_direct) / np.maximum(truth, 1e-6)
        share = (d / np.maximum(d + b, 1e-9)).mean(-1)
        lit = surface & (share > 0.2)
        dark = surface & (d.max(-1) <= 0)
        print(f"{k:4}  {str(np.round(shot['position'], 2)):24} {lit.sum():6}  {ratio(d, dc, lit):.3f} "
              f"{ratio(b, bc, lit):.3f}   {dark.sum():6}  {ratio(b, bc, dark):.3f}")
        for name, mask, show in (("lit", lit, lambda m: f"D {ratio(d, dc, m):.3f} B {ratio(b, bc, m):.3f}"),
                                 ("indirect-only", dark, lambda m: f"B {ratio(b, bc, m):.3f}")):
            ids, counts = np.unique(objects[mask], return_counts=True)
            top = ids[np.argsort(-counts)][:6]
            print(f"      {name} by object: " + "  ".join(f"{i}: {show(mask & (objects == i))}" for i in top))


if __name__ == "__main__":
    main()
