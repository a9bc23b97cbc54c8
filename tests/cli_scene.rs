//! Several volumes in one picture through the binary (`--channels`,
//! `--channel-colors`, `--mix`, `--overlay`), a file's time points as an
//! animation (`--frames`), `volray info`'s hint, and the refusals: each
//! one line naming the option, exit 1.
//!
//! The files are written here: 4-D NIfTI-1 files of 24³ frames (raw
//! bytes: a 348-byte header, unit spacing from `pixdim`), `.npy` volumes,
//! and an NRRD placed far from the others. Seen along −x (the default
//! view), +y is to the right and +z up.

mod common;

use common::nifti::{self, ball, frame, nifti};
use common::{Picture, stderr, stdout, volray};
use std::path::{Path, PathBuf};
use volray_core::transfer::labels::PALETTE;

const N: usize = nifti::N;

/// A 24³ `.npy` volume.
fn npy(dir: &Path, name: &str, data: Vec<f32>) -> String {
    let volume = volray_core::Volume::new([N; 3], data).unwrap();
    let path = dir.join(name);
    volray_io::write_npy(&path, &volume).unwrap();
    path.to_str().unwrap().to_string()
}

/// Renders `args` at 48² into `name`, asserting success; the picture.
fn render(dir: &Path, name: &str, args: &[&str]) -> Picture {
    let out = out(dir, name);
    let all = [&["render", "--size", "48", "-o", &out], args].concat();
    let run = volray(&all);
    assert!(run.status.success(), "{all:?}: {}", stderr(&run));
    Picture::read(Path::new(&out))
}

fn out(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

/// Runs `volray render ... -o OUT.png` expecting a refusal: its one line.
fn refused(dir: &Path, args: &[&str]) -> String {
    let out = out(dir, "refused.png");
    let all = [&["render", "--size", "48", "-o", &out], args].concat();
    let run = volray(&all);
    let text = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{all:?}: {text}");
    assert_eq!(text.lines().count(), 1, "one line: {text}");
    assert!(!Path::new(&out).exists());
    text
}

/// A ball left (frame 0) and a ball right (frame 1).
fn two_channels(dir: &Path) -> String {
    nifti(dir, "two.nii", &[ball(6.0), ball(17.0)])
}

#[test]
fn channels_of_one_file_show_in_the_palette_magenta_then_green() {
    let dir = tempfile::tempdir().unwrap();
    let file = two_channels(dir.path());
    let p = render(
        dir.path(),
        "ch.png",
        &[&file, "--channels", "all", "--no-shading"],
    );
    let (left, right) = (p.at(11, 24), p.at(36, 24));
    // Magenta: red and blue alike, no green.
    assert!(
        left[0] > 60 && left[0].abs_diff(left[2]) <= 2 && left[1] <= 2,
        "{left:?}"
    );
    // Green alone.
    assert!(right[1] > 60 && right[0] <= 2 && right[2] <= 2, "{right:?}");
    // Between them, nothing.
    assert_eq!(p.at(24, 2), [0, 0, 0]);
}

#[test]
fn channel_colors_replace_the_palette_by_name_and_by_hex() {
    let dir = tempfile::tempdir().unwrap();
    let file = two_channels(dir.path());
    let p = render(
        dir.path(),
        "ch.png",
        &[
            &file,
            "--channels",
            "0,1",
            "--channel-colors",
            "cyan,#ff0000",
            "--no-shading",
        ],
    );
    let (left, right) = (p.at(11, 24), p.at(36, 24));
    assert!(
        left[1] > 60 && left[1].abs_diff(left[2]) <= 2 && left[0] <= 2,
        "{left:?}"
    );
    assert!(right[0] > 60 && right[1] <= 2 && right[2] <= 2, "{right:?}");
    // One channel alone: only the right ball, in the first colour.
    let one = render(
        dir.path(),
        "one.png",
        &[&file, "--channels", "1", "--no-shading"],
    );
    assert_eq!(one.at(11, 24), [0, 0, 0]);
    let only = one.at(36, 24);
    assert!(
        only[0] > 60 && only[0].abs_diff(only[2]) <= 2 && only[1] <= 2,
        "{only:?}"
    );
}

#[test]
fn the_additive_mix_sums_overlapping_channels_and_is_the_default_for_channels() {
    let dir = tempfile::tempdir().unwrap();
    // Two channels of one ball: red and green where both are.
    let file = nifti(dir.path(), "same.nii", &[ball(12.0), ball(12.0)]);
    let look = [
        &file,
        "--channels",
        "all",
        "--channel-colors",
        "red,green",
        "--no-shading",
    ];
    let default = render(dir.path(), "default.png", &look);
    let additive = render(
        dir.path(),
        "add.png",
        &[&look[..], &["--mix", "additive"]].concat(),
    );
    let composite = render(
        dir.path(),
        "comp.png",
        &[&look[..], &["--mix", "composite"]].concat(),
    );
    assert_eq!(default, additive);
    let (a, c) = (additive.at(24, 24), composite.at(24, 24));
    // Additive: each channel's full colour; composite: the mean colour of
    // the union's opacity.
    assert!(
        a[0].abs_diff(a[1]) <= 2 && c[0].abs_diff(c[1]) <= 2,
        "{a:?} {c:?}"
    );
    assert!(a[0] > c[0] + 20, "additive {a:?} vs composite {c:?}");
}

#[test]
fn an_overlay_of_labels_draws_its_label_in_the_table_colour_over_a_faint_volume() {
    let dir = tempfile::tempdir().unwrap();
    // A faint volume filling the box, and label 3 in a ball left of centre.
    let faint = npy(dir.path(), "faint.npy", frame(|_, y, _| y as f32));
    let seg = npy(
        dir.path(),
        "seg.npy",
        frame(|x, y, z| {
            let r = ((x - 12.0).powi(2) + (y - 7.0).powi(2) + (z - 12.0).powi(2)).sqrt();
            if r <= 4.5 { 3.0 } else { 0.0 }
        }),
    );
    let faint_look = [faint.as_str(), "--opacity", "0,0.01", "--no-shading"];
    let alone = render(dir.path(), "alone.png", &faint_look);
    let overlay = format!("{seg}:labels");
    let both = render(
        dir.path(),
        "both.png",
        &[&faint_look[..], &["--overlay", &overlay]].concat(),
    );
    let want = PALETTE[3].map(|c| (c * 255.0).round() as u8);
    let got = both.at(14, 24);
    assert!(
        (0..3).all(|c| got[c].abs_diff(want[c]) <= 12),
        "{got:?} vs label 3's {want:?}"
    );
    // Label 0 is not drawn: the faint volume alone.
    for (col, row) in [(36, 24), (24, 4), (40, 40)] {
        let (a, b) = (alone.at(col, row), both.at(col, row));
        assert!(a != [0, 0, 0], "the faint volume shows at ({col}, {row})");
        assert!(
            (0..3).all(|c| a[c].abs_diff(b[c]) <= 1),
            "({col}, {row}): {a:?} vs {b:?}"
        );
    }
}

#[test]
fn a_hidden_overlay_frames_but_is_not_drawn_and_overlays_go_beside_a_tf_file() {
    let dir = tempfile::tempdir().unwrap();
    let first = npy(dir.path(), "first.npy", ball(8.0));
    let second = npy(dir.path(), "second.npy", ball(16.0));
    let tf = dir.path().join("tf.json");
    std::fs::write(&tf, r#"{"opacity": [[0, 0], [1, 0.9]]}"#).unwrap();
    let tf = tf.to_str().unwrap();
    let look = [first.as_str(), "--tf", tf, "--no-shading"];
    let alone = render(dir.path(), "alone.png", &look);
    // The first volume's --tf file beside an overlay with its own look.
    let shown = format!("{second}:range=0,1,opacity=0,1");
    let both = render(
        dir.path(),
        "both.png",
        &[&look[..], &["--overlay", &shown]].concat(),
    );
    assert_ne!(both, alone, "the overlay shows");
    // Hidden, on the same grid: the first volume's picture exactly.
    let hidden = format!("{shown},hidden");
    let none = render(
        dir.path(),
        "hidden.png",
        &[&look[..], &["--overlay", &hidden]].concat(),
    );
    assert_eq!(none, alone, "a hidden overlay draws nothing");
    let text = refused(
        dir.path(),
        &[&first, "--overlay", &format!("{second}:hidden=1")],
    );
    assert!(text.contains("hidden takes no value"), "{text}");
}

#[test]
fn the_volumes_of_one_picture_share_max_memory() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    // Compressed, so read whole (an uncompressed .nii is mapped, and its
    // pages are the system's): 54 KiB a channel.
    let plain = two_channels(dir.path());
    let gz = dir.path().join("two.nii.gz");
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(&std::fs::read(&plain).unwrap()).unwrap();
    std::fs::write(&gz, e.finish().unwrap()).unwrap();
    let gz = gz.to_str().unwrap();
    let args = |m: &'static str| [gz, "--channels", "all", "--max-memory", m];
    // Each fits 100000 bytes alone, both do not.
    render(dir.path(), "both.png", &args("150000"));
    let text = refused(dir.path(), &args("100000"));
    assert!(
        text.contains("the volumes read before it hold 54 KiB of --max-memory 98 KiB"),
        "{text}"
    );
}

#[test]
fn channels_not_asked_for_are_not_charged_and_none_is_read_twice() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    // Three channels of 54 KiB, read whole (compressed): two fit 150000
    // bytes, three do not.
    let plain = nifti(
        dir.path(),
        "three.nii",
        &[ball(6.0), ball(12.0), ball(17.0)],
    );
    let gz = dir.path().join("three.nii.gz");
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(&std::fs::read(&plain).unwrap()).unwrap();
    std::fs::write(&gz, e.finish().unwrap()).unwrap();
    let gz = gz.to_str().unwrap();
    let two = |which: &str, colors: &str| {
        render(
            dir.path(),
            &format!("{}.png", which.replace(',', "_")),
            &[
                gz,
                "--channels",
                which,
                "--channel-colors",
                colors,
                "--max-memory",
                "150000",
                "--no-shading",
            ],
        )
    };
    // Channel 0, read to count the channels, is dropped and not charged.
    let p = two("1,2", "magenta,green");
    assert_eq!(p.at(11, 24), [0, 0, 0], "channel 0 not drawn");
    // Channel 0 asked for after another is the one read first, kept.
    let later = two("2,0", "green,magenta");
    let first = two("0,2", "magenta,green");
    assert!(later.max_diff(&first) <= 1);
    let refused = refused(
        dir.path(),
        &[gz, "--channels", "all", "--max-memory", "150000"],
    );
    assert!(refused.contains("--max-memory"), "{refused}");
}

/// An OME-Zarr image (v2, uncompressed) of `channels` along its `c` axis.
fn ome_zarr(dir: &Path, name: &str, channels: &[Vec<f32>]) -> String {
    let root = dir.join(name);
    let level = root.join("0");
    std::fs::create_dir_all(&level).unwrap();
    std::fs::write(root.join(".zgroup"), r#"{"zarr_format": 2}"#).unwrap();
    let axes = r#"[{"name": "c", "type": "channel"}, {"name": "z", "type": "space"}, {"name": "y", "type": "space"}, {"name": "x", "type": "space"}]"#;
    let attrs = format!(
        r#"{{"multiscales": [{{"version": "0.4", "axes": {axes}, "datasets": [{{"path": "0", "coordinateTransformations": [{{"type": "scale", "scale": [1, 1, 1, 1]}}]}}]}}]}}"#
    );
    std::fs::write(root.join(".zattrs"), attrs).unwrap();
    let array = format!(
        r#"{{"zarr_format": 2, "shape": [{c}, {N}, {N}, {N}], "chunks": [1, {N}, {N}, {N}], "dtype": "<f4", "compressor": null, "fill_value": 0, "order": "C", "filters": null}}"#,
        c = channels.len()
    );
    std::fs::write(level.join(".zarray"), array).unwrap();
    for (c, data) in channels.iter().enumerate() {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(level.join(format!("{c}.0.0.0")), bytes).unwrap();
    }
    root.to_str().unwrap().to_string()
}

#[test]
fn channels_of_an_ome_zarr_image_are_its_c_axis() {
    let dir = tempfile::tempdir().unwrap();
    let image = ome_zarr(dir.path(), "cells.zarr", &[ball(6.0), ball(17.0)]);
    let p = render(
        dir.path(),
        "zarr.png",
        &[&image, "--channels", "all", "--no-shading"],
    );
    let (left, right) = (p.at(11, 24), p.at(36, 24));
    assert!(
        left[0] > 60 && left[0].abs_diff(left[2]) <= 2 && left[1] <= 2,
        "{left:?}"
    );
    assert!(right[1] > 60 && right[0] <= 2 && right[2] <= 2, "{right:?}");
    let run = volray(&["info", &image]);
    let text = stdout(&run);
    assert!(
        text.contains("channels:  2 (read: 0; --channel picks another; together: volray render"),
        "{text}"
    );
}

/// The numbered PNGs `name_%03d.png` in `dir`, in order.
fn numbered(dir: &Path, stem: &str) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_str().unwrap().starts_with(stem))
        .collect();
    found.sort();
    found
}

#[test]
fn frames_renders_each_time_point_as_a_frame_of_an_animation() {
    let dir = tempfile::tempdir().unwrap();
    // A ball moving right over three time points.
    let file = nifti(
        dir.path(),
        "moving.nii",
        &[ball(6.0), ball(12.0), ball(17.0)],
    );
    let all = out(dir.path(), "all_%03d.png");
    let run = volray(&[
        "render",
        &file,
        "--frames",
        "all",
        "--size",
        "48",
        "--no-shading",
        "-o",
        &all,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let frames: Vec<Picture> = numbered(dir.path(), "all_")
        .iter()
        .map(|p| Picture::read(p))
        .collect();
    assert_eq!(frames.len(), 3);
    // The brightest column of the middle row moves right.
    let peak = |p: &Picture| {
        (0..48)
            .max_by_key(|&c| p.at(c, 24).iter().map(|&v| v as u32).sum::<u32>())
            .unwrap()
    };
    let peaks: Vec<usize> = frames.iter().map(peak).collect();
    assert!(peaks[0] < peaks[1] && peaks[1] < peaks[2], "{peaks:?}");

    // A slice of them, as an animated PNG.
    let some = out(dir.path(), "some.png");
    let run = volray(&[
        "render", &file, "--frames", "1:3", "--size", "48", "-o", &some,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&some).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!(reader.info().animation_control().unwrap().num_frames, 2);
}

#[test]
fn channels_turn_in_a_turntable() {
    let dir = tempfile::tempdir().unwrap();
    let file = two_channels(dir.path());
    let turn = out(dir.path(), "turn_%03d.png");
    let run = volray(&[
        "render",
        &file,
        "--channels",
        "all",
        "--turntable",
        "2",
        "--size",
        "32",
        "-o",
        &turn,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert_eq!(numbered(dir.path(), "turn_").len(), 2);
}

#[test]
fn info_says_how_to_render_the_channels_together() {
    let dir = tempfile::tempdir().unwrap();
    let file = two_channels(dir.path());
    let run = volray(&["info", &file]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = stdout(&run);
    let want = format!(
        "channels:  1 (its 2 time points rendered together as channels: volray render {file} --channels all)"
    );
    assert!(text.lines().any(|l| l == want), "{text}");
}

#[test]
fn bad_channels_and_overlays_are_refused_in_one_line_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = two_channels(d);
    let one = nifti(d, "one.nii", &[ball(12.0)]);

    let e = refused(
        d,
        &[
            &file,
            "--channels",
            "all",
            "--channel-colors",
            "red,green,blue",
        ],
    );
    assert!(
        e.contains("--channel-colors") && e.contains("3 colour(s) for 2 channels"),
        "{e}"
    );

    let e = refused(d, &[&one, "--channels", "all"]);
    assert!(e.contains("--channels") && e.contains("one volume"), "{e}");

    let e = refused(d, &[&file, "--channels", "5"]);
    assert!(
        e.contains("--channels 5") && e.contains("2 channels"),
        "{e}"
    );

    let spec = format!("{one}:color=red");
    let e = refused(d, &[&file, "--overlay", &spec]);
    assert!(
        e.contains(&format!(
            "--overlay {spec}: unknown option \"color\" (labels, colormap=NAME"
        )),
        "{e}"
    );

    // A volume a hundred voxels away from the first.
    let far = d.join("far.nrrd");
    let mut bytes = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {N} {N} {N}\nspace: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (100,100,100)\nendian: little\nencoding: raw\n\n"
    )
    .into_bytes();
    bytes.extend(ball(12.0).iter().flat_map(|v| v.to_le_bytes()));
    std::fs::write(&far, bytes).unwrap();
    let far = far.to_str().unwrap();
    let e = refused(d, &[&file, "--overlay", far]);
    assert!(
        e.contains(&format!("--overlay {far}")) && e.contains("does not meet"),
        "{e}"
    );
    assert!(
        e.contains("[100, 100, 100]") && e.contains("[0, 0, 0]"),
        "{e}"
    );

    // The reader's refusal of an overlay, after the option that names it.
    let junk = d.join("junk.txt");
    std::fs::write(&junk, "not a volume").unwrap();
    let junk = junk.to_str().unwrap();
    let e = refused(d, &[&file, "--overlay", junk]);
    assert!(
        e.starts_with(&format!(
            "volray: error: --overlay: {junk}: unknown volume format"
        )) && e.contains("name the format with --format (the volumes read before it hold"),
        "{e}"
    );

    let e = refused(d, &["blobs:16", "--channels", "all"]);
    assert!(
        e.contains("--channels: blobs:16 is a built-in source, one volume"),
        "{e}"
    );

    let e = refused(d, &[&file, "--overlay", &format!("{one}:preset=bones")]);
    assert!(
        e.contains("--overlay") && e.contains("preset=") && e.contains("bones"),
        "{e}"
    );

    let e = refused(d, &[&file, &one, "--overlay", &one]);
    assert!(e.contains("--overlay") && e.contains("series"), "{e}");

    let e = refused(d, &[&file, "--mix", "additive"]);
    assert!(e.contains("--mix"), "{e}");

    let e = refused(d, &[&one, "--frames", "all"]);
    assert!(
        e.contains("--frames") && e.contains("one time point"),
        "{e}"
    );

    let e = refused(d, &[&file, "--frames", "all", "--turntable", "2"]);
    assert!(e.contains("--frames") && e.contains("--turntable"), "{e}");
}

#[test]
fn the_viewer_refuses_what_it_cannot_serve_with_several_volumes_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = two_channels(dir.path());
    for (args, expect) in [
        (
            vec!["--channels", "all", "--frames", "all"],
            "--channels and --frames cannot be combined",
        ),
        (vec!["--channels", "all", "--log"], "--channels with --log"),
        (vec!["--frames", "0:5"], "holds 2 time point(s)"),
        (vec!["--frames", "all", "--frame", "1"], "--frame picks one"),
        (
            vec!["--channels", "all", "--preset", "ct-bone"],
            "--preset does not apply",
        ),
    ] {
        let all = [
            &["view", file.as_str(), "--no-browser", "--port", "0"][..],
            &args,
        ]
        .concat();
        let run = volray(&all);
        let text = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{all:?}: {text}");
        assert_eq!(text.lines().count(), 1, "one line: {text}");
        assert!(text.contains(expect), "{all:?}: {text}");
        assert!(stdout(&run).is_empty(), "no URL is printed: {all:?}");
    }
}
