//! Time points and channels kept apart in every format (issue 41): a
//! 2-time × 3-channel ImageJ hyperstack (tifffile, `axes='TZCYX'`), an
//! HDF5 dataset `a[t, c, z, y, x]` with dimension labels (h5py) and a
//! 5-D NIfTI (nibabel, `dim[4]` time, `dim[5]` components), written here
//! by `target/pyenv` (which `.ci/run` installs; without it these tests
//! fail under `CI=true` and are skipped elsewhere).
//!
//! Every file holds the same 24³ float32 volumes: at time point t,
//! channel c, a soft ball of radius 5 about (x, y, z) = (12, 5 + 7c,
//! 8 + 8t). Seen along −x (the default view), +y is to the right and +z
//! up, so each channel's ball has its own column of the picture and each
//! time point its own row. `one.npy` is the volume at t = 1, c = 2 alone.

mod common;

use std::path::Path;

use common::{Picture, stderr, stdout, volray};

const WRITE: &str = r#"
import sys
import numpy as np
import tifffile, h5py, nibabel
out = sys.argv[1]
n = 24
z, y, x = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
def ball(t, c):
    r = np.sqrt((x - 12.0)**2 + (y - 5.0 - 7 * c)**2 + (z - 8.0 - 8 * t)**2)
    return np.maximum(0, 1 - r / 5).astype("f4")
a = np.stack([np.stack([ball(t, c) for c in range(3)]) for t in range(2)])  # t, c, z, y, x
tifffile.imwrite(out + "/hyper.tif", a.transpose(0, 2, 1, 3, 4), imagej=True,
                 metadata={"axes": "TZCYX"})
with h5py.File(out + "/tczyx.h5", "w") as f:
    d = f.create_dataset("a", data=a)
    for i, label in enumerate("tczyx"):
        d.dims[i].label = label
    # The same volumes with channel before time: found by their labels.
    d = f.create_dataset("b", data=a.transpose(1, 0, 2, 3, 4))
    for i, label in enumerate("ctzyx"):
        d.dims[i].label = label
img = nibabel.Nifti1Image(a.transpose(4, 3, 2, 0, 1), np.eye(4))  # x, y, z, t, c
nibabel.save(img, out + "/five.nii")
np.save(out + "/one.npy", a[1, 2].transpose(2, 1, 0))  # a[x, y, z]
"#;

/// The files, or `None` where the writers are missing outside CI.
fn files() -> Option<tempfile::TempDir> {
    common::written_by_python(
        &["numpy", "tifffile", "h5py", "nibabel"],
        &["-W", "ignore"],
        WRITE,
    )
}

/// The three files, as INPUT.
fn inputs(dir: &Path) -> [String; 3] {
    ["hyper.tif", "tczyx.h5:/a", "five.nii"].map(|f| format!("{}/{f}", dir.display()))
}

/// Renders `args` at 48², unshaded, into `name`: the picture.
fn render(dir: &Path, name: &str, args: &[&str]) -> Picture {
    let out = dir.join(name);
    let all = [
        &["render", "--size", "48", "--no-shading", "-o"],
        &[out.to_str().unwrap()][..],
        args,
    ]
    .concat();
    let run = volray(&all);
    assert!(run.status.success(), "{all:?}: {}", stderr(&run));
    Picture::read(&out)
}

/// `volray ARGS` expecting a one-line refusal: the line.
fn refused(args: &[&str]) -> String {
    let run = volray(args);
    let text = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{args:?}: {text}");
    assert_eq!(text.lines().count(), 1, "one line: {text}");
    text
}

#[test]
fn info_counts_channels_and_time_points_apart_in_every_format() {
    let Some(dir) = files() else { return };
    for input in inputs(dir.path()) {
        let run = volray(&["info", &input, "--json"]);
        assert!(run.status.success(), "{input}: {}", stderr(&run));
        let json: serde_json::Value = serde_json::from_str(&stdout(&run)).unwrap();
        let count = |key: &str| json[key].as_u64().unwrap_or_else(|| panic!("{key}"));
        assert_eq!(count("channels"), 3, "{input}");
        assert_eq!(count("time_points"), 2, "{input}");
        assert_eq!(count("frames"), 6, "{input}: the volumes, T x C");
        let run = volray(&["info", &input, "--channel", "2", "--frame", "1", "--json"]);
        let json: serde_json::Value = serde_json::from_str(&stdout(&run)).unwrap();
        assert_eq!(
            [&json["time_point"], &json["channel"], &json["frame"]],
            [1, 2, 5].map(serde_json::Value::from).each_ref(),
            "{input}"
        );
        let text = stdout(&volray(&["info", &input]));
        assert!(text.contains("channels:  3 (read: 0;"), "{input}: {text}");
        assert!(text.contains("time points: 2 (read: 0;"), "{input}: {text}");
    }
}

#[test]
fn a_channel_at_a_time_point_is_that_one_volume_in_every_format() {
    let Some(dir) = files() else { return };
    let d = dir.path();
    let alone = render(d, "alone.png", &[&format!("{}/one.npy", d.display())]);
    assert!(alone.rgb.iter().any(|p| *p != alone.rgb[0]), "blank");
    let b = format!("{}/tczyx.h5:/b", d.display());
    for input in inputs(d).iter().chain([&b]) {
        let p = render(d, "picked.png", &[input, "--channel", "2", "--frame", "1"]);
        assert_eq!(p, alone, "{input}: --channel 2 --frame 1");
        // Another channel at that time point, or that channel at another,
        // is another volume.
        let other = render(d, "other.png", &[input, "--channel", "1", "--frame", "1"]);
        assert_ne!(other, alone, "{input}");
        let other = render(d, "other.png", &[input, "--channel", "2"]);
        assert_ne!(other, alone, "{input}");
    }
}

#[test]
fn channels_at_a_time_point_are_each_channel_alone_at_it_summed() {
    let Some(dir) = files() else { return };
    let d = dir.path();
    let colors = ["red", "green", "blue"];
    for input in inputs(d) {
        let all = render(
            d,
            "all.png",
            &[
                &input,
                "--channels",
                "all",
                "--frame",
                "1",
                "--channel-colors",
                "red,green,blue",
            ],
        );
        // Each channel alone at time point 1, in its colour, over black.
        let alone: Vec<Picture> = (0..3)
            .map(|c| {
                render(
                    d,
                    "one.png",
                    &[
                        &input,
                        "--channels",
                        &c.to_string(),
                        "--frame",
                        "1",
                        "--channel-colors",
                        colors[c],
                    ],
                )
            })
            .collect();
        for (i, p) in all.rgb.iter().enumerate() {
            for (k, &got) in p.iter().enumerate() {
                let sum: u32 = alone.iter().map(|a| u32::from(a.rgb[i][k])).sum();
                assert!(
                    u32::from(got).abs_diff(sum.min(255)) <= 2,
                    "{input}: pixel {i} channel {k}: {got} vs {sum}"
                );
            }
        }
        // Each alone shows its ball in its colour only.
        for (c, a) in alone.iter().enumerate() {
            let lit = |p: &[u8; 3]| p[c] > 40 && (0..3).all(|j| j == c || p[j] <= 2);
            assert!(a.rgb.iter().any(lit), "{input}: channel {c}");
        }
        let earlier = render(
            d,
            "t0.png",
            &[
                &input,
                "--channels",
                "all",
                "--channel-colors",
                "red,green,blue",
            ],
        );
        assert_ne!(earlier, all, "{input}: time point 0 is another picture");
    }
}

#[test]
fn time_points_walk_one_channel_and_out_of_range_picks_are_refused_naming_the_flag() {
    let Some(dir) = files() else { return };
    let d = dir.path();
    for input in inputs(d) {
        let e = refused(&["info", &input, "--channel", "3"]);
        assert!(
            e.contains("--channel 3 is out of range") && e.contains("3 channels"),
            "{input}: {e}"
        );
        let e = refused(&["info", &input, "--frame", "2"]);
        assert!(
            e.contains("--frame 2 is out of range") && e.contains("2 time points"),
            "{input}: {e}"
        );
        let out = d.join("t.png");
        let e = refused(&[
            "render",
            &input,
            "--channels",
            "all",
            "--channel",
            "1",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(e.contains("--channel picks one"), "{input}: {e}");
        // --frames walks the time points of the channel --channel picks.
        let seq = d.join("walk_%03d.png");
        let run = volray(&[
            "render",
            &input,
            "--frames",
            "all",
            "--channel",
            "2",
            "--size",
            "48",
            "--no-shading",
            "-o",
            seq.to_str().unwrap(),
        ]);
        assert!(run.status.success(), "{input}: {}", stderr(&run));
        let mut names: Vec<_> = (std::fs::read_dir(d).unwrap())
            .map(|e| e.unwrap().path())
            .filter(|p| {
                p.file_name()
                    .unwrap()
                    .to_str()
                    .unwrap()
                    .starts_with("walk_")
            })
            .collect();
        names.sort();
        let walked: Vec<Picture> = names.iter().map(|p| Picture::read(p)).collect();
        assert_eq!(walked.len(), 2, "{input}: {names:?}");
        for p in &names {
            std::fs::remove_file(p).unwrap();
        }
        let alone = render(d, "alone.png", &[&format!("{}/one.npy", d.display())]);
        assert!(walked[1].max_diff(&alone) <= 1, "{input}: time point 1");
        assert_ne!(walked[0], walked[1], "{input}");
    }
    // A file of one channel: --channel 1 is out of range.
    let npy = format!("{}/one.npy", d.display());
    let e = refused(&["info", &npy, "--channel", "1"]);
    assert!(e.contains("--channel 1 is out of range"), "{e}");
}

#[test]
fn frames_walk_the_time_points_with_every_channel_asked_for() {
    let Some(dir) = files() else { return };
    let d = dir.path();
    for input in inputs(d) {
        let look = ["--channels", "all", "--channel-colors", "red,green,blue"];
        let seq = d.join("both_%03d.png");
        let run = volray(
            &[
                &["render", &input, "--frames", "all", "--size", "48"],
                &["--no-shading", "-o", seq.to_str().unwrap()][..],
                &look[..],
            ]
            .concat(),
        );
        assert!(run.status.success(), "{input}: {}", stderr(&run));
        for t in 0..2 {
            let name = d.join(format!("both_{t:03}.png"));
            let walked = Picture::read(&name);
            std::fs::remove_file(&name).unwrap();
            let at = render(
                d,
                "at.png",
                &[&[input.as_str(), "--frame", &t.to_string()], &look[..]].concat(),
            );
            assert!(walked.max_diff(&at) <= 1, "{input}: time point {t}");
        }
    }
}
