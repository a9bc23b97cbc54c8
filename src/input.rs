//! The INPUT argument: a built-in source spec or a volume file.

use crate::error::CliError;
use crate::flags::InputArgs;
use std::path::{Path, PathBuf};
use volray_core::glam::DVec3;
use volray_core::{NonFinite, Volume};
use volray_io::{
    DType, Endian, FileInfo, FlatImage, IoError, MapPolicy, RawOptions, ReadOptions, VolumeFormat,
};
use volray_options::level::LevelChoice;

/// What `volray render` shows when given no input.
pub const DEMO: &str = "fractal:129,seed=1,dim=3.7,sigma=1,ramp=0.3,threshold=0.5869113206863403";

/// A loaded volume and how to name it in messages.
pub struct Input {
    pub volume: Volume,
    /// The spec or the file's path, for messages.
    pub name: String,
    /// The file's format and what its header said, if it came from a file.
    pub file: Option<(VolumeFormat, FileInfo)>,
    /// `--max-memory` (or its default), which rendering must fit too.
    pub max_memory: u64,
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

/// Loads the input for rendering: a file holding an image, not a volume,
/// is refused with the reason (exit 1).
pub fn load(args: &InputArgs) -> Result<Input, CliError> {
    load_with(args, MapPolicy::IfLarger)
}

/// [`load`], mapping the file as `map` says (a distributed render maps
/// every file it can, and reads each rank's box from the map).
pub fn load_with(args: &InputArgs, map: MapPolicy) -> Result<Input, CliError> {
    match describe_with(args, map)? {
        Described::Volume(input) => Ok(*input),
        Described::Image { name, image } => Err(CliError::from(IoError::FlatImage {
            path: name.into(),
            image,
        })),
    }
}

/// Loads the input for `volray info`: a volume, or the image a file holds.
pub fn describe(args: &InputArgs) -> Result<Described, CliError> {
    describe_with(args, MapPolicy::IfLarger)
}

/// [`describe`], mapping the file as `map` says.
fn describe_with(args: &InputArgs, map: MapPolicy) -> Result<Described, CliError> {
    let spec = args.input.as_deref().unwrap_or(DEMO);
    let max_memory = args
        .max_memory
        .unwrap_or_else(volray_io::default_max_memory);
    let (volume, mut file) = if volray_data::is_source_spec(spec) {
        let n = source_grid(args, spec)? as u64;
        volray_io::check_volume_size(
            Path::new(spec),
            "points per side",
            &[n, n, n],
            4,
            max_memory,
        )?;
        (volray_data::generate(spec)?, None)
    } else {
        let path = PathBuf::from(spec);
        let opts = read_options(args, spec, &path, max_memory, map)?;
        let loaded = match volray_io::read(&path, &opts) {
            Ok(loaded) => loaded,
            Err(IoError::FlatImage { mut image, .. }) => {
                if let Some(s) = args.spacing {
                    image.spacing = DVec3::from(s);
                }
                return Ok(Described::Image {
                    name: spec.to_string(),
                    image,
                });
            }
            Err(e) => return Err(e.into()),
        };
        (loaded.volume, Some((loaded.format, loaded.info)))
    };
    let reoriented = file
        .as_mut()
        .and_then(|(_, info)| info.reorientation.as_mut());
    let volume = match (args.spacing, reoriented) {
        // Kept in the file's axes (a distributed render's mapping): the
        // spacing is the world-aligned volume's, which its boxes take.
        (Some(s), Some(r)) => {
            let s = DVec3::from(s);
            if !(s.is_finite() && s.min_element() > 0.0) {
                let e = volray_core::VolumeError::BadSpacing(s.x, s.y, s.z);
                return Err(CliError::input(format!("--spacing: {e}")));
            }
            r.spacing = s;
            volume
        }
        (Some(s), None) => volume
            .with_spacing(DVec3::from(s))
            .map_err(|e| CliError::input(format!("--spacing: {e}")))?,
        (None, _) => volume,
    };
    Ok(Described::Volume(Box::new(Input {
        volume,
        name: spec.to_string(),
        file,
        max_memory,
    })))
}

/// The reader's options for the file `path` (INPUT as given: `spec`)
/// from the input flags: the format, a raw layout, the frame, array,
/// level and channel, the memory limit and the mapping policy.
pub fn read_options(
    args: &InputArgs,
    spec: &str,
    path: &Path,
    max_memory: u64,
    map: MapPolicy,
) -> Result<ReadOptions, CliError> {
    let raw_flags = args.dims.is_some() || args.dtype.is_some() || args.endian.is_some();
    let format = match &args.format {
        Some(f) => Some(
            f.parse::<VolumeFormat>()
                .map_err(|e| CliError::input(format!("--format: {e}")))?,
        ),
        None => None,
    };
    // Raw layout flags on a file that names another format (`a.npy
    // --dtype u8`) are misplaced, not a raw file missing its --dims.
    if raw_flags
        && format.is_none()
        && let Some(named) = VolumeFormat::from_path(path).filter(|f| *f != VolumeFormat::Raw)
    {
        return Err(CliError::input(format!(
            "{spec}: --dims, --dtype and --endian describe raw files; this is a {} file (give --format raw to read it as raw)",
            named.description()
        )));
    }
    let raw = if raw_flags || format == Some(VolumeFormat::Raw) {
        Some(raw_options(args, path)?)
    } else {
        None
    };
    Ok(ReadOptions {
        format,
        raw,
        frame: args.frame,
        array: args.array.clone(),
        level: level_number(args)?,
        channel: args.channel,
        max_memory,
        // A volume over --max-memory is mapped from its file where its
        // format allows (volray-io's MapPolicy), refused otherwise.
        map,
    })
}

/// Points per side of the cube grid the built-in source `spec` samples,
/// parsed as the source itself parses it (every built-in source is an
/// N³ grid), so that its size is checked before it is generated.
/// The points per side of built-in source `spec`, after refusing the file
/// flags given with it.
pub fn source_grid(args: &InputArgs, spec: &str) -> Result<usize, CliError> {
    let raw_flags = args.dims.is_some() || args.dtype.is_some() || args.endian.is_some();
    let file_flags = args.format.is_some() || args.frame.is_some() || args.array.is_some();
    let zarr_flags = args.level.is_some() || args.channel.is_some();
    if raw_flags || file_flags || zarr_flags {
        return Err(CliError::input(format!(
            "{spec}: --dims, --dtype, --endian, --format, --frame, --array, --level and --channel apply to files only, not to built-in sources"
        )));
    }
    source_points(spec)
}

/// `--level` as a number: `auto` needs the picture it is chosen for, so
/// only `render`'s still images take it (see `streamed.rs`); elsewhere it
/// is refused.
fn level_number(args: &InputArgs) -> Result<Option<usize>, CliError> {
    match args.level {
        None => Ok(None),
        Some(LevelChoice::Index(n)) => Ok(Some(n)),
        Some(LevelChoice::Auto) => Err(CliError::input(
            "--level auto chooses the level a still image needs (volray render ... -o OUT.png): give a level number here, 0 the finest",
        )),
    }
}

fn source_points(spec: &str) -> Result<usize, CliError> {
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

fn raw_options(args: &InputArgs, path: &Path) -> Result<RawOptions, CliError> {
    let name = path.display();
    let dims = args.dims.ok_or_else(|| {
        CliError::input(format!(
            "{name}: raw data needs --dims X,Y,Z (and --dtype unless it is f32)"
        ))
    })?;
    let dtype = match &args.dtype {
        Some(d) => d
            .parse::<DType>()
            .map_err(|e| CliError::input(format!("--dtype: {e}")))?,
        None => DType::F32,
    };
    let endian = match &args.endian {
        Some(e) => e
            .parse::<Endian>()
            .map_err(|e| CliError::input(format!("--endian: {e}")))?,
        None => Endian::Little,
    };
    let mut raw = RawOptions::new(dims, dtype);
    raw.endian = endian;
    raw.spacing = DVec3::from(args.spacing.unwrap_or([1.0; 3]));
    Ok(raw)
}
