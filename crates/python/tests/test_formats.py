"""volray.read on the formats of issue 25: the volumes, spacing and origin
that the Rust readers' tests hold to the tools that wrote the fixtures
(crates/io/tests/fixtures: netCDF4-python, astropy, nibabel), and the
formats still refused, refused by name."""

from pathlib import Path

import numpy as np
import pytest

import volray

FIXTURES = Path(__file__).resolve().parents[3] / "crates/io/tests/fixtures"


def ramp(i, j, k, t=0):
    return i + 10 * j + 100 * k + 1000 * t


def grid(nx, ny, nz):
    return np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")


def test_a_netcdf3_variable_reads_with_its_cf_coordinates_and_its_record():
    v = volray.read(FIXTURES / "netcdf/classic.nc", array="rho", frame=1)
    assert v.dims == (12, 10, 8)
    # x = -3 + 0.5 i mm, y = 20 - 2 j mm (decreasing: flipped), z in m.
    assert v.spacing == pytest.approx((0.5, 2.0, 4.0))
    assert v.origin == pytest.approx((-3.0, 2.0, 10.0))
    i, j, k = grid(12, 10, 8)
    want = ramp(i, 9 - j, k, 1) + 0.25
    assert np.array_equal(v.data, want.astype(v.data.dtype))


def test_a_netcdf3_file_with_two_variables_needs_array_and_says_so():
    with pytest.raises(ValueError, match=r"rho\(time, z, y, x\), temp\(time, z, y, x\)"):
        volray.read(FIXTURES / "netcdf/classic.nc")


def test_a_fits_cube_reads_with_astropys_world_coordinates():
    v = volray.read(FIXTURES / "fits/wcs_mm.fits")
    assert v.dims == (8, 6, 5)
    # astropy.wcs: pixel (0, 0, 0) at (9, -5, 98) mm, steps 0.5, -0.75, 2.
    assert v.spacing == pytest.approx((0.5, 0.75, 2.0))
    assert v.origin == pytest.approx((9.0, -8.75, 98.0))
    i, j, k = grid(8, 6, 5)
    want = ramp(i, 5 - j, k) + 0.25
    assert np.array_equal(v.data, want.astype(v.data.dtype))


def test_mgh_and_mgz_read_the_same_volume_and_frames():
    for name in ("f32", "i16"):
        for frame in (0, 1):
            plain = volray.read(FIXTURES / f"mgh/{name}.mgh", frame=frame)
            packed = volray.read(FIXTURES / f"mgh/{name}.mgz", frame=frame)
            assert np.array_equal(plain.data, packed.data)
            assert plain.spacing == packed.spacing and plain.origin == packed.origin
        assert not np.array_equal(
            volray.read(FIXTURES / f"mgh/{name}.mgh", frame=0).data,
            volray.read(FIXTURES / f"mgh/{name}.mgh", frame=1).data,
        )


@pytest.mark.parametrize(
    "name, format",
    [
        ("T1.PAR", "Philips PAR/REC"),
        ("tinypet.v", "ECAT 7"),
        ("grid.vdb", "OpenVDB"),
    ],
)
def test_formats_volray_does_not_read_are_refused_by_name(name, format):
    with pytest.raises(ValueError, match="not read by volray") as raised:
        volray.read(FIXTURES / "not_read" / name)
    assert format in str(raised.value) and name in str(raised.value)
