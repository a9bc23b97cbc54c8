"""Writes the GIPL images of crates/io/tests/gipl.rs into argv[1] with
SimpleITK (ITK's GiplImageIO), and what SimpleITK reads back from each
(values x fastest, spacing, origin) as JSON beside it."""
import json
import pathlib
import sys

import numpy as np
import SimpleITK as sitk

out = pathlib.Path(sys.argv[1])
k, j, i = np.indices((5, 3, 4))  # SimpleITK arrays are a[z, y, x]
ramp = i + 10 * j + 100 * k
for name, array in [
    ("i16.gipl", (ramp - 1000).astype(np.int16)),
    ("u8.gipl", (ramp % 256).astype(np.uint8)),
    ("f32.gipl", ramp.astype(np.float32) + 0.25),
    ("f64.gipl.gz", ramp.astype(np.float64) - 0.125),
    ("u16.gipl", (ramp + 60000).astype(np.uint16)),
]:
    image = sitk.GetImageFromArray(array)
    image.SetSpacing((0.5, 0.25, 2.0))
    image.SetOrigin((1.0, -2.0, 3.5))
    sitk.WriteImage(image, str(out / name))
    back = sitk.ReadImage(str(out / name))
    (out / (name + ".json")).write_text(json.dumps({
        "values": sitk.GetArrayFromImage(back).ravel().astype(float).tolist(),
        "spacing": list(back.GetSpacing()),
        "origin": list(back.GetOrigin()),
        "size": list(back.GetSize()),
    }))
