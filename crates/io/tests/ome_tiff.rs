//! OME-TIFF stacks written by tifffile with `ome=True`
//! (`fixtures/make_tiff_fixtures.py`): the OME-XML's physical sizes and
//! units, and its DimensionOrder, SizeZ/SizeC/SizeT saying which pages
//! are the z slices of which channel and time point.
//!
//! Every volume is (x, y, z) = (5, 4, 3) holding `v = x + 10y + 100z`
//! (tifffile's `a[z, y, x]`), plus `1000·frame`, frame `t·SizeC + c`.

mod common;

use std::path::PathBuf;

use common::{assert_frame_out_of_range, check_voxels, frame, header_value, ramp, refuse};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("tiff", name)
}

fn load(name: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&fixture(name), opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.format, VolumeFormat::Tiff);
    l
}

fn assert_ramp(what: &str, volume: &Volume, frame: usize) {
    check_voxels(what, volume, [5, 4, 3], |x, y, z| {
        (ramp(x, y, z) + 1000 * frame as i64) as f32
    });
}

fn assert_close(got: DVec3, want: DVec3) {
    assert!((got - want).abs().max_element() < 1e-12, "{got} != {want}");
}

#[test]
fn ome_physical_sizes_give_the_spacing_in_their_unit() {
    let l = load("ome_zyx.ome.tif", &ReadOptions::default());
    assert_ramp("ome_zyx", &l.volume, 0);
    // Page 0, row 0, column 1 holds 1: at volume (1, 0, 0).
    assert_eq!(l.volume.get(1, 0, 0), 1.0);
    assert_close(l.volume.spacing(), DVec3::new(0.5, 0.25, 2.0));
    assert_eq!(l.volume.origin(), DVec3::ZERO);
    assert_eq!(l.info.length_unit.as_deref(), Some("\u{b5}m"));
    assert_eq!(l.info.frames, 1);
    assert_eq!(
        header_value(&l, "OME Pixels"),
        "DimensionOrder XYCZT, SizeZ 3, SizeC 1, SizeT 1"
    );
}

#[test]
fn sizes_in_different_units_are_converted_to_the_finest() {
    // PhysicalSizeX 500 nm, Y 0.25 (the default µm), Z 0.002 mm: in nm,
    // the finest, by whole powers of ten: 250 nm exactly.
    let l = load("ome_zcyx.ome.tif", &ReadOptions::default());
    assert_eq!(l.volume.spacing(), DVec3::new(500.0, 250.0, 2000.0));
    assert_eq!(l.info.length_unit.as_deref(), Some("nm"));
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n == "x in nm, y in \u{b5}m, z in mm: spacing in nm (y × 1000, z × 1000000)"),
        "{:?}",
        l.info.notes
    );
    // One unit throughout: kept as written.
    let l = load("ome_tzyx.ome.tif", &ReadOptions::default());
    assert_close(l.volume.spacing(), DVec3::new(0.1, 0.1, 0.3));
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
}

#[test]
fn channels_and_time_points_are_picked_apart_whatever_the_dimension_order() {
    // XYCZT (channel fastest) and XYZCT (z fastest): two channels.
    for name in ["ome_zcyx.ome.tif", "ome_czyx.ome.tif"] {
        for c in 0..2 {
            let l = load(name, &common::at(0, c));
            assert_ramp(name, &l.volume, c);
            let i = &l.info;
            assert_eq!((i.time_points, i.channels, i.channel), (1, 2, c), "{name}");
        }
        let err = read(&fixture(name), &common::at(0, 2)).unwrap_err();
        assert!(
            matches!(err, IoError::ChannelOutOfRange { channel: 2, .. }),
            "{err}"
        );
        assert!(
            err.to_string().ends_with(
                "channel 2 is out of range: the stack holds 2 channels (SizeC), numbered from 0"
            ),
            "{err}"
        );
    }
    // Two time points of one channel.
    let name = "ome_tzyx.ome.tif";
    for t in 0..2 {
        let l = load(name, &frame(t));
        assert_ramp(name, &l.volume, 2 * t);
        assert_eq!((l.info.time_points, l.info.time_point), (2, t));
    }
    let err = read(&fixture(name), &frame(2)).unwrap_err();
    assert_frame_out_of_range(&err, 2, "the stack holds 2 volumes (SizeT)");
}

#[test]
fn ome_xml_that_does_not_fit_the_pages_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(fixture("ome_zcyx.ome.tif")).unwrap();
    // More planes than pages (same length, so the TIFF stays whole).
    let lying = common::replace(&good, "SizeZ=\"3\"", "SizeZ=\"9\"");
    refuse(
        dir.path(),
        "lying.ome.tif",
        &lying,
        "OME-XML says SizeZ=9 SizeC=2 SizeT=1 (18 planes) but the file has 6 full-resolution page(s)",
    );
    let order = common::replace(&good, "XYCZT", "XYCZZ");
    refuse(
        dir.path(),
        "order.ome.tif",
        &order,
        "OME-XML: Pixels DimensionOrder=\"XYCZZ\" is not XY followed by Z, C and T",
    );
    let size = common::replace(&good, "PhysicalSizeX=\"500.0\"", "PhysicalSizeX=\"-50.00\"");
    refuse(
        dir.path(),
        "size.ome.tif",
        &size,
        "OME-XML: Pixels PhysicalSizeX=\"-50.00\" is not a positive length",
    );
    let unit = common::replace(
        &good,
        "PhysicalSizeXUnit=\"nm\"",
        "PhysicalSizeXUnit=\"zz\"",
    );
    refuse(
        dir.path(),
        "unit.ome.tif",
        &unit,
        "\"zz\" is not a length unit",
    );
    let xml = common::replace(&good, "<Pixels ", "<Pixels<");
    refuse(dir.path(), "xml.ome.tif", &xml, "OME-XML");
}
