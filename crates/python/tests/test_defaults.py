"""The picture a file gets with no keywords where its file says what it
is, as the command line draws it (issue 43 item 8): axes in different
units (degrees by metres) stretched to a box, `scale=` as `--scale`; a CT
in Hounsfield units in the CT look. The files are written here by
netCDF4 and pydicom."""

import importlib
import os

import numpy as np
import pytest

import volray
from conftest import rgb


def need(module):
    """`module`, skipped where missing, except under CI=true."""
    try:
        return importlib.import_module(module)
    except ImportError:
        if os.environ.get("CI") == "true":
            raise
        pytest.skip(f"{module} missing (.ci/run installs it)")


def cf_file(tmp_path):
    """t(level, lat, lon): lon 10 to 19 degrees_east, lat 40 to 47
    degrees_north, level 0 to 3000 m (positive up)."""
    netCDF4 = need("netCDF4")
    path = tmp_path / "cf.nc"
    with netCDF4.Dataset(path, "w") as f:
        for name, n in [("level", 6), ("lat", 8), ("lon", 10)]:
            f.createDimension(name, n)
        lon = f.createVariable("lon", "f8", ("lon",))
        lon.units = "degrees_east"
        lon[:] = 10 + np.arange(10)
        lat = f.createVariable("lat", "f8", ("lat",))
        lat.units = "degrees_north"
        lat[:] = 40 + np.arange(8)
        lev = f.createVariable("level", "f8", ("level",))
        lev.units = "m"
        lev.positive = "up"
        lev[:] = 600 * np.arange(6)
        t = f.createVariable("t", "f4", ("level", "lat", "lon"))
        k, j, i = np.mgrid[0:6, 0:8, 0:10]
        t[:] = 1.0 + i + j + k
    return path


def covered(pixels):
    """The columns and rows a picture covers (not its corner's colour)."""
    on = np.abs(pixels - pixels[0, 0]).max(axis=2) > 2
    cols, rows = np.nonzero(on.any(axis=0))[0], np.nonzero(on.any(axis=1))[0]
    width = cols.max() - cols.min() + 1 if cols.size else 0
    height = rows.max() - rows.min() + 1 if rows.size else 0
    return width, height


def test_degrees_by_metres_are_drawn_as_the_command_line_draws_them(tmp_path, cli_image):
    path = cf_file(tmp_path)
    vol = volray.read(path)
    # read keeps the stored geometry; render stretches it.
    assert vol.spacing == (1.0, 1.0, 600.0)
    got = rgb(volray.render(vol, size=48))
    want = cli_image(path, "--size", "48")[:, :, :3]
    assert np.abs(got - want).max() <= 1
    width, height = covered(got)
    assert width > 15 and height > 15, (width, height)
    # scale= as --scale: (1, 1, 1) the stored line.
    stored = rgb(volray.render(vol, size=48, scale=(1, 1, 1)))
    assert np.abs(stored - cli_image(path, "--size", "48", "--scale", "1,1,1")[:, :, :3]).max() <= 1
    assert covered(stored)[0] <= 2
    with pytest.raises(ValueError, match="scale"):
        volray.render(vol, size=48, scale=(1, 0, 1))


CT = """
import sys, numpy as np, pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid, CTImageStorage
out, n = sys.argv[1], 16
k, j, i = np.mgrid[0:n, 0:n, 0:n].astype(float)
c = (n - 1) / 2
hu = np.full((n, n, n), -1000.0)
hu[(abs(i - c) <= 6) & (abs(j - c) <= 6) & (abs(k - c) <= 6)] = 40.0
hu[(i - c) ** 2 + (j - c) ** 2 + (k - c) ** 2 <= 9] = 1200.0
stored = (hu + 1024).astype(np.uint16)
series = generate_uid()
for z in range(n):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = CTImageStorage
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = CTImageStorage, meta.MediaStorageSOPInstanceUID
    ds.SeriesInstanceUID, ds.Modality, ds.InstanceNumber = series, "CT", z + 1
    ds.ImagePositionPatient, ds.ImageOrientationPatient = [0, 0, z], [1, 0, 0, 0, 1, 0]
    ds.PixelSpacing, ds.Rows, ds.Columns = [1, 1], n, n
    ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
    ds.BitsAllocated = ds.BitsStored = 16
    ds.HighBit, ds.PixelRepresentation = 15, 0
    ds.RescaleIntercept, ds.RescaleSlope = -1024, 1
    ds.PixelData = stored[z].tobytes()
    ds.save_as(f"{out}/ct{z:02}.dcm", enforce_file_format=True)
"""


def test_a_ct_is_drawn_in_the_ct_look_as_the_command_line_draws_it(tmp_path, cli_image):
    need("pydicom")
    import subprocess
    import sys

    # Beside the pictures, not holding them (render refuses to write
    # into its input).
    series = tmp_path / "ct"
    series.mkdir()
    subprocess.run([sys.executable, "-c", CT, str(series)], check=True)
    vol = volray.read(series)
    got = rgb(volray.render(vol, size=48))
    assert np.abs(got - cli_image(series, "--size", "48")[:, :, :3]).max() <= 1
    bone = cli_image(series, "--size", "48", "--preset", "ct-bone")[:, :, :3]
    assert np.abs(got - bone).max() <= 1
    assert (np.abs(got - got[0, 0]).max(axis=2) > 2).any(), "the bone is drawn"
    # tf="auto" keeps the histogram's choice, as --tf auto does.
    auto = rgb(volray.render(vol, size=48, tf="auto"))
    assert np.abs(auto - cli_image(series, "--size", "48", "--tf", "auto")[:, :, :3]).max() <= 1


def test_an_ome_zarr_in_degrees_by_metres_is_stretched_whole_and_in_pieces(tmp_path, cli_image):
    zarr = need("zarr")
    k, j, i = np.mgrid[0:32, 0:64, 0:64]
    a = np.exp(-((i - 32) ** 2 + (j - 32) ** 2 + (k - 16) ** 2) / 200.0).astype(np.float32)
    path = tmp_path / "o.zarr"
    g = zarr.open_group(str(path), mode="w", zarr_format=2)
    g.create_array("0", shape=a.shape, chunks=(8, 16, 16), dtype="f4")[:] = a
    axes = [{"name": "z", "type": "space", "unit": "meter"}]
    axes += [{"name": n, "type": "space", "unit": "degree"} for n in "yx"]
    scale = [{"type": "scale", "scale": [100.0, 0.25, 0.25]}]
    g.attrs["multiscales"] = [
        {"version": "0.4", "axes": axes, "datasets": [{"path": "0", "coordinateTransformations": scale}]}
    ]
    vol = volray.read(path)
    whole = rgb(volray.render(vol, size=48))
    assert np.abs(whole - cli_image(path, "--size", "48")[:, :, :3]).max() <= 1
    # Under 600 KiB the level (626 KiB whole) is rendered in pieces.
    pieces = rgb(volray.render(vol, size=48, max_memory=600 << 10))
    assert np.abs(pieces - whole).max() <= 1
    width, height = covered(pieces)
    assert width > 10 and height > 10, (width, height)
