"""Writes the HDF5 files crates/io/tests/hdf5_latest.rs reads, into the
directory named on the command line: datasets as h5py 3.16 (HDF5 2.0)
writes them with libver='latest' (layout message version 5 for filtered
chunks; a fixed array, an extensible array or a version 2 B-tree as the
chunk index, by the number of unlimited dimensions), each beside its
content as h5py reads it, `NAME.npy` for FILE:/NAME (a[x, y, z] for
both: volray's reading of a dataset without axis names); and a
NetCDF-4 file as netCDF-C before 4.x's `_Netcdf4Dimid` wrote it (its
dimensions only in the DIMENSION_LIST references of HDF5's dimension
scales), checked by netCDF4 (netCDF-C) to have the dimensions and
coordinates the tests expect. Then hostile copies: a version 2 B-tree
header whose record count lies, its checksum recomputed so that only
the count is wrong; a layout message damaged inside an intact object
header.
"""

import sys
from pathlib import Path

import h5py
import netCDF4
import numpy as np

out = Path(sys.argv[1])
SHAPE = (40, 30, 20)


def field(dtype):
    x, y, z = np.meshgrid(*[np.arange(n) for n in SHAPE], indexing="ij")
    v = (x * 73 + y * 151 + z * 1009) % 65521
    if np.dtype(dtype).kind == "f":
        return (v * 0.5 - 1000).astype(dtype)
    return (v % 30000 - 15000).astype(dtype)


def save(name, f):
    np.save(out / f"{name}.npy", np.ascontiguousarray(f[name][...]))


with h5py.File(out / "latest.h5", "w", libver="latest") as f:
    f.create_dataset("gzip", data=field("f4"), chunks=(8, 8, 8), compression="gzip")
    f.create_dataset(
        "shuffle_gzip", data=field("<i2"), chunks=(8, 7, 5), compression="gzip", shuffle=True
    )
    f.create_dataset(
        "fletcher", data=field(">f8"), chunks=(16, 16, 16), compression="gzip", fletcher32=True
    )
    f.create_dataset("plain", data=field("<i2"), chunks=(8, 8, 8))
    f.create_dataset(
        "one_unlimited", data=field("f4"), chunks=(8, 8, 8), maxshape=(None, 30, 20),
        compression="gzip",
    )
    f.create_dataset(
        "two_unlimited", data=field("f4"), chunks=(8, 8, 8), maxshape=(None, None, 20),
        compression="gzip", shuffle=True,
    )
    f.create_dataset(
        "two_unlimited_plain", data=field("<u2"), chunks=(8, 8, 8), maxshape=(None, None, 20)
    )
    # Chunks never written read as the fill value: only x < 16 and y < 8.
    d = f.create_dataset(
        "sparse", shape=SHAPE, dtype="f4", chunks=(8, 8, 8), maxshape=(None, None, 20),
        compression="gzip", fillvalue=-7.5,
    )
    d[:16, :8, :] = field("f4")[:16, :8, :]
    d = f.create_dataset(
        "sparse_fixed", shape=SHAPE, dtype="<i2", chunks=(8, 8, 8), compression="gzip",
        fillvalue=-3,
    )
    d[8:24, :, 10:] = field("<i2")[8:24, :, 10:]
    for name in list(f):
        save(name, f)

# NetCDF-4 as old netCDF-C wrote it: dimension scales x, y (both 6 long:
# only the references say which axis is which), z and a variable
# temp(z, y, x) attached to them; no _Netcdf4Dimid, no
# _Netcdf4Coordinates.
with h5py.File(out / "old_dims.nc", "w") as f:
    coords = {
        "x": np.arange(6) * 2.5 + 10.0,
        "y": np.arange(6) * 0.5 - 1.0,
        "z": np.arange(4) * 3.0,
    }
    for name, c in coords.items():
        f.create_dataset(name, data=c)
        f[name].make_scale(name)
        f[name].attrs["units"] = "m"
    t = np.fromfunction(lambda k, j, i: i + 10 * j + 100 * k, (4, 6, 6)).astype("f4")
    v = f.create_dataset("temp", data=t)
    for axis, name in enumerate(["z", "y", "x"]):
        v.dims[axis].attach_scale(f[name])
    for name in ("x", "y", "z"):
        assert "_Netcdf4Dimid" not in f[name].attrs
np.save(out / "temp.npy", np.ascontiguousarray(t.transpose(2, 1, 0)))

# The oracle: netCDF-C sees temp's dimensions as (z, y, x) and their
# coordinates.
with netCDF4.Dataset(out / "old_dims.nc") as nc:
    assert nc["temp"].dimensions == ("z", "y", "x"), nc["temp"].dimensions
    assert np.array_equal(nc["x"][:], coords["x"])
    assert np.array_equal(nc["y"][:], coords["y"])


def lookup3(data, initval=0):
    """Bob Jenkins' hashlittle (lookup3.c), HDF5's metadata checksum
    (H5_checksum_lookup3, H5checksum.c)."""
    mask = 0xFFFFFFFF

    def rot(x, k):
        return ((x << k) | (x >> (32 - k))) & mask

    length = len(data)
    a = b = c = (0xDEADBEEF + length + initval) & mask
    i = 0
    while length > 12:
        a = (a + int.from_bytes(data[i : i + 4], "little")) & mask
        b = (b + int.from_bytes(data[i + 4 : i + 8], "little")) & mask
        c = (c + int.from_bytes(data[i + 8 : i + 12], "little")) & mask
        a = (a - c) & mask; a ^= rot(c, 4); c = (c + b) & mask
        b = (b - a) & mask; b ^= rot(a, 6); a = (a + c) & mask
        c = (c - b) & mask; c ^= rot(b, 8); b = (b + a) & mask
        a = (a - c) & mask; a ^= rot(c, 16); c = (c + b) & mask
        b = (b - a) & mask; b ^= rot(a, 19); a = (a + c) & mask
        c = (c - b) & mask; c ^= rot(b, 4); b = (b + a) & mask
        length -= 12
        i += 12
    if length == 0:
        return c
    tail = data[i:] + bytes(12 - length)
    a = (a + int.from_bytes(tail[0:4], "little")) & mask
    b = (b + int.from_bytes(tail[4:8], "little")) & mask
    c = (c + int.from_bytes(tail[8:12], "little")) & mask
    c ^= b; c = (c - rot(b, 14)) & mask
    a ^= c; a = (a - rot(c, 11)) & mask
    b ^= a; b = (b - rot(a, 25)) & mask
    c ^= b; c = (c - rot(b, 16)) & mask
    a ^= c; a = (a - rot(c, 4)) & mask
    b ^= a; b = (b - rot(a, 14)) & mask
    c ^= b; c = (c - rot(b, 24)) & mask
    return c


# A version 2 B-tree chunk index, damaged three ways, each checksum
# recomputed so that only the damage is wrong.
with h5py.File(out / "btree.h5", "w", libver="latest") as f:
    f.create_dataset(
        "v", data=field("f4"), chunks=(8, 8, 8), maxshape=(None, None, 20), compression="gzip"
    )
np.save(out / "btree.npy", field("f4"))
good = (out / "btree.h5").read_bytes()
at = good.find(b"BTHD")
assert at > 0 and good.find(b"BTHD", at + 1) < 0
# The header: signature 4, version 1, type 1, node size 4, record size 2,
# depth 2, split 1, merge 1, root address 8, records in the root 2, total
# records 8 (8-byte lengths), checksum 4.
end = at + 4 + 1 + 1 + 4 + 2 + 2 + 1 + 1 + 8 + 2 + 8
assert lookup3(good[at:end]) == int.from_bytes(good[end : end + 4], "little")
node, record, depth = (int.from_bytes(good[at + k : at + k + n], "little") for k, n in
                       [(6, 4), (10, 2), (12, 2)])
root = int.from_bytes(good[end - 18 : end - 10], "little")
in_root = int.from_bytes(good[end - 10 : end - 8], "little")
assert (node, record, depth, in_root) == (2048, 44, 1, 1), (node, record, depth, in_root)
assert good[root : root + 4] == b"BTIN"


def patched_at(good, edits, checksummed):
    """`good` with each (offset, bytes) of `edits` written, then each
    (start, stop) range's lookup3 checksum written at stop."""
    raw = bytearray(good)
    for offset, value in edits:
        raw[offset : offset + len(value)] = value
    for start, stop in checksummed:
        raw[stop : stop + 4] = lookup3(bytes(raw[start:stop])).to_bytes(4, "little")
    return bytes(raw)


def patched(edits, checksummed):
    return patched_at(good, edits, checksummed)


# The total record count says 2^40: it counts, it allocates nothing.
(out / "btree_total_lies.h5").write_bytes(
    patched([(end - 8, (1 << 40).to_bytes(8, "little"))], [(at, end)])
)
# The root says it holds 60000 records, more than a 2048-byte node can.
(out / "btree_root_count.h5").write_bytes(
    patched([(end - 10, (60000).to_bytes(2, "little"))], [(at, end)])
)
# The root's first child is the root itself: a loop. The internal node:
# signature 4, version 1, type 1, one record of 44 bytes, two children of
# an address 8 and a record count 1 (a leaf holds at most 46), checksum.
child = root + 6 + 44
body = 6 + 44 + 2 * 9
assert lookup3(good[root : root + body]) == int.from_bytes(
    good[root + body : root + body + 4], "little"
)
(out / "btree_loop.h5").write_bytes(
    patched([(child, root.to_bytes(8, "little"))], [(root, root + body)])
)

# A layout message of version 5 damaged inside an intact object header
# (its checksum recomputed): its chunk index type 9, which no version
# defines; and its size cut to 4 bytes, the message ending inside its
# chunk dimensions.
with h5py.File(out / "layout.h5", "w", libver="latest") as f:
    f.create_dataset("v", data=field("f4"), chunks=(8, 8, 8), compression="gzip")
good = (out / "layout.h5").read_bytes()
hits = [i for i in range(len(good) - 6) if good[i] == 8 and good[i + 4 : i + 6] == b"\x05\x02"]
assert len(hits) == 1, hits
msg = hits[0]  # type 1, size 2, flags 1, then the message: 5, 2, flags,
size = int.from_bytes(good[msg + 1 : msg + 3], "little")
body = msg + 4  # dimensionality, dimension size width, dimensions...
ndims, width = good[body + 3], good[body + 4]
index_type = body + 5 + ndims * width
assert good[index_type] == 3, good[index_type]  # a fixed array
oh = good.rfind(b"OHDR", 0, msg)
flags = good[oh + 5]
at = oh + 6 + (16 if flags & 0x20 else 0) + (4 if flags & 0x10 else 0)
width0 = 1 << (flags & 3)
chunk0 = int.from_bytes(good[at : at + width0], "little")
start = at + width0
assert start <= msg < start + chunk0
assert lookup3(good[oh : start + chunk0]) == int.from_bytes(
    good[start + chunk0 : start + chunk0 + 4], "little"
)
(out / "layout_index_type.h5").write_bytes(
    patched_at(good, [(index_type, b"\x09")], [(oh, start + chunk0)])
)
(out / "layout_cut.h5").write_bytes(
    patched_at(good, [(msg + 1, (4).to_bytes(2, "little"))], [(oh, start + chunk0)])
)
assert size > 4
