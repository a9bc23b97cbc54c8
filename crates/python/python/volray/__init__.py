"""volray: volume rendering by ray casting, numpy in, image out.

    >>> import numpy as np, volray
    >>> x, y, z = np.mgrid[-1:1:64j, -1:1:64j, -1:1:64j]
    >>> ball = np.exp(-4 * (x * x + y * y + z * z)).astype(np.float32)
    >>> frame = volray.render(ball, azimuth=30, size=256)
    >>> frame.save("ball.png")        # or np.asarray(frame), or show it in Jupyter

Axes: an array is ``a[x, y, z]``, as in volray's own ``.npy`` files,
nibabel, pyvista and yt; give ``order="zyx"`` for ``a[z, y, x]`` (numpy
images, SimpleITK, napari). ``spacing``, ``origin`` and every world
coordinate (``view``, ``look_at``, ``crop``, ``clip``) are ``(x, y, z)``.
An array whose memory has x fastest (Fortran order, or C order with
``order="zyx"``) of uint8, int8, uint16, int16 or float32 is rendered
without a copy; other types become float32. Arrays volray returns
(``Volume.data``, ``hydrogen``, ``fractal``) are ``a[x, y, z]``; a volume
:func:`read` from a file is read-only (``.copy()`` it to change it). A
:class:`Renderer` renders an array as it is at each frame: change it in
place between frames, not while one renders.

A chunked file (Zarr, OME-Zarr) is read lazily: ``volray.read`` reads its
metadata only (``Volume.lazy``), ``Volume.data`` reads the level when
first asked for, and ``volray.render(volume, level="auto")`` reads the
level each view needs, piece by piece where it would not fit
``max_memory`` whole.

Several volumes in one picture: ``volray.render([a, b], looks=[{...},
{...}], mix="composite")`` renders them in one ray march, each occluding
the others where it lies in front; each look is a dict of the per-volume
keywords (``tf``, ``colormap``, ``range``, ``labels``, ...) with
``color``, ``opacity_scale`` and ``visible``. ``channel_axis=`` splits a
4-D array into channels, coloured magenta, green, cyan, yellow, ...
:class:`Scene` keeps the volumes prepared across frames.

In Jupyter, ``volray.view(volume, **options)`` shows the interactive
viewer in the notebook (an anywidget; ``pip install anywidget``): its
frames travel over the kernel's connection, and ``w.camera`` and
``w.transfer_function`` read the view back for :func:`render`.

Every keyword of :func:`render` is the ``volray render`` flag of the same
name (``look_at`` is ``--look-at``; ``shading=False`` is ``--no-shading``)
with the same default and the same pixels. Bad input raises ``ValueError``
(``TypeError`` for a wrong type, ``OSError`` when a file cannot be read or
written) with the command line's one-line message; Ctrl-C stops a render.
"""

from ._volray import (
    COLORMAPS,
    PRESETS,
    Camera,
    Frame,
    Renderer,
    Scene,
    TransferFunction,
    Volume,
    __version__,
    fractal,
    hydrogen,
    read,
    render,
)


def view(volume, *, height=560, **options):
    """The interactive viewer of ``volume`` (an array, a :class:`Volume`
    or a file's path) in a notebook, an anywidget: ``volray view``'s page
    in the cell's output, its frames rendered in the kernel and carried
    over the kernel's connection. ``options`` are :func:`render`'s
    keywords (but the figure's and ``level``): the view it
    starts with; without ``size`` the frame fits the widget, ``height``
    pixels high. The widget's ``camera`` and ``transfer_function`` read
    the view shown back: ``render(volume, camera=w.camera,
    tf=w.transfer_function)`` renders its still frame."""
    from ._jupyter import view as _view

    return _view(volume, height=height, **options)


__all__ = [
    "COLORMAPS",
    "PRESETS",
    "Camera",
    "Frame",
    "Renderer",
    "Scene",
    "TransferFunction",
    "Volume",
    "__version__",
    "fractal",
    "hydrogen",
    "read",
    "render",
    "view",
]
