#!/usr/bin/python3
"""Anti-aliasing and dark-dot counts of one rendered frame (an EXR written by prtr).

partial: pixels whose alpha (coverage) is strictly between 0 and 1, i.e. anti-aliased edges.
dots:    fully covered pixels (alpha 1) whose luminance is below a quarter of the median
         luminance of the fully covered pixels in their 5 x 5 neighbourhood.

Reads the EXR through oiiotool (OpenImageIO's command-line tool, a dependency of the build):
luminance and alpha become 32-bit float FITS files, which numpy parses. Prints one JSON
object.
"""
import json
import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np


def read_fits(path):
    """A one-channel 32-bit float FITS image as OpenImageIO writes it, top row first."""
    with open(path, "rb") as f:
        data = f.read()
    cards, offset = {}, 0
    while True:
        block = data[offset:offset + 2880]
        offset += 2880
        for i in range(0, 2880, 80):
            card = block[i:i + 80].decode("ascii")
            key, _, value = card.partition("=")
            cards[key.strip()] = value.split("/")[0].strip()
        if any(block[i:i + 80].startswith(b"END ") for i in range(0, 2880, 80)):
            break
    width, height = int(cards["NAXIS1"]), int(cards["NAXIS2"])
    if int(cards["BITPIX"]) != -32:
        sys.exit(f"{path}: expected 32-bit float FITS, got BITPIX {cards['BITPIX']}")
    pixels = np.frombuffer(data, dtype=">f4", count=width * height, offset=offset)
    # FITS stores the bottom row first.
    return pixels.reshape(height, width)[::-1].astype(np.float64)


def read_exr(path):
    """Rec. 709 luminance and alpha of an RGBA EXR, through oiiotool and FITS files."""
    with tempfile.TemporaryDirectory() as tmp:
        lum, alpha = os.path.join(tmp, "lum.fits"), os.path.join(tmp, "a.fits")
        subprocess.run(["oiiotool", path, "--ch", "R,G,B",
                        "--chsum:weight=0.2126,0.7152,0.0722", "-d", "float", "-o", lum],
                       check=True)
        subprocess.run(["oiiotool", path, "--ch", "A", "-d", "float", "-o", alpha], check=True)
        return read_fits(lum), read_fits(alpha)


def quality(lum, alpha):
    covered = alpha >= 1.0 - 1e-6
    partial = int(np.count_nonzero((alpha > 0) & ~covered))
    h, w = lum.shape
    pad = 2
    lum_p = np.pad(np.where(covered, lum, np.nan), pad, constant_values=np.nan)
    windows = np.stack([lum_p[dy:dy + h, dx:dx + w] for dy in range(5) for dx in range(5)])
    with warnings.catch_warnings():  # uncovered windows have no median (NaN, never a dot)
        warnings.simplefilter("ignore", RuntimeWarning)
        median = np.nanmedian(windows, axis=0)
    dots = covered & (lum < 0.25 * median)
    ys, xs = np.nonzero(dots)
    return {
        "width": w,
        "height": h,
        "covered": int(np.count_nonzero(covered)),
        "partial": partial,
        "dots": int(dots.sum()),
        "dots_below_0_01": int(np.count_nonzero(dots & (lum < 0.01))),
        "first_dots": [[int(x), int(y)] for x, y in list(zip(xs, ys))[:10]],
    }


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: frame_quality.py FRAME.exr")
    print(json.dumps(quality(*read_exr(sys.argv[1]))))


if __name__ == "__main__":
    main()
