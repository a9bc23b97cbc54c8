//! The volume file formats volray reads: [`VolumeFormat`], the table
//! [`FORMATS`] that says everything about each one, and one module per
//! format.
//!
//! Each module turns a file of its format into a [`Volume`](volray_core::Volume)
//! and a [`FileInfo`](crate::FileInfo); formats volray also writes (raw,
//! `.npy`, NRRD) keep their writer beside their reader. What the readers
//! share lives in `shared/`.
//!
//! Adding a format: a [`VolumeFormat`] variant, its module here with a
//! `read` function, and its row in [`FORMATS`] (in the variant's place).
//! Names, descriptions, detection by file name and by content, the list
//! of names `--format` accepts, the list of known kinds in
//! [`IoError::UnknownFormat`], which reader options apply and the reader
//! itself all come from the row.
//!
//! The file runs past 800 lines because the table is one row per format
//! (25), kept beside the enum it indexes and the detection that reads it.

pub(crate) mod bdv;
pub(crate) mod chgcar;
pub(crate) mod cube;
pub(crate) mod dicom;
pub(crate) mod fits;
pub(crate) mod gipl;
pub(crate) mod hdf5;
pub(crate) mod hdf5_axes;
pub(crate) mod hdf5_lazy;
pub(crate) mod metaimage;
pub(crate) mod mgh;
pub(crate) mod minc;
pub(crate) mod minc1;
pub(crate) mod minc_common;
pub(crate) mod mrc;
pub(crate) mod mrtrix;
pub(crate) mod netcdf;
pub(crate) mod netcdf4;
pub(crate) mod nifti;
pub(crate) mod not_read;
pub(crate) mod npy;
pub(crate) mod npz;
pub(crate) mod nrrd;
pub(crate) mod opendx;
pub(crate) mod plt;
pub(crate) mod raw;
pub(crate) mod tiff;
pub(crate) mod vti;
pub(crate) mod vtk_legacy;
pub(crate) mod vtkhdf;
pub(crate) mod xsf;
pub(crate) mod zarr;

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use crate::dtype::ParseNameError;
use crate::{IoError, Loaded, ReadOptions};

/// The volume file formats volray reads.
///
/// Each variant has its row, in the same order, in the table of formats
/// (`FORMATS` in `formats/mod.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VolumeFormat {
    /// Headerless samples laid out by [`RawOptions`](crate::RawOptions).
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
    /// An HDF5 dataset, `file.h5:/path/to/dataset`.
    Hdf5,
    /// Gaussian cube (`.cube`, `.cub`).
    Cube,
    /// CCP4 / MRC maps (`.map`, `.mrc`, `.ccp4`).
    Mrc,
    /// VASP CHGCAR / CHG and their kin (by file name or content).
    Chgcar,
    /// MINC2 (`.mnc`): HDF5 in libminc's layout.
    Minc,
    /// A Zarr v2 or v3 array, or an OME-Zarr image (a directory).
    Zarr,
    /// NetCDF-3 (`.nc`, `.cdf`, `.nc3`): classic, 64-bit offset and
    /// 64-bit data, and NetCDF-4 (HDF5 underneath, `formats/netcdf4.rs`),
    /// with the CF conventions; a MINC1 file as MINC.
    Netcdf,
    /// FITS images (`.fits`, `.fit`, `.fts`, `.fits.gz`): the primary HDU
    /// and IMAGE extensions.
    Fits,
    /// FreeSurfer MGH (`.mgh`) and gzip-compressed MGH (`.mgz`).
    Mgh,
    /// Analyze 7.5 `.hdr`/`.img` pairs (no NIfTI magic), read by the
    /// NIfTI reader.
    Analyze,
    /// OpenDX scalar fields (`.dx`): APBS, VMD, PyMOL, GridDataFormats.
    Dx,
    /// XCrySDen XSF and BXSF data and band grids (`.xsf`, `.bxsf`).
    Xsf,
    /// gOpenMol plot files (`.plt`), binary.
    Plt,
    /// NumPy `.npz` archives (`numpy.savez`, `savez_compressed`).
    Npz,
    /// GIPL images (`.gipl`, `.gipl.gz`): ITK, SimpleITK.
    Gipl,
    /// MRtrix images (`.mif`, `.mih`, `.mif.gz`).
    Mrtrix,
    /// VTKHDF image data (`.vtkhdf`, or an HDF5 file with a `/VTKHDF`
    /// group): VTK's own HDF5 format.
    Vtkhdf,
    /// BigDataViewer HDF5: a SpimData `dataset.xml` and its `.h5` (or
    /// the `.h5` alone), levels, view setups and time points.
    Bdv,
}

/// Everything volray knows about one format besides its reader's code.
pub(crate) struct FormatSpec {
    pub format: VolumeFormat,
    /// The name [`VolumeFormat::from_str`] takes (the CLI's `--format`).
    pub name: &'static str,
    /// A human name for messages and `volray info`.
    pub description: &'static str,
    /// File name extensions that announce the format, lower case, without
    /// the leading dot; one holding a dot (`nii.gz`) matches the end of
    /// the name.
    pub extensions: &'static [&'static str],
    /// File names that announce the format by their first word, lower
    /// case: the name up to its first `.`, `_` or `-` (VASP's `CHGCAR`,
    /// `CHGCAR_relaxed`, `AECCAR0.gz`). Tried after every format's
    /// extensions.
    pub name_stems: &'static [&'static str],
    /// How [`VolumeFormat::KNOWN`] lists the files detected as this format
    /// without naming it; empty for a format never detected (raw).
    pub known_as: &'static str,
    /// The first bytes that show the format.
    pub magic: Magic,
    /// Whether a file may hold several volumes, one of which
    /// [`ReadOptions::frame`] picks.
    pub frames: bool,
    /// Whether a file may hold several named arrays, one of which
    /// [`ReadOptions::array`] picks.
    pub arrays: bool,
    /// Whether a file may hold several resolution levels, one of which
    /// [`ReadOptions::level`] picks, and several channels, one of which
    /// [`ReadOptions::channel`] picks.
    pub levels: bool,
    /// The reader.
    pub read: fn(&Path, &ReadOptions) -> Result<Loaded, IoError>,
}

/// Byte strings at fixed offsets: `(offset, bytes)`.
type Signatures = &'static [(usize, &'static [u8])];

/// How the first bytes of a file show a format (see [`VolumeFormat::sniff`]).
/// Where one file could show two formats, the kind of test decides: every
/// format's `strong` signatures are tried first (in table order), then
/// the `weak` ones, then the `text` tests.
#[derive(Clone, Copy)]
pub(crate) struct Magic {
    /// Byte strings that other formats' files do not hold where these are
    /// (a magic number at offset 0, or at a fixed offset the other
    /// formats' magic numbers make impossible).
    pub strong: Signatures,
    /// Byte strings that another format's file may hold by chance: NIfTI's
    /// magic at byte 344 or 4 (a TIFF's first directory offset, a DICOM
    /// preamble), the two bytes of gzip.
    pub weak: Signatures,
    /// A test of the first 1024 bytes as text (lossy UTF-8), for text
    /// headers; the formats' tests must not both accept a file.
    pub text: Option<fn(&str) -> bool>,
    /// A test of the first bytes as binary fields, for headers without a
    /// magic string (MGH's version word, Analyze's `sizeof_hdr`): tried
    /// after every format's `weak` signatures, before the `text` tests.
    pub binary: Option<fn(&[u8]) -> bool>,
}

impl Magic {
    /// No magic number: the format is known by its name only, or named.
    const NONE: Magic = Magic {
        strong: &[],
        weak: &[],
        text: None,
        binary: None,
    };

    const fn strong(signatures: Signatures) -> Magic {
        Magic {
            strong: signatures,
            ..Magic::NONE
        }
    }
}

/// Every format volray reads, in [`VolumeFormat`]'s order (the order
/// `--format` lists them).
pub(crate) const FORMATS: &[FormatSpec] = &[
    FormatSpec {
        format: VolumeFormat::Raw,
        name: "raw",
        description: "raw samples",
        extensions: &["raw"],
        name_stems: &[],
        known_as: "",
        magic: Magic::NONE,
        frames: false,
        arrays: false,
        levels: false,
        read: raw::read,
    },
    FormatSpec {
        format: VolumeFormat::Npy,
        name: "npy",
        description: "NumPy .npy",
        extensions: &["npy"],
        name_stems: &[],
        known_as: ".npy",
        magic: Magic::strong(&[(0, b"\x93NUMPY")]),
        frames: false,
        arrays: false,
        levels: false,
        read: npy::read,
    },
    FormatSpec {
        format: VolumeFormat::Nrrd,
        name: "nrrd",
        description: "NRRD",
        extensions: &["nrrd", "nhdr"],
        name_stems: &[],
        known_as: ".nrrd/.nhdr",
        magic: Magic::strong(&[(0, b"NRRD000")]),
        frames: true,
        arrays: false,
        levels: false,
        read: nrrd::read,
    },
    FormatSpec {
        format: VolumeFormat::MetaImage,
        name: "metaimage",
        description: "MetaImage",
        extensions: &["mha", "mhd"],
        name_stems: &[],
        known_as: ".mha/.mhd",
        magic: Magic {
            text: Some(metaimage::sniff_text),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: metaimage::read,
    },
    FormatSpec {
        format: VolumeFormat::Nifti,
        name: "nifti",
        description: "NIfTI",
        extensions: &["nii", "nii.gz"],
        name_stems: &[],
        known_as: ".nii/.nii.gz",
        magic: Magic {
            weak: &[
                (344, b"n+1\0"),
                (344, b"ni1\0"),
                (4, b"n+2\0"),
                (4, b"ni2\0"),
                // gzip: in volray's formats only .nii.gz is a gzip file.
                (0, b"\x1f\x8b"),
            ],
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: nifti::read,
    },
    FormatSpec {
        format: VolumeFormat::VtkLegacy,
        name: "vtk",
        description: "legacy VTK structured points",
        extensions: &["vtk"],
        name_stems: &[],
        known_as: ".vtk",
        magic: Magic::strong(&[(0, b"# vtk DataFile")]),
        frames: false,
        arrays: true,
        levels: false,
        read: vtk_legacy::read,
    },
    FormatSpec {
        format: VolumeFormat::Vti,
        name: "vti",
        description: "VTK XML image data",
        extensions: &["vti"],
        name_stems: &[],
        known_as: ".vti",
        magic: Magic {
            text: Some(vti::sniff_text),
            ..Magic::NONE
        },
        frames: false,
        arrays: true,
        levels: false,
        read: vti::read,
    },
    FormatSpec {
        format: VolumeFormat::Dicom,
        name: "dicom",
        description: "DICOM",
        extensions: &["dcm", "dicom"],
        name_stems: &[],
        known_as: "DICOM (.dcm or a directory)",
        magic: Magic::strong(&[(128, b"DICM")]),
        frames: true,
        arrays: false,
        levels: false,
        read: dicom::read,
    },
    FormatSpec {
        format: VolumeFormat::Tiff,
        name: "tiff",
        description: "TIFF stack",
        extensions: &["tif", "tiff"],
        name_stems: &[],
        known_as: ".tif/.tiff",
        // Classic TIFF and BigTIFF, either byte order.
        magic: Magic::strong(&[(0, b"II*\0"), (0, b"MM\0*"), (0, b"II+\0"), (0, b"MM\0+")]),
        frames: true,
        arrays: false,
        levels: false,
        read: tiff::read,
    },
    FormatSpec {
        format: VolumeFormat::Hdf5,
        name: "hdf5",
        description: "HDF5 dataset",
        extensions: &["h5", "hdf5", "he5"],
        name_stems: &[],
        known_as: ".h5:/dataset",
        magic: Magic::strong(&[(0, b"\x89HDF\r\n\x1a\n")]),
        frames: true,
        arrays: false,
        levels: false,
        read: hdf5::read,
    },
    FormatSpec {
        format: VolumeFormat::Cube,
        name: "cube",
        description: "Gaussian cube",
        extensions: &["cube", "cub"],
        name_stems: &[],
        known_as: ".cube",
        magic: Magic {
            text: Some(cube::sniff_text),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: cube::read,
    },
    FormatSpec {
        format: VolumeFormat::Mrc,
        name: "mrc",
        description: "CCP4/MRC map",
        extensions: &["map", "mrc", "ccp4", "mrcs"],
        name_stems: &[],
        known_as: ".map/.mrc/.ccp4",
        magic: Magic::strong(&[(208, b"MAP ")]),
        frames: false,
        arrays: false,
        levels: false,
        read: mrc::read,
    },
    FormatSpec {
        format: VolumeFormat::Chgcar,
        name: "chgcar",
        description: "VASP CHGCAR/CHG",
        extensions: &[],
        name_stems: &[
            "chgcar", "chg", "aeccar0", "aeccar1", "aeccar2", "parchg", "elfcar", "locpot",
        ],
        known_as: "CHGCAR/CHG",
        magic: Magic {
            text: Some(chgcar::sniff_text),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: chgcar::read,
    },
    FormatSpec {
        format: VolumeFormat::Minc,
        name: "minc",
        description: "MINC2",
        extensions: &["mnc"],
        name_stems: &[],
        known_as: ".mnc",
        // HDF5's magic is the HDF5 row's; a MINC2 file under another name
        // is handed over by the HDF5 reader.
        magic: Magic::NONE,
        frames: true,
        arrays: false,
        levels: false,
        read: minc::read,
    },
    FormatSpec {
        format: VolumeFormat::Zarr,
        name: "zarr",
        description: "Zarr/OME-Zarr",
        // A directory is known by its metadata files (read.rs), whatever
        // its name; the extension only sends a `.zarr` path that is no
        // Zarr store to the Zarr reader, which says what is missing.
        extensions: &["zarr", "ome.zarr"],
        name_stems: &[],
        known_as: "Zarr/OME-Zarr (a directory)",
        magic: Magic::NONE,
        frames: true,
        arrays: true,
        levels: true,
        read: zarr::read,
    },
    FormatSpec {
        format: VolumeFormat::Netcdf,
        name: "netcdf",
        description: "NetCDF",
        extensions: &["nc", "cdf", "nc3", "netcdf"],
        name_stems: &[],
        known_as: ".nc/.cdf",
        // CDF-1, CDF-2, CDF-5; NetCDF-4 is HDF5 (the HDF5 row's magic).
        magic: Magic::strong(&[(0, b"CDF\x01"), (0, b"CDF\x02"), (0, b"CDF\x05")]),
        frames: true,
        arrays: true,
        levels: false,
        read: netcdf::read,
    },
    FormatSpec {
        format: VolumeFormat::Fits,
        name: "fits",
        description: "FITS image",
        extensions: &["fits", "fit", "fts", "fits.gz", "fit.gz", "fts.gz"],
        name_stems: &[],
        known_as: ".fits/.fits.gz",
        // FITS Standard 4.0 §4.4.1.1: SIMPLE, value T in column 30.
        magic: Magic::strong(&[(0, b"SIMPLE  =                    T")]),
        frames: true,
        arrays: true,
        levels: false,
        read: fits::read,
    },
    FormatSpec {
        format: VolumeFormat::Mgh,
        name: "mgh",
        description: "FreeSurfer MGH/MGZ",
        extensions: &["mgh", "mgz", "mgh.gz"],
        name_stems: &[],
        known_as: ".mgh/.mgz",
        // Version 1, big-endian, then plausible dimensions and type; an
        // .mgz is sniffed after inflating its first bytes (`sniff`).
        magic: Magic {
            binary: Some(mgh::sniff),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: mgh::read,
    },
    FormatSpec {
        format: VolumeFormat::Analyze,
        name: "analyze",
        description: "Analyze 7.5",
        // `.hdr` is NIfTI's pair too: the content decides.
        extensions: &[],
        name_stems: &[],
        known_as: ".hdr/.img (Analyze 7.5)",
        magic: Magic {
            binary: Some(nifti::sniff_analyze),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: nifti::read,
    },
    FormatSpec {
        format: VolumeFormat::Dx,
        name: "dx",
        description: "OpenDX field",
        extensions: &["dx"],
        name_stems: &[],
        known_as: ".dx",
        magic: Magic {
            text: Some(opendx::sniff_text),
            ..Magic::NONE
        },
        frames: false,
        arrays: false,
        levels: false,
        read: opendx::read,
    },
    FormatSpec {
        format: VolumeFormat::Xsf,
        name: "xsf",
        description: "XCrySDen XSF grid",
        extensions: &["xsf", "bxsf"],
        name_stems: &[],
        known_as: ".xsf/.bxsf",
        magic: Magic {
            text: Some(xsf::sniff_text),
            ..Magic::NONE
        },
        frames: true,
        arrays: true,
        levels: false,
        read: xsf::read,
    },
    FormatSpec {
        format: VolumeFormat::Plt,
        name: "plt",
        description: "gOpenMol plt grid",
        extensions: &["plt"],
        name_stems: &[],
        known_as: ".plt (gOpenMol)",
        // Rank 3 in either byte order and plausible fields (`plt::sniff`).
        magic: Magic {
            binary: Some(plt::sniff),
            ..Magic::NONE
        },
        frames: false,
        arrays: false,
        levels: false,
        read: plt::read,
    },
    FormatSpec {
        format: VolumeFormat::Npz,
        name: "npz",
        description: "NumPy .npz",
        extensions: &["npz"],
        name_stems: &[],
        known_as: ".npz",
        // A zip file's first local header: other zip-based files (a .docx)
        // are sent here too and refused as holding no .npy arrays.
        magic: Magic::strong(&[(0, b"PK\x03\x04")]),
        frames: false,
        arrays: true,
        levels: false,
        read: npz::read,
    },
    FormatSpec {
        format: VolumeFormat::Gipl,
        name: "gipl",
        description: "GIPL image",
        extensions: &["gipl", "gipl.gz"],
        name_stems: &[],
        known_as: ".gipl",
        // ITK's two magic numbers at byte 252 (`gipl::MAGIC`).
        magic: Magic::strong(&[(252, b"\xef\xff\xe9\xb0"), (252, b"\x2a\xe3\x89\xb8")]),
        frames: true,
        arrays: false,
        levels: false,
        read: gipl::read,
    },
    FormatSpec {
        format: VolumeFormat::Mrtrix,
        name: "mrtrix",
        description: "MRtrix image",
        extensions: &["mif", "mih", "mif.gz"],
        name_stems: &[],
        known_as: ".mif/.mih",
        magic: Magic {
            text: Some(mrtrix::sniff_text),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: false,
        read: mrtrix::read,
    },
    FormatSpec {
        format: VolumeFormat::Vtkhdf,
        name: "vtkhdf",
        description: "VTKHDF image data",
        extensions: &["vtkhdf"],
        name_stems: &[],
        known_as: ".vtkhdf (or an HDF5 file with a /VTKHDF group)",
        // HDF5's signature: an HDF5 file is told by its /VTKHDF group
        // (`read.rs`'s `detect`).
        magic: Magic::NONE,
        frames: false,
        arrays: true,
        levels: false,
        read: vtkhdf::read,
    },
    FormatSpec {
        format: VolumeFormat::Bdv,
        name: "bdv",
        description: "BigDataViewer HDF5",
        extensions: &[],
        name_stems: &[],
        known_as: "dataset.xml (BigDataViewer, or its .h5)",
        // The XML by its root element; the .h5 by its groups
        // (`read.rs`'s `detect`).
        magic: Magic {
            text: Some(bdv::sniff),
            ..Magic::NONE
        },
        frames: true,
        arrays: false,
        levels: true,
        read: bdv::read,
    },
];

// Row i describes variant i, so `spec` can index the table.
const _: () = {
    let mut i = 0;
    while i < FORMATS.len() {
        assert!(
            FORMATS[i].format as usize == i,
            "FORMATS must list the formats in VolumeFormat's order"
        );
        i += 1;
    }
};

/// One string field of every row, as an array (a macro: a `const fn`
/// cannot call the accessor it would be given).
macro_rules! column {
    ($field:ident) => {{
        let mut parts = [""; FORMATS.len()];
        let mut i = 0;
        while i < FORMATS.len() {
            parts[i] = FORMATS[i].$field;
            i += 1;
        }
        parts
    }};
}

impl VolumeFormat {
    /// Every format, in the order `--format` lists them.
    pub const ALL: [VolumeFormat; FORMATS.len()] = {
        let mut all = [VolumeFormat::Raw; FORMATS.len()];
        let mut i = 0;
        while i < FORMATS.len() {
            all[i] = FORMATS[i].format;
            i += 1;
        }
        all
    };

    /// The file kinds detected without `--format`, for messages.
    pub const KNOWN: &'static str = {
        const PARTS: [&str; FORMATS.len()] = column!(known_as);
        const BYTES: [u8; joined_len(&PARTS)] = join(&PARTS);
        as_str(&BYTES)
    };

    /// The names [`FromStr`] accepts, comma separated.
    const NAMES: &'static str = {
        const PARTS: [&str; FORMATS.len()] = column!(name);
        const BYTES: [u8; joined_len(&PARTS)] = join(&PARTS);
        as_str(&BYTES)
    };

    /// The format's row in [`FORMATS`].
    pub(crate) fn spec(self) -> &'static FormatSpec {
        &FORMATS[self as usize]
    }

    /// The name `--format` takes.
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// A human name for messages and `volray info`.
    pub fn description(self) -> &'static str {
        self.spec().description
    }

    /// The format a file name announces, if any: its extension
    /// (case-insensitive; `.nii.gz` counts as NIfTI), or a VASP name
    /// (`CHGCAR`, `CHG`, `AECCAR0`, `PARCHG`, ... with any suffix).
    pub fn from_path(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let announces = |ext: &&str| {
            if ext.contains('.') {
                name.ends_with(&format!(".{ext}"))
            } else {
                extension.as_deref() == Some(*ext)
            }
        };
        let stem = name.split(['.', '_', '-']).next().unwrap_or("");
        FORMATS
            .iter()
            .find(|spec| spec.extensions.iter().any(announces))
            .or_else(|| FORMATS.iter().find(|spec| spec.name_stems.contains(&stem)))
            .map(|spec| spec.format)
    }

    /// The format the first bytes of a file show, if they carry a magic
    /// number (`head` should hold at least the first 1024 bytes, or the
    /// whole file if shorter).
    pub fn sniff(head: &[u8]) -> Option<Self> {
        // A gzip file (.nii.gz, .mgz, .cube.gz), or a bzip2 or xz one, is
        // known by what it decompresses to (shared/packed.rs); a gzip file
        // that shows nothing is still taken for a .nii.gz.
        if let Some(unpacked) = crate::shared::packed::unpack_head(head)
            && let Some(format) = Self::sniff_plain(&unpacked)
        {
            return Some(format);
        }
        Self::sniff_plain(head)
    }

    /// [`VolumeFormat::sniff`] of bytes that are not inflated first.
    fn sniff_plain(head: &[u8]) -> Option<Self> {
        let shows = |signatures: Signatures| {
            signatures
                .iter()
                .any(|&(offset, bytes)| head.get(offset..offset + bytes.len()) == Some(bytes))
        };
        let by_bytes = FORMATS
            .iter()
            .find(|spec| shows(spec.magic.strong))
            .or_else(|| FORMATS.iter().find(|spec| shows(spec.magic.weak)))
            .or_else(|| {
                FORMATS
                    .iter()
                    .find(|spec| spec.magic.binary.is_some_and(|test| test(head)))
            });
        let spec = by_bytes.or_else(|| {
            let text = String::from_utf8_lossy(&head[..head.len().min(1024)]);
            FORMATS
                .iter()
                .find(|spec| spec.magic.text.is_some_and(|test| test(&text)))
        })?;
        Some(spec.format)
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
                accepted: VolumeFormat::NAMES,
            })
    }
}

// The lists in messages, joined from the table at compile time so that
// they stay `&'static str`s.

/// The length of the non-empty `parts` joined by ", ".
const fn joined_len(parts: &[&str]) -> usize {
    let (mut len, mut i) = (0, 0);
    while i < parts.len() {
        if !parts[i].is_empty() {
            if len > 0 {
                len += 2;
            }
            len += parts[i].len();
        }
        i += 1;
    }
    len
}

/// The non-empty `parts` joined by ", " (`N` from [`joined_len`]).
const fn join<const N: usize>(parts: &[&str]) -> [u8; N] {
    let mut out = [0u8; N];
    let (mut at, mut i) = (0, 0);
    while i < parts.len() {
        let part = parts[i].as_bytes();
        if !part.is_empty() {
            if at > 0 {
                out[at] = b',';
                out[at + 1] = b' ';
                at += 2;
            }
            let mut j = 0;
            while j < part.len() {
                out[at + j] = part[j];
                j += 1;
            }
            at += part.len();
        }
        i += 1;
    }
    out
}

/// Joined UTF-8 strings are UTF-8.
const fn as_str(bytes: &'static [u8]) -> &'static str {
    match std::str::from_utf8(bytes) {
        Ok(s) => s,
        Err(_) => panic!("joined names are not UTF-8"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            crate::split_hdf5_path(Path::new("/no/such/run.h5:/fields/rho")),
            Some((
                std::path::PathBuf::from("/no/such/run.h5"),
                "/fields/rho".to_string()
            ))
        );
        assert_eq!(crate::split_hdf5_path(Path::new("/no/such/run.nrrd")), None);
    }

    #[test]
    fn lists_are_joined_from_the_table() {
        assert_eq!(
            VolumeFormat::KNOWN,
            ".npy, .nrrd/.nhdr, .mha/.mhd, .nii/.nii.gz, .vtk, .vti, DICOM (.dcm or a directory), .tif/.tiff, .h5:/dataset, .cube, .map/.mrc/.ccp4, CHGCAR/CHG, .mnc, Zarr/OME-Zarr (a directory), .nc/.cdf, .fits/.fits.gz, .mgh/.mgz, .hdr/.img (Analyze 7.5), .dx, .xsf/.bxsf, .plt (gOpenMol), .npz, .gipl, .mif/.mih, .vtkhdf (or an HDF5 file with a /VTKHDF group), dataset.xml (BigDataViewer, or its .h5)"
        );
        assert_eq!(
            VolumeFormat::NAMES,
            "raw, npy, nrrd, metaimage, nifti, vtk, vti, dicom, tiff, hdf5, cube, mrc, chgcar, minc, zarr, netcdf, fits, mgh, analyze, dx, xsf, plt, npz, gipl, mrtrix, vtkhdf, bdv"
        );
        assert_eq!(VolumeFormat::ALL.len(), 27);
        assert_eq!(VolumeFormat::ALL[13], VolumeFormat::Minc);
    }

    #[test]
    fn magic_numbers_keep_their_precedence() {
        // A TIFF whose first directory is at 0x00322b6e holds "n+2\0" at
        // byte 4, NIfTI-2's magic: the TIFF magic wins.
        let mut tiff = b"II*\0n+2\0".to_vec();
        tiff.resize(400, 0);
        assert_eq!(VolumeFormat::sniff(&tiff), Some(VolumeFormat::Tiff));
        // A DICOM preamble may hold anything, gzip's magic too.
        let mut dicom = vec![0x1f, 0x8b];
        dicom.resize(128, 0);
        dicom.extend_from_slice(b"DICM");
        assert_eq!(VolumeFormat::sniff(&dicom), Some(VolumeFormat::Dicom));
        let mut nifti = vec![0u8; 348];
        nifti[344..].copy_from_slice(b"n+1\0");
        assert_eq!(VolumeFormat::sniff(&nifti), Some(VolumeFormat::Nifti));
        assert_eq!(
            VolumeFormat::sniff(&[0x1f, 0x8b, 8, 0]),
            Some(VolumeFormat::Nifti)
        );
        // XML that is not image data is no MetaImage header either.
        assert_eq!(
            VolumeFormat::sniff(b"<?xml version=\"1.0\"?>\nNDims = 3\n"),
            None
        );
    }
}
