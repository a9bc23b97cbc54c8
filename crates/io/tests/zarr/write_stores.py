"""Writes the Zarr and OME-Zarr stores that crates/io/tests/zarr.rs reads.

Usage: python write_stores.py OUT_DIR

Each store is written by zarr-python (v2 and v3 arrays) or ome-zarr-py
(OME-Zarr 0.4 on Zarr v2, 0.5 on Zarr v3), and every array it holds is
dumped beside it with numpy as NAME.npy, transposed to (x, y, z) so that
volray's .npy reader (a[x, y, z]) reads the values in the same places.
For a 5-D OME array, each time point and channel is dumped on its own:
NAME_t{T}_c{C}.npy. Sizes are tiny; values are exact in float32.
"""

import os
import sys

import numpy as np
import zarr
from zarr.codecs import BloscCodec, GzipCodec, ZstdCodec
import numcodecs

out = sys.argv[1]


def dump(name, zyx):
    np.save(os.path.join(out, name + ".npy"), np.asarray(zyx).T)


def values(shape, dtype, seed):
    rng = np.random.default_rng(seed)
    info = np.iinfo(dtype) if np.dtype(dtype).kind in "iu" else None
    if info is not None:
        lo, hi = max(info.min, -30000), min(info.max, 60000)
        return rng.integers(lo, hi, size=shape, endpoint=True).astype(dtype)
    return rng.standard_normal(shape).astype(dtype)


def plain(name, shape, chunks, dtype, fmt, seed, fill=0, hole=False, **kw):
    """A bare array; `hole` leaves the first chunk all fill value, so
    zarr-python writes no file for it (write_empty_chunks is off)."""
    data = values(shape, dtype, seed)
    if hole:
        data[: chunks[0], : chunks[1], : chunks[2]] = fill
    arr = zarr.create_array(
        os.path.join(out, name + ".zarr"),
        shape=shape,
        chunks=chunks,
        dtype=dtype,
        zarr_format=fmt,
        fill_value=fill,
        **kw,
    )
    arr[...] = data
    dump(name, data)


plain("v2_gzip", (5, 6, 7), (2, 3, 4), "int16", 2, 1, fill=-7, hole=True,
      compressors=numcodecs.GZip(level=5))
plain("v2_blosc", (4, 5, 9), (3, 3, 3), "float32", 2, 2,
      compressors=numcodecs.Blosc(cname="lz4", clevel=5, shuffle=numcodecs.Blosc.SHUFFLE))
plain("v2_zstd_u16", (3, 4, 5), (2, 2, 2), "uint16", 2, 3,
      compressors=numcodecs.Zstd(level=3))
# Fortran order: zarrs reads it through the transpose codec.
plain("v2_forder", (3, 4, 5), (2, 3, 2), "int8", 2, 9, order="F",
      compressors=numcodecs.Zstd(level=1))
plain("v3_zstd", (5, 6, 7), (2, 3, 4), "uint16", 3, 4, fill=9, hole=True,
      compressors=ZstdCodec(level=3))
plain("v3_gzip_f64", (3, 4, 6), (3, 4, 6), "float64", 3, 5,
      compressors=GzipCodec(level=6))
plain("v3_sharded_blosc", (6, 6, 8), (2, 3, 4), "uint8", 3, 6,
      shards=(4, 6, 8), compressors=BloscCodec(cname="zstd", clevel=3, shuffle="bitshuffle"))

# OME-Zarr: a pyramid of two levels (t, c, z, y, x), the second halved
# along y and x, each with its own scale and translation.
from ome_zarr.format import FormatV04, FormatV05
from ome_zarr.writer import write_multiscale

axes = [
    {"name": "t", "type": "time"},
    {"name": "c", "type": "channel"},
    {"name": "z", "type": "space", "unit": "micrometer"},
    {"name": "y", "type": "space", "unit": "micrometer"},
    {"name": "x", "type": "space", "unit": "micrometer"},
]
transforms = [
    [{"type": "scale", "scale": [1.0, 1.0, 2.0, 0.5, 0.25]},
     {"type": "translation", "translation": [0.0, 0.0, 10.0, -3.0, 1.5]}],
    [{"type": "scale", "scale": [1.0, 1.0, 2.0, 1.0, 0.5]},
     {"type": "translation", "translation": [0.0, 0.0, 10.0, -2.75, 1.625]}],
]


def ome(name, fmt, zarr_format, dtype, seed):
    level0 = values((2, 3, 4, 6, 8), dtype, seed)
    level1 = np.ascontiguousarray(level0[:, :, :, ::2, ::2])
    group = zarr.open_group(os.path.join(out, name + ".zarr"), mode="w", zarr_format=zarr_format)
    write_multiscale(
        [level0, level1], group, fmt=fmt, axes=axes,
        coordinate_transformations=transforms,
        storage_options={"chunks": (1, 1, 2, 3, 4)},
    )
    for level, data in enumerate([level0, level1]):
        for t in range(data.shape[0]):
            for c in range(data.shape[1]):
                dump(f"{name}_{level}_t{t}_c{c}", data[t, c])
    meta = "zarr.json" if zarr_format == 3 else ".zattrs"
    with open(os.path.join(out, name + ".zarr", meta)) as f:
        text = f.read()
    assert "multiscales" in text, text


ome("ome04", FormatV04(), 2, "uint16", 7)
ome("ome05", FormatV05(), 3, "float32", 8)

# The missing chunks really are missing.
assert not os.path.exists(os.path.join(out, "v2_gzip.zarr", "0.0.0"))
assert not os.path.exists(os.path.join(out, "v3_zstd.zarr", "c", "0", "0", "0"))
assert os.path.exists(os.path.join(out, "v3_zstd.zarr", "c", "0", "0", "1"))
print("wrote", sorted(os.listdir(out)))
