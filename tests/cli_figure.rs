//! Figures from the command line: `--colorbar` (its `--units`),
//! `--scale-bar`, `--axes`, `--outline`, `--title` and `--label` drawn into a still or each frame
//! of an animation by volray-annotate (whose own tests hold the bar's
//! colours at its ticks, the text to the font's rasterisation, the
//! triad's directions). Here: the annotations land where they belong and
//! leave the rest of the picture as it was, the scale bar is its length
//! over the view's pixel size, the outline runs along the box's edges as
//! the camera projects them, the triad points as the view turns the
//! axes, turntables and series are annotated frame by frame, OpenEXR
//! keeps the bare frame and says so, and what is not drawn yet is refused
//! in one line.

mod common;

use common::{Picture, stderr, volray};
use std::path::Path;
use volray_core::camera::{Camera, View};
use volray_core::glam::DVec3;
use volray_core::{Fit, Projection};

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
fn the_colour_bar_says_the_units_given_and_hounsfield_units_under_a_ct_preset() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, _) = render(dir.path(), "plain.png", 200, &["--colorbar"]);
    let (kelvin, _) = render(dir.path(), "k.png", 200, &["--colorbar", "--units", "K"]);
    let changed: Vec<usize> = (0..200 * 200)
        .filter(|&k| plain.at(k % 200, k / 200) != kelvin.at(k % 200, k / 200))
        .collect();
    assert!(!changed.is_empty(), "the unit was not written");
    assert!(
        changed.iter().all(|&k| k % 200 >= 150),
        "the unit changed more than the bar's ticks"
    );
    // A CT preset's bar is in HU, as if --units HU were given; --units wins.
    let ct = ["--colorbar", "--preset", "ct-bone"];
    let (preset, _) = render(dir.path(), "ct.png", 200, &ct);
    let (hu, _) = render(
        dir.path(),
        "hu.png",
        200,
        &[&ct[..], &["--units", "HU"]].concat(),
    );
    let (k, _) = render(
        dir.path(),
        "ctk.png",
        200,
        &[&ct[..], &["--units", "K"]].concat(),
    );
    assert_eq!(preset, hu);
    assert_ne!(preset, k);
    let out = dir.path().join("bad.png");
    let run = volray(&[
        "render",
        "sphere:16",
        "--colorbar",
        "--units",
        " ",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(stderr(&run).contains("not a unit"), "{}", stderr(&run));
    assert!(!out.exists());
}

#[test]
fn openexr_keeps_the_bare_frame_and_bad_lengths_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("out.exr");
    let bare = dir.path().join("bare.exr");
    let base = [
        "render",
        "hydrogen:6,2,1",
        "--size",
        "32",
        "--colormap",
        "magma",
    ];
    let run = volray(&[&base[..], &["-o", bare.to_str().unwrap()]].concat());
    assert!(run.status.success(), "{}", stderr(&run));
    let bare = std::fs::read(&bare).unwrap();
    for flags in [
        &["--colorbar"][..],
        &["--axes"],
        &["--outline"],
        &["--scale-bar", "--title", "T", "--label", "a"],
        &["--colorbar", "left", "--units", "K"],
    ] {
        let run = volray(&[&base[..], flags, &["-o", exr.to_str().unwrap()]].concat());
        assert!(run.status.success(), "{}", stderr(&run));
        let message = stderr(&run);
        assert!(
            message.contains("keeps the bare frame") && message.starts_with(flags[0]),
            "{message}"
        );
        assert_eq!(message.lines().count(), 1, "{message}");
        // The frame's values as rendered, byte for byte: the figure is
        // drawn into 8- and 16-bit pictures only.
        assert!(
            std::fs::read(&exr).unwrap() == bare,
            "{flags:?} changed the EXR"
        );
    }
    let gif = dir.path().join("out.gif");
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
    assert!(!gif.exists());
}

/// The distance from `p` to the segment `a`–`b`.
fn distance(p: (f64, f64), (a, b): ((f64, f64), (f64, f64))) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

/// The box's twelve edges as `view` projects them.
fn edges(view: &View, (lo, hi): (DVec3, DVec3)) -> Vec<((f64, f64), (f64, f64))> {
    let corner = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let mut out = Vec::new();
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                let (a, b) = (corner(i), corner(i | bit));
                out.push((view.project(a).unwrap(), view.project(b).unwrap()));
            }
        }
    }
    out
}

#[test]
fn the_outline_runs_along_the_boxs_edges_as_the_camera_projects_them() {
    let dir = tempfile::tempdir().unwrap();
    let bounds = (DVec3::splat(-1.0), DVec3::ONE);
    for (perspective, zoom) in [(None, "1"), (Some(35.0), "1"), (None, "1.6")] {
        let mut args = vec!["--azimuth", "30", "--elevation", "20", "--zoom", zoom];
        let fov = perspective.map(|f: f64| f.to_string());
        if let Some(fov) = &fov {
            args.extend(["--perspective", fov]);
        }
        let (bare, _) = render(dir.path(), "bare.png", 240, &args);
        args.push("--outline");
        let (fig, _) = render(dir.path(), "outline.png", 240, &args);
        let camera = Camera {
            azimuth: 30.0,
            elevation: 20.0,
            zoom: zoom.parse().unwrap(),
            projection: perspective.map_or(Projection::Orthographic, |fov_degrees| {
                Projection::Perspective { fov_degrees }
            }),
            fit: Fit::Box,
            ..Camera::default()
        };
        let view = View::frame(&camera, bounds, 240, 240).unwrap();
        let segments = edges(&view, bounds);
        // Along each edge, the pixels carry the ink (white, at least half
        // covered).
        let mut on = 0;
        for &(a, b) in &segments {
            for f in 1..40 {
                let f = f as f64 / 40.0;
                let p = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
                if p.0 < 0.0 || p.1 < 0.0 || p.0 >= 240.0 || p.1 >= 240.0 {
                    continue;
                }
                let (x, y) = (p.0 as usize, p.1 as usize);
                let (was, is) = (bare.at(x, y)[1] as f64, fig.at(x, y)[1] as f64);
                assert!(
                    is - was >= 0.5 * (255.0 - was) - 1.0,
                    "{perspective:?} {zoom}: ({x}, {y}) {was} -> {is}"
                );
                on += 1;
            }
        }
        assert!(on > 100, "{perspective:?} {zoom}: {on}");
        // Far from every edge, the picture is the bare one.
        let mut far = 0;
        for y in 0..240 {
            for x in 0..240 {
                let p = (x as f64 + 0.5, y as f64 + 0.5);
                if segments.iter().all(|&s| distance(p, s) > 1.8) {
                    assert_eq!(fig.at(x, y), bare.at(x, y), "({x}, {y})");
                    far += 1;
                }
            }
        }
        assert!(far > 240 * 200, "{far}");
    }
}

/// The mean position of the pixels of `fig` that differ from `bare` and
/// are mostly channel `k` (the triad's red x, green y, blue z), and how
/// many there are.
fn ink_of(fig: &Picture, bare: &Picture, k: usize) -> ((f64, f64), usize) {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0);
    for y in 0..fig.height {
        for x in 0..fig.width {
            let p = fig.at(x, y);
            let others = (0..3).filter(|&o| o != k);
            if p != bare.at(x, y)
                && p[k] > 100
                && others
                    .clone()
                    .all(|o| u32::from(p[o]) * 10 < u32::from(p[k]) * 7)
            {
                sx += x as f64;
                sy += y as f64;
                n += 1;
            }
        }
    }
    ((sx / n.max(1) as f64, sy / n.max(1) as f64), n)
}

#[test]
fn the_axes_point_as_the_view_turns_them() {
    let dir = tempfile::tempdir().unwrap();
    for azimuth in ["0", "90"] {
        let args = ["--azimuth", azimuth, "--colormap", "gray"];
        let (bare, _) = render(dir.path(), "bare.png", 240, &args);
        let (fig, _) = render(
            dir.path(),
            "axes.png",
            240,
            &[&args[..], &["--axes"]].concat(),
        );
        let (x, nx) = ink_of(&fig, &bare, 0);
        let (y, ny) = ink_of(&fig, &bare, 1);
        let (z, nz) = ink_of(&fig, &bare, 2);
        // z is up in both views: its ink lies above the others'.
        assert!(
            nz > 20 && z.1 < x.1 - 5.0 && z.1 < y.1 - 5.0,
            "{azimuth}: {x:?} {y:?} {z:?}"
        );
        // The triad sits in the bottom right corner, clear of the volume.
        assert!(z.0 > 180.0 && z.1 > 150.0, "{azimuth}: {z:?}");
        let view = View::frame(
            &Camera {
                azimuth: azimuth.parse().unwrap(),
                ..Camera::default()
            },
            (DVec3::splat(-1.0), DVec3::ONE),
            240,
            240,
        )
        .unwrap();
        let o = view.project(DVec3::ZERO).unwrap();
        let along = |axis: DVec3| {
            let p = view.project(axis).unwrap();
            (p.0 - o.0, p.1 - o.1)
        };
        if azimuth == "0" {
            // Along −x: +x points at the viewer (a dot), +y to the right.
            assert!(along(DVec3::X).0.abs() < 1e-9 && along(DVec3::Y).0 > 0.0);
            assert!(
                y.0 > z.0 + 5.0 && nx * 2 < ny,
                "{x:?} {nx} {y:?} {ny} {z:?}"
            );
        } else {
            // Along −y: +x points to the left, +y at the viewer.
            assert!(along(DVec3::X).0 < 0.0 && along(DVec3::Y).0.abs() < 1e-9);
            assert!(
                x.0 < z.0 - 5.0 && ny * 2 < nx,
                "{x:?} {nx} {y:?} {ny} {z:?}"
            );
        }
    }
}

/// The frames of a PNG sequence `pattern` (`…_%03d.png`) wrote.
fn frames(dir: &Path, stem: &str, n: usize) -> Vec<Picture> {
    (0..n)
        .map(|i| Picture::read(&dir.join(format!("{stem}_{i:03}.png"))))
        .collect()
}

#[test]
fn turntables_are_annotated_frame_by_frame() {
    let dir = tempfile::tempdir().unwrap();
    let run_turn = |stem: &str, extra: &[&str]| {
        let pattern = dir.path().join(format!("{stem}_%03d.png"));
        let mut all = vec![
            "render",
            "fractal:33",
            "--size",
            "240",
            "--turntable",
            "4",
            "--colormap",
            "viridis",
            "-o",
            pattern.to_str().unwrap(),
        ];
        all.extend_from_slice(extra);
        let run = volray(&all);
        assert!(run.status.success(), "{all:?}: {}", stderr(&run));
        frames(dir.path(), stem, 4)
    };
    let bare = run_turn("bare", &[]);
    let fig = run_turn(
        "fig",
        &["--scale-bar", "0.5", "--axes", "--title", "Turning"],
    );
    // The scale bar in each frame: 0.5 over the turntable's pixel (the
    // view fits the box's bounding sphere, the same at every azimuth).
    let (lo, hi) = (DVec3::splat(-1.0), DVec3::ONE);
    for (i, (fig, bare)) in fig.iter().zip(&bare).enumerate() {
        let view = View::frame(
            &Camera {
                azimuth: 90.0 * i as f64,
                fit: Fit::Sphere,
                ..Camera::default()
            },
            (lo, hi),
            240,
            240,
        )
        .unwrap();
        let want = 0.5 / view.as_orthographic().unwrap().pixel_size;
        let longest = (200..240)
            .map(|y| {
                let (mut best, mut run) = (0, 0);
                for x in 0..240 {
                    run = if fig.at(x, y) == [255; 3] { run + 1 } else { 0 };
                    best = best.max(run);
                }
                best
            })
            .max()
            .unwrap();
        assert!(
            (longest as f64 - want).abs() <= 1.0,
            "{i}: {longest} vs {want}"
        );
        // The title and the triad; the middle is the volume's.
        let differs = |x0: usize, x1: usize, y0: usize, y1: usize| {
            (y0..y1).any(|y| (x0..x1).any(|x| fig.at(x, y) != bare.at(x, y)))
        };
        assert!(differs(60, 180, 0, 30), "{i}: no title");
        assert!(differs(180, 240, 170, 240), "{i}: no triad");
        assert!(!differs(60, 180, 60, 180), "{i}: the volume was drawn over");
    }
    // The triad turns: the pixels it changes differ from frame to frame.
    let changed = |i: usize| -> Vec<(usize, usize)> {
        (170..240)
            .flat_map(|y| (180..240).map(move |x| (x, y)))
            .filter(|&(x, y)| fig[i].at(x, y) != bare[i].at(x, y))
            .collect()
    };
    assert!(!changed(0).is_empty());
    assert_ne!(changed(0), changed(1));
}

#[test]
fn a_series_has_one_colour_bar_and_scale_bar_for_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let run_series = |stem: &str, extra: &[&str]| {
        let pattern = dir.path().join(format!("{stem}_%03d.png"));
        let mut all = vec![
            "render",
            "sphere:32",
            "blobs:32",
            "--size",
            "240",
            // The volumes in the middle half, clear of the bars.
            "--zoom",
            "0.5",
            "--colormap",
            "viridis",
            "-o",
            pattern.to_str().unwrap(),
        ];
        all.extend_from_slice(extra);
        let run = volray(&all);
        assert!(run.status.success(), "{all:?}: {}", stderr(&run));
        frames(dir.path(), stem, 2)
    };
    let bare = run_series("bare", &[]);
    let fig = run_series("fig", &["--colorbar", "--scale-bar", "--outline"]);
    assert_ne!(bare[0].rgb, bare[1].rgb, "the volumes differ");
    // Where the bars are drawn, the two frames are the same pixels.
    let region = |p: &Picture, x0: usize, x1: usize, y0: usize, y1: usize| -> Vec<[u8; 3]> {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .map(|(x, y)| p.at(x, y))
            .collect()
    };
    for (x0, x1, y0, y1, what) in [
        (190, 240, 48, 192, "colour bar"),
        (0, 110, 200, 240, "scale bar"),
    ] {
        let (a, b) = (
            region(&fig[0], x0, x1, y0, y1),
            region(&fig[1], x0, x1, y0, y1),
        );
        assert!(a != region(&bare[0], x0, x1, y0, y1), "no {what}");
        let first = (0..a.len()).find(|&i| a[i] != b[i]);
        assert!(
            first.is_none(),
            "the {what} differs between frames at {:?}",
            first.map(|i| (x0 + i % (x1 - x0), y0 + i / (x1 - x0), a[i], b[i]))
        );
    }
}

/// An 8³ NRRD ball, its world named by `space` (or not), in `dir`.
fn nrrd(dir: &Path, name: &str, space: Option<&str>) -> String {
    let mut header = String::from("NRRD0004\ntype: float\ndimension: 3\nsizes: 8 8 8\n");
    match space {
        Some(space) => header.push_str(&format!(
            "space: {space}\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\n"
        )),
        None => header.push_str("spacings: 1 1 1\n"),
    }
    header.push_str("encoding: raw\nendian: little\n\n");
    let mut bytes = header.into_bytes();
    for k in 0..8 {
        for j in 0..8 {
            for i in 0..8 {
                let r = ((i as f32 - 3.5).powi(2)
                    + (j as f32 - 3.5).powi(2)
                    + (k as f32 - 3.5).powi(2))
                .sqrt();
                bytes.extend_from_slice(&(1.0 - r / 4.0).max(0.0).to_le_bytes());
            }
        }
    }
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn the_axes_are_named_as_the_files_world_is() {
    let dir = tempfile::tempdir().unwrap();
    let draw = |input: &str, out: &str, axes: bool| {
        let out = dir.path().join(out);
        let mut args = vec![
            "render",
            input,
            "--size",
            "240",
            "--azimuth",
            "30",
            "--elevation",
            "20",
            "-o",
            out.to_str().unwrap(),
        ];
        if axes {
            args.push("--axes");
        }
        let run = volray(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        Picture::read(&out)
    };
    let ras = nrrd(dir.path(), "ras.nrrd", Some("right-anterior-superior"));
    let lps = nrrd(dir.path(), "lps.nrrd", Some("LPS"));
    let plain = nrrd(dir.path(), "plain.nrrd", None);
    let bare = draw(&plain, "bare.png", false);
    assert_eq!(
        draw(&ras, "ras_bare.png", false).rgb,
        bare.rgb,
        "the same volume"
    );
    let xyz = draw(&plain, "xyz.png", true);
    let named = draw(&ras, "ras.png", true);
    let other = draw(&lps, "lps.png", true);
    // The same lines, other names: they differ only in the triad's corner.
    for (a, b) in [(&xyz, &named), (&named, &other)] {
        let mut differ = 0;
        for y in 0..240 {
            for x in 0..240 {
                if a.at(x, y) != b.at(x, y) {
                    assert!(x > 160 && y > 160, "({x}, {y})");
                    differ += 1;
                }
            }
        }
        assert!(differ > 10, "{differ}");
    }
}
