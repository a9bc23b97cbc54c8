#!/usr/bin/env python3
"""VTK's fixed-point ray caster on a volume kept in its own sample type,
for the large-volume benchmark (docs/performance.md).

    python scripts/vtk_typed_bench.py DIR NAME:W [--n 5] [--threads 2] [--png OUT.png]

DIR/NAME.raw and its sidecar DIR/NAME.json (dims, dtype, min, max; as
`scripts/make_ct_phantom.py --sidecar` writes them) are rendered in a W x W
window exactly as the peer benchmark (../shared/peers, vtk_bench.py) renders
its workloads: orthographic along +x, +z up, the window fitting the y-z
extent, step 0.5 voxel, the peers' opacity and colour of
t = (v - min)/(max - min), one white headlight with ambient 0.1, diffuse
0.7, specular 0.2, power 10. The difference from vtk_bench.py is the
scalars: handed to VTK in the file's type (int16 stays VTK_SHORT, mapped
from the file without a copy) instead of as float32, so VTK holds what it
would hold for the user's file.

Prints one JSON line: warm-up (first frame, the mapper's own tables built)
and timed frames in seconds, their median (the mapper's GetTimeToDraw, as
vtk_bench.py reports), and the peak resident set of the process, in bytes.
Run it with the peers' venv (numpy and vtk), on an idle machine.
"""
import argparse
import json
import os
import resource
import statistics
import time

import numpy as np

OPACITY = [(0.0, 0.0), (0.05, 0.0), (0.95, 0.95), (1.0, 0.95)]
COLOR = [(0.0, (0.230, 0.299, 0.754)), (0.5, (0.865, 0.865, 0.865)), (1.0, (0.706, 0.016, 0.150))]
VTK_TYPES = {"float32": "VTK_FLOAT", "int16": "VTK_SHORT", "uint16": "VTK_UNSIGNED_SHORT",
             "int8": "VTK_SIGNED_CHAR", "uint8": "VTK_UNSIGNED_CHAR"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir")
    ap.add_argument("case", help="NAME:W")
    ap.add_argument("--n", type=int, default=5)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--png", default=None)
    args = ap.parse_args()
    name, w = args.case.split(":")
    w = int(w)
    with open(os.path.join(args.dir, name + ".json")) as f:
        side = json.load(f)
    nx, ny, nz = side["dims"]
    dtype = side.get("dtype", "float32")
    vmin, vmax = float(side["min"]), float(side["max"])

    import vtk
    from vtk.util import numpy_support

    vtk.vtkMultiThreader.SetGlobalMaximumNumberOfThreads(args.threads)
    vtk.vtkObject.GlobalWarningDisplayOff()

    # x fastest in the file, as vtkImageData expects: no reordering, and
    # read into memory once (np.fromfile), shared with VTK (deep=False).
    flat = np.fromfile(os.path.join(args.dir, name + ".raw"), dtype=np.dtype(dtype).newbyteorder("<"))
    assert flat.size == nx * ny * nz, "the raw file does not match the sidecar's dims"
    scalars = numpy_support.numpy_to_vtk(flat, deep=False, array_type=getattr(vtk, VTK_TYPES[dtype]))
    img = vtk.vtkImageData()
    img.SetDimensions(nx, ny, nz)
    img.SetSpacing(1.0, 1.0, 1.0)
    img.GetPointData().SetScalars(scalars)

    ctf = vtk.vtkColorTransferFunction()
    ctf.SetColorSpaceToRGB()
    for t, (r, g, b) in COLOR:
        ctf.AddRGBPoint(vmin + t * (vmax - vmin), r, g, b)
    otf = vtk.vtkPiecewiseFunction()
    for t, a in OPACITY:
        otf.AddPoint(vmin + t * (vmax - vmin), a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(1.0)
    prop.SetInterpolationTypeToLinear()
    prop.SetShade(1)
    prop.SetAmbient(0.1)
    prop.SetDiffuse(0.7)
    prop.SetSpecular(0.2)
    prop.SetSpecularPower(10.0)

    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetNumberOfThreads(args.threads)
    mapper.IntermixIntersectingGeometryOff()
    mapper.SetInputData(img)
    mapper.SetBlendModeToComposite()
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(0.5)
    mapper.SetImageSampleDistance(1.0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    ren = vtk.vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.AddVolume(volume)
    light = vtk.vtkLight()
    light.SetLightTypeToHeadlight()
    ren.AddLight(light)
    rw = vtk.vtkRenderWindow()
    rw.SetOffScreenRendering(1)
    rw.SetMultiSamples(0)
    rw.AddRenderer(ren)
    rw.SetSize(w, w)
    cx, cy, cz = (nx - 1) / 2.0, (ny - 1) / 2.0, (nz - 1) / 2.0
    cam = ren.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetFocalPoint(cx, cy, cz)
    cam.SetPosition(cx - 2.0 * nx, cy, cz)
    cam.SetViewUp(0.0, 0.0, 1.0)
    cam.SetParallelScale((nz - 1) / 2.0)
    ren.ResetCameraClippingRange()

    t0 = time.perf_counter()
    rw.Render()
    warm = time.perf_counter() - t0
    frames, walls = [], []
    for _ in range(args.n):
        t0 = time.perf_counter()
        rw.Render()
        walls.append(time.perf_counter() - t0)
        frames.append(mapper.GetTimeToDraw())
    if args.png:
        w2i = vtk.vtkWindowToImageFilter()
        w2i.SetInput(rw)
        w2i.SetInputBufferTypeToRGB()
        w2i.ReadFrontBufferOff()
        w2i.Update()
        wr = vtk.vtkPNGWriter()
        wr.SetFileName(args.png)
        wr.SetInputConnection(w2i.GetOutputPort())
        wr.Write()
    print(json.dumps({
        "case": args.case, "dims": [nx, ny, nz], "dtype": dtype, "threads": args.threads,
        "warmup_s": warm, "mapper_times_s": frames, "wall_times_s": walls,
        "median_s": statistics.median(frames),
        "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        "vtk_version": vtk.vtkVersion.GetVTKVersion(),
    }))


if __name__ == "__main__":
    main()
