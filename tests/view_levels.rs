//! `volray view` of an OME-Zarr pyramid, without a browser: it opens the
//! file from its metadata, says which level the view shows while it
//! moves and which when still, and refuses a level the file lacks or a
//! `--level auto` on a file of one level. (What the frames read, level by
//! level and piece by piece, is tested on a session in
//! `crates/view/src/session/level_tests.rs`.)

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

/// A 96³ pyramid (levels 96³ and 48³) written by `volray convert`.
fn pyramid(dir: &std::path::Path) -> String {
    let path = dir.join("b.ome.zarr");
    let path = path.to_str().unwrap().to_string();
    let out = common::volray(&["convert", "blobs:96", "-o", &path]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    path
}

#[test]
fn a_pyramid_is_served_level_by_level_and_says_which_levels_it_shows() {
    let dir = tempfile::tempdir().unwrap();
    let path = pyramid(dir.path());
    let mut child = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(["view", &path, "--size", "64", "--port", "0", "--no-browser"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut url = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut url)
        .unwrap();
    let mut note = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut note)
        .unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    // 32² drafts resolve no more than the 48³ level; the stills choose.
    assert!(
        note.contains("2 levels; the view shows level 1 (48x48x48) while it moves, the level each still needs (--level auto; 0 for the start) when still"),
        "{note}"
    );
}

#[test]
fn a_level_the_file_lacks_and_auto_on_a_file_of_one_level_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = pyramid(dir.path());
    let out = common::volray(&["view", &path, "--level", "5", "--no-browser"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        common::stderr(&out).contains("level"),
        "{}",
        common::stderr(&out)
    );
    let raw = dir.path().join("b.npy");
    let raw = raw.to_str().unwrap();
    let out = common::volray(&["convert", "blobs:16", "-o", raw]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let out = common::volray(&["view", raw, "--level", "auto", "--no-browser"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        common::stderr(&out).contains("--level auto applies to multiscale images"),
        "{}",
        common::stderr(&out)
    );
}

#[test]
fn a_pyramid_whose_coarsest_drafts_overrun_the_memory_or_auto_with_log_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = pyramid(dir.path());
    // The 48³ level's draft frame takes more than a quarter of 600 KiB.
    let args = ["view", &path, "--max-memory", "600000", "--no-browser"];
    let out = common::volray(&args);
    assert_eq!(out.status.code(), Some(1));
    let err = common::stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("b.ome.zarr: its coarsest level (48x48x48) may take up to ")
            && err.contains(
                "more than the 1/4 of --max-memory 586 KiB the viewer gives the frames while the view moves: raise --max-memory"
            ),
        "{err}"
    );
    for flag in [&["--log"][..], &["--spacing", "1,1,2"]] {
        let args = [
            &["view", &path, "--level", "auto", "--no-browser"][..],
            flag,
        ]
        .concat();
        let out = common::volray(&args);
        assert_eq!(out.status.code(), Some(1));
        assert!(
            common::stderr(&out).contains(
                "--level auto: the viewer reads a multiscale image's levels as its frames need them, but not yet with --log or --spacing"
            ),
            "{}",
            common::stderr(&out)
        );
    }
}
