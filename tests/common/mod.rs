//! Running the `volray` binary from the integration tests.
#![allow(dead_code)] // each test binary uses part of this

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
