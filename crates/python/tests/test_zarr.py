"""volray.read of OME-Zarr images: `level=`, `channel=` and `frame=` pick
what the command line's --level, --channel and --frame pick, with the
values ome-zarr-py wrote and the level's spacing and origin; out of range
they raise. The stores are written at test time by
crates/io/tests/zarr/write_stores.py (zarr-python and ome-zarr-py, which
.ci/run installs in target/pyenv)."""


import numpy as np
import pytest

import volray

from conftest import written_by


@pytest.fixture(scope="module")
def stores(tmp_path_factory):
    return written_by(
        tmp_path_factory,
        "crates/io/tests/zarr/write_stores.py",
        ["ome_zarr", "zarr"],
        "zarr or ome-zarr",
    )


@pytest.mark.parametrize("name", ["ome04", "ome05"])
def test_read_takes_a_level_a_channel_and_a_time_point(stores, name):
    for level, t, c in [(0, 0, 0), (0, 1, 2), (1, 1, 1)]:
        v = volray.read(stores / f"{name}.zarr", level=level, frame=t, channel=c)
        expect = np.load(stores / f"{name}_{level}_t{t}_c{c}.npy")
        assert v.data.shape == expect.shape
        np.testing.assert_array_equal(v.data.astype(np.float64), expect.astype(np.float64))
    # The metadata's scale and translation (x, y, z), level by level.
    full = volray.read(stores / f"{name}.zarr")
    coarse = volray.read(stores / f"{name}.zarr", level=1)
    assert full.spacing == pytest.approx((0.25, 0.5, 2.0))
    assert full.origin == pytest.approx((1.5, -3.0, 10.0))
    assert coarse.spacing == pytest.approx((0.5, 1.0, 2.0))
    assert coarse.origin == pytest.approx((1.625, -2.75, 10.0))
    # Every level is listed, whichever was read, as read at that level.
    for v in (full, coarse):
        assert [lv["dims"] for lv in v.levels] == [full.data.shape, coarse.data.shape]
        assert v.levels[1]["spacing"] == pytest.approx(coarse.spacing)
        assert v.levels[1]["origin"] == pytest.approx(coarse.origin)
        assert v.levels[0]["bytes_stored"] > 0
        assert v.levels[0]["bytes_in_memory"] == full.data.nbytes
    assert volray.read("hydrogen:2,1,0,grid=20").levels == []


def test_a_level_or_channel_out_of_range_or_on_a_source_raises(stores):
    with pytest.raises(ValueError, match="level"):
        volray.read(stores / "ome04.zarr", level=2)
    with pytest.raises(ValueError, match="channel"):
        volray.read(stores / "ome04.zarr", channel=3)
    with pytest.raises(ValueError, match="built-in source"):
        volray.read("hydrogen:2,1,0,grid=20", level=1)
