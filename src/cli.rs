//! The command line: argument definitions and their value parsers. Nothing
//! here renders; `render.rs` and `bench.rs` turn these into library calls.

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "volray",
    version,
    about = "Ray-casting volume renderer (Ramesh & Athithan 1993, after Levoy 1988)",
    long_about = "Ray-casting volume renderer (Ramesh & Athithan 1993, after Levoy 1988).\n\n\
        Exit codes: 0 success, 1 bad input or arguments, 2 I/O failure."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a volume to a PNG image.
    Render(RenderArgs),
    /// Time frames of a volume: median of several views, each new.
    Bench(BenchArgs),
}

/// Where the volume comes from and how to read it.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// A volume file or a built-in source spec such as
    /// `marschner-lobb:41`, `blobs:64`, `sphere:64,radius=0.7`, `torus`
    /// (see `volray-data`); default: the demo volume `blobs:64`.
    /// A file whose name is a source's name needs a path, e.g. `./sphere`.
    pub input: Option<String>,

    /// Raw files: points along x, y and z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_dims, help_heading = "Raw files")]
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
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_positive_vec3)]
    pub spacing: Option<[f64; 3]>,

    /// Read the file as this format, whatever its name and content say
    /// [default: from the extension, else from the file's magic number].
    #[arg(
        long,
        value_name = "raw|npy|nrrd|metaimage|nifti|vtk|vti|dicom|tiff|hdf5|cube|mrc|chgcar"
    )]
    pub format: Option<String>,

    /// Which volume of a file that holds several, from 0: a 4-D NIfTI,
    /// NRRD or MetaImage time point, a cube file's orbital, ... [default: 0].
    #[arg(long, value_name = "N")]
    pub frame: Option<usize>,

    /// Which named array of a VTK file (.vtk, .vti) [default: the active
    /// scalars, else the first array].
    #[arg(long, value_name = "NAME")]
    pub array: Option<String>,
}

/// How to render a frame.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Image size: W (square) or WxH, in pixels.
    #[arg(long, value_name = "W|WxH", default_value = "480", value_parser = parse_size)]
    pub size: (usize, usize),

    /// View point, world coordinates [default: on the +x axis through the
    /// view reference, looking along −x, as in the paper's Fig. 1a].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub view: Option<[f64; 3]>,

    /// View reference (the point looked at, the image centre) [default: the
    /// centre of the volume].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_at: Option<[f64; 3]>,

    /// Up direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,1", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: [f64; 3],

    /// Sample spacing along the rays, in voxels (of the smallest spacing).
    #[arg(
        long,
        value_name = "S",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub step: f64,

    /// The paper's opacity ramp: α = p + t·(q − p) over the normalised value
    /// t, with 0 ≤ p < q ≤ 1 [default: 0,0.5]. Conflicts with an opacity in --tf.
    #[arg(long, value_name = "P,Q", value_parser = parse_pair, allow_hyphen_values = true)]
    pub opacity: Option<(f32, f32)>,

    /// Transfer function JSON: {"domain": [lo, hi], "opacity": [[t, a], ...],
    /// "color": [[t, r, g, b], ...]}, all keys optional.
    #[arg(long, value_name = "FILE.json")]
    pub tf: Option<PathBuf>,

    /// Ambient reflection k_a: one value or r,g,b.
    #[arg(long, value_name = "A|R,G,B", allow_hyphen_values = true, default_value = "0.1", value_parser = parse_rgb)]
    pub ambient: [f32; 3],

    /// Diffuse reflection k_d: one value or r,g,b.
    #[arg(long, value_name = "D|R,G,B", allow_hyphen_values = true, default_value = "0.7", value_parser = parse_rgb)]
    pub diffuse: [f32; 3],

    /// Specular reflection k_s: one value or r,g,b.
    #[arg(long, value_name = "S|R,G,B", allow_hyphen_values = true, default_value = "0.2", value_parser = parse_rgb)]
    pub specular: [f32; 3],

    /// Specular exponent n.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 10.0,
        allow_hyphen_values = true
    )]
    pub shininess: f32,

    /// Direction towards the light at infinity [default: a headlight, L = V].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub light: Option<[f64; 3]>,

    /// Colour of the light, C_s.
    #[arg(long, value_name = "R,G,B", default_value = "1,1,1", value_parser = parse_rgb)]
    pub light_color: [f32; 3],

    /// No lighting: voxels take their material colour.
    #[arg(long)]
    pub no_shading: bool,

    /// The opaque background colour, components in [0, 1].
    #[arg(long, value_name = "R,G,B", default_value = "0,0,0", value_parser = parse_rgb)]
    pub background: [f32; 3],

    /// Use the reference path (the paper's back-to-front compositing, no
    /// shortcuts), the oracle for the fast default.
    #[arg(long)]
    pub reference: bool,

    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// Output PNG file, written atomically (never half-written).
    #[arg(short, long, value_name = "OUT.png")]
    pub output: PathBuf,

    /// Bits per channel of the PNG.
    #[arg(long, value_name = "8|16", default_value = "8", value_parser = parse_bit_depth)]
    pub bit_depth: u8,

    #[command(flatten)]
    pub view: ViewArgs,
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// Timed frames after one warm-up; each turns the camera by a further
    /// half degree about the up axis, so no frame reuses view-dependent work.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub frames: u32,

    #[command(flatten)]
    pub view: ViewArgs,
}

fn numbers<T: std::str::FromStr>(s: &str, what: &str) -> Result<Vec<T>, String> {
    s.split(',')
        .map(|part| {
            part.trim()
                .parse::<T>()
                .map_err(|_| format!("'{part}' is not a valid {what}"))
        })
        .collect()
}

fn finite(values: Vec<f64>) -> Result<Vec<f64>, String> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("{v} is not a finite number")),
        None => Ok(values),
    }
}

pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = finite(numbers::<f64>(s, "number")?)?;
    <[f64; 3]>::try_from(v).map_err(|v| format!("expected X,Y,Z (three numbers), got {}", v.len()))
}

fn parse_positive_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = parse_vec3(s)?;
    if v.iter().any(|x| *x <= 0.0) {
        return Err("every component must be positive".into());
    }
    Ok(v)
}

fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v = numbers::<usize>(s, "point count")?;
    <[usize; 3]>::try_from(v).map_err(|v| format!("expected X,Y,Z (three counts), got {}", v.len()))
}

fn parse_pair(s: &str) -> Result<(f32, f32), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [p, q] => Ok((p as f32, q as f32)),
        ref v => Err(format!("expected P,Q (two numbers), got {}", v.len())),
    }
}

/// One value for all three channels, or r,g,b.
pub fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [v] => Ok([v as f32; 3]),
        [r, g, b] => Ok([r as f32, g as f32, b as f32]),
        ref v => Err(format!(
            "expected one value or R,G,B, got {} values",
            v.len()
        )),
    }
}

/// `W` (square) or `WxH`.
pub fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let parse = |p: &str| {
        p.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{p}' is not a pixel count"))
    };
    let (w, h) = match s.split_once(['x', 'X']) {
        Some((w, h)) => (parse(w)?, parse(h)?),
        None => (parse(s)?, parse(s)?),
    };
    if w == 0 || h == 0 {
        return Err(format!("image size {w}x{h} must be at least 1x1"));
    }
    Ok((w, h))
}

fn parse_bit_depth(s: &str) -> Result<u8, String> {
    match s {
        "8" => Ok(8),
        "16" => Ok(16),
        _ => Err(format!("bit depth must be 8 or 16, got '{s}'")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_parsers() {
        assert_eq!(parse_vec3("1, -2.5,3e2"), Ok([1.0, -2.5, 300.0]));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,nan,2").is_err());
        assert_eq!(parse_rgb("0.5"), Ok([0.5; 3]));
        assert_eq!(parse_rgb("1,0,0.25"), Ok([1.0, 0.0, 0.25]));
        assert!(parse_rgb("1,0").is_err());
        assert_eq!(parse_size("480"), Ok((480, 480)));
        assert_eq!(parse_size("640x360"), Ok((640, 360)));
        assert!(parse_size("0").is_err());
        assert!(parse_size("12x").is_err());
        assert_eq!(parse_dims("4,5,6"), Ok([4, 5, 6]));
        assert!(parse_dims("4,-5,6").is_err());
        assert_eq!(parse_pair("0.1,0.9"), Ok((0.1, 0.9)));
        assert!(parse_positive_vec3("1,0,1").is_err());
        assert_eq!(parse_bit_depth("16"), Ok(16));
        assert!(parse_bit_depth("12").is_err());
    }
}
