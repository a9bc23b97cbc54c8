//! `volray bench`'s flags, and the flag groups `--peers` ignores.

use super::camera::CameraArgs;
use super::input::InputArgs;
use super::look::LookArgs;
use super::parse::{Cases, parse_cases};
use super::sampling::SamplingArgs;
use super::view::ViewArgs;
use clap::{Args, Command};
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
    /// +x, step 0.5 voxel, their transfer functions and shading. The input,
    /// camera, rendering and sampling options do not apply, and are
    /// refused (--threads does, --shadows adds shadows, the camera's key
    /// light, and --ambient-occlusion ambient occlusion).
    #[arg(long, value_name = "DIR", conflicts_with_all = peers_ignores())]
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

/// The flag groups `bench --peers` does not use: the workloads fix their
/// own input, view and transfer functions (of the view, only `--threads`
/// applies). Each group is given by the `Args` struct that defines it:
/// its `augment_args`, which adds the group's flags to a command.
const PEERS_IGNORE: [fn(Command) -> Command; 4] = [
    <InputArgs as Args>::augment_args,
    <CameraArgs as Args>::augment_args,
    <LookArgs as Args>::augment_args,
    <SamplingArgs as Args>::augment_args,
];

/// The flags of the [`PEERS_IGNORE`] groups, which `--peers` conflicts
/// with, but `--shadows` and `--ambient-occlusion`, which add depth cues
/// to the workloads. Flag by
/// flag rather than by group id, so that clap's error names
/// the flag given, not every flag of its group; without INPUT, which
/// `bench.rs` refuses with a message saying what `--peers` does instead.
fn peers_ignores() -> Vec<clap::Id> {
    PEERS_IGNORE
        .iter()
        .fold(Command::new("peers"), |cmd, group| group(cmd))
        .get_arguments()
        .filter(|arg| !arg.is_positional())
        // The peers' workloads with depth cues: their cost.
        .filter(|arg| !["shadows", "ambient_occlusion"].contains(&arg.get_id().as_str()))
        .map(|arg| arg.get_id().clone())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Cli;
    use crate::parse::one_line_error;
    use clap::error::ErrorKind;
    use clap::{CommandFactory, Parser};

    /// `volray bench` with `args`, parsed.
    fn bench(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from([&["volray", "bench"][..], args].concat())
    }

    /// The words that give `arg`: the flag, and a value it takes without
    /// `--peers` (its default, or the first of a few shapes that fits).
    fn given(arg: &clap::Arg) -> Vec<String> {
        let flag = format!("--{}", arg.get_long().expect("a flag has a long name"));
        if !arg.get_action().takes_values() {
            return vec![flag];
        }
        let defaults = (arg.get_default_values().iter()).map(|v| v.to_string_lossy().into_owned());
        let value = defaults
            .chain(["1", "0,1", "2,2,2", "0,1,0,1,0,1", "1:0.5"].map(String::from))
            .find(|v| bench(&[&flag, v]).is_ok())
            .unwrap_or_else(|| panic!("no sample value fits {flag}: add one here"));
        vec![flag, value]
    }

    #[test]
    fn peers_refuses_every_flag_of_the_groups_it_ignores() {
        let mut cli = Cli::command();
        cli.build();
        let ignored = peers_ignores();
        let flags: Vec<&clap::Arg> = (cli.find_subcommand("bench").unwrap().get_arguments())
            .filter(|arg| ignored.contains(arg.get_id()))
            .collect();
        // The 41 flags of the list this replaced (all but INPUT of the
        // input options, and all but --threads of the view options), and
        // --labels, --label-opacity, --show-labels, --level, --channel,
        // --series, --scale and --linear since.
        assert_eq!(flags.len(), 49);
        for arg in flags {
            let given = given(arg);
            let given: Vec<&str> = given.iter().map(String::as_str).collect();
            let peers = ["--peers", "dir"];
            let named = arg.to_string();
            for (args, message) in [
                (
                    [&peers[..], &given].concat(),
                    format!("error: the argument '--peers <DIR>' cannot be used with '{named}'"),
                ),
                (
                    [&given[..], &peers].concat(),
                    format!("error: the argument '{named}' cannot be used with '--peers <DIR>'"),
                ),
            ] {
                let e = bench(&args).expect_err(&named);
                assert_eq!(e.kind(), ErrorKind::ArgumentConflict, "{args:?}");
                assert_eq!(one_line_error(&e), message);
            }
        }
    }

    #[test]
    fn peers_takes_the_flags_outside_those_groups() {
        let all = [
            "--peers",
            "dir",
            "--cases",
            "a:8",
            "--frames",
            "3",
            "--json",
            "b.json",
            "--vs-vtk",
            "--peers-python",
            "python3",
            "--threads",
            "2",
        ];
        assert!(bench(&all).is_ok());
        // INPUT is refused after parsing, by bench.rs, which says why.
        assert!(bench(&["sphere:8", "--peers", "dir"]).is_ok());
    }
}
