//! HDF5 datasets that name their axes (`fixtures/hdf5/axes.h5`, written by
//! h5py in `fixtures/make_hdf5_fixtures.py`): an `axes` attribute, ilastik's
//! `axistags`, h5py's `DIMENSION_LABELS`, read in the order the names say,
//! eagerly and box by box alike.
//!
//! Every volume is (x, y, z) = (5, 4, 3) holding `v = x + 10y + 100z` at
//! volume (x, y, z) (frame f adds 1000 f), whatever order the file stores
//! it in; so the sample at file index [z=0, y=0, x=1] of a `zyx` dataset
//! lands at volume (1, 0, 0).

mod common;

use std::path::PathBuf;

use common::{assert_frame_out_of_range, check_voxels, error_about, frame, header_value, ramp};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, open_lazy, read};

const DIMS: [usize; 3] = [5, 4, 3];

fn fixture(dataset: &str) -> PathBuf {
    common::fixture("hdf5", &format!("axes.h5:/{dataset}"))
}

fn load(dataset: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&fixture(dataset), opts).unwrap_or_else(|e| panic!("{dataset}: {e}"));
    assert_eq!(l.format, VolumeFormat::Hdf5);
    l
}

/// Voxel (x, y, z) holds v + 1000·frame exactly.
fn assert_ramp(what: &str, volume: &Volume, frame: usize) {
    check_voxels(what, volume, DIMS, |x, y, z| {
        (ramp(x, y, z) + 1000 * frame as i64) as f32
    });
}

#[test]
fn an_axes_attribute_zyx_puts_the_last_file_axis_along_x() {
    let l = load("zyx", &ReadOptions::default());
    assert_ramp("zyx", &l.volume, 0);
    // File index [z=0, y=0, x=1] holds 1: at volume (1, 0, 0).
    assert_eq!(l.volume.get(1, 0, 0), 1.0);
    // element_size_um [2, 0.5, 0.25] in the dataset's order (z, y, x).
    assert_eq!(l.volume.spacing(), DVec3::new(0.25, 0.5, 2.0));
    assert_eq!(l.info.length_unit.as_deref(), Some("um"));
    assert_eq!(
        header_value(&l, "axis order"),
        "a[z, y, x] from attribute axes"
    );
}

#[test]
fn names_in_any_case_and_as_string_arrays_give_the_order() {
    let l = load("zyx_gzip", &ReadOptions::default());
    assert_ramp("zyx_gzip (\"ZYX\")", &l.volume, 0);
    assert_eq!(l.volume.origin(), DVec3::new(10.0, 20.0, 30.0));
    assert_ramp("yxz", &load("yxz", &ReadOptions::default()).volume, 0);
    assert_ramp("xyz", &load("xyz", &ReadOptions::default()).volume, 0);
}

#[test]
fn dimension_labels_give_the_order_where_there_is_no_axes_attribute() {
    let l = load("labels", &ReadOptions::default());
    assert_ramp("labels", &l.volume, 0);
    assert_eq!(
        header_value(&l, "axis order"),
        "a[z, y, x] from attribute DIMENSION_LABELS"
    );
}

#[test]
fn ilastik_axistags_name_a_channel_axis_whose_channels_are_frames() {
    for c in 0..2 {
        let l = load("ilastik", &common::at(0, c));
        assert_ramp("ilastik", &l.volume, c);
        assert_eq!((l.info.channels, l.info.channel), (2, c));
        assert_eq!((l.info.frames, l.info.frame), (2, c));
        assert_eq!(
            header_value(&l, "axis order"),
            "a[z, y, x, c] from attribute axistags"
        );
    }
    let err = read(&fixture("ilastik"), &common::at(0, 2)).unwrap_err();
    assert!(
        err.to_string().ends_with(
            "channel 2 is out of range: HDF5 dataset \"/ilastik\" holds 2 channels (axis c), numbered from 0"
        ),
        "{err}"
    );
    // One time point: --frame 1 is out of range.
    let err = read(&fixture("ilastik"), &frame(1)).unwrap_err();
    assert_frame_out_of_range(
        &err,
        1,
        "HDF5 dataset \"/ilastik\" holds 1 time point (axis t) of 2 channels (axis c)",
    );
}

#[test]
fn time_and_channel_axes_are_picked_apart() {
    // a[t, c, z, y, x] of 2 time points and 2 channels: the file's
    // volume 2t + c.
    for f in 0..4 {
        let (t, c) = (f / 2, f % 2);
        let l = load("tczyx", &common::at(t, c));
        assert_ramp("tczyx", &l.volume, f);
        assert_eq!((l.info.frames, l.info.frame), (4, f));
        assert_eq!((l.info.time_points, l.info.channels), (2, 2));
        // spacing [1, 1, 3, 2, 1.5], one per dataset axis.
        assert_eq!(l.volume.spacing(), DVec3::new(1.5, 2.0, 3.0));
    }
    let err = read(&fixture("tczyx"), &frame(2)).unwrap_err();
    assert_frame_out_of_range(
        &err,
        2,
        "HDF5 dataset \"/tczyx\" holds 2 time points (axis t) of 2 channels (axis c)",
    );
}

#[test]
fn attached_h5py_dimension_scales_are_not_followed_and_say_so() {
    let l = load("scaled", &ReadOptions::default());
    assert_ramp("scaled", &l.volume, 0);
    assert!(
        l.info.notes.iter().any(|n| n.contains("DIMENSION_LIST")),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn netcdf_style_names_go_by_the_cf_rule() {
    // DIMENSION_LABELS depth, lat, lon: a[z, y, x].
    let l = load("cf_names", &ReadOptions::default());
    assert_ramp("cf_names", &l.volume, 0);
    assert_eq!(
        header_value(&l, "axis order"),
        "a[z, y, x] from attribute DIMENSION_LABELS read by the CF conventions (depth is z (its name), lat is y (its name), lon is x (its name))"
    );
}

#[test]
fn names_neither_axis_letters_nor_cf_names_keep_the_default_order_with_a_note() {
    let l = load("other_names", &ReadOptions::default());
    assert_ramp("other_names", &l.volume, 0);
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("i, j, k") && n.contains("not x, y, z, t, c, nor CF names")),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn axis_names_that_make_no_order_are_refused_in_one_line() {
    let file = common::fixture("hdf5", "axes.h5");
    for (dataset, want) in [
        ("bad_twice", "axis y is named twice"),
        (
            "bad_count",
            "names 4 axes (t, z, y, x), but the dataset has 3",
        ),
    ] {
        let err = error_about(&fixture(dataset), &ReadOptions::default(), &file).to_string();
        assert!(err.contains(want), "{dataset}: {err}");
        assert!(err.contains("attribute axes"), "{dataset}: {err}");
        assert!(!err.contains('\n'), "{err}");
    }
}

/// Every box of the volume (at least 2 samples a side) read box by box
/// equals the same box of the volume read whole, with the same geometry.
#[test]
fn every_box_read_box_by_box_equals_the_eager_read() {
    for (dataset, frames, storage) in [
        ("zyx", 1, "contiguous"),
        ("zyx_gzip", 1, "deflate"),
        ("labels", 1, "chunks of shape"),
        ("ilastik", 2, "chunks of shape"),
        ("tczyx", 4, "chunks of shape"), // fletcher32: decoded per chunk
        ("yxz", 1, "contiguous"),
        ("cf_names", 1, "contiguous"),
    ] {
        for f in 0..frames {
            // The file's volume f: time point f / C, channel f % C.
            let channels = if dataset == "ilastik" {
                2
            } else {
                frames.min(2)
            };
            let opts = common::at(f / channels, f % channels);
            let whole = load(dataset, &opts);
            assert_ramp(dataset, &whole.volume, f);
            let lazy = open_lazy(&fixture(dataset), &opts)
                .unwrap_or_else(|e| panic!("{dataset}: {e}"))
                .unwrap_or_else(|| panic!("{dataset}: not opened box by box"));
            assert!(
                lazy.info.notes.iter().any(|n| n.contains(storage)),
                "{dataset}: {:?}",
                lazy.info.notes
            );
            let grid = lazy.source.grid();
            assert_eq!(grid.dims, DIMS);
            assert_eq!(grid.spacing, whole.volume.spacing(), "{dataset}");
            assert_eq!(grid.origin, whole.volume.origin(), "{dataset}");
            let mut boxes = 0;
            for lo in boxes_from() {
                for hi in boxes_from() {
                    if (0..3).any(|a| hi[a] < lo[a] + 2) {
                        continue;
                    }
                    let part = lazy
                        .source
                        .read_box(lo, hi)
                        .unwrap_or_else(|e| panic!("{dataset} {lo:?}..{hi:?}: {e}"));
                    let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
                    check_voxels(
                        &format!("{dataset} frame {f} box {lo:?}..{hi:?}"),
                        &part,
                        dims,
                        |x, y, z| whole.volume.get(lo[0] + x, lo[1] + y, lo[2] + z),
                    );
                    boxes += 1;
                }
            }
            assert_eq!(boxes, 10 * 6 * 3, "{dataset}");
        }
    }
}

/// Every corner (x, y, z) of the grid, for boxes' ends.
fn boxes_from() -> impl Iterator<Item = [usize; 3]> {
    (0..=DIMS[2])
        .flat_map(|z| (0..=DIMS[1]).flat_map(move |y| (0..=DIMS[0]).map(move |x| [x, y, z])))
}
