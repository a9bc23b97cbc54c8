//! Label volumes (`--labels`): a segmentation written by nibabel (NIfTI,
//! `uint8`) and the same labels written by VTK (`.vti`), rendered through
//! the binary: each label in its colour of the categorical table, label 0
//! transparent, `--show-labels` and `--label-opacity`, the reference path
//! as the oracle, `volray info`'s suggestion, and the refusals.
//!
//! The fixtures (`crates/io/tests/fixtures/make_label_fixtures.py`): on a
//! 24³ grid of unit spacing, label 1 in a ball of radius 9 about the
//! centre (11.5, 11.5, 11.5), label 2 in a ball of radius 4.5 inside it,
//! label 5 in a small box in a corner, 0 elsewhere.

mod common;

use common::{Picture, stderr, stdout, volray};
use std::path::{Path, PathBuf};
use volray_core::transfer::labels::PALETTE;

fn fixture(name: &str) -> String {
    let p: PathBuf = [
        env!("CARGO_MANIFEST_DIR"),
        "crates/io/tests/fixtures/labels",
        name,
    ]
    .iter()
    .collect();
    p.to_str().unwrap().to_string()
}

/// Renders `input` with `args` at 48², seen along −x (the default view),
/// unshaded unless `args` says otherwise; the picture.
fn render(dir: &Path, name: &str, input: &str, args: &[&str]) -> Picture {
    let out = dir.join(name);
    let mut all = vec!["render", input, "--size", "48", "-o", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let run = volray(&all);
    assert!(run.status.success(), "{all:?}: {}", stderr(&run));
    Picture::read(&out)
}

/// The 8-bit level of a colour channel.
fn level(c: f32) -> u8 {
    (c * 255.0).round() as u8
}

fn close(got: [u8; 3], want: [f32; 3], tolerance: u8) -> bool {
    got.iter()
        .zip(want)
        .all(|(&g, w)| g.abs_diff(level(w)) <= tolerance)
}

#[test]
fn each_label_shows_in_its_own_colour_and_label_0_is_transparent() {
    let dir = tempfile::tempdir().unwrap();
    let seg = fixture("seg.nii.gz");
    let flat = render(dir.path(), "flat.png", &seg, &["--labels", "--no-shading"]);
    // Through the centre: the opaque surface of label 1 (orange).
    let centre = flat.at(24, 24);
    assert!(
        close(centre, PALETTE[1], 3),
        "{centre:?} vs {:?}",
        PALETTE[1]
    );
    // Past the ball's outline: label 0, the background.
    assert_eq!(flat.at(1, 24), [0, 0, 0]);
    assert_eq!(flat.at(24, 46), [0, 0, 0]);

    // Only label 2 shown: the inner ball in green, nothing else.
    let inner = render(
        dir.path(),
        "inner.png",
        &seg,
        &["--labels", "--no-shading", "--show-labels", "2"],
    );
    let centre = inner.at(24, 24);
    assert!(
        close(centre, PALETTE[2], 3),
        "{centre:?} vs {:?}",
        PALETTE[2]
    );
    assert_eq!(inner.at(24, 12), [0, 0, 0], "label 1 is hidden");
}

/// The fixture's labels (see the module docs) with label 1 left out: 0
/// where the big ball is, as an `.npy` file (`f32`, `a[x, y, z]`).
fn without_label_1(dir: &Path) -> String {
    const N: usize = 24;
    let mut data = vec![0f32; N * N * N];
    for z in 0..N {
        for y in 0..N {
            for x in 0..N {
                let d = |i: usize| i as f64 - 11.5;
                let r = (d(x).powi(2) + d(y).powi(2) + d(z).powi(2)).sqrt();
                let label = if r <= 4.5 {
                    2.0
                } else if (1..4).contains(&x) && (1..4).contains(&y) && (18..22).contains(&z) {
                    5.0
                } else {
                    0.0
                };
                data[x + N * (y + N * z)] = label;
            }
        }
    }
    let volume = volray_core::Volume::new([N; 3], data).unwrap();
    let path = dir.join("without_1.npy");
    volray_io::write_npy(&path, &volume).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn label_opacity_0_makes_a_label_vanish_and_between_lets_the_inside_show_through() {
    let dir = tempfile::tempdir().unwrap();
    let seg = fixture("seg.nii.gz");
    let look = ["--labels", "--no-shading"];
    let with = |opacity: &'static str| [&look[..], &["--label-opacity", opacity]].concat();
    let opaque = render(dir.path(), "opaque.png", &seg, &look);
    let gone = render(dir.path(), "gone.png", &seg, &with("1:0"));
    let faint = render(dir.path(), "faint.png", &seg, &with("1:0.2"));
    // Label 1 at opacity 0 is the volume without it: the inner ball and
    // the box of label 5, nothing of the big ball.
    let without = render(
        dir.path(),
        "without.png",
        &without_label_1(dir.path()),
        &look,
    );
    assert_eq!(gone.max_diff(&without), 0);
    let centre = gone.at(24, 24);
    assert!(
        close(centre, PALETTE[2], 3),
        "{centre:?} vs {:?}",
        PALETTE[2]
    );
    assert_eq!(gone.at(24, 12), [0, 0, 0], "label 1 has vanished");
    // Opaque, label 1 hides the inner ball; faint, the ray crosses about
    // 4.5 voxels of it first and the inner ball's green shows through:
    // the centre's red (orange 255, green 44) falls between the two.
    let centre = opaque.at(24, 24);
    assert!(
        close(centre, PALETTE[1], 3),
        "{centre:?} vs {:?}",
        PALETTE[1]
    );
    let red = |p: &Picture| p.at(24, 24)[0];
    assert!(
        red(&gone) < red(&faint) && red(&faint) < red(&opaque),
        "{} {} {}",
        red(&gone),
        red(&faint),
        red(&opaque)
    );
    // Between the balls' outlines the ray meets label 1 alone: orange
    // opaque, dimmer orange (over the black background) faint.
    let (solid, dim) = (opaque.at(24, 12), faint.at(24, 12));
    assert!(close(solid, PALETTE[1], 3), "{solid:?}");
    assert!(dim[0] > 0 && dim[0] < solid[0], "{dim:?} vs {solid:?}");
}

#[test]
fn the_nifti_and_vtk_files_render_alike_and_the_reference_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let view = ["--labels", "--azimuth", "30", "--elevation", "20"];
    let nifti = render(dir.path(), "nifti.png", &fixture("seg.nii.gz"), &view);
    let vti = render(dir.path(), "vti.png", &fixture("tissue.vti"), &view);
    // u8 from NIfTI, f32 from VTK XML: the same labels, the same image.
    assert_eq!(nifti.max_diff(&vti), 0);
    // The reference path (the oracle) shades with the same label normals.
    let oracle = render(
        dir.path(),
        "oracle.png",
        &fixture("seg.nii.gz"),
        &[&view[..], &["--reference"]].concat(),
    );
    assert!(nifti.max_diff(&oracle) <= 1, "{}", nifti.max_diff(&oracle));
    // Shaded, the ball is lit by its label normals: brighter at the centre
    // (facing the headlight) than near the outline.
    let lum = |p: [u8; 3]| p.iter().map(|&c| c as u32).sum::<u32>();
    assert!(lum(nifti.at(24, 24)) > lum(nifti.at(24, 8)) + 30);
}

#[test]
fn info_suggests_labels_for_a_segmentation_only() {
    let seg = volray(&["info", &fixture("seg.nii.gz")]);
    let text = stdout(&seg);
    assert!(
        text.contains("labels:    4 distinct integer values (0, 1, 2, 5)")
            && text.contains("--labels"),
        "{text}"
    );
    let blobs = volray(&["info", "blobs:16"]);
    assert!(!stdout(&blobs).contains("--labels"));
}

#[test]
fn labels_are_refused_where_they_do_not_apply() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let out = out.to_str().unwrap();
    let seg = fixture("seg.nii.gz");
    for (args, names) in [
        (vec!["blobs:16", "--labels"], "not an integer"),
        (
            vec![seg.as_str(), "--labels", "--show-labels", "7"],
            "label 7 is not in the volume",
        ),
        (vec![seg.as_str(), "--label-opacity", "1:0.5"], "--labels"),
        (
            vec![seg.as_str(), "--labels", "--colormap", "magma"],
            "--colormap",
        ),
        (
            vec![seg.as_str(), "--labels", "--label-opacity", "1:2"],
            "must be in [0, 1]",
        ),
        (
            vec![seg.as_str(), "--labels", "--tf", "auto"],
            "--tf auto conflicts with --labels",
        ),
    ] {
        let mut all = vec!["render", "-o", out];
        all.extend(args.iter().copied());
        let run = volray(&all);
        assert_eq!(run.status.code(), Some(1), "{all:?}");
        let err = stderr(&run);
        assert!(err.contains(names), "{all:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!Path::new(out).exists());
    }
}
