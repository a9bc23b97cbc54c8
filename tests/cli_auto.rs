//! `volray render` with no options (`--tf auto`) of data that used to
//! render nearly blank: a raster whose range a few hot pixels set (the
//! histogram refined to the values' window, in memory and piece by piece
//! alike), and a density spanning decades (the log window, said on
//! stderr; `--linear` and `--range` keep the values).
//!
//! The files are written here: `.npy` volumes (volray-io's writer) and an
//! OME-Zarr 0.5 image of `float32` chunks written by hand, as
//! `cli_streamed.rs` does, so these tests need no Python.

mod common;

use common::{Picture, render};
use serde_json::json;
use std::fs;
use std::path::Path;

/// The raster's grid, (x, y, z): thin along x, the default view's axis,
/// so that its footprint is the whole y–z rectangle.
const RASTER: [usize; 3] = [4, 48, 40];

/// The raster's values: 10..=100, spread evenly (a sky's, a sample's).
fn raster_value(x: usize, y: usize, z: usize) -> f32 {
    10.0 + 90.0 * ((x * 31 + y * 7 + z * 13) % 97) as f32 / 96.0
}

/// The voxels of `dims` (x fastest) at `value`, with `hot` at the first
/// `n` of `[(1, 5, 7), (2, 30, 20), (0, 40, 33)]`.
fn with_hot_pixels(
    dims: [usize; 3],
    value: &dyn Fn(usize, usize, usize) -> f32,
    hot: f32,
    n: usize,
) -> Vec<f32> {
    let hot_at = [(1, 5, 7), (2, 30, 20), (0, 40, 33)];
    let mut data = Vec::with_capacity(dims.iter().product());
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let is_hot = hot_at[..n].contains(&(x, y, z));
                data.push(if is_hot { hot } else { value(x, y, z) });
            }
        }
    }
    data
}

fn npy(dir: &Path, name: &str, dims: [usize; 3], data: Vec<f32>) -> String {
    let volume = volray_core::Volume::new(dims, data).unwrap();
    let path = dir.join(name);
    volray_io::write_npy(&path, &volume).unwrap();
    path.to_str().unwrap().to_string()
}

/// The pixels of `picture` that differ from its corner's (the background)
/// by more than 8 in some channel.
fn coloured(picture: &Picture) -> Vec<bool> {
    let background = picture.rgb[0];
    (picture.rgb.iter())
        .map(|p| (0..3).any(|c| p[c].abs_diff(background[c]) > 8))
        .collect()
}

#[test]
fn a_raster_with_a_few_hot_pixels_renders_its_values_with_no_options() {
    let dir = tempfile::tempdir().unwrap();
    let size = ["--size", "96x80"];
    // The footprint: every ray through the raster, as its maximum
    // (values of 10 and more, all coloured) shows it.
    let clean = npy(
        dir.path(),
        "clean.npy",
        RASTER,
        with_hot_pixels(RASTER, &raster_value, 0.0, 0),
    );
    let footprint_png = dir.path().join("footprint.png");
    render(
        &[
            &[clean.as_str(), "--blend", "mip", "--colormap", "viridis"],
            &size[..],
        ]
        .concat(),
        &footprint_png,
    );
    let footprint = coloured(&Picture::read(&footprint_png));
    let area = footprint.iter().filter(|c| **c).count();
    // The y–z rectangle, 48 × 40 voxels, framed in 96 × 80 pixels: most
    // of the picture.
    assert!(area > 96 * 80 / 2, "{area}");
    for hot in [1e6f32, 1e30] {
        let file = npy(
            dir.path(),
            "hot.npy",
            RASTER,
            with_hot_pixels(RASTER, &raster_value, hot, 3),
        );
        let out = dir.path().join("hot.png");
        let said = render(&[&[file.as_str()], &size[..]].concat(), &out);
        assert!(!said.contains("decades"), "{said}");
        let shown = coloured(&Picture::read(&out));
        let covered = (footprint.iter().zip(&shown))
            .filter(|(f, s)| **f && **s)
            .count();
        // Most of the footprint: the values 10..100 span the ramp (over a
        // window of 0..3.9e27 they would all be transparent). The rays
        // through only low values (transparent at 10, the ramp's foot)
        // stay dark: 86 % are coloured, as without the hot pixels.
        assert!(
            covered as f64 >= 0.8 * area as f64,
            "{hot}: {covered} of {area}"
        );
    }
}

#[test]
fn hot_pixels_read_piece_by_piece_give_the_picture_read_whole() {
    // 48·40·36 f32 voxels (276 kB): 100 kB holds only pieces of them.
    const DIMS: [usize; 3] = [48, 40, 36];
    let data = with_hot_pixels(DIMS, &raster_value, 1e6, 3);
    let at = |x: usize, y: usize, z: usize| data[x + DIMS[0] * (y + DIMS[1] * z)];
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("hot.ome.zarr");
    let bytes = |x, y, z| at(x, y, z).to_le_bytes();
    common::zarr::write_level(&image.join("0"), DIMS, "float32", json!(0.0), &bytes);
    let meta = json!({
        "zarr_format": 3,
        "node_type": "group",
        "attributes": {"ome": {"version": "0.5", "multiscales": [{
            "axes": [
                {"name": "z", "type": "space"},
                {"name": "y", "type": "space"},
                {"name": "x", "type": "space"},
            ],
            "datasets": [{"path": "0", "coordinateTransformations": [
                {"type": "scale", "scale": [1.0, 1.0, 1.0]}]}],
        }]}},
    });
    fs::write(image.join("zarr.json"), meta.to_string()).unwrap();
    let path = image.to_str().unwrap();
    let (whole, pieces) = (dir.path().join("whole.png"), dir.path().join("pieces.png"));
    let said = render(&[path, "--size", "48x40"], &whole);
    assert!(!said.contains("pieces"), "{said}");
    let said = render(&[path, "--size", "48x40", "--max-memory", "100K"], &pieces);
    assert!(said.contains("in pieces"), "{said}");
    let picture = Picture::read(&whole);
    let shown = coloured(&picture).iter().filter(|c| **c).count();
    assert!(shown > 48 * 40 / 2, "{shown}");
    let diff = Picture::read(&pieces).max_diff(&picture);
    assert!(diff <= 1, "{diff}");
}

#[test]
fn a_density_spanning_decades_is_rendered_as_its_log_unless_linear_or_a_range_is_given() {
    // r⁻³ about the centre of a 32³ grid: 1.5 down to 5e-5, half of the
    // voxels under 2.6e-4, the 99.9 % point near 0.125.
    const N: usize = 32;
    let data = (0..N * N * N)
        .map(|i| {
            let p = [i % N, (i / N) % N, i / (N * N)].map(|c| c as f64 - 15.5);
            (p.iter().map(|c| c * c).sum::<f64>()).powf(-1.5) as f32
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let file = npy(dir.path(), "density.npy", [N; 3], data);
    let out = |name: &str| dir.path().join(name);
    let said = render(&[&file, "--size", "48"], &out("auto.png"));
    assert!(said.contains("the values span decades"), "{said}");
    assert!(said.contains("--linear"), "{said}");
    // What --log renders, to the bit.
    let said = render(&[&file, "--size", "48", "--log"], &out("log.png"));
    assert!(!said.contains("decades"), "{said}");
    let auto = Picture::read(&out("auto.png"));
    assert_eq!(auto.max_diff(&Picture::read(&out("log.png"))), 0);
    // --linear and --range keep the values, and say nothing.
    for (name, extra) in [
        ("linear.png", &["--linear"][..]),
        ("range.png", &["--range", "0,1.5"][..]),
    ] {
        let said = render(
            &[&[file.as_str(), "--size", "48"], extra].concat(),
            &out(name),
        );
        assert!(!said.contains("decades"), "{extra:?}: {said}");
        assert!(Picture::read(&out(name)).max_diff(&auto) > 16, "{extra:?}");
    }
}

#[test]
fn a_series_with_hot_pixels_takes_the_window_of_its_first_volume() {
    let dir = tempfile::tempdir().unwrap();
    let first = npy(
        dir.path(),
        "a.npy",
        RASTER,
        with_hot_pixels(RASTER, &raster_value, 1e6, 3),
    );
    let second = npy(
        dir.path(),
        "b.npy",
        RASTER,
        with_hot_pixels(RASTER, &raster_value, 1e9, 2),
    );
    let size = ["--size", "96x80"];
    // The first alone: the window 10..100.
    let still = dir.path().join("still.png");
    render(&[&[first.as_str()], &size[..]].concat(), &still);
    let pattern = dir.path().join("frame_%03d.png");
    render(
        &[&[first.as_str(), second.as_str()], &size[..]].concat(),
        &pattern,
    );
    let frames = [0, 1].map(|i| Picture::read(&dir.path().join(format!("frame_{i:03}.png"))));
    // The choice made on the first volume's refined histogram, its window
    // the series' (a colour bar's): the first frame is the still, the
    // second as covered.
    let still = Picture::read(&still);
    let still_shown = coloured(&still).iter().filter(|c| **c).count();
    assert!(still_shown > 96 * 80 / 2, "{still_shown}");
    assert_eq!(frames[0].max_diff(&still), 0);
    let shown = coloured(&frames[1]).iter().filter(|c| **c).count();
    assert!(
        shown as f64 > 0.8 * coloured(&still).iter().filter(|c| **c).count() as f64,
        "{shown}"
    );
}

/// `volray view ARGS --port 0 --no-browser` until it prints its URL,
/// then stopped: what it said on stderr.
fn viewer_says(args: &[&str]) -> String {
    use std::io::{BufRead, BufReader, Read};
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(
            [
                &["view"],
                args,
                &["--size", "32", "--port", "0", "--no-browser"],
            ]
            .concat(),
        )
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut url = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut url)
        .unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    let mut said = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut said)
        .unwrap();
    said
}

#[test]
fn the_viewer_of_a_density_spanning_decades_starts_from_its_log() {
    const N: usize = 32;
    let data = (0..N * N * N)
        .map(|i| {
            let p = [i % N, (i / N) % N, i / (N * N)].map(|c| c as f64 - 15.5);
            (p.iter().map(|c| c * c).sum::<f64>()).powf(-1.5) as f32
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let file = npy(dir.path(), "density.npy", [N; 3], data);
    let said = viewer_says(&[&file]);
    assert!(said.contains("the values span decades"), "{said}");
    let said = viewer_says(&[&file, "--linear"]);
    assert!(!said.contains("decades"), "{said}");
}
