"""Type stubs for volray (see the package's docstring for the conventions)."""

from os import PathLike
from typing import (
    Any,
    Dict,
    List,
    Literal,
    Mapping,
    Optional,
    Sequence,
    Tuple,
    TypedDict,
    Union,
    overload,
)

import numpy as np
import numpy.typing as npt

__version__: str
PRESETS: List[str]
COLORMAPS: List[str]

Vec3 = Tuple[float, float, float]
Rgb = Union[float, Tuple[float, float, float]]
Pair = Tuple[float, float]
Plane = Union[Tuple[float, float, float, float, float, float], Tuple[Vec3, Vec3]]
ArrayLike = Union[npt.NDArray[Any], Sequence[Any]]
Path = Union[str, PathLike]
Blend = Literal["composite", "mip", "maximum", "minip", "minimum", "average", "iso"]
Level = Union[int, Literal["auto"]]

class TransferFunction:
    def __init__(
        self,
        opacity: Optional[Sequence[Tuple[float, float]]] = None,
        color: Optional[Sequence[Tuple[float, float, float, float]]] = None,
        domain: Optional[Pair] = None,
    ) -> None: ...
    @staticmethod
    def from_json(text_or_path: Union[str, PathLike]) -> "TransferFunction": ...
    @staticmethod
    def preset(name: str) -> "TransferFunction": ...
    def with_colormap(self, name: str) -> "TransferFunction": ...
    @property
    def opacity(self) -> Optional[List[Tuple[float, float]]]: ...
    @property
    def color(self) -> Optional[List[Tuple[float, float, float, float]]]: ...
    @property
    def domain(self) -> Optional[Pair]: ...
    def __call__(self, t: float) -> Tuple[float, float, float, float]: ...

class Camera:
    def __init__(
        self,
        *,
        size: Union[int, Tuple[int, int]] = 480,
        view: Optional[Vec3] = None,
        look_at: Optional[Vec3] = None,
        up: Vec3 = (0, 0, 1),
        perspective: Optional[float] = None,
        azimuth: float = 0,
        elevation: float = 0,
        zoom: float = 1,
        clip: Optional[Union[Plane, Sequence[Plane]]] = None,
        crop: Optional[Tuple[float, float, float, float, float, float]] = None,
    ) -> None: ...
    size: Tuple[int, int]
    view: Optional[Vec3]
    look_at: Optional[Vec3]
    azimuth: float
    elevation: float
    zoom: float
    perspective: Optional[float]

class Volume:
    """Samples with their spacing and origin. A volume ``read`` from a
    chunked file (Zarr, OME-Zarr) is lazy: ``dims``, ``spacing``,
    ``origin``, ``sample_type``, ``labels``, ``levels`` and ``info`` come
    from the metadata; ``data`` reads the level whole on first use
    (``ValueError`` over ``max_memory``) and keeps it; ``render`` and
    ``Renderer`` read only the level a frame needs, piece by piece where
    it would not fit whole."""

    def __init__(
        self,
        data: ArrayLike,
        *,
        spacing: Optional[Vec3] = None,
        origin: Optional[Vec3] = None,
        order: Literal["xyz", "zyx"] = "xyz",
        labels: bool = False,
    ) -> None: ...
    @property
    def data(self) -> npt.NDArray[Any]: ...
    @property
    def dims(self) -> Tuple[int, int, int]: ...
    @property
    def spacing(self) -> Vec3: ...
    @property
    def origin(self) -> Vec3: ...
    @property
    def labels(self) -> bool: ...
    @property
    def sample_type(self) -> str: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    @property
    def levels(self) -> List[Dict[str, Any]]: ...
    @property
    def lazy(self) -> bool:
        """True for a volume read lazily from a chunked file."""
    @property
    def level(self) -> Optional[int]:
        """Which of its file's levels this volume is (None for an array)."""

class Frame:
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    def to_numpy(self, dtype: Any = None) -> npt.NDArray[Any]: ...
    def __array__(self, dtype: Any = None, copy: Optional[bool] = None) -> npt.NDArray[Any]: ...
    def save(self, path: Path, *, bit_depth: Literal[8, 16] = 8) -> None: ...
    def _repr_png_(self) -> bytes: ...

class Renderer:
    def __init__(
        self,
        volume: Union[Volume, ArrayLike],
        *,
        spacing: Optional[Vec3] = None,
        origin: Optional[Vec3] = None,
        order: Literal["xyz", "zyx"] = "xyz",
        labels: Optional[bool] = None,
        log: bool = False,
        nonfinite: Literal["refuse", "transparent"] = "refuse",
        max_memory: Optional[int] = None,
        level: Optional[Level] = None,
    ) -> None: ...
    def render(
        self,
        *,
        size: Union[int, Tuple[int, int]] = 480,
        view: Optional[Vec3] = None,
        look_at: Optional[Vec3] = None,
        up: Vec3 = (0, 0, 1),
        perspective: Optional[float] = None,
        azimuth: float = 0,
        elevation: float = 0,
        zoom: float = 1,
        clip: Optional[Union[Plane, Sequence[Plane]]] = None,
        crop: Optional[Tuple[float, float, float, float, float, float]] = None,
        camera: Optional[Camera] = None,
        step: float = 1,
        jitter: bool = False,
        reference: bool = False,
        opacity: Optional[Pair] = None,
        tf: Union[None, Literal["auto"], TransferFunction, Mapping[str, Any], Path] = None,
        preset: Optional[str] = None,
        colormap: Optional[str] = None,
        range: Optional[Pair] = None,
        blend: Blend = "composite",
        iso: Optional[float] = None,
        iso_thickness: Optional[float] = None,
        gradient_opacity: Optional[Pair] = None,
        post_classification: bool = False,
        shading: bool = True,
        ambient: Rgb = 0.1,
        diffuse: Rgb = 0.7,
        specular: Rgb = 0.2,
        shininess: float = 10,
        light: Optional[Vec3] = None,
        light_color: Rgb = 1,
        shadows: bool = False,
        ambient_occlusion: bool | float = False,
        background: Rgb = 0,
        label_opacity: Optional[Union[Mapping[int, float], Sequence[Tuple[int, float]]]] = None,
        show_labels: Optional[Sequence[int]] = None,
        threads: Optional[int] = None,
        colorbar: Optional[Literal["right", "left"]] = None,
        units: Optional[str] = None,
        scale_bar: Union[None, bool, float] = None,
        title: Optional[str] = None,
        label: Optional[str] = None,
        axes: bool = False,
        outline: bool = False,
    ) -> Frame: ...
    @property
    def value_range(self) -> Pair: ...
    @property
    def level(self) -> Optional[int]:
        """The level of a lazy volume's file the last frame rendered."""
    @property
    def pieces(self) -> Optional[int]:
        """The pieces the last frame was cut into (1: read whole)."""

Mix = Literal["composite", "additive"]
Color = Union[str, float, Tuple[float, float, float]]

class Look(TypedDict, total=False):
    """One volume's look in a scene: the per-volume keywords of
    :func:`render` (volume keywords are fixed once a :class:`Scene` is
    made), with ``color`` (a name, ``'#rrggbb'`` or ``(r, g, b)``: that
    colour throughout), ``opacity_scale`` (its opacity times this, in
    [0, 1]) and ``visible``."""

    spacing: Vec3
    origin: Vec3
    order: Literal["xyz", "zyx"]
    labels: bool
    log: bool
    nonfinite: Literal["refuse", "transparent"]
    opacity: Pair
    tf: Union[Literal["auto"], TransferFunction, Mapping[str, Any], Path]
    preset: str
    colormap: str
    range: Pair
    iso: float
    iso_thickness: float
    gradient_opacity: Pair
    label_opacity: Union[Mapping[int, float], Sequence[Tuple[int, float]]]
    show_labels: Sequence[int]
    color: Color
    opacity_scale: float
    visible: bool

Volumes = Union[Sequence[Union[Volume, npt.NDArray[Any]]], npt.NDArray[Any]]

class Scene:
    """Several volumes rendered together in one ray march (each occludes
    the others where it lies in front), each kept prepared across frames
    as a :class:`Renderer` keeps one. ``channel_axis`` splits a 4-D array
    into channels coloured magenta, green, cyan, yellow, red, blue,
    orange, white (then again). ``mix`` is ``"composite"`` by default,
    ``"additive"`` for channels."""

    def __init__(
        self,
        volumes: Volumes,
        *,
        looks: Optional[Sequence[Mapping[str, Any]]] = None,
        mix: Optional[Mix] = None,
        channel_axis: Optional[int] = None,
        spacing: Optional[Vec3] = None,
        origin: Optional[Vec3] = None,
        order: Literal["xyz", "zyx"] = "xyz",
        labels: Optional[bool] = None,
        log: bool = False,
        nonfinite: Literal["refuse", "transparent"] = "refuse",
        max_memory: Optional[int] = None,
    ) -> None: ...
    def render(
        self,
        *,
        size: Union[int, Tuple[int, int]] = 480,
        view: Optional[Vec3] = None,
        look_at: Optional[Vec3] = None,
        up: Vec3 = (0, 0, 1),
        perspective: Optional[float] = None,
        azimuth: float = 0,
        elevation: float = 0,
        zoom: float = 1,
        clip: Optional[Union[Plane, Sequence[Plane]]] = None,
        crop: Optional[Tuple[float, float, float, float, float, float]] = None,
        camera: Optional[Camera] = None,
        step: float = 1,
        jitter: bool = False,
        reference: bool = False,
        opacity: Optional[Pair] = None,
        tf: Union[None, Literal["auto"], TransferFunction, Mapping[str, Any], Path] = None,
        preset: Optional[str] = None,
        colormap: Optional[str] = None,
        range: Optional[Pair] = None,
        blend: Blend = "composite",
        iso: Optional[float] = None,
        iso_thickness: Optional[float] = None,
        gradient_opacity: Optional[Pair] = None,
        post_classification: bool = False,
        shading: bool = True,
        ambient: Rgb = 0.1,
        diffuse: Rgb = 0.7,
        specular: Rgb = 0.2,
        shininess: float = 10,
        light: Optional[Vec3] = None,
        light_color: Rgb = 1,
        shadows: bool = False,
        ambient_occlusion: bool | float = False,
        background: Rgb = 0,
        label_opacity: Optional[Union[Mapping[int, float], Sequence[Tuple[int, float]]]] = None,
        show_labels: Optional[Sequence[int]] = None,
        threads: Optional[int] = None,
        colorbar: Optional[Literal["right", "left"]] = None,
        units: Optional[str] = None,
        scale_bar: Union[None, bool, float] = None,
        title: Optional[str] = None,
        label: Optional[str] = None,
        axes: bool = False,
        outline: bool = False,
        color: Optional[Color] = None,
        opacity_scale: Optional[float] = None,
        visible: Optional[bool] = None,
    ) -> Frame:
        """One frame; the per-volume keywords given here apply to every
        volume whose look does not give them."""
    @property
    def looks(self) -> List[Dict[str, Any]]:
        """Copies of the looks, one per volume."""
    @looks.setter
    def looks(self, looks: Sequence[Mapping[str, Any]]) -> None: ...
    @property
    def mix(self) -> Mix: ...
    @mix.setter
    def mix(self, mix: Mix) -> None: ...
    def __len__(self) -> int: ...

@overload
def render(
    volume: Volumes,
    *,
    looks: Optional[Sequence[Mapping[str, Any]]] = None,
    mix: Optional[Mix] = None,
    channel_axis: Optional[int] = None,
    spacing: Optional[Vec3] = None,
    origin: Optional[Vec3] = None,
    order: Literal["xyz", "zyx"] = "xyz",
    labels: Optional[bool] = None,
    log: bool = False,
    nonfinite: Literal["refuse", "transparent"] = "refuse",
    max_memory: Optional[int] = None,
    size: Union[int, Tuple[int, int]] = 480,
    view: Optional[Vec3] = None,
    look_at: Optional[Vec3] = None,
    up: Vec3 = (0, 0, 1),
    perspective: Optional[float] = None,
    azimuth: float = 0,
    elevation: float = 0,
    zoom: float = 1,
    clip: Optional[Union[Plane, Sequence[Plane]]] = None,
    crop: Optional[Tuple[float, float, float, float, float, float]] = None,
    camera: Optional[Camera] = None,
    step: float = 1,
    jitter: bool = False,
    reference: bool = False,
    opacity: Optional[Pair] = None,
    tf: Union[None, Literal["auto"], TransferFunction, Mapping[str, Any], Path] = None,
    preset: Optional[str] = None,
    colormap: Optional[str] = None,
    range: Optional[Pair] = None,
    blend: Blend = "composite",
    iso: Optional[float] = None,
    iso_thickness: Optional[float] = None,
    gradient_opacity: Optional[Pair] = None,
    post_classification: bool = False,
    shading: bool = True,
    ambient: Rgb = 0.1,
    diffuse: Rgb = 0.7,
    specular: Rgb = 0.2,
    shininess: float = 10,
    light: Optional[Vec3] = None,
    light_color: Rgb = 1,
    shadows: bool = False,
    ambient_occlusion: bool | float = False,
    background: Rgb = 0,
    label_opacity: Optional[Union[Mapping[int, float], Sequence[Tuple[int, float]]]] = None,
    show_labels: Optional[Sequence[int]] = None,
    threads: Optional[int] = None,
    colorbar: Optional[Literal["right", "left"]] = None,
    units: Optional[str] = None,
    scale_bar: Union[None, bool, float] = None,
    title: Optional[str] = None,
    label: Optional[str] = None,
    axes: bool = False,
    outline: bool = False,
    color: Optional[Color] = None,
    opacity_scale: Optional[float] = None,
    visible: Optional[bool] = None,
) -> Frame:
    """Several volumes in one picture (a list or tuple of volumes, or a
    4-D array with ``channel_axis``): the shared keywords, each volume's
    look from ``looks`` (see :class:`Look`)."""

@overload
def render(
    volume: Union[Volume, ArrayLike],
    *,
    spacing: Optional[Vec3] = None,
    origin: Optional[Vec3] = None,
    order: Literal["xyz", "zyx"] = "xyz",
    labels: Optional[bool] = None,
    log: bool = False,
    nonfinite: Literal["refuse", "transparent"] = "refuse",
    max_memory: Optional[int] = None,
    level: Optional[Level] = None,
    size: Union[int, Tuple[int, int]] = 480,
    view: Optional[Vec3] = None,
    look_at: Optional[Vec3] = None,
    up: Vec3 = (0, 0, 1),
    perspective: Optional[float] = None,
    azimuth: float = 0,
    elevation: float = 0,
    zoom: float = 1,
    clip: Optional[Union[Plane, Sequence[Plane]]] = None,
    crop: Optional[Tuple[float, float, float, float, float, float]] = None,
    camera: Optional[Camera] = None,
    step: float = 1,
    jitter: bool = False,
    reference: bool = False,
    opacity: Optional[Pair] = None,
    tf: Union[None, Literal["auto"], TransferFunction, Mapping[str, Any], Path] = None,
    preset: Optional[str] = None,
    colormap: Optional[str] = None,
    range: Optional[Pair] = None,
    blend: Blend = "composite",
    iso: Optional[float] = None,
    iso_thickness: Optional[float] = None,
    gradient_opacity: Optional[Pair] = None,
    post_classification: bool = False,
    shading: bool = True,
    ambient: Rgb = 0.1,
    diffuse: Rgb = 0.7,
    specular: Rgb = 0.2,
    shininess: float = 10,
    light: Optional[Vec3] = None,
    light_color: Rgb = 1,
    shadows: bool = False,
    ambient_occlusion: bool | float = False,
    background: Rgb = 0,
    label_opacity: Optional[Union[Mapping[int, float], Sequence[Tuple[int, float]]]] = None,
    show_labels: Optional[Sequence[int]] = None,
    threads: Optional[int] = None,
    colorbar: Optional[Literal["right", "left"]] = None,
    units: Optional[str] = None,
    scale_bar: Union[None, bool, float] = None,
    title: Optional[str] = None,
    label: Optional[str] = None,
    axes: bool = False,
    outline: bool = False,
) -> Frame: ...

def read(
    path: Path,
    *,
    format: Optional[str] = None,
    frame: Optional[int] = None,
    array: Optional[str] = None,
    level: Optional[int] = None,
    channel: Optional[int] = None,
    dims: Optional[Tuple[int, int, int]] = None,
    dtype: Optional[str] = None,
    endian: Optional[Literal["little", "big"]] = None,
    spacing: Optional[Vec3] = None,
    max_memory: Optional[int] = None,
) -> Volume:
    """The volume in ``path``; a chunked file (Zarr, OME-Zarr) lazily,
    from its metadata (see :class:`Volume`). ``frame`` picks the time
    point and ``channel`` the channel, in every format."""

def hydrogen(
    n: int, l: int, m: int, grid: int = 50, extent: Optional[float] = None, real: bool = False
) -> npt.NDArray[np.float32]: ...

def fractal(
    size: int,
    dimension: float = 3.7,
    sigma: float = 1.0,
    seed: int = 1,
    ramp: float = 0.3,
    threshold: float = 0.45,
    raw_field: bool = False,
    random_additions: bool = False,
) -> npt.NDArray[np.float32]: ...

class Viewer:
    """The viewer in a notebook (an ``anywidget.AnyWidget``), made by
    :func:`view`. ``camera`` and ``transfer_function`` read back the view
    shown last: ``render(volume, camera=w.camera, tf=w.transfer_function)``
    renders its still frame where the other keywords are the defaults,
    ``render(volume, **w.keywords)`` whatever they are."""

    height: int
    @property
    def camera(self) -> Camera: ...
    @property
    def transfer_function(self) -> TransferFunction: ...
    @property
    def keywords(self) -> Dict[str, Any]: ...
    @property
    def state(self) -> Dict[str, Any]: ...
    def close(self) -> None: ...

def view(
    volume: Union[Volume, ArrayLike, Path],
    *,
    height: int = 560,
    spacing: Optional[Vec3] = None,
    origin: Optional[Vec3] = None,
    order: Literal["xyz", "zyx"] = "xyz",
    log: bool = False,
    nonfinite: Literal["refuse", "transparent"] = "refuse",
    max_memory: Optional[int] = None,
    level: Optional[Level] = None,
    size: Optional[Union[int, Tuple[int, int]]] = None,
    view: Optional[Vec3] = None,
    look_at: Optional[Vec3] = None,
    up: Vec3 = (0, 0, 1),
    perspective: Optional[float] = None,
    azimuth: float = 0,
    elevation: float = 0,
    zoom: float = 1,
    clip: Optional[Union[Plane, Sequence[Plane]]] = None,
    crop: Optional[Tuple[float, float, float, float, float, float]] = None,
    camera: Optional[Camera] = None,
    step: float = 1,
    jitter: bool = False,
    reference: bool = False,
    opacity: Optional[Pair] = None,
    tf: Union[None, Literal["auto"], TransferFunction, Mapping[str, Any], Path] = None,
    preset: Optional[str] = None,
    colormap: Optional[str] = None,
    range: Optional[Pair] = None,
    blend: Blend = "composite",
    iso: Optional[float] = None,
    iso_thickness: Optional[float] = None,
    gradient_opacity: Optional[Pair] = None,
    post_classification: bool = False,
    shading: bool = True,
    ambient: Rgb = 0.1,
    diffuse: Rgb = 0.7,
    specular: Rgb = 0.2,
    shininess: float = 10,
    light: Optional[Vec3] = None,
    light_color: Rgb = 1,
    shadows: bool = False,
    ambient_occlusion: bool | float = False,
    background: Rgb = 0,
    labels: bool = False,
    label_opacity: Optional[Union[Mapping[int, float], Sequence[Tuple[int, float]]]] = None,
    show_labels: Optional[Sequence[int]] = None,
    threads: Optional[int] = None,
    colorbar: Optional[Literal["right", "left"]] = None,
    units: Optional[str] = None,
    scale_bar: Union[None, bool, float] = None,
    title: Optional[str] = None,
    label: Optional[str] = None,
    axes: bool = False,
    outline: bool = False,
) -> Viewer:
    """The interactive viewer of ``volume`` in a notebook (needs
    anywidget): ``volray view``'s page in the output, its frames rendered
    in the kernel and carried over the kernel's connection. The keywords
    are :func:`render`'s: the view it starts with, the figure's its
    Figure box, ``level`` the level of a chunked file its stills show
    (``"auto"`` by default); without ``size`` the frame fits the
    widget."""
