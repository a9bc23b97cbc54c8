//! The rendering options of `volray render` (blend modes, isovalue
//! contours, log scale, gradient opacity, post-classification, jitter, the
//! camera, clipping and cropping), each through the binary on a tiny
//! volume whose picture is known, and the one-line refusals of bad values.

use std::fs;
use std::path::Path;

mod common;
use common::{Picture, stderr, volray};

impl Picture {
    fn lit(&self, col: usize, row: usize) -> bool {
        self.at(col, row).iter().any(|&c| c > 8)
    }

    /// How many pixels in columns `cols` are lit.
    fn lit_count(&self, cols: std::ops::Range<usize>) -> usize {
        (0..self.height)
            .flat_map(|r| cols.clone().map(move |c| (c, r)))
            .filter(|&(c, r)| self.lit(c, r))
            .count()
    }

    /// The sum of every pixel's channels.
    fn brightness(&self) -> u64 {
        self.rgb.iter().flatten().map(|&c| c as u64).sum()
    }

    /// Whether no channel of any pixel is brighter than in `other`.
    fn nowhere_brighter_than(&self, other: &Picture) -> bool {
        (self.rgb.iter().zip(&other.rgb)).all(|(a, b)| (0..3).all(|c| a[c] <= b[c]))
    }

    /// The largest difference of a channel from `other`'s, in levels.
    fn worst_difference(&self, other: &Picture) -> u8 {
        (self.rgb.iter().zip(&other.rgb))
            .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
            .max()
            .unwrap()
    }
}

/// `render fractal:17` with `flags`, which must be refused: its message,
/// no output written.
fn refused(dir: &Path, flags: &[&str]) -> String {
    let out = dir.join("refused.png");
    let mut args = vec!["render", "fractal:17"];
    args.extend_from_slice(flags);
    args.extend_from_slice(&["-o", out.to_str().unwrap()]);
    let run = volray(&args);
    assert!(!run.status.success(), "{flags:?}");
    assert!(!out.exists());
    stderr(&run)
}

/// Renders with `args` to a PNG in `dir` and reads it back.
fn render(dir: &Path, args: &[&str]) -> Picture {
    let out = dir.join("out.png");
    let _ = fs::remove_file(&out);
    let mut all = vec!["render"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", out.to_str().unwrap()]);
    let run = volray(&all);
    assert!(run.status.success(), "{args:?}: {}", stderr(&run));
    Picture::read(&out)
}

/// A raw little-endian f32 volume of `dims` (x fastest) with values
/// `f(i, j, k)`; returns its path and the `--dims` flags that read it
/// (spacing 1, origin 0: world coordinates are voxel indices).
fn raw_volume(
    dir: &Path,
    name: &str,
    dims: [usize; 3],
    f: impl Fn(usize, usize, usize) -> f32,
) -> Vec<String> {
    let mut bytes = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                bytes.extend_from_slice(&f(i, j, k).to_le_bytes());
            }
        }
    }
    let path = dir.join(name);
    fs::write(&path, bytes).unwrap();
    vec![
        path.to_str().unwrap().to_string(),
        "--dims".into(),
        format!("{},{},{}", dims[0], dims[1], dims[2]),
    ]
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// The 8-bit level a value in [0, 1] is written as.
fn level(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

// The default view looks along −x from +x: screen right is +y, screen up
// +z. A volume of 7×9×9 voxels at spacing 1 shows its 8×8 y–z face; at
// 16×16 pixels, pixel (c, r) is the ray at y = 0.25 + c/2, z = 8 − (0.25 +
// r/2), whose samples lie on the x grid planes (the image plane passes
// through x = 3, a grid plane, and the step is one voxel).

/// Values along x of the separable test volume `f = a(y, z)·b(x)`, with
/// `a = (y + z)/16` (trilinear interpolation reproduces it exactly).
const B: [f32; 7] = [0.5, 0.6, 0.2, 0.7, 0.4, 1.0, 0.5];

fn separable(dir: &Path) -> Vec<String> {
    raw_volume(dir, "sep.raw", [7, 9, 9], |i, j, k| {
        (j + k) as f32 / 16.0 * B[i]
    })
}

/// `a` at the centre of pixel (c, r).
fn a_at(c: usize, r: usize) -> f64 {
    let y = 0.25 + c as f64 / 2.0;
    let z = 8.0 - (0.25 + r as f64 / 2.0);
    (y + z) / 16.0
}

#[test]
fn projections_are_the_per_ray_maximum_minimum_and_mean() {
    let dir = tempfile::tempdir().unwrap();
    let vol = separable(dir.path());
    let mean = B.iter().map(|&b| b as f64).sum::<f64>() / B.len() as f64;
    for (blend, factor) in [
        ("mip", 1.0),
        ("maximum", 1.0),
        ("minip", 0.2),
        ("average", mean),
    ] {
        let mut args = strs(&vol);
        args.extend(["--size", "16", "--range", "0,1", "--blend", blend]);
        let pic = render(dir.path(), &args);
        for r in 0..16 {
            for c in 0..16 {
                let want = level(factor * a_at(c, r));
                let got = pic.at(c, r);
                assert!(
                    got.iter().all(|&g| g.abs_diff(want) <= 1),
                    "--blend {blend}: pixel ({c}, {r}) is {got:?}, the ray's value is {want}"
                );
            }
        }
    }
    // A colour map colours the projected value; grey is the identity.
    let mut args = strs(&vol);
    args.extend(["--size", "16", "--range", "0,1", "--blend", "mip"]);
    let grey = render(dir.path(), &args);
    args.extend(["--colormap", "grey"]);
    assert_eq!(render(dir.path(), &args), grey);
}

#[test]
fn log_scale_turns_decades_into_a_linear_ramp() {
    // f = 10^(−4 + j/2): four decades along y, constant along x and z.
    let dir = tempfile::tempdir().unwrap();
    let value = |j: usize| 10f32.powf(-4.0 + j as f32 / 2.0);
    let vol = raw_volume(dir.path(), "decades.raw", [5, 9, 9], |_, j, _| value(j));
    let base = {
        let mut a = strs(&vol);
        a.extend(["--size", "16", "--blend", "mip"]);
        a
    };
    // --log with the window in the data's units: t = (log10 f + 4)/4, and
    // log10 f is linear in y, so the picture is a linear ramp: y/8.
    let mut args = base.clone();
    args.extend(["--log", "--range", "1e-4,1"]);
    let log = render(dir.path(), &args);
    // Without --log the same window shows f itself, interpolated linearly
    // between the voxels: nearly black but for the last decade.
    let mut args = base.clone();
    args.extend(["--range", "0,1"]);
    let linear = render(dir.path(), &args);
    for c in 0..16 {
        let y = 0.25 + c as f64 / 2.0;
        let (j, frac) = (y.floor() as usize, y.fract());
        let f = value(j) as f64 * (1.0 - frac) + value(j + 1) as f64 * frac;
        for r in [0, 7, 15] {
            assert!(
                log.at(c, r)[0].abs_diff(level(y / 8.0)) <= 1,
                "log: column {c}: {:?} for y = {y}",
                log.at(c, r)
            );
            assert!(
                linear.at(c, r)[0].abs_diff(level(f)) <= 1,
                "linear: column {c}: {:?} for f = {f}",
                linear.at(c, r)
            );
        }
    }
    // The window in log units would be a different picture: --range is
    // in the data's units. A window that is not positive is refused.
    let mut args = base.clone();
    args.extend(["--log", "--range", "0,1", "-o"]);
    let out = dir.path().join("refused.png");
    args.push(out.to_str().unwrap());
    let mut all = vec!["render"];
    all.extend(args);
    let run = volray(&all);
    assert_eq!(run.status.code(), Some(1));
    assert!(stderr(&run).contains("--range") && stderr(&run).contains("--log"));
    assert!(!out.exists());
}

/// A ball of density 1 − r/16 on a 33³ grid (r in voxels from the centre).
fn ball(dir: &Path) -> Vec<String> {
    raw_volume(dir, "ball.raw", [33, 33, 33], |i, j, k| {
        let d = |n: usize| n as f32 - 16.0;
        (1.0 - (d(i) * d(i) + d(j) * d(j) + d(k) * d(k)).sqrt() / 16.0).max(0.0)
    })
}

#[test]
fn iso_contour_draws_a_shell() {
    // At 64 pixels over 32 voxels, column 32 + 2b is the ray passing b
    // voxels from the centre (in the central row).
    let dir = tempfile::tempdir().unwrap();
    let vol = ball(dir.path());
    let mut args = strs(&vol);
    args.extend(["--size", "64", "--no-shading"]);
    let plain = render(dir.path(), &args);
    // --iso 0.5: the shell r = 8 ± 1 voxel (|∇f| = 1/16 per voxel, so
    // |f − 0.5| <= 1·|∇f| there); rays through the inside cross it twice,
    // rays grazing it run along it, rays outside miss it.
    // A translucent shell (α_v = q = 0.2), so that the rim's long path
    // through it shows against the centre's two crossings.
    args.extend(["--iso", "0.5", "--iso-thickness", "1", "--opacity", "0,0.2"]);
    let iso = render(dir.path(), &args);
    let row = 32;
    let grey = |p: &Picture, b: usize| p.at(32 + 2 * b, row)[0];
    let ring = (13..=16).map(|b2| iso.at(32 + b2, row)[0]).max().unwrap();
    assert!(
        ring as f64 > 1.3 * grey(&iso, 0) as f64,
        "the shell's rim ({ring}) must be brighter than its centre ({})",
        grey(&iso, 0)
    );
    assert!(grey(&iso, 0) > 20, "the centre ray crosses the shell twice");
    for b in 10..16 {
        assert_eq!(grey(&iso, b), 0, "b = {b}: outside the shell is empty");
        assert!(grey(&plain, b) > 0, "b = {b}: the ball without --iso");
    }
    // Without --iso the ball is densest through its centre.
    assert!(grey(&plain, 0) > (13..=16).map(|b2| plain.at(32 + b2, row)[0]).max().unwrap());
    // --blend iso is the same as --iso alone.
    args.extend(["--blend", "iso"]);
    assert_eq!(render(dir.path(), &args), iso);
}

#[test]
fn gradient_opacity_hides_uniform_regions() {
    // A ramp along y for y <= 4 (|∇f| the largest there), then a plateau
    // of 1 (|∇f| = 0 from y = 5 on).
    let dir = tempfile::tempdir().unwrap();
    let vol = raw_volume(dir.path(), "plateau.raw", [7, 9, 9], |_, j, _| {
        (j as f32 / 4.0).min(1.0)
    });
    let mut args = strs(&vol);
    // The paper's ramp: opacity wherever the value is above 0 (the colours
    // chosen from the data, the same in both renders).
    args.extend(["--size", "16", "--opacity", "0,0.5"]);
    let plain = render(dir.path(), &args);
    args.extend(["--gradient-opacity", "0.5,1"]);
    let graded = render(dir.path(), &args);
    for r in 2..14 {
        // Ramp rays (y from 1.25 to 2.75): the factor is 1, nothing changes.
        for c in 2..=5 {
            assert!(plain.lit(c, r));
            assert!(graded.at(c, r)[0].abs_diff(plain.at(c, r)[0]) <= 1);
        }
        // Plateau rays (y from 5.75 on): no gradient, no opacity.
        for c in 11..16 {
            assert!(plain.lit(c, r), "({c}, {r})");
            assert_eq!(graded.at(c, r), [0, 0, 0], "({c}, {r})");
        }
    }
}

#[test]
fn post_classification_and_jitter_change_the_samples_not_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let vol = ball(dir.path());
    let mut args = strs(&vol);
    args.extend(["--size", "48"]);
    let pre = render(dir.path(), &args);
    let mean = |p: &Picture| p.rgb.iter().map(|c| c[0] as f64).sum::<f64>() / p.rgb.len() as f64;

    // Post-classification interpolates the scalar and classifies each
    // sample: a different, close picture (the ball is smooth).
    let out = dir.path().join("post.png");
    let mut post_args = vec!["render"];
    post_args.extend(args.iter().copied());
    post_args.extend(["--post-classification", "-o", out.to_str().unwrap()]);
    let run = volray(&post_args);
    assert!(run.status.success(), "{}", stderr(&run));
    let post = Picture::read(&out);
    assert_ne!(post, pre);
    assert!((mean(&post) - mean(&pre)).abs() < 0.05 * mean(&pre));

    // Jitter moves each pixel's samples by its own fraction of a step:
    // the same every run, different from the unjittered picture, with
    // the same overall brightness.
    args.push("--jitter");
    let jittered = render(dir.path(), &args);
    assert_eq!(render(dir.path(), &args), jittered);
    assert_ne!(jittered, pre);
    assert!((mean(&jittered) - mean(&pre)).abs() < 0.02 * mean(&pre));
}

#[test]
fn crop_removes_half_a_sphere_and_clip_planes_cut_alike() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["sphere:24", "--size", "32"];
    let plain = render(dir.path(), &base);
    let with = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        render(dir.path(), &a)
    };
    // Keep y >= 0: the left half of the picture (screen right is +y).
    let cropped = with(&["--crop", "-1,1,0,1,-1,1"]);
    assert!(plain.lit_count(0..16) > 100);
    assert_eq!(cropped.lit_count(0..16), 0);
    for r in 0..32 {
        for c in 16..32 {
            assert_eq!(cropped.at(c, r), plain.at(c, r), "({c}, {r})");
        }
    }
    // The plane y = 0 keeping +y cuts the same, and a second plane z <= 0.2
    // (normal −z) cuts as the box's top face does.
    assert_eq!(with(&["--clip", "0,0,0,0,1,0"]), cropped);
    assert_eq!(
        with(&["--clip", "0,0,0,0,1,0", "--clip", "0,0,0.2,0,0,-1"]),
        with(&["--crop", "-1,1,0,1,-1,0.2"])
    );
    // Seen obliquely, where the planes cut the rays at an angle.
    let oblique = ["--view", "3,2,1.5"];
    let clip = with(&[&oblique[..], &["--clip", "0,0,-0.3,0,0,1"]].concat());
    let crop = with(&[&oblique[..], &["--crop", "-1,1,-1,1,-0.3,1"]].concat());
    assert!(clip.max_diff(&crop) <= 1);
    assert!(clip.max_diff(&with(&oblique)) > 30, "the plane must cut");
}

/// Two balls of radius 4 voxels on a 33³ grid, one on the eye's side
/// (x = 26) on the left of the picture (y = 10), one far (x = 6) on the
/// right (y = 22).
fn near_and_far(dir: &Path) -> Vec<String> {
    raw_volume(dir, "two.raw", [33, 33, 33], |i, j, k| {
        let ball = |cx: f32, cy: f32| {
            let (x, y, z) = (i as f32 - cx, j as f32 - cy, k as f32 - 16.0);
            (4.5 - (x * x + y * y + z * z).sqrt()).clamp(0.0, 1.0)
        };
        ball(26.0, 10.0) + ball(6.0, 22.0)
    })
}

#[test]
fn perspective_enlarges_near_features() {
    let dir = tempfile::tempdir().unwrap();
    let vol = near_and_far(dir.path());
    let mut args = strs(&vol);
    args.extend(["--size", "96"]);
    let ortho = render(dir.path(), &args);
    let (near, far) = (ortho.lit_count(0..48), ortho.lit_count(48..96));
    assert!(
        near > 50 && (near as f64 / far as f64 - 1.0).abs() < 0.1,
        "orthographic: {near} and {far} pixels"
    );
    // 60°: the eye stands 2R from the centre (R = 16√3 voxels, the
    // bounding sphere), so the balls are 2R ∓ 10 away: the near one looks
    // (2R + 10)/(2R − 10) ≈ 1.44 times as wide, ≈ 2.1 times the area.
    let out = dir.path().join("p.png");
    let mut all = vec!["render"];
    all.extend(args.iter().copied());
    all.extend(["--perspective", "60", "-o", out.to_str().unwrap()]);
    let run = volray(&all);
    assert!(run.status.success(), "{}", stderr(&run));
    let persp = Picture::read(&out);
    let (near, far) = (persp.lit_count(0..48), persp.lit_count(48..96));
    let ratio = near as f64 / far as f64;
    assert!(
        (1.7..2.6).contains(&ratio),
        "perspective: {near} and {far} pixels"
    );
}

/// Lit pixels along row `row`: (first, last) column.
fn lit_span(p: &Picture, row: usize) -> (usize, usize) {
    let cols: Vec<usize> = (0..p.width).filter(|&c| p.lit(c, row)).collect();
    (cols[0], *cols.last().unwrap())
}

#[test]
fn zoom_two_doubles_the_size_in_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["sphere:24,radius=0.3", "--size", "64"];
    let one = render(dir.path(), &base);
    let two = render(dir.path(), &[&base[..], &["--zoom", "2"]].concat());
    let (a0, a1) = lit_span(&one, 32);
    let (b0, b1) = lit_span(&two, 32);
    let (w1, w2) = ((a1 - a0 + 1) as i64, (b1 - b0 + 1) as i64);
    assert!(w1 >= 12, "the ball spans {w1} pixels");
    assert!((w2 - 2 * w1).abs() <= 2, "zoom 2: {w2} pixels against {w1}");
    // About the image centre.
    assert!((a0 + a1).abs_diff(b0 + b1) <= 1);
}

#[test]
fn azimuth_and_elevation_orbit_as_vtk_does() {
    // blobs is not symmetric: each side looks different.
    let dir = tempfile::tempdir().unwrap();
    let base = ["blobs:24", "--size", "24"];
    let with = |extra: &[&str]| render(dir.path(), &[&base[..], extra].concat());
    let front = with(&[]);
    // Azimuth 90 takes the eye from +x to +y (the reference is the
    // centre, 0).
    let turned = with(&["--azimuth", "90"]);
    assert!(turned.max_diff(&front) > 30);
    assert!(turned.max_diff(&with(&["--view", "0,5,0"])) <= 1);
    // Elevation 90 raises it to +z, the up vector tilting with it to −x.
    let above = with(&["--elevation", "90"]);
    assert!(above.max_diff(&with(&["--view", "0,0,5", "--up", "-1,0,0"])) <= 1);
    assert!(above.max_diff(&front) > 30);
    // Negative angles go the other way: −90 views from −y.
    assert!(with(&["--azimuth", "-90"]).max_diff(&with(&["--view", "0,-5,0"])) <= 1);
}

#[test]
fn bad_values_are_refused_in_one_line_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.png");
    for (args, flag) in [
        (&["--perspective", "0"][..], "--perspective"),
        (&["--perspective", "180"], "--perspective"),
        (&["--zoom", "-1"], "--zoom"),
        (&["--zoom", "0"], "--zoom"),
        (&["--azimuth", "nan"], "--azimuth"),
        (&["--crop", "1,-1,-1,1,-1,1"], "--crop"),
        (&["--crop", "-1,1,-1,1,-1"], "--crop"),
        (&["--clip", "0,0,0,0,0,0"], "--clip"),
        (&["--clip", "0,0,0,1,0"], "--clip"),
        (&["--iso", "0.5", "--iso-thickness", "0"], "--iso-thickness"),
        (&["--iso-thickness", "2"], "--iso-thickness"),
        (&["--blend", "iso"], "--blend iso"),
        (&["--blend", "sum"], "--blend"),
        (&["--blend", "mip", "--iso", "0.5"], "--iso"),
        (
            &["--blend", "minip", "--gradient-opacity", "0,1"],
            "--gradient-opacity",
        ),
        (
            &["--blend", "average", "--post-classification"],
            "--post-classification",
        ),
        (&["--gradient-opacity", "0.5,0.2"], "--gradient-opacity"),
        (&["--gradient-opacity", "0,2"], "--gradient-opacity"),
        (&["--log", "--iso", "-1"], "--iso"),
        (&["--log", "--preset", "ct-bone"], "--preset"),
    ] {
        let mut all = vec!["render", "sphere:16", "--size", "8"];
        all.extend_from_slice(args);
        all.extend(["-o", out.to_str().unwrap()]);
        let run = volray(&all);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote an output");
    }
    // --log on data with no positive value names the flag and the input.
    let vol = raw_volume(dir.path(), "neg.raw", [3, 3, 3], |_, _, _| -1.0);
    let mut all = vec!["render"];
    all.extend(strs(&vol));
    all.extend(["--log", "-o", out.to_str().unwrap()]);
    let run = volray(&all);
    assert_eq!(run.status.code(), Some(1));
    assert!(stderr(&run).contains("--log") && stderr(&run).contains("neg.raw"));
    assert!(!out.exists());
}

/// A ball of 1 (radius 6) in a haze of 0.1 with a little noise (falling
/// counts: 0.1, 0.104, 0.108, 0.112 in 8:4:2:1), and one voxel of 0 in a
/// corner: a CT-like histogram, one tall peak low in the range 0..1.
fn ball_in_haze(dir: &Path) -> Vec<String> {
    raw_volume(dir, "haze.raw", [21, 21, 21], |i, j, k| {
        let d = |n: usize| n as f32 - 10.0;
        let level = match (i * 7 + j * 13 + k * 31) % 15 {
            0..=7 => 0.0,
            8..=11 => 1.0,
            12..=13 => 2.0,
            _ => 3.0,
        };
        if (i, j, k) == (0, 0, 0) {
            0.0
        } else if (d(i) * d(i) + d(j) * d(j) + d(k) * d(k)).sqrt() <= 6.0 {
            1.0
        } else {
            0.1 + 0.004 * level
        }
    })
}

#[test]
fn with_no_transfer_function_the_background_peak_is_transparent_and_the_rest_in_viridis() {
    let dir = tempfile::tempdir().unwrap();
    let vol = ball_in_haze(dir.path());
    let mut args = strs(&vol);
    args.extend(["--size", "40"]);
    let chosen = render(dir.path(), &args);
    // The default is `--tf auto`.
    let explicit = render(dir.path(), &[&args[..], &["--tf", "auto"]].concat());
    assert_eq!(chosen.at(0, 0), explicit.at(0, 0));
    assert!((0..40).all(|r| (0..40).all(|c| chosen.at(c, r) == explicit.at(c, r))));
    // The haze around the ball is cut: the corners are the background.
    for (c, r) in [(0, 0), (39, 0), (0, 39), (39, 39), (20, 1)] {
        assert_eq!(chosen.at(c, r), [0, 0, 0], "({c}, {r})");
    }
    // The ball, at the top of the range, in viridis' yellow: red and
    // green above blue.
    let [r, g, b] = chosen.at(20, 20);
    assert!(r > b && g > b && g > 40, "{r} {g} {b}");

    // --opacity keeps the paper's ramp: the haze (t ≈ 0.1) gets opacity
    // 0.05 per voxel and shows around the ball.
    let ramp = render(dir.path(), &[&args[..], &["--opacity", "0,0.5"]].concat());
    assert!(ramp.lit(20, 1), "{:?}", ramp.at(20, 1));
    // So does a named colour map alone (no transfer function is chosen).
    let magma = render(dir.path(), &[&args[..], &["--colormap", "magma"]].concat());
    assert_ne!(magma.at(20, 1), [0, 0, 0]);
    // A projection keeps its grey (no transfer function is chosen).
    let mip = render(dir.path(), &[&args[..], &["--blend", "mip"]].concat());
    let [r, g, b] = mip.at(20, 20);
    assert!(r == g && g == b && r > 200, "{r} {g} {b}");
}

#[test]
fn tf_auto_conflicts_with_a_preset() {
    let run = volray(&[
        "render",
        "blobs:16",
        "--tf",
        "auto",
        "--preset",
        "mr",
        "-o",
        "/tmp/x.png",
    ]);
    assert_eq!(run.status.code(), Some(1));
    let err = stderr(&run);
    assert!(err.contains("--preset conflicts with --tf"), "{err}");
}

#[test]
fn shadows_darken_what_the_light_cannot_reach_and_are_refused_where_nothing_is_lit() {
    // The fractal cloud lit from above and the side: with --shadows the
    // far side of the cloud from the light darkens, the near side keeps
    // its light, and the reference path agrees within two levels.
    let dir = tempfile::tempdir().unwrap();
    let base = ["fractal:33", "--size", "64x64", "--light", "1,0,1"];
    let plain = render(dir.path(), &base);
    let with = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        render(dir.path(), &args)
    };
    let shadowed = with(&["--shadows"]);
    let reference = with(&["--shadows", "--reference"]);
    assert!(
        shadowed.brightness() * 10 < plain.brightness() * 9,
        "shadows darken the picture: {} vs {}",
        shadowed.brightness(),
        plain.brightness()
    );
    assert!(shadowed.nowhere_brighter_than(&plain));
    let worst = shadowed.worst_difference(&reference);
    assert!(worst <= 2, "fast vs reference with shadows: {worst} levels");
    for flags in [
        &["--shadows", "--blend", "mip"][..],
        &["--shadows", "--no-shading"][..],
    ] {
        let err = refused(dir.path(), flags);
        assert!(err.contains("--shadows"), "{err}");
    }
}

#[test]
fn ambient_occlusion_darkens_the_ambient_light_in_creases_and_is_refused_where_nothing_is_composited()
 {
    // Unlit, the colour is the ambient light's: every pixel darkens or
    // stays, the reference path agrees within a level, and a longer
    // radius reaches more of the cloud around each point.
    let dir = tempfile::tempdir().unwrap();
    let base = ["fractal:33", "--size", "64x64", "--no-shading"];
    let with = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        render(dir.path(), &args)
    };
    let plain = with(&[]);
    let occluded = with(&["--ambient-occlusion", "4"]);
    let reference = with(&["--ambient-occlusion", "4", "--reference"]);
    let wider = with(&["--ambient-occlusion"]);
    assert!(occluded.brightness() * 10 < plain.brightness() * 9);
    assert!(wider.brightness() < occluded.brightness());
    assert!(
        occluded.nowhere_brighter_than(&plain),
        "ambient occlusion only takes light away"
    );
    let worst = occluded.worst_difference(&reference);
    assert!(worst <= 1, "fast vs reference: {worst} levels");
    for (flags, why) in [
        (&["--ambient-occlusion", "--blend", "mip"][..], "unshaded"),
        (&["--ambient-occlusion", "40"][..], "1 to 32 voxels"),
    ] {
        let err = refused(dir.path(), flags);
        assert!(
            err.contains("--ambient-occlusion") && err.contains(why),
            "{err}"
        );
    }
}
