"""Files of 2 time points x 3 channels written by the independent tools,
for tests/axes.rs: the same volumes in every file, the sample at
(x, y, z) of time point t, channel c holding x + 10 y + 100 z + 1000 c
+ 10000 t, (x, y, z) of (6, 5, 4).

- hyper.tif: an ImageJ hyperstack (tifffile, axes TZCYX), uint16;
- ome.ome.tif: an OME-TIFF (tifffile, axes TCZYX), uint16;
- axes.h5: /tczyx and /ctzyx, dimension labels (h5py's dims[i].label);
  /zyxc, an axes attribute "zyxc" (channels fastest, no time);
- five.nii: a 5-D NIfTI (nibabel), shape (x, y, z, t, c);
- vector.nrrd: channels along a first axis of kind "vector" (pynrrd),
  time point 0; time.nrrd: the time points of channel 1 along a last
  axis of kind "time".
"""

import sys

import h5py
import nibabel
import nrrd
import numpy as np
import tifffile

out = sys.argv[1]
T, C, Z, Y, X = 2, 3, 4, 5, 6
t, c, z, y, x = np.meshgrid(*(np.arange(n) for n in (T, C, Z, Y, X)), indexing="ij")
a = (x + 10 * y + 100 * z + 1000 * c + 10000 * t).astype("<u2")  # t, c, z, y, x

tifffile.imwrite(out + "/hyper.tif", a.transpose(0, 2, 1, 3, 4), imagej=True,
                 metadata={"axes": "TZCYX"})
tifffile.imwrite(out + "/ome.ome.tif", a, ome=True, metadata={"axes": "TCZYX"})

with h5py.File(out + "/axes.h5", "w") as f:
    for name, order in [("tczyx", (0, 1, 2, 3, 4)), ("ctzyx", (1, 0, 2, 3, 4))]:
        d = f.create_dataset(name, data=a.transpose(order))
        for i, label in enumerate(name):
            d.dims[i].label = label
    d = f.create_dataset("zyxc", data=a[0].transpose(1, 2, 3, 0))
    d.attrs["axes"] = "zyxc"

nibabel.save(nibabel.Nifti1Image(a.transpose(4, 3, 2, 0, 1), np.eye(4)), out + "/five.nii")

# pynrrd writes Fortran order by default: the first axis fastest.
nrrd.write(out + "/vector.nrrd", np.asfortranarray(a[0].transpose(0, 3, 2, 1)),
           {"kinds": ["vector", "domain", "domain", "domain"]})
nrrd.write(out + "/time.nrrd", np.asfortranarray(a[:, 1].transpose(3, 2, 1, 0)),
           {"kinds": ["domain", "domain", "domain", "time"]})
