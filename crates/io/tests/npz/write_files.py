"""Writes the .npz archives of crates/io/tests/npz.rs into argv[1] with
numpy's own numpy.savez (stored members) and numpy.savez_compressed
(deflated members)."""
import pathlib
import sys

import numpy as np

out = pathlib.Path(sys.argv[1])
i, j, k = np.indices((4, 3, 5))
ramp = (i + 10 * j + 100 * k).astype(np.float32)  # a[x, y, z]
np.savez(out / "one.npz", ramp)
np.savez(out / "named.npz", density=ramp, potential=(-ramp).astype(np.int16),
         flat=np.zeros((4, 3), np.float32))
np.savez_compressed(out / "compressed.npz", ramp.astype(np.float64) + 0.5,
                    np.asfortranarray(ramp.astype(np.uint16)))
np.savez_compressed(out / "zeros.npz", big=np.zeros((64, 64, 64), np.float32))
