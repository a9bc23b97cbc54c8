"""Shrinks `volray paper all` outputs for the README gallery.

    python docs/gallery/shrink.py OUT_DIR docs/gallery
    python docs/gallery/shrink.py --strip docs/gallery/first.png A.png B.png ...

The second form puts same-height PNGs side by side into one (the README's
first picture: what `volray render` draws with no options).

Each figure is reduced to an indexed-colour PNG of at most 128 colours
(k-means in RGB, scipy), the 480x480 clouds first halved by 2x2 box
averaging. Needs numpy and scipy; PNGs are read and written with zlib
alone (8-bit RGB in, 8-bit palette out).
"""

import struct
import sys
import zlib
from pathlib import Path

import numpy as np
from scipy.cluster.vq import kmeans2

COLOURS = 128


def read_rgb(path):
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert (depth, colour) == (8, 2), f"{path}: not 8-bit RGB"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = 3 * width
    out = np.zeros((height, stride), np.uint8)
    prev = np.zeros(stride, np.int32)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for x in range(stride):
            a = cur[x - 3] if x >= 3 else 0
            b = prev[x]
            c = prev[x - 3] if x >= 3 else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 255
        out[y] = cur
        prev = cur
    return out.reshape(height, width, 3)


def write_indexed(path, indices, palette):
    height, width = indices.shape

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    raw = b"".join(b"\x00" + indices[y].astype(np.uint8).tobytes() for y in range(height))
    Path(path).write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 3, 0, 0, 0))
        + chunk(b"PLTE", palette.astype(np.uint8).tobytes())
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


def shrink(rgb, path):
    """Writes `rgb` to `path` as an indexed PNG of at most COLOURS colours."""
    pixels = rgb.reshape(-1, 3)
    # Black (the background) is kept exact; the rest is clustered.
    rng = np.random.default_rng(1)
    centres, _ = kmeans2(pixels[pixels.sum(axis=1) > 0], COLOURS - 1, minit="++", seed=rng)
    palette = np.vstack([[0.0, 0.0, 0.0], centres]).clip(0, 255).round()
    d = ((pixels[:, None, :] - palette[None, :, :]) ** 2).sum(axis=2)
    indices = d.argmin(axis=1).reshape(rgb.shape[:2])
    write_indexed(path, indices, palette)
    print(path, Path(path).stat().st_size, "bytes")


def main(src, dst):
    for name in ["figure1a", "figure1b", "figure1c", "figure2a", "figure2b"]:
        rgb = read_rgb(Path(src) / f"{name}.png").astype(np.float64)
        if name.startswith("figure2"):
            h, w, _ = rgb.shape
            rgb = rgb.reshape(h // 2, 2, w // 2, 2, 3).mean(axis=(1, 3))
        shrink(rgb, Path(dst) / f"{name}.png")


if __name__ == "__main__":
    if sys.argv[1] == "--strip":
        panels = [read_rgb(p).astype(np.float64) for p in sys.argv[3:]]
        shrink(np.concatenate(panels, axis=1), sys.argv[2])
    else:
        main(*sys.argv[1:])
