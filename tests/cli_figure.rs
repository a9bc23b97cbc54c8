//! Figures from the command line: `--colorbar`, `--scale-bar`, `--title`
//! and `--label` drawn into a still by volray-annotate (whose own tests
//! hold the bar's colours at its ticks and the text to the font's
//! rasterisation). Here: the annotations land where they belong and leave
//! the rest of the picture as it was, the scale bar is its length over the
//! view's pixel size, OpenEXR keeps the bare frame and says so, and what
//! is not drawn yet is refused in one line.

mod common;

use common::{Picture, stderr, volray};
use std::path::Path;
use volray_core::camera::{Camera, View};
use volray_core::glam::DVec3;

/// Renders the built-in `sphere:32` (its box [−1, 1]³) at
/// `size`², seen along −x, with `args`; the picture and stderr.
fn render(dir: &Path, name: &str, size: usize, args: &[&str]) -> (Picture, String) {
    let out = dir.join(name);
    let size = size.to_string();
    let mut all = vec![
        "render",
        "sphere:32",
        "--size",
        &size,
        "--no-shading",
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let run = volray(&all);
    assert!(run.status.success(), "{all:?}: {}", stderr(&run));
    (Picture::read(&out), stderr(&run))
}

#[test]
fn annotations_are_drawn_at_the_edges_and_leave_the_volume_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let (bare, _) = render(dir.path(), "bare.png", 240, &[]);
    let (fig, _) = render(
        dir.path(),
        "fig.png",
        240,
        &[
            "--colorbar",
            "--scale-bar",
            "--title",
            "A sphere",
            "--label",
            "b",
        ],
    );
    let differs = |x0: usize, x1: usize, y0: usize, y1: usize| {
        (y0..y1).any(|y| (x0..x1).any(|x| fig.at(x, y) != bare.at(x, y)))
    };
    // The middle of the picture is the volume's, untouched.
    assert!(!differs(70, 170, 60, 180), "the volume was drawn over");
    assert!(differs(180, 240, 40, 200), "no colour bar on the right");
    assert!(differs(0, 120, 200, 240), "no scale bar at the bottom left");
    assert!(differs(60, 180, 0, 30), "no title");
    assert!(differs(0, 30, 0, 30), "no label");
}

#[test]
fn the_scale_bar_is_its_length_over_the_views_pixel_size() {
    let dir = tempfile::tempdir().unwrap();
    for (size, length) in [(240usize, "0.5"), (600, "1")] {
        // A colour map: no pixel of the sphere is pure white.
        let (fig, _) = render(
            dir.path(),
            "scale.png",
            size,
            &["--scale-bar", length, "--colormap", "viridis"],
        );
        // The view the command line frames: the sphere's box, along −x.
        let view = View::frame(
            &Camera::default(),
            (DVec3::splat(-1.0), DVec3::ONE),
            size,
            size,
        )
        .unwrap();
        let pixel = view.as_orthographic().unwrap().pixel_size;
        let want = length.parse::<f64>().unwrap() / pixel;
        // The longest run of white pixels along a row of the lowest fifth.
        let longest = (size * 4 / 5..size)
            .map(|y| {
                let (mut best, mut run) = (0, 0);
                for x in 0..size {
                    run = if fig.at(x, y) == [255; 3] { run + 1 } else { 0 };
                    best = best.max(run);
                }
                best
            })
            .max()
            .unwrap();
        assert!(
            (longest as f64 - want).abs() <= 1.0,
            "{size}: {longest} vs {want}"
        );
    }
}

#[test]
fn openexr_keeps_the_bare_frame_and_animations_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("out.exr");
    let run = volray(&[
        "render",
        "sphere:16",
        "--size",
        "32",
        "--colorbar",
        "-o",
        exr.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(
        stderr(&run).contains("keeps the bare frame"),
        "{}",
        stderr(&run)
    );
    let gif = dir.path().join("turn.gif");
    let run = volray(&[
        "render",
        "sphere:16",
        "--size",
        "32",
        "--turntable",
        "3",
        "--title",
        "x",
        "-o",
        gif.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1));
    let message = stderr(&run);
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(
        message.contains("--title") && message.contains("animations"),
        "{message}"
    );
    assert!(!gif.exists());
    let run = volray(&[
        "render",
        "sphere:16",
        "--scale-bar=-3",
        "-o",
        gif.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(
        stderr(&run).contains("not a positive length"),
        "{}",
        stderr(&run)
    );
}
