//! volray's file formats: getting volumes in and images out.
//!
//! The data path of the renderer is
//!
//! ```text
//! file --read--> Volume --volray-core renders--> Image --write_png / write_exr / Animation--> file
//! ```
//!
//! This crate owns both ends: [`read`] turns a file into a [`Volume`](volray_core::Volume)
//! (x fastest, `index = x + nx·(y + ny·z)`, axis-aligned with the file's
//! spacing and origin) plus a [`FileInfo`] saying what the header said and
//! what was done with it; [`write_png`], [`write_exr`] and [`Animation`]
//! turn [`Image`](volray_core::Image)s into pictures, and [`write_nrrd`],
//! [`write_npy`] and [`write_raw`] write volumes, [`write_ome_zarr`] an
//! OME-Zarr image with its pyramid (from any
//! [`VolumeSource`](volray_core::VolumeSource), in bounded memory). Every
//! file is written through [`write_atomically`] or [`AtomicFile`] (a Zarr
//! store through [`AtomicDir`]), so a failed write never leaves a
//! half-written file. Errors are [`IoError`]s: one-line messages
//! that name the file and the field, split by [`IoError::is_io_failure`]
//! into operating-system failures and bad input; an error a reader option
//! caused (a frame out of range, the memory limit) has a variant of its
//! own, so that a caller can name the option its own way. Readers check
//! every header against the file's length before allocating.
//!
//! The format comes from [`ReadOptions::format`], else the file name
//! ([`VolumeFormat::from_path`]), else its content ([`VolumeFormat::sniff`]:
//! a magic number, or the structure of a cube or VASP text header). One
//! module per format, under `formats/`:
//!
//! | format | module | notes |
//! |---|---|---|
//! | raw | `formats/raw.rs` | layout from [`RawOptions`] |
//! | NumPy `.npy` | `formats/npy/` | `a[x, y, z]`; C order transposed |
//! | NRRD `.nrrd`, `.nhdr` | `formats/nrrd/` | raw, gzip, bzip2, ascii, hex; detached and multi-file data; space directions; 4-D frames |
//! | MetaImage `.mha`, `.mhd` | `formats/metaimage/` | raw, zlib; TransformMatrix; 4-D frames |
//! | NIfTI-1/2 `.nii`, `.nii.gz`, `.hdr`/`.img` | `formats/nifti/` | scl_slope/inter; sform, else qform, else pixdim (RAS+ mm); 4-D frames; 5-D components as frames; sheared sform resampled, NaN outside ([`FileInfo::nan_is_empty`]) |
//! | legacy VTK `.vtk` | `formats/vtk_legacy/` | STRUCTURED_POINTS, ASCII and binary; point and cell data |
//! | VTK XML `.vti` | `formats/vti/` | ascii, base64, appended, zlib, LZ4, LZMA; Direction; pieces |
//! | DICOM directory (a DICOMDIR's file-set, subfolders) or `.dcm` | `formats/dicom/` | series sorted along the slice normal (LPS mm); the largest of several, or one named; enhanced multi-frame; RT dose; Segmentations as label volumes; RLE, JPEG, JPEG-LS and JPEG 2000 pixel data |
//! | TIFF stacks `.tif` | `formats/tiff/` | pages are z; ImageJ spacing; hyperstack frames; OME-XML page order, physical sizes and units; else the resolution tags in cm or inch (`tiff/resolution.rs`) |
//! | HDF5 `file.h5:/dataset` | `formats/hdf5.rs` | pure Rust (`hdf5-pure`; `hdf5-reader` for the chunk indexes of HDF5 2.0 and the version 2 B-tree); axes named by `axes`, `axistags`, `DIMENSION_LABELS`, dimension scales (`hdf5_axes.rs`), else `a[x, y, z]`, `a[t, x, y, z]`; chunked, deflate, shuffle |
//! | Gaussian cube `.cube` | `formats/cube.rs` | bohr or Å; orbitals as frames; skewed cells resampled; known by content too |
//! | CCP4/MRC `.map`, `.mrc` | `formats/mrc.rs` | modes 0, 1, 2, 6, 12; MAPC/R/S; origin; skewed: a whole cell resampled periodically, a part (or more) over its box, NaN outside ([`FileInfo::nan_is_empty`]) |
//! | VASP CHGCAR/CHG | `formats/chgcar/` | divided by the cell volume; periodic plane added; spin blocks as frames; known by content too |
//! | MINC2 `.mnc` | `formats/minc.rs` | on the HDF5 layer; dimorder, steps, starts, direction cosines; image-min/max scaling as nibabel |
//! | Zarr v2/v3, OME-Zarr 0.4/0.5 (a directory) | `formats/zarr/` | through `zarrs` (blosc, zstd, gzip, sharding, fill values); known by `zarr.json`/`.zarray`/`.zgroup`; levels ([`ReadOptions::level`]), time points, channels ([`ReadOptions::channel`]) |
//! | NetCDF-3 `.nc`, `.cdf` (CDF-1, CDF-2, CDF-5) | `formats/netcdf/` | own bounds-checked parser; record dimension; CF conventions (`shared/cf.rs`): axes, coordinate variables, units, packing, fill values; `--frame` (time), `--array` (variable) |
//! | MINC1 `.mnc` (NetCDF-3) | `formats/minc1.rs` | on the NetCDF-3 layer (`netcdf/header.rs`) with MINC2's geometry and scaling (`formats/minc_common.rs`); signtype |
//! | FITS `.fits`, `.fits.gz` | `formats/fits/` | own parser; BITPIX 8 … −64, BSCALE/BZERO, BLANK as NaN; linear WCS (world spacing when the axes share a unit, else pixel coordinates); image HDUs and a 4th axis as frames, `--array EXTNAME` |
//! | FreeSurfer MGH `.mgh`, `.mgz` | `formats/mgh/` | big-endian; nibabel's get_affine (Mdc, delta, Pxyz_c); frames; gzip streamed; known by content too |
//! | Analyze 7.5 `.hdr`/`.img` | `formats/nifti/` | a NIfTI-1 pair without magic; SPM's `.mat` beside it (`nifti/spm.rs`, MATLAB files by `shared/matlab.rs`), else nibabel's affine (x flipped, centre or SPM originator); known by content |
//! | VTKHDF `.vtkhdf` (or an HDF5 file with `/VTKHDF`) | `formats/vtkhdf.rs` | ImageData: extent, origin, spacing; point and cell arrays (`--array`), components (`--channel`); read through `hdf5.rs` and `hdf5_lazy.rs` |
//! | BigDataViewer `dataset.xml` (or its `.h5`) | `formats/bdv/` | SpimData XML (`xml.rs`); setups as channels, time points, levels as OME-Zarr's ([`ReadOptions::level`]); voxel size and registration; int16 as unsigned |
//! | OpenDX `.dx` | `formats/opendx.rs` | APBS, VMD, PyMOL, GridDataFormats; text values (data follows); deltas placed exactly, rotated kept in the grid's axes, skewed resampled over the box; known by content too |
//! | XSF/BXSF `.xsf`, `.bxsf` | `formats/xsf.rs` | XCrySDen, Quantum ESPRESSO, ASE, VESTA; DATAGRID_3D grids as arrays (`--array`), BANDGRID_3D bands as frames; general (periodic) grids, skewed cells resampled; known by content too |
//! | gOpenMol `.plt` | `formats/plt.rs` | binary, either byte order; min..max inclusive (gOpenMol, VMD); known by content too |
//! | NumPy `.npz` | `formats/npz.rs` | `numpy.savez` (stored) and `savez_compressed` (deflated) archives through the `zip` crate; each array as `.npy`; `--array NAME`, the first by default |
//! | GIPL `.gipl`, `.gipl.gz` | `formats/gipl.rs` | ITK's layout: big-endian, i8 … f64; pixdim, origin (no direction: world axes); a 4th axis as frames; known by its magic |
//! | MRtrix `.mif`, `.mih`, `.mif.gz` | `formats/mrtrix.rs` | MRtrix3's header: dim, vox, layout (ranks and reversed axes), datatype, transform (scanner RAS mm), scaling; a 4th axis as frames; known by content too |
//!
//! The text formats (cube, CHGCAR, legacy VTK, OpenDX, XSF), gOpenMol, GIPL
//! and MRtrix are also read inside gzip, bzip2 or xz, known by content (`shared/packed.rs`).
//!
//! A file that holds one image rather than a volume (a single DICOM
//! slice, a 2-D NRRD, NIfTI, MetaImage or HDF5 image, a one-page TIFF) is
//! read and refused as a volume with [`IoError::FlatImage`], which
//! carries what was read ([`FlatImage`]) for a caller that describes it.
//! Formats recognised but not read (PAR/REC, ECAT 7, AFNI, OpenVDB, N5:
//! `formats/not_read.rs`) are refused with [`IoError::NotRead`], which
//! names the format and a tool that converts it.
//!
//! What the readers share is under `shared/` (its module docs list each
//! piece and who uses it): [`grid_to_volume`] (`shared/geometry.rs`) maps
//! a file's grid (origin and one step vector per index axis) onto the
//! axis-aligned volume, reordering and flipping axes exactly;
//! `shared/text_header.rs` reads the lines and field values of NRRD and
//! MetaImage headers, and `shared/payload/` their data (skips,
//! encodings, multi-file lists) within the file's bounds;
//! [`inflate_exact`] (`shared/compress.rs`) decodes gzip, zlib, LZ4 and
//! xz to a declared size;
//! [`check_volume_size`] (`shared/limits.rs`) checks a header's dimensions
//! for overflow and against [`ReadOptions::max_memory`];
//! `shared/text_reader.rs` streams numbers out of text formats and text
//! data; `shared/periodic_cell.rs` resamples skewed periodic cells (and
//! the boxes of skewed maps that are not one cell); `shared/hdf5.rs` opens
//! HDF5 files and reads their attributes and datasets (HDF5, MINC2);
//! `shared/hdf5_index.rs` lists through `hdf5-reader` the chunk indexes
//! `hdf5-pure` cannot read (HDF5 2.0's layout message 5, the version 2
//! B-tree) and follows `DIMENSION_LIST` references (NetCDF-4);
//! `shared/vtk_arrays.rs` chooses the array of a VTK file.
//!
//! The axes beside space are one model for every reader (`axes.rs`):
//! a file holds [`Volumes`], time points of channels (OME's TCZYX), and
//! [`ReadOptions::frame`] picks the time point, [`ReadOptions::channel`]
//! the channel, in every format; [`FileInfo`] says how many of each
//! the file holds and which was read.
//!
//! Sample types and byte orders ([`DType`], [`Endian`]) are in `dtype.rs`.
//! Images are written by `images/` (`png.rs`, `exr.rs`, `animation.rs`),
//! every file through `atomic.rs`.
//!
//! # Example
//!
//! ```
//! use volray_io::{DType, Endian, RawOptions, read_volume};
//! use volray_core::glam::DVec3;
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("ramp.raw");
//! // A 2×2×2 volume of big-endian u16 samples 0, 10, ..., 70, x fastest.
//! let bytes: Vec<u8> = (0..8u16).flat_map(|v| (10 * v).to_be_bytes()).collect();
//! std::fs::write(&path, bytes)?;
//!
//! let opts = RawOptions {
//!     dims: [2, 2, 2],
//!     dtype: DType::U16,
//!     endian: Endian::Big,
//!     spacing: DVec3::new(1.0, 1.0, 2.5),
//! };
//! let volume = read_volume(&path, Some(&opts))?;
//! assert_eq!(volume.dims(), [2, 2, 2]);
//! assert_eq!(volume.get(1, 0, 1), 50.0); // index 1 + 2·(0 + 2·1) = 5
//! assert_eq!(volume.spacing().z, 2.5);
//!
//! // Without a layout, a file that is not .npy is refused.
//! let err = read_volume(&path, None).unwrap_err();
//! assert!(!err.is_io_failure());
//! assert!(matches!(err, volray_io::IoError::UnknownFormat { .. }));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod atomic;
mod axes;
mod dtype;
mod error;
pub mod ffmpeg;
mod formats;
mod images;
mod read;
mod shared;

pub use atomic::{AtomicDir, AtomicFile, remove_unfinished_files, write_atomically};
pub use axes::{AxisNames, Picked, Volumes};
pub use dtype::{
    DType, Endian, ParseNameError, bytes_to_f32, bytes_to_samples, extend_f32, f16_to_f32,
};
pub use error::IoError;
pub use formats::VolumeFormat;
pub use formats::dicom::directory_files as dicom_directory_files;
pub use formats::npy::{read_npy, write_npy};
pub use formats::nrrd::write_nrrd;
pub use formats::raw::{RawOptions, read_raw, write_raw};
pub use formats::zarr::{
    OmeZarrOptions, OmeZarrWritten, WrittenLevel, ZarrVersion, write_ome_zarr,
};
pub use images::animation::{Animation, AnimationKind, sequence_path};
pub use images::exr::write_exr;
pub use images::png::{BitDepth, quantize_8, quantize_16, rgb8, write_png};
pub use read::{
    AxisUnitName, FileInfo, FlatImage, Lazy, LevelInfo, Loaded, OmeroChannel, ReadOptions, Segment,
    open_lazy, read, read_volume, split_hdf5_path, world_axis_names,
};
pub use shared::compress::{Compression, inflate_exact};
pub use shared::geometry::{Reorientation, grid_to_volume};
pub use shared::limits::{
    FALLBACK_MAX_MEMORY, check_memory, check_volume_size, count_values, default_max_memory,
    format_bytes, parse_size,
};
pub use shared::mapped::{MapPolicy, MappedFile};
pub use shared::panics;
