//! `volray bench`'s flags, and the flags `--peers` ignores.

use super::input::InputArgs;
use super::parse::{Cases, parse_cases};
use super::view::ViewArgs;
use clap::Args;
use std::path::PathBuf;

/// `volray bench`.
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
