//! NumPy `.npy` files (format versions 1.0, 2.0 and 3.0), read and written
//! without NumPy.
//!
//! A `.npy` file is the magic `\x93NUMPY`, a version (major, minor byte),
//! a little-endian header length (`u16` in version 1, `u32` in 2 and 3), a
//! header that is a Python dict literal such as
//! `{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }`, and
//! then the array's bytes.
//!
//! # Axis convention
//!
//! A 3-D array is indexed `a[x, y, z]`, as yt, SciPy and PyVista do: its
//! shape is `(nx, ny, nz)`. A C-order array has z fastest in memory, so it
//! is transposed into volray's x-fastest layout; a Fortran-order array is
//! x-fastest already and is read as is. [`write_npy`] writes Fortran
//! order, so `np.load` gives back `a[x, y, z]` without any copy.

mod header;
mod literal;
#[cfg(test)]
mod tests;

use std::io::Read;
use std::path::Path;

use volray_core::{Volume, VolumeError};

use self::header::{Elem, Header, MAGIC, descr_name, read_header};
use crate::atomic::write_atomically;
use crate::dtype::{Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::geometry::Reorientation;
use crate::shared::input::{open_input, read_samples};
use crate::shared::limits::check_dims;
use crate::shared::mapped::{self, MapPolicy, Plan};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Header bytes are padded so the data starts at a multiple of this.
const ALIGN: usize = 64;

/// Reads the 3-D array in the `.npy` file at `path` as a volume with unit
/// spacing and its origin at zero.
///
/// The array is indexed `a[x, y, z]` (see the module docs). Accepted
/// element types (`descr`, byte order `<`, `>`, `|` or `=`): `b1` (as 0 or
/// 1), `i1 u1 i2 u2 i4 u4 i8 u8` (64-bit ones with `as f32`), `f2 f4 f8`.
/// The header is checked against the file's length before anything is
/// allocated, and the file must end exactly where the data does.
pub fn read_npy(path: &Path) -> Result<Volume, IoError> {
    read_npy_with_info(path, crate::default_max_memory(), MapPolicy::IfLarger).map(|(v, _)| v)
}

/// Reads the `.npy` file at `path` (see [`read_npy`]) within
/// `opts.max_memory`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (volume, info) = read_npy_with_info(path, opts.max_memory, opts.map)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Npy,
        info,
    })
}

/// [`read_npy`], with the header's fields for `volray info`, within
/// `max_memory` bytes: a larger array is mapped from the file where
/// `policy` and its layout allow, refused otherwise.
fn read_npy_with_info(
    path: &Path,
    max_memory: u64,
    policy: MapPolicy,
) -> Result<(Volume, FileInfo), IoError> {
    let (mut file, file_len) = open_input(path)?;
    let header = read_header(path, &mut file, file_len)?;
    let [nx, ny, nz] = header.shape;
    if nx < 2 || ny < 2 || nz < 2 {
        return Err(IoError::volume(path, VolumeError::TooThin(nx, ny, nz)));
    }
    // read_header checked count · size against the file, so no overflow.
    let stored = header.elem.stored();
    let count = nx * ny * nz;
    // C order has z fastest: mapped only in the file's own axis order
    // (z, y, x), for a reader of boxes that transposes each box.
    let in_file_order = !header.fortran_order && policy == MapPolicy::AlwaysInFileOrder;
    let mappable = match header.elem {
        _ if !header.fortran_order && !in_file_order => Err(
            "C order: a[x, y, z] has z fastest and is transposed as it is read; save it with np.asfortranarray".to_string(),
        ),
        Elem::Plain(d, e) => mapped::mappable(d, e, header.data_offset),
        _ => Err(format!("{} elements are converted as they are read", descr_name(header.elem))),
    };
    let plan = mapped::plan(
        policy,
        mappable,
        check_dims(
            path,
            "shape",
            &header.shape,
            stored.bytes() as u64,
            max_memory,
        ),
    )?;
    let data = match (plan, header.elem) {
        (Plan::Map, Elem::Plain(d, _)) => mapped::map_samples(path, header.data_offset, d, count)?,
        _ => read_as_stored!(stored, |T| read_data::<T>(path, &mut file, &header, count))?,
    };
    let mut info = header_info(&header);
    let dims = if plan == Plan::Map && !header.fortran_order {
        // Index axes z, y, x in the file, each along its world axis.
        info.notes.push(
            "C order, mapped in the file's own axis order (z fastest); each box read is transposed to x fastest".into(),
        );
        info.reorientation = Some(Reorientation {
            file_dims: [nz, ny, nx],
            world_axis: [2, 1, 0],
            flipped: [false; 3],
            spacing: volray_core::glam::DVec3::ONE,
            origin: volray_core::glam::DVec3::ZERO,
        });
        [nz, ny, nx]
    } else {
        if !header.fortran_order {
            info.notes
                .push("C order: the array a[x, y, z] was transposed to x fastest".into());
        }
        header.shape
    };
    let volume = Volume::from_samples(dims, data).map_err(|e| IoError::volume(path, e))?;
    if plan == Plan::Map {
        info.notes.push(mapped::mapped_note(&volume));
    }
    Ok((volume, info))
}

/// What `header` says, for `volray info`: the stored type and the fields.
fn header_info(header: &Header) -> FileInfo {
    let elem = header.elem;
    let [nx, ny, nz] = header.shape;
    let mut info = FileInfo::new(descr_name(elem));
    info.header = vec![
        ("descr".into(), descr_name(elem)),
        (
            "fortran_order".into(),
            if header.fortran_order {
                "True"
            } else {
                "False"
            }
            .into(),
        ),
        ("shape".into(), format!("({nx}, {ny}, {nz})")),
    ];
    info
}

/// The 3-D array of the `.npy` bytes `reader` gives, `len` of them (a
/// member of an `.npz` archive, `formats/npz.rs`), read into memory
/// within `max_memory` (never mapped): as [`read_npy`] reads a file.
pub(crate) fn read_stream(
    path: &Path,
    reader: &mut impl Read,
    len: u64,
    max_memory: u64,
) -> Result<(Volume, FileInfo), IoError> {
    let header = read_header(path, reader, len)?;
    let [nx, ny, nz] = header.shape;
    if nx < 2 || ny < 2 || nz < 2 {
        return Err(IoError::volume(path, VolumeError::TooThin(nx, ny, nz)));
    }
    let stored = header.elem.stored();
    let count = check_dims(
        path,
        "shape",
        &header.shape,
        stored.bytes() as u64,
        max_memory,
    )?;
    let data = read_as_stored!(stored, |T| read_data::<T>(path, reader, &header, count))?;
    let mut info = header_info(&header);
    if !header.fortran_order {
        info.notes
            .push("C order: the array a[x, y, z] was transposed to x fastest".into());
    }
    let volume = Volume::from_samples(header.shape, data).map_err(|e| IoError::volume(path, e))?;
    Ok((volume, info))
}

/// The `count` samples after the header, x fastest, as `T`.
fn read_data<T: Stored>(
    path: &Path,
    file: &mut impl Read,
    header: &Header,
    count: usize,
) -> Result<Vec<T>, IoError> {
    let [nx, ny, nz] = header.shape;
    let elem = header.elem;
    let fortran = header.fortran_order;
    let decode = |bytes: &[u8], out: &mut Vec<T>| elem.decode(bytes, out);
    // Fortran order is x fastest in the file already; C order has z
    // fastest, so its values are scattered into x-fastest order.
    let mut data = if fortran {
        Vec::with_capacity(count)
    } else {
        vec![T::default(); count]
    };
    let (mut x, mut y, mut z) = (0usize, 0usize, 0usize);
    read_samples(
        path,
        file,
        count,
        elem.size(),
        header.data_offset,
        decode,
        |values| {
            if fortran {
                data.extend_from_slice(values);
                return;
            }
            for &v in values {
                data[x + nx * (y + ny * z)] = v;
                z += 1;
                if z == nz {
                    z = 0;
                    y += 1;
                    if y == ny {
                        y = 0;
                        x += 1;
                    }
                }
            }
        },
    )?;
    Ok(data)
}

/// Writes `volume` to `path` as a `.npy` file, atomically: format version
/// 1.0, `descr` of its own sample type (`'|u1'`, `'|i1'`, `'<u2'`,
/// `'<i2'`, `'<f4'`), Fortran order, shape `(nx, ny, nz)`, so that
/// `np.load(path)[x, y, z]` is the voxel at `(x, y, z)`. The header is
/// padded so the data starts at a multiple of 64 bytes. Spacing and origin
/// are not stored: `.npy` has no place for them.
pub fn write_npy(path: &Path, volume: &Volume) -> Result<(), IoError> {
    let header = header_text(volume.dims(), volume.sample_type());
    let len = u16::try_from(header.len()).map_err(|_| {
        IoError::npy(
            path,
            format!(".npy header of {} bytes is too long", header.len()),
        )
    })?;
    write_atomically(path, |w| {
        w.write_all(MAGIC)?;
        w.write_all(&[1, 0])?;
        w.write_all(&len.to_le_bytes())?;
        w.write_all(header.as_bytes())?;
        volume
            .samples()
            .try_for_each_le_chunk(1 << 16, |bytes| w.write_all(bytes))?;
        Ok(())
    })
}

/// The version-1.0 header for a Fortran-order array of `dims` samples of
/// type `t` (little-endian), padded with spaces and ended with a newline
/// so that the 10-byte preamble plus the header is a multiple of
/// [`ALIGN`].
fn header_text(dims: [usize; 3], t: volray_core::SampleType) -> String {
    use volray_core::SampleType::*;
    let descr = match t {
        U8 => "|u1",
        I8 => "|i1",
        U16 => "<u2",
        I16 => "<i2",
        F32 => "<f4",
    };
    let mut h = format!(
        "{{'descr': '{descr}', 'fortran_order': True, 'shape': ({}, {}, {}), }}",
        dims[0], dims[1], dims[2]
    );
    let unpadded = 10 + h.len() + 1;
    let pad = (ALIGN - unpadded % ALIGN) % ALIGN;
    h.extend(std::iter::repeat_n(' ', pad));
    h.push('\n');
    h
}
