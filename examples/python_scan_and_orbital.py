#!/usr/bin/env python3
"""A real use of the Python module: a NIfTI scan and a Gaussian cube file,
each read, looked at in a few ways, and saved.

    pip install ./crates/python
    python examples/python_scan_and_orbital.py SCAN.nii.gz ORBITAL.cube [OUT_DIR]

Without arguments it uses two small files from the test fixtures (a
nibabel-written NIfTI volume and a cube file of an orbital), so that it
runs anywhere in the source tree.
"""

import sys
from pathlib import Path

import numpy as np
import volray

FIXTURES = Path(__file__).resolve().parents[1] / "crates/io/tests/fixtures"
scan = Path(sys.argv[1]) if len(sys.argv) > 1 else FIXTURES / "nifti/f32.nii"
orbital = Path(sys.argv[2]) if len(sys.argv) > 2 else FIXTURES / "cube/orbitals_angstrom.cube"
out = Path(sys.argv[3]) if len(sys.argv) > 3 else Path(".")
out.mkdir(parents=True, exist_ok=True)

# A scan: what the header says, then a turntable of maximum projections
# and one composited view, all from one renderer (the volume's bricks and
# value range are found once).
volume = volray.read(scan)
info = volume.info
print(f"{scan.name}: {info['format']}, {info['dims']}, {info['sample_type']}, "
      f"spacing {info['spacing']}, values {info['values']['min']:.3g}..{info['values']['max']:.3g}")
renderer = volray.Renderer(volume)
frames = [np.asarray(renderer.render(blend="mip", azimuth=a, size=240)) for a in range(0, 360, 45)]
np.save(out / "scan_mip_turntable.npy", np.stack(frames))
renderer.render(size=480, elevation=20, colormap="grey").save(out / "scan.png")

# A cube file: |ψ|² of an orbital, its positive and negative lobes apart
# (`volray.read` gives ψ; numpy does the rest), with the electron-density
# preset, as the command line's `--preset electron-density` draws them.
psi = volray.read(orbital)
density = volray.Volume(psi.data**2, spacing=psi.spacing, origin=psi.origin)
volray.render(density, preset="electron-density", size=480, azimuth=30).save(out / "orbital.png")
positive = np.where(psi.data > 0, psi.data, 0).astype(np.float32)
volray.render(positive, spacing=psi.spacing, origin=psi.origin, colormap="magma", size=480).save(out / "lobes.png")
print(f"wrote {out / 'scan.png'}, {out / 'orbital.png'}, {out / 'lobes.png'} and the turntable")
