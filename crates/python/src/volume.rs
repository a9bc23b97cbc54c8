//! `Volume` (a numpy array with its spacing, origin and what its file
//! said) and `read` (any file volray reads, or a built-in source).
//!
//! A file stored in chunks (Zarr, OME-Zarr, and whatever else
//! volray-lazy's `Chunked::open` opens box by box) is read lazily: `read`
//! opens it from its metadata and reads no sample; `Volume.data` reads
//! the level whole on first use (checked against `max_memory` first) and
//! keeps it; `render` and `Renderer` read the level a frame needs, whole
//! or piece by piece (`renderer.rs`).

use crate::array::{self, Order};
use crate::errors::{app_error, value_error};
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyList, PyString};
use std::path::PathBuf;
use volray_app::AppError;
use volray_app::input::{self, Request, Spec};
use volray_app::plan;
use volray_core::{Histogram, SampleType, Volume as CoreVolume};
use volray_io::{FileInfo, MapPolicy, VolumeFormat, format_bytes};
use volray_lazy::Chunked;
use volray_options::level::LevelChoice;

/// A volume: `data`, a numpy array `a[x, y, z]` (x fastest in memory),
/// and where its voxels lie, `spacing` and `origin` in `(x, y, z)`.
///
/// An array is used without a copy where its memory already has x
/// fastest (Fortran order with `order="xyz"`, C order with
/// `order="zyx"`) in a type a volume keeps (uint8, int8, uint16, int16,
/// float32). Change it between frames and a `Renderer` renders what it
/// holds then (it digests the samples before each frame); do not change
/// it while a frame of it renders (the GIL is released meanwhile: the
/// frame is refused with `OSError`). A volume `read` gives is read-only.
///
/// A volume `read` from a chunked file (Zarr, OME-Zarr) is lazy
/// (`lazy` is True): its dims, spacing, levels and info come from the
/// metadata, no sample is read until `data` is asked for (then the level
/// is read whole, if it fits `max_memory`, and kept), and `render` /
/// `Renderer` read only the level a frame needs, piece by piece where it
/// would not fit whole.
#[pyclass(frozen, module = "volray")]
pub struct Volume {
    /// The samples, C-contiguous `(nz, ny, nx)`: set at once, or (a lazy
    /// volume) on first use.
    data: PyOnceLock<Py<PyUntypedArray>>,
    pub sample: SampleType,
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    pub labels: bool,
    /// The file's path or the source's spec, for messages.
    pub name: String,
    /// Whether the samples are volray's own, read-only (`read`'s): they
    /// cannot change, so a renderer need not digest them each frame.
    pub frozen: bool,
    pub file: Option<(VolumeFormat, FileInfo)>,
    /// Where a lazy volume's samples stay until they are asked for.
    pub lazy: Option<LazyFile>,
}

/// A level of a chunked file, opened from its metadata.
pub struct LazyFile {
    pub chunked: Chunked,
    /// What `read` was asked (volray-app's request, its level the one
    /// open): a level is read whole as the command line reads it.
    pub request: Request,
    /// `read`'s `max_memory`: what reading the level whole may take.
    pub max_memory: u64,
    /// Whether `read` was given a spacing (which holds for this level
    /// only).
    pub spacing_given: bool,
}

impl LazyFile {
    /// Level `level` of the file read whole into memory (never mapped:
    /// the samples move into numpy or a renderer), within `max_memory`,
    /// as volray-app reads any input; `read`'s spacing applies to its
    /// own level only.
    pub fn read_level(&self, level: usize, max_memory: u64) -> Result<CoreVolume, AppError> {
        let own = level == self.chunked.level();
        let request = Request {
            spacing: self.request.spacing.filter(|_| own),
            max_memory: Some(max_memory),
            ..self.request.at_level(Some(level))
        };
        Ok(input::load_with(&request, MapPolicy::Never)?.volume)
    }
}

impl Volume {
    /// A volume of `data` (an array, or anything numpy takes) read in
    /// `order`.
    pub fn from_array(
        data: &Bound<'_, PyAny>,
        spacing: Option<[f64; 3]>,
        origin: Option<[f64; 3]>,
        order: Order,
        labels: bool,
    ) -> PyResult<Self> {
        let (array, sample) = array::normalise(data, order, "volume")?;
        let volume = Volume {
            data: PyOnceLock::new(),
            sample,
            spacing: spacing.unwrap_or([1.0; 3]),
            origin: origin.unwrap_or([0.0; 3]),
            labels,
            name: "volume".into(),
            frozen: false,
            file: None,
            lazy: None,
        };
        let _ = volume.data.set(data.py(), array.unbind());
        // Sides, spacing and origin checked now, not at the first frame.
        volume.core(data.py())?;
        Ok(volume)
    }

    /// The samples, C-contiguous `(nz, ny, nx)`: a lazy volume's level
    /// read whole now if it was not yet.
    pub fn array<'py>(&self, py: Python<'py>) -> PyResult<&Bound<'py, PyUntypedArray>> {
        let data = self.data.get_or_try_init(py, || self.read_whole(py))?;
        Ok(data.bind(py))
    }

    /// The samples if they are in memory (always, but for a lazy volume
    /// whose `data` was not asked for).
    pub fn loaded<'py>(&self, py: Python<'py>) -> Option<&Bound<'py, PyUntypedArray>> {
        self.data.get(py).map(|d| d.bind(py))
    }

    /// A lazy volume's level, read whole: refused before a byte is read
    /// where it would take more than `read`'s `max_memory`.
    fn read_whole(&self, py: Python<'_>) -> PyResult<Py<PyUntypedArray>> {
        let Some(lazy) = &self.lazy else {
            unreachable!("a volume not read lazily has its samples from the start")
        };
        let chunked = &lazy.chunked;
        let [x, y, z] = chunked.source().grid().dims;
        let bytes =
            [x, y, z].iter().map(|&n| n as u128).product::<u128>() * self.sample.bytes() as u128;
        if bytes > u128::from(lazy.max_memory) {
            let level = chunked.level();
            let fits = (chunked.levels().iter())
                .position(|l| u128::from(l.bytes_in_memory) <= u128::from(lazy.max_memory));
            let coarser = match fits {
                Some(n) if n > level => {
                    format!("read a coarser level (volray.read(path, level={n})), ")
                }
                _ => String::new(),
            };
            return Err(value_error(format!(
                "{}: level {level} ({x}x{y}x{z} {}) takes {} in memory, more than max_memory {}: {coarser}raise max_memory, or render the volume without reading .data (render and Renderer read what a frame needs, piece by piece)",
                self.name,
                self.sample.name(),
                format_bytes(bytes),
                format_bytes(u128::from(lazy.max_memory)),
            )));
        }
        let level = chunked.level();
        let volume = py
            .detach(|| lazy.read_level(level, lazy.max_memory))
            .map_err(app_error)?;
        if volume.dims() != [x, y, z] || volume.sample_type() != self.sample {
            let [a, b, c] = volume.dims();
            return Err(PyErr::new::<pyo3::exceptions::PyOSError, _>(format!(
                "{}: the store changed since it was opened: level {} was {x}x{y}x{z} {}, now {a}x{b}x{c} {}: read it again",
                self.name,
                chunked.level(),
                self.sample.name(),
                volume.sample_type().name()
            )));
        }
        Ok(array::to_numpy(py, volume, false)?.unbind())
    }

    /// The volume as volray-core's, over the same samples (no copy).
    pub fn core(&self, py: Python<'_>) -> PyResult<CoreVolume> {
        self.core_expecting(py, None)
    }

    /// [`Volume::core`], its samples expected to keep the digest
    /// `expected` (checked after each frame) where one is given.
    pub fn core_expecting(&self, py: Python<'_>, expected: Option<u64>) -> PyResult<CoreVolume> {
        let volume = array::volume(
            self.array(py)?,
            self.sample,
            self.spacing,
            self.origin,
            &self.name,
            expected,
        )?;
        Ok(if self.labels {
            volume.as_labels()
        } else {
            volume
        })
    }

    /// The display window its file gives (an OME-Zarr `omero` window),
    /// which renders take as their default `range`.
    pub fn display_window(&self) -> Option<(f64, f64)> {
        self.file.as_ref()?.1.display_window()
    }

    /// The colours its file gives its labels (a DICOM Segmentation's
    /// segments), which `labels=True` renders draw them in.
    pub fn label_colours(&self) -> Vec<(i64, [f32; 3])> {
        self.file
            .as_ref()
            .map(|(_, info)| volray_app::input::segment_colours(info))
            .unwrap_or_default()
    }

    /// Whether the file marks its NaN values as space it does not cover
    /// (always rendered as empty space).
    pub fn nan_is_empty(&self) -> bool {
        self.file
            .as_ref()
            .is_some_and(|(_, info)| info.nan_is_empty)
    }
}

#[pymethods]
impl Volume {
    /// `Volume(data, *, spacing=(1, 1, 1), origin=(0, 0, 0), order="xyz",
    /// labels=False)`: `order="xyz"` reads `data[x, y, z]` (volray's
    /// `.npy` files, nibabel, pyvista, yt), `"zyx"` reads `data[z, y, x]`
    /// (numpy images, SimpleITK, napari); `labels=True` marks a
    /// segmentation.
    #[new]
    #[pyo3(signature = (data, *, spacing=None, origin=None, order="xyz", labels=false))]
    fn new(
        data: &Bound<'_, PyAny>,
        spacing: Option<[f64; 3]>,
        origin: Option<[f64; 3]>,
        order: &str,
        labels: bool,
    ) -> PyResult<Self> {
        Volume::from_array(data, spacing, origin, Order::parse(order)?, labels)
    }

    /// The samples, `a[x, y, z]`: a view of them, not a copy. A lazy
    /// volume reads its level whole the first time (`ValueError` if it
    /// would take more than `read`'s `max_memory`) and keeps it.
    #[getter]
    fn data<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array::xyz(self.array(py)?)
    }

    /// Points along x, y and z.
    #[getter]
    pub fn dims(&self, py: Python<'_>) -> (usize, usize, usize) {
        if let Some(lazy) = &self.lazy {
            let [x, y, z] = lazy.chunked.source().grid().dims;
            return (x, y, z);
        }
        let shape = self.loaded(py).map(|d| d.shape().to_vec());
        let shape = shape.unwrap_or_else(|| vec![0; 3]);
        (shape[2], shape[1], shape[0])
    }

    /// Whether the volume is read lazily from a chunked file: no sample
    /// read until `data` is asked for, and `render` / `Renderer` read only
    /// what a frame needs (a `level`, whole or piece by piece).
    #[getter]
    fn lazy(&self) -> bool {
        self.lazy.is_some()
    }

    /// Which of its file's `levels` this volume is (0 the finest); `None`
    /// for an array or a built-in source.
    #[getter]
    pub fn level(&self) -> Option<usize> {
        self.file.as_ref().map(|(_, info)| info.level)
    }

    #[getter]
    fn spacing(&self) -> (f64, f64, f64) {
        self.spacing.into()
    }

    #[getter]
    fn origin(&self) -> (f64, f64, f64) {
        self.origin.into()
    }

    #[getter]
    fn labels(&self) -> bool {
        self.labels
    }

    /// The type the samples are kept in: `"u8"`, `"i16"`, `"f32"`, ...
    #[getter]
    fn sample_type(&self) -> &'static str {
        self.sample.name()
    }

    /// The resolution levels of the multiscale image (OME-Zarr) this
    /// volume is one level of, finest first, each a dict: `path`, `dims`
    /// (x, y, z), `spacing`, `origin`, `chunk_shape` and `shard_shape`
    /// (in the array's axis order), `codecs`, `bytes_stored` (its chunk
    /// files, counted when asked for; `None` for a level of more than
    /// 100 000 files) and `bytes_in_memory` (one time point and channel); empty
    /// for a file with one level, an array or a built-in source.
    /// `volray.read(path, level=N)` reads level N.
    #[getter]
    fn levels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let levels = PyList::empty(py);
        if let Some((_, info)) = &self.file {
            for l in &info.levels {
                let d = PyDict::new(py);
                d.set_item("path", &l.path)?;
                d.set_item("dims", (l.dims[0], l.dims[1], l.dims[2]))?;
                d.set_item("spacing", (l.spacing[0], l.spacing[1], l.spacing[2]))?;
                d.set_item("origin", (l.origin[0], l.origin[1], l.origin[2]))?;
                d.set_item("chunk_shape", l.chunk_shape.clone())?;
                d.set_item("shard_shape", l.shard_shape.clone())?;
                d.set_item("codecs", &l.codecs)?;
                // Counted when asked for (opening a level does not walk
                // its chunk files), as `volray info` counts them.
                let stored = l.bytes_stored.or_else(|| {
                    py.detach(|| l.count_bytes_stored(volray_io::LevelInfo::COUNTED_FILES))
                });
                d.set_item("bytes_stored", stored)?;
                d.set_item("bytes_in_memory", l.bytes_in_memory)?;
                levels.append(d)?;
            }
        }
        Ok(levels)
    }

    /// What `volray info` says of the volume: its format, dims, sample
    /// type, spacing, origin, value statistics, and for a file the type
    /// stored, frames, arrays, header fields and the notes on how it was
    /// read.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let format = match &self.file {
            Some((format, _)) => format.description(),
            None => "numpy array",
        };
        d.set_item("input", &self.name)?;
        d.set_item("format", format)?;
        d.set_item("dims", self.dims(py))?;
        d.set_item("sample_type", self.sample.name())?;
        d.set_item("spacing", self.spacing)?;
        d.set_item("origin", self.origin)?;
        d.set_item("lazy", self.lazy.is_some())?;
        let values = PyDict::new(py);
        // A lazy volume's values are known once its samples are read.
        if self.lazy.is_none() || self.loaded(py).is_some() {
            let volume = self.core(py)?;
            let histogram = py.detach(|| Histogram::of(&volume, 256));
            if let Some(h) = histogram {
                values.set_item("min", h.min)?;
                values.set_item("max", h.max)?;
                values.set_item("mean", h.mean)?;
                values.set_item("non_finite", h.non_finite)?;
            }
        }
        d.set_item("values", values)?;
        if let Some((_, i)) = &self.file {
            d.set_item("length_unit", &i.length_unit)?;
            d.set_item("stored_type", &i.stored_type)?;
            // `frames` = time points × channels, `frame` the one read.
            d.set_item("frames", i.frames)?;
            d.set_item("frame", i.frame)?;
            d.set_item("time_points", i.time_points)?;
            d.set_item("time_point", i.time_point)?;
            d.set_item("channels", i.channels)?;
            d.set_item("channel", i.channel)?;
            d.set_item("arrays", PyList::new(py, &i.arrays)?)?;
            d.set_item("array", &i.array)?;
            let header = PyDict::new(py);
            for (k, v) in &i.header {
                header.set_item(k, v)?;
            }
            d.set_item("header", header)?;
            d.set_item("notes", PyList::new(py, &i.notes)?)?;
            d.set_item("nan_is_empty", i.nan_is_empty)?;
        }
        Ok(d)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let (x, y, z) = self.dims(py);
        format!(
            "Volume({}: {x}x{y}x{z} {}, spacing {:?}, origin {:?}{}{})",
            self.name,
            self.sample.name(),
            self.spacing,
            self.origin,
            if self.labels { ", labels" } else { "" },
            match &self.lazy {
                Some(l) => format!(
                    ", level {} of {}, lazy",
                    l.chunked.level(),
                    l.chunked.levels().len()
                ),
                None => String::new(),
            }
        )
    }
}

/// `read(path, *, format=None, frame=None, array=None, level=None,
/// channel=None, dims=None, dtype=None, endian=None, spacing=None,
/// max_memory=None, series=None)`: the volume
/// in a file of any format volray reads (or a built-in source such as
/// `"hydrogen:4,2,1"`), its samples moved into a numpy array without a
/// copy, read-only (`volume.data.copy()` is a writeable copy). `frame`
/// picks the time point and `channel` the channel of a file holding
/// several, in every format (a hyperstack's, an HDF5 dataset's `t` and
/// `c`, a 5-D NIfTI's `dim[4]` and `dim[5]`; the command line's
/// `--frame` and `--channel`; 0 by default); `level` a level of an
/// OME-Zarr image. `dims`, `dtype` and `endian` describe a raw file.
/// `series` picks a series of a DICOM directory or DICOMDIR: its number
/// in the list the file's notes give (from 1) or its SeriesInstanceUID
/// (default: the largest; the command line's `--series`).
///
/// A chunked file (Zarr, OME-Zarr) is read lazily: the volume comes from
/// the metadata alone, `volume.data` reads the level when first asked
/// for, and `render(volume, level="auto")` picks the level each view
/// needs (`level="auto"` here cannot know the view, and is refused).
#[pyfunction]
#[pyo3(signature = (path, *, format=None, frame=None, array=None, level=None, channel=None, dims=None, dtype=None, endian=None, spacing=None, max_memory=None, series=None))]
#[allow(clippy::too_many_arguments)]
pub fn read(
    py: Python<'_>,
    path: PathBuf,
    format: Option<&str>,
    frame: Option<usize>,
    array: Option<String>,
    level: Option<&Bound<'_, PyAny>>,
    channel: Option<usize>,
    dims: Option<[usize; 3]>,
    dtype: Option<&str>,
    endian: Option<&str>,
    spacing: Option<[f64; 3]>,
    max_memory: Option<u64>,
    series: Option<&Bound<'_, PyAny>>,
) -> PyResult<Volume> {
    let spec = path.to_string_lossy().to_string();
    let level = read_level(&spec, level)?;
    // A number (from 1) or a UID, as an int or a str.
    let series = series.map(|s| s.str().map(|s| s.to_string())).transpose()?;
    // Opened as the command line opens its INPUT (volray-app): a
    // built-in source's spec or a file, the same options refused the
    // same way, in volray-app's words.
    let request = Request {
        spec: Spec::parse(&spec),
        dims,
        dtype: dtype.map(String::from),
        endian: endian.map(String::from),
        spacing,
        format: format.map(String::from),
        frame,
        array,
        level: level.map(LevelChoice::Index),
        channel,
        series,
        max_memory,
        // `read` keeps the stored geometry; `render` stretches (`scale=`).
        scale: None,
    };
    let max_memory = request.max_memory();
    let chunked = py
        .detach(|| plan::open_chunked(&request, max_memory))
        .map_err(app_error)?;
    if let Some(chunked) = chunked {
        return Ok(lazy_volume(chunked, request));
    }
    // The samples move into a numpy array, which owns its memory: never
    // mapped from the file.
    let loaded = py
        .detach(|| input::load_with(&request, MapPolicy::Never))
        .map_err(app_error)?;
    let (volume, file) = (loaded.volume, loaded.file);
    let spacing = volume.spacing().to_array();
    let origin = volume.origin().to_array();
    let labels = volume.is_labels();
    let sample = volume.sample_type();
    // Read-only: a renderer of the volume need not digest the samples
    // before each frame (docs/python.md); `.copy()` gives a writeable one.
    let data = array::to_numpy(py, volume, false)?;
    let volume = Volume {
        data: PyOnceLock::new(),
        sample,
        spacing,
        origin,
        labels,
        name: spec,
        frozen: true,
        file,
        lazy: None,
    };
    let _ = volume.data.set(py, data.unbind());
    Ok(volume)
}

/// `read`'s `level=`: a level number, or `None`.
fn read_level(spec: &str, level: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(level) = level else { return Ok(None) };
    if let Ok(s) = level.cast::<PyString>()
        && s.to_cow()? == "auto"
    {
        return Err(value_error(format!(
            "{spec}: level='auto' picks the level a view needs, which read() cannot know: read the file (lazily, no sample is read) and give level='auto' to render() or Renderer(): volray.render(volray.read(path), level='auto')"
        )));
    }
    crate::keywords::extract::<usize>(level, "level", "a level number (0 the finest)").map(Some)
}

/// The volume of a chunked file's level, from its metadata: no sample
/// read.
fn lazy_volume(chunked: Chunked, request: Request) -> Volume {
    let source = chunked.source();
    let grid = source.grid();
    let spacing = request.spacing;
    Volume {
        data: PyOnceLock::new(),
        sample: source.sample_type(),
        spacing: spacing.unwrap_or(grid.spacing.to_array()),
        origin: grid.origin.to_array(),
        labels: source.is_labels(),
        name: request.spec.name(),
        frozen: true,
        file: Some((chunked.format(), chunked.info().clone())),
        lazy: Some(LazyFile {
            chunked,
            max_memory: request.max_memory(),
            spacing_given: spacing.is_some(),
            request,
        }),
    }
}
