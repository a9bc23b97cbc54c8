//! The command line: argument definitions and their value parsers. Nothing
//! here renders; `render.rs` and `bench.rs` turn these into library calls.

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use volray_data::fractal::FractalParams;

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
    /// Describe a volume: format, dims, spacing, origin, sample type, value
    /// range, a histogram, and what the header said versus what was used.
    Info(InfoArgs),
    /// Write a generated volume to a file: a hydrogen-atom density or a
    /// fractal cloud (the paper's two test data sets).
    Generate(GenerateArgs),
}

/// `volray generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    #[command(subcommand)]
    pub kind: GenerateKind,
}

#[derive(Debug, Subcommand)]
pub enum GenerateKind {
    /// The hydrogen-atom probability density |ψ_nlm|² (in a₀⁻³) on an
    /// N³ grid over [−R, R]³ (in a₀).
    Hydrogen(HydrogenArgs),
    /// A fractal cloud by 3-D midpoint displacement, post-processed as in
    /// the paper (ramp toward the boundary, threshold, negatives to 0).
    Fractal(FractalArgs),
}

#[derive(Debug, Args)]
pub struct HydrogenArgs {
    /// Principal quantum number, 1 to 12.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub n: u32,
    /// Orbital quantum number, 0 to n − 1.
    #[arg(long, value_name = "L")]
    pub l: u32,
    /// Magnetic quantum number, −l to l.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub m: i32,
    /// Points per side of the grid.
    #[arg(long, value_name = "N", default_value_t = 50)]
    pub grid: usize,
    /// Half-width R of the cube [−R, R]³ in Bohr radii [default: the
    /// radius that holds 99.5% of the radial probability].
    #[arg(long, value_name = "R")]
    pub extent: Option<f64>,
    /// The real orbital chemists use (p_x, p_y, d_xy, ...: cos mφ for m > 0,
    /// sin |m|φ for m < 0) instead of the complex e^{imφ} one.
    #[arg(long)]
    pub real: bool,
    /// Output file: .nrrd (keeps spacing and origin), .npy or .raw
    /// (f32, little-endian, x fastest), written atomically.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct FractalArgs {
    /// Points per side: 2^k + 1 (3, 5, 9, ..., 1025).
    #[arg(long, value_name = "N", default_value_t = FractalParams::default().size)]
    pub size: usize,
    /// Fractal dimension D of the field's graph, 3 ≤ D < 4 (Hurst H = 4 − D).
    #[arg(long, value_name = "D", default_value_t = FractalParams::default().dimension)]
    pub dimension: f64,
    /// Standard deviation of the corner values (the coarsest displacements).
    #[arg(long, value_name = "SIGMA", default_value_t = FractalParams::default().sigma)]
    pub sigma: f64,
    /// Random seed: the same seed gives the same bytes on any machine.
    #[arg(long, value_name = "SEED", default_value_t = FractalParams::default().seed)]
    pub seed: u64,
    /// Post-processing: the fraction of the half width over which the
    /// field is ramped down to 0 at the boundary sphere (0 < R ≤ 1).
    #[arg(long, value_name = "R", default_value_t = FractalParams::default().ramp)]
    pub ramp: f64,
    /// Post-processing: subtracted from the field scaled to [0, 1] (after
    /// the ramp) before negatives are set to 0 (0 ≤ T < 1).
    #[arg(long, value_name = "T", default_value_t = FractalParams::default().threshold, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Skip the post-processing: write the raw midpoint-displacement field.
    #[arg(long)]
    pub raw_field: bool,
    /// Voss's successive random additions: displace every point at every
    /// level, for better statistics.
    #[arg(long)]
    pub random_additions: bool,
    /// Output file: .nrrd (keeps spacing and origin), .npy or .raw
    /// (f32, little-endian, x fastest), written atomically.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
}

/// `volray info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// Histogram bins.
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=1000))]
    pub bins: u16,

    /// Print the description as JSON instead of text.
    #[arg(long)]
    pub json: bool,
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

    /// A transfer-function preset: ct-bone and ct-soft-tissue (Hounsfield
    /// units), mr and electron-density (relative to the value range).
    /// Conflicts with --tf.
    #[arg(long, value_name = "ct-bone|ct-soft-tissue|mr|electron-density")]
    pub preset: Option<String>,

    /// A named colour map for the colour transfer function, replacing a
    /// preset's colours. Conflicts with a colour in --tf [default: white].
    #[arg(
        long,
        value_name = "viridis|magma|inferno|plasma|cividis|turbo|coolwarm|grey"
    )]
    pub colormap: Option<String>,

    /// The value window LO,HI that t = 0..1 spans (values outside are
    /// clamped) [default: the volume's min and max]. Conflicts with a
    /// domain in --tf and with the CT presets, whose window is fixed.
    #[arg(long, value_name = "LO,HI", value_parser = parse_range, allow_hyphen_values = true)]
    pub range: Option<(f64, f64)>,

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

    /// Output image, written atomically (never half-written): PNG, or
    /// OpenEXR (32-bit float RGBA, unquantised) if the name ends in .exr.
    #[arg(short, long, value_name = "OUT.png|OUT.exr")]
    pub output: PathBuf,

    /// Bits per channel of a PNG.
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

    /// Instead of INPUT, time the peer benchmark's six workloads from the
    /// raw float32 volumes and JSON sidecars in DIR (made by the peers'
    /// make_volumes.py), each exactly as the peers define it: view along
    /// +x, step 0.5 voxel, their transfer functions and shading. The view
    /// options other than --threads do not apply.
    #[arg(long, value_name = "DIR")]
    pub peers: Option<PathBuf>,

    /// With --peers: only these workloads, each NAME:W (the volume
    /// DIR/NAME.raw with its sidecar, in a W×W window) [default: the six
    /// workloads hydrogen_421:120, hydrogen_632:120, fractal_65:240,
    /// fractal_129:480, fractal_257:480, fractal_257:1024].
    #[arg(long, value_name = "NAME:W,...", requires = "peers", value_parser = parse_cases)]
    pub cases: Option<Cases>,

    /// Also write the medians to FILE as a JSON list of
    /// {"dataset", "window", "threads", "median_s"}.
    #[arg(long, value_name = "FILE.json")]
    pub json: Option<PathBuf>,

    /// With --peers: also time VTK's fixed-point ray caster on each
    /// workload in the same run, alternating with volray, through the
    /// peers' vtk_bench.py in DIR's parent, and print the ratios and the
    /// image differences.
    #[arg(long, requires = "peers")]
    pub vs_vtk: bool,

    /// The Python of the peers' venv, for --vs-vtk [default:
    /// $VOLRAY_PEERS_PYTHON, else DIR/../.venv/bin/python].
    #[arg(long, value_name = "PATH", requires = "vs_vtk")]
    pub peers_python: Option<PathBuf>,

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

fn parse_range(s: &str) -> Result<(f64, f64), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [lo, hi] if lo < hi => Ok((lo, hi)),
        [lo, hi] => Err(format!("LO {lo} must be below HI {hi}")),
        ref v => Err(format!("expected LO,HI (two numbers), got {}", v.len())),
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

/// Workloads of `bench --cases`: volume names and window sizes.
#[derive(Debug, Clone, PartialEq)]
pub struct Cases(pub Vec<(String, usize)>);

/// `NAME:W,NAME:W,...` for `bench --cases`.
fn parse_cases(s: &str) -> Result<Cases, String> {
    s.split(',')
        .map(|case| {
            let (name, window) = case
                .split_once(':')
                .ok_or(format!("'{case}' is not NAME:W"))?;
            let window = window
                .trim()
                .parse::<usize>()
                .ok()
                .filter(|w| (1..=16384).contains(w))
                .ok_or(format!("'{window}' is not a window size from 1 to 16384"))?;
            let name = name.trim();
            if name.is_empty() || name.contains(['/', '\\']) {
                return Err(format!("'{name}' is not a volume name"));
            }
            Ok((name.to_string(), window))
        })
        .collect::<Result<_, _>>()
        .map(Cases)
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
        assert_eq!(
            parse_cases("fractal_129:480, hydrogen_421:120"),
            Ok(Cases(vec![
                ("fractal_129".to_string(), 480),
                ("hydrogen_421".to_string(), 120)
            ]))
        );
        assert!(parse_cases("fractal_129").is_err());
        assert!(parse_cases("fractal_129:0").is_err());
        assert!(parse_cases("../x:10").is_err());
        assert!(parse_bit_depth("12").is_err());
    }
}
