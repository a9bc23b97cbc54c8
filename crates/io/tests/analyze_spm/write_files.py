"""Writes the Analyze 7.5 images crates/io/tests/analyze_spm.rs reads,
each with SPM's orientation in a .mat beside the header, and the affine
nibabel gives each (nibabel.load picks Spm2AnalyzeImage for an Analyze
header, which reads the .mat), the test's oracle.

Usage: python write_files.py OUT_DIR

Every image is 4 x 3 x 5 (i, j, k) int16 holding v = i + 10 j + 100 k.
Files (the .hdr/.img pairs and their .mat):

    coronal.*    nibabel's Spm2AnalyzeImage.to_filename with a permuting
                 affine (j to z, k to -y, i to x, not flipped): nibabel
                 writes a level-4 .mat holding "M" and "mat"
    m_only.*     the header of coronal, and a .mat by scipy.io.savemat
                 (level 5) holding only "M" (no flip: nibabel flips x)
    pages.*      a compressed level-5 .mat whose "mat" is 4 x 4 x 2 (the
                 first page is used)
    empty.*      an empty .mat: ignored
    neither.*    a .mat holding only "other": nibabel raises, volray
                 refuses
    singular.*   a .mat whose "mat" is all zeros: refused

affines.txt: one line per readable image, its name and nibabel's 3 x 4
affine (rows), 12 numbers.
"""

import os
import shutil
import sys
import warnings

import nibabel as nib
import numpy as np
import scipy.io as sio

out = sys.argv[1]
k, j, i = np.indices((5, 3, 4))
v = np.ascontiguousarray((i + 10 * j + 100 * k).astype(np.int16).transpose(2, 1, 0))

coronal = np.array(
    [[1.5, 0, 0, -10], [0, 0, -0.75, 20], [0, 2.0, 0, -5], [0, 0, 0, 1]], float
)
img = nib.Spm2AnalyzeImage(v, coronal)
img.to_filename(os.path.join(out, "coronal.hdr"))
assert os.path.getsize(os.path.join(out, "coronal.mat")) > 0


def copy_pair(name):
    for ext in ("hdr", "img"):
        shutil.copy(os.path.join(out, f"coronal.{ext}"), os.path.join(out, f"{name}.{ext}"))


M = np.array([[2.0, 0, 0, 3], [0, 1.0, 0, -4], [0, 0, 0.5, 6], [0, 0, 0, 1]])
copy_pair("m_only")
sio.savemat(os.path.join(out, "m_only.mat"), {"M": M})

copy_pair("pages")
pages = np.stack([coronal, np.eye(4)], axis=2)
sio.savemat(os.path.join(out, "pages.mat"), {"mat": pages}, do_compression=True)

copy_pair("empty")
open(os.path.join(out, "empty.mat"), "wb").close()

copy_pair("neither")
sio.savemat(os.path.join(out, "neither.mat"), {"other": np.eye(4)})

copy_pair("singular")
sio.savemat(os.path.join(out, "singular.mat"), {"mat": np.zeros((4, 4))})

with open(os.path.join(out, "affines.txt"), "w") as f:
    for name in ("coronal", "m_only", "pages", "empty"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            loaded = nib.load(os.path.join(out, f"{name}.hdr"))
        assert isinstance(loaded, nib.Spm2AnalyzeImage), type(loaded)
        assert np.array_equal(np.asarray(loaded.dataobj), v), name
        numbers = " ".join(repr(float(x)) for x in loaded.affine[:3].ravel())
        f.write(f"{name} {numbers}\n")
try:
    nib.load(os.path.join(out, "neither.hdr"))
    raise SystemExit("nibabel read neither.hdr")
except ValueError:
    pass
