"""Writes the VTKHDF files crates/io/tests/vtkhdf.rs reads, with VTK's own
vtkHDFWriter, and a few broken ones edited with h5py.

Usage: python write_files.py OUT_DIR

image.vtkhdf   vtkImageData, extent (1..4, 0..2, 2..6), so 4 x 3 x 5 points,
               spacing (0.5, 2, 1.5), origin (10, 20, 30):
               PointData "density" float32 v = x + 10 y + 100 z (x, y, z
               counted from the extent's start; the active scalars),
               "twice" int16 2 v, "vector" float64 3 components
               (v, -v, 1000 + v); CellData "cells" float64 holding the
               cell index i + 10 j + 100 k over 3 x 2 x 4 cells
image.h5       the same file named .h5 (told by its /VTKHDF group)
grid.vtkhdf    a vtkUnstructuredGrid (Type UnstructuredGrid)
rotated.vtkhdf image data with a rotating direction matrix
short.vtkhdf   image.vtkhdf with "density" cut to 4 z slices (h5py)
"""

import os
import shutil
import sys

import h5py
import numpy as np
import vtk
from vtk.util import numpy_support as ns

out = sys.argv[1]


def image(direction=None):
    img = vtk.vtkImageData()
    img.SetExtent(1, 4, 0, 2, 2, 6)
    img.SetSpacing(0.5, 2.0, 1.5)
    img.SetOrigin(10.0, 20.0, 30.0)
    if direction is not None:
        img.SetDirectionMatrix(*direction)
    z, y, x = np.indices((5, 3, 4))
    v = (x + 10 * y + 100 * z).astype(np.float32).ravel()
    a = ns.numpy_to_vtk(v, deep=1)
    a.SetName("density")
    img.GetPointData().SetScalars(a)
    b = ns.numpy_to_vtk((2 * v).astype(np.int16), deep=1)
    b.SetName("twice")
    img.GetPointData().AddArray(b)
    vec = np.stack([v, -v, 1000 + v], axis=1).astype(np.float64)
    c = ns.numpy_to_vtk(vec, deep=1)
    c.SetName("vector")
    img.GetPointData().AddArray(c)
    k, j, i = np.indices((4, 2, 3))
    cells = ns.numpy_to_vtk((i + 10 * j + 100 * k).astype(np.float64).ravel(), deep=1)
    cells.SetName("cells")
    img.GetCellData().AddArray(cells)
    return img


def write(data, name):
    w = vtk.vtkHDFWriter()
    w.SetInputData(data)
    w.SetFileName(os.path.join(out, name))
    assert w.Write() == 1, name


write(image(), "image.vtkhdf")
shutil.copy(os.path.join(out, "image.vtkhdf"), os.path.join(out, "image.h5"))

# VTK's own reader, the oracle for where the points lie.
r = vtk.vtkHDFReader()
r.SetFileName(os.path.join(out, "image.vtkhdf"))
r.Update()
back = r.GetOutput()
assert back.GetExtent() == (1, 4, 0, 2, 2, 6), back.GetExtent()
assert back.GetPoint(0) == (10.5, 20.0, 33.0), back.GetPoint(0)
assert back.GetPointData().GetScalars().GetName() == "density"

grid = vtk.vtkUnstructuredGrid()
pts = vtk.vtkPoints()
for p in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]:
    pts.InsertNextPoint(*p)
grid.SetPoints(pts)
grid.InsertNextCell(vtk.VTK_TETRA, 4, [0, 1, 2, 3])
write(grid, "grid.vtkhdf")

write(image((0, -1, 0, 1, 0, 0, 0, 0, 1)), "rotated.vtkhdf")

shutil.copy(os.path.join(out, "image.vtkhdf"), os.path.join(out, "short.vtkhdf"))
with h5py.File(os.path.join(out, "short.vtkhdf"), "a") as f:
    data = f["VTKHDF/PointData/density"][:4]
    attrs = dict(f["VTKHDF/PointData/density"].attrs)
    del f["VTKHDF/PointData/density"]
    d = f.create_dataset("VTKHDF/PointData/density", data=data)
    for k, v in attrs.items():
        d.attrs[k] = v
