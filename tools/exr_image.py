# exr_image.py — reading an image with OpenImageIO for the tools' reports (recovery_report.py,
# remodel_report.py, recovery_transport_report.py): its pixels as float32 (H x W x C) and its
# channel names, or chosen channels of it, or exit naming the file.
import sys

import numpy as np

import OpenImageIO as oiio


def read_image(path):
    image = oiio.ImageInput.open(path)
    if image is None:
        sys.exit(f"{path}: cannot open: {oiio.geterror()}")
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    return pixels, list(spec.channelnames)


def read_channels(path, names, shape=None):
    """The named channels of an image, stacked last (H x W x len(names)), or exit naming the file
    and what it lacks: a channel, or the size `shape` (H, W) the caller's other images have."""
    pixels, have = read_image(path)
    missing = [n for n in names if n not in have]
    if missing:
        sys.exit(f"{path}: no channel {', '.join(missing)} (it has {', '.join(have)})")
    if shape is not None and pixels.shape[:2] != tuple(shape):
        sys.exit(f"{path}: {pixels.shape[1]}x{pixels.shape[0]} pixels, the other images are {shape[1]}x{shape[0]}")
    return np.stack([pixels[..., have.index(n)] for n in names], -1)
