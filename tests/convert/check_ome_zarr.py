"""The OME-Zarr image `volray convert` wrote, as Python's tools read it.

    check_ome_zarr.py write IN.npy
        writes a uint16 array a[x, y, z] of shape (37, 20, 9), C order,
        its extremes included, for volray to convert;
    check_ome_zarr.py check IN.npy STORE 3|2
        checks the image volray wrote from it (with --chunk 8):
        zarr-python reads level 0 as the array itself (z, y, x: a
        transposed) and every level as numpy's own 2x2x2 block means of
        the level above (axes of more than 2 voxels halved, the voxels
        present at odd edges, rounded halves up); ome-zarr-py lists the
        same levels with their scale and translation; ome-zarr-models
        validates the metadata as NGFF 0.5 (Zarr v3) or 0.4 (Zarr v2).

Prints "ok" when every check holds (tests/cli_convert.rs runs it).
"""

import sys

import numpy as np
import zarr


def write(path):
    rng = np.random.default_rng(7)
    a = rng.integers(0, 65536, size=(37, 20, 9), dtype=np.uint16)
    a[0, 0, 0] = 0
    a[-1, -1, -1] = 65535
    np.save(path, a)
    print("ok")


def next_level(b):
    """b (z, y, x) as float64, one level down."""
    f = [2 if n > 2 else 1 for n in b.shape]
    padded = [-(-n // k) * k for n, k in zip(b.shape, f)]
    p = np.full(padded, np.nan)
    p[: b.shape[0], : b.shape[1], : b.shape[2]] = b
    blocks = p.reshape(padded[0] // f[0], f[0], padded[1] // f[1], f[1], padded[2] // f[2], f[2])
    return np.nanmean(blocks, axis=(1, 3, 5)), f


def check(npy, store, version):
    a = np.load(npy)
    zyx = a.transpose(2, 1, 0)
    group = zarr.open_group(store, mode="r")
    assert group.metadata.zarr_format == int(version), group.metadata

    # zarr-python: every level's values and layout.
    expect = zyx.astype(np.float64)
    scale = np.array([1.0, 1.0, 1.0])
    translation = np.array([0.0, 0.0, 0.0])
    transforms = []
    shapes = []
    level = 0
    while str(level) in group:
        arr = group[str(level)]
        if level > 0:
            expect, f = next_level(expect)
            expect = np.floor(expect + 0.5)
            translation = translation + 0.5 * scale * (np.array(f) - 1)
            scale = scale * np.array(f)
        assert arr.dtype == np.uint16, arr.dtype
        assert arr.shape == expect.shape, (level, arr.shape, expect.shape)
        got = arr[...]
        assert np.array_equal(got.astype(np.float64), expect), f"level {level} values"
        if level == 0:
            assert np.array_equal(got, zyx), "level 0 is the input"
        assert arr.chunks == tuple(min(8, n) for n in arr.shape), arr.chunks
        if version == "3":
            assert arr.shards is not None, "sharded"
            names = [type(c).__name__ for c in arr.metadata.codecs]
            assert names == ["ShardingCodec"], names
        else:
            assert arr.metadata.compressor.codec_id == "blosc", arr.metadata.compressor
            assert arr.metadata.dimension_separator == "/", arr.metadata
        transforms.append((scale.copy(), translation.copy()))
        shapes.append(arr.shape)
        level += 1
    assert shapes == [(9, 20, 37), (5, 10, 19), (3, 5, 10), (2, 3, 5)], shapes

    # ome-zarr-py: the image's levels and their transformations.
    from ome_zarr.io import parse_url
    from ome_zarr.reader import Multiscales, Reader

    nodes = list(Reader(parse_url(store))())
    image = nodes[0]
    assert image.load(Multiscales) is not None, "a multiscale image"
    assert [tuple(d.shape) for d in image.data] == shapes, image.data
    assert np.array_equal(np.asarray(image.data[0]), zyx), "ome-zarr level 0"
    assert [ax["name"] for ax in image.metadata["axes"]] == ["z", "y", "x"]
    for (s, t), ct in zip(transforms, image.metadata["coordinateTransformations"]):
        by = {c["type"]: c for c in ct}
        assert np.allclose(by["scale"]["scale"], s), (ct, s)
        assert np.allclose(by["translation"]["translation"], t), (ct, t)

    # ome-zarr-models: the metadata validates as NGFF 0.5 / 0.4.
    if version == "3":
        from ome_zarr_models.v05 import Image

        model = Image.from_zarr(group)
        ms = model.ome_attributes.multiscales
    else:
        from ome_zarr_models.v04 import Image

        model = Image.from_zarr(group)
        ms = model.attributes.multiscales
    assert len(ms) == 1 and len(ms[0].datasets) == len(shapes), ms
    print("ok")


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write(sys.argv[2])
    else:
        check(sys.argv[2], sys.argv[3], sys.argv[4])
