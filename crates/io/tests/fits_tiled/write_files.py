"""Writes the tile-compressed FITS images crates/io/tests/fits_tiled.rs
reads, with astropy's CompImageHDU (cfitsio's compression code), and the
values astropy decompresses them to, the test's oracle (as .npy, in
astropy's (z, y, x) order).

Usage: python write_files.py OUT_DIR

int16_<method>.fits   a 12 x 10 x 6 int16 ramp with noise, tiles 5 x 4 x 1
                      (cut at the edges), RICE_1, GZIP_1, GZIP_2
uint16_rice.fits      uint16 (BZERO 32768) up to 65535, Rice
int32_rice.fits       int32 over the whole range, Rice at 4 bytes
uint8_rice.fits       uint8, Rice at 1 byte
float_dither1.fits    float32 smooth field + noise, quantised (q = 4) with
                      SUBTRACTIVE_DITHER_1, ZDITHER0 7, Rice; a NaN
float_dither2.fits    the same, SUBTRACTIVE_DITHER_2 with exact zeros
float_nodither.fits   the same, NO_DITHER, GZIP_2
float_lossless.fits   float32 kept exactly (quantize_level 0: GZIP of
                      the floats)
plio.fits, hcompress.fits  PLIO_1 and HCOMPRESS_1 (refused by name)
"""

import sys

import numpy as np
from astropy.io import fits

out = sys.argv[1]
z, y, x = np.indices((6, 10, 12))
rng = np.random.default_rng(5)


def write(name, data, **kw):
    hdu = fits.CompImageHDU(data, **kw)
    fits.HDUList([fits.PrimaryHDU(), hdu]).writeto(f"{out}/{name}.fits", overwrite=True)
    with fits.open(f"{out}/{name}.fits") as f:
        np.save(f"{out}/{name}.npy", np.asarray(f[1].data))


ramp = (x * 37 + y * 101 + z * 997 - 3000 + rng.integers(-50, 50, x.shape)).astype(np.int16)
for method in ["RICE_1", "GZIP_1", "GZIP_2"]:
    write(f"int16_{method.lower()}", ramp, compression_type=method, tile_shape=(1, 4, 5))
write("uint16_rice", (ramp.astype(np.int32) * 9 + 32768).clip(0, 65535).astype(np.uint16),
      compression_type="RICE_1")
write("int32_rice", (ramp.astype(np.int64) * 700_000).clip(-2**31, 2**31 - 1).astype(np.int32),
      compression_type="RICE_1")
write("uint8_rice", (ramp % 256).astype(np.uint8), compression_type="RICE_1")
field = (np.sin(x / 3.0) * np.cos(y / 4.0) * 100 + z * 10 + rng.normal(0, 1, x.shape)).astype(np.float32)
field[2, 3, 4] = np.nan
write("float_dither1", field, compression_type="RICE_1", quantize_level=4,
      quantize_method=1, dither_seed=7, tile_shape=(1, 10, 12))
zeros = field.copy()
zeros[1, :, :3] = 0.0
write("float_dither2", zeros, compression_type="RICE_1", quantize_level=4,
      quantize_method=2, dither_seed=7, tile_shape=(1, 10, 12))
write("float_nodither", field, compression_type="GZIP_2", quantize_level=4,
      quantize_method=-1, tile_shape=(1, 10, 12))
write("float_lossless", field, compression_type="GZIP_1", quantize_level=0)
write("plio", (ramp % 100).astype(np.int32).clip(0), compression_type="PLIO_1")
write("hcompress", ramp, compression_type="HCOMPRESS_1", tile_shape=(1, 10, 12))
