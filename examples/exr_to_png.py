#!/usr/bin/env python3
"""examples/exr_to_png.py: tone-map nsp_render's EXR images to 8-bit sRGB PNGs for viewing.

usage: exr_to_png.py IN.exr [IN2.exr ...] [--exposure STOPS] [--out DIR]
Needs: pip install OpenEXR numpy pillow. Tone map: exposure, then Reinhard x / (1 + x), then sRGB.
"""
import argparse
import os

import numpy as np
import OpenEXR
from PIL import Image


def to_png(src, dst, exposure):
    with OpenEXR.File(src) as f:
        ch = f.channels()
        if "RGB" in ch:  # the module groups R, G, B into one (H, W, 3) channel
            rgb = np.asarray(ch["RGB"].pixels, dtype=np.float64)
        else:
            rgb = np.stack([ch[c].pixels for c in ("R", "G", "B")], axis=-1).astype(np.float64)
    x = np.maximum(rgb, 0.0) * 2.0 ** exposure
    x = x / (1.0 + x)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    Image.fromarray(np.clip(srgb * 255.0 + 0.5, 0, 255).astype(np.uint8)).save(dst)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("inputs", nargs="+")
    ap.add_argument("--exposure", type=float, default=0.0, help="exposure in stops (default 0)")
    ap.add_argument("--out", default=None, help="output directory (default: beside each input)")
    a = ap.parse_args()
    for src in a.inputs:
        name = os.path.splitext(os.path.basename(src))[0] + ".png"
        dst = os.path.join(a.out or os.path.dirname(src) or ".", name)
        if a.out:
            os.makedirs(a.out, exist_ok=True)
        to_png(src, dst, a.exposure)
        print(dst)


if __name__ == "__main__":
    main()
