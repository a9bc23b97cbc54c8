"""Writes the HDF5 and NetCDF-4 files crates/io/tests/hdf5_lazy.rs reads
box by box, with h5py (and netCDF4, h5netcdf), into the directory named
on the command line; beside each volume, its expected content as a .npy
(numpy), one volume a[x, y, z] per file: `NAME.npy` for FILE:/NAME, or
`NAME_tT.npy` for volume T of a 4-D series.

Values: ((x * 73 + y * 151 + z * 1009 + t * 3001) % 65521) spread over
the type's range, so that every byte of a sample varies (shuffle and
byte order matter), plus a fraction for floats.
"""

import sys
import zlib
from pathlib import Path

import h5py
import numpy as np

out = Path(sys.argv[1])


def field(shape, dtype, t=0):
    x, y, z = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    v = (x * 73 + y * 151 + z * 1009 + t * 3001) % 65521
    dt = np.dtype(dtype)
    if dt.kind == "f":
        return (v * 37.25 - 1e5).astype(dt)
    info = np.iinfo(dt)
    span = int(info.max) - int(info.min)
    return (int(info.min) + (v.astype(np.float64) / 65520 * span)).astype(np.float64).clip(
        info.min, info.max
    ).astype(dt) if dt.itemsize >= 8 else (int(info.min) + v * span // 65520).astype(dt)


def save(name, a):
    np.save(out / f"{name}.npy", np.ascontiguousarray(a))


SHAPE = (37, 29, 23)

# Every type, chunked (edge chunks on every axis), some filtered.
with h5py.File(out / "types.h5", "w") as f:
    for dtype, chunks, filt in [
        ("u1", (8, 7, 5), {}),
        ("i1", (8, 7, 5), {"compression": "gzip", "shuffle": True}),
        ("<u2", (8, 7, 5), {"compression": "gzip", "compression_opts": 4, "shuffle": True}),
        ("<i2", (16, 16, 16), {}),
        (">i2", (5, 9, 11), {"compression": "gzip"}),
        ("<u4", (8, 7, 5), {"shuffle": True}),
        ("<i4", (8, 7, 5), {"compression": "gzip", "shuffle": True}),
        ("<u8", (8, 7, 5), {"compression": "gzip", "shuffle": True}),
        (">i8", (8, 7, 5), {}),
        ("<f4", (8, 7, 5), {"compression": "gzip", "shuffle": True}),
        (">f4", (37, 29, 23), {"compression": "gzip"}),
        ("<f8", (8, 7, 5), {"compression": "gzip", "shuffle": True}),
        (">f8", (1, 29, 23), {"shuffle": True}),
    ]:
        name = ("be_" if dtype[0] == ">" else "") + np.dtype(dtype).name
        a = field(SHAPE, dtype)
        f.create_dataset(name, data=a, chunks=chunks, **filt)
        save(name, a)
    # Contiguous, both byte orders.
    for dtype, name in [("<f4", "contiguous_f32"), (">i2", "contiguous_be_i16")]:
        a = field(SHAPE, dtype)
        f.create_dataset(name, data=a)
        save(name, a)

# A 4-D series a[t, x, y, z], chunks across frames.
with h5py.File(out / "series.h5", "w") as f:
    shape = (3, 20, 18, 16)
    a = np.stack([field(shape[1:], "<u2", t) for t in range(shape[0])])
    f.create_dataset("s", data=a, chunks=(2, 7, 6, 5), compression="gzip", shuffle=True)
    f.create_dataset("c", data=a.astype("<f4"))
    for t in range(shape[0]):
        save(f"s_t{t}", a[t])
        save(f"c_t{t}", a[t].astype("<f4"))

# The other chunk indexes (the 1.10 format, as libver="v110" writes it): fixed array, extensible array,
# B-tree v2; and what is read through hdf5-pure's row windows.
with h5py.File(out / "latest.h5", "w", libver=("v110", "v110")) as f:
    a = field(SHAPE, "<i2")
    f.create_dataset("fixed", data=a, chunks=(8, 7, 5), compression="gzip", shuffle=True)
    f.create_dataset("extensible", data=a, chunks=(8, 7, 5), maxshape=(None,) + SHAPE[1:],
                     compression="gzip")
    f.create_dataset("btree2", data=a, chunks=(8, 7, 5), maxshape=(None, None, None),
                     compression="gzip")
    f.create_dataset("fletcher", data=a, chunks=(8, 7, 5), fletcher32=True)
    f.create_dataset("lzf", data=a, chunks=(8, 7, 5), compression="lzf")
    sparse = f.create_dataset("sparse", shape=SHAPE, dtype="<i2", chunks=(8, 7, 5),
                              fillvalue=-7)
    sparse[:16, :14, :] = a[:16, :14, :]
    b = np.full(SHAPE, -7, dtype="<i2")
    b[:16, :14, :] = a[:16, :14, :]
    for name in ["fixed", "extensible", "btree2", "fletcher", "lzf"]:
        save(name, a)
    save("sparse", b)

# The filters decoded box by box beyond deflate and shuffle: LZF (h5py's
# filter 32000), Fletcher-32 (an odd chunk size, and a chunk longer than
# the checksum's 360-word blocks), both with deflate and shuffle; chunks
# never written (the fill value); data never written at all.
with h5py.File(out / "filters.h5", "w") as f:
    for name, dtype, chunks, filt in [
        ("lzf_f32", "<f4", (8, 7, 5), {"compression": "lzf"}),
        ("shuffle_lzf_i16", ">i2", (16, 9, 11), {"compression": "lzf", "shuffle": True}),
        ("fletcher_u8", "u1", (9, 9, 11), {"fletcher32": True}),
        ("gzip_fletcher_f64", "<f8", (8, 7, 5),
         {"compression": "gzip", "shuffle": True, "fletcher32": True}),
        ("lzf_fletcher_u16", "<u2", (8, 7, 5), {"compression": "lzf", "fletcher32": True}),
    ]:
        a = field(SHAPE, dtype)
        f.create_dataset(name, data=a, chunks=chunks, **filt)
        save(name, a)
    a = field(SHAPE, "<f4")
    d = f.create_dataset("sparse_lzf_f32", shape=SHAPE, dtype="<f4", chunks=(8, 7, 5),
                         compression="lzf", fillvalue=-2.5)
    d[8:24, 7:, :10] = a[8:24, 7:, :10]
    b = np.full(SHAPE, -2.5, dtype="<f4")
    b[8:24, 7:, :10] = a[8:24, 7:, :10]
    save("sparse_lzf_f32", b)
    f.create_dataset("unwritten_i16", shape=SHAPE, dtype="<i2", fillvalue=-300)
    save("unwritten_i16", np.full(SHAPE, -300, dtype="<i2"))
    f.create_dataset("unwritten_chunked_u8", shape=SHAPE, dtype="u1", chunks=(8, 7, 5))
    save("unwritten_chunked_u8", np.zeros(SHAPE, dtype="u1"))

# A series (t, z, y, x) named by an axes attribute, in LZF chunks of one
# frame each, one chunk of frame 2 never written (fill value -1.5).
with h5py.File(out / "series_lzf.h5", "w") as f:
    shape = (4, 12, 18, 20)
    d = f.create_dataset("s", shape=shape, dtype="<f4", chunks=(1, 5, 8, 7),
                         compression="lzf", fillvalue=-1.5)
    d.attrs["axes"] = "tzyx"
    for t in range(shape[0]):
        # field(x, y, z) as a[x, y, z]; the file holds a[z, y, x].
        frame = field(shape[:0:-1], "<f4", t).transpose(2, 1, 0)
        if t == 2:
            d[t, 5:] = frame[5:]
            d[t, :5, 8:] = frame[:5, 8:]
            d[t, :5, :8, 7:] = frame[:5, :8, 7:]
            frame = frame.copy()
            frame[:5, :8, :7] = -1.5
        else:
            d[t] = frame
        save(f"s_lzf_t{t}", frame.transpose(2, 1, 0))

# Fletcher-32 over each chunk: one chunk's stored bytes changed.
with h5py.File(out / "fletcher_bad.h5", "w") as f:
    a = field((32, 32, 32), "<u2")
    d = f.create_dataset("v", data=a, chunks=(16, 16, 16), fletcher32=True)
    save("v_fletcher", a)
    info = d.id.get_chunk_info_by_coord((16, 0, 16))
    bad = info.byte_offset + 100
data = bytearray((out / "fletcher_bad.h5").read_bytes())
data[bad] ^= 0x40
(out / "fletcher_bad.h5").write_bytes(bytes(data))

# szip (filter 4) in the pipeline, set optional so that the file is
# written whether or not this h5py can apply it.
with h5py.File(out / "szip.h5", "w") as f:
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_chunk((8, 8, 8))
    dcpl.set_filter(h5py.h5z.FILTER_SZIP, h5py.h5z.FLAG_OPTIONAL, (4, 8))
    space = h5py.h5s.create_simple((16, 16, 16))
    h5py.h5d.create(f.id, b"v", h5py.h5t.STD_U8LE, space, dcpl=dcpl)
    f["v"][...] = field((16, 16, 16), "u1")

# A chunk no box may touch is corrupt: a box that does not touch it reads,
# one that does is refused (and so is the whole).
with h5py.File(out / "one_bad_chunk.h5", "w") as f:
    a = field((32, 32, 32), "<u2")
    d = f.create_dataset("v", data=a, chunks=(16, 16, 16), compression="gzip")
    save("v", a)
    info = d.id.get_chunk_info_by_coord((16, 16, 16))
    bad = (info.byte_offset, info.size)
data = bytearray((out / "one_bad_chunk.h5").read_bytes())
data[bad[0]:bad[0] + bad[1]] = b"\xff" * bad[1]
(out / "one_bad_chunk.h5").write_bytes(bytes(data))

# NetCDF-4: a variable written by netCDF-C (netCDF4) and by h5netcdf.
a = field((30, 26, 21), "<f4")
save("rho", a)
import netCDF4

with netCDF4.Dataset(out / "netcdf4.nc", "w", format="NETCDF4") as nc:
    for name, n in zip("xyz", a.shape):
        nc.createDimension(name, n)
    v = nc.createVariable("rho", "f4", ("x", "y", "z"), zlib=True, shuffle=True,
                          chunksizes=(8, 8, 8))
    v[:] = a
    t = nc.createVariable("temp", "i2", ("x", "y", "z"), contiguous=True)
    t[:] = field(a.shape, "<i2")
    save("temp", field(a.shape, "<i2"))
# ERA5's layout: t(time, z, latitude, longitude), latitude from 90 down
# to -90 (decreasing), in zlib chunks across it. The volume a[x, y, z] runs
# along longitude, latitude flipped to increase, z.
with netCDF4.Dataset(out / "latdown.nc", "w", format="NETCDF4") as nc:
    shape = (2, 5, 13, 16)
    for name, n in zip(["time", "z", "latitude", "longitude"], shape):
        nc.createDimension(name, n)
    for name, values, units in [
        ("time", np.arange(2.0), "hours since 2000-01-01"),
        ("z", np.arange(5.0) * 2, "m"),
        ("latitude", 90.0 - 15.0 * np.arange(13), "degrees_north"),
        ("longitude", 22.5 * np.arange(16), "degrees_east"),
    ]:
        c = nc.createVariable(name, "f8", (name,))
        c[:] = values
        c.units = units
    v = nc.createVariable("t", "f4", ("time", "z", "latitude", "longitude"), zlib=True,
                          chunksizes=(1, 2, 5, 8))
    for t in range(shape[0]):
        frame = field(shape[:0:-1], "<f4", t).transpose(2, 1, 0)  # [z, lat, lon]
        v[t] = frame
        save(f"t_latdown_t{t}", frame.transpose(2, 1, 0)[:, ::-1, :])
import h5netcdf

with h5netcdf.File(out / "h5netcdf.nc", "w") as nc:
    nc.dimensions = {"x": a.shape[0], "y": a.shape[1], "z": a.shape[2]}
    v = nc.create_variable("rho", ("x", "y", "z"), "f4", chunks=(8, 8, 8),
                           compression="gzip", shuffle=True)
    v[...] = a

# Hostile files.
# A chunk index entry pointing past the end of the file.
with h5py.File(out / "past_end.h5", "w") as f:
    d = f.create_dataset("v", data=field((16, 16, 16), "u1"), chunks=(8, 8, 8))
    at = d.id.get_chunk_info_by_coord((8, 8, 8)).byte_offset
data = bytearray((out / "past_end.h5").read_bytes())
needle = at.to_bytes(8, "little")
assert data.count(needle) == 1, data.count(needle)
i = data.index(needle)
data[i:i + 8] = (len(data) + (1 << 20)).to_bytes(8, "little")
(out / "past_end.h5").write_bytes(bytes(data))

# A declared shape of 2^40 voxels, nothing written.
with h5py.File(out / "huge.h5", "w") as f:
    f.create_dataset("v", shape=(1 << 14, 1 << 13, 1 << 13), dtype="u1", chunks=(64, 64, 64))

# A deflated chunk that inflates past its chunk's 512 bytes.
with h5py.File(out / "inflates.h5", "w") as f:
    d = f.create_dataset("v", data=field((16, 16, 16), "u1"), chunks=(8, 8, 8),
                         compression="gzip")
    d.id.write_direct_chunk((0, 0, 0), zlib.compress(bytes(8 * 8 * 8 * 4)))
