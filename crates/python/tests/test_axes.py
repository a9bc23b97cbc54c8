"""volray.read's `frame=` (time point) and `channel=` in every format, as
the command line's --frame and --channel: time and channel kept apart,
and `info` counting them (`time_points`, `channels`; `frames` = T x C).
The files are written at test time by crates/io/tests/axes/write_files.py
(tifffile, h5py, nibabel, pynrrd, which .ci/run installs in
target/pyenv): every volume holds x + 10y + 100z + 1000c + 10000t."""


import numpy as np
import pytest

import volray

from conftest import written_by


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    return written_by(
        tmp_path_factory,
        "crates/io/tests/axes/write_files.py",
        ["h5py", "nibabel", "nrrd", "tifffile"],
        "tifffile, h5py, nibabel or pynrrd",
    )


def expected(t, c):
    x, y, z = np.meshgrid(np.arange(6), np.arange(5), np.arange(4), indexing="ij")
    return x + 10 * y + 100 * z + 1000 * c + 10000 * t  # a[x, y, z]


@pytest.mark.parametrize("name", ["hyper.tif", "ome.ome.tif", "axes.h5:/tczyx", "five.nii"])
def test_read_takes_a_time_point_and_a_channel_in_every_format(files, name):
    for t, c in [(0, 0), (1, 2), (0, 1)]:
        v = volray.read(f"{files}/{name}", frame=t, channel=c)
        np.testing.assert_array_equal(v.data, expected(t, c))
        info = v.info
        assert (info["time_points"], info["channels"], info["frames"]) == (2, 3, 6)
        assert (info["time_point"], info["channel"], info["frame"]) == (t, c, 3 * t + c)
    with pytest.raises(ValueError, match="channel 3 is out of range"):
        volray.read(f"{files}/{name}", channel=3)
    with pytest.raises(ValueError, match="frame 2 is out of range"):
        volray.read(f"{files}/{name}", frame=2)
