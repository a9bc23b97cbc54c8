//! The demo: what `volray render -o demo.png` draws with no INPUT, the
//! first picture a newcomer sees. It is the paper's first fractal cloud
//! (Figure 2a's: D = 3.7, σ = 1, seed 1, 129³, thresholded as
//! volray-paper chooses), shaded, in a perceptual colour map over the
//! window whose denser voxels hold a fifth of the cloud (the paper's
//! `f_top`), seen from the paper's view point, with a colour bar and a
//! title: [`WORDS`], which the note on standard error prints so that the
//! picture can be remade and changed flag by flag.
//!
//! The demo's look applies only when the command names nothing but where
//! and how big to write (the flags of `PLAIN`); any other flag renders
//! the demo volume with the user's look instead, as it would any file.

use clap::ArgMatches;
use clap::parser::ValueSource;
use std::ffi::OsString;

/// The demo volume: Figure 2a's cloud (`volray_app::input::DEMO`), the
/// threshold volray-paper's `clouds::cloud(129, 1, ..)` chooses (test
/// below).
pub const VOLUME: &str = volray_app::input::DEMO;

/// The demo's look, after INPUT. `--range 0,0.1` is the paper's window
/// `[f_min, f_top]`, `f_top` the level whose denser voxels hold 20 % of
/// the cloud's sum (0.0992); the lighting and the opacity ramp are
/// Figure 2's (ambient 0.6, diffuse 0.4, no highlight, α from 0 to 0.25),
/// the view point the paper's (500, 150, 100), zoomed so that the cloud
/// fills the frame beside its colour bar.
pub const WORDS: &[&str] = &[
    "--colormap",
    "inferno",
    "--range",
    "0,0.1",
    "--opacity",
    "0,0.25",
    "--ambient",
    "0.6",
    "--diffuse",
    "0.4",
    "--specular",
    "0",
    "--view",
    "500,150,100",
    "--look-at",
    "0,0,0",
    "--zoom",
    "1.3",
    "--colorbar",
    "--title",
    "volray: a fractal cloud (Ramesh & Athithan 1993, Fig. 2a)",
];

/// The demo's size, unless `--size` is given.
pub const SIZE: &str = "720x540";

/// The `render` flags that leave the demo's look in place: the output,
/// its size and bit depth, threads and memory, a turntable and its rate.
const PLAIN: &[&str] = &[
    "output",
    "bit_depth",
    "size",
    "threads",
    "max_memory",
    "turntable",
    "fps",
];

/// `argv` with the demo's words inserted after `render` when `render`
/// (its matches `render`) has no INPUT and only `PLAIN` flags; `None`
/// otherwise. The words come before the user's, so the user's `--size`
/// is the one kept (the demo's is left out then).
pub fn words(argv: &[OsString], render: &ArgMatches) -> Option<Vec<OsString>> {
    let given = |id: &str| render.value_source(id) == Some(ValueSource::CommandLine);
    // clap lists each flattened struct too, as a group of its flags
    // (`OutputArgs`): only the flags count.
    let flag = |id: &str| id.starts_with(|c: char| c.is_ascii_lowercase());
    if given("input")
        || render
            .ids()
            .any(|id| flag(id.as_str()) && given(id.as_str()) && !PLAIN.contains(&id.as_str()))
    {
        return None;
    }
    let at = argv.iter().position(|a| a == "render")? + 1;
    let mut demo: Vec<OsString> = std::iter::once(VOLUME)
        .chain(WORDS.iter().copied())
        .map(OsString::from)
        .collect();
    if !given("size") {
        demo.extend(["--size", SIZE].map(OsString::from));
    }
    let mut out = argv[..at].to_vec();
    out.extend(demo);
    out.extend_from_slice(&argv[at..]);
    Some(out)
}

/// The note that says what the demo is and how to make it again.
pub fn note() -> String {
    let quoted: Vec<String> = WORDS
        .iter()
        .map(|w| {
            if w.contains(' ') {
                format!("\"{w}\"")
            } else {
                w.to_string()
            }
        })
        .collect();
    format!(
        "volray: note: no INPUT, so the demo: volray render {VOLUME} {} (name a file or a source, e.g. hydrogen:4,2,0, to render your own)",
        quoted.join(" ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};

    fn argv(words: &[&str]) -> Vec<OsString> {
        words.iter().map(OsString::from).collect()
    }

    fn demo_of(words: &[&str]) -> Option<Vec<OsString>> {
        let argv = argv(words);
        let matches = crate::Cli::command().try_get_matches_from(&argv).unwrap();
        super::words(&argv, matches.subcommand_matches("render").unwrap())
    }

    #[test]
    fn the_demo_volume_is_the_papers_first_cloud() {
        let style = volray_paper::clouds::CloudStyle::default();
        let cloud = volray_paper::clouds::cloud(129, 1, &style).unwrap();
        assert_eq!(cloud.spec(), VOLUME);
        // --range's top is the paper's f_top, rounded: the level whose
        // denser voxels hold a fifth of the cloud's sum.
        let top = volray_paper::orbitals::density_level(&cloud.volume, style.top_share);
        assert!((f64::from(top) - 0.1).abs() < 0.002, "f_top {top}");
        let range = WORDS.iter().position(|&w| w == "--range").unwrap();
        assert_eq!(WORDS[range + 1], "0,0.1");
    }

    #[test]
    fn the_demos_words_come_only_with_plain_flags() {
        let words = demo_of(&["volray", "render", "-o", "a.png", "--size", "64"]).unwrap();
        assert_eq!(&words[..3], &argv(&["volray", "render", VOLUME])[..]);
        assert!(words.contains(&OsString::from("--colorbar")));
        // The user's size is the one kept, the demo's left out.
        assert!(!words.contains(&OsString::from(SIZE)));
        assert_eq!(words.iter().filter(|w| *w == "--size").count(), 1);
        let words = demo_of(&["volray", "render", "-o", "a.png"]).unwrap();
        assert!(words.contains(&OsString::from(SIZE)));
        assert!(demo_of(&["volray", "render", "-o", "a.png", "--colormap", "viridis"]).is_none());
        assert!(demo_of(&["volray", "render", "blobs:64", "-o", "a.png"]).is_none());
        assert!(demo_of(&["volray", "render", "-o", "a.png", "--azimuth", "30"]).is_none());
    }

    #[test]
    fn the_demos_words_parse_as_a_render_command() {
        let words = demo_of(&["volray", "render", "-o", "a.png"]).unwrap();
        let cli = crate::Cli::try_parse_from(&words).unwrap();
        match cli.command {
            crate::Command::Render(args) => {
                assert_eq!(args.input.input.as_deref(), Some(VOLUME));
                assert!(args.figure.colorbar.is_some());
            }
            _ => panic!("not render"),
        }
    }
}
