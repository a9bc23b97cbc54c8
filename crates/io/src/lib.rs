//! volray's file formats: getting volumes in and images out.
//!
//! The data path of the renderer is
//!
//! ```text
//! file --read--> Volume --volray-core renders--> Image --write_png / write_exr / Animation--> file
//! ```
//!
//! This crate owns both ends: [`read`] turns a file into a [`Volume`]
//! (x fastest, `index = x + nx·(y + ny·z)`, axis-aligned with the file's
//! spacing and origin) plus a [`FileInfo`] saying what the header said and
//! what was done with it; [`write_png`], [`write_exr`] and [`Animation`]
//! turn [`Image`](volray_core::Image)s into pictures, and [`write_nrrd`],
//! [`write_npy`] and [`write_raw`] write volumes. Every file is written
//! through [`write_atomically`] or [`AtomicFile`], so a failed write never
//! leaves a half-written file. Errors are [`IoError`]s: one-line messages
//! that name the file and the field, split by [`IoError::is_io_failure`]
//! into operating-system failures and bad input. Readers check every
//! header against the file's length before allocating.
//!
//! The format comes from [`ReadOptions::format`], else the file name
//! ([`VolumeFormat::from_path`]), else its magic number
//! ([`VolumeFormat::sniff`]). One module per format, under `formats/`:
//!
//! | format | module | notes |
//! |---|---|---|
//! | raw | `formats/raw.rs` | layout from [`RawOptions`] |
//! | NumPy `.npy` | `formats/npy.rs` | `a[x, y, z]`; C order transposed |
//! | NRRD `.nrrd`, `.nhdr` | `formats/nrrd/` | raw, gzip, ascii, hex; detached and multi-file data; space directions; 4-D frames |
//! | MetaImage `.mha`, `.mhd` | `formats/metaimage/` | raw, zlib; TransformMatrix; 4-D frames |
//! | NIfTI-1/2 `.nii`, `.nii.gz`, `.hdr`/`.img` | `formats/nifti.rs` | scl_slope/inter; sform, else qform, else pixdim (RAS+ mm); 4-D frames |
//! | legacy VTK `.vtk` | `formats/vtk_legacy/` | STRUCTURED_POINTS, ASCII and binary; point and cell data |
//! | VTK XML `.vti` | `formats/vti/` | ascii, base64, appended, zlib; Direction; pieces |
//! | DICOM directory or `.dcm` | `formats/dicom/` | series sorted along the slice normal (LPS mm); enhanced multi-frame; RT dose |
//! | TIFF stacks `.tif` | `formats/tiff.rs` | pages are z; ImageJ spacing; hyperstack frames |
//! | HDF5 `file.h5:/dataset` | `formats/hdf5.rs` | cargo feature `hdf5`; `a[x, y, z]`, `a[t, x, y, z]` |
//! | Gaussian cube `.cube` | `formats/cube.rs` | bohr or Å; orbitals as frames; skewed cells resampled |
//! | CCP4/MRC `.map`, `.mrc` | `formats/mrc.rs` | modes 0, 1, 2, 6, 12; MAPC/R/S; origin |
//! | VASP CHGCAR/CHG | `formats/chgcar/` | divided by the cell volume; periodic plane added; spin blocks as frames |
//!
//! What the readers share is under `shared/` (its module docs list each
//! piece and who uses it): [`grid_to_volume`] (`shared/geometry.rs`) maps
//! a file's grid (origin and one step vector per index axis) onto the
//! axis-aligned volume, reordering and flipping axes exactly;
//! `shared/text_header.rs` reads the lines and field values of NRRD and
//! MetaImage headers, and `shared/payload.rs` their data (skips,
//! encodings, multi-file lists) within the file's bounds;
//! [`inflate_exact`] (`shared/compress.rs`) inflates to a declared size;
//! [`check_volume_size`] (`shared/limits.rs`) checks a header's dimensions
//! for overflow and against [`ReadOptions::max_memory`];
//! `shared/text_reader.rs` streams numbers out of text formats and text
//! data; `shared/periodic_cell.rs` resamples skewed periodic cells;
//! `shared/vtk_arrays.rs` chooses the array of a VTK file.
//!
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
//! assert!(err.to_string().contains("--dims"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod atomic;
mod error;
mod formats;
mod images;
mod shared;

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use volray_core::Volume;

pub use atomic::{AtomicFile, remove_unfinished_files, write_atomically};
pub use error::IoError;
pub use formats::npy::{read_npy, write_npy};
pub use formats::nrrd::write_nrrd;
pub use formats::raw::{RawOptions, read_raw, write_raw};
pub use images::animation::{Animation, AnimationKind, sequence_path};
pub use images::exr::write_exr;
pub use images::png::{BitDepth, quantize_8, quantize_16, write_png};
pub use shared::compress::{Compression, inflate_exact};
pub use shared::dtype::{DType, Endian, ParseNameError, bytes_to_f32, extend_f32, f16_to_f32};
pub use shared::geometry::grid_to_volume;
pub use shared::limits::{
    FALLBACK_MAX_MEMORY, check_memory, check_volume_size, count_values, default_max_memory,
    format_bytes, parse_size,
};

/// The volume file formats volray reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VolumeFormat {
    /// Headerless samples laid out by [`RawOptions`].
    Raw,
    /// NumPy `.npy`.
    Npy,
    /// NRRD: `.nrrd` (attached) and `.nhdr` (detached header).
    Nrrd,
    /// MetaImage: `.mha` (attached) and `.mhd` (detached data).
    MetaImage,
    /// NIfTI-1 and NIfTI-2: `.nii`, `.nii.gz`.
    Nifti,
    /// Legacy VTK `.vtk` STRUCTURED_POINTS, ASCII or binary.
    VtkLegacy,
    /// VTK XML image data `.vti`.
    Vti,
    /// DICOM: a directory of slices, or one multi-frame file (`.dcm`).
    Dicom,
    /// Multi-page TIFF stacks (`.tif`, `.tiff`).
    Tiff,
    /// An HDF5 dataset, `file.h5:/path/to/dataset` (cargo feature `hdf5`).
    Hdf5,
    /// Gaussian cube (`.cube`, `.cub`).
    Cube,
    /// CCP4 / MRC maps (`.map`, `.mrc`, `.ccp4`).
    Mrc,
    /// VASP CHGCAR / CHG (by file name).
    Chgcar,
}

impl VolumeFormat {
    /// Every format, in the order `--format` lists them.
    pub const ALL: [VolumeFormat; 13] = [
        VolumeFormat::Raw,
        VolumeFormat::Npy,
        VolumeFormat::Nrrd,
        VolumeFormat::MetaImage,
        VolumeFormat::Nifti,
        VolumeFormat::VtkLegacy,
        VolumeFormat::Vti,
        VolumeFormat::Dicom,
        VolumeFormat::Tiff,
        VolumeFormat::Hdf5,
        VolumeFormat::Cube,
        VolumeFormat::Mrc,
        VolumeFormat::Chgcar,
    ];

    /// The file kinds detected without `--format`, for messages.
    pub const KNOWN: &'static str = ".npy, .nrrd/.nhdr, .mha/.mhd, .nii/.nii.gz, .vtk, .vti, DICOM (.dcm or a directory), .tif/.tiff, .h5:/dataset, .cube, .map/.mrc/.ccp4, CHGCAR/CHG";

    /// The name `--format` takes.
    pub fn name(self) -> &'static str {
        match self {
            VolumeFormat::Raw => "raw",
            VolumeFormat::Npy => "npy",
            VolumeFormat::Nrrd => "nrrd",
            VolumeFormat::MetaImage => "metaimage",
            VolumeFormat::Nifti => "nifti",
            VolumeFormat::VtkLegacy => "vtk",
            VolumeFormat::Vti => "vti",
            VolumeFormat::Dicom => "dicom",
            VolumeFormat::Tiff => "tiff",
            VolumeFormat::Hdf5 => "hdf5",
            VolumeFormat::Cube => "cube",
            VolumeFormat::Mrc => "mrc",
            VolumeFormat::Chgcar => "chgcar",
        }
    }

    /// A human name for messages and `volray info`.
    pub fn description(self) -> &'static str {
        match self {
            VolumeFormat::Raw => "raw samples",
            VolumeFormat::Npy => "NumPy .npy",
            VolumeFormat::Nrrd => "NRRD",
            VolumeFormat::MetaImage => "MetaImage",
            VolumeFormat::Nifti => "NIfTI",
            VolumeFormat::VtkLegacy => "legacy VTK structured points",
            VolumeFormat::Vti => "VTK XML image data",
            VolumeFormat::Dicom => "DICOM",
            VolumeFormat::Tiff => "TIFF stack",
            VolumeFormat::Hdf5 => "HDF5 dataset",
            VolumeFormat::Cube => "Gaussian cube",
            VolumeFormat::Mrc => "CCP4/MRC map",
            VolumeFormat::Chgcar => "VASP CHGCAR/CHG",
        }
    }

    /// The format a file name announces, if any: its extension
    /// (case-insensitive; `.nii.gz` counts as NIfTI), or a VASP name
    /// (`CHGCAR`, `CHG`, `AECCAR0`, `PARCHG`, ... with any suffix).
    pub fn from_path(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        if name.ends_with(".nii.gz") {
            return Some(VolumeFormat::Nifti);
        }
        if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
            let format = match ext.to_ascii_lowercase().as_str() {
                "npy" => Some(VolumeFormat::Npy),
                "nrrd" | "nhdr" => Some(VolumeFormat::Nrrd),
                "mha" | "mhd" => Some(VolumeFormat::MetaImage),
                "nii" => Some(VolumeFormat::Nifti),
                "vtk" => Some(VolumeFormat::VtkLegacy),
                "vti" => Some(VolumeFormat::Vti),
                "dcm" | "dicom" => Some(VolumeFormat::Dicom),
                "tif" | "tiff" => Some(VolumeFormat::Tiff),
                "h5" | "hdf5" | "he5" => Some(VolumeFormat::Hdf5),
                "cube" | "cub" => Some(VolumeFormat::Cube),
                "map" | "mrc" | "ccp4" | "mrcs" => Some(VolumeFormat::Mrc),
                "raw" => Some(VolumeFormat::Raw),
                _ => None,
            };
            if format.is_some() {
                return format;
            }
        }
        let stem = name.split(['.', '_', '-']).next().unwrap_or("");
        match stem {
            "chgcar" | "chg" | "aeccar0" | "aeccar1" | "aeccar2" | "parchg" | "elfcar"
            | "locpot" => Some(VolumeFormat::Chgcar),
            _ => None,
        }
    }

    /// The format the first bytes of a file show, if they carry a magic
    /// number (`head` should hold at least the first 1024 bytes, or the
    /// whole file if shorter).
    pub fn sniff(head: &[u8]) -> Option<Self> {
        let at =
            |offset: usize, magic: &[u8]| head.get(offset..offset + magic.len()) == Some(magic);
        if at(0, b"\x93NUMPY") {
            Some(VolumeFormat::Npy)
        } else if at(0, b"NRRD000") {
            Some(VolumeFormat::Nrrd)
        } else if at(0, b"# vtk DataFile") {
            Some(VolumeFormat::VtkLegacy)
        } else if at(128, b"DICM") {
            Some(VolumeFormat::Dicom)
        } else if at(0, b"II*\0") || at(0, b"MM\0*") || at(0, b"II+\0") || at(0, b"MM\0+") {
            Some(VolumeFormat::Tiff)
        } else if at(0, b"\x89HDF\r\n\x1a\n") {
            Some(VolumeFormat::Hdf5)
        } else if at(208, b"MAP ") {
            Some(VolumeFormat::Mrc)
        } else if at(344, b"n+1\0") || at(344, b"ni1\0") || at(4, b"n+2\0") || at(4, b"ni2\0") {
            Some(VolumeFormat::Nifti)
        } else if head.starts_with(&[0x1f, 0x8b]) {
            // gzip: in volray's formats only .nii.gz is a gzip file.
            Some(VolumeFormat::Nifti)
        } else {
            let text = String::from_utf8_lossy(&head[..head.len().min(1024)]);
            if text.trim_start().starts_with("<?xml") || text.trim_start().starts_with("<VTKFile") {
                text.contains("ImageData").then_some(VolumeFormat::Vti)
            } else if text.lines().take(4).any(|l| {
                let key = l.split('=').next().unwrap_or("").trim();
                matches!(key, "ObjectType" | "NDims")
            }) {
                Some(VolumeFormat::MetaImage)
            } else {
                None
            }
        }
    }
}

impl fmt::Display for VolumeFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for VolumeFormat {
    type Err = ParseNameError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        VolumeFormat::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| ParseNameError {
                what: "format",
                given: s.to_string(),
                accepted: "raw, npy, nrrd, metaimage, nifti, vtk, vti, dicom, tiff, hdf5, cube, mrc, chgcar",
            })
    }
}

/// How to read a file: everything a reader may need beyond the path.
#[derive(Debug, Clone)]
pub struct ReadOptions {
    /// Read as this format, whatever the name and content say (`--format`).
    pub format: Option<VolumeFormat>,
    /// The layout of a raw file (`--dims`, `--dtype`, `--endian`, `--spacing`).
    pub raw: Option<RawOptions>,
    /// Which volume of a file holding several, counted from 0 (`--frame`):
    /// the 4th dimension of NIfTI, NRRD, MetaImage and HDF5, the orbital of
    /// a cube file, the frame set of a TIFF stack, the density block of a
    /// CHGCAR (0 total, 1 magnetisation).
    pub frame: Option<usize>,
    /// Which named array of a file holding several (`--array`): VTK point
    /// or cell data arrays.
    pub array: Option<String>,
    /// The most bytes the decoded volume and the reader's whole-payload
    /// buffers may take (`--max-memory`): a header asking for more is
    /// refused before anything is allocated (see [`check_volume_size`]).
    /// Default: [`default_max_memory`], half the physical memory.
    pub max_memory: u64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            format: None,
            raw: None,
            frame: None,
            array: None,
            max_memory: default_max_memory(),
        }
    }
}

/// A volume read from a file, with what the file said about it.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub volume: Volume,
    pub format: VolumeFormat,
    pub info: FileInfo,
}

/// What a file's header said and how the reader used it, for `volray info`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FileInfo {
    /// The stored sample type as the file names it, e.g. `"int16 (big-endian)"`.
    pub stored_type: String,
    /// The header's fields as written, in file order (`key`, `value`).
    pub header: Vec<(String, String)>,
    /// What was done to the data beyond decoding: scaling applied
    /// (`scl_slope`, Rescale Slope, cell volume), axes reordered or
    /// flipped, cell data turned into points, units converted, header
    /// fields ignored.
    pub notes: Vec<String>,
    /// The unit of spacing and origin, as the file gives it (`"mm"`,
    /// `"bohr"`, `"angstrom"`), if it gives one.
    pub length_unit: Option<String>,
    /// How many volumes the file holds (4th dimension, orbitals, arrays);
    /// 1 for most files.
    pub frames: usize,
    /// Which of them was read.
    pub frame: usize,
    /// The named arrays the file holds (VTK), if any, and the one read.
    pub arrays: Vec<String>,
    pub array: Option<String>,
}

impl FileInfo {
    /// A `FileInfo` for a file holding one volume of `stored_type`.
    pub fn new(stored_type: impl Into<String>) -> Self {
        FileInfo {
            stored_type: stored_type.into(),
            frames: 1,
            ..FileInfo::default()
        }
    }
}

/// Reads the volume at `path` (see [`read`]): the volume only.
pub fn read_volume(path: &Path, raw: Option<&RawOptions>) -> Result<Volume, IoError> {
    let opts = ReadOptions {
        raw: raw.cloned(),
        ..ReadOptions::default()
    };
    read(path, &opts).map(|l| l.volume)
}

/// Reads the volume at `path`.
///
/// The format is `opts.format` if given, else the one the file name
/// announces ([`VolumeFormat::from_path`]), else the one its first bytes
/// show ([`VolumeFormat::sniff`]); a directory is a DICOM series. Raw
/// layout options apply to raw files only. An HDF5 dataset is named as
/// `file.h5:/group/dataset`.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let format = detect(path, opts)?;
    if opts.raw.is_some() && format != VolumeFormat::Raw {
        return Err(IoError::RawOptionsNotApplicable {
            path: path.to_path_buf(),
            format: format.description(),
        });
    }
    if opts.frame.is_some()
        && !matches!(
            format,
            VolumeFormat::Nrrd
                | VolumeFormat::MetaImage
                | VolumeFormat::Nifti
                | VolumeFormat::Dicom
                | VolumeFormat::Tiff
                | VolumeFormat::Hdf5
                | VolumeFormat::Cube
                | VolumeFormat::Chgcar
        )
    {
        return Err(IoError::invalid(
            path,
            format!(
                "--frame does not apply to {} files: they hold one volume",
                format.description()
            ),
        ));
    }
    if opts.array.is_some() && !matches!(format, VolumeFormat::VtkLegacy | VolumeFormat::Vti) {
        return Err(IoError::invalid(
            path,
            format!(
                "--array applies to VTK files only, not to {} files",
                format.description()
            ),
        ));
    }
    match format {
        VolumeFormat::Raw => match &opts.raw {
            Some(raw) => {
                let volume = formats::raw::read_raw_limited(path, raw, opts.max_memory)?;
                let info = FileInfo::new(format!("{} ({}-endian)", raw.dtype, raw.endian));
                Ok(Loaded {
                    volume,
                    format,
                    info,
                })
            }
            None => Err(IoError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        },
        VolumeFormat::Npy => {
            let (volume, info) = formats::npy::read_npy_with_info(path, opts.max_memory)?;
            Ok(Loaded {
                volume,
                format,
                info,
            })
        }
        VolumeFormat::Nrrd => formats::nrrd::read(path, opts),
        VolumeFormat::MetaImage => formats::metaimage::read(path, opts),
        VolumeFormat::Nifti => formats::nifti::read(path, opts),
        VolumeFormat::VtkLegacy => formats::vtk_legacy::read(path, opts),
        VolumeFormat::Vti => formats::vti::read(path, opts),
        VolumeFormat::Dicom => formats::dicom::read(path, opts),
        VolumeFormat::Tiff => formats::tiff::read(path, opts),
        VolumeFormat::Hdf5 => read_hdf5(path, opts),
        VolumeFormat::Cube => formats::cube::read(path, opts),
        VolumeFormat::Mrc => formats::mrc::read(path, opts),
        VolumeFormat::Chgcar => formats::chgcar::read(path, opts),
    }
}

/// Splits `file.h5:/group/dataset` into the file and the dataset path,
/// if `path` has that shape and is not itself an existing file.
pub fn split_hdf5_path(path: &Path) -> Option<(PathBuf, String)> {
    if path.exists() {
        return None;
    }
    let s = path.to_str()?;
    let lower = s.to_ascii_lowercase();
    [".h5:", ".hdf5:", ".he5:"].iter().find_map(|ext| {
        let at = lower.find(ext)? + ext.len() - 1;
        Some((PathBuf::from(&s[..at]), s[at + 1..].to_string()))
    })
}

#[cfg(feature = "hdf5")]
fn read_hdf5(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    formats::hdf5::read(path, opts)
}

#[cfg(not(feature = "hdf5"))]
fn read_hdf5(path: &Path, _opts: &ReadOptions) -> Result<Loaded, IoError> {
    Err(IoError::invalid(
        path,
        "this volray was built without HDF5 support: rebuild with `cargo build --release --features hdf5` (needs Debian's libhdf5-dev)",
    ))
}

/// The format to read `path` as: see [`read`].
fn detect(path: &Path, opts: &ReadOptions) -> Result<VolumeFormat, IoError> {
    if let Some(format) = opts.format {
        return Ok(format);
    }
    if split_hdf5_path(path).is_some() {
        return Ok(VolumeFormat::Hdf5);
    }
    if path.is_dir() {
        return Ok(VolumeFormat::Dicom);
    }
    if let Some(format) = VolumeFormat::from_path(path) {
        return Ok(format);
    }
    if opts.raw.is_some() {
        return Ok(VolumeFormat::Raw);
    }
    let mut head = Vec::with_capacity(1024);
    let (file, _) = shared::input::open_input(path)?;
    use std::io::Read;
    file.take(1024)
        .read_to_end(&mut head)
        .map_err(|e| IoError::os(path, "read", e))?;
    VolumeFormat::sniff(&head).ok_or_else(|| IoError::UnknownFormat {
        path: path.to_path_buf(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_by_extension() {
        let dir = tempfile::tempdir().unwrap();
        let v = Volume::new([2, 2, 3], (0..12).map(|i| i as f32).collect()).unwrap();
        let upper = dir.path().join("V.NPY");
        write_npy(&upper, &v).unwrap();
        assert_eq!(read_volume(&upper, None).unwrap(), v);

        let opts = RawOptions::new([2, 2, 3], DType::F32);
        let err = read_volume(&upper, Some(&opts)).unwrap_err();
        assert!(!err.is_io_failure());
        assert!(
            err.to_string().ends_with(
                "raw options (--dims, --dtype, --endian) do not apply to NumPy .npy files"
            ),
            "{err}"
        );

        // A .npy file under another name is known by its magic, unless a
        // raw layout is given; a file with neither is refused.
        let renamed = dir.path().join("v.bin");
        std::fs::copy(&upper, &renamed).unwrap();
        assert_eq!(read_volume(&renamed, None).unwrap(), v);
        let err = read_volume(&renamed, Some(&opts)).unwrap_err();
        assert!(matches!(err, IoError::RawSizeMismatch { .. }), "{err}");
        let unknown = dir.path().join("v.dat");
        std::fs::write(&unknown, [7u8; 48]).unwrap();
        let err = read_volume(&unknown, None).unwrap_err();
        assert!(matches!(err, IoError::UnknownFormat { .. }), "{err}");
        assert!(err.to_string().starts_with(&unknown.display().to_string()));

        // Missing .npy file: an I/O failure.
        let err = read_volume(&dir.path().join("gone.npy"), None).unwrap_err();
        assert!(err.is_io_failure());
    }

    #[test]
    fn format_detection() {
        assert_eq!(
            VolumeFormat::from_path(Path::new("a/b.Npy")),
            Some(VolumeFormat::Npy)
        );
        assert_eq!(VolumeFormat::from_path(Path::new("a/npy")), None);
        assert_eq!(
            VolumeFormat::from_path(Path::new("b.npy.raw")),
            Some(VolumeFormat::Raw)
        );
        assert_eq!(
            VolumeFormat::from_path(Path::new("x/brain.NII.gz")),
            Some(VolumeFormat::Nifti)
        );
        assert_eq!(
            VolumeFormat::from_path(Path::new("run1/CHGCAR")),
            Some(VolumeFormat::Chgcar)
        );
        assert_eq!(
            VolumeFormat::from_path(Path::new("CHGCAR_relaxed")),
            Some(VolumeFormat::Chgcar)
        );
        assert_eq!(VolumeFormat::from_path(Path::new("charge.dat")), None);
        for f in VolumeFormat::ALL {
            assert_eq!(f.name().parse::<VolumeFormat>(), Ok(f));
        }
        let mut mrc = vec![0u8; 1024];
        mrc[208..212].copy_from_slice(b"MAP ");
        assert_eq!(VolumeFormat::sniff(&mrc), Some(VolumeFormat::Mrc));
        assert_eq!(
            VolumeFormat::sniff(b"NRRD0004\ntype: float\n"),
            Some(VolumeFormat::Nrrd)
        );
        assert_eq!(
            VolumeFormat::sniff(b"ObjectType = Image\nNDims = 3\n"),
            Some(VolumeFormat::MetaImage)
        );
        assert_eq!(
            VolumeFormat::sniff(b"<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\">"),
            Some(VolumeFormat::Vti)
        );
        assert_eq!(VolumeFormat::sniff(b"hello"), None);
        assert_eq!(
            split_hdf5_path(Path::new("/no/such/run.h5:/fields/rho")),
            Some((PathBuf::from("/no/such/run.h5"), "/fields/rho".to_string()))
        );
        assert_eq!(split_hdf5_path(Path::new("/no/such/run.nrrd")), None);
    }
}
