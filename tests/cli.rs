//! The `volray` command as a user meets it: outputs, exit codes, messages.

use std::fs;
use std::path::{Path, PathBuf};

mod common;
use common::{stderr, volray};

/// Decoded PNG: (width, height, bit depth, samples as u16).
fn read_png(path: &Path) -> (u32, u32, u8, Vec<u16>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let bytes = &buf[..info.buffer_size()];
    let samples = match info.bit_depth {
        png::BitDepth::Eight => bytes.iter().map(|&b| b as u16).collect(),
        png::BitDepth::Sixteen => bytes
            .chunks(2)
            .map(|c| u16::from_be_bytes([c[0], c[1]]))
            .collect(),
        d => panic!("unexpected bit depth {d:?}"),
    };
    (info.width, info.height, info.bit_depth as u8, samples)
}

/// A 12×10×8 ball (1 − r, clamped) as little-endian f32, x fastest.
fn ball_values() -> Vec<f32> {
    let mut v = Vec::new();
    for k in 0..8 {
        for j in 0..10 {
            for i in 0..12 {
                let (x, y, z) = (
                    (i as f32 - 5.5) / 5.5,
                    (j as f32 - 4.5) / 4.5,
                    (k as f32 - 3.5) / 3.5,
                );
                v.push((1.0 - (x * x + y * y + z * z).sqrt()).max(0.0));
            }
        }
    }
    v
}

fn write_raw_f32(path: &Path, values: &[f32]) {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    fs::write(path, bytes).unwrap();
}

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn renders_the_demo_with_no_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo.png");
    let run = volray(&["render", "--size", "64x48", "-o", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, h, depth, samples) = read_png(&out);
    assert_eq!((w, h, depth), (64, 48, 8));
    assert!(
        samples.iter().any(|&s| s > 100),
        "the demo must show something"
    );
    assert!(samples.contains(&0), "the demo must leave black background");
}

#[test]
fn sixteen_bit_output_agrees_with_eight_bit() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    for (path, depth) in [(&a, "8"), (&b, "16")] {
        let run = volray(&[
            "render",
            "torus:24",
            "--size",
            "32",
            "--bit-depth",
            depth,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(run.status.success(), "{}", stderr(&run));
    }
    let (_, _, d8, s8) = read_png(&a);
    let (_, _, d16, s16) = read_png(&b);
    assert_eq!((d8, d16), (8, 16));
    // 16-bit v ↦ 8-bit round(v / 257) within rounding of the same float.
    for (x, y) in s8.iter().zip(&s16) {
        assert!((*x as f64 - *y as f64 / 257.0).abs() <= 0.51, "{x} vs {y}");
    }
    assert!(
        s16.iter().any(|&v| v % 257 != 0),
        "16-bit must carry more precision"
    );
}

#[test]
fn raw_files_of_any_dtype_and_endianness_render_alike() {
    let dir = tempfile::tempdir().unwrap();
    let values = ball_values();
    let f32_path = dir.path().join("ball.f32");
    write_raw_f32(&f32_path, &values);
    // The same ball scaled to 0..1000 as big-endian u16: the normalised
    // scalar, and so the picture, is the same.
    let u16_path = dir.path().join("ball.u16");
    let u16_bytes: Vec<u8> = values
        .iter()
        .flat_map(|v| ((v * 1000.0).round() as u16).to_be_bytes())
        .collect();
    fs::write(&u16_path, u16_bytes).unwrap();

    let render = |input: &Path, extra: &[&str], out: &str| {
        let out = dir.path().join(out);
        let mut args = vec![
            "render",
            input.to_str().unwrap(),
            "--dims",
            "12,10,8",
            "--size",
            "40",
            "-o",
        ];
        args.push(out.to_str().unwrap());
        args.extend_from_slice(extra);
        let run = volray(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        read_png(&out).3
    };
    let a = render(&f32_path, &[], "a.png");
    let b = render(&u16_path, &["--dtype", "u16", "--endian", "big"], "b.png");
    assert!(a.iter().any(|&s| s > 50));
    let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
    assert!(worst <= 2, "f32 and u16 renders differ by {worst} levels");
}

#[test]
fn reference_and_fast_paths_agree_through_the_command() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("fast.png"), dir.path().join("ref.png"));
    for (path, extra) in [(&a, None), (&b, Some("--reference"))] {
        let mut args = vec![
            "render",
            "marschner-lobb:33",
            "--size",
            "48",
            "--view",
            "150,150,500",
            "--step",
            "0.5",
        ];
        args.extend(extra);
        args.extend(["-o", path.to_str().unwrap()]);
        let run = volray(&args);
        assert!(run.status.success(), "{}", stderr(&run));
    }
    let (fast, reference) = (read_png(&a).3, read_png(&b).3);
    let worst = fast
        .iter()
        .zip(&reference)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap();
    assert!(worst <= 1, "fast and reference differ by {worst} levels");
}

/// Runs a render that must fail: checks the exit code, that stderr is one
/// line naming `expect`, and that no output appeared.
fn refused(args: &[&str], code: i32, expect: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["-o", out.to_str().unwrap()]);
    let run = volray(&all);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(code), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: one line expected, got: {err}"
    );
    assert!(err.starts_with("volray: "), "{err}");
    assert!(
        err.contains(expect),
        "{args:?}: expected '{expect}' in: {err}"
    );
    assert!(
        files_in(dir.path()).is_empty(),
        "{args:?} left files behind"
    );
}

#[test]
fn bad_input_gets_one_clear_line_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("ball.raw");
    write_raw_f32(&raw, &ball_values());
    let raw = raw.to_str().unwrap();
    let mut nan = ball_values();
    nan[7] = f32::NAN;
    nan[100] = f32::NEG_INFINITY;
    nan[101] = f32::NAN;
    let nan_path = dir.path().join("nan.raw");
    write_raw_f32(&nan_path, &nan);
    let tf = dir.path().join("tf.json");
    fs::write(&tf, r#"{"opacity": [[0, 0], [1, 1.5]]}"#).unwrap();
    let tf_with_opacity = dir.path().join("tf2.json");
    fs::write(&tf_with_opacity, r#"{"opacity": [[0, 0], [1, 1]]}"#).unwrap();

    refused(&["render", raw, "--dims", "12,10,9"], 1, "3840 bytes");
    refused(
        &["render", raw, "--dims", "12,10,8", "--dtype", "u7"],
        1,
        "u7",
    );
    refused(&["render", raw], 1, "--dims");
    refused(
        &["render", nan_path.to_str().unwrap(), "--dims", "12,10,8"],
        1,
        "3 of 960 values are not finite",
    );
    refused(
        &["render", "sphere:8", "--opacity", "0.5,0.5"],
        1,
        "0 <= p < q <= 1",
    );
    refused(
        &["render", "sphere:8", "--opacity", "0.6,0.2"],
        1,
        "0 <= p < q <= 1",
    );
    refused(&["render", "sphere:8", "--step", "0"], 1, "step 0");
    refused(&["render", "sphere:8", "--step", "-0.5"], 1, "step");
    refused(&["render", "sphere:8", "--step", "1e-12"], 1, "too small");
    refused(&["render", "sphere:8", "--size", "0"], 1, "size");
    refused(&["render", "sphere:8", "--size", "20000"], 1, "16384");
    refused(
        &["render", "sphere:8", "--size", "10000x10000"],
        1,
        "pixels",
    );
    refused(&["render", "sphere:8", "--threads", "0"], 1, "threads");
    refused(&["render", "sphere:8", "--view", "1,2"], 1, "X,Y,Z");
    refused(&["render", "sphere:8", "--up", "1,0,0"], 1, "parallel");
    refused(
        &["render", "sphere:8", "--background", "2,0,0"],
        1,
        "background",
    );
    refused(
        &["render", "sphere:8", "--dims", "8,8,8"],
        1,
        "apply to files only",
    );
    refused(&["render", "sphere:1"], 1, "at least 2");
    refused(&["render", "sphere:8,radius=abc"], 1, "abc");
    refused(
        &["render", "sphere:8", "--tf", tf.to_str().unwrap()],
        1,
        "tf.json",
    );
    refused(
        &[
            "render",
            "sphere:8",
            "--tf",
            tf_with_opacity.to_str().unwrap(),
            "--opacity",
            "0,1",
        ],
        1,
        "conflicts",
    );
    refused(
        &["render", "sphere:8", "--tf", "/nonexistent/tf.json"],
        2,
        "tf.json",
    );
    refused(
        &["render", "/nonexistent/volume.raw", "--dims", "2,2,2"],
        2,
        "/nonexistent/volume.raw",
    );
    refused(&["render", "sphere:8", "--bogus"], 1, "--bogus");
}

#[test]
fn a_failed_run_keeps_an_existing_output_and_leaves_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("keep.png");
    fs::write(&out, b"previous picture").unwrap();
    let run = volray(&[
        "render",
        "sphere:8",
        "--step",
        "0",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1));
    assert_eq!(fs::read(&out).unwrap(), b"previous picture");
    assert_eq!(files_in(dir.path()), vec![out.clone()]);
    // A successful run replaces it whole.
    let run = volray(&[
        "render",
        "sphere:8",
        "--size",
        "8",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success());
    assert_eq!(read_png(&out).0, 8);
    assert_eq!(files_in(dir.path()), vec![out]);
}

#[test]
fn output_problems_are_io_failures() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no/such/dir/out.png");
    let run = volray(&["render", "sphere:8", "-o", missing.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
    assert!(stderr(&run).contains("does not exist"));
    let run = volray(&["render", "sphere:8", "-o", dir.path().to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
}

#[test]
fn never_overwrites_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("ball.raw");
    write_raw_f32(&raw, &ball_values());
    let before = fs::read(&raw).unwrap();
    let run = volray(&[
        "render",
        raw.to_str().unwrap(),
        "--dims",
        "12,10,8",
        "-o",
        raw.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(stderr(&run).contains("refusing to overwrite"));
    assert_eq!(fs::read(&raw).unwrap(), before);
}

#[test]
fn npy_input_renders() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("npy.png");
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/io/tests/fixtures/fortran_f4.npy"
    );
    let run = volray(&[
        "render",
        fixture,
        "--size",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    // .npy carries no spacing: --spacing supplies it.
    let run = volray(&[
        "render",
        fixture,
        "--spacing",
        "1,2,0.5",
        "--size",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let run = volray(&[
        "render",
        fixture,
        "--dims",
        "2,3,4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1));
}

#[test]
fn help_lists_every_option_with_its_default() {
    let run = volray(&["render", "--help"]);
    assert!(run.status.success());
    let help = String::from_utf8_lossy(&run.stdout);
    for option in [
        "--dims",
        "--dtype",
        "--endian",
        "--spacing",
        "--size",
        "--view",
        "--look-at",
        "--up",
        "--step",
        "--opacity",
        "--tf",
        "--ambient",
        "--diffuse",
        "--specular",
        "--shininess",
        "--light",
        "--light-color",
        "--no-shading",
        "--background",
        "--reference",
        "--threads",
        "--bit-depth",
        "--output",
    ] {
        assert!(help.contains(option), "{option} missing from help");
    }
    for default in [
        "[default: 480]",
        "[default: 0,0,1]",
        "[default: 1]",
        "[default: 0.1]",
        "[default: 10]",
    ] {
        assert!(help.contains(default), "{default} missing from help");
    }
    let run = volray(&["--help"]);
    assert!(run.status.success());
    assert!(String::from_utf8_lossy(&run.stdout).contains("Exit codes"));
    assert_eq!(volray(&[]).status.code(), Some(1));
}

#[test]
fn bench_reports_a_median() {
    let run = volray(&[
        "bench",
        "sphere:16",
        "--size",
        "24",
        "--frames",
        "3",
        "--threads",
        "2",
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(text.contains("2 threads"), "{text}");
    assert_eq!(
        text.lines()
            .filter(|l| l.trim_start().starts_with(char::is_numeric))
            .count(),
        3,
        "{text}"
    );
    assert!(text.contains("median"), "{text}");
}
