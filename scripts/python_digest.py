#!/usr/bin/env python3
"""What the digest a Python `Renderer` takes of a numpy array before each
frame (so that an array changed in place is rendered as it is now) costs,
against the frame.

    target/pyenv/bin/python scripts/python_digest.py            # after cargo test --test python
    target/pyenv/bin/python scripts/python_digest.py --rounds 5 --size 480

For each volume (256³ uint16, 512³ uint8: a ball of noise in empty
space), prints the digest alone (median of FRAMES), and the median frame
of a Renderer over the array (watched: digested before each frame and,
through `verify`, after it) and over the same samples read from a .npy
file (`volray.read`: read-only, never digested), each frame turned a
further half degree, the two alternating ROUNDS times.
"""

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import volray
from volray import _volray


def volume(n, dtype):
    """A ball of noise filling half the cube's width, zero outside."""
    rng = np.random.default_rng(7)
    a = np.zeros((n, n, n), dtype, order="F")
    axis = np.linspace(-1, 1, n, dtype=np.float32)
    top = np.iinfo(dtype).max
    for z in range(n):  # a slice at a time: no whole-volume float temporaries
        r2 = axis[:, None] ** 2 + axis[None, :] ** 2 + axis[z] ** 2
        inside = r2 < 0.25
        a[:, :, z] = np.where(inside, rng.random((n, n), np.float32) * top * (1 - 4 * r2), 0)
    return a


def median_ms(fn, frames):
    times = []
    for i in range(frames):
        start = time.perf_counter()
        fn(i)
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--frames", type=int, default=7)
    parser.add_argument("--size", type=int, default=480)
    args = parser.parse_args()
    for n, dtype in [(256, np.uint16), (512, np.uint8)]:
        a = volume(n, dtype)
        with tempfile.TemporaryDirectory() as tmp:
            np.save(Path(tmp) / "v.npy", a)
            read = volray.read(Path(tmp) / "v.npy")
        digest = median_ms(lambda i: _volray._digest(a), args.frames)
        watched, frozen = volray.Renderer(a), volray.Renderer(read)
        watched.render(size=args.size)
        frozen.render(size=args.size)
        medians = {"watched": [], "read-only": []}
        for _ in range(args.rounds):
            for name, renderer in (("watched", watched), ("read-only", frozen)):
                frame = lambda i, r=renderer: r.render(size=args.size, azimuth=0.5 * (i + 1))
                medians[name].append(median_ms(frame, args.frames))
        w, f = statistics.median(medians["watched"]), statistics.median(medians["read-only"])
        print(
            f"{n}^3 {np.dtype(dtype).name} ({a.nbytes >> 20} MiB): digest {digest:.1f} ms "
            f"({a.nbytes / digest / 1e6:.1f} GB/s); frame {args.size}²: array {w:.1f} ms, "
            f"read-only {f:.1f} ms, difference {w - f:+.1f} ms ({(w - f) / f * 100:+.1f} %)"
        )


if __name__ == "__main__":
    main()
