"""Writes the zarr target's seeds (fuzz/seeds/zarr/): small arrays written
by zarr-python (v3: bytes, zstd, gzip, blosc, sharded with zstd subchunks
and a crc32c index; v2: none, zstd, gzip, blosc), each packed as the
target reads its input: a control byte (bit 0 Zarr v2, bit 1 no chunk
file, bit 2 a lazy read of half the array), the metadata's length as a
little-endian u16, the metadata file, then the one chunk or shard file.
See fuzz_targets/zarr.rs. Run with target/pyenv/bin/python (zarr,
numcodecs, numpy)."""
import pathlib
import struct
import tempfile

import numcodecs
import numpy as np
import zarr
from zarr.codecs import BloscCodec, GzipCodec, ZstdCodec

out = pathlib.Path(__file__).parent / "seeds" / "zarr"
out.mkdir(parents=True, exist_ok=True)


def pack(name, control, meta, chunk):
    (out / name).write_bytes(bytes([control]) + struct.pack("<H", len(meta)) + meta + chunk)


def seed(name, zarr_format, shape, dtype, controls, **kwargs):
    with tempfile.TemporaryDirectory() as d:
        a = zarr.create_array(
            store=d, shape=shape, dtype=dtype, fill_value=7, zarr_format=zarr_format, **kwargs
        )
        a[...] = (np.arange(np.prod(shape)) % 200).reshape(shape).astype(dtype)
        root = pathlib.Path(d)
        if zarr_format == 3:
            meta, chunk = root / "zarr.json", root / "c" / "0" / "0" / "0"
        else:
            meta, chunk = root / ".zarray", root / "0.0.0"
        for control in controls:
            pack(f"{name}_{control}", control, meta.read_bytes(), chunk.read_bytes())


v3 = dict(zarr_format=3, shape=(2, 3, 4), chunks=(2, 3, 4))
seed("v3_bytes_u16", dtype="uint16", compressors=None, controls=[0, 2, 4], **v3)
seed("v3_zstd_f32", dtype="float32", compressors=ZstdCodec(level=3), controls=[0], **v3)
seed("v3_gzip_i16", dtype="int16", compressors=GzipCodec(level=5), controls=[0], **v3)
seed("v3_blosc_u8", dtype="uint8", compressors=BloscCodec(cname="lz4"), controls=[0], **v3)
seed(
    "v3_sharded_zstd_u16",
    zarr_format=3,
    shape=(2, 4, 4),
    chunks=(2, 2, 2),
    shards=(2, 4, 4),
    dtype="uint16",
    compressors=ZstdCodec(level=3),
    controls=[0, 4],
)
v2 = dict(zarr_format=2, shape=(2, 3, 4), chunks=(2, 3, 4))
seed("v2_none_u16", dtype="uint16", compressors=None, controls=[1, 3], **v2)
seed("v2_zstd_f64", dtype="float64", compressors=numcodecs.Zstd(level=3), controls=[1], **v2)
seed("v2_gzip_i32", dtype="int32", compressors=numcodecs.GZip(level=5), controls=[1], **v2)
seed("v2_blosc_u16", dtype="uint16", compressors=numcodecs.Blosc(cname="zstd"), controls=[1, 5], **v2)
