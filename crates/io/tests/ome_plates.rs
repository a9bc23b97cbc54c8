//! OME-Zarr plates and collections (`--array` names the image: a plate's
//! `ROW/COLUMN/FIELD`, a bioformats2raw series, a subgroup) and `omero`
//! rendering hints: stores written at test time by ome-zarr-py and
//! zarr-python (`tests/ome_plates/write_stores.py`), whose every sample
//! says which image it belongs to (1000 · tag + x + 10y + 100z).
//!
//! The writers run in `target/pyenv` (ome-zarr, zarr and numpy, which
//! `.ci/run` installs); without them these tests fail under `CI=true` and
//! are skipped elsewhere.

mod common;

use std::path::Path;
use std::sync::OnceLock;

use volray_io::{OmeroChannel, ReadOptions, open_lazy, read};

/// The directory the writers filled, or `None` (with the reason printed)
/// where they are missing outside CI.
fn stores() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["zarr", "ome_zarr", "numpy"],
        "tests/ome_plates/write_stores.py",
    )
}

fn opts(array: Option<&str>, channel: Option<usize>) -> ReadOptions {
    ReadOptions {
        array: array.map(str::to_string),
        channel,
        ..ReadOptions::default()
    }
}

/// The tag of the image read from `store` with `--array array`, checked
/// sample for sample.
fn tag_of(store: &Path, array: &str) -> u32 {
    let loaded = read(store, &opts(Some(array), None))
        .unwrap_or_else(|e| panic!("{} --array {array}: {e}", store.display()));
    let v = &loaded.volume;
    assert_eq!(v.dims(), [6, 5, 4]);
    let tag = (v.get(0, 0, 0) / 1000.0) as u32;
    for (x, y, z) in [(0, 0, 0), (5, 0, 0), (0, 4, 0), (0, 0, 3), (5, 4, 3)] {
        let want = (1000 * tag + x + 10 * y + 100 * z) as f32;
        assert_eq!(v.get(x as usize, y as usize, z as usize), want);
    }
    assert_eq!(loaded.info.array.as_deref(), Some(array));
    // The lazy path opens the same image.
    let lazy = open_lazy(store, &opts(Some(array), None)).unwrap().unwrap();
    assert_eq!(
        lazy.source.read_box([0; 3], [6, 5, 4]).unwrap(),
        loaded.volume
    );
    tag
}

/// The one-line error reading `store` without `--array`.
fn refused(store: &Path, array: Option<&str>) -> String {
    let err = read(store, &opts(array, None)).unwrap_err().to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with(&store.display().to_string()), "{err}");
    err
}

#[test]
fn array_names_the_field_of_a_plate_and_without_it_the_fields_are_listed() {
    let Some(dir) = stores() else { return };
    let plate = dir.join("plate.ome.zarr");
    assert_eq!(tag_of(&plate, "A/1/0"), 1);
    assert_eq!(tag_of(&plate, "A/1/1"), 2);
    assert_eq!(tag_of(&plate, "B/2/0"), 3);
    let held = read(&plate, &opts(Some("B/2/0"), None))
        .unwrap()
        .info
        .arrays;
    assert_eq!(held, ["A/1/0", "A/1/1", "B/2/0"]);
    let err = refused(&plate, None);
    assert!(
        err.ends_with(
            "an OME-Zarr plate of 3 images: name one with --array PATH (A/1/0, A/1/1, B/2/0)"
        ),
        "{err}"
    );
    let err = refused(&plate, Some("C/3/0"));
    assert!(
        err.ends_with("--array \"C/3/0\" is no Zarr group or array in the store; its images: A/1/0, A/1/1, B/2/0"),
        "{err}"
    );
    let err = refused(&plate, Some("../plate.ome.zarr"));
    assert!(
        err.contains("is no Zarr group or array in the store"),
        "{err}"
    );
}

#[test]
fn array_names_a_series_of_a_collection_and_without_it_the_series_are_listed() {
    let Some(dir) = stores() else { return };
    let collection = dir.join("collection.ome.zarr");
    assert_eq!(tag_of(&collection, "0"), 4);
    assert_eq!(tag_of(&collection, "1"), 5);
    let err = refused(&collection, None);
    assert!(
        err.ends_with("an OME-Zarr collection of 2 images: name one with --array PATH (0, 1)"),
        "{err}"
    );
    // A group of images with no listing: its subgroups that are images.
    let plain = dir.join("plain.zarr");
    assert_eq!(tag_of(&plain, "a"), 4);
    assert_eq!(tag_of(&plain, "b"), 5);
    let err = refused(&plain, None);
    assert!(
        err.ends_with("collection of 2 images: name one with --array PATH (a, b)"),
        "{err}"
    );
}

#[test]
fn the_omero_hints_of_the_channel_read_are_kept() {
    let Some(dir) = stores() else { return };
    let store = dir.join("omero.ome.zarr");
    let info = |channel| read(&store, &opts(None, channel)).unwrap().info.omero;
    assert_eq!(
        info(None),
        Some(OmeroChannel {
            channel: 0,
            label: Some("DAPI".into()),
            color: Some("0000FF".into()),
            active: Some(true),
            window: Some((6100.0, 6400.0, Some(0.0), Some(65535.0))),
        })
    );
    let second = info(Some(1)).unwrap();
    assert_eq!(second.label.as_deref(), Some("GFP"));
    assert_eq!(second.color.as_deref(), Some("00FF00"));
    assert_eq!(second.active, Some(false));
    assert_eq!(
        second.window,
        Some((6700.0, 6900.0, Some(6500.0), Some(7000.0)))
    );
    // An image without them: none.
    let plate = dir.join("plate.ome.zarr");
    assert_eq!(
        read(&plate, &opts(Some("A/1/0"), None)).unwrap().info.omero,
        None
    );
}
