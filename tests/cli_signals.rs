//! The `volray` process against its surroundings: a reader that closes
//! the pipe early (`volray info F | head -1`), standard output that cannot
//! be written, and Ctrl-C (SIGINT) or SIGTERM in the middle of writing an
//! output file, which must leave no partial or temporary file behind and
//! the previous output as it was.

mod common;

use common::volray;
use std::fs;
use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn spawn(args: &[&str], stdout: Stdio) -> Child {
    Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(Stdio::piped())
        .spawn()
        .expect("volray starts")
}

/// Waits for `child`, killing it after `limit`; its exit code and stderr.
fn finish(mut child: Child, limit: Duration) -> (Option<i32>, String) {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("volray still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_reader_that_stops_after_one_line_ends_info_successfully() {
    // 1000 histogram bins print about 75 KB, more than a pipe holds, so
    // volray is still writing when the reader goes.
    let mut child = spawn(
        &["info", "marschner-lobb:21", "--bins", "1000"],
        Stdio::piped(),
    );
    let mut pipe = child.stdout.take().unwrap();
    let mut first = Vec::new();
    let mut byte = [0u8];
    while pipe.read(&mut byte).unwrap() == 1 && byte[0] != b'\n' {
        first.push(byte[0]);
    }
    assert_eq!(
        String::from_utf8(first).unwrap(),
        "input:     marschner-lobb:21"
    );
    drop(pipe);
    let (code, err) = finish(child, Duration::from_secs(60));
    assert_eq!(code, Some(0), "stderr: {err}");
    assert!(err.is_empty(), "stderr: {err}");
}

#[test]
fn a_pipe_closed_before_any_output_ends_every_printing_command_successfully() {
    for args in [
        &["info", "blobs:16"][..],
        &["info", "blobs:16", "--json"],
        &["bench", "blobs:16", "--size", "16", "--frames", "1"],
    ] {
        let mut child = spawn(args, Stdio::piped());
        drop(child.stdout.take());
        let (code, err) = finish(child, Duration::from_secs(60));
        assert_eq!(code, Some(0), "{args:?}: stderr: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[cfg(target_os = "linux")]
#[test]
fn standard_output_that_cannot_be_written_is_an_io_failure() {
    let full = fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let child = spawn(&["info", "blobs:16"], Stdio::from(full));
    let (code, err) = finish(child, Duration::from_secs(60));
    assert_eq!(code, Some(2), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("volray: error: cannot write to standard output"),
        "{err}"
    );
}

/// The temporary files volray left in `dir`.
fn temporary_files(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

/// Starts a long turntable into `dir/turn.gif` (which holds an earlier
/// output), sends `signal` once its temporary file exists, and checks that
/// volray exits with `code`, removing the temporary file and leaving the
/// earlier output as it was.
#[cfg(unix)]
fn interrupt_a_render(signal: &str, code: i32) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("turn.gif");
    fs::write(&out, b"the previous output").unwrap();
    // About a thousand frames: minutes of work, never finished here.
    let child = spawn(
        &[
            "render",
            "blobs:48",
            "--turntable",
            "1000",
            "--size",
            "200",
            "-o",
            out.to_str().unwrap(),
        ],
        Stdio::null(),
    );
    let start = Instant::now();
    while temporary_files(dir.path()).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary file appeared"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    // Signalled as soon as the temporary file exists: what is checked
    // (the file removed, the exit code, the old output kept) does not
    // depend on how many frames went into it, so nothing waits on time.
    let killed = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let (exit, err) = finish(child, Duration::from_secs(60));
    assert_eq!(exit, Some(code), "{signal}: stderr: {err}");
    assert_eq!(err.trim_end(), "volray: interrupted");
    assert_eq!(temporary_files(dir.path()), Vec::<String>::new());
    assert_eq!(fs::read(&out).unwrap(), b"the previous output");
}

#[cfg(unix)]
#[test]
fn ctrl_c_removes_the_unfinished_output_and_exits_130() {
    interrupt_a_render("INT", 130);
}

#[cfg(unix)]
#[test]
fn sigterm_removes_the_unfinished_output_and_exits_143() {
    interrupt_a_render("TERM", 143);
}

#[test]
fn help_lists_the_exit_codes() {
    let help = common::stdout(&volray(&["--help"]));
    assert!(
        help.contains(
            "Exit codes: 0 success, 1 bad input or arguments, 2 I/O failure, 130 interrupted"
        ),
        "{help}"
    );
}
