"""Renders the README gallery's pictures of several volumes in one picture
(docs/scenes.md): three fluorescence channels of synthetic cells, a CT
phantom with its segmentation over it, and a time series.

    target/pyenv/bin/python docs/gallery/scenes.py docs/gallery [--volray target/release/volray] [--no-time]

Needs numpy, nibabel and the `volray` module (`maturin develop`, as
tests/python.rs does); the time series is written as a 4-D NIfTI file and
rendered by the command line's `--frames all` (the `volray` binary given,
default target/release/volray). The CT phantom and its labels come from
scripts/make_ct_phantom.py's geometry, so the labels fit the scan exactly.
"""

import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import volray

ROOT = Path(__file__).resolve().parents[2]


def cells(n=112, count=14, seed=3):
    """Three channels (c, z, y, x) of synthetic cells: nuclei, membranes
    around them, and filaments between some of them."""
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, n, dtype=np.float32)
    z, y, x = np.meshgrid(u, u, u, indexing="ij")
    nuclei = np.zeros((n, n, n), np.float32)
    membranes = np.zeros_like(nuclei)
    centres = rng.uniform(0.12, 0.88, size=(count, 3))
    radii = rng.uniform(0.07, 0.11, size=count)
    for (cx, cy, cz), r in zip(centres, radii):
        d = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
        nuclei = np.maximum(nuclei, np.exp(-((d / (0.45 * r)) ** 2)))
        membranes = np.maximum(membranes, np.exp(-(((d - r) / 0.012) ** 2)))
    filaments = np.zeros_like(nuclei)
    for _ in range(9):
        a, b = centres[rng.choice(count, 2, replace=False)]
        bend = rng.normal(size=3)
        for t in np.linspace(0.0, 1.0, 120):
            p = a + t * (b - a) + 0.05 * np.sin(np.pi * t) * bend
            d2 = (x - p[0]) ** 2 + (y - p[1]) ** 2 + (z - p[2]) ** 2
            filaments = np.maximum(filaments, np.exp(-d2 / 0.015**2))
    return np.stack([nuclei, membranes, filaments])


def phantom(n=160):
    """The CT phantom (HU, z, y, x) and its labels: ventricles 1, eyes 2,
    lesions 3, jaw bone 4."""
    spec = importlib.util.spec_from_file_location("phantom", ROOT / "scripts/make_ct_phantom.py")
    ph = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ph)
    hu = ph.slab(n, n, 0, n, np.random.default_rng(1))
    u = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    z, y, x = np.meshgrid(u, u, u, indexing="ij")
    inside = lambda c, a: ph.ellipsoid(x, y, z, c, a) <= 1  # noqa: E731
    labels = np.zeros(hu.shape, np.uint8)
    for side in (-1, 1):
        labels[inside((side * 0.12, 0.05, 0.12), (0.08, 0.25, 0.12))] = 1
        labels[inside((side * 0.3, -0.72, -0.25), (0.11, 0.11, 0.11))] = 2
    labels[inside((0.2, 0.3, 0.35), (0.06, 0.05, 0.07))] = 3
    labels[inside((-0.25, -0.2, -0.1), (0.04, 0.04, 0.04))] = 3
    labels[inside((0.0, -0.45, -0.7), (0.45, 0.3, 0.1))] = 4
    return hu, labels


def dividing(n=64, frames=12):
    """A cell dividing: two blobs drawing apart along y over `frames` time
    points, (x, y, z, t) as NIfTI stores them."""
    u = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    x, y, z = np.meshgrid(u, u, u, indexing="ij")
    out = np.zeros((n, n, n, frames), np.float32)
    for t in range(frames):
        s = 0.5 * t / (frames - 1)
        for sign in (-1, 1):
            d2 = (x / 0.8) ** 2 + (y - sign * s) ** 2 + (z / 0.8) ** 2
            out[..., t] = np.maximum(out[..., t], np.exp(-d2 / 0.12))
    return out


def main():
    out = Path(sys.argv[1])
    binary = ROOT / "target/release/volray"
    if "--volray" in sys.argv:
        binary = Path(sys.argv[sys.argv.index("--volray") + 1])
    out.mkdir(parents=True, exist_ok=True)

    stack = cells()
    frame = volray.render(
        stack,
        channel_axis=0,
        order="zyx",
        looks=[{"opacity": (0.0, 0.9)}, {"opacity": (0.0, 0.2)}, {"opacity": (0.0, 0.25)}],
        size=360,
        azimuth=35,
        elevation=25,
    )
    frame.save(str(out / "channels.png"))

    hu, labels = phantom()
    soft = {
        "domain": [-1000, 1500],
        "opacity": [[0, 0], [0.38, 0], [0.42, 0.003], [0.6, 0.004], [0.7, 0.03], [1, 0.05]],
        "color": [[0, 0.9, 0.7, 0.6], [0.42, 0.9, 0.75, 0.65], [0.72, 1, 1, 0.95], [1, 1, 1, 1]],
    }
    tf = Path(tempfile.mkdtemp()) / "soft.json"
    tf.write_text(__import__("json").dumps(soft))
    frame = volray.render(
        [hu, labels],
        order="zyx",
        looks=[{"tf": str(tf)}, {"labels": True}],
        size=360,
        azimuth=-60,
        elevation=15,
    )
    frame.save(str(out / "overlay.png"))

    if "--no-time" in sys.argv:  # the two pictures only, no volray binary
        return
    import nibabel

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "dividing.nii.gz"
        nibabel.save(nibabel.Nifti1Image(dividing(), np.eye(4)), str(path))
        subprocess.run(
            [str(binary), "render", str(path), "--frames", "all", "--colormap", "magma",
             "--opacity", "0,0.6", "--size", "200", "--azimuth", "20", "--elevation", "20",
             "-o", str(out / "dividing.gif")],
            check=True,
        )


if __name__ == "__main__":
    main()
