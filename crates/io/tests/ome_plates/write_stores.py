"""Writes the OME-Zarr plate, collection and omero stores that
crates/io/tests/ome_plates.rs reads, with ome-zarr-py and zarr-python,
into the directory named on the command line. Each image is a 3-D
(z, y, x) uint16 array of one level whose every sample is
1000 * tag + x + 10 * y + 100 * z, tag naming the image (plate field
A/1/0: 1, A/1/1: 2, B/2/0: 3; series 0: 4, series 1: 5; the omero
image: 6), so that a test knows which image it read.
"""

import json
import sys
from pathlib import Path

import numpy as np
import zarr
from ome_zarr.io import parse_url
from ome_zarr.writer import write_image, write_plate_metadata, write_well_metadata

out = Path(sys.argv[1])
SHAPE = (4, 5, 6)  # z, y, x


def image(tag):
    z, y, x = np.meshgrid(*[np.arange(n) for n in SHAPE], indexing="ij")
    return (1000 * tag + x + 10 * y + 100 * z).astype("u2")


def group(path):
    store = parse_url(str(path), mode="w").store
    return zarr.group(store=store)


# A plate: rows A, B; columns 1, 2; wells A/1 (two fields) and B/2 (one).
root = group(out / "plate.ome.zarr")
write_plate_metadata(root, ["A", "B"], ["1", "2"], ["A/1", "B/2"])
tag = 1
for well, fields in [("A/1", 2), ("B/2", 1)]:
    row, col = well.split("/")
    w = root.require_group(row).require_group(col)
    write_well_metadata(w, [str(f) for f in range(fields)])
    for f in range(fields):
        write_image(image(tag), w.require_group(str(f)), axes="zyx", scaler=None)
        tag += 1

# A bioformats2raw layout: OME/ listing the series, images 0/ and 1/.
root = group(out / "collection.ome.zarr")
root.attrs["bioformats2raw.layout"] = 3
ome = root.require_group("OME")
ome.attrs["series"] = ["0", "1"]
for series, tag in [("0", 4), ("1", 5)]:
    write_image(image(tag), root.require_group(series), axes="zyx", scaler=None)

# A plain group of two images, no listing.
root = group(out / "plain.zarr")
for name, tag in [("b", 5), ("a", 4)]:
    write_image(image(tag), root.require_group(name), axes="zyx", scaler=None)

# An image of two channels with omero hints.
root = group(out / "omero.ome.zarr")
two = np.stack([image(6), image(6) + 500])  # c, z, y, x
write_image(two, root, axes="czyx", scaler=None)
# ome-zarr-py's writer takes no omero block: added as its readers expect
# it, under "ome" (0.5).
ome = dict(root.attrs["ome"])
ome["omero"] = {
    "channels": [
        {"label": "DAPI", "color": "0000FF", "active": True,
         "window": {"start": 6100, "end": 6400, "min": 0, "max": 65535}},
        {"label": "GFP", "color": "00ff00", "active": False,
         "window": {"start": 6700, "end": 6900, "min": 6500, "max": 7000}},
    ],
    "rdefs": {"model": "color"},
}
root.attrs["ome"] = ome
print(json.dumps(sorted(p.name for p in out.iterdir())))
