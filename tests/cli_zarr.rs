//! `volray info` and `--level` on an OME-Zarr image: a two-level OME-Zarr
//! 0.5 group written here by hand (Zarr v3, the `bytes` codec alone, one
//! chunk a level), so that these tests need no Python. The values and
//! every codec are checked against zarr-python's stores in
//! `crates/io/tests/zarr.rs`.

mod common;

use std::fs;
use std::path::Path;

use common::{Picture, stderr, stdout, volray};
use serde_json::{Value, json};

/// One uint8 level of shape (z, y, x) at `dir`, values 0, 1, 2, ... in C order.
fn write_level(dir: &Path, shape: [u64; 3]) {
    fs::create_dir_all(dir.join("c/0/0")).unwrap();
    let meta = json!({
        "zarr_format": 3,
        "node_type": "array",
        "shape": shape,
        "data_type": "uint8",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": shape}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": 0,
        "codecs": [{"name": "bytes"}],
    });
    fs::write(dir.join("zarr.json"), meta.to_string()).unwrap();
    let n = shape.iter().product::<u64>() as u8;
    fs::write(dir.join("c/0/0/0"), (0..n).collect::<Vec<u8>>()).unwrap();
}

/// An image of two levels: (z, y, x) 2 x 4 x 6 at spacing 3, 1, 0.5, and
/// 2 x 2 x 3 at 3, 2, 1, both from (7, 8, 9).
fn write_image(root: &Path) {
    write_level(&root.join("0"), [2, 4, 6]);
    write_level(&root.join("1"), [2, 2, 3]);
    let level = |path: &str, scale: [f64; 3]| {
        json!({"path": path, "coordinateTransformations": [
            {"type": "scale", "scale": scale},
            {"type": "translation", "translation": [7.0, 8.0, 9.0]},
        ]})
    };
    let meta = json!({
        "zarr_format": 3,
        "node_type": "group",
        "attributes": {"ome": {"version": "0.5", "multiscales": [{
            "axes": [
                {"name": "z", "type": "space", "unit": "micrometer"},
                {"name": "y", "type": "space", "unit": "micrometer"},
                {"name": "x", "type": "space", "unit": "micrometer"},
            ],
            "datasets": [level("0", [3.0, 1.0, 0.5]), level("1", [3.0, 2.0, 1.0])],
        }]}},
    });
    fs::write(root.join("zarr.json"), meta.to_string()).unwrap();
}

fn info_json(args: &[&str]) -> Value {
    let out = volray(args);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_str(&stdout(&out)).unwrap()
}

#[test]
fn info_lists_every_level_and_describes_the_one_read() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("cells.ome.zarr");
    write_image(&image);
    let path = image.to_str().unwrap();

    let j = info_json(&["info", path, "--json"]);
    assert_eq!(j["format"], "Zarr/OME-Zarr");
    assert_eq!(j["dims"], json!([6, 4, 2]));
    assert_eq!(j["spacing"], json!([0.5, 1.0, 3.0]));
    assert_eq!(j["origin"], json!([9.0, 8.0, 7.0]));
    assert_eq!(j["level"], 0);
    let levels = j["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 2);
    assert_eq!(levels[1]["dims"], json!([3, 2, 2]));
    assert_eq!(levels[1]["chunk_shape"], json!([2, 2, 3]));
    assert_eq!(levels[1]["codecs"], "bytes");
    assert_eq!(levels[0]["bytes_stored"], 48);
    assert_eq!(levels[1]["bytes_in_memory"], 12);

    // --level 1 reads the coarser level, values and geometry.
    let j = info_json(&["info", path, "--json", "--level", "1"]);
    assert_eq!(
        (j["level"].clone(), j["dims"].clone()),
        (json!(1), json!([3, 2, 2]))
    );
    assert_eq!(j["spacing"], json!([1.0, 2.0, 3.0]));
    assert_eq!(j["values"]["max"], 11.0);

    let out = volray(&["info", path]);
    let text = stdout(&out);
    assert!(
        text.contains("levels:    2 (read: 0; --level picks another)"),
        "{text}"
    );
    assert!(
        text.contains("  1: 3 x 2 x 2, spacing 1, 2, 3; chunks 2x2x3, shards -; codecs bytes; 12 bytes stored, 12 bytes in memory"),
        "{text}"
    );
}

#[test]
fn level_flags_are_refused_where_they_cannot_apply() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("img");
    write_image(&image);
    let path = image.to_str().unwrap();
    let refused = |args: &[&str], expect: &str| {
        let out = volray(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = stderr(&out);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{err}");
    };
    refused(
        &["info", path, "--level", "auto"],
        "--level auto chooses the level a still image needs",
    );
    refused(&["info", path, "--level", "1.5"], "\"1.5\" is not a level");
    refused(
        &["info", path, "--level", "2"],
        "level 2 is out of range: the image holds 2 levels",
    );
    refused(
        &["info", path, "--channel", "1"],
        "channel 1 is out of range: the image holds 1 channel",
    );
    refused(
        &["info", "sphere:8", "--level", "0"],
        "--level and --channel apply to files only",
    );
    let raw = dir.path().join("v.raw");
    fs::write(&raw, [0u8; 8]).unwrap();
    refused(
        &[
            "info",
            raw.to_str().unwrap(),
            "--dims",
            "2,2,2",
            "--level",
            "0",
        ],
        "--level applies to Zarr/OME-Zarr images only, not to raw samples files",
    );
}

/// Adds an `omero` block to the image's attributes: channel 0 shown in
/// the window `start`..`end`.
fn add_omero(root: &Path, start: f64, end: f64) {
    let path = root.join("zarr.json");
    let mut meta: Value = serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
    meta["attributes"]["ome"]["omero"] = json!({"channels": [{
        "label": "nuclei", "color": "00FF00", "active": true,
        "window": {"start": start, "end": end, "min": 0, "max": 255},
    }]});
    fs::write(&path, meta.to_string()).unwrap();
}

#[test]
fn an_omero_window_is_the_default_range_and_flags_override_it() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.ome.zarr");
    let hinted = dir.path().join("hinted.ome.zarr");
    write_image(&plain);
    write_image(&hinted);
    add_omero(&hinted, 10.0, 30.0);
    let render = |image: &Path, name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["render", image.to_str().unwrap(), "--size", "24x24"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let run = volray(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        // The pixels: the PNG's text chunks name the file.
        Picture::read(&out)
    };
    // The hint is the window a --range would give, not the value range.
    let hinted_default = render(&hinted, "hinted.png", &[]);
    assert_eq!(
        hinted_default,
        render(&plain, "ranged.png", &["--range", "10,30"])
    );
    assert_ne!(hinted_default, render(&plain, "plain.png", &[]));
    // A flag that fixes the domain wins; others take the window.
    assert_eq!(
        render(&hinted, "hinted-ranged.png", &["--range", "0,47"]),
        render(&plain, "plain-ranged.png", &["--range", "0,47"])
    );
    assert_eq!(
        render(&hinted, "hinted-viridis.png", &["--colormap", "viridis"]),
        render(
            &plain,
            "plain-viridis.png",
            &["--colormap", "viridis", "--range", "10,30"]
        )
    );
}
