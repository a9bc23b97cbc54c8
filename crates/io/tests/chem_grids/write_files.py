"""Writes the OpenDX, XSF/BXSF and gOpenMol plt fixtures of
crates/io/tests/chem_grids.rs into argv[1], each by its field's own tool
where one writes it, and what that tool (or its reader) gives back, as
JSON beside each file, for the test to compare with.

- OpenDX: GridDataFormats' Grid.export (as MDAnalysis writes densities),
  and an APBS-style file by hand (APBS's header and 3 values per line).
- XSF: ase.io.write(..., format="xsf", data=...); read back with
  ase.io.read(..., read_data=True) for the oracle. Several grids and a
  BXSF band grid by hand after the XSF specification.
- plt: written by the documented layout (gOpenMol, CSC 2003) in both byte
  orders, read back with GridDataFormats' gOpenMol.Plt as the oracle.
"""
import gzip
import json
import pathlib
import struct
import sys

import numpy as np
from gridData import Grid
from gridData.gOpenMol import Plt
import ase
import ase.io

out = pathlib.Path(sys.argv[1])


def ramp(shape):
    i, j, k = np.indices(shape)
    return (i + 10 * j + 100 * k).astype(np.float64)


def dump(name, **fields):
    (out / (name + ".json")).write_text(json.dumps(fields))


# ---- OpenDX ----
a = ramp((4, 3, 5))
g = Grid(a, origin=[1.0, -2.0, 0.5], delta=[0.5, 0.25, 2.0])
g.export(str(out / "ramp.dx"))
back = Grid(str(out / "ramp.dx"))
dump("ramp.dx", shape=list(back.grid.shape), origin=back.origin.tolist(),
     delta=np.diag(back.delta).tolist(), values=back.grid.ravel(order="F").tolist())
(out / "ramp_dx.gz").write_bytes(gzip.compress((out / "ramp.dx").read_bytes()))

lines = [
    "# Data from APBS 3.4.1",
    "# ",
    "# POTENTIAL (kT/e)",
    "# ",
    "object 1 class gridpositions counts 3 4 2",
    "origin -1.500000e+00 -2.000000e+00 -5.000000e-01",
    "delta 1.500000e+00 0.000000e+00 0.000000e+00",
    "delta 0.000000e+00 1.000000e+00 0.000000e+00",
    "delta 0.000000e+00 0.000000e+00 1.000000e+00",
    "object 2 class gridconnections counts 3 4 2",
    "object 3 class array type double rank 0 items 24 data follows",
]
b = ramp((3, 4, 2)) * -0.5
flat = b.ravel(order="C")  # z fastest
for n in range(0, len(flat), 3):
    lines.append(" ".join("%e" % v for v in flat[n:n + 3]))
lines += [
    'attribute "dep" string "positions"',
    'object "regular positions regular connections" class field',
    'component "positions" value 1',
    'component "connections" value 2',
    'component "data" value 3',
]
(out / "apbs.dx").write_text("\n".join(lines) + "\n")
dump("apbs.dx", shape=[3, 4, 2], values=b.ravel(order="F").tolist())

# ---- XSF ----
def read_xsf(path):
    """ase's reader: the last grid, its origin and spanning vectors."""
    from ase.io.xsf import read_xsf as ase_read_xsf
    with open(path) as f:
        got = ase_read_xsf(f, read_data=True)
    return got[0], got[1], got[2]


atoms = ase.Atoms("H2", positions=[[0, 0, 0], [0.7, 0, 0]],
                  cell=[[3, 0, 0], [0, 4, 0], [0, 0, 5]], pbc=True)
c = ramp((4, 3, 5)) + 0.25
ase.io.write(str(out / "ramp.xsf"), atoms, format="xsf", data=c)
data, origin, spans = read_xsf(out / "ramp.xsf")
dump("ramp.xsf", shape=list(data.shape), origin=origin.tolist(), spans=spans.tolist(),
     values=data.ravel(order="F").tolist())

hexa = ase.Atoms("C", positions=[[0, 0, 0]],
                 cell=[[2, 0, 0], [-1, 3 ** 0.5, 0], [0, 0, 3]], pbc=True)
# A periodic grid whose last point repeats the first: f(i, j, k) of the
# fractional position, with its own period.
n = (7, 7, 5)
i, j, k = np.indices(n)
f = np.cos(2 * np.pi * i / (n[0] - 1)) + np.sin(2 * np.pi * j / (n[1] - 1)) + k % (n[2] - 1)
ase.io.write(str(out / "hexagonal.xsf"), hexa, format="xsf", data=f,
             origin=[0, 0, 0], span_vectors=hexa.cell[:])
data, origin, spans = read_xsf(out / "hexagonal.xsf")
dump("hexagonal.xsf", shape=list(data.shape), origin=origin.tolist(), spans=spans.tolist(),
     values=data.ravel(order="F").tolist())


def grid_text(name, arr, origin, spans):
    rows = ["  BEGIN_DATAGRID_3D_" + name, "  %d %d %d" % arr.shape,
            "  %f %f %f" % tuple(origin)]
    rows += ["  %f %f %f" % tuple(s) for s in spans]
    flat = arr.ravel(order="F")
    rows += ["   " + " ".join("%g" % v for v in flat[n:n + 6]) for n in range(0, len(flat), 6)]
    rows.append("  END_DATAGRID_3D")
    return rows


two = ["# two grids in one block, after the XSF specification", "CRYSTAL", "PRIMVEC",
       " 2.0 0.0 0.0", " 0.0 3.0 0.0", " 0.0 0.0 4.0", "PRIMCOORD", " 1 1", " 6 0.0 0.0 0.0",
       "BEGIN_BLOCK_DATAGRID_3D", " pp.x output"]
two += grid_text("density", ramp((3, 4, 5)), [0, 0, 0], [[2, 0, 0], [0, 3, 0], [0, 0, 4]])
two += grid_text("potential", -ramp((3, 4, 5)), [0, 0, 0], [[2, 0, 0], [0, 3, 0], [0, 0, 4]])
two.append("END_BLOCK_DATAGRID_3D")
(out / "two.xsf").write_text("\n".join(two) + "\n")

bands = [ramp((3, 3, 4)) * 0.1, ramp((3, 3, 4)) * 0.1 + 5.0]
bx = ["BEGIN_INFO", "  Fermi Energy: 4.5", "END_INFO", "BEGIN_BLOCK_BANDGRID_3D",
      " band_energies", " BEGIN_BANDGRID_3D_BANDS", "  2", "  3 3 4",
      "  0.0 0.0 0.0", "  1.0 0.0 0.0", "  0.0 1.0 0.0", "  0.0 0.0 1.5"]
for nb, arr in enumerate(bands):
    bx.append(" BAND: %d" % (nb + 1))
    flat = arr.ravel(order="F")
    bx += ["  " + " ".join("%g" % v for v in flat[n:n + 6]) for n in range(0, len(flat), 6)]
bx += [" END_BANDGRID_3D", "END_BLOCK_BANDGRID_3D"]
(out / "fermi.bxsf").write_text("\n".join(bx) + "\n")

# ---- gOpenMol plt ----
d = ramp((4, 3, 5)).astype(np.float32) - 7.5  # d[x, y, z]
for name, order in [("little.plt", "<"), ("big.plt", ">")]:
    nx, ny, nz = d.shape
    head = struct.pack(order + "5i6f", 3, 200, nz, ny, nx, -1.0, 7.0, 0.0, 1.0, 2.0, 3.5)
    body = d.ravel(order="F").astype(order + "f4").tobytes()  # x fastest
    (out / name).write_bytes(head + body)
    p = Plt(str(out / name))
    h = {k: (float(v) if isinstance(v, float) else v) for k, v in p.header.items()
         if k in ("rank", "surface", "nx", "ny", "nz", "xmin", "xmax", "ymin", "ymax", "zmin", "zmax")}
    dump(name, shape=list(p.array.shape), header=h, values=p.array.ravel(order="F").tolist())
