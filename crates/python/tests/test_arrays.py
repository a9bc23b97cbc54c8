"""numpy arrays as volumes: the axis convention (order="xyz", the
default, reads a[x, y, z] as volray's .npy files hold it; order="zyx"
reads a[z, y, x]), every dtype taken, and no copy where the array can be
used as it is."""

import numpy as np
import pytest
import volray
from conftest import rgb


def asymmetric():
    """a[z, y, x]: a ball near the +x end, a smaller one near +y, a rod
    along z: every axis flip or swap changes the picture."""
    z, y, x = np.mgrid[0:24, 0:32, 0:40].astype(np.float32)
    a = np.exp(-((x - 30) ** 2 + (y - 16) ** 2 + (z - 12) ** 2) / 18)
    a += np.exp(-((x - 10) ** 2 + (y - 26) ** 2 + (z - 12) ** 2) / 6)
    a += np.exp(-((x - 10) ** 2 + (y - 8) ** 2) / 4) * (z > 4)
    return a.astype(np.float32)  # shape (24, 32, 40): nz, ny, nx


def test_zyx_and_xyz_orders_read_the_same_volume(cli_image, tmp_path):
    a = asymmetric()
    assert volray.Volume(a, order="zyx").dims == (40, 32, 24)
    xyz_array = a.T  # a[x, y, z], x fastest in memory (Fortran order)
    assert volray.Volume(xyz_array).dims == (40, 32, 24)
    view = dict(size=64, azimuth=35, elevation=25)
    zyx = rgb(volray.render(a, order="zyx", **view))
    xyz = rgb(volray.render(xyz_array, **view))
    c_xyz = rgb(volray.render(np.ascontiguousarray(xyz_array), **view))
    assert np.array_equal(zyx, xyz) and np.array_equal(xyz, c_xyz)
    flags = ["--size", "64", "--azimuth", "35", "--elevation", "25"]
    # The same volume as a raw file, x fastest, is what the command line sees,
    a.tofile(tmp_path / "a.raw")
    assert np.abs(zyx - cli_image(tmp_path / "a.raw", "--dims", "40,32,24", *flags)).max() == 0
    # and so is a C-ordered a[x, y, z] saved by numpy.
    np.save(tmp_path / "a.npy", np.ascontiguousarray(xyz_array))
    assert np.abs(zyx - cli_image(tmp_path / "a.npy", *flags)).max() == 0
    # Read in the other order, the array is another volume.
    swapped = rgb(volray.render(a, **view))
    assert swapped.shape != zyx.shape or not np.array_equal(swapped, zyx)


def test_an_array_in_other_strides_is_copied_into_the_same_volume():
    a = asymmetric()
    strided = np.zeros((24, 32, 80), np.float32)[:, :, ::2]
    strided[...] = a
    assert not strided.flags.c_contiguous
    got = np.asarray(volray.render(strided, order="zyx", size=48))
    assert np.array_equal(got, np.asarray(volray.render(a, order="zyx", size=48)))


@pytest.mark.parametrize("dtype", ["u1", "i1", "u2", "i2", "u4", "i4", "f4", "f8", ">f4", ">u2"])
def test_every_dtype_renders_as_its_float32_values(dtype):
    a = (asymmetric().T * 100).astype(dtype)
    got = np.asarray(volray.render(a, size=48, azimuth=20))
    expected = np.asarray(volray.render(a.astype(np.float32), size=48, azimuth=20))
    assert np.array_equal(got, expected), dtype


@pytest.mark.parametrize("dtype", [np.uint8, np.int8, np.uint16, np.int16, np.float32])
def test_a_kept_type_is_used_without_a_copy(dtype):
    names = {np.uint8: "u8", np.int8: "i8", np.uint16: "u16", np.int16: "i16", np.float32: "f32"}
    c_zyx = (asymmetric() * 100).astype(dtype)
    volume = volray.Volume(c_zyx, order="zyx")
    assert volume.sample_type == names[dtype]
    assert np.shares_memory(volume.data, c_zyx)
    assert np.array_equal(volume.data, c_zyx.T)  # handed back as a[x, y, z]
    fortran_xyz = c_zyx.T
    assert np.shares_memory(volray.Volume(fortran_xyz).data, fortran_xyz)


def rss_bytes():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise AssertionError("no VmRSS")


def test_a_256_cube_of_u16_renders_without_a_copy_of_its_samples():
    n = 256
    a = np.zeros((n, n, n), np.uint16, order="F")
    a[100:156, 100:156, 100:156] = 1000  # a small block: a small working set
    a[0, 0, 0] = 1
    renderer = volray.Renderer(a)
    frame = renderer.render(size=256)
    assert np.asarray(frame)[128, 128, :3].max() > 0
    before = rss_bytes()
    for azimuth in (10, 20, 30):
        renderer.render(size=256, azimuth=azimuth)
    volray.render(a, size=256)
    grown = rss_bytes() - before
    # A copy would be 32 MiB (64 MiB as float32); frames are 1 MiB each.
    assert grown < a.nbytes // 2, f"RSS grew by {grown} bytes"
