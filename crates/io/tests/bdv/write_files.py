"""Writes the BigDataViewer datasets crates/io/tests/bdv.rs reads, with
npy2bdv (the BigDataViewer HDF5 + XML writer on PyPI), and the values
h5py reads back from them, the test's oracle.

Usage: python write_files.py OUT_DIR

dataset.xml + dataset.h5
    two channels (view setups 0, 1), two time points, levels of factors
    (1, 1, 1) and (2, 2, 2), 4^3 chunks, gzip; level 0 is 10 x 6 x 8
    (x, y, z) holding v = x + 10 y + 100 z + 40000 c + 1000 t (above
    32767: BigDataViewer keeps uint16 in int16 datasets); voxel size
    0.5 0.5 2 um, the calibration (1, 1, 4) and a shift (10, 20, 30)
    in BigDataViewer's world units as registration
alone.h5       dataset.h5 copied, without an XML beside it
level1_c1_t1.npy  level 1 of channel 1 at time point 1, (z, y, x), as
               h5py reads it (npy2bdv's downsampling), as uint16
n5.xml         dataset.xml with ImageLoader format "bdv.n5"
rotated.xml    dataset.xml whose shift is a rotation about z
"""

import os
import shutil
import sys

import h5py
import npy2bdv
import numpy as np

out = sys.argv[1]
z, y, x = np.indices((8, 6, 10))
base = x + 10 * y + 100 * z
shift = np.array([[1, 0, 0, 10], [0, 1, 0, 20], [0, 0, 1, 30]], float)

w = npy2bdv.BdvWriter(
    os.path.join(out, "dataset.h5"),
    nchannels=2,
    subsamp=((1, 1, 1), (2, 2, 2)),
    blockdim=((4, 4, 4), (4, 4, 4)),
    compression="gzip",
)
for t in range(2):
    for c in range(2):
        w.append_view(
            (base + 40000 * c + 1000 * t).astype(np.uint16),
            time=t,
            channel=c,
            voxel_size_xyz=(0.5, 0.5, 2.0),
            voxel_units="um",
            calibration=(1, 1, 4),
            m_affine=shift,
            name_affine="shift",
        )
w.write_xml()
w.close()

shutil.copy(os.path.join(out, "dataset.h5"), os.path.join(out, "alone.h5"))
with h5py.File(os.path.join(out, "dataset.h5"), "r") as f:
    level1 = f["t00001/s01/1/cells"][...].astype(np.int64) % 65536
    np.save(os.path.join(out, "level1_c1_t1.npy"), level1.astype(np.uint16))

xml = open(os.path.join(out, "dataset.xml")).read()
open(os.path.join(out, "n5.xml"), "w").write(xml.replace('format="bdv.hdf5"', 'format="bdv.n5"'))
rotated = xml.replace(
    "1.000000 0.000000 0.000000 10.000000 0.000000 1.000000 0.000000 20.000000",
    "0.000000 -1.000000 0.000000 10.000000 1.000000 0.000000 0.000000 20.000000",
)
assert rotated != xml
open(os.path.join(out, "rotated.xml"), "w").write(rotated)
