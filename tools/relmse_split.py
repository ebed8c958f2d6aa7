#!/usr/bin/env python3
"""Splits the relMSE of images against a reference into luminance and colour.

Usage: tools/relmse_split.py REFERENCE.exr IMAGE.exr...   (needs numpy and OpenEXR)

Prints, as means over the images: relMSE (mean over pixels and channels of (x - r)^2 / (r^2 +
0.01), as restir-pt's metrics) and its trimmed form (without the largest 0.1% of pixel errors);
the same of the luminance alone (Rec. 709 weights); and of each pixel given the reference's
colour at its own luminance, r * L(x) / L(r), which keeps the luminance error and drops the
colour error. Used for the lab notebook's "ReSTIR PT in motion, eight runs a point".
"""
import sys

import numpy as np
import OpenEXR

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def load(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        rgb = ch["RGB"].pixels if "RGB" in ch else np.stack([ch[c].pixels for c in "RGB"], -1)
        return np.asarray(rgb, dtype=np.float64)


def plain_and_trimmed(per_pixel):
    e = per_pixel.ravel()
    keep = int(len(e) * 0.999)
    return e.mean(), np.sort(e)[:keep].mean()


def split(image, reference):
    rel = lambda x, r: (x - r) ** 2 / (r**2 + 1e-2)
    li, lr = image @ LUMINANCE, reference @ LUMINANCE
    reference_colour = reference * (li / np.maximum(lr, 1e-9))[..., None]
    return (
        *plain_and_trimmed(rel(image, reference).mean(-1)),
        *plain_and_trimmed(rel(li, lr)),
        *plain_and_trimmed(rel(reference_colour, reference).mean(-1)),
    )


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    reference = load(sys.argv[1])
    r = np.mean([split(load(p), reference) for p in sys.argv[2:]], axis=0)
    print(
        f"{len(sys.argv) - 2} images: relMSE {r[0]:.4f} trimmed {r[1]:.4f} | luminance {r[2]:.4f} "
        f"trimmed {r[3]:.4f} | reference colour {r[4]:.4f} trimmed {r[5]:.4f}"
    )


if __name__ == "__main__":
    main()
