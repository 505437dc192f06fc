#!/usr/bin/python3
"""make_exr_samples.py OUT_DIR — the small EXR files tests/data/exr holds, written by OpenImageIO.

The native reader (host/io/exr_reader.cpp) is tested against OpenImageIO on them: one image of
19 x 37 pixels (37 lines: ZIP's blocks of 16 lines end with a short one) in every compression it
reads (NONE, RLE, ZIPS, ZIP) and in two layouts it refuses (PIZ compression, tiles). Its channels
mix the three pixel types and four layers, listed out of order: HALF R, G, B, A (values from 2^-24,
half's smallest subnormal, to 60000, both signs, one infinity), FLOAT diffuse.R/G/B and depth.Z,
UINT id. One string attribute, "obscura:part", is read back by both readers.
"""
import sys

import numpy as np
import OpenImageIO as oiio

WIDTH, HEIGHT = 19, 37
CHANNELS = ["depth.Z", "B", "diffuse.G", "R", "id", "A", "diffuse.R", "G", "diffuse.B"]
FORMATS = {"R": "half", "G": "half", "B": "half", "A": "half", "id": "uint"}


def pixels():
    rng = np.random.default_rng(36)
    image = np.zeros((HEIGHT, WIDTH, len(CHANNELS)), dtype=np.float64)
    for c, name in enumerate(CHANNELS):
        kind = FORMATS.get(name, "float")
        if kind == "half":  # exponents over half's whole range, subnormals included
            value = rng.uniform(1, 2, (HEIGHT, WIDTH)) * np.exp2(rng.integers(-24, 15, (HEIGHT, WIDTH)))
            value *= np.where(rng.random((HEIGHT, WIDTH)) < 0.3, -1, 1)
        elif kind == "uint":
            # OpenImageIO writes a float v as the integer v x (2^32 - 1), and reads it back divided
            value = rng.integers(0, 2**32 - 1, (HEIGHT, WIDTH), endpoint=True) / (2**32 - 1)
        else:
            value = rng.normal(0, 1, (HEIGHT, WIDTH)) * np.exp2(rng.integers(-30, 30, (HEIGHT, WIDTH)))
        image[:, :, c] = value
    image[5, 7, CHANNELS.index("R")] = np.inf
    image[0:4, :, :] = np.round(image[0:4, :, :] * 0)  # four lines of zeros: runs for RLE
    return image


def write(path, image, compression, tiled=False):
    spec = oiio.ImageSpec(WIDTH, HEIGHT, len(CHANNELS), "float")
    spec.channelnames = tuple(CHANNELS)
    spec.channelformats = tuple(oiio.TypeDesc(FORMATS.get(n, "float")) for n in CHANNELS)
    spec.attribute("compression", compression)
    spec.attribute("obscura:part", "2 of 5")
    if tiled:
        spec.tile_width = spec.tile_height = 16
    out = oiio.ImageOutput.create(path)
    if not out.open(path, spec):
        sys.exit(f"{path}: {oiio.geterror()}")
    out.write_image(image.astype(np.float32))
    out.close()


def main():
    folder = sys.argv[1]
    image = pixels()
    for compression in ["none", "rle", "zips", "zip", "piz"]:
        write(f"{folder}/samples-{compression}.exr", image, compression)
    write(f"{folder}/samples-tiled.exr", image, "zip", tiled=True)


if __name__ == "__main__":
    main()
