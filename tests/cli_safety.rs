//! volray never writes to its inputs, and its exit codes say what went
//! wrong: 1 bad input or arguments, 2 I/O failure.

mod common;

use common::{stderr, volray};
use std::fs;
use std::path::Path;

const NPY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/crates/io/tests/fixtures/c_f4.npy"
);

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `args` and checks it was refused for overwriting an input, with
/// `file` left as it was.
fn assert_refused(args: &[&str], file: &Path) {
    let before = fs::read(file).unwrap();
    let out = volray(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.contains("refusing to overwrite"), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(fs::read(file).unwrap(), before, "{args:?} changed {file:?}");
}

#[test]
fn no_input_of_a_series_is_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.npy");
    let b = dir.path().join("b.png"); // a .npy volume under another name
    fs::copy(NPY, &a).unwrap();
    fs::copy(NPY, &b).unwrap();
    assert_refused(
        &["render", s(&a), s(&b), "--format", "npy", "-o", s(&b)],
        &b,
    );
    // The same file through another path.
    let dotted = dir.path().join(".").join("b.png");
    assert_refused(&["render", s(&b), "--format", "npy", "-o", s(&dotted)], &b);
}

#[cfg(unix)]
#[test]
fn a_hard_or_symbolic_link_to_the_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.npy");
    fs::copy(NPY, &input).unwrap();
    let hard = dir.path().join("hard.png");
    fs::hard_link(&input, &hard).unwrap();
    assert_refused(&["render", s(&input), "-o", s(&hard)], &input);
    let soft = dir.path().join("soft.png");
    std::os::unix::fs::symlink(&input, &soft).unwrap();
    assert_refused(&["render", s(&input), "-o", s(&soft)], &input);
}

#[test]
fn a_frame_of_a_png_sequence_that_is_the_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("turn_002.png");
    fs::copy(NPY, &input).unwrap();
    let pattern = dir.path().join("turn_%03d.png");
    assert_refused(
        &[
            "render",
            s(&input),
            "--format",
            "npy",
            "--turntable",
            "4",
            "--size",
            "8",
            "-o",
            s(&pattern),
        ],
        &input,
    );
    // Two frames write files 000 and 001 only: the input (002) is safe and
    // the run goes ahead.
    let out = volray(&[
        "render",
        s(&input),
        "--format",
        "npy",
        "--turntable",
        "2",
        "--size",
        "8",
        "-o",
        s(&pattern),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("turn_001.png").exists());
}

#[test]
fn the_data_file_of_a_detached_header_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data.png");
    fs::write(&data, (0..8u8).collect::<Vec<_>>()).unwrap();
    let header = dir.path().join("vol.nhdr");
    fs::write(
        &header,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: data.png\n",
    )
    .unwrap();
    assert_refused(&["render", s(&header), "-o", s(&data)], &data);
    let mhd = dir.path().join("vol.mhd");
    fs::write(
        &mhd,
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = data.png\n",
    )
    .unwrap();
    assert_refused(&["render", s(&mhd), "-o", s(&data)], &data);
}

#[test]
fn the_transfer_function_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let tf = dir.path().join("tf.png");
    fs::write(&tf, r#"{"opacity": [[0, 0], [1, 0.5]]}"#).unwrap();
    assert_refused(&["render", "blobs:8", "--tf", s(&tf), "-o", s(&tf)], &tf);
}

#[test]
fn bench_json_onto_its_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.npy");
    fs::copy(NPY, &input).unwrap();
    assert_refused(
        &[
            "bench",
            s(&input),
            "--size",
            "8",
            "--frames",
            "1",
            "--json",
            s(&input),
        ],
        &input,
    );
}

#[test]
fn exit_codes_tell_bad_input_from_io_failures() {
    let dir = tempfile::tempdir().unwrap();
    // A file that is not there: the operating system's failure, 2.
    let missing = dir.path().join("missing.npy");
    let out = volray(&["info", s(&missing)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("missing.npy"), "{}", stderr(&out));

    // A header that lies: bad input, 1.
    let bad = dir.path().join("bad.npy");
    fs::write(&bad, b"\x93NUMPY\x01\x00\x10\x00{'descr': 'x'}\n").unwrap();
    let out = volray(&["info", s(&bad)]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).starts_with("volray: error: "),
        "{}",
        stderr(&out)
    );

    // An output directory that does not exist, or cannot take files: 2.
    let nowhere = dir.path().join("no/such/dir/out.png");
    let out = volray(&["render", "blobs:8", "--size", "8", "-o", s(&nowhere)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    #[cfg(target_os = "linux")]
    {
        // /proc takes no new files, even from root.
        let out = volray(&["render", "blobs:8", "--size", "8", "-o", "/proc/volray.png"]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert_eq!(stderr(&out).lines().count(), 1, "{}", stderr(&out));
    }
}

/// Runs `args`, killing volray if it takes more than 20 s: a hang fails.
fn volray_within_20s(args: &[&str]) -> std::process::Output {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let mut child = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("{args:?} hung");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn fifos_and_devices_are_refused_without_blocking() {
    // Opening a FIFO for reading blocks until a writer comes: volray must
    // look before it opens, for an input, a header's data file and --tf.
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("data.raw");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.unwrap().success(), "mkfifo");
    let header = dir.path().join("vol.nhdr");
    fs::write(
        &header,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: data.raw\n",
    )
    .unwrap();
    let out_png = dir.path().join("o.png");
    for (args, code) in [
        (
            vec!["info", s(&fifo), "--dims", "2,2,2", "--dtype", "u8"],
            2,
        ),
        (vec!["info", s(&header)], 2),
        (vec!["render", s(&header), "-o", s(&out_png)], 2),
        (
            vec!["render", "sphere:8", "--tf", s(&fifo), "-o", s(&out_png)],
            1,
        ),
        // A device would feed read_to_string forever.
        (
            vec!["render", "sphere:8", "--tf", "/dev/zero", "-o", s(&out_png)],
            1,
        ),
    ] {
        let out = volray_within_20s(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("volray: error:"), "{args:?}: {err}");
        assert!(!out_png.exists());
    }
}

/// `volray view` where there is a display: the browser is opened through
/// a redirect page of this user's alone, so that the URL's access token
/// is in no process's arguments (`ps` shows them to every user).
#[cfg(unix)]
#[test]
fn the_viewers_access_token_never_reaches_a_programs_arguments() {
    use std::io::{BufRead, BufReader};
    use std::os::unix::fs::PermissionsExt;
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    let dir = tempfile::tempdir().unwrap();
    let (bin, runtime) = (dir.path().join("bin"), dir.path().join("runtime"));
    fs::create_dir_all(&bin).unwrap();
    fs::create_dir_all(&runtime).unwrap();
    // A stand-in for xdg-open: it records its arguments, and a copy of
    // the page it was given with that page's mode.
    let record = dir.path().join("opened");
    let opener = bin.join("xdg-open");
    fs::write(
        &opener,
        format!(
            "#!/bin/sh\nr='{0}'\nprintf '%s\\n' \"$@\" > \"$r.args\"\npage=\"${{1#file://}}\"\nstat -c %a \"$page\" > \"$r.mode\"\ncp \"$page\" \"$r.html\"\nmv \"$r.args\" \"$r\"\n",
            record.display()
        ),
    )
    .unwrap();
    fs::set_permissions(&opener, fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );

    let mut child = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(["view", "fractal:17", "--port", "0"])
        .env("DISPLAY", ":99")
        .env("XDG_RUNTIME_DIR", &runtime)
        .env("PATH", path)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut url = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut url)
        .unwrap();
    let url = url.trim().to_string();
    let token = url.split_once("token=").expect("a token URL").1.to_string();
    assert!(token.len() >= 16, "{url}");

    let start = Instant::now();
    while !record.exists() && start.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let args = fs::read_to_string(&record).expect("the opener was run");
    let page_path = args.trim().strip_prefix("file://").expect("a file URL");
    let html = fs::read_to_string(record.with_extension("html")).unwrap();
    let mode = fs::read_to_string(record.with_extension("mode")).unwrap();

    // Stopped as Ctrl-C would, the viewer removes the page.
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    child.wait().unwrap();

    assert!(
        !args.contains(&token),
        "the opener's arguments hold the token: {args}"
    );
    assert!(Path::new(page_path).starts_with(&runtime), "{page_path}");
    assert_eq!(mode.trim(), "600", "the page is this user's alone");
    assert!(html.contains(&url.replace('&', "&amp;")), "{html}");
    assert!(
        !Path::new(page_path).exists(),
        "the page outlived the viewer"
    );
}
