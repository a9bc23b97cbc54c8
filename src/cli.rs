//! The command line: argument definitions and their value parsers. Nothing
//! here renders; `render.rs` and `bench.rs` turn these into library calls.

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use volray_core::{MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE};
use volray_data::fractal::FractalParams;

#[derive(Debug, Parser)]
#[command(
    name = "volray",
    version,
    about = "Ray-casting volume renderer (Ramesh & Athithan 1993, after Levoy 1988)",
    long_about = "Ray-casting volume renderer (Ramesh & Athithan 1993, after Levoy 1988).\n\n\
        Exit codes: 0 success, 1 bad input or arguments, 2 I/O failure, \
        130 interrupted (Ctrl-C; 128 + the signal for SIGTERM and SIGHUP)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a volume to an image (PNG, OpenEXR), or a turntable or a
    /// series of volumes to an animation (animated PNG, GIF, numbered PNGs).
    Render(RenderArgs),
    /// Time frames of a volume: median of several views, each new.
    Bench(BenchArgs),
    /// Describe a volume: format, dims, spacing, origin, sample type, value
    /// range, a histogram, and what the header said versus what was used.
    Info(InfoArgs),
    /// Write a generated volume to a file: a hydrogen-atom density or a
    /// fractal cloud (the paper's two test data sets).
    Generate(GenerateArgs),
    /// Reproduce the paper's Figures 1a, 1b, 1c, 2a, 2b and Table 1 into a
    /// directory (figure1a.png ... figure2b.png, table1.md).
    Paper(PaperArgs),
}

/// `volray paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// What to make: one figure, the table, or all of them.
    #[arg(value_enum, default_value = "all")]
    pub what: PaperItem,
    /// Output directory, created if missing; files in it are replaced
    /// atomically.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Reduced sizes for tests and CI: 30³ grids and 40² panels, 33³ clouds
    /// at 96², small Table 1 cases timed once. Not the paper's sizes.
    #[arg(long)]
    pub quick: bool,
    /// Worker threads [default: one per core]; Table 1 reports the count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..), allow_hyphen_values = true)]
    pub threads: Option<u16>,
}

/// The items of `volray paper`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PaperItem {
    Figure1a,
    Figure1b,
    Figure1c,
    Figure2a,
    Figure2b,
    Table1,
    All,
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
    #[arg(long, value_name = "L", allow_hyphen_values = true)]
    pub l: u32,
    /// Magnetic quantum number, −l to l.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub m: i32,
    /// Points per side of the grid.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 50,
        allow_hyphen_values = true
    )]
    pub grid: usize,
    /// Half-width R of the cube [−R, R]³ in Bohr radii [default: the
    /// radius that holds 99.5% of the radial probability].
    #[arg(long, value_name = "R", allow_hyphen_values = true)]
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
    #[arg(long, value_name = "N", default_value_t = FractalParams::default().size, allow_hyphen_values = true)]
    pub size: usize,
    /// Fractal dimension D of the field's graph, 3 ≤ D < 4 (Hurst H = 4 − D).
    #[arg(long, value_name = "D", default_value_t = FractalParams::default().dimension, allow_hyphen_values = true)]
    pub dimension: f64,
    /// Standard deviation of the corner values (the coarsest displacements).
    #[arg(long, value_name = "SIGMA", default_value_t = FractalParams::default().sigma, allow_hyphen_values = true)]
    pub sigma: f64,
    /// Random seed: the same seed gives the same bytes on any machine.
    #[arg(long, value_name = "SEED", default_value_t = FractalParams::default().seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Post-processing: the fraction of the half width over which the
    /// field is ramped down to 0 at the boundary sphere (0 < R ≤ 1).
    #[arg(long, value_name = "R", default_value_t = FractalParams::default().ramp, allow_hyphen_values = true)]
    pub ramp: f64,
    /// Post-processing: subtracted from the field scaled to [0, 1] (after
    /// the ramp) before negatives are set to 0 (0 ≤ T < 1).
    #[arg(long, value_name = "T", default_value_t = FractalParams::default().threshold, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Skip the post-processing: write the raw midpoint-displacement field.
    #[arg(long, conflicts_with_all = ["ramp", "threshold"])]
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
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=1000), allow_hyphen_values = true)]
    pub bins: u16,

    /// Print the description as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Where the volume comes from and how to read it.
#[derive(Debug, Clone, Args)]
pub struct InputArgs {
    /// A volume file or a built-in source spec such as
    /// `marschner-lobb:41`, `blobs:64`, `sphere:64,radius=0.7`, `torus`
    /// (see `volray-data`); default: the demo volume `blobs:64`.
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

    /// Read the file as this format, whatever its name and content say
    /// [default: from the extension, else from the file's magic number].
    #[arg(
        long,
        value_name = "raw|npy|nrrd|metaimage|nifti|vtk|vti|dicom|tiff|hdf5|cube|mrc|chgcar"
    )]
    pub format: Option<String>,

    /// Which volume of a file that holds several, from 0: a 4-D NIfTI,
    /// NRRD or MetaImage time point, a cube file's orbital, ... [default: 0].
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub frame: Option<usize>,

    /// Which named array of a VTK file (.vtk, .vti) [default: the active
    /// scalars, else the first array].
    #[arg(long, value_name = "NAME")]
    pub array: Option<String>,

    /// The most memory the volume may take, read and rendered: bytes, or
    /// a number with K, M, G or T (powers of 1024), e.g. 512M, 4G, 1.5GiB.
    /// A file whose header asks for more, or a volume whose rendering may
    /// need more, is refused before anything is allocated [default: half
    /// the physical memory].
    #[arg(long, value_name = "SIZE", value_parser = volray_io::parse_size, allow_hyphen_values = true)]
    pub max_memory: Option<u64>,
}

/// How to render a frame.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Image size: W (square) or WxH, in pixels.
    #[arg(long, value_name = "W|WxH", default_value = "480", value_parser = parse_size, allow_hyphen_values = true)]
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
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,1", value_parser = parse_direction, allow_hyphen_values = true)]
    pub up: [f64; 3],

    /// Sample spacing along the rays, in voxels (of the smallest spacing).
    #[arg(long, value_name = "S", default_value = "1", value_parser = parse_step, allow_hyphen_values = true)]
    pub step: f64,

    /// The paper's opacity ramp: α = p + t·(q − p) over the normalised value
    /// t, with 0 ≤ p < q ≤ 1 [default: 0,0.5]. Conflicts with an opacity in --tf.
    #[arg(long, value_name = "P,Q", value_parser = parse_opacity, allow_hyphen_values = true)]
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
    #[arg(long, value_name = "N", default_value = "10", value_parser = parse_shininess, allow_hyphen_values = true)]
    pub shininess: f32,

    /// Direction towards the light at infinity [default: a headlight, L = V].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_direction, allow_hyphen_values = true)]
    pub light: Option<[f64; 3]>,

    /// Colour of the light, C_s.
    #[arg(long, value_name = "R,G,B", default_value = "1,1,1", value_parser = parse_rgb, allow_hyphen_values = true)]
    pub light_color: [f32; 3],

    /// No lighting: voxels take their material colour.
    #[arg(long)]
    pub no_shading: bool,

    /// The opaque background colour, components in [0, 1].
    #[arg(long, value_name = "R,G,B", default_value = "0,0,0", value_parser = parse_background, allow_hyphen_values = true)]
    pub background: [f32; 3],

    /// Use the reference path (the paper's back-to-front compositing, no
    /// shortcuts), the oracle for the fast default.
    #[arg(long)]
    pub reference: bool,

    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..), allow_hyphen_values = true)]
    pub threads: Option<u16>,

    /// How the samples along a ray make the pixel: composite (the paper's
    /// transparency formula), mip (maximum intensity projection, also
    /// `maximum`), minip (minimum, also `minimum`), average (the mean), or
    /// iso (composite of the --iso contour, as --iso alone). The
    /// projections show the value through the colour map (grey without
    /// one: with --range 0,1 a mip pixel's grey is the ray's maximum),
    /// unshaded and opaque.
    #[arg(
        long,
        value_enum,
        value_name = "MODE",
        default_value = "composite",
        help_heading = "Rendering options"
    )]
    pub blend: BlendMode,

    /// Levoy's isovalue contour (1988, eq. 3): only a shell about the
    /// surface f = VALUE is opaque, with the opacity the transfer function
    /// gives VALUE on it, falling to 0 at --iso-thickness voxels either
    /// side, whatever the steepness of the data.
    #[arg(long, value_name = "VALUE", allow_hyphen_values = true, value_parser = parse_iso_value, help_heading = "Rendering options")]
    pub iso: Option<f32>,

    /// Half-width R of the --iso shell, in voxels of the smallest spacing
    /// [default: 1].
    #[arg(long, value_name = "R", allow_hyphen_values = true, value_parser = parse_thickness, help_heading = "Rendering options")]
    pub iso_thickness: Option<f32>,

    /// Render log10 of the data, for values that span decades (densities);
    /// values <= 0 take the log of the smallest positive value. --range,
    /// --iso and a --tf domain stay in the data's own units (they must
    /// then be positive) and are converted: `--log --range 1e-4,1` spans
    /// four decades.
    #[arg(long, help_heading = "Rendering options")]
    pub log: bool,

    /// Opacity times a ramp of the gradient magnitude |∇f|, 0 at LO and 1
    /// at HI, fractions of the volume's largest |∇f| (0 <= LO < HI <= 1):
    /// boundaries show and uniform insides fade.
    #[arg(long, value_name = "LO,HI", value_parser = parse_gradient_opacity, allow_hyphen_values = true, help_heading = "Rendering options")]
    pub gradient_opacity: Option<(f32, f32)>,

    /// Interpolate the scalar (and its gradient) at each sample, then
    /// classify and shade it, instead of the paper's classified voxel
    /// colours: sharper, slower.
    #[arg(long, help_heading = "Rendering options")]
    pub post_classification: bool,

    /// Start each pixel's samples a fraction of a step further (a fixed
    /// hash of the pixel, the same every run) against wood-grain artifacts.
    #[arg(long, help_heading = "Rendering options")]
    pub jitter: bool,

    /// NaN and infinite voxel values: refuse the volume (naming their
    /// count), or render them as empty space: no opacity, not counted by
    /// mip/minip/average; the value window is the finite values'.
    #[arg(
        long,
        value_enum,
        value_name = "refuse|transparent",
        default_value = "refuse",
        help_heading = "Rendering options"
    )]
    pub nonfinite: NonFiniteMode,

    /// Perspective projection with this vertical field of view in degrees
    /// (0 < FOV < 180) [default: orthographic]. Without --view the eye
    /// stands where the volume's bounding sphere just fills the view.
    #[arg(long, value_name = "FOV", value_parser = parse_fov, allow_hyphen_values = true, help_heading = "Camera")]
    pub perspective: Option<f64>,

    /// Magnification about the image centre, > 0: 2 shows everything twice
    /// as large (as VTK's Zoom).
    #[arg(long, value_name = "Z", default_value_t = 1.0, value_parser = parse_zoom, allow_hyphen_values = true, help_heading = "Camera")]
    pub zoom: f64,

    /// Degrees the view point orbits about the up vector through the view
    /// reference (VTK's Azimuth: 90 takes the default eye from +x to +y).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_angle, allow_hyphen_values = true, help_heading = "Camera")]
    pub azimuth: f64,

    /// Degrees the view point then rises about the screen's horizontal
    /// axis (VTK's Elevation: 90 looks down the up vector).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_angle, allow_hyphen_values = true, help_heading = "Camera")]
    pub elevation: f64,

    /// A clip plane through the world point X,Y,Z with normal NX,NY,NZ:
    /// keeps the side the normal points to. Repeatable: what every plane
    /// keeps is rendered.
    #[arg(long, value_name = "X,Y,Z,NX,NY,NZ", value_parser = parse_clip, allow_hyphen_values = true, help_heading = "Camera")]
    pub clip: Vec<([f64; 3], [f64; 3])>,

    /// Render only the world box X0..X1, Y0..Y1, Z0..Z1 (VTK's cropping
    /// region planes, in world coordinates rather than voxels).
    #[arg(long, value_name = "X0,X1,Y0,Y1,Z0,Z1", value_parser = parse_crop, allow_hyphen_values = true, help_heading = "Camera")]
    pub crop: Option<([f64; 3], [f64; 3])>,
}

/// `--nonfinite`: what to do with NaN and infinite voxel values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum NonFiniteMode {
    /// Refuse the volume.
    Refuse,
    /// Render them as empty space.
    Transparent,
}

/// `--blend`: how a ray's samples make its pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BlendMode {
    /// The paper's compositing of classified, shaded samples.
    Composite,
    /// Maximum intensity projection.
    #[value(alias = "maximum")]
    Mip,
    /// Minimum intensity projection.
    #[value(alias = "minimum")]
    Minip,
    /// The mean value along the ray.
    Average,
    /// Composite of Levoy's isovalue contour (needs --iso).
    Iso,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// More volumes after INPUT: render them all as an animation, one
    /// frame per volume in the order given, with one transfer function
    /// (the value range spans every volume unless --range) and one framing
    /// (the box around every volume). They are read one at a time, twice.
    #[arg(value_name = "MORE")]
    pub series: Vec<String>,

    /// Output image, written atomically (never half-written): PNG, or
    /// OpenEXR (32-bit float RGBA, unquantised) if the name ends in .exr.
    /// An animation (--turntable, several inputs) is an animated PNG
    /// (.png), a GIF (.gif) or numbered PNGs (a name with %03d or %d).
    #[arg(short, long, value_name = "OUT.png|OUT.exr|OUT.gif|OUT_%03d.png")]
    pub output: PathBuf,

    /// Bits per channel of a PNG.
    #[arg(long, value_name = "8|16", default_value = "8", value_parser = parse_bit_depth, allow_hyphen_values = true)]
    pub bit_depth: u8,

    /// Render FRAMES views into an animation, the view point orbiting the
    /// up vector (azimuth --azimuth + 360·i/FRAMES for frame i) with the
    /// window fitted to the bounding sphere so the picture keeps its scale.
    #[arg(long, value_name = "FRAMES", value_parser = clap::value_parser!(u32).range(1..=100_000), allow_hyphen_values = true, help_heading = "Animations")]
    pub turntable: Option<u32>,

    /// Frames per second of an animation, in (0, 100] [default: 24]; GIF
    /// keeps the delay in hundredths of a second.
    #[arg(long, value_name = "FPS", value_parser = parse_fps, allow_hyphen_values = true, help_heading = "Animations")]
    pub fps: Option<f64>,

    #[command(flatten)]
    pub view: ViewArgs,
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// Timed frames after one warm-up; each turns the camera by a further
    /// half degree about the up axis, so no frame reuses view-dependent work.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000), allow_hyphen_values = true)]
    pub frames: u32,

    /// Instead of INPUT, time the peer benchmark's six workloads from the
    /// raw float32 volumes and JSON sidecars in DIR (made by the peers'
    /// make_volumes.py), each exactly as the peers define it: view along
    /// +x, step 0.5 voxel, their transfer functions and shading. The view
    /// options other than --threads do not apply, and are refused.
    #[arg(long, value_name = "DIR", conflicts_with_all = PEERS_IGNORE)]
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

/// The options `bench --peers` does not use: the workloads fix their own
/// input, view and transfer functions.
const PEERS_IGNORE: [&str; 41] = [
    "max_memory",
    "nonfinite",
    "dims",
    "dtype",
    "endian",
    "spacing",
    "format",
    "frame",
    "array",
    "size",
    "view",
    "look_at",
    "up",
    "step",
    "opacity",
    "tf",
    "preset",
    "colormap",
    "range",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "light",
    "light_color",
    "no_shading",
    "background",
    "reference",
    "blend",
    "iso",
    "iso_thickness",
    "log",
    "gradient_opacity",
    "post_classification",
    "jitter",
    "perspective",
    "zoom",
    "azimuth",
    "elevation",
    "clip",
    "crop",
];

/// A clap error as one line: its first, with the arguments it lists on the
/// lines below when the first ends in a colon ("the following required
/// arguments were not provided:"), so that the line names the flag.
pub fn one_line_error(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut lines = text.lines();
    let first = lines
        .next()
        .unwrap_or("error: invalid arguments")
        .trim_end();
    match first.strip_suffix(':') {
        Some(head) => {
            let listed: Vec<&str> = lines
                .take_while(|l| l.starts_with("  "))
                .map(str::trim)
                .collect();
            format!("{head}: {}", listed.join(", "))
        }
        None => first.to_string(),
    }
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

/// Finite and within `f32`'s range, for values the renderer keeps as `f32`.
fn finite_f32(values: Vec<f64>) -> Result<Vec<f64>, String> {
    let values = finite(values)?;
    match values.iter().find(|v| v.abs() > f32::MAX as f64) {
        Some(v) => Err(format!("{v} is beyond the range of 32-bit floats")),
        None => Ok(values),
    }
}

pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = finite(numbers::<f64>(s, "number")?)?;
    <[f64; 3]>::try_from(v).map_err(|v| format!("expected X,Y,Z (three numbers), got {}", v.len()))
}

/// The smallest and largest voxel spacing `--spacing` takes, and the most
/// one axis's may exceed another's: beyond these the world box's squared
/// extents leave `f64`, or a ray along the coarse axis would take more
/// samples of the fine one than the renderer allows.
const SPACING_LIMITS: (f64, f64) = (1e-30, 1e30);
const MAX_SPACING_RATIO: f64 = 1e6;

fn parse_spacing(s: &str) -> Result<[f64; 3], String> {
    let v = parse_vec3(s)?;
    if v.iter().any(|x| *x <= 0.0) {
        return Err("every component must be positive".into());
    }
    let (lo, hi) = SPACING_LIMITS;
    if let Some(x) = v.iter().find(|x| !(lo..=hi).contains(*x)) {
        return Err(format!("{x} is outside {lo:e} to {hi:e}"));
    }
    let (min, max) = (
        v.iter().copied().fold(f64::MAX, f64::min),
        v.iter().copied().fold(0.0, f64::max),
    );
    if max / min > MAX_SPACING_RATIO {
        return Err(format!(
            "the largest spacing {max} is more than {MAX_SPACING_RATIO:e} times the smallest {min}"
        ));
    }
    Ok(v)
}

/// A direction (`--up`, `--light`, a clip plane's normal): not zero, and
/// with a length whose square `f64` holds, so that it can be normalised.
fn direction(v: [f64; 3]) -> Result<[f64; 3], String> {
    let largest = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if largest == 0.0 {
        return Err("a direction must not be zero".into());
    }
    if !(1e-100..=1e100).contains(&largest) {
        return Err(format!(
            "the direction {},{},{} is too short or too long to normalise (components from 1e-100 to 1e100)",
            v[0], v[1], v[2]
        ));
    }
    Ok(v)
}

fn parse_direction(s: &str) -> Result<[f64; 3], String> {
    direction(parse_vec3(s)?)
}

/// The fewest points per axis a volume spans (two make one cell).
const MIN_POINTS: usize = 2;

fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v = numbers::<usize>(s, "point count")?;
    let dims = <[usize; 3]>::try_from(v)
        .map_err(|v| format!("expected X,Y,Z (three counts), got {}", v.len()))?;
    match dims.iter().find(|n| **n < MIN_POINTS) {
        Some(n) => Err(format!(
            "every axis needs at least {MIN_POINTS} points to span a volume, got {n}"
        )),
        None => Ok(dims),
    }
}

fn parse_pair(s: &str) -> Result<(f32, f32), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [p, q] => Ok((p as f32, q as f32)),
        ref v => Err(format!("expected P,Q (two numbers), got {}", v.len())),
    }
}

/// The paper's opacity ramp `p,q`: opacities, `0 <= p < q <= 1`.
fn parse_opacity(s: &str) -> Result<(f32, f32), String> {
    match parse_pair(s)? {
        (p, q) if 0.0 <= p && p < q && q <= 1.0 => Ok((p, q)),
        (p, q) => Err(format!("P,Q = {p},{q} needs 0 <= p < q <= 1")),
    }
}

/// `--step`: a positive number of voxels.
fn parse_step(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        v if v > 0.0 => Ok(v),
        v => Err(format!("step {v} must be a positive number of voxels")),
    }
}

/// `--shininess`: the Phong exponent, finite and non-negative.
fn parse_shininess(s: &str) -> Result<f32, String> {
    match finite_f32(vec![parse_number(s)?])?[..] {
        [v] if v >= 0.0 => Ok(v as f32),
        ref v => Err(format!("shininess {} must be non-negative", v[0])),
    }
}

fn parse_range(s: &str) -> Result<(f64, f64), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [lo, hi] if lo < hi => Ok((lo, hi)),
        [lo, hi] => Err(format!("LO {lo} must be below HI {hi}")),
        ref v => Err(format!("expected LO,HI (two numbers), got {}", v.len())),
    }
}

/// One value for all three channels, or r,g,b: reflection coefficients
/// and colours, finite and non-negative.
pub fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    let rgb = match finite_f32(numbers::<f64>(s, "number")?)?[..] {
        [v] => [v as f32; 3],
        [r, g, b] => [r as f32, g as f32, b as f32],
        ref v => {
            return Err(format!(
                "expected one value or R,G,B, got {} values",
                v.len()
            ));
        }
    };
    match rgb.iter().find(|c| **c < 0.0) {
        Some(c) => Err(format!("{c} is negative; components must be 0 or more")),
        None => Ok(rgb),
    }
}

/// `--background`: an opaque colour, components in [0, 1].
fn parse_background(s: &str) -> Result<[f32; 3], String> {
    let rgb = parse_rgb(s)?;
    match rgb.iter().find(|c| **c > 1.0) {
        Some(c) => Err(format!(
            "{c} is above 1; background components lie in [0, 1]"
        )),
        None => Ok(rgb),
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
    if w.max(h) > MAX_IMAGE_SIDE {
        return Err(format!(
            "image {w}x{h}: each side must be between 1 and {MAX_IMAGE_SIDE} pixels"
        ));
    }
    if w * h > MAX_IMAGE_PIXELS {
        return Err(format!(
            "image {w}x{h} has more than {MAX_IMAGE_PIXELS} pixels"
        ));
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

/// One finite number.
fn parse_number(s: &str) -> Result<f64, String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [v] => Ok(v),
        ref v => Err(format!("expected one number, got {}", v.len())),
    }
}

fn parse_iso_value(s: &str) -> Result<f32, String> {
    let v = parse_number(s)?;
    if v.abs() > f32::MAX as f64 {
        return Err(format!("{v} is out of the range of the data's f32 values"));
    }
    Ok(v as f32)
}

fn parse_thickness(s: &str) -> Result<f32, String> {
    match parse_number(s)? {
        r if r > 0.0 && r <= 1e6 => Ok(r as f32),
        r => Err(format!(
            "the shell's half-width {r} must be a positive number of voxels"
        )),
    }
}

fn parse_gradient_opacity(s: &str) -> Result<(f32, f32), String> {
    match parse_pair(s)? {
        (lo, hi) if 0.0 <= lo && lo < hi && hi <= 1.0 => Ok((lo, hi)),
        (lo, hi) => Err(format!(
            "LO,HI = {lo},{hi} needs 0 <= LO < HI <= 1 (fractions of the largest gradient magnitude)"
        )),
    }
}

fn parse_fov(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        fov if fov > 0.0 && fov < 180.0 => Ok(fov),
        fov => Err(format!(
            "field of view {fov} must lie strictly between 0 and 180 degrees"
        )),
    }
}

fn parse_zoom(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        z if z > 0.0 => Ok(z),
        z => Err(format!("zoom {z} must be greater than 0")),
    }
}

fn parse_angle(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        a if a.abs() <= 1e6 => Ok(a),
        a => Err(format!("{a} degrees is not a usable angle")),
    }
}

/// `X,Y,Z,NX,NY,NZ`: a point on the plane and its normal.
fn parse_clip(s: &str) -> Result<([f64; 3], [f64; 3]), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [_, _, _, nx, ny, nz] if nx == 0.0 && ny == 0.0 && nz == 0.0 => {
            Err("the normal NX,NY,NZ must not be zero".into())
        }
        [x, y, z, nx, ny, nz] => Ok(([x, y, z], direction([nx, ny, nz])?)),
        ref v => Err(format!(
            "expected X,Y,Z,NX,NY,NZ (a point and a normal, six numbers), got {}",
            v.len()
        )),
    }
}

/// `X0,X1,Y0,Y1,Z0,Z1` as the box's (low, high) corners.
fn parse_crop(s: &str) -> Result<([f64; 3], [f64; 3]), String> {
    let v = finite(numbers::<f64>(s, "number")?)?;
    if v.len() != 6 {
        return Err(format!(
            "expected X0,X1,Y0,Y1,Z0,Z1 (six numbers), got {}",
            v.len()
        ));
    }
    for (axis, name) in ["X", "Y", "Z"].iter().enumerate() {
        let (lo, hi) = (v[2 * axis], v[2 * axis + 1]);
        if lo >= hi {
            return Err(format!("{name}0 {lo} must be below {name}1 {hi}"));
        }
    }
    Ok(([v[0], v[2], v[4]], [v[1], v[3], v[5]]))
}

fn parse_fps(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        f if f > 0.0 && f <= 100.0 => Ok(f),
        f => Err(format!("{f} frames per second must be in (0, 100]")),
    }
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
        assert!(parse_spacing("1,0,1").is_err());
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

    #[test]
    fn rendering_option_parsers() {
        assert_eq!(parse_fov("30"), Ok(30.0));
        for bad in ["0", "180", "-5", "nan", "30,40"] {
            assert!(parse_fov(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_zoom("2"), Ok(2.0));
        assert!(parse_zoom("0").is_err() && parse_zoom("-1").is_err());
        assert_eq!(parse_angle("-90"), Ok(-90.0));
        assert!(parse_angle("inf").is_err());
        assert_eq!(parse_thickness("0.5"), Ok(0.5));
        assert!(parse_thickness("0").is_err());
        assert_eq!(parse_iso_value("-3e2"), Ok(-300.0));
        assert!(parse_iso_value("1e300").is_err());
        assert_eq!(parse_gradient_opacity("0,0.5"), Ok((0.0, 0.5)));
        assert!(parse_gradient_opacity("0.5,0.5").is_err());
        assert!(parse_gradient_opacity("0.1,1.5").is_err());
        assert_eq!(
            parse_clip("1,2,3,0,-1,0"),
            Ok(([1.0, 2.0, 3.0], [0.0, -1.0, 0.0]))
        );
        assert!(parse_clip("1,2,3,0,0,0").is_err());
        assert!(parse_clip("1,2,3,0,1").is_err());
        // X0,X1,Y0,Y1,Z0,Z1 → (low corner, high corner).
        assert_eq!(
            parse_crop("-1,1,0,2,-3,-2"),
            Ok(([-1.0, 0.0, -3.0], [1.0, 2.0, -2.0]))
        );
        assert!(parse_crop("1,-1,0,2,-3,-2").is_err());
        assert!(parse_crop("0,1,0,1,2,2").is_err());
        assert!(parse_crop("0,1,0,1").is_err());
        assert_eq!(parse_fps("24"), Ok(24.0));
        assert!(parse_fps("0").is_err() && parse_fps("101").is_err());
    }

    #[test]
    fn blend_names_and_aliases() {
        let blend = |name: &str| {
            let cli = Cli::try_parse_from(["volray", "render", "-o", "x.png", "--blend", name])
                .map_err(|e| e.to_string())?;
            match cli.command {
                Command::Render(args) => Ok(args.view.blend),
                _ => Err("not render".to_string()),
            }
        };
        assert_eq!(blend("mip"), Ok(BlendMode::Mip));
        assert_eq!(blend("maximum"), Ok(BlendMode::Mip));
        assert_eq!(blend("minimum"), Ok(BlendMode::Minip));
        assert_eq!(blend("average"), Ok(BlendMode::Average));
        assert!(blend("sum").is_err());
    }

    #[test]
    fn several_inputs_and_repeated_clip_planes() {
        let cli = Cli::try_parse_from([
            "volray",
            "render",
            "a.cube",
            "b.cube",
            "c.cube",
            "-o",
            "x.gif",
            "--clip",
            "0,0,0,1,0,0",
            "--clip",
            "0,0,0,0,-1,0",
        ])
        .unwrap();
        let Command::Render(args) = cli.command else {
            panic!("not render")
        };
        assert_eq!(args.input.input.as_deref(), Some("a.cube"));
        assert_eq!(args.series, ["b.cube", "c.cube"]);
        assert_eq!(args.view.clip.len(), 2);
        assert_eq!(args.view.clip[1].1, [0.0, -1.0, 0.0]);
    }
}
