#!/usr/bin/python3
# remodel_report.py — the round trip of issue 36's relighting goal: the room `obscura recover`
# recovered (REC), relit through `obscura remodel` with the six photographed lamps off and the
# photo set's new lamp on (lights.json "new_lamp", a position no shot used), against Cycles'
# photograph of that lamp (its "image"): the mean ratio (goal within 3 %), the median relative
# error of 8x8 block means (goal <= 5 %) and the median relative error per pixel, over the pixels
# that see a surface.
#
# Needs numpy and OpenImageIO's Python bindings (Debian: python3-numpy python3-openimageio).
#   tools/remodel_report.py OBSCURA REC PHOTOS/lights.json [remodel options...]
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

from exr_image import read_image


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: remodel_report.py OBSCURA REC PHOTOS/lights.json [remodel options...]")
    obscura, rec, photos = sys.argv[1:4]
    with open(photos) as f:
        meta = json.load(f)
    lamp = meta.get("new_lamp")
    if lamp is None:
        sys.exit(f"{photos}: no new_lamp")
    folder = os.path.dirname(os.path.abspath(photos))
    edits = [{"light": f"shot{i}", "scale": 0.0} for i in range(len(meta["shots"]))]
    edits.append({"add_light": {"type": "point", "name": "new_lamp", "position": lamp["position"],
                                "color": lamp["gltf_light"]["color"], "intensity": lamp["gltf_light"]["intensity"]}})
    with tempfile.TemporaryDirectory() as work:
        edit_file = os.path.join(work, "edits.json")
        with open(edit_file, "w") as f:
            json.dump(edits, f)
        out = os.path.join(work, "relit.exr")
        subprocess.run([obscura, "remodel", rec, "--edits", edit_file, "-o", out] + sys.argv[4:], check=True)
        relit, names = read_image(out)
    relit = relit[:, :, [names.index(c) for c in ("R", "G", "B")]] if "R" in names else relit[:, :, :3]
    photo = read_image(os.path.join(folder, lamp["image"]))[0][:, :, :3]
    reflectance, channels = read_image(os.path.join(rec, "reflectance.exr"))
    surface = reflectance[:, :, channels.index("object.id")] >= 0
    lum = np.array([0.2126, 0.7152, 0.0722])
    a, b = relit @ lum, photo @ lum
    mean_ratio = a[surface].sum() / b[surface].sum()
    pixel = np.abs(a - b)[surface] / np.maximum(b[surface], 1e-9)
    h, w = a.shape
    errors = []
    for y in range(0, h - 7, 8):
        for x in range(0, w - 7, 8):
            m = surface[y:y + 8, x:x + 8]
            if m.sum() < 32:  # a block mostly of background says little
                continue
            pb = b[y:y + 8, x:x + 8][m].mean()
            if pb > 0:
                errors.append(abs(a[y:y + 8, x:x + 8][m].mean() - pb) / pb)
    print(f"remodel_report: {rec} relit by {lamp['image']}'s lamp: mean ratio {mean_ratio:.4f} (goal within 3 %), "
          f"median 8x8 block error {100 * np.median(errors):.1f} % (goal <= 5 %), median pixel error "
          f"{100 * np.median(pixel):.1f} %")


main()
