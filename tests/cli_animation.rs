//! Animations from `volray render`: turntables (`--turntable FRAMES`) and
//! series of input files, written as animated PNG, GIF or numbered PNGs
//! and decoded here with the png and gif crates.

use std::fs;
use std::path::{Path, PathBuf};

mod common;
use common::{stderr, volray};

/// One 8-bit RGB frame.
type Frame = Vec<[u8; 3]>;

/// The frames of an animated PNG, and its frame delay (numerator,
/// denominator).
fn read_apng(path: &Path) -> (u32, Vec<Frame>, (u16, u16)) {
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let control = reader
        .info()
        .animation_control
        .expect("an animated PNG has an acTL chunk");
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let mut frames = Vec::new();
    let mut delay = (0, 0);
    for _ in 0..control.num_frames {
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let fc = reader.info().frame_control.unwrap();
        delay = (fc.delay_num, fc.delay_den);
        frames.push(rgb(&buf[..info.buffer_size()]));
    }
    (control.num_frames, frames, delay)
}

/// A still PNG's pixels.
fn read_png(path: &Path) -> Frame {
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    assert!(reader.info().animation_control.is_none(), "a still PNG");
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    rgb(&buf[..info.buffer_size()])
}

/// A GIF's frames (RGB) and their delays in hundredths of a second.
fn read_gif(path: &Path) -> (Vec<Frame>, Vec<u16>) {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = opts.read_info(fs::File::open(path).unwrap()).unwrap();
    let (mut frames, mut delays) = (Vec::new(), Vec::new());
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        frames.push(frame.buffer.chunks(4).map(|c| [c[0], c[1], c[2]]).collect());
        delays.push(frame.delay);
    }
    (frames, delays)
}

fn rgb(bytes: &[u8]) -> Frame {
    bytes.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn max_diff(a: &Frame, b: &Frame) -> u8 {
    assert_eq!(a.len(), b.len());
    (a.iter().zip(b))
        .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
        .max()
        .unwrap()
}

fn run_ok(args: &[&str]) {
    let run = volray(args);
    assert!(run.status.success(), "{args:?}: {}", stderr(&run));
}

fn path(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// A turntable fits the window to the bounding sphere; a still fits the
/// box. For the cube [−1, 1]³ seen along an axis, the box's face is 2 wide
/// and the sphere 2√3: a still zoomed by 1/√3 has the turntable's window.
const SPHERE_OVER_BOX: &str = "0.57735026918962576";

#[test]
fn turntable_apng_has_every_view_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let out = path(dir.path(), "turn.png");
    let base = ["render", "blobs:24", "--size", "32"];
    run_ok(
        &[
            &base[..],
            &["--turntable", "4", "--fps", "10", "-o"],
            &[out.to_str().unwrap()],
        ]
        .concat(),
    );
    let (count, frames, delay) = read_apng(&out);
    assert_eq!(count, 4);
    assert_eq!(delay, (10, 100), "10 frames per second");
    // Frame i is the still view at azimuth 90·i with the sphere's window.
    for (i, frame) in frames.iter().enumerate() {
        let still = path(dir.path(), &format!("still{i}.png"));
        let azimuth = (90 * i).to_string();
        run_ok(
            &[
                &base[..],
                &["--azimuth", &azimuth, "--zoom", SPHERE_OVER_BOX, "-o"],
                &[still.to_str().unwrap()],
            ]
            .concat(),
        );
        assert!(
            max_diff(frame, &read_png(&still)) <= 1,
            "frame {i} against the still at azimuth {azimuth}"
        );
    }
    // The views differ (blobs has no symmetry about z).
    for i in 1..4 {
        assert!(max_diff(&frames[0], &frames[i]) > 30, "frame {i}");
    }
    // The turn starts at --azimuth: a 2-frame turntable from azimuth 90
    // is frames 1 and 3 of the 4-frame one.
    let half = path(dir.path(), "half.png");
    run_ok(
        &[
            &base[..],
            &["--turntable", "2", "--azimuth", "90", "-o"],
            &[half.to_str().unwrap()],
        ]
        .concat(),
    );
    let (_, two, _) = read_apng(&half);
    assert_eq!(two, [frames[1].clone(), frames[3].clone()]);
    assert_eq!(names(dir.path()).len(), 6, "{:?}", names(dir.path()));
}

#[test]
fn turntable_gif_and_png_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["render", "blobs:24", "--size", "32", "--turntable", "3"];
    let apng = path(dir.path(), "t.png");
    run_ok(&[&base[..], &["-o", apng.to_str().unwrap()]].concat());
    let (_, frames, delay) = read_apng(&apng);
    assert_eq!(
        delay,
        (4, 100),
        "24 frames per second by default, to the centisecond"
    );

    let gif = path(dir.path(), "t.gif");
    run_ok(&[&base[..], &["--fps", "20", "-o", gif.to_str().unwrap()]].concat());
    let (gif_frames, delays) = read_gif(&gif);
    assert_eq!(gif_frames.len(), 3);
    assert_eq!(delays, [5, 5, 5]);
    for (g, p) in gif_frames.iter().zip(&frames) {
        // 256 colours per frame: close to the PNG's, not equal.
        let mean = g
            .iter()
            .zip(p)
            .map(|(a, b)| a[0].abs_diff(b[0]) as f64)
            .sum::<f64>()
            / g.len() as f64;
        assert!(mean < 3.0, "mean difference {mean}");
    }

    let sub = dir.path().join("seq");
    fs::create_dir(&sub).unwrap();
    let pattern = sub.join("turn_%03d.png");
    run_ok(&[&base[..], &["-o", pattern.to_str().unwrap()]].concat());
    assert_eq!(
        names(&sub),
        ["turn_000.png", "turn_001.png", "turn_002.png"]
    );
    for (i, frame) in frames.iter().enumerate() {
        assert_eq!(&read_png(&sub.join(format!("turn_{i:03}.png"))), frame);
    }
}

/// The 9³ ball 1 − r/4 (r in voxels from the centre) times `scale`, as a
/// raw f32 file.
fn scaled_ball(dir: &Path, name: &str, scale: f32) -> (String, f32) {
    let mut values = Vec::new();
    for k in 0..9 {
        for j in 0..9 {
            for i in 0..9 {
                let d = |n: i32| (n - 4) as f32;
                let r = (d(i) * d(i) + d(j) * d(j) + d(k) * d(k)).sqrt();
                values.push(scale * (1.0 - r / 4.0).max(0.0));
            }
        }
    }
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let p = dir.join(name);
    fs::write(&p, bytes).unwrap();
    let max = values.iter().copied().fold(0.0, f32::max);
    (p.to_str().unwrap().to_string(), max)
}

#[test]
fn a_series_is_one_frame_per_file_under_one_transfer_function() {
    let dir = tempfile::tempdir().unwrap();
    let files: Vec<(String, f32)> = (1..=3)
        .map(|s| scaled_ball(dir.path(), &format!("ball{s}.raw"), s as f32))
        .collect();
    // A named transfer function (the ramp in grey): one chosen from the
    // data (`--tf auto`, the default) would depend on the volume it is
    // chosen from, and a frame would not be its file rendered alone.
    let raw = ["--dims", "9,9,9", "--size", "24", "--colormap", "grey"];
    let out = path(dir.path(), "series.png");
    let mut args = vec!["render"];
    args.extend(files.iter().map(|(f, _)| f.as_str()));
    args.extend(raw);
    args.extend(["-o", out.to_str().unwrap()]);
    run_ok(&args);
    let (count, frames, _) = read_apng(&out);
    assert_eq!(count, 3);
    // One value window for all: from 0 to the largest value of the three,
    // so each frame is the file rendered alone with that --range.
    let top = files[2].1 as f64;
    let range = format!("0,{top}");
    for (i, (file, _)) in files.iter().enumerate() {
        let still = path(dir.path(), &format!("alone{i}.png"));
        run_ok(
            &[
                &["render", file],
                &raw[..],
                &["--range", &range, "-o", still.to_str().unwrap()],
            ]
            .concat(),
        );
        assert_eq!(read_png(&still), frames[i], "frame {i}");
    }
    // So the denser balls look brighter; rendered alone, each would fill
    // its own window and look the same.
    let centre = 12 + 24 * 12;
    assert!(frames[0][centre][0] < frames[1][centre][0]);
    assert!(frames[1][centre][0] < frames[2][centre][0]);
    let alone = path(dir.path(), "own.png");
    run_ok(
        &[
            &["render", &files[0].0],
            &raw[..],
            &["-o", alone.to_str().unwrap()],
        ]
        .concat(),
    );
    assert_eq!(
        read_png(&alone),
        frames[2],
        "1 − r alone is 3(1 − r) in 0..3"
    );
}

/// The 9³ paraboloid ball 1 − (r/4)² times `scale`, as a raw f32 file:
/// its gradient grows from 0 at the centre to the largest at r = 4.
fn paraboloid(dir: &Path, name: &str, scale: f32) -> String {
    let mut values = Vec::new();
    for k in 0..9 {
        for j in 0..9 {
            for i in 0..9 {
                let d = |n: i32| (n - 4) as f32 / 4.0;
                let r2 = d(i) * d(i) + d(j) * d(j) + d(k) * d(k);
                values.push(scale * (1.0 - r2).max(0.0));
            }
        }
    }
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let p = dir.join(name);
    fs::write(&p, bytes).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn a_series_shares_its_gradient_opacity_scale() {
    // Volume 2 is volume 1 doubled, so its largest gradient is twice
    // volume 1's. In the series, --gradient-opacity fractions are of
    // volume 2's largest gradient: volume 1's frame equals volume 1 alone
    // with the fractions doubled (of its own largest gradient) and the
    // same value window.
    let dir = tempfile::tempdir().unwrap();
    let one = paraboloid(dir.path(), "one.raw", 1.0);
    let two = paraboloid(dir.path(), "two.raw", 2.0);
    let raw = ["--dims", "9,9,9", "--size", "24", "--no-shading"];
    let out = path(dir.path(), "series.png");
    let go = ["--gradient-opacity", "0.2,0.5"];
    run_ok(
        &[
            &["render", &one, &two][..],
            &raw[..],
            &go[..],
            &["-o", out.to_str().unwrap()],
        ]
        .concat(),
    );
    let (_, frames, _) = read_apng(&out);
    let alone = |fractions: &str, name: &str| {
        let still = path(dir.path(), name);
        run_ok(
            &[
                &["render", &one][..],
                &raw[..],
                &["--range", "0,2", "--gradient-opacity", fractions],
                &["-o", still.to_str().unwrap()],
            ]
            .concat(),
        );
        read_png(&still)
    };
    assert!(max_diff(&alone("0.4,1", "doubled.png"), &frames[0]) <= 1);
    // Its own scale would give another picture.
    let own = max_diff(&alone("0.2,0.5", "own.png"), &frames[0]);
    assert!(own > 8, "{own}");
}

/// A NRRD file of the 9³ ball 1 − r/4 with its first voxel at `origin`.
fn ball_nrrd(dir: &Path, name: &str, origin: [f64; 3]) -> String {
    let mut data = Vec::new();
    for k in 0..9 {
        for j in 0..9 {
            for i in 0..9 {
                let d = |n: i32| (n - 4) as f32;
                let r = (d(i) * d(i) + d(j) * d(j) + d(k) * d(k)).sqrt();
                data.extend_from_slice(&(1.0 - r / 4.0).max(0.0).to_le_bytes());
            }
        }
    }
    let header = format!(
        "NRRD0004\ntype: float\ndimension: 3\nspace dimension: 3\nsizes: 9 9 9\n\
         space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: ({},{},{})\n\
         endian: little\nencoding: raw\n\n",
        origin[0], origin[1], origin[2]
    );
    let p = dir.join(name);
    fs::write(&p, [header.as_bytes(), &data].concat()).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn a_series_is_framed_around_every_volume() {
    // The same ball at y = 0..8 and at y = 12..20: the frame covers
    // y = 0..20 (and z = 0..8), so at 40×16 pixels each pixel is half a
    // unit and the second ball shows 24 pixels right of the first.
    let dir = tempfile::tempdir().unwrap();
    let a = ball_nrrd(dir.path(), "a.nrrd", [0.0, 0.0, 0.0]);
    let b = ball_nrrd(dir.path(), "b.nrrd", [0.0, 12.0, 0.0]);
    let out = path(dir.path(), "moving.gif");
    let run = volray(&[
        "render",
        &a,
        &b,
        "--size",
        "40x16",
        "--no-shading",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).is_empty(), "{}", stderr(&run));
    let (frames, _) = read_gif(&out);
    assert_eq!(frames.len(), 2);
    let lit_cols = |f: &Frame| -> Vec<usize> {
        (0..40)
            .filter(|&c| (0..16).any(|r| f[c + 40 * r][0] > 8))
            .collect()
    };
    let (first, second) = (lit_cols(&frames[0]), lit_cols(&frames[1]));
    assert!(
        !first.is_empty() && *first.last().unwrap() < 17,
        "{first:?}"
    );
    let shifted: Vec<usize> = first.iter().map(|c| c + 24).collect();
    assert_eq!(second, shifted);
}

#[test]
fn animations_refuse_what_they_cannot_write_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (good, _) = scaled_ball(dir.path(), "good.raw", 1.0);
    // The middle file is too short for its dims: the series fails on it,
    // after the first frame could have been rendered.
    fs::write(dir.path().join("short.raw"), [0u8; 100]).unwrap();
    let short = path(dir.path(), "short.raw");
    let before = names(dir.path());
    for (args, expect) in [
        (
            vec!["render", "blobs:16", "--turntable", "0"],
            "--turntable",
        ),
        (vec!["render", "blobs:16", "--turntable", "3"], ".exr"),
        (
            vec![
                "render",
                "blobs:16",
                "--turntable",
                "3",
                "--bit-depth",
                "16",
            ],
            "--bit-depth",
        ),
        (vec!["render", "blobs:16", "--fps", "10"], "--fps"),
        (
            vec!["render", "blobs:16", "--turntable", "3", "--fps", "0"],
            "--fps",
        ),
        (
            vec!["render", "blobs:16", "blobs:16", "--turntable", "2"],
            "--turntable",
        ),
        (vec!["render", "blobs:16", "sphere:16"], "several inputs"),
        (
            vec![
                "render",
                good.as_str(),
                short.to_str().unwrap(),
                good.as_str(),
                "--dims",
                "9,9,9",
            ],
            "short.raw",
        ),
    ] {
        // Each to the name that provokes it: .exr for the OpenEXR cases,
        // else an animated PNG.
        let out = if expect == ".exr" || expect == "several inputs" {
            path(dir.path(), "anim.exr")
        } else {
            path(dir.path(), "anim.png")
        };
        let mut all = args.clone();
        all.extend(["--size", "8", "-o", out.to_str().unwrap()]);
        let run = volray(&all);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert_eq!(names(dir.path()), before, "{args:?} left a file");
    }
}
