"""Writes the TIFF stacks crates/io/tests/tiff_resolution.rs reads: plain
stacks (no ImageJ or OME metadata) whose resolution tags say the pixel
size, as CT and microscopy exporters write them, and ones whose tags say
nothing about it.

Usage: python write_files.py OUT_DIR

Every stack is 4 columns (x) by 3 rows (y) by 5 pages (z), uint16,
v = x + 10 y + 100 z. Files (tifffile's resolution= and resolutionunit=):

    cm.tif          20 x 40 pixels per centimetre: 0.5 x 0.25 mm pixels
    inch.tif        50.8 pixels per inch: 0.5 mm pixels
    dpi72.tif       72 pixels per inch, a print default
    no_unit.tif     20 x 20 pixels, ResolutionUnit NONE (tifffile's default)
"""

import os
import sys

import numpy as np
import tifffile

out = sys.argv[1]
z, y, x = np.indices((5, 3, 4))
v = (x + 10 * y + 100 * z).astype(np.uint16)

for name, res, unit in [
    ("cm.tif", (20.0, 40.0), "CENTIMETER"),
    ("inch.tif", (50.8, 50.8), "INCH"),
    ("dpi72.tif", (72.0, 72.0), "INCH"),
    ("no_unit.tif", (20.0, 20.0), "NONE"),
]:
    tifffile.imwrite(
        os.path.join(out, name), v, resolution=res, resolutionunit=unit,
        photometric="minisblack",
    )

# tifffile's own reading of the tags, the test's oracle: 2 and 4 pixels
# per mm are pixels of 0.5 and 0.25 mm.
with tifffile.TiffFile(os.path.join(out, "cm.tif")) as t:
    got = t.pages[0].get_resolution("MILLIMETER")
    assert got == (2.0, 4.0), got
