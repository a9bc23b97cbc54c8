"""numpy arrays as volumes: the axis convention (order="xyz", the
default, reads a[x, y, z] as volray's .npy files hold it; order="zyx"
reads a[z, y, x]), every dtype taken, and no copy where the array can be
used as it is."""

import subprocess
import sys

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


PEAK_SCRIPT = """
import resource, sys
import numpy as np
import volray

def peak():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux

# The module, its thread pool and a frame's buffers are warm before the
# baseline: a small volume's frame at the same size.
volray.render(np.ones((8, 8, 8), np.float32), size=256)
n = 256
a = np.empty((n, n, n), np.uint16, order="F")
a.fill(0)  # every page touched: resident before the baseline
a[100:156, 100:156, 100:156] = 1000  # a small block: a small working set
a[0, 0, 0] = 1
before = peak()
renderer = volray.Renderer(a)
assert np.asarray(renderer.render(size=256))[128, 128, :3].max() > 0
for azimuth in (10, 20, 30):
    renderer.render(size=256, azimuth=azimuth)
a[0, 0, 1] = 2  # changed in place: prepared again, still without a copy
renderer.render(size=256)
volray.render(a, size=256)
print(peak() - before, a.nbytes)
"""


def test_a_256_cube_of_u16_renders_without_a_copy_of_its_samples():
    # The peak resident size (ru_maxrss) of a fresh interpreter, so that a
    # temporary copy freed before the frame returns still counts.
    done = subprocess.run([sys.executable, "-c", PEAK_SCRIPT], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    grown, nbytes = map(int, done.stdout.split())
    # A copy would be 32 MiB (64 MiB as float32); the frames, histogram and
    # the block's bricks take a few MiB.
    assert grown < nbytes // 2, f"peak RSS grew by {grown} bytes"


def test_a_misaligned_array_is_copied_and_renders_as_an_aligned_one():
    for dtype in (np.uint16, np.int16, np.float32):
        a = (asymmetric() * 100).astype(dtype)
        # A u16 view at an odd byte offset: numpy does not promise alignment.
        misaligned = np.frombuffer(bytearray(a.nbytes + 1), dtype=dtype, offset=1, count=a.size)
        misaligned = misaligned.reshape(a.shape)
        misaligned[...] = a
        assert not misaligned.flags.aligned and misaligned.flags.c_contiguous
        volume = volray.Volume(misaligned, order="zyx")
        assert not np.shares_memory(volume.data, misaligned)
        assert np.array_equal(volume.data, a.T)
        got = rgb(volray.render(misaligned, order="zyx", size=48))
        assert np.array_equal(got, rgb(volray.render(a, order="zyx", size=48))), dtype


VIEW = dict(size=64, azimuth=35, elevation=25)
FLAGS = ["--size", "64", "--azimuth", "35", "--elevation", "25"]


def test_a_renderer_renders_the_array_as_it_is_after_an_in_place_change(cli_image, tmp_path):
    a = asymmetric()  # a[z, y, x], C order: rendered in place
    renderer = volray.Renderer(a, order="zyx")
    before = rgb(renderer.render(**VIEW))
    assert renderer.value_range == (a.min(), a.max())
    a *= 3
    a[:, :, 20:] = 0  # the large ball gone
    after = rgb(renderer.render(**VIEW))
    assert not np.array_equal(after, before)
    assert np.array_equal(after, rgb(volray.Renderer(a.copy(), order="zyx").render(**VIEW)))
    a.tofile(tmp_path / "a.raw")
    assert np.abs(after - cli_image(tmp_path / "a.raw", "--dims", "40,32,24", *FLAGS)).max() == 0
    assert renderer.value_range == (a.min(), a.max())
    # One sample changed is seen too.
    a[3, 4, 5] = 7
    assert renderer.value_range == (a.min(), 7)


@pytest.mark.parametrize(
    "make,keywords",
    [
        (lambda a: a.T, {}),  # a[x, y, z] in Fortran order: in place
        (lambda a: a.astype(np.float64), {"order": "zyx"}),  # copied to float32
        (lambda a: np.repeat(a, 2, axis=2)[:, :, ::2], {"order": "zyx"}),  # strided: copied
        (lambda a: a, {"order": "zyx", "log": True}),  # the log's copy
        (lambda a: a, {"order": "zyx", "nonfinite": "transparent"}),  # the cleaned copy
        (lambda a: volray.Volume(a, order="zyx"), {}),  # a Volume over the array
    ],
    ids=["fortran", "float64", "strided", "log", "nonfinite", "Volume"],
)
def test_every_kind_of_array_is_rendered_as_it_is_now(make, keywords):
    a = asymmetric() + 0.01
    held = make(a)
    renderer = volray.Renderer(held, **keywords)
    before = np.asarray(renderer.render(**VIEW))
    target = held.data if isinstance(held, volray.Volume) else held
    # In place, through the caller's own array: half of the volume emptied,
    # the rest raised to a new maximum.
    target[: target.shape[0] // 2] = target.min()
    target[-3] *= 2
    if keywords.get("nonfinite"):
        target.flat[7] = np.nan
    after = np.asarray(renderer.render(**VIEW))
    fresh = volray.Renderer(target.copy(), **{k: v for k, v in keywords.items()}).render(**VIEW)
    assert not np.array_equal(after, before)
    assert np.array_equal(after, np.asarray(fresh))


def test_label_volumes_changed_in_place_show_their_new_labels():
    labels = np.zeros((24, 24, 24), np.uint8)
    labels[4:10, 4:10, 4:10] = 1
    renderer = volray.Renderer(labels, labels=True)
    before = np.asarray(renderer.render(size=48))
    labels[14:20, 14:20, 14:20] = 2  # a label the renderer has not seen
    after = np.asarray(renderer.render(size=48))
    assert np.array_equal(after, np.asarray(volray.render(labels.copy(), labels=True, size=48)))
    assert not np.array_equal(after, before)


def test_a_read_volume_is_read_only_for_good(tmp_path):
    # So that a renderer of it need not digest its samples before each frame.
    np.save(tmp_path / "a.npy", asymmetric().T.copy())
    volume = volray.read(tmp_path / "a.npy")
    with pytest.raises(ValueError, match="read-only"):
        volume.data[0, 0, 0] = 1
    # numpy refuses to make it writeable again: volray owns the memory.
    with pytest.raises(ValueError):
        volume.data.flags.writeable = True
    copy = volume.data.copy()
    copy[0, 0, 0] = 1
    assert copy[0, 0, 0] == 1 and np.array_equal(volume.data, asymmetric().T)
