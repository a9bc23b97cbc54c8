"""Writes the files crates/io/tests/geometry.rs reads: vertical
coordinates that point down (pressure levels, ocean depth) and axes in
several length units.

Usage: python write_files.py OUT_DIR

Every volume stores v = i + 10 j + 100 k at file index [k, j, i] (z, y, x
slowest first, as NetCDF and OME-Zarr store them), so a value names the
file index it came from. Files:

    pressure.nc      NetCDF-4 (netCDF4-python): t(level, lat, lon) float32;
                     level 1000, 850, 700, 550, 400 hPa (the ground
                     first), positive = "down", standard_name air_pressure;
                     lat 0, 10, 20, 30 degrees_north; lon 0, 10, ... 40
                     degrees_east; chunked (2, 2, 3)
    pressure3.nc     the same as NetCDF-3 (NETCDF3_CLASSIC)
    pressure_up.nc   NetCDF-4, level stored 400, 550, ... 1000 hPa (the top
                     first), units hPa only: no positive, no standard_name
    ocean.nc         NetCDF-4: temp(depth, y, x); depth 0, 25, 50, 75 m,
                     positive = "down"; y 0, 2, 4 km; x 0, 1, ... 4 km
    mixed04.zarr     OME-Zarr 0.4 (ome-zarr-py, Zarr v2): (z, y, x) 3 x 4 x 5,
                     z in micrometer, y and x in nanometer, scale
                     [1, 100, 100], translation [2, 50, 0]
    mixed05.zarr     the same as OME-Zarr 0.5 (Zarr v3)
    mixed.nrrd       pynrrd: space directions diag(0.5, 0.5, 2), space units
                     "mm" "mm" "um", space origin (1, 2, 3)
"""

import os
import sys

import netCDF4
import numpy as np

out = sys.argv[1]
K, J, I = 5, 4, 5
k, j, i = np.indices((K, J, I))
v = (i + 10 * j + 100 * k).astype(np.float32)


def coord(nc, name, values, **attrs):
    c = nc.createVariable(name, "f8", (name,))
    c[:] = values
    for key, a in attrs.items():
        c.setncattr(key, a)


def pressure(name, fmt, levels, **level_attrs):
    with netCDF4.Dataset(os.path.join(out, name), "w", format=fmt) as nc:
        for d, n in [("level", K), ("lat", J), ("lon", I)]:
            nc.createDimension(d, n)
        coord(nc, "level", levels, units="hPa", **level_attrs)
        coord(nc, "lat", 10.0 * np.arange(J), units="degrees_north")
        coord(nc, "lon", 10.0 * np.arange(I), units="degrees_east")
        kw = {"chunksizes": (2, 2, 3)} if fmt == "NETCDF4" else {}
        t = nc.createVariable("t", "f4", ("level", "lat", "lon"), **kw)
        t[:] = v


down = {"positive": "down", "standard_name": "air_pressure"}
pressure("pressure.nc", "NETCDF4", [1000, 850, 700, 550, 400], **down)
pressure("pressure3.nc", "NETCDF3_CLASSIC", [1000, 850, 700, 550, 400], **down)
pressure("pressure_up.nc", "NETCDF4", [400, 550, 700, 850, 1000])

with netCDF4.Dataset(os.path.join(out, "ocean.nc"), "w", format="NETCDF4") as nc:
    for d, n in [("depth", 4), ("y", 3), ("x", 5)]:
        nc.createDimension(d, n)
    coord(nc, "depth", 25.0 * np.arange(4), units="m", positive="down")
    coord(nc, "y", 2.0 * np.arange(3), units="km", axis="Y")
    coord(nc, "x", 1.0 * np.arange(5), units="km", axis="X")
    t = nc.createVariable("temp", "f4", ("depth", "y", "x"))
    t[:] = v[:4, :3, :5]

with netCDF4.Dataset(os.path.join(out, "pressure.nc")) as nc:
    assert nc["t"][0, 1, 2] == 12 and nc["level"][0] == 1000

import zarr
from ome_zarr.format import FormatV04, FormatV05
from ome_zarr.writer import write_multiscale

axes = [
    {"name": "z", "type": "space", "unit": "micrometer"},
    {"name": "y", "type": "space", "unit": "nanometer"},
    {"name": "x", "type": "space", "unit": "nanometer"},
]
zyx = np.ascontiguousarray(v[:3, :4, :5]).astype(np.uint16)
for name, fmt, zarr_format in [("mixed04", FormatV04(), 2), ("mixed05", FormatV05(), 3)]:
    group = zarr.open_group(os.path.join(out, name + ".zarr"), mode="w", zarr_format=zarr_format)
    write_multiscale(
        [zyx], group, fmt=fmt, axes=axes,
        coordinate_transformations=[[
            {"type": "scale", "scale": [1.0, 100.0, 100.0]},
            {"type": "translation", "translation": [2.0, 50.0, 0.0]},
        ]],
    )

import nrrd

nrrd.write(
    os.path.join(out, "mixed.nrrd"),
    np.ascontiguousarray(v[:3, :4, :5].T),  # pynrrd: a[x, y, z], x fastest
    {
        "space": "right-anterior-superior",
        "space directions": np.diag([0.5, 0.5, 2.0]),
        "space units": ["mm", "mm", "um"],
        "space origin": np.array([1.0, 2.0, 3.0]),
    },
    index_order="F",
)
print("wrote", sorted(os.listdir(out)))
