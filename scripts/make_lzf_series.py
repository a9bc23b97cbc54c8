"""Writes the series issue 41 measures box-by-box HDF5 reading with: four
frames of 512³ float32, a dataset s(t, z, y, x) (an `axes` attribute
"tzyx") in LZF chunks of (1, 64, 64, 64), 2 GiB of samples. Written slab by
slab (64 z planes at a time), so that writing it takes about 300 MB.

Each frame is three Gaussian blobs over a faint ramp along z, the blobs
moving with t, so that a frame's picture shows which frame was read.

    target/pyenv/bin/python scripts/make_lzf_series.py [OUT]
        (OUT defaults to /tmp/volray_lzf_series.h5; an existing OUT is kept)
    /usr/bin/time -v target/release/volray render OUT:/s --frame 2 \\
        --max-memory 256M -o x.png

Not committed, not in the repository: 2 GiB is made on demand and cached
outside it.
"""

import sys
from pathlib import Path

import h5py
import numpy as np

N, T, SLAB = 512, 4, 64
out = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/volray_lzf_series.h5")
if out.exists():
    print(f"{out} exists: kept")
    sys.exit(0)

tmp = out.with_suffix(".partial")
y, x = np.meshgrid(np.arange(N, dtype=np.float32), np.arange(N, dtype=np.float32),
                   indexing="ij")
with h5py.File(tmp, "w") as f:
    d = f.create_dataset("s", shape=(T, N, N, N), dtype="<f4", chunks=(1, SLAB, SLAB, SLAB),
                         compression="lzf")
    d.attrs["axes"] = "tzyx"
    for t in range(T):
        blobs = [((140 + 60 * t, 200, 180), 60.0, 1000.0),
                 ((330, 300 - 40 * t, 320), 80.0, 700.0),
                 ((260, 260, 120 + 50 * t), 45.0, 1200.0)]
        for z0 in range(0, N, SLAB):
            z = np.arange(z0, z0 + SLAB, dtype=np.float32)[:, None, None]
            slab = np.broadcast_to(0.2 * z, (SLAB, N, N)).astype(np.float32)
            for (cx, cy, cz), r, a in blobs:
                d2 = (x - cx) ** 2 + (y - cy) ** 2
                slab += a * np.exp(-(d2[None] + (z - cz) ** 2) / (2 * r * r))
            d[t, z0:z0 + SLAB] = slab
        print(f"frame {t} written", flush=True)
tmp.rename(out)
print(f"{out}: {out.stat().st_size / 2**30:.2f} GiB")
