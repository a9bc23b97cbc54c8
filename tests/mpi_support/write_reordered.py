"""Writes three volumes whose axes are not x, y, z in order and sense,
each by the tool its community uses, for tests/mpi.rs:

- perm.mrc: a CCP4/MRC map (mrcfile) with MAPC, MAPR, MAPS = 2, 1, 3
  (columns along y, rows along x), as crystallographic maps often are;
- las.nii: a NIfTI image (nibabel) whose first axis runs along -x (LAS);
- neg.nhdr + neg.raw: a detached NRRD (pynrrd) whose index axes run along
  -z, +x, +y;
- c.npy: numpy's own np.save of a[x, y, z], in C order (z fastest).

All are f32 and uncompressed, so that every rank maps them and reorders
its own box. The field is the same smooth, asymmetric one in world
space (two blobs and a ramp), so that a wrong axis shows in the image.

    python write_reordered.py OUT_DIR
"""
import sys
from pathlib import Path

import mrcfile
import nibabel
import nrrd
import numpy as np


def field(x, y, z):
    a = np.exp(-((x - 0.3) ** 2 + (y - 0.6) ** 2 + (z - 0.4) ** 2) / 0.02)
    b = 0.6 * np.exp(-((x - 0.7) ** 2 + (y - 0.3) ** 2 + (z - 0.7) ** 2) / 0.01)
    return (a + b + 0.15 * x * y).astype(np.float32)


def grid(n):
    return np.linspace(0.0, 1.0, n)


def main(out):
    out = Path(out)
    # MRC: data[section, row, column]; columns along y (MAPC 2), rows
    # along x (MAPR 1), sections along z (MAPS 3).
    nx, ny, nz = 30, 26, 22
    x, y, z = np.meshgrid(grid(nx), grid(ny), grid(nz), indexing="ij")
    f = field(x, y, z)  # f[i, j, k] at x_i, y_j, z_k
    with mrcfile.new(out / "perm.mrc", overwrite=True) as m:
        m.set_data(np.ascontiguousarray(f.transpose(2, 0, 1)))  # [z][x][y]
        m.header.mapc, m.header.mapr, m.header.maps = 2, 1, 3
        # Cell lengths along x, y, z: spacing 1.0, 1.2, 0.8 angstrom.
        m.header.mx, m.header.my, m.header.mz = nx, ny, nz
        m.header.cella = (nx * 1.0, ny * 1.2, nz * 0.8)

    # NIfTI, LAS: index axis 0 runs along -x.
    affine = np.diag([-1.1, 0.9, 1.3, 1.0])
    affine[:3, 3] = [40.0, -10.0, 5.0]
    # The array index i runs along -x: sample i is at x = 40 - 1.1 i.
    las = np.ascontiguousarray(f[::-1, :, :])
    img = nibabel.Nifti1Image(las, affine)
    img.set_qform(affine, code=1)
    img.set_sform(affine, code=1)
    nibabel.save(img, out / "las.nii")

    # NRRD: index axes along -z, +x, +y (data[a, b, c], a fastest).
    g = np.ascontiguousarray(f.transpose(2, 0, 1)[::-1, :, :])  # [z reversed][x][y]
    header = {
        "space": "right-anterior-superior",
        "space directions": np.array([[0.0, 0.0, -0.8], [1.0, 0.0, 0.0], [0.0, 1.2, 0.0]]),
        "space origin": np.array([0.0, 0.0, 20.0]),
        "encoding": "raw",
        "endian": "little",
    }
    nrrd.write(str(out / "neg.nhdr"), g, header, detached_header=True, index_order="F")

    np.save(out / "c.npy", f)


if __name__ == "__main__":
    main(sys.argv[1])
