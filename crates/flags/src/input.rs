//! Where the volume comes from and how to read it: INPUT and the reading
//! options (`--dims`, `--dtype`, `--endian`, `--spacing`, `--format`,
//! `--frame`, `--series`, `--array`, `--level`, `--channel`, `--max-memory`), which `render`, `bench` and
//! `info` share. volray-app's `input` reads the volume they describe
//! ([`InputArgs::request`]).

use super::parse::{parse_dims, parse_spacing};
use clap::Args;
use volray_options::level::LevelChoice;

/// Where the volume comes from and how to read it.
#[derive(Debug, Clone, Args)]
pub struct InputArgs {
    /// A volume file or a built-in source spec such as
    /// `marschner-lobb:41`, `blobs:64`, `sphere:64,radius=0.7`, `torus`
    /// (see `volray-data`); default: the demo volume, the paper's fractal
    /// cloud of Figure 2a (`render` without INPUT draws it in the demo's
    /// look when no look flag is given).
    /// A file whose name is a source's name needs a path, e.g. `./sphere`.
    pub input: Option<String>,

    /// Raw files: points along x, y and z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_dims, allow_hyphen_values = true, help_heading = "Raw files")]
    pub dims: Option<[usize; 3]>,

    /// Raw files: the sample type.
    #[arg(
        long,
        value_name = "u8|i8|u16|i16|u32|i32|u64|i64|f16|f32|f64",
        help_heading = "Raw files"
    )]
    pub dtype: Option<String>,

    /// Raw files: the byte order.
    #[arg(long, value_name = "little|big", help_heading = "Raw files")]
    pub endian: Option<String>,

    /// Voxel spacing in world units along x, y and z, replacing what the
    /// file says [default: the file's spacing; 1,1,1 for raw and .npy
    /// files; built-in sources have their own].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_spacing, allow_hyphen_values = true)]
    pub spacing: Option<[f64; 3]>,

    /// Stretch each world axis by these factors for drawing (vertical
    /// exaggeration): spacing and origin are multiplied, so --look-at,
    /// --crop and --clip are in the stretched coordinates [default: axes
    /// in different units (degrees by metres) drawn with comparable
    /// extents, a note says how; others as stored]. 1,1,1 draws the axes
    /// as stored. `info` notes the default; `convert` writes the volume
    /// as stored.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_spacing, allow_hyphen_values = true)]
    pub scale: Option<[f64; 3]>,

    /// Read the file as this format, whatever its name and content say
    /// [default: from the extension, else from the file's magic number].
    #[arg(
        long,
        value_name = "raw|npy|nrrd|metaimage|nifti|vtk|vti|dicom|tiff|hdf5|cube|mrc|chgcar"
    )]
    pub format: Option<String>,

    /// Which time point of a file that holds several, from 0: a 4-D NIfTI,
    /// NRRD or MetaImage volume, a hyperstack's or OME-TIFF's, an HDF5
    /// dataset's or OME-Zarr image's `t`; for files of other volumes, a
    /// cube file's orbital, a DICOM directory's series, ... [default: 0].
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub frame: Option<usize>,

    /// DICOM: which series of a directory or DICOMDIR (a CD or DVD):
    /// its number in the list `volray info` shows, from 1, or its
    /// SeriesInstanceUID [default: the largest, with a note naming the
    /// others].
    // Its own id: `render`'s MORE volumes are `series` already.
    #[arg(long = "series", id = "dicom_series", value_name = "N|UID")]
    pub series: Option<String>,

    /// Which named array of a VTK file (.vtk, .vti) [default: the active
    /// scalars, else the first array].
    #[arg(long, value_name = "NAME")]
    pub array: Option<String>,

    /// Zarr/OME-Zarr: which resolution level of a multiscale image, 0 the
    /// finest (`volray info` lists them), or `auto` (render, view): the
    /// coarsest level whose voxels are no larger than a pixel [default:
    /// auto where `render` or `view` draws a multiscale image; 0 elsewhere].
    #[arg(long, value_name = "N|auto", value_parser = parse_level)]
    pub level: Option<LevelChoice>,

    /// Which channel, from 0, of a file that holds several: an OME-Zarr
    /// image's or HDF5 dataset's `c` axis, a hyperstack's or OME-TIFF's
    /// channels, a 5-D NIfTI's components (`dim[5]`), an NRRD's or
    /// MetaImage's vector components; --frame picks the time point
    /// [default: 0].
    #[arg(long, value_name = "N")]
    pub channel: Option<usize>,

    /// The most memory the volume may take, read and rendered: bytes, or
    /// a number with K, M, G or T (powers of 1024), e.g. 512M, 4G, 1.5GiB.
    /// A file whose header asks for more, or a volume whose rendering may
    /// need more, is refused before anything is allocated [default: half
    /// the physical memory].
    #[arg(long, value_name = "SIZE", value_parser = volray_io::parse_size, allow_hyphen_values = true)]
    pub max_memory: Option<u64>,
}

/// A `--level`: `auto` or a level number.
fn parse_level(text: &str) -> Result<LevelChoice, String> {
    text.trim().parse()
}

impl InputArgs {
    /// INPUT and its reading flags in volray-app's plain terms.
    pub fn request(&self) -> volray_app::input::Request {
        volray_app::input::Request {
            spec: volray_app::input::Spec::parse(
                self.input.as_deref().unwrap_or(volray_app::input::DEMO),
            ),
            dims: self.dims,
            dtype: self.dtype.clone(),
            endian: self.endian.clone(),
            spacing: self.spacing,
            format: self.format.clone(),
            frame: self.frame,
            series: self.series.clone(),
            array: self.array.clone(),
            level: self.level,
            channel: self.channel,
            max_memory: self.max_memory,
            scale: self.scale,
        }
    }

    /// These flags reading INPUT whole at `level` (`--level auto`
    /// resolved to a number).
    pub fn at_level(&self, level: Option<usize>) -> InputArgs {
        InputArgs {
            // Unresolved (a built-in source): as given, for the reader to refuse.
            level: level.map(LevelChoice::Index).or(self.level),
            ..self.clone()
        }
    }
}
