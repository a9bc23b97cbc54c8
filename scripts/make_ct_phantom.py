#!/usr/bin/env python3
"""Write a CT-like head phantom as raw 16-bit samples, for the large-volume
benchmarks (docs/performance.md). Never committed: 1024^3 is 2 GiB.

    python3 scripts/make_ct_phantom.py SIZE OUT.raw [--dtype i16|u16] [--nz NZ]

Values are Hounsfield units (air -1000, soft tissue 20-60, bone 700-1500),
stored as little-endian int16 (`--dtype i16`, the default) or as uint16
with the usual offset of 1024 (`--dtype u16`, HU + 1024), x fastest, on an
SIZE x SIZE x NZ grid (NZ = SIZE by default) of 0.25 mm voxels at 1024.

The head: a skin-and-fat ellipsoid, a skull shell 6-8 mm thick with a
denser outer table, the brain (grey and white matter), the ventricles, a
few lesions, the eyes and a jaw bone, plus noise of 8 HU, so that most
8^3 bricks inside the head hold tissue a CT preset shows.

Render it with, for example:

    volray render OUT.raw --dims SIZE,SIZE,NZ --dtype i16 --preset ct-bone -o head.png

Needs numpy. Writes slab by slab (a few hundred MiB of memory at 1024^3).
"""

import argparse
import sys

import numpy as np


def ellipsoid(x, y, z, centre, axes):
    """Inside-ness (<= 1 inside) of an axis-aligned ellipsoid."""
    cx, cy, cz = centre
    ax, ay, az = axes
    return ((x - cx) / ax) ** 2 + ((y - cy) / ay) ** 2 + ((z - cz) / az) ** 2


def slab(n, nz, z0, z1, rng):
    """HU values of planes z0..z1 (exclusive), shape (z1 - z0, n, n), [z, y, x]."""
    # Coordinates in [-1, 1], x fastest.
    u = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    w = np.linspace(-1.0, 1.0, nz, dtype=np.float32)[z0:z1]
    z, y, x = np.meshgrid(w, u, u, indexing="ij")
    hu = np.full(z.shape, -1000.0, dtype=np.float32)
    head = ellipsoid(x, y, z, (0, 0, 0), (0.72, 0.88, 0.92))
    hu[head <= 1] = -80.0  # fat under the skin
    hu[ellipsoid(x, y, z, (0, 0, 0), (0.70, 0.86, 0.90)) <= 1] = 40.0  # soft tissue
    outer = ellipsoid(x, y, z, (0, 0, 0.05), (0.66, 0.82, 0.84))
    inner = ellipsoid(x, y, z, (0, 0, 0.05), (0.60, 0.76, 0.78))
    hu[outer <= 1] = 1400.0  # outer table of the skull
    hu[ellipsoid(x, y, z, (0, 0, 0.05), (0.635, 0.79, 0.81)) <= 1] = 800.0  # diploe
    brain = inner <= 1
    hu[brain] = 35.0  # grey matter
    hu[ellipsoid(x, y, z, (0, 0, 0.08), (0.5, 0.64, 0.62)) <= 1] = 25.0  # white matter
    for side in (-1, 1):
        hu[ellipsoid(x, y, z, (side * 0.12, 0.05, 0.12), (0.08, 0.25, 0.12)) <= 1] = 5.0  # ventricles
        hu[ellipsoid(x, y, z, (side * 0.3, -0.72, -0.25), (0.11, 0.11, 0.11)) <= 1] = 15.0  # eyes
    hu[ellipsoid(x, y, z, (0.2, 0.3, 0.35), (0.06, 0.05, 0.07)) <= 1] = 70.0  # a lesion
    hu[ellipsoid(x, y, z, (-0.25, -0.2, -0.1), (0.04, 0.04, 0.04)) <= 1] = 90.0  # another
    hu[ellipsoid(x, y, z, (0.0, -0.45, -0.7), (0.45, 0.3, 0.1)) <= 1] = 1100.0  # jaw
    hu[(ellipsoid(x, y, z, (0.0, -0.45, -0.7), (0.38, 0.24, 0.07)) <= 1)] = 300.0
    hu += rng.normal(0.0, 8.0, size=hu.shape).astype(np.float32)
    return hu


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("size", type=int)
    p.add_argument("out")
    p.add_argument("--dtype", choices=["i16", "u16"], default="i16")
    p.add_argument("--nz", type=int, default=None)
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args()
    n, nz = args.size, args.nz or args.size
    rng = np.random.default_rng(args.seed)
    step = max(1, (256 << 20) // (n * n * 4 * 8))
    with open(args.out, "wb") as f:
        for z0 in range(0, nz, step):
            z1 = min(nz, z0 + step)
            hu = np.rint(slab(n, nz, z0, z1, rng))
            if args.dtype == "u16":
                out = np.clip(hu + 1024, 0, 65535).astype("<u2")
            else:
                out = np.clip(hu, -32768, 32767).astype("<i2")
            f.write(out.tobytes())
            print(f"\r{z1}/{nz} planes", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)


if __name__ == "__main__":
    main()
