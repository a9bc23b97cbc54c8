#!/usr/bin/env python3
"""Frames per second from Python against `volray bench` on the same
workloads, and against pyvista's fixed-point mapper where pyvista imports.

    target/pyenv/bin/python scripts/python_bench.py            # after cargo test --test python
    target/pyenv/bin/python scripts/python_bench.py --rounds 5 --size 480

Each workload is timed as `volray bench` times it: one warm-up frame,
then FRAMES frames each turned a further half degree about the up axis
(so no frame reuses view-dependent work), the median reported. The
command line and Python alternate ROUNDS times in one run, and the ratio
of their medians is the overhead of the module (argument parsing, the
GIL released and taken back, the frame handed to numpy). pyvista, when
its import works (it needs VTK and an off-screen OpenGL context), renders
the same array with add_volume(mapper="fixed_point") off screen, with
the same work: a linear opacity ramp over the value range (volray's
`opacity=(0, 1)`), viridis, shading on, one sample per voxel along each
ray and one ray per pixel (automatic sample distances off).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import volray

REPO = Path(__file__).resolve().parents[1]
WORKLOADS = ["hydrogen:6,3,2,grid=100", "fractal:129", "marschner-lobb:129"]


def cli_median(binary, spec, size, frames):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        subprocess.run(
            [binary, "bench", spec, "--size", str(size), "--frames", str(frames), "--json", str(out)]
            + ["--opacity", "0,1", "--colormap", "viridis"],
            check=True,
            capture_output=True,
        )
        return json.loads(out.read_text())[0]["median_s"]


def python_medians(renderer, size, frames):
    """Medians of the frame alone and of the frame made a numpy array."""
    look = dict(opacity=(0, 1), colormap="viridis")
    renderer.render(size=size, azimuth=0.0, **look)  # warm-up
    alone, with_numpy = [], []
    for i in range(1, frames + 1):
        start = time.perf_counter()
        frame = renderer.render(size=size, azimuth=0.5 * i, **look)
        rendered = time.perf_counter()
        np.asarray(frame)
        alone.append(rendered - start)
        with_numpy.append(time.perf_counter() - start)
    return statistics.median(alone), statistics.median(with_numpy)


def pyvista_median(array, spacing, size, frames):
    try:
        import pyvista as pv
    except ImportError:
        return None
    grid = pv.ImageData(dimensions=array.shape, spacing=spacing)
    grid.point_data["values"] = array.ravel(order="F")
    plotter = pv.Plotter(off_screen=True, window_size=(size, size))
    actor = plotter.add_volume(
        grid, scalars="values", mapper="fixed_point", cmap="viridis", opacity="linear", shade=True
    )
    # The same work as volray's: one sample per voxel along each ray, one
    # ray per pixel, whatever the frame rate.
    actor.mapper.SetAutoAdjustSampleDistances(False)
    actor.mapper.SetSampleDistance(min(spacing))
    actor.mapper.SetImageSampleDistance(1.0)
    plotter.show(auto_close=False)  # warm-up
    times = []
    for _ in range(frames):
        plotter.camera.azimuth += 0.5
        start = time.perf_counter()
        plotter.render()
        plotter.screenshot(return_img=True)
        times.append(time.perf_counter() - start)
    plotter.close()
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=480)
    parser.add_argument("--frames", type=int, default=9)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--binary", default=str(REPO / "target/release/volray"))
    parser.add_argument("--workloads", nargs="*", default=WORKLOADS)
    args = parser.parse_args()
    if not os.path.exists(args.binary):
        sys.exit(f"{args.binary}: build it first (cargo build --release)")
    print(
        f"{'workload':26} {'cli ms':>8} {'python ms':>10} {'ratio':>6} "
        f"{'+numpy ms':>10} {'ratio':>6} {'pyvista ms':>11}"
    )
    for spec in args.workloads:
        volume = volray.read(spec)
        renderer = volray.Renderer(volume)
        cli, alone, with_numpy = [], [], []
        for _ in range(args.rounds):
            cli.append(cli_median(args.binary, spec, args.size, args.frames))
            a, n = python_medians(renderer, args.size, args.frames)
            alone.append(a)
            with_numpy.append(n)
        c = statistics.median(cli)
        a, n = statistics.median(alone), statistics.median(with_numpy)
        pv = pyvista_median(volume.data, volume.spacing, args.size, args.frames)
        pv_text = f"{pv * 1e3:11.1f}" if pv is not None else f"{'n/a':>11}"
        print(
            f"{spec:26} {c * 1e3:8.1f} {a * 1e3:10.1f} {a / c:6.3f} "
            f"{n * 1e3:10.1f} {n / c:6.3f} {pv_text}",
            flush=True,
        )


if __name__ == "__main__":
    main()
