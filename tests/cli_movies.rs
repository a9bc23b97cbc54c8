//! `volray render --keyframes FILE` (docs/movies.md): movies through
//! ffmpeg (frame count, size and rate as ffprobe reads them, and each
//! decoded frame against a still rendered with the frame's interpolated
//! values), PNG sequences equal to those stills exactly (a clip sweep, a
//! transfer-function fade and a 4-D NIfTI's time points), `--resume`
//! after a Ctrl-C and `--movie-frames` rendering only what is missing, a
//! turntable unchanged, and bad input refused in one line.

mod common;

use common::nifti::{ball, nifti};
use common::{Picture, render, stderr, volray};
use std::path::Path;
use std::process::Command;

const SIZE: &str = "64x48";

/// Whether ffmpeg and ffprobe run; under `CI=true` they must.
fn has_ffmpeg() -> bool {
    let runs = |tool: &str| {
        Command::new(tool)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    let has = runs("ffmpeg") && runs("ffprobe");
    if !has {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "ffmpeg and ffprobe are missing: .ci/run installs Debian's ffmpeg"
        );
        eprintln!("skipped: ffmpeg or ffprobe is missing (Debian: apt-get install ffmpeg)");
    }
    has
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// The peak signal-to-noise ratio of `b` against `a` (8-bit), in dB.
fn psnr(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mse = (a.iter().zip(b))
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    if mse == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (255.0f64 * 255.0 / mse).log10()
}

#[test]
fn an_mp4_holds_every_frame_at_its_size_and_rate_and_each_is_the_still_of_its_interpolated_values()
{
    if !has_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let keys = write(
        dir.path(),
        "orbit.json",
        r#"{"version": 1, "fps": 8, "keyframes": [
            {"t": 0, "azimuth": 0, "zoom": 1, "ease": "linear"},
            {"t": 1, "azimuth": 60, "zoom": 1.5}]}"#,
    );
    let movie = dir.path().join("orbit.mp4");
    let base = ["blobs:32", "--size", SIZE, "--elevation", "20"];
    render(&[&base[..], &["--keyframes", &keys]].concat(), &movie);
    let probe = Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=width,height,r_frame_rate,nb_read_frames",
        ])
        .args(["-of", "csv=p=0"])
        .arg(&movie)
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&probe.stdout).trim(), "64,48,8/1,9");
    // WebM: VP9, the same frames.
    let webm = dir.path().join("orbit.webm");
    render(&[&base[..], &["--keyframes", &keys]].concat(), &webm);
    let probe = Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=codec_name,nb_read_frames",
            "-of",
            "csv=p=0",
        ])
        .arg(&webm)
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&probe.stdout).trim(), "vp9,9");
    let decoded = Command::new("ffmpeg")
        .args(["-v", "error", "-i"])
        .arg(&movie)
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-"])
        .output()
        .unwrap();
    assert!(decoded.status.success());
    let frame_bytes = 64 * 48 * 3;
    assert_eq!(decoded.stdout.len(), 9 * frame_bytes);
    let still = |k: usize| {
        // Linear: frame k at k/8 s is k/8 of the way.
        let s = k as f64 / 8.0;
        let out = dir.path().join(format!("still{k}.png"));
        let (azimuth, zoom) = (format!("{}", 60.0 * s), format!("{}", 1.0 + 0.5 * s));
        render(
            &[&base[..], &["--azimuth", &azimuth, "--zoom", &zoom]].concat(),
            &out,
        );
        let p = Picture::read(&out);
        p.rgb.iter().flatten().copied().collect::<Vec<u8>>()
    };
    let stills: Vec<Vec<u8>> = (0..9).map(still).collect();
    for (k, still) in stills.iter().enumerate() {
        let frame = &decoded.stdout[k * frame_bytes..(k + 1) * frame_bytes];
        let db = psnr(still, frame);
        assert!(db >= 40.0, "frame {k}: PSNR {db:.1} dB");
    }
    // The check tells frames apart: the first frame is not the last still.
    assert!(psnr(&stills[8], &decoded.stdout[..frame_bytes]) < 40.0);
}

#[test]
fn a_png_sequence_of_a_clip_sweep_a_tf_fade_and_time_points_equals_the_stills_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let series = nifti(d, "series.nii", &[ball(8.0), ball(12.0), ball(16.0)]);
    let tf = |opacity: f32| {
        format!(
            r#"{{"opacity": [[0, 0], [1, {}]], "color": [[0, 1, 0.5, 0.2], [1, 1, 0.9, 0.8]]}}"#,
            f64::from(opacity)
        )
    };
    write(d, "skin.json", &tf(0.2));
    write(d, "bone.json", &tf(0.8));
    let keys = write(
        d,
        "keys.json",
        r#"{"version": 1, "fps": 4, "time": "hold", "keyframes": [
            {"t": 0, "frame": 0, "clip": [12, 12, 4, 0, 0, 1], "tf": "skin.json", "ease": "linear"},
            {"t": 1, "frame": 2, "clip": [12, 12, 20, 0, 0, 1], "tf": "bone.json"}]}"#,
    );
    let base = [series.as_str(), "--size", SIZE, "--elevation", "30"];
    let one = d.join("one");
    let two = d.join("two");
    std::fs::create_dir_all(&one).unwrap();
    std::fs::create_dir_all(&two).unwrap();
    let pattern = |dir: &Path| dir.join("f_%02d.png");
    render(
        &[&base[..], &["--keyframes", &keys, "--threads", "1"]].concat(),
        &pattern(&one),
    );
    render(
        &[&base[..], &["--keyframes", &keys, "--threads", "2"]].concat(),
        &pattern(&two),
    );
    assert_eq!(names(&one).len(), 5, "{:?}", names(&one));
    for k in 0..5 {
        let s = k as f64 / 4.0;
        let name = format!("f_{k:02}.png");
        // Bit-identical at 1 and 2 threads.
        assert_eq!(
            std::fs::read(one.join(&name)).unwrap(),
            std::fs::read(two.join(&name)).unwrap(),
            "{name}"
        );
        // The still at frame k's values: the time point held (2s rounded
        // down), the plane's z linear, the opacity mixed point by point.
        let time_point = (2.0 * s).floor() as usize;
        let clip = format!("12,12,{},0,0,1", 4.0 + 16.0 * s);
        let opacity = (f64::from(0.2f32) + (f64::from(0.8f32) - f64::from(0.2f32)) * s) as f32;
        let tf_file = write(d, &format!("tf{k}.json"), &tf(opacity));
        let still = d.join(format!("still{k}.png"));
        let frame = time_point.to_string();
        render(
            &[
                &base[..],
                &["--frame", &frame, "--clip", &clip, "--tf", &tf_file],
            ]
            .concat(),
            &still,
        );
        let diff = Picture::read(&one.join(&name)).max_diff(&Picture::read(&still));
        assert_eq!(diff, 0, "frame {k}");
    }
    // The frames differ: the sweep moves.
    assert_ne!(
        Picture::read(&one.join("f_00.png")),
        Picture::read(&one.join("f_02.png"))
    );
}

#[test]
fn a_turntable_through_the_movie_path_is_the_turntable_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.gif");
    let kept = dir.path().join("kept.gif");
    let base = [
        "blobs:32",
        "--size",
        SIZE,
        "--turntable",
        "6",
        "--fps",
        "12",
    ];
    render(&base, &plain);
    // --resume takes the movie path: frames kept, then encoded.
    render(&[&base[..], &["--resume"]].concat(), &kept);
    assert_eq!(
        std::fs::read(&plain).unwrap(),
        std::fs::read(&kept).unwrap()
    );
    assert_eq!(names(dir.path()), ["kept.gif", "plain.gif"]);
}

/// A 24-frame movie's keyframes in `dir`.
fn movie_keys(dir: &Path) -> String {
    write(
        dir,
        "keys.json",
        r#"{"version": 1, "fps": 8, "keyframes": [
            {"t": 0, "azimuth": 0, "background": [0, 0, 0]},
            {"t": 2.875, "azimuth": 120, "background": [0.1, 0.2, 0.4]}]}"#,
    )
}

fn interrupted(args: &[&str], after: usize) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_volray"))
        .arg("render")
        .args(args)
        .env("VOLRAY_TEST_INTERRUPT_AFTER", after.to_string())
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn resumed_after_ctrl_c_only_the_missing_frames_are_rendered_and_the_movie_is_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let keys = movie_keys(d);
    let whole = d.join("whole.png");
    let base = ["blobs:32", "--size", SIZE, "--keyframes", keys.as_str()];
    render(&base, &whole);
    // An animated PNG: interrupted after 10 frames, nothing at the output,
    // the 10 frames kept.
    let apng = d.join("movie.png");
    let args = [&base[..], &["--resume", "-o", apng.to_str().unwrap()]].concat();
    let (code, said) = interrupted(&args, 10);
    assert_eq!(code, Some(130), "{said}");
    assert!(!apng.exists());
    let work = d.join("movie.png.frames");
    assert_eq!(
        names(&work).iter().filter(|n| n.ends_with(".png")).count(),
        10
    );
    let said = render(&[&base[..], &["--resume"]].concat(), &apng);
    assert!(said.contains("resumed: 10 of 24 frames kept"), "{said}");
    assert!(said.contains("14 to render"), "{said}");
    assert_eq!(
        std::fs::read(&apng).unwrap(),
        std::fs::read(&whole).unwrap()
    );
    assert!(
        !work.exists(),
        "the work folder is removed once the movie is done"
    );

    // A PNG sequence: its finished files are not written again.
    let seq = d.join("seq");
    std::fs::create_dir(&seq).unwrap();
    let pattern = seq.join("frame_%05d.png");
    let args = [&base[..], &["--resume", "-o", pattern.to_str().unwrap()]].concat();
    let (code, said) = interrupted(&args, 12);
    assert_eq!(code, Some(130), "{said}");
    let file = |k: usize| seq.join(format!("frame_{k:05}.png"));
    let kept: Vec<_> = (0..12)
        .map(|k| std::fs::metadata(file(k)).unwrap().modified().unwrap())
        .collect();
    assert!(!file(12).exists());
    std::thread::sleep(std::time::Duration::from_millis(20));
    let said = render(&[&base[..], &["--resume"]].concat(), &pattern);
    assert!(said.contains("resumed: 12 of 24 frames kept"), "{said}");
    for (k, time) in kept.iter().enumerate() {
        assert_eq!(
            std::fs::metadata(file(k)).unwrap().modified().unwrap(),
            *time
        );
    }
    // Frame for frame the uninterrupted movie's.
    let plain = d.join("plain");
    std::fs::create_dir(&plain).unwrap();
    render(&base, &plain.join("frame_%05d.png"));
    for k in 0..24 {
        let name = format!("frame_{k:05}.png");
        assert_eq!(
            std::fs::read(seq.join(&name)).unwrap(),
            std::fs::read(plain.join(&name)).unwrap(),
            "{name}"
        );
    }
    assert_eq!(names(&seq).len(), 24, "{:?}", names(&seq));
}

#[test]
fn parts_rendered_apart_make_the_movie_once_the_last_is_in() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let keys = movie_keys(d);
    let base = ["blobs:32", "--size", SIZE, "--keyframes", keys.as_str()];
    let whole = d.join("whole.gif");
    render(&base, &whole);
    let parts = d.join("parts.gif");
    let said = render(&[&base[..], &["--movie-frames", "12:24"]].concat(), &parts);
    assert!(said.contains("12 of 24 still missing"), "{said}");
    assert!(!parts.exists());
    // Another command's part is not mixed in.
    let out = volray(
        &[
            &["render"],
            &base[..],
            &[
                "--zoom",
                "2",
                "--movie-frames",
                "0:12",
                "-o",
                parts.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("parts.gif.frames: holds the frames of another command"),
        "{}",
        stderr(&out)
    );
    let said = render(&[&base[..], &["--movie-frames", "0:12"]].concat(), &parts);
    assert!(!said.contains("missing"), "{said}");
    assert_eq!(
        std::fs::read(&parts).unwrap(),
        std::fs::read(&whole).unwrap()
    );
    // A part outside the movie is refused.
    let out = volray(
        &[
            &["render"],
            &base[..],
            &["--movie-frames", "20:30", "-o", "x.gif"],
        ]
        .concat(),
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("24 frames"), "{}", stderr(&out));
}

#[test]
fn a_movie_stopped_by_ctrl_c_or_without_ffmpeg_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let keys = movie_keys(d);
    let movie = d.join("m.mp4");
    let base = ["blobs:32", "--size", SIZE, "--keyframes", keys.as_str()];
    let args = [&base[..], &["-o", movie.to_str().unwrap()]].concat();
    // No ffmpeg on PATH: one line, exit 2, no file.
    let out = Command::new(env!("CARGO_BIN_EXE_volray"))
        .arg("render")
        .args(&args)
        .env("PATH", d)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert_eq!(said.trim().lines().count(), 1, "{said}");
    assert!(
        said.contains("needs ffmpeg, which is not on PATH"),
        "{said}"
    );
    assert_eq!(names(d), ["keys.json"]);
    // Not even kept frames are rendered for a movie ffmpeg cannot write.
    let resumable = [&args[..], &["--resume"]].concat();
    let out = Command::new(env!("CARGO_BIN_EXE_volray"))
        .arg("render")
        .args(&resumable)
        .env("PATH", d)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(names(d), ["keys.json"]);
    // An ffmpeg that fails: rendering stops, its words in one line.
    let bin = d.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let fake = bin.join("ffmpeg");
    std::fs::write(
        &fake,
        "#!/bin/sh\necho \"Unknown encoder 'libx264'\" >&2\nexit 1\n",
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_volray"))
        .arg("render")
        .args(&args)
        .env("PATH", &bin)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert_eq!(said.trim().lines().count(), 1, "{said}");
    assert!(
        said.contains("ffmpeg") && said.contains("Unknown encoder 'libx264'"),
        "{said}"
    );
    std::fs::remove_dir_all(&bin).unwrap();
    assert_eq!(names(d), ["keys.json"]);
    if !has_ffmpeg() {
        return;
    }
    let (code, said) = interrupted(&args, 5);
    assert_eq!(code, Some(130), "{said}");
    assert_eq!(names(d), ["keys.json"]);
    // An odd size is refused, naming --size.
    let odd = ["blobs:32", "--size", "63x48", "--keyframes", &keys, "-o"];
    let out = volray(&[&["render"], &odd[..], &[movie.to_str().unwrap()]].concat());
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--size 63x48"), "{}", stderr(&out));
}

#[test]
fn a_bad_keyframes_file_is_refused_in_one_line_naming_the_file_and_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (text, says) in [
        (
            r#"{"keyframes": [{"t": 0, "zooom": 2}]}"#,
            "keyframes[0].zooom: unknown key",
        ),
        (
            r#"{"keyframes": [{"t": 1}, {"t": 0.5}]}"#,
            "keyframes[1].t: 0.5 is not after",
        ),
        (
            r#"{"keyframes": [{"t": 0, "azimuth": [1]}]}"#,
            "keyframes[0].azimuth",
        ),
        (r#"{"version": 7, "keyframes": [{"t": 0}]}"#, "version 7"),
        (
            r#"{"keyframes": [{"t": 0, "colormap": "plaid"}]}"#,
            "keyframes[0]: ",
        ),
    ] {
        let keys = write(d, "bad.json", text);
        let out = volray(&[
            "render",
            "blobs:32",
            "--size",
            SIZE,
            "--keyframes",
            &keys,
            "-o",
            d.join("m.gif").to_str().unwrap(),
        ]);
        let said = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{said}");
        assert_eq!(said.trim().lines().count(), 1, "{said}");
        assert!(said.contains(&format!("--keyframes {keys}: ")), "{said}");
        assert!(said.contains(says), "{said}");
        assert!(!d.join("m.gif").exists());
    }
}

#[test]
fn time_points_interpolated_are_the_stills_of_the_volumes_mixed_voxel_by_voxel() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (a, b) = (ball(8.0), ball(16.0));
    let series = nifti(d, "series.nii", &[a.clone(), b.clone()]);
    let keys = write(
        d,
        "keys.json",
        r#"{"version": 1, "fps": 4, "time": "interpolate", "keyframes": [
            {"t": 0, "frame": 0, "ease": "linear"}, {"t": 1, "frame": 1}]}"#,
    );
    let base = ["--size", SIZE, "--elevation", "30", "--range", "0,1"];
    let frames = d.join("f_%d.png");
    render(
        &[&[series.as_str()], &base[..], &["--keyframes", &keys]].concat(),
        &frames,
    );
    for k in 0..5 {
        // Frame k shows time point k/4: (1 − w)·a + w·b as volray mixes them.
        let w = k as f32 / 4.0;
        let mixed: Vec<f32> = (a.iter().zip(&b)).map(|(&x, &y)| x + (y - x) * w).collect();
        let one = nifti(d, &format!("mixed{k}.nii"), &[mixed]);
        let still = d.join(format!("still{k}.png"));
        render(&[&[one.as_str()], &base[..]].concat(), &still);
        let movie = Picture::read(&d.join(format!("f_{k}.png")));
        assert_eq!(movie.max_diff(&Picture::read(&still)), 0, "frame {k}");
    }
}

#[test]
fn a_chunked_dataset_over_max_memory_is_filmed_piece_by_piece_as_its_stills_are() {
    // A chunked HDF5 dataset written by h5py: 48·40·36 u16 voxels (138 kB)
    // that 100 kB cannot hold whole.
    let script = r#"
import sys
import numpy as np
import h5py
x, y, z = np.meshgrid(np.arange(48.0), np.arange(40.0), np.arange(36.0), indexing="ij")
v = (30000 * np.exp(-((x - 20)**2 + (y - 18)**2 + (z - 14)**2) / 72) + 40 * z).astype("<u2")
with h5py.File(sys.argv[1] + "/vol.h5", "w") as f:
    f.create_dataset("data", data=v, chunks=(16, 16, 16), compression="gzip")
"#;
    let Some(dir) = common::written_by_python(&["h5py", "numpy"], &[], script) else {
        return;
    };
    let d = dir.path();
    let input = format!("{}/vol.h5:/data", d.display());
    let keys = write(
        d,
        "keys.json",
        r#"{"version": 1, "fps": 2, "keyframes": [
            {"t": 0, "azimuth": 0, "ease": "linear"}, {"t": 1, "azimuth": 40}]}"#,
    );
    let base = [
        input.as_str(),
        "--preset",
        "mr",
        "--range",
        "0,32000",
        "--size",
        "40x36",
        "--max-memory",
        "100K",
    ];
    let said = render(
        &[&base[..], &["--keyframes", &keys]].concat(),
        &d.join("f_%d.png"),
    );
    assert!(said.contains("rendered in pieces"), "{said}");
    for k in 0..3 {
        let still = d.join(format!("still{k}.png"));
        let azimuth = (20 * k).to_string();
        render(&[&base[..], &["--azimuth", &azimuth]].concat(), &still);
        let frame = Picture::read(&d.join(format!("f_{k}.png")));
        assert_eq!(frame.max_diff(&Picture::read(&still)), 0, "frame {k}");
    }
}

#[test]
fn every_frame_is_held_within_max_memory_before_the_first_is_rendered() {
    // 32³ at 64x48 takes 218 KiB, 512 KiB with shadows: 300 KiB holds the
    // first keyframe's frames but not the second's.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let keys = write(
        d,
        "keys.json",
        r#"{"version": 1, "fps": 2, "keyframes": [{"t": 0}, {"t": 1, "shadows": true}]}"#,
    );
    let movie = d.join("m.gif");
    let base = ["render", "blobs:32", "--size", SIZE, "--max-memory", "300K"];
    let out = volray(
        &[
            &base[..],
            &["--keyframes", &keys, "-o", movie.to_str().unwrap()],
        ]
        .concat(),
    );
    let said = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains("more than --max-memory 300 KiB"), "{said}");
    assert_eq!(names(d), ["keys.json"]);
    // Without the shadows, the same limit holds every frame.
    let keys = write(
        d,
        "keys.json",
        r#"{"fps": 2, "keyframes": [{"t": 0}, {"t": 1, "zoom": 2}]}"#,
    );
    let out = volray(
        &[
            &base[..],
            &["--keyframes", &keys, "-o", movie.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
}
