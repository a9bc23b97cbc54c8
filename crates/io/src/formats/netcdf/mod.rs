//! NetCDF (`.nc`, `.cdf`, `.nc3`): NetCDF-3 files, CDF-1 (classic), CDF-2
//! (64-bit offset) and CDF-5 (64-bit data), read with the CF conventions
//! (`shared/cf.rs`); a NetCDF-4 file, which is HDF5, goes to the HDF5
//! route, and a MINC1 file (NetCDF-3 in libminc's layout) to
//! `formats/minc1.rs`, which reads it on this reader's layer
//! (`header.rs`: the header, and the values of a variable).
//!
//! - The header (`header.rs`) is parsed by a small own parser rather than
//!   the `netcdf3` crate: that crate reads a variable only whole (its
//!   documented limitation), which a frame of a record variable or a box
//!   of a large one should not need, it knows the classic and 64-bit
//!   offset versions but not CDF-5, and it brings nom and byteorder for a
//!   format whose header is four lists of big-endian words. Here every
//!   count, offset and size is checked against the file's length, and the
//!   volume against [`ReadOptions::max_memory`], before anything is
//!   allocated.
//! - Types: byte, char (refused as data), short, int, float, double and
//!   CDF-5's ubyte, ushort, uint, int64, uint64, all big-endian, widened
//!   to `f64`, packed values unpacked (CF `scale_factor`, `add_offset`),
//!   fill values and values outside the valid range read as NaN (empty
//!   space), and kept as `f32`.
//! - The record (unlimited) dimension: a record variable's part of record
//!   `r` lies at `begin + r · recsize`, its records interleaved with the
//!   other record variables' (each padded to 4 bytes, but for a single
//!   record variable); only the frame read is read.
//! - Which variable, which axes, spacing, origin, units and frames: CF
//!   (`shared/cf.rs`).
//! - Not done: the NetCDF default fill values (a variable without
//!   `_FillValue` keeps every stored value, as xarray does; netCDF4-python
//!   masks the type's default fill), the `_Unsigned` attribute of
//!   NetCDF-3 bytes, and box-by-box (lazy) reads: a variable is read
//!   whole, a frame at a time, within `--max-memory`.

pub(crate) mod header;

use std::io::Read;
use std::path::Path;

use crate::error::IoError;
use crate::shared::cf::{self, Packing};
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::check_frame_size;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

use header::{Header, NcType, check_in_file, open, read_values, small_values};

/// Reads the NetCDF file at `path`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    if is_netcdf4(path) {
        // A NetCDF-4 file: HDF5 underneath, read with the same CF rules.
        return super::netcdf4::read(path, opts);
    }
    let (file, header) = open(path)?;
    if super::minc1::is_minc1(&header) {
        return super::minc1::read_parsed(path, opts, file, header);
    }
    read_cf(path, opts, file, header)
}

/// Whether `path` is a NetCDF-4 file (HDF5 underneath), or names a
/// variable in one (`file.nc:/var`).
pub(crate) fn is_netcdf4(path: &Path) -> bool {
    match crate::split_hdf5_path(path) {
        Some((file, _)) => is_hdf5(&file),
        None => is_hdf5(path),
    }
}

/// Whether the file at `path` starts with HDF5's signature (a NetCDF-4
/// file); false where it cannot be read (the reader then says why).
pub(crate) fn is_hdf5(path: &Path) -> bool {
    let mut magic = [0u8; 8];
    // Not opened unless a regular file: opening a FIFO blocks.
    std::fs::metadata(path).is_ok_and(|m| m.is_file())
        && std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut magic))
            .is_ok()
        && &magic == b"\x89HDF\r\n\x1a\n"
}

/// The variables of `header` as CF sees them.
pub(crate) fn cf_variables(header: &Header) -> Vec<cf::Variable> {
    header
        .vars
        .iter()
        .map(|v| cf::Variable {
            name: v.name.clone(),
            dims: v
                .dims
                .iter()
                .map(|&d| header.dims[d].name.clone())
                .collect(),
            shape: header.shape(v),
            attrs: v.attrs.clone(),
            type_name: v.ty.name().to_string(),
            integer: v.ty.is_integer(),
        })
        .collect()
}

/// The version as `volray info` shows it.
fn version_name(version: u8) -> &'static str {
    match version {
        1 => "NetCDF-3 classic (CDF-1)",
        2 => "NetCDF-3 64-bit offset (CDF-2)",
        _ => "NetCDF-3 64-bit data (CDF-5)",
    }
}

/// Reads the CF variable of a parsed NetCDF-3 file.
fn read_cf(
    path: &Path,
    opts: &ReadOptions,
    mut file: std::fs::File,
    header: Header,
) -> Result<Loaded, IoError> {
    let vars = cf_variables(&header);
    let var = cf::choose(path, &vars, opts.array.as_deref())?;
    let index = vars.iter().position(|v| v.name == var.name).unwrap_or(0);
    let nc = &header.vars[index];
    let layout = cf::layout(path, var, &vars, opts.frame)?;
    if nc.ty == NcType::Char {
        return Err(IoError::invalid(
            path,
            format!("variable {} holds characters, not numbers", var.name),
        ));
    }
    let shape = &var.shape;
    let voxels = check_frame_size(
        path,
        &format!("variable {} shape", var.name),
        shape,
        layout.frames as u64,
        4,
        opts.max_memory,
    )? / layout.frames;

    let mut info = FileInfo::new(format!("{} (big-endian)", nc.ty.name()));
    info.header
        .push(("format".into(), version_name(header.version).into()));
    let dims: Vec<(String, u64, bool)> = header
        .dims
        .iter()
        .map(|d| (d.name.clone(), d.len, d.record))
        .collect();
    cf::describe(&dims, &header.attrs, &vars, var, &layout, &mut info);

    let packing = Packing::of(path, var)?;
    let mut coordinate = |c: &cf::Variable| -> Result<Vec<f64>, IoError> {
        let i = vars.iter().position(|v| v.name == c.name).unwrap_or(0);
        let p = Packing::of(path, c)?;
        small_values(path, &mut file, &header, &header.vars[i], Some(&p), 1 << 24)
    };
    let placement = cf::place(path, var, &vars, &layout, &mut coordinate, &mut info)?;
    if let Some(d) = layout.frame_dim
        && let Some(t) = cf::coordinate(&vars, &var.dims[d])
        && let Ok(values) = coordinate(t)
        && let Some(value) = values.get(layout.frame)
    {
        info.notes.push(format!(
            "frame {}: {} = {value}{}",
            layout.frame,
            t.name,
            t.text("units")
                .map(|u| format!(" ({u})"))
                .unwrap_or_default()
        ));
    }
    if let Some(note) = packing.note(&var.name) {
        info.notes.push(note);
    }
    info.nan_is_empty = !packing.missing.is_empty() || packing.lo.is_some() || packing.hi.is_some();
    info.length_unit = placement.length_unit.clone();
    info.axis_units = placement.axis_units.clone();

    // The slab: the frame along the frame dimension, every other
    // non-spatial dimension (length 1) at 0; C order keeps the spatial
    // dimensions in the variable's order, the last fastest. Its last
    // element must lie in the file before the volume is allocated.
    let (outer, inner, along) = match layout.frame_dim {
        Some(f) => (
            shape[..f].iter().product::<u64>(),
            shape[f + 1..].iter().product::<u64>(),
            shape[f],
        ),
        None => (1, voxels as u64, 1),
    };
    let last = ((outer - 1) * along + layout.frame as u64) * inner + inner - 1;
    check_in_file(path, &header, nc, last)?;
    let mut data = vec![0f32; voxels];
    let mut at = 0usize;
    for o in 0..outer {
        let first = (o * along + layout.frame as u64) * inner;
        read_values(
            path,
            &mut file,
            &header,
            nc,
            first,
            inner as usize,
            &mut |i, v| {
                data[at + i] = packing.real(v) as f32;
            },
        )?;
        at += inner as usize;
    }
    let volume = grid_to_volume(
        path,
        placement.dims,
        data,
        placement.steps,
        placement.origin,
        &mut info,
    )?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Netcdf,
        info,
    })
}
