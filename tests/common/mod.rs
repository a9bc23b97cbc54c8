//! Running the `volray` binary from the integration tests.
#![allow(dead_code)] // each test binary uses part of this

pub mod nifti;
pub mod zarr;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `volray` with `args` and returns what it did.
pub fn volray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(args)
        .output()
        .expect("volray runs")
}

pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The workspace's `target/pyenv` python (which `.ci/run` makes), if it
/// imports every one of `modules`; else `None`, the reason printed, and
/// under `CI=true` a failure rather than a skip.
pub fn pyenv_with(modules: &[&str]) -> Option<PathBuf> {
    let python = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/pyenv/bin/python");
    let has = Command::new(&python)
        .args(["-c", &format!("import {}", modules.join(", "))])
        .status()
        .is_ok_and(|s| s.success());
    if !has {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "target/pyenv lacks one of {modules:?}: .ci/run installs them"
        );
        eprintln!("skipped: target/pyenv lacks one of {modules:?} (.ci/run installs them)");
        return None;
    }
    Some(python)
}

/// A new directory holding the files `script` writes with `target/pyenv`'s
/// python (`python FLAGS -c SCRIPT DIR`), asserting it succeeds; `None`
/// where that python lacks one of `modules` outside CI ([`pyenv_with`]).
pub fn written_by_python(
    modules: &[&str],
    flags: &[&str],
    script: &str,
) -> Option<tempfile::TempDir> {
    let python = pyenv_with(modules)?;
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(&python)
        .args(flags)
        .args(["-c", script, dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(dir)
}

/// `volray render ARGS -o OUT`, asserting success; its stderr (the notes).
pub fn render(args: &[&str], out: &Path) -> String {
    let all = [&["render"], args, &["-o", out.to_str().unwrap()]].concat();
    let result = volray(&all);
    assert!(result.status.success(), "{all:?}: {}", stderr(&result));
    stderr(&result)
}

/// An 8-bit RGB picture read back from a PNG volray wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    pub width: usize,
    pub height: usize,
    /// Row 0 at the top, x fastest.
    pub rgb: Vec<[u8; 3]>,
}

impl Picture {
    pub fn read(path: &Path) -> Picture {
        let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        Picture {
            width: info.width as usize,
            height: info.height as usize,
            rgb: buf[..info.buffer_size()]
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        }
    }

    pub fn at(&self, col: usize, row: usize) -> [u8; 3] {
        self.rgb[col + self.width * row]
    }

    /// The largest channel difference from `other`, of the same size.
    pub fn max_diff(&self, other: &Picture) -> u8 {
        assert_eq!((self.width, self.height), (other.width, other.height));
        (self.rgb.iter().zip(&other.rgb))
            .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
            .max()
            .unwrap()
    }
}
