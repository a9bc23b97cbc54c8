//! `--nonfinite refuse|transparent` through the binary: a volume with NaN
//! or infinite values is refused by default (exit 1, one line naming the
//! file and the count, and the way out), and with `transparent` rendered
//! as the same data without those voxels would be.

mod common;

use common::{Picture, stderr, volray};
use std::path::Path;

/// 17 points along each axis: a ball of values 1 − r²/64 about the
/// centre, 0 outside it; then `hole(i, j, k)` sets some voxels.
fn ball(hole: impl Fn(usize, usize, usize) -> Option<f32>) -> Vec<f32> {
    let n = 17;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let r2 = [i, j, k]
                    .iter()
                    .map(|&c| (c as f32 - 8.0).powi(2))
                    .sum::<f32>();
                let value = (1.0 - r2 / 64.0).max(0.0);
                data.push(hole(i, j, k).unwrap_or(value));
            }
        }
    }
    data
}

/// Writes `data` as a raw little-endian f32 file.
fn write_raw(path: &Path, data: &[f32]) {
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(path, bytes).unwrap();
}

const RAW: [&str; 4] = ["--dims", "17,17,17", "--dtype", "f32"];

/// `volray render FILE` (a raw 17³ f32 file) with `extra` to `out`.
fn render(file: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["render", file.to_str().unwrap()];
    args.extend(RAW);
    args.extend([
        "--size",
        "40",
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    args.extend(extra);
    volray(&args)
}

/// NaN, +∞ and −∞ in turn over the planes x ≥ 11.
fn non_finite_beyond_x_10(i: usize, j: usize, k: usize) -> Option<f32> {
    (i >= 11).then(|| [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][(i + j + k) % 3])
}

#[test]
fn non_finite_values_are_refused_unless_rendered_transparent() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("holes.raw");
    write_raw(&file, &ball(non_finite_beyond_x_10));
    let out = dir.path().join("out.png");
    // 6 planes of 17² voxels: 1734 of 4913.
    for extra in [&[][..], &["--nonfinite", "refuse"][..]] {
        let run = render(&file, &out, extra);
        assert_eq!(run.status.code(), Some(1), "{extra:?}");
        let err = stderr(&run);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("holes.raw"), "{err}");
        assert!(err.contains("1734 of 4913 values are not finite"), "{err}");
        assert!(
            err.contains("use --nonfinite transparent to render them as empty space"),
            "{err}"
        );
        assert!(!out.exists(), "nothing is written when refused");
    }
    let run = render(&file, &out, &["--nonfinite", "transparent"]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let picture = Picture::read(&out);
    assert_eq!((picture.width, picture.height), (40, 40));
    assert!(picture.rgb.iter().any(|p| p[0] > 50), "the ball shows");
}

#[test]
fn transparent_non_finite_voxels_render_as_empty_space() {
    // Composited (the default ramp, transparent at the bottom of the
    // window): NaN and ±∞ render as the volume's smallest value, 0, does.
    // Seen from +x through them, the ball's far half shows as if the
    // non-finite planes held zeros.
    let dir = tempfile::tempdir().unwrap();
    let (holes, zeros) = (dir.path().join("holes.raw"), dir.path().join("zeros.raw"));
    write_raw(&holes, &ball(non_finite_beyond_x_10));
    write_raw(
        &zeros,
        &ball(|i, j, k| non_finite_beyond_x_10(i, j, k).map(|_| 0.0)),
    );
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let run = render(&holes, &a, &["--nonfinite", "transparent"]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let run = render(&zeros, &b, &[]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let (a, b) = (Picture::read(&a), Picture::read(&b));
    assert_eq!(a.max_diff(&b), 0);
    assert!(a.rgb.iter().any(|p| p[0] > 50));

    // Maximum intensity with +∞ in the planes x ≥ 11: the picture of the
    // same data cut at x = 10 by --crop, whatever the +∞ voxels are
    // replaced by there (here 5, far above the ball's values: a sample
    // that weighed them would show white).
    let infinite = dir.path().join("inf.raw");
    write_raw(
        &infinite,
        &ball(|i, _, _| (i >= 11).then_some(f32::INFINITY)),
    );
    let bright = dir.path().join("bright.raw");
    write_raw(&bright, &ball(|i, _, _| (i >= 11).then_some(5.0)));
    let mip = ["--blend", "mip", "--range", "0,1", "--view", "40,-30,25"];
    let (c, d, e) = (
        dir.path().join("c.png"),
        dir.path().join("d.png"),
        dir.path().join("e.png"),
    );
    let mut transparent = mip.to_vec();
    transparent.extend(["--nonfinite", "transparent"]);
    let run = render(&infinite, &c, &transparent);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let mut cropped = mip.to_vec();
    cropped.extend(["--crop", "-1,10,-1,17,-1,17"]);
    let run = render(&bright, &d, &cropped);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let (c, d) = (Picture::read(&c), Picture::read(&d));
    assert_eq!(c.max_diff(&d), 0);
    // Uncropped, the bright planes show: the comparison means something.
    let run = render(&bright, &e, &mip);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    assert!(Picture::read(&e).max_diff(&c) > 100);
}

#[test]
fn bench_takes_the_flag_too() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("holes.raw");
    write_raw(&file, &ball(non_finite_beyond_x_10));
    let bench = |extra: &[&str]| {
        let mut args = vec!["bench", file.to_str().unwrap()];
        args.extend(RAW);
        args.extend(["--size", "24", "--frames", "2", "--threads", "1"]);
        args.extend(extra);
        volray(&args)
    };
    let run = bench(&[]);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains("1734 of 4913 values are not finite")
            && stderr(&run).contains("--nonfinite transparent"),
        "{}",
        stderr(&run)
    );
    let run = bench(&["--nonfinite", "transparent"]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
}

#[test]
fn an_unknown_mode_is_refused_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("holes.raw");
    write_raw(&file, &ball(non_finite_beyond_x_10));
    let out = dir.path().join("out.png");
    let run = render(&file, &out, &["--nonfinite", "bogus"]);
    assert_eq!(run.status.code(), Some(1));
    let err = stderr(&run);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--nonfinite") && err.contains("bogus"),
        "{err}"
    );
    assert!(!out.exists());
}
