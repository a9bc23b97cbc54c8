//! numpy arrays as volumes, without a copy where the array can be used as
//! it is.
//!
//! The axis convention: `order="xyz"` (the default) reads `a[x, y, z]`,
//! as volray's own `.npy` files, nibabel, pyvista and yt hold volumes: a
//! Fortran-ordered array (x fastest in memory, volray-core's [`Volume`]
//! layout) is used as it is. `order="zyx"` reads `a[z, y, x]` (numpy
//! images, SimpleITK, napari, scikit-image): a C-ordered array is used as
//! it is. Either way the samples are kept as a C-contiguous `(nz, ny,
//! nx)` array of the type the volume keeps, made by
//! `numpy.ascontiguousarray`, which returns the array itself (or a view)
//! where nothing needs to change; only other strides, another byte order
//! or a type the volume does not keep (`u32`, `i32`, `f64`, ... become
//! `f32`) cost a copy. Arrays handed back (`Volume.data`, `hydrogen`,
//! `fractal`) are `a[x, y, z]` views of those samples. Spacing, origin
//! and every world coordinate are `(x, y, z)` whatever the order.

use crate::digest::digest;
use crate::errors::value_error;
use numpy::{PyArray3, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::IntoPyDict;
use std::sync::Arc;
use volray_core::glam::DVec3;
use volray_core::{External, ExternalBytes, Sample, SampleType, Samples, Store, Volume};

/// Which index of the array is x.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// `a[x, y, z]`.
    Xyz,
    /// `a[z, y, x]`.
    Zyx,
}

impl Order {
    pub fn parse(name: &str) -> PyResult<Self> {
        match name {
            "zyx" | "C" => Ok(Order::Zyx),
            "xyz" | "F" => Ok(Order::Xyz),
            _ => Err(value_error(format!(
                "order: '{name}' is not an axis order: expected 'xyz' (a[x, y, z], the default) or 'zyx' (a[z, y, x])"
            ))),
        }
    }
}

/// The sample type a volume keeps for a numpy dtype of `kind` and
/// `itemsize`, if it is a type volray takes.
fn sample_type(kind: u8, itemsize: usize) -> Option<SampleType> {
    Some(match (kind, itemsize) {
        (b'u', 1) | (b'b', 1) => SampleType::U8,
        (b'i', 1) => SampleType::I8,
        (b'u', 2) => SampleType::U16,
        (b'i', 2) => SampleType::I16,
        (b'f', 4) => SampleType::F32,
        // Kept as f32, as volray-io keeps these types read from files.
        (b'u' | b'i', 4 | 8) | (b'f', 2 | 8) => SampleType::F32,
        _ => return None,
    })
}

fn numpy_name(sample: SampleType) -> &'static str {
    match sample {
        SampleType::U8 => "uint8",
        SampleType::I8 => "int8",
        SampleType::U16 => "uint16",
        SampleType::I16 => "int16",
        SampleType::F32 => "float32",
    }
}

/// `data` (a numpy array, or anything `numpy.asarray` takes) as the
/// C-contiguous `(nz, ny, nx)` array of a type a volume keeps, read in
/// `order`; `what` names it in messages.
pub fn normalise<'py>(
    data: &Bound<'py, PyAny>,
    order: Order,
    what: &str,
) -> PyResult<(Bound<'py, PyUntypedArray>, SampleType)> {
    let py = data.py();
    let np = py.import("numpy")?;
    let array = match data.cast::<PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => np
            .call_method1("asarray", (data,))
            .and_then(|a| Ok(a.cast_into::<PyUntypedArray>()?))
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "{what}: expected a 3-D numpy array, got {}",
                    type_name(data)
                ))
            })?,
    };
    if array.ndim() != 3 {
        return Err(value_error(format!(
            "{what}: a volume is a 3-D array, but this one has shape {:?}",
            array.shape()
        )));
    }
    let dtype = array.dtype();
    let sample = sample_type(dtype.kind(), dtype.itemsize()).ok_or_else(|| {
        PyTypeError::new_err(format!(
            "{what}: numpy dtype {} is not a volume's: expected uint8, int8, uint16, int16, uint32, int32, float32 or float64",
            dtype.str().map(|s| s.to_string()).unwrap_or_default()
        ))
    })?;
    let oriented = match order {
        Order::Zyx => array.into_any(),
        Order::Xyz => array.getattr("T")?,
    };
    let mut kept = np.call_method1("ascontiguousarray", (oriented, numpy_name(sample)))?;
    // numpy does not promise alignment: a view at an odd byte offset
    // (`np.frombuffer(buf, np.uint16, offset=1)`) is C-contiguous and kept
    // as it is by `ascontiguousarray`. Its samples cannot be read in place
    // as `u16` (`External::new` would refuse them), so they are copied
    // into a fresh array, which numpy allocates aligned.
    if !kept
        .getattr("flags")?
        .getattr("aligned")?
        .extract::<bool>()?
    {
        kept = np.call_method1("array", (kept,))?;
    }
    Ok((kept.cast_into::<PyUntypedArray>()?, sample))
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "an object".into())
}

/// The bytes of a C-contiguous numpy array, owned by the array: a
/// volume's samples without a copy.
pub struct ArrayBytes {
    /// Keeps the array, and so its buffer, alive.
    _array: Py<PyAny>,
    ptr: *const u8,
    len: usize,
    /// The [`digest`] of the bytes when the volume over them was made,
    /// where a renderer checks that they stay so ([`ExternalBytes::verify`]).
    expected: Option<u64>,
}

// SAFETY: `ptr` is only read (through `bytes`), and the buffer it points
// into is kept alive by `_array`, a strong reference: a `Py` may be sent
// and shared between threads (its reference count is only touched with
// the interpreter attached). The bytes are shared with Python, which may
// write them while the GIL is released for a render: that is the same
// contract as any extension that reads a numpy array without the GIL
// (numpy's own ufuncs do), stated in `Volume`'s documentation: do not
// change an array while it renders. A renderer digests the bytes before
// each frame and, through `verify`, after it, so a write between frames
// is rendered and a write during one is refused, not shown.
unsafe impl Send for ArrayBytes {}
unsafe impl Sync for ArrayBytes {}

impl ArrayBytes {
    /// The bytes of `array`, one contiguous run (C or Fortran order)
    /// whatever its type, byte order or alignment, expected to keep the
    /// digest `expected` where one is given.
    pub fn new(array: &Bound<'_, PyUntypedArray>, expected: Option<u64>) -> PyResult<Self> {
        if !(array.is_c_contiguous() || array.is_fortran_contiguous()) {
            return Err(value_error("volume: the samples are not contiguous"));
        }
        // SAFETY: `as_array_ptr` is the `PyArrayObject` of `array`, alive
        // while the `Bound` is held (the GIL attached); its data pointer
        // is read, nothing is written.
        let ptr = unsafe { (*array.as_array_ptr()).fields.data } as *const u8;
        Ok(ArrayBytes {
            _array: array.clone().into_any().unbind(),
            ptr,
            len: array.len() * array.dtype().itemsize(),
            expected,
        })
    }

    /// Whether `self` and `other` are the same bytes of memory.
    pub fn same_bytes(&self, other: &ArrayBytes) -> bool {
        self.ptr == other.ptr && self.len == other.len
    }

    /// The [`digest`] of the bytes as they are now (on the current rayon
    /// pool; the GIL need not be held).
    pub fn digest(&self) -> u64 {
        digest(self.bytes())
    }
}

impl std::fmt::Debug for ArrayBytes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "numpy array of {} bytes", self.len)
    }
}

impl ExternalBytes for ArrayBytes {
    fn bytes(&self) -> &[u8] {
        if self.len == 0 {
            return &[];
        }
        // SAFETY: a `&[u8]` needs a non-null pointer aligned for `u8` (any
        // pointer is) to `len` initialised bytes in one allocation that
        // live as long as the slice. `ptr` is the data pointer of a
        // C-contiguous array (checked in `new`), so its `len` =
        // elements × itemsize bytes are one run in one buffer, non-null as
        // the array is not empty; its bytes were written by numpy or are
        // what its allocator handed out (`np.empty`): arbitrary values,
        // each a valid `u8`, from memory allocated outside Rust. The buffer lives as long as `_array` (the
        // array, which holds its base), and so as long as `self`. numpy
        // cannot move or free the buffer under that reference: `resize`
        // refuses an array referenced elsewhere unless told
        // `refcheck=False`, which numpy documents as unsafe. Reading the
        // bytes as samples of their type (`Store`'s `Deref`) needs the
        // type's alignment, which numpy does not promise: `normalise`
        // copies a misaligned array, and `External::new` checks the
        // alignment again (refusing, never reading unaligned). What Rust's
        // rules also ask, that nothing writes the bytes while the slice
        // lives, is the documented contract (see the `Send` note), and
        // `verify` refuses a frame that read bytes changed under it.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }

    fn verify(&self) -> Result<(), String> {
        match self.expected {
            Some(expected) if self.digest() != expected => Err(
                "the numpy array was written during the frame: write to it only between frames"
                    .to_string(),
            ),
            _ => Ok(()),
        }
    }
}

fn store<T: Sample + numpy::Element>(
    array: &Bound<'_, PyUntypedArray>,
    expected: Option<u64>,
) -> PyResult<Store<T>> {
    // The dtype checked against the type the bytes are read as.
    array.cast::<PyArray3<T>>()?;
    let bytes = ArrayBytes::new(array, expected)?;
    let len = bytes.len / size_of::<T>();
    let external =
        External::new(Arc::new(bytes), 0, len).map_err(|e| value_error(e.to_string()))?;
    Ok(Store::External(external))
}

/// A volume over the samples of `array` (from [`normalise`]), without a
/// copy; `expected`, where given, is their [`digest`], which the
/// renderer's [`ExternalBytes::verify`] checks after each frame.
pub fn volume(
    array: &Bound<'_, PyUntypedArray>,
    sample: SampleType,
    spacing: [f64; 3],
    origin: [f64; 3],
    what: &str,
    expected: Option<u64>,
) -> PyResult<Volume> {
    let shape = array.shape();
    let dims = [shape[2], shape[1], shape[0]];
    if dims.iter().any(|&n| n < 2) {
        return Err(value_error(format!(
            "{what}: every axis needs at least two points to be ray cast, but the array has shape {shape:?}"
        )));
    }
    let samples = match sample {
        SampleType::U8 => Samples::U8(store::<u8>(array, expected)?),
        SampleType::I8 => Samples::I8(store::<i8>(array, expected)?),
        SampleType::U16 => Samples::U16(store::<u16>(array, expected)?),
        SampleType::I16 => Samples::I16(store::<i16>(array, expected)?),
        SampleType::F32 => Samples::F32(store::<f32>(array, expected)?),
    };
    let bad = |e: volray_core::VolumeError| value_error(format!("{what}: {e}"));
    Volume::from_samples(dims, samples)
        .map_err(bad)?
        .with_spacing(DVec3::from(spacing))
        .map_err(|e| value_error(format!("spacing: {e}")))?
        .with_origin(DVec3::from(origin))
        .map_err(|e| value_error(format!("origin: {e}")))
}

/// A volume's samples as a C-contiguous numpy array `(nz, ny, nx)`,
/// moved into it without a copy where the volume owns them; read-only
/// unless `writeable`: then numpy refuses to make it (or any view of it)
/// writeable again, as its memory is owned by a Rust object that offers
/// no writeable buffer, so the samples cannot change.
pub fn to_numpy<'py>(
    py: Python<'py>,
    volume: Volume,
    writeable: bool,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    let [nx, ny, nz] = volume.dims();
    fn array<'py, T: Sample + numpy::Element>(
        py: Python<'py>,
        store: Store<T>,
        shape: [usize; 3],
        writeable: bool,
    ) -> PyResult<Bound<'py, PyUntypedArray>> {
        let vec = match store {
            Store::Owned(v) => v,
            Store::External(e) => Store::External(e).to_vec(),
        };
        let flat = numpy::PyArray1::from_vec(py, vec);
        if !writeable {
            // Before the reshape, so that no array over the memory is
            // writeable (numpy lets a view become writeable again while
            // its base is).
            flat.call_method("setflags", (), Some(&[("write", false)].into_py_dict(py)?))?;
        }
        Ok(flat
            .reshape(shape)?
            .into_any()
            .cast_into::<PyUntypedArray>()?)
    }
    let shape = [nz, ny, nx];
    match volume.into_samples() {
        Samples::U8(s) => array(py, s, shape, writeable),
        Samples::I8(s) => array(py, s, shape, writeable),
        Samples::U16(s) => array(py, s, shape, writeable),
        Samples::I16(s) => array(py, s, shape, writeable),
        Samples::F32(s) => array(py, s, shape, writeable),
    }
}

/// The bytes whose digest says whether `object` (an array, or anything
/// numpy takes, handed to a renderer) changed: the array's own memory
/// where it is one contiguous run, else a C-ordered copy (made each time
/// this is asked: the price of a strided view, or of a list).
pub fn watched(object: &Bound<'_, PyAny>) -> PyResult<ArrayBytes> {
    if let Ok(array) = object.cast::<PyUntypedArray>()
        && (array.is_c_contiguous() || array.is_fortran_contiguous())
    {
        return ArrayBytes::new(array, None);
    }
    let np = object.py().import("numpy")?;
    let copy = np.call_method1("ascontiguousarray", (object,))?;
    ArrayBytes::new(copy.cast::<PyUntypedArray>()?, None)
}

/// The `a[x, y, z]` view of samples kept `(nz, ny, nx)`: what Python sees.
pub fn xyz<'py>(stored: &Bound<'py, PyUntypedArray>) -> PyResult<Bound<'py, PyAny>> {
    stored.getattr("T")
}
