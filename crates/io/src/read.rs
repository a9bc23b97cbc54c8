//! Reading a volume: [`read`] and what it takes ([`ReadOptions`]) and
//! gives ([`Loaded`], [`FileInfo`]). It finds the file's format (named,
//! else by file name, else by content), checks that the options given
//! apply to it, and hands the file to the format's reader (all from
//! [`FORMATS`](crate::formats::FORMATS)).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use volray_core::{Volume, VolumeSource};

use crate::formats::{VolumeFormat, not_read};
use crate::shared::geometry::Reorientation;
use crate::shared::input::open_input;
use crate::shared::limits::default_max_memory;
use crate::{IoError, MapPolicy, RawOptions};

/// How to read a file: everything a reader may need beyond the path.
#[derive(Debug, Clone)]
pub struct ReadOptions {
    /// Read as this format, whatever the name and content say (the CLI's
    /// `--format`).
    pub format: Option<VolumeFormat>,
    /// The layout of a raw file (the CLI's `--dims`, `--dtype`, `--endian`,
    /// `--spacing`).
    pub raw: Option<RawOptions>,
    /// Which time point of a file holding several, counted from 0 (the
    /// CLI's `--frame`; see [`Volumes`](crate::Volumes)): the 4th
    /// dimension of NIfTI, NRRD, MetaImage and HDF5, an HDF5 dataset's or
    /// Zarr image's `t` axis, a TIFF hyperstack's time points; and for
    /// formats whose volumes are no time series, the orbital of a cube
    /// file, the density block of a CHGCAR (0 total, 1 magnetisation),
    /// the series of a DICOM directory, the 3-D images of a FITS file
    /// (and the steps of their 4th axis) in file order.
    pub frame: Option<usize>,
    /// Which named array of a file holding several (the CLI's `--array`):
    /// VTK point or cell data arrays; the image of an OME-Zarr plate
    /// (`A/1/0`: row, column, field) or collection (`0`, a series); the
    /// HDU of a FITS file, by EXTNAME or number.
    pub array: Option<String>,
    /// Which resolution level of a multiscale image (the CLI's `--level`),
    /// 0 the finest: the `datasets` of an OME-Zarr image.
    pub level: Option<usize>,
    /// Which channel of an image holding several (the CLI's `--channel`),
    /// counted from 0, in every format (see [`Volumes`](crate::Volumes)):
    /// an OME-Zarr image's or HDF5 dataset's `c` axis, a TIFF
    /// hyperstack's or OME-TIFF's channels, a 5-D NIfTI's components
    /// (`dim[5]`), an NRRD's or MetaImage's vector components; a file
    /// of one channel takes channel 0 only.
    pub channel: Option<usize>,
    /// The most bytes the decoded volume and the reader's whole-payload
    /// buffers may take (the CLI's `--max-memory`): a header asking for
    /// more is refused before anything is allocated (see
    /// [`check_volume_size`](crate::check_volume_size)).
    /// Default: [`default_max_memory`], half the physical memory.
    pub max_memory: u64,
    /// When a volume is mapped from its file rather than read into memory:
    /// by default, when it exceeds `max_memory` and its format stores it
    /// uncompressed, contiguous and in a type and byte order it keeps (see
    /// [`MapPolicy`]).
    pub map: MapPolicy,
    /// Which series of a DICOM directory or DICOMDIR: its number in the
    /// list the reader gives (from 1, in the order of SeriesNumber and
    /// SeriesInstanceUID) or its SeriesInstanceUID. Default: the largest.
    pub series: Option<String>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            format: None,
            raw: None,
            frame: None,
            array: None,
            level: None,
            channel: None,
            max_memory: default_max_memory(),
            map: MapPolicy::IfLarger,
            series: None,
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

/// A file volray parsed that holds one image, not a volume (a single
/// DICOM slice, a 2-D NRRD, NIfTI, MetaImage or TIFF image): what was
/// read, so that `volray info` can describe it, carried by
/// [`IoError::FlatImage`], whose message says why a volume needs more.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatImage {
    /// The file's format (set by [`read`]).
    pub format: VolumeFormat,
    /// Samples along the file's index axes, x fastest; at least one is 1.
    pub dims: [usize; 3],
    /// The distance between samples along each index axis (1 where the
    /// file gives none, as along the axis of a single slice).
    pub spacing: volray_core::glam::DVec3,
    /// The world position of the first sample.
    pub origin: volray_core::glam::DVec3,
    /// The samples, index axis 0 fastest, as a volume would hold them.
    pub values: Vec<f32>,
    pub info: FileInfo,
    /// Why this is not a volume and what to pass instead, e.g. `a single
    /// DICOM slice (512 x 512): pass the directory of the series (ct)`.
    pub reason: String,
}

impl FlatImage {
    /// The least and greatest finite value, their mean, and how many
    /// values are NaN or infinite; `None` for the range if no value is
    /// finite.
    pub fn value_range(&self) -> (Option<(f32, f32, f64)>, usize) {
        let (mut lo, mut hi, mut sum, mut n) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f64, 0usize);
        for &v in self.values.iter().filter(|v| v.is_finite()) {
            lo = lo.min(v);
            hi = hi.max(v);
            sum += f64::from(v);
            n += 1;
        }
        let range = (n > 0).then(|| (lo, hi, sum / n as f64));
        (range, self.values.len() - n)
    }
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
    /// How many volumes the file holds (time points × channels;
    /// orbitals, series); 1 for most files.
    pub frames: usize,
    /// Which of them was read: `time_point · channels + channel`.
    pub frame: usize,
    /// How many time points and channels the file holds (OME's T and
    /// C; see [`Volumes`](crate::Volumes)), `frames` their product, and
    /// which time point and channel was read.
    pub time_points: usize,
    pub channels: usize,
    pub time_point: usize,
    pub channel: usize,
    /// The named arrays the file holds (VTK; an OME-Zarr plate's or
    /// collection's images), if any, and the one read.
    pub arrays: Vec<String>,
    pub array: Option<String>,
    /// The volume's NaN values hold no value: space the file does not
    /// cover (the box of a skewed CCP4 map or sheared NIfTI grid
    /// resampled onto an axis-aligned grid), or samples the file marks
    /// undefined (FITS BLANK, CF fill values): to be rendered as empty
    /// space, not refused.
    pub nan_is_empty: bool,
    /// The volume was mapped in the file's own axis order, which is not
    /// x, y, z along world +x, +y, +z (only under
    /// [`MapPolicy::AlwaysInFileOrder`]): how to take the world-aligned
    /// volume's boxes from it.
    pub reorientation: Option<Reorientation>,
    /// The resolution levels of a multiscale image (OME-Zarr), finest
    /// first; one for a bare Zarr array, none for other formats.
    pub levels: Vec<LevelInfo>,
    /// Which of them was read.
    pub level: usize,
    /// The OME-Zarr `omero` rendering hints of the channel read, if any.
    pub omero: Option<OmeroChannel>,
    /// The segments of a label volume whose file names them (a DICOM
    /// Segmentation): each label value's name and colour.
    pub segments: Vec<Segment>,
    /// Whether the file's frames are the series of a DICOM directory
    /// (each its own grid, one picked by `--series`, the notes listing
    /// them), not time points of one grid.
    pub frames_are_series: bool,
    /// The imaging modality the file names (DICOM Modality `CT`, `MR`;
    /// MetaImage `Modality = MET_MOD_CT` as `CT`), if it names one: what
    /// picks a CT's default look (volray-app's `look.rs`).
    pub modality: Option<String>,
    /// The name and unit of each world axis (x, y, z) where the file
    /// gives the axes units that are not one length unit, some not a
    /// length at all (degrees by metres: `units.rs` keeps them apart);
    /// `None` otherwise. What the display scale stretches (volray-app's
    /// `display.rs`). Filled by the CF readers (NetCDF-3, NetCDF-4) and
    /// OME-Zarr's.
    pub axis_units: Option<[AxisUnitName; 3]>,
}

/// One world axis as a file names it and the unit its spacing and origin
/// are in ([`FileInfo::axis_units`]): `("lev", Some("Pa"))`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AxisUnitName {
    /// The axis's name in the file (a CF dimension's), for the notes.
    pub name: String,
    /// Its unit as written, after lengths are brought to one unit; `None`
    /// where the file gives it none.
    pub unit: Option<String>,
}

/// One segment of a label volume: the label value that marks it, its
/// name and its recommended display colour, as the file gives them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Segment {
    /// The label value (a DICOM SegmentNumber).
    pub label: i64,
    /// Its name (SegmentLabel), empty if none.
    pub name: String,
    /// Its colour, sRGB 0..255 (from RecommendedDisplayCIELabValue).
    pub colour: Option<[u8; 3]>,
}

/// An OME-Zarr image's `omero` rendering hints for one channel: what its
/// viewer would show it with.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OmeroChannel {
    /// The channel (index along `c`) these are the hints of.
    pub channel: usize,
    pub label: Option<String>,
    /// `RRGGBB`, upper case, without `#`.
    pub color: Option<String>,
    /// Whether the channel is shown.
    pub active: Option<bool>,
    /// The display window `start`..`end`, within the data's `min`..`max`
    /// where given.
    pub window: Option<(f64, f64, Option<f64>, Option<f64>)>,
}

impl FileInfo {
    /// The display window the file gives its values (an OME-Zarr image's
    /// `omero` window of the channel read), where it is a range.
    pub fn display_window(&self) -> Option<(f64, f64)> {
        self.omero.as_ref()?.window_range()
    }
}

impl OmeroChannel {
    /// The display window `start`..`end`, where it is a range (finite,
    /// `start < end`): what a viewer of the image maps to black..full.
    pub fn window_range(&self) -> Option<(f64, f64)> {
        let (start, end, _, _) = self.window?;
        (start.is_finite() && end.is_finite() && start < end).then_some((start, end))
    }
}

/// The names of the world's +x, +y, +z where a file of `format` says
/// what they are: a NIfTI, Analyze, MGH or MINC world is RAS+ (x towards
/// the subject's right, y anterior, z superior), DICOM's LPS+, NRRD's its
/// `space` (RAS, LAS, LPS); `None` otherwise, and for a grid kept in its
/// own axes because they are rotated away from the world's (its axes are
/// then the grid's, not the world's).
pub fn world_axis_names(format: VolumeFormat, info: &FileInfo) -> Option<[&'static str; 3]> {
    if (info.notes.iter()).any(|n| n.contains("rendered in the grid's own axes")) {
        return None;
    }
    match format {
        VolumeFormat::Nifti | VolumeFormat::Analyze | VolumeFormat::Mgh | VolumeFormat::Minc => {
            Some(["R", "A", "S"])
        }
        VolumeFormat::Dicom => Some(["L", "P", "S"]),
        VolumeFormat::Nrrd => {
            let space = (info.header.iter())
                .find(|(k, _)| k.trim() == "space")
                .map(|(_, v)| v.trim().to_ascii_lowercase());
            match space.as_deref() {
                Some("right-anterior-superior" | "ras") => Some(["R", "A", "S"]),
                Some("left-anterior-superior" | "las") => Some(["L", "A", "S"]),
                Some("left-posterior-superior" | "lps") => Some(["L", "P", "S"]),
                _ => None,
            }
        }
        _ => None,
    }
}

/// One resolution level of a multiscale image, for `volray info`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LevelInfo {
    /// The level's array, relative to the image (empty for a bare array).
    pub path: String,
    /// The array's shape in its own axis order (t, c, z, y, x).
    pub shape: Vec<u64>,
    /// Samples along x, y and z.
    pub dims: [usize; 3],
    /// Spacing and origin along x, y and z.
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    /// The chunk shape (the inner chunk of a sharded array), and the
    /// shard shape, in the array's axis order.
    pub chunk_shape: Option<Vec<u64>>,
    pub shard_shape: Option<Vec<u64>>,
    /// The codecs, in order, e.g. `bytes, zstd` or `blosc (lz4)`.
    pub codecs: String,
    /// The level's directory (the file, for a level inside one file).
    pub dir: PathBuf,
    /// The bytes the level's chunk files take on disk, where counted:
    /// opening a level does not count them (a level of 64³ chunks of a
    /// 16384³ image is 16 million files); see
    /// [`count_bytes_stored`](Self::count_bytes_stored).
    pub bytes_stored: Option<u64>,
    /// The bytes one volume of it (a time point and channel) takes in memory.
    pub bytes_in_memory: u64,
}

impl LevelInfo {
    /// The most chunk files the front ends count a level's stored bytes
    /// over (`volray info`, Python's `Volume.levels`): walking them takes
    /// about 4 µs a file here (262 144 shards of a 16384³ level: 1 s), so
    /// a level of millions of chunks is left uncounted.
    pub const COUNTED_FILES: usize = 100_000;

    /// The bytes the level's chunk files take on disk, counted file by
    /// file: `None` past `max_files` files (the walk is a statistic for
    /// `volray info`, and would take minutes on a level of millions of
    /// chunks). Hard-linked files count once for each name.
    pub fn count_bytes_stored(&self, max_files: usize) -> Option<u64> {
        // A level inside one file (BigDataViewer's HDF5) is not counted.
        if !self.dir.is_dir() {
            return None;
        }
        crate::formats::zarr::stored_bytes(&self.dir, max_files)
    }
}

impl FileInfo {
    /// A `FileInfo` for a file holding one volume of `stored_type`.
    pub fn new(stored_type: impl Into<String>) -> Self {
        FileInfo {
            stored_type: stored_type.into(),
            frames: 1,
            time_points: 1,
            channels: 1,
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
    let spec = format.spec();
    check_options(path, format, opts)?;
    let mut loaded = (spec.read)(path, opts).map_err(|e| match e {
        IoError::FlatImage { path, mut image } => {
            image.format = format;
            image.info.fill_volumes();
            IoError::FlatImage { path, image }
        }
        other => other,
    })?;
    loaded.info.fill_volumes();
    check_channel_read(path, opts, &loaded.info)?;
    if loaded.info.reorientation.is_some() && opts.map != MapPolicy::AlwaysInFileOrder {
        return Err(IoError::invalid(
            path,
            "the file's axes are not x, y, z in that order and sense, so its samples would have to be reordered, which a volume mapped from the file (larger than the memory limit) cannot be: store it with x fastest and the axes along +x, +y, +z",
        ));
    }
    Ok(loaded)
}

/// Splits `file.h5:/group/dataset` into the file and the dataset path,
/// if `path` has that shape and is not itself an existing file; a
/// NetCDF-4 file is an HDF5 file, so `file.nc:/variable` too.
pub fn split_hdf5_path(path: &Path) -> Option<(PathBuf, String)> {
    if path.exists() {
        return None;
    }
    let s = path.to_str()?;
    let lower = s.to_ascii_lowercase();
    [".h5:", ".hdf5:", ".he5:", ".nc:", ".nc4:"]
        .iter()
        .find_map(|ext| {
            let at = lower.find(ext)? + ext.len() - 1;
            Some((PathBuf::from(&s[..at]), s[at + 1..].to_string()))
        })
}

/// Refuses the options that do not apply to `format`.
fn check_options(path: &Path, format: VolumeFormat, opts: &ReadOptions) -> Result<(), IoError> {
    let spec = format.spec();
    if opts.raw.is_some() && format != VolumeFormat::Raw {
        return Err(IoError::RawOptionsNotApplicable {
            path: path.to_path_buf(),
            format: spec.description,
        });
    }
    if opts.frame.is_some() && !spec.frames {
        return Err(IoError::FrameNotApplicable {
            path: path.to_path_buf(),
            format: spec.description,
        });
    }
    // An HDF5 dataset is one level, level 0: `render` names it when it
    // reads whole what it opened box by box (`open_lazy`).
    let one_level =
        matches!(format, VolumeFormat::Hdf5 | VolumeFormat::Netcdf) && opts.level == Some(0);
    if opts.level.is_some() && !one_level && !spec.levels {
        return Err(IoError::LevelNotApplicable {
            path: path.to_path_buf(),
            format: spec.description,
        });
    }
    if let Some(channel) = opts.channel.filter(|&c| c > 0)
        && !has_channels(format)
    {
        return Err(IoError::channel_out_of_range(
            path,
            channel,
            format!("{} files hold one channel (channel 0)", spec.description),
        ));
    }
    if opts.series.is_some() && format != VolumeFormat::Dicom {
        return Err(IoError::invalid(
            path,
            format!(
                "series selection applies to DICOM directories and DICOMDIRs only, not to {} files",
                spec.description
            ),
        ));
    }
    if opts.array.is_some() && !spec.arrays {
        return Err(IoError::ArrayNotApplicable {
            path: path.to_path_buf(),
            format: spec.description,
        });
    }
    Ok(())
}

/// Whether a file of `format` may hold several channels (see
/// [`Volumes`](crate::Volumes)), one of which [`ReadOptions::channel`]
/// picks; the others hold one.
fn has_channels(format: VolumeFormat) -> bool {
    use VolumeFormat as F;
    matches!(
        format,
        F::Tiff | F::Hdf5 | F::Nifti | F::Zarr | F::Nrrd | F::MetaImage | F::Vtkhdf | F::Bdv
    )
}

/// Refuses a volume read from a file of fewer channels than
/// [`ReadOptions::channel`] asks for: what a reader that knows of no
/// channel axis read is channel 0.
fn check_channel_read(path: &Path, opts: &ReadOptions, info: &FileInfo) -> Result<(), IoError> {
    match opts.channel {
        Some(c) if c >= info.channels.max(1) => Err(IoError::channel_out_of_range(
            path,
            c,
            info.volumes().channels_held(crate::AxisNames {
                holder: "the file",
                time: "",
                channel: "",
            }),
        )),
        _ => Ok(()),
    }
}

/// A volume opened without reading its samples: a source of boxes of it
/// (see [`VolumeSource`]), and what its metadata says.
pub struct Lazy {
    pub source: Arc<dyn VolumeSource>,
    pub format: VolumeFormat,
    pub info: FileInfo,
}

/// Opens `path` as a source of boxes, reading no sample, where its format
/// can be read box by box (Zarr, OME-Zarr, HDF5 datasets and so NetCDF-4
/// variables: chunk by chunk, or row by row of contiguous data): what an
/// out-of-core render and the ranks of an MPI render read their pieces
/// from. `Ok(None)` for the other formats, which [`read`] reads whole or
/// maps (and for an HDF5 file that is MINC2's, or holds a 2-D image). The
/// options are those of [`read`], checked alike; a format read box by
/// box holds one level at least, so `--level 0` applies to HDF5 too.
pub fn open_lazy(path: &Path, opts: &ReadOptions) -> Result<Option<Lazy>, IoError> {
    let format = detect(path, opts)?;
    check_options(path, format, opts)?;
    let mut lazy = open_lazy_as(path, format, opts)?;
    if let Some(lazy) = &mut lazy {
        lazy.info.fill_volumes();
        check_channel_read(path, opts, &lazy.info)?;
    }
    Ok(lazy)
}

/// [`open_lazy`] of a file of `format`, the options checked.
fn open_lazy_as(
    path: &Path,
    format: VolumeFormat,
    opts: &ReadOptions,
) -> Result<Option<Lazy>, IoError> {
    match format {
        VolumeFormat::Zarr => {
            let (level, info) = crate::formats::zarr::open(path, opts)?;
            Ok(Some(Lazy {
                source: Arc::new(level),
                format,
                info,
            }))
        }
        VolumeFormat::Hdf5 => Ok(crate::formats::hdf5::open_lazy(path, opts)?.map(
            |(source, info)| Lazy {
                source: Arc::new(source),
                format,
                info,
            },
        )),
        VolumeFormat::Vtkhdf => Ok(crate::formats::vtkhdf::open_lazy(path, opts)?.map(
            |(source, info)| Lazy {
                source: Arc::new(source),
                format,
                info,
            },
        )),
        VolumeFormat::Bdv => Ok(crate::formats::bdv::open_lazy(path, opts)?.map(
            |(source, info)| Lazy {
                source: Arc::new(source),
                format,
                info,
            },
        )),
        // A NetCDF-4 variable (HDF5 underneath) with its CF geometry and
        // packing; a NetCDF-3 variable is read whole.
        VolumeFormat::Netcdf if crate::formats::netcdf::is_netcdf4(path) => Ok(
            crate::formats::netcdf4::open_lazy(path, opts)?.map(|(source, info)| Lazy {
                source: Arc::new(source),
                format,
                info,
            }),
        ),
        _ => Ok(None),
    }
}

/// The format to read `path` as: see [`read`]. An HDF5 file (by name or
/// content, not named with `:/dataset`) holding a `/VTKHDF` group is
/// VTKHDF; one holding BigDataViewer's groups is BigDataViewer's.
fn detect(path: &Path, opts: &ReadOptions) -> Result<VolumeFormat, IoError> {
    let format = detect_by_name_or_content(path, opts)?;
    if format == VolumeFormat::Hdf5
        && opts.format.is_none()
        && split_hdf5_path(path).is_none()
        && crate::formats::vtkhdf::is_vtkhdf(path)
    {
        return Ok(VolumeFormat::Vtkhdf);
    }
    if format == VolumeFormat::Hdf5
        && opts.format.is_none()
        && split_hdf5_path(path).is_none()
        && crate::formats::bdv::is_bdv_h5(path)
    {
        return Ok(VolumeFormat::Bdv);
    }
    Ok(format)
}

/// [`detect`] but for VTKHDF.
fn detect_by_name_or_content(path: &Path, opts: &ReadOptions) -> Result<VolumeFormat, IoError> {
    if let Some(format) = opts.format {
        return Ok(format);
    }
    if let Some((file, _)) = split_hdf5_path(path) {
        // `file.nc:/var` names a NetCDF-4 variable: read with its CF
        // geometry (formats/netcdf4.rs); any other `file:/dataset` is HDF5.
        let netcdf = VolumeFormat::from_path(&file) == Some(VolumeFormat::Netcdf);
        return Ok(if netcdf {
            VolumeFormat::Netcdf
        } else {
            VolumeFormat::Hdf5
        });
    }
    if path.is_dir() {
        // Zarr groups and arrays by their metadata files; N5 refused by
        // name; a directory inside a Zarr store or holding stores named
        // as such; any other directory is a DICOM series (or a `.zarr`
        // missing its metadata).
        let zarr = crate::formats::zarr::is_zarr_dir(path)
            || VolumeFormat::from_path(path) == Some(VolumeFormat::Zarr);
        if zarr {
            return Ok(VolumeFormat::Zarr);
        }
        if let Some(refusal) = not_read::refuse_dir(path).or_else(|| stores_near(path)) {
            return Err(refusal);
        }
        return Ok(VolumeFormat::Dicom);
    }
    if let Some(format) = VolumeFormat::from_path(path) {
        return Ok(format);
    }
    if opts.raw.is_some() {
        return Ok(VolumeFormat::Raw);
    }
    let mut head = Vec::with_capacity(1024);
    let (file, _) = open_input(path)?;
    file.take(1024)
        .read_to_end(&mut head)
        .map_err(|e| IoError::os(path, "read", e))?;
    // Formats recognised but not read are named before the readers'
    // weaker signatures are tried.
    if let Some(refusal) = not_read::refuse_file(path, &head) {
        return Err(refusal);
    }
    // A compressed file is known by what it decompresses to, read from
    // the file (a bzip2 stream shows nothing before its first block).
    let inside = crate::shared::packed::unpack_file_head(path, &head);
    let format = (inside.as_deref().and_then(VolumeFormat::sniff))
        .or_else(|| VolumeFormat::sniff(&head))
        .ok_or_else(|| IoError::UnknownFormat {
            path: path.to_path_buf(),
        })?;
    refuse_packed(path, &head, inside.as_deref(), format)?;
    Ok(format)
}

/// Whether `format`'s reader reads its files inside gzip (and bzip2 and
/// xz where it streams through `shared/packed.rs`); the others are refused
/// by name of the compression when found inside one (below).
fn reads_packed(format: VolumeFormat) -> bool {
    use VolumeFormat as F;
    matches!(
        format,
        F::Nifti
            | F::Mgh
            | F::Fits
            | F::Cube
            | F::Chgcar
            | F::VtkLegacy
            | F::Dx
            | F::Xsf
            | F::Plt
            | F::Gipl
    )
}

/// Refuses a file found to be `format` inside gzip, bzip2 or xz where its
/// reader reads the format uncompressed only, naming the way round.
fn refuse_packed(
    path: &Path,
    head: &[u8],
    inside: Option<&[u8]>,
    format: VolumeFormat,
) -> Result<(), IoError> {
    use crate::shared::packed::Packing;
    let Some(packing) = Packing::of(head) else {
        return Ok(());
    };
    let inside = inside.and_then(VolumeFormat::sniff);
    if reads_packed(format) || inside != Some(format) {
        return Ok(());
    }
    Err(IoError::invalid(
        path,
        format!(
            "a {}-compressed {} file, which volray reads uncompressed only: decompress it first ({} FILE)",
            packing.name(),
            format.description(),
            packing.tool()
        ),
    ))
}

/// Most directory entries looked at for Zarr or N5 stores inside a
/// directory that is neither (a DICOM series holds files, not stores).
const STORES_LOOKED_AT: usize = 4096;

/// Why the directory `dir` (neither Zarr nor N5 itself) is no DICOM
/// series: it lies inside a Zarr or N5 store, or holds such stores.
fn stores_near(dir: &Path) -> Option<IoError> {
    let is_store =
        |d: &Path| crate::formats::zarr::is_zarr_dir(d) || not_read::refuse_dir(d).is_some();
    if let Some(store) = dir.ancestors().skip(1).take(32).find(|a| is_store(a)) {
        return Some(IoError::invalid(
            dir,
            format!(
                "this directory lies inside the store {}: pass the store (or one of its arrays), not a directory of its chunks",
                store.display()
            ),
        ));
    }
    let mut stores: Vec<String> = std::fs::read_dir(dir)
        .ok()?
        .take(STORES_LOOKED_AT)
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.is_dir() && is_store(p))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    if stores.is_empty() {
        return None;
    }
    stores.sort();
    Some(IoError::invalid(
        dir,
        format!(
            "this directory holds Zarr or N5 stores, not a DICOM series: pass one of them ({})",
            stores.join(", ")
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DType, write_npy};

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
            err.to_string()
                .ends_with("raw layout options do not apply to NumPy .npy files"),
            "{err}"
        );
        assert!(
            matches!(err, IoError::RawOptionsNotApplicable { format, .. } if format == "NumPy .npy")
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
}
