//! What several readers share: sample types, decompression, opening
//! files, the memory limit, geometry, and the parsing pieces common to a
//! family of formats.
//!
//! | module | what | used by |
//! |---|---|---|
//! | `compress.rs` | gzip and zlib inflated to a declared size | NRRD, MetaImage, NIfTI, VTI, TIFF, DICOM; its ratio bound: HDF5 |
//! | `input.rs` | opening input files, reading samples in bounded chunks | every reader |
//! | `mapped.rs` | volumes over the memory limit mapped from their file (when and why not) | raw, NRRD, MetaImage, NIfTI, npy, MRC, legacy VTK |
//! | `sigbus.rs` | a mapped file truncated under the renderer: an error, not a crash | `mapped.rs` |
//! | `limits.rs` | the memory limit and the size checks before allocating | every reader |
//! | `hdf5.rs` | HDF5 files opened, attributes read, numeric datasets read in slabs (pure Rust) | HDF5, MINC2 |
//! | `hdf5_index.rs` | what hdf5-pure cannot read, through hdf5-reader: layout version 5 and version 2 B-tree chunk indexes, `DIMENSION_LIST` references | HDF5, NetCDF-4 |
//! | `geometry.rs` | a file's grid (origin, step vectors) → the axis-aligned volume | every reader with geometry |
//! | `text_header.rs` | header lines and field values | NRRD, MetaImage |
//! | `payload/` | the data behind a text header: skips, encodings, multi-file lists, frames | NRRD, MetaImage |
//! | `packed.rs` | files behind gzip, bzip2 or xz, known by their first bytes, streamed as they decompress | cube, CHGCAR, legacy VTK, OpenDX, XSF, gOpenMol; the sniffers |
//! | `text_reader.rs` | numbers streamed out of text | cube, CHGCAR, text data of NRRD and MetaImage |
//! | `rescale.rs` | stored values rescaled (slope, intercept), kept in an integer type where exact | NIfTI, DICOM |
//! | `periodic_cell.rs` | skewed periodic cells resampled onto an axis-aligned grid | cube, CHGCAR, MRC |
//! | `vtk_arrays.rs` | choosing the named point or cell array to read | legacy VTK, VTI |
//! | `xml.rs` | an XML element's name and attributes without namespace prefixes | OME-TIFF, BigDataViewer |
//! | `matlab.rs` | the real matrices of a MATLAB `.mat` file (levels 4 and 5) | SPM's Analyze orientation |
//! | `panics.rs` | a panic inside a third-party decoder as an error, with no panic text | DICOM |
//! | `cf.rs` | the CF conventions, format neutral: axes, coordinate variables, packing, fill values | NetCDF-3, MINC1, NetCDF-4 |
//! | `units.rs` | each axis's length unit brought to one (the finest), other units kept apart | OME-Zarr, OME-TIFF, CF, NRRD, MINC, FITS |

pub(crate) mod cf;
pub(crate) mod compress;
pub(crate) mod geometry;
pub(crate) mod hdf5;
pub(crate) mod hdf5_index;
pub(crate) mod input;
pub(crate) mod limits;
pub(crate) mod mapped;
pub(crate) mod matlab;
pub(crate) mod packed;
pub mod panics;
pub(crate) mod payload;
pub(crate) mod periodic_cell;
pub(crate) mod rescale;
pub(crate) mod sigbus;
pub(crate) mod text_header;
pub(crate) mod text_reader;
pub(crate) mod units;
pub(crate) mod vtk_arrays;
pub(crate) mod xml;
