//! `volray render` of an OME-Zarr image that `--max-memory` will not let
//! it read whole: rendered piece by piece from its chunks, the same
//! picture as the image read whole within a level; and `--level auto`
//! choosing the level the picture needs. The image is written here by
//! hand (Zarr v3, the `bytes` codec, 16³ chunks), so these tests need no
//! Python; zarr-python's stores are read in `crates/io/tests/zarr.rs`.

mod common;

use std::fs;
use std::path::Path;

use common::{Picture, render, stderr, volray};
use serde_json::json;

/// The image's finest level, (x, y, z).
const DIMS: [usize; 3] = [48, 40, 36];

/// A smooth u16 field: two blobs over a ramp.
fn value(x: usize, y: usize, z: usize) -> u16 {
    let p = [x as f64, y as f64, z as f64];
    let blob = |c: [f64; 3], r: f64| {
        let d2: f64 = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum();
        (-d2 / (2.0 * r * r)).exp()
    };
    let v = 30000.0 * blob([16.0, 14.0, 12.0], 6.0) + 20000.0 * blob([32.0, 26.0, 24.0], 5.0);
    (v + 40.0 * p[2]) as u16
}

/// An OME-Zarr 0.5 image of three levels, each halving every axis (2³
/// block means), unit spacing at level 0.
fn write_image(root: &Path) {
    common::zarr::write_level(&root.join("0"), DIMS, "uint16", json!(0), &|x, y, z| {
        value(x, y, z).to_le_bytes()
    });
    let mut dims = DIMS;
    let mut scale = 1.0;
    let mut datasets = vec![json!({"path": "0", "coordinateTransformations": [
        {"type": "scale", "scale": [1.0, 1.0, 1.0]}]})];
    for level in 1..3 {
        let factor = 1usize << level;
        dims = dims.map(|n| n.div_ceil(2));
        scale *= 2.0;
        let mean = move |x: usize, y: usize, z: usize| {
            let mut sum = 0.0;
            let mut n = 0.0;
            for k in z * factor..((z + 1) * factor).min(DIMS[2]) {
                for j in y * factor..((y + 1) * factor).min(DIMS[1]) {
                    for i in x * factor..((x + 1) * factor).min(DIMS[0]) {
                        sum += f64::from(value(i, j, k));
                        n += 1.0;
                    }
                }
            }
            (sum / n).round() as u16
        };
        common::zarr::write_level(
            &root.join(level.to_string()),
            dims,
            "uint16",
            json!(0),
            &|x, y, z| mean(x, y, z).to_le_bytes(),
        );
        let shift = (scale - 1.0) / 2.0;
        datasets.push(
            json!({"path": level.to_string(), "coordinateTransformations": [
            {"type": "scale", "scale": [scale, scale, scale]},
            {"type": "translation", "translation": [shift, shift, shift]}]}),
        );
    }
    let meta = json!({
        "zarr_format": 3,
        "node_type": "group",
        "attributes": {"ome": {"version": "0.5", "multiscales": [{
            "axes": [
                {"name": "z", "type": "space"},
                {"name": "y", "type": "space"},
                {"name": "x", "type": "space"},
            ],
            "datasets": datasets,
        }]}},
    });
    fs::write(root.join("zarr.json"), meta.to_string()).unwrap();
}

const LOOK: [&str; 6] = ["--preset", "mr", "--range", "0,32000", "--size", "40x36"];

#[test]
fn a_level_over_max_memory_renders_piece_by_piece_as_it_would_whole() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();
    let (whole, pieces) = (dir.path().join("whole.png"), dir.path().join("pieces.png"));
    let said = render(&[&[path, "--level", "0"], &LOOK[..]].concat(), &whole);
    assert!(!said.contains("pieces"), "{said}");
    // 48·40·36 u16 voxels take 138 kB: 100 kB cannot hold them whole, but
    // it holds pieces of them and their frames.
    let said = render(
        &[&[path, "--level", "0", "--max-memory", "100K"], &LOOK[..]].concat(),
        &pieces,
    );
    assert!(said.contains("in pieces"), "{said}");
    let picture = Picture::read(&whole);
    assert!(picture.rgb.iter().any(|p| *p != picture.rgb[0]), "blank");
    let diff = Picture::read(&pieces).max_diff(&picture);
    assert!(diff <= 1, "{diff}");
    // The value range the preset's window does not give is found piece by
    // piece too: --tf auto (a histogram) and a colour map over the data.
    for extra in [&["--tf", "auto"][..], &["--colormap", "viridis"][..]] {
        let args = [&[path, "--size", "40x36"], extra].concat();
        render(&args, &whole);
        let limited = [&args[..], &["--max-memory", "100K"]].concat();
        let said = render(&limited, &pieces);
        assert!(said.contains("in pieces"), "{extra:?}: {said}");
        let diff = Picture::read(&pieces).max_diff(&Picture::read(&whole));
        assert!(diff <= 1, "{extra:?}: {diff}");
    }
    // --log: the level's smallest positive value found first, then each
    // piece on the whole's log scale (a third of the budget: 300 kB cannot
    // hold the level's f32 log whole).
    for extra in [&["--log"][..], &["--log", "--tf", "auto"][..]] {
        let args = [&[path, "--size", "40x36"], extra].concat();
        render(&args, &whole);
        let limited = [&args[..], &["--max-memory", "300K"]].concat();
        let said = render(&limited, &pieces);
        assert!(said.contains("in pieces"), "{extra:?}: {said}");
        let diff = Picture::read(&pieces).max_diff(&Picture::read(&whole));
        assert!(diff <= 1, "{extra:?}: {diff}");
    }
}

#[test]
fn level_auto_takes_the_coarsest_level_no_coarser_than_a_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();
    let out = |name: &str| dir.path().join(name);
    // Seen from +x, the 39 x 35 face fitted: 1.08 units a pixel at 36
    // rows (level 0, spacing 1); 2.06 at 17 (level 1, spacing 2); 4.4 at
    // 8 (level 2, spacing 4).
    for (height, level) in [("36", 0), ("17", 1), ("8", 2)] {
        let size = ["--size", height, "--preset", "mr", "--range", "0,32000"];
        let said = render(
            &[&[path, "--level", "auto"], &size[..]].concat(),
            &out("auto.png"),
        );
        assert!(
            said.contains(&format!("level {level} of 3")),
            "{height}: {said}"
        );
        let n = level.to_string();
        render(
            &[&[path, "--level", n.as_str()], &size[..]].concat(),
            &out("fixed.png"),
        );
        assert_eq!(
            Picture::read(&out("auto.png")),
            Picture::read(&out("fixed.png")),
            "{height}"
        );
    }
    // A file of one level: refused by name.
    let raw = dir.path().join("v.npy");
    let made = volray(&["convert", "sphere:8", "-o", raw.to_str().unwrap()]);
    assert!(made.status.success(), "{}", stderr(&made));
    let refused = volray(&[
        "render",
        raw.to_str().unwrap(),
        "--level",
        "auto",
        "-o",
        "x.png",
    ]);
    assert_eq!(refused.status.code(), Some(1));
    let err = stderr(&refused);
    assert!(err.contains("--level") && err.lines().count() == 1, "{err}");
}

#[test]
fn a_multiscale_image_without_a_level_is_drawn_at_the_auto_level_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();
    let out = |name: &str| dir.path().join(name);
    // 17 rows: level 1 (the test above), with no --level given.
    let size = ["--size", "17", "--preset", "mr", "--range", "0,32000"];
    let said = render(&[&[path], &size[..]].concat(), &out("default.png"));
    assert!(
        said.contains("level 1 of 3") && said.contains("the default for a multiscale image"),
        "{said}"
    );
    render(
        &[&[path, "--level", "1"], &size[..]].concat(),
        &out("fixed.png"),
    );
    assert_eq!(
        Picture::read(&out("default.png")),
        Picture::read(&out("fixed.png"))
    );
    // --level 0 still draws the finest level.
    let said = render(
        &[&[path, "--level", "0"], &size[..]].concat(),
        &out("finest.png"),
    );
    assert!(!said.contains("level 1 of 3"), "{said}");
}

#[test]
fn a_turntable_of_a_level_over_max_memory_turns_piece_by_piece() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();
    let whole = dir.path().join("whole_%02d.png");
    let pieces = dir.path().join("pieces_%02d.png");
    let turn = ["--turntable", "3"];
    let said = render(
        &[&[path, "--level", "0"], &LOOK[..], &turn[..]].concat(),
        &whole,
    );
    assert!(!said.contains("pieces"), "{said}");
    let said = render(
        &[
            &[path, "--level", "0", "--max-memory", "100K"],
            &LOOK[..],
            &turn[..],
        ]
        .concat(),
        &pieces,
    );
    // Each frame was rendered from pieces: the note names them.
    assert!(
        said.contains("rendered in pieces") && said.contains("the last of 3 frames"),
        "{said}"
    );
    assert_eq!(said.lines().count(), 1, "{said}");
    for i in 0..3 {
        let a = Picture::read(&dir.path().join(format!("whole_{i:02}.png")));
        let b = Picture::read(&dir.path().join(format!("pieces_{i:02}.png")));
        assert!(a.max_diff(&b) <= 1, "frame {i}: {}", a.max_diff(&b));
    }
    // Built-in sources have no levels, auto or not.
    let out = volray(&["render", "sphere:8", "--level", "auto", "-o", "x.png"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("apply to files only"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn annotations_are_refused_in_pieces_in_one_line_and_drawn_whole() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();
    for (extra, out) in [
        (&[][..], "still.png"),
        (&["--turntable", "2"][..], "turn.gif"),
    ] {
        let out = dir.path().join(out);
        let args = [
            &[
                "render",
                path,
                "--level",
                "0",
                "--max-memory",
                "100K",
                "--axes",
                "-o",
                out.to_str().unwrap(),
            ][..],
            &LOOK[..],
            extra,
        ]
        .concat();
        let run = volray(&args);
        assert_eq!(run.status.code(), Some(1), "{extra:?}: {}", stderr(&run));
        let err = stderr(&run);
        assert!(
            err.starts_with("volray: error: --axes: ") && err.contains("piece by piece"),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!out.exists());
        // Read whole, the same frame is annotated.
        let whole = [
            &[
                "render",
                path,
                "--level",
                "0",
                "--outline",
                "-o",
                out.to_str().unwrap(),
            ][..],
            &LOOK[..],
            extra,
        ]
        .concat();
        let run = volray(&whole);
        assert!(run.status.success(), "{extra:?}: {}", stderr(&run));
    }
}

#[test]
fn info_reads_the_metadata_of_a_large_level_and_the_values_of_a_smaller_one() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();
    let info = |extra: &[&str]| -> serde_json::Value {
        let out = volray(&[&["info", path, "--json"], extra].concat());
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_str(&common::stdout(&out)).unwrap()
    };
    // Level 0 takes 138 kB: under 100 kB / 4, level 1 (17 kB) gives the values.
    let small = info(&["--max-memory", "100K"]);
    assert_eq!(small["dims"], json!([48, 40, 36]));
    assert_eq!(small["level"], 0);
    assert_eq!(small["values_level"], 1);
    // With room, the level's own values.
    let whole = info(&[]);
    assert_eq!(whole["values_level"], serde_json::Value::Null);
    assert_eq!(whole["dims"], small["dims"]);
    assert_eq!(whole["spacing"], small["spacing"]);
    let (lo, hi) = (&whole["values"], &small["values"]);
    // Block means lie within the level's range.
    assert!(hi["min"].as_f64() >= lo["min"].as_f64(), "{hi} {lo}");
    assert!(hi["max"].as_f64() <= lo["max"].as_f64(), "{hi} {lo}");
    assert!(hi["max"].as_f64().unwrap() < lo["max"].as_f64().unwrap());
}

#[test]
fn an_omero_window_is_the_default_range_in_pieces_as_whole() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let meta_path = image.join("zarr.json");
    let mut meta: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&meta_path).unwrap()).unwrap();
    meta["attributes"]["ome"]["omero"] = json!({"channels": [{
        "window": {"start": 8000, "end": 24000, "min": 0, "max": 65535}
    }]});
    fs::write(&meta_path, meta.to_string()).unwrap();
    let path = image.to_str().unwrap();
    let look = ["--colormap", "viridis", "--size", "40x36", "--level", "0"];
    let out = |name: &str| dir.path().join(name);
    let said = render(
        &[&[path, "--max-memory", "100K"], &look[..]].concat(),
        &out("p.png"),
    );
    assert!(said.contains("pieces"), "{said}");
    render(
        &[&[path, "--range", "8000,24000"], &look[..]].concat(),
        &out("w.png"),
    );
    render(
        &[path].iter().chain(&look).copied().collect::<Vec<_>>(),
        &out("d.png"),
    );
    render(
        &[&[path, "--range", "0,32000"], &look[..]].concat(),
        &out("o.png"),
    );
    let pieces = Picture::read(&out("p.png"));
    let ranged = Picture::read(&out("w.png"));
    assert!(pieces.max_diff(&ranged) <= 1);
    assert!(Picture::read(&out("d.png")).max_diff(&ranged) <= 1);
    // A window the picture shows: another range is another picture.
    assert!(pieces.max_diff(&Picture::read(&out("o.png"))) > 16);
}

/// `volray render` of the image's level 0 in pieces (`--max-memory
/// 100K`) to `out`: its exit code and its stderr.
fn render_in_pieces(image: &Path, out: &Path) -> (Option<i32>, String) {
    let args = [
        &["render", image.to_str().unwrap(), "--level", "0"][..],
        &["--max-memory", "100K", "-o", out.to_str().unwrap()],
        &LOOK[..],
    ]
    .concat();
    let run = volray(&args);
    (run.status.code(), stderr(&run))
}

#[test]
fn a_corrupt_chunk_read_piece_by_piece_is_bad_input_and_an_unreadable_one_an_io_failure() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img.ome.zarr");
    write_image(&image);
    let out = dir.path().join("out.png");
    let level = image.join("0").display().to_string();
    let chunk = image.join("0/c/1/1/1");
    let bytes = fs::read(&chunk).unwrap();
    // The chunk's bytes at fault (cut short, or empty): bad input, exit
    // 1, one line naming the level's array and the chunk.
    for (what, data) in [("cut short", &bytes[..bytes.len() / 2]), ("empty", &[][..])] {
        fs::write(&chunk, data).unwrap();
        let (code, said) = render_in_pieces(&image, &out);
        assert_eq!(code, Some(1), "{what}: {said}");
        assert_eq!(said.lines().count(), 1, "{what}: {said}");
        assert!(
            said.contains(&format!("error: {level}: ")),
            "{what}: {said}"
        );
        assert!(
            said.contains("cannot read Zarr chunks: c/1/1/1"),
            "{what}: {said}"
        );
        assert!(!said.contains("panicked"), "{what}: {said}");
    }
    // A directory where the chunk's file should be: the system cannot
    // read it, an I/O failure, exit 2.
    fs::remove_file(&chunk).unwrap();
    fs::create_dir(&chunk).unwrap();
    let (code, said) = render_in_pieces(&image, &out);
    assert_eq!(code, Some(2), "{said}");
    assert_eq!(said.lines().count(), 1, "{said}");
    assert!(said.contains(&format!("error: {level}: ")), "{said}");
    assert!(!said.contains("panicked"), "{said}");
    // Restored, the same command renders.
    fs::remove_dir(&chunk).unwrap();
    fs::write(&chunk, &bytes).unwrap();
    let (code, said) = render_in_pieces(&image, &out);
    assert_eq!(code, Some(0), "{said}");
    assert!(said.contains("in pieces"), "{said}");
}
