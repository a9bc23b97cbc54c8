//! Opening an input by spec: a built-in source (`blobs:64`, volray-data)
//! or a volume file, with the reader's options (the command line's input
//! flags, Python's `read` keywords: [`Request`]), and `--log`.

use crate::error::{AppError, InputOpt};
use std::path::{Path, PathBuf};
use volray_core::glam::DVec3;
use volray_core::{NonFinite, Volume};
use volray_io::{
    DType, Endian, FileInfo, FlatImage, IoError, MapPolicy, RawOptions, ReadOptions, VolumeFormat,
};
use volray_options::level::LevelChoice;

/// The volume a command reads when given no input: the paper's first
/// fractal cloud (Figure 2a's), which `volray render` without INPUT draws
/// in the demo's look (volray-flags' `demo.rs`).
pub const DEMO: &str = "fractal:129,seed=1,dim=3.7,sigma=1,ramp=0.3,threshold=0.5869113206863403";

/// Where a volume comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Spec {
    /// A built-in source (volray-data): `blobs:64`, `sphere:64,radius=0.7`.
    Source(String),
    /// A volume file or directory (a DICOM series, a Zarr store).
    File(PathBuf),
}

impl Spec {
    /// The spec `text` names: a built-in source's spec, else a path (a
    /// file whose name is a source's name needs a path, `./sphere`).
    pub fn parse(text: &str) -> Spec {
        if volray_data::is_source_spec(text) {
            Spec::Source(text.to_string())
        } else {
            Spec::File(PathBuf::from(text))
        }
    }

    /// The spec or the file's path as given, for messages.
    pub fn name(&self) -> String {
        match self {
            Spec::Source(spec) => spec.clone(),
            Spec::File(path) => path.display().to_string(),
        }
    }
}

impl Default for Spec {
    /// The demo volume, [`DEMO`].
    fn default() -> Spec {
        Spec::Source(DEMO.to_string())
    }
}

/// An input and how to read it: the front ends' reading options, in
/// plain terms (the command line's `--dims`, `--dtype`, ..., Python's
/// `read` keywords).
#[derive(Debug, Clone, Default)]
pub struct Request {
    pub spec: Spec,
    /// Raw files: points along x, y and z; the sample type; the byte order.
    pub dims: Option<[usize; 3]>,
    pub dtype: Option<String>,
    pub endian: Option<String>,
    /// Voxel spacing replacing what the file says.
    pub spacing: Option<[f64; 3]>,
    /// The format, whatever the file's name and content say.
    pub format: Option<String>,
    pub frame: Option<usize>,
    /// Which series of a DICOM directory: its number (from 1) or UID.
    pub series: Option<String>,
    pub array: Option<String>,
    pub level: Option<LevelChoice>,
    pub channel: Option<usize>,
    /// The memory limit; `None` for volray-io's default.
    pub max_memory: Option<u64>,
    /// Each world axis stretched for drawing (`--scale`, Python's
    /// `scale=`): `None` for the default rule (`display.rs`: axes in
    /// different units drawn comparable, others as stored).
    pub scale: Option<[f64; 3]>,
}

impl Request {
    /// The request of the spec `text` ([`Spec::parse`]), no option given.
    pub fn of(text: &str) -> Request {
        Request {
            spec: Spec::parse(text),
            ..Request::default()
        }
    }

    /// The memory limit: as given, else half the physical memory.
    pub fn max_memory(&self) -> u64 {
        self.max_memory
            .unwrap_or_else(volray_io::default_max_memory)
    }

    /// The level `level N` names; `None` for `auto` or none.
    pub fn fixed_level(&self) -> Option<usize> {
        match self.level {
            Some(LevelChoice::Index(n)) => Some(n),
            _ => None,
        }
    }

    /// This request reading the input whole at `level` (`level auto`
    /// resolved to a number).
    pub fn at_level(&self, level: Option<usize>) -> Request {
        Request {
            // Unresolved (a built-in source): as given, for the reader to refuse.
            level: level.map(LevelChoice::Index).or(self.level),
            ..self.clone()
        }
    }

    /// Whether raw layout options (dims, dtype, endian) are given.
    fn raw_flags(&self) -> bool {
        self.dims.is_some() || self.dtype.is_some() || self.endian.is_some()
    }
}

/// A loaded volume and how to name it in messages.
pub struct Input {
    pub volume: Volume,
    /// The spec or the file's path, for messages.
    pub name: String,
    /// The file's format and what its header said, if it came from a file.
    pub file: Option<(VolumeFormat, FileInfo)>,
    /// `--max-memory` (or its default), which rendering must fit too.
    pub max_memory: u64,
    /// How its axes were stretched for drawing, where they were by the
    /// default rule (`display.rs`): the note a front end says.
    pub display_note: Option<String>,
    /// Whether `volume` is the log10 of the data because `--tf auto`
    /// chose it ([`auto_log`]): figures then label decades, as with
    /// `--log`.
    pub auto_log: bool,
}

impl Input {
    /// How rendering treats NaN and infinite values: as `--nonfinite`
    /// says, except that NaN values the file marks as space it does not
    /// cover (the box of a skewed crystallographic map, resampled) are
    /// always empty space.
    pub fn non_finite(&self, requested: NonFinite) -> NonFinite {
        match &self.file {
            Some((_, info)) if info.nan_is_empty => NonFinite::Transparent,
            _ => requested,
        }
    }
}

/// The colours the file of `input` gives its labels (a DICOM
/// Segmentation's segment colours), `(label, sRGB 0..1)`, for the look's
/// `label_colours`; none for other inputs.
pub fn label_colours(input: &Input) -> Vec<(i64, [f32; 3])> {
    match &input.file {
        Some((_, info)) => segment_colours(info),
        None => Vec::new(),
    }
}

/// The colours a file's `info` gives its labels (a DICOM Segmentation's
/// segments), each label with its sRGB colour in 0..1: what `--labels`
/// (and Python's `labels=True`) draws them in.
pub fn segment_colours(info: &FileInfo) -> Vec<(i64, [f32; 3])> {
    (info.segments.iter())
        .filter_map(|s| Some((s.label, s.colour?.map(|c| f32::from(c) / 255.0))))
        .collect()
}

/// What `volray info` describes: a volume, or a file holding one image
/// (a single slice, a 2-D image) that `render` refuses.
pub enum Described {
    Volume(Box<Input>),
    Image {
        /// The file's path, for messages.
        name: String,
        image: Box<FlatImage>,
    },
}

/// `input` stretched for drawing as [`crate::display::stretch`] says (`explicit`:
/// `--scale`), its note kept in `input.display_note`; unchanged where
/// nothing is stretched.
pub fn displayed(mut input: Input, explicit: Option<[f64; 3]>) -> Result<Input, crate::AppError> {
    let info = input.file.as_ref().map(|(_, info)| info);
    let reoriented = info.and_then(|i| i.reorientation.as_ref());
    let extent = match reoriented {
        Some(r) => {
            let d = r.dims();
            r.spacing * DVec3::new(d[0] as f64 - 1.0, d[1] as f64 - 1.0, d[2] as f64 - 1.0)
        }
        None => input.volume.extent(),
    };
    let Some(stretch) = crate::display::stretch(info, extent, explicit) else {
        return Ok(input);
    };
    let f = DVec3::from(stretch.factors);
    if !(f.is_finite() && f.min_element() > 0.0) {
        let e = volray_core::VolumeError::BadSpacing(f.x, f.y, f.z);
        return Err(crate::AppError::Spacing(e));
    }
    // Kept in the file's axes (a distributed render's mapping): the
    // world-aligned volume's spacing and origin, which its boxes take.
    match input
        .file
        .as_mut()
        .and_then(|(_, i)| i.reorientation.as_mut())
    {
        Some(r) => {
            r.spacing *= f;
            r.origin *= f;
        }
        None => {
            input.volume = crate::display::stretched(input.volume, stretch.factors)
                .map_err(crate::AppError::Spacing)?;
        }
    }
    if let (Some(note), Some((_, info))) = (&stretch.note, input.file.as_mut()) {
        info.notes.push(note.clone());
    }
    input.display_note = stretch.note;
    Ok(input)
}

/// Reads the volume `request` names for rendering: with `log`, its
/// log10; its axes stretched for drawing as `request.scale` or the
/// default rule says ([`displayed`]).
pub fn load_log(request: &Request, log: bool) -> Result<Input, AppError> {
    let mut input = displayed(load(request)?, request.scale)?;
    if log {
        input.volume = input.volume.to_log10().map_err(|e| AppError::Log {
            name: input.name.clone(),
            message: e.to_string(),
        })?;
    }
    Ok(input)
}

/// With `look`'s `--tf auto` and no window (`transfer_function`, the
/// flags' before the volume completes it), takes the log10 of `input`'s
/// volume where its values span decades (volray-options'
/// [`chooses_log`](volray_options::chooses_log)), marks it
/// [`Input::auto_log`] and returns the note to print (`linear`: how the
/// front end keeps the values, `--linear`); `None` where it keeps them.
/// For a volume read whole and rendered alone: a series, a scene and a
/// volume read piece by piece keep their values.
pub fn auto_log(
    look: &volray_options::LookOptions,
    transfer_function: &volray_core::TransferFunction,
    input: &mut Input,
    linear: &str,
) -> Result<Option<String>, AppError> {
    // The file's own window counts as a window given.
    let window = (input.file.as_ref()).and_then(|(_, info)| info.display_window());
    if window.is_some() || !volray_options::chooses_log(look, transfer_function, &input.volume) {
        return Ok(None);
    }
    input.volume = input.volume.to_log10().map_err(|e| AppError::Log {
        name: input.name.clone(),
        message: e.to_string(),
    })?;
    input.auto_log = true;
    Ok(Some(volray_options::auto_log_note(&input.name, linear)))
}

/// Loads the input for rendering: a file holding an image, not a volume,
/// is refused with the reason (exit 1).
pub fn load(request: &Request) -> Result<Input, AppError> {
    load_with(request, MapPolicy::IfLarger)
}

/// [`load`], mapping the file as `map` says (a distributed render maps
/// every file it can, and reads each rank's box from the map).
pub fn load_with(request: &Request, map: MapPolicy) -> Result<Input, AppError> {
    match describe_with(request, map)? {
        Described::Volume(input) => Ok(*input),
        Described::Image { name, image } => Err(AppError::from(IoError::FlatImage {
            path: name.into(),
            image,
        })),
    }
}

/// Loads the input for `volray info`: a volume, or the image a file holds.
pub fn describe(request: &Request) -> Result<Described, AppError> {
    describe_with(request, MapPolicy::IfLarger)
}

/// [`describe`], mapping the file as `map` says.
fn describe_with(request: &Request, map: MapPolicy) -> Result<Described, AppError> {
    let spec = request.spec.name();
    let max_memory = request.max_memory();
    let (volume, mut file) = match &request.spec {
        Spec::Source(source) => {
            let n = source_grid(request)? as u64;
            volray_io::check_volume_size(
                Path::new(source),
                "points per side",
                &[n, n, n],
                4,
                max_memory,
            )?;
            (volray_data::generate(source)?, None)
        }
        Spec::File(path) => {
            let opts = read_options(request, max_memory, map)?;
            let loaded = match volray_io::read(path, &opts) {
                Ok(loaded) => loaded,
                Err(IoError::FlatImage { mut image, .. }) => {
                    if let Some(s) = request.spacing {
                        image.spacing = DVec3::from(s);
                    }
                    return Ok(Described::Image { name: spec, image });
                }
                Err(e) => return Err(e.into()),
            };
            (loaded.volume, Some((loaded.format, loaded.info)))
        }
    };
    let reoriented = file
        .as_mut()
        .and_then(|(_, info)| info.reorientation.as_mut());
    let volume = match (request.spacing, reoriented) {
        // Kept in the file's axes (a distributed render's mapping): the
        // spacing is the world-aligned volume's, which its boxes take.
        (Some(s), Some(r)) => {
            let s = DVec3::from(s);
            if !(s.is_finite() && s.min_element() > 0.0) {
                let e = volray_core::VolumeError::BadSpacing(s.x, s.y, s.z);
                return Err(AppError::Spacing(e));
            }
            r.spacing = s;
            volume
        }
        (Some(s), None) => volume
            .with_spacing(DVec3::from(s))
            .map_err(AppError::Spacing)?,
        (None, _) => volume,
    };
    Ok(Described::Volume(Box::new(Input {
        volume,
        name: spec,
        file,
        max_memory,
        display_note: None,
        auto_log: false,
    })))
}

/// The reader's options for the file `request` names, from its options:
/// the format, a raw layout, the frame, array, level and channel, the
/// memory limit `max_memory` and the mapping policy. A built-in source
/// gets the options a file would.
pub fn read_options(
    request: &Request,
    max_memory: u64,
    map: MapPolicy,
) -> Result<ReadOptions, AppError> {
    let spec = request.spec.name();
    let path = PathBuf::from(&spec);
    let raw_flags = request.raw_flags();
    let format = format_named(request.format.as_deref())?;
    // Raw layout flags on a file that names another format (`a.npy
    // --dtype u8`) are misplaced, not a raw file missing its --dims.
    if raw_flags
        && format.is_none()
        && let Some(named) = VolumeFormat::from_path(&path).filter(|f| *f != VolumeFormat::Raw)
    {
        return Err(AppError::RawLayoutOnFormat {
            spec,
            format: named.description(),
        });
    }
    let raw = if raw_flags || format == Some(VolumeFormat::Raw) {
        Some(raw_options(request, &path)?)
    } else {
        None
    };
    Ok(ReadOptions {
        format,
        raw,
        frame: request.frame,
        array: request.array.clone(),
        level: level_number(request)?,
        channel: request.channel,
        max_memory,
        // A volume over --max-memory is mapped from its file where its
        // format allows (volray-io's MapPolicy), refused otherwise.
        map,
        series: request.series.clone(),
    })
}

/// The points per side of the built-in source `request` names, after
/// refusing the file options given with it: parsed as the source itself
/// parses it (every built-in source is an N³ grid), so that its size is
/// checked before it is generated.
pub fn source_grid(request: &Request) -> Result<usize, AppError> {
    let spec = request.spec.name();
    let file_flags = request.format.is_some()
        || request.frame.is_some()
        || request.array.is_some()
        || request.series.is_some();
    let zarr_flags = request.level.is_some() || request.channel.is_some();
    if request.raw_flags() || file_flags || zarr_flags {
        return Err(AppError::FileOptionsOnSource { spec });
    }
    source_points(&spec)
}

/// `--level` as a number: `auto` needs the picture it is chosen for, so
/// only `render`'s still images take it (see `plan.rs`); elsewhere it
/// is refused.
fn level_number(request: &Request) -> Result<Option<usize>, AppError> {
    match request.level {
        None => Ok(None),
        Some(LevelChoice::Index(n)) => Ok(Some(n)),
        Some(LevelChoice::Auto) => Err(AppError::AutoLevelNeedsStill),
    }
}

fn source_points(spec: &str) -> Result<usize, AppError> {
    use volray_data::{
        SourceSpec, blobs::Blobs, fractal::FractalParams, hydrogen::HydrogenParams,
        marschner_lobb::MarschnerLobb, sphere::Sphere, torus::Torus,
    };
    let parsed = SourceSpec::parse(spec)?;
    Ok(match parsed.name.as_str() {
        "marschner-lobb" => MarschnerLobb::from_spec(&parsed)?.n,
        "blobs" => Blobs::from_spec(&parsed)?.n,
        "sphere" => Sphere::from_spec(&parsed)?.n,
        "torus" => Torus::from_spec(&parsed)?.n,
        "hydrogen" => HydrogenParams::from_spec(&parsed)?.grid,
        "fractal" => FractalParams::from_spec(&parsed)?.size,
        // A source added later: its volume is checked when rendered.
        _ => 2,
    })
}

fn raw_options(request: &Request, path: &Path) -> Result<RawOptions, AppError> {
    let dims = request.dims.ok_or_else(|| AppError::RawNeedsDims {
        path: path.display().to_string(),
    })?;
    let (dtype, endian) = (request.dtype.as_deref(), request.endian.as_deref());
    raw_layout(dims, dtype, endian, request.spacing)
}

/// The format a front end names (`--format`, Python's `format=`), if any.
pub fn format_named(name: Option<&str>) -> Result<Option<VolumeFormat>, AppError> {
    (name.map(str::parse::<VolumeFormat>).transpose()).map_err(|e| AppError::BadValue {
        option: InputOpt::Format,
        message: e.to_string(),
    })
}

/// A raw file's layout: `dims` points of `dtype` (default `f32`) in
/// `endian` byte order (default little), `spacing` apart (default 1).
pub fn raw_layout(
    dims: [usize; 3],
    dtype: Option<&str>,
    endian: Option<&str>,
    spacing: Option<[f64; 3]>,
) -> Result<RawOptions, AppError> {
    let dtype = match dtype {
        Some(d) => d.parse::<DType>().map_err(|e| AppError::BadValue {
            option: InputOpt::Dtype,
            message: e.to_string(),
        })?,
        None => DType::F32,
    };
    let endian = match endian {
        Some(e) => e.parse::<Endian>().map_err(|e| AppError::BadValue {
            option: InputOpt::Endian,
            message: e.to_string(),
        })?,
        None => Endian::Little,
    };
    let mut raw = RawOptions::new(dims, dtype);
    raw.endian = endian;
    raw.spacing = DVec3::from(spacing.unwrap_or([1.0; 3]));
    Ok(raw)
}
