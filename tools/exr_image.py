# exr_image.py — reading an image with OpenImageIO for the tools' reports (recovery_report.py,
# remodel_report.py): its pixels as float32 (H x W x C) and its channel names, or exit naming
# the file.
import sys

import OpenImageIO as oiio


def read_image(path):
    image = oiio.ImageInput.open(path)
    if image is None:
        sys.exit(f"{path}: cannot open: {oiio.geterror()}")
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    return pixels, list(spec.channelnames)
