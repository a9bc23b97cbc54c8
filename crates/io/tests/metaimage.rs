//! Reads the MetaImage files SimpleITK wrote (some with header or data
//! edited the way the format allows, see
//! `fixtures/make_metaimage_fixtures.py`, which checks each one with
//! SimpleITK). Every voxel is compared with the formula the file was made
//! from; geometry and `FileInfo` with what the header says. Malformed
//! variants made here must fail with specific one-line errors.

mod common;

use std::fs;
use std::path::PathBuf;

use common::{
    Grid, assert_frame_out_of_range, check_voxels, check_world, error_about, frame, has_note,
    header_value, ramp, refuse, replace, scrambled,
};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("metaimage", name)
}

fn load(name: &str) -> Loaded {
    read(&fixture(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn small(i: usize, j: usize, k: usize) -> i64 {
    (i + 2 * j + 6 * k) as i64
}

/// Every voxel of a 4 x 3 x 5 volume whose axes are the file's axes.
fn check_values(v: &Volume, f: impl Fn(usize, usize, usize) -> f32) {
    check_voxels("", v, [4, 3, 5], f);
}

/// The geometry SimpleITK gave most fixtures.
fn check_default_geometry(l: &Loaded) {
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 1.25, 2.0));
    assert_eq!(l.volume.origin(), DVec3::new(1.0, -2.0, 3.0));
}

#[test]
fn float_attached() {
    let l = load("f32.mha");
    assert_eq!(l.format, VolumeFormat::MetaImage);
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    check_default_geometry(&l);
    assert_eq!(l.info.stored_type, "MET_FLOAT (f32, little-endian)");
    assert_eq!((l.info.frames, l.info.frame), (1, 0));
    assert_eq!(l.info.length_unit, None);
    assert_eq!(
        l.info.header[0],
        ("ObjectType".to_string(), "Image".to_string())
    );
    assert_eq!(header_value(&l, "ElementDataFile"), "LOCAL");
    assert!(l.info.notes.is_empty(), "{:?}", l.info.notes);
}

#[test]
fn uchar_detached() {
    let l = load("u8.mhd");
    check_values(&l.volume, |i, j, k| small(i, j, k) as f32);
    check_default_geometry(&l);
    assert_eq!(l.info.stored_type, "MET_UCHAR (u8)");
}

#[test]
fn zlib_attached_and_detached() {
    let l = load("i16_zlib.mha");
    check_values(&l.volume, |i, j, k| -ramp(i, j, k) as f32);
    check_default_geometry(&l);
    let l = load("u16_zlib.mhd");
    check_values(&l.volume, |i, j, k| (100 * ramp(i, j, k)) as f32);
    // Without CompressedDataSize the compressed data runs to the end of the file.
    let l = load("u16_nosize.mhd");
    check_values(&l.volume, |i, j, k| (100 * ramp(i, j, k)) as f32);
}

#[test]
fn permuted_and_flipped_axes_keep_world_positions() {
    let l = load("f64_permuted.mha");
    let v = &l.volume;
    // Index axis 0 steps -2 along z, axis 1 +0.5 along x, axis 2 +1.5 along y.
    assert_eq!(v.dims(), [3, 5, 4]);
    assert_eq!(v.spacing(), DVec3::new(0.5, 1.5, 2.0));
    assert_eq!(v.origin(), DVec3::new(10.0, 20.0, 24.0));
    let grid = Grid {
        n: [4, 3, 5],
        steps: [
            DVec3::new(0.0, 0.0, -2.0),
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.0, 1.5, 0.0),
        ],
        origin: DVec3::new(10.0, 20.0, 30.0),
    };
    check_world("", v, &grid, 1e-12, |i, j, k| ramp(i, j, k) as f32 / 8.0);
    assert!(has_note(&l, "index axis 0 -> -z"), "{:?}", l.info.notes);
    assert_eq!(l.info.stored_type, "MET_DOUBLE (f64, little-endian)");
}

#[test]
fn rotated_axes_are_kept_and_noted() {
    let l = load("rotated.mha");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    assert!((l.volume.spacing() - DVec3::ONE).length() < 1e-12);
    assert!(
        has_note(&l, "rotation is not applied"),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn other_element_types() {
    let l = load("i8.mha");
    check_values(&l.volume, |i, j, k| (small(i, j, k) - 16) as f32);
    assert_eq!(l.info.stored_type, "MET_CHAR (i8)");
    check_values(&load("u32.mha").volume, |i, j, k| {
        (100_000 * ramp(i, j, k)) as f32
    });
    check_values(&load("i32.mha").volume, |i, j, k| {
        (1000 * ramp(i, j, k) - 50_000) as f32
    });
    check_values(&load("i64.mha").volume, |i, j, k| {
        (1_000_000_000_000 * ramp(i, j, k) - 7) as f32
    });
    let l = load("u64.mha");
    check_values(&l.volume, |i, j, k| {
        ((1u64 << 40) * ramp(i, j, k) as u64 + 3) as f32
    });
    assert_eq!(l.info.stored_type, "MET_ULONG_LONG (u64, little-endian)");
}

#[test]
fn four_d_series_picks_frames() {
    let path = fixture("series4d.mha");
    for t in 0..3 {
        let l = read(&path, &frame(t)).unwrap();
        check_values(&l.volume, |i, j, k| {
            (ramp(i, j, k) + 1000 * t as i64) as f32
        });
        assert_eq!((l.info.frames, l.info.frame), (3, t));
        assert!(
            has_note(&l, &format!("volume {t} of 3 along the 4th axis")),
            "{:?}",
            l.info.notes
        );
    }
    let l = load("series4d.mha");
    assert_eq!(l.info.frame, 0);
    let err = read(&path, &frame(3)).unwrap_err();
    assert_frame_out_of_range(&err, 3, "the file holds 3 volumes (frames 0 to 2)");
    assert_eq!(
        err.to_string(),
        format!(
            "{}: frame 3 is out of range: the file holds 3 volumes (frames 0 to 2), numbered from 0",
            path.display()
        )
    );
}

#[test]
fn big_endian_data() {
    let l = load("be_i16.mhd");
    check_values(&l.volume, |i, j, k| -ramp(i, j, k) as f32);
    assert_eq!(l.info.stored_type, "MET_SHORT (i16, big-endian)");
}

#[test]
fn header_size_forward_and_from_the_end() {
    let l = load("headersize.mhd");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    check_default_geometry(&l);
    check_values(&load("tail.mhd").volume, |i, j, k| ramp(i, j, k) as f32);
}

#[test]
fn list_and_numbered_data_files() {
    let l = load("list.mhd");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    assert!(has_note(&l, "data read from 5 files"));
    let l = load("pattern.mhd");
    check_values(&l.volume, |i, j, k| small(i, j, k) as f32);
    check_default_geometry(&l);
}

#[test]
fn text_data() {
    let l = load("text.mha");
    check_values(&l.volume, |i, j, k| -ramp(i, j, k) as f32);
    assert_eq!(l.info.stored_type, "MET_SHORT (i16)");
}

#[test]
fn vector_images_are_read_a_channel_at_a_time() {
    // SimpleITK's vector image: the ramp in each of 3 channels.
    let path = fixture("vector.mha");
    for c in 0..3 {
        let l = read(&path, &common::at(0, c)).unwrap();
        check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
        assert_eq!((l.info.channels, l.info.channel), (3, c));
        check_default_geometry(&l);
    }
    let err = read(&path, &common::at(0, 3)).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: channel 3 is out of range: the file holds 3 channels (ElementNumberOfChannels), numbered from 0",
            path.display()
        )
    );
    // Each voxel's values together, as MetaIO stores them: channel c of
    // voxel n holds 10n + c.
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = b"ObjectType = Image\nNDims = 3\nDimSize = 2 3 2\nElementNumberOfChannels = 2\nElementType = MET_SHORT\nElementDataFile = LOCAL\n".to_vec();
    bytes.extend((0..24i16).flat_map(|i| (10 * (i / 2) + i % 2).to_le_bytes()));
    let two = dir.path().join("two.mha");
    fs::write(&two, bytes).unwrap();
    for c in 0..2 {
        let l = read(&two, &common::at(0, c)).unwrap();
        check_voxels("two.mha", &l.volume, [2, 3, 2], |x, y, z| {
            (10 * (x + 2 * (y + 3 * z)) + c) as f32
        });
    }
    // A 4-D series of vectors is refused.
    let four = dir.path().join("four.mha");
    fs::write(
        &four,
        b"NDims = 4\nDimSize = 2 2 2 2\nElementNumberOfChannels = 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
    )
    .unwrap();
    let err = read(&four, &ReadOptions::default()).unwrap_err();
    assert!(
        err.to_string()
            .contains("ElementNumberOfChannels = 2: volray reads"),
        "{err}"
    );
}

#[test]
fn found_by_content_without_extension() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("volume.dat");
    fs::copy(fixture("i16_zlib.mha"), &p).unwrap();
    let l = read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(l.format, VolumeFormat::MetaImage);
    check_values(&l.volume, |i, j, k| -ramp(i, j, k) as f32);
}

// ---- malformed files ----

/// A header with `fields` before `ElementType = MET_UCHAR` and LOCAL data.
fn mha(fields: &str, data: &[u8]) -> Vec<u8> {
    let mut b =
        format!("ObjectType = Image\n{fields}\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n")
            .into_bytes();
    b.extend_from_slice(data);
    b
}

#[test]
fn truncated_and_lying_sizes_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = fs::read(fixture("f32.mha")).unwrap();
    refuse(
        d,
        "short.mha",
        &good[..good.len() - 4],
        "60 samples of f32 (240 bytes)",
    );
    refuse(
        d,
        "lying.mha",
        &mha("NDims = 3\nDimSize = 100000 100000 100000", &[0; 60]),
        "the file has only 60 bytes there",
    );
    refuse(
        d,
        "huge.mha",
        &mha("NDims = 3\nDimSize = 18446744073709551615 2 2", &[0; 60]),
        "describe more data than this machine can address",
    );

    // Compressed: the declared size is checked against the stream.
    let z = fs::read(fixture("i16_zlib.mha")).unwrap();
    let dims = |to: &str| replace(&z, "DimSize = 4 3 5", to);
    refuse(
        d,
        "zbig.mha",
        &dims("DimSize = 400 300 500"),
        "cannot inflate to more than",
    );
    refuse(
        d,
        "zshort.mha",
        &dims("DimSize = 4 3 6"),
        "zlib data inflates to 120 bytes, but the header declares 144",
    );
    let text = String::from_utf8_lossy(&z);
    let size_at = text.find("CompressedDataSize = ").unwrap() + 21;
    let size_end = size_at + text[size_at..].find('\n').unwrap();
    let lying = [&z[..size_at], b"99999", &z[size_end..]].concat();
    refuse(
        d,
        "zsize.mha",
        &lying,
        "MetaImage field CompressedDataSize = 99999 but only",
    );
    let n = z.len();
    refuse(
        d,
        "corrupt.mha",
        &scrambled(&z, n - 40..n - 10),
        "zlib data",
    );
}

#[test]
fn bad_fields_name_field_and_value() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data = [0u8; 60];
    let tube = String::from_utf8(mha("NDims = 3\nDimSize = 4 3 5", &data))
        .unwrap()
        .replace("= Image", "= Tube");
    refuse(
        d,
        "notimage.mha",
        tube.as_bytes(),
        "MetaImage field ObjectType = Tube: not an image",
    );
    refuse(
        d,
        "ndims.mha",
        &mha("NDims = 5\nDimSize = 4 3 1 1 1", &data),
        "MetaImage field NDims = 5: volray reads 3-D volumes",
    );
    refuse(
        d,
        "dimsize.mha",
        &mha("NDims = 3\nDimSize = 4 3", &data),
        "MetaImage field DimSize: 2 values but 3 are needed",
    );
    refuse(
        d,
        "dim0.mha",
        &mha("NDims = 3\nDimSize = 4 0 5", &data),
        "MetaImage field DimSize: axis 1 has size 0",
    );
    refuse(
        d,
        "nodims.mha",
        &mha("NDims = 3", &data),
        "MetaImage header has no DimSize field",
    );
    refuse(
        d,
        "spacing.mha",
        &mha(
            "NDims = 3\nDimSize = 4 3 5\nElementSpacing = 1 nan 1",
            &data,
        ),
        "MetaImage field ElementSpacing: \"nan\" is not a finite number",
    );
    refuse(
        d,
        "zero.mha",
        &mha("NDims = 3\nDimSize = 4 3 5\nElementSpacing = 1 0 1", &data),
        "grid step along index axis 1",
    );
    refuse(
        d,
        "matrix.mha",
        &mha(
            "NDims = 3\nDimSize = 4 3 5\nTransformMatrix = 1 0 0 0 1 0",
            &data,
        ),
        "MetaImage field TransformMatrix: 6 values but 9 are needed",
    );
    refuse(
        d,
        "skew.mha",
        &mha(
            "NDims = 3\nDimSize = 4 3 5\nTransformMatrix = 1 0 0 1 1 0 0 0 1",
            &data,
        ),
        "grid axes 0 and 1 meet at 45.000 degrees",
    );
    refuse(
        d,
        "msb.mha",
        &mha(
            "NDims = 3\nDimSize = 4 3 5\nBinaryDataByteOrderMSB = maybe",
            &data,
        ),
        "BinaryDataByteOrderMSB = maybe: expected True or False",
    );
    refuse(
        d,
        "hs.mha",
        &mha("NDims = 3\nDimSize = 4 3 5\nHeaderSize = -2", &data),
        "MetaImage field HeaderSize = -2: must be -1",
    );
    refuse(
        d,
        "hs2.mha",
        &mha("NDims = 3\nDimSize = 4 3 5\nHeaderSize = 5000", &data),
        "skipping 5000 bytes",
    );
    refuse(
        d,
        "hs3.mha",
        &mha(
            "NDims = 3\nDimSize = 4 3 5\nHeaderSize = -1\nCompressedData = True",
            &data,
        ),
        "HeaderSize = -1 with compressed data needs CompressedDataSize",
    );
    refuse(
        d,
        "text.mha",
        &mha(
            "NDims = 3\nDimSize = 2 2 2\nBinaryData = False",
            b"1 2 3 4 5 6 7 x",
        ),
        "text value 8 is \"x\", not a number",
    );
    refuse(
        d,
        "noend.mha",
        b"ObjectType = Image\nNDims = 3\nDimSize = 4 3 5\n",
        "has no ElementDataFile field",
    );

    let mut typed =
        b"NDims = 3\nDimSize = 4 3 5\nElementType = MET_STRING\nElementDataFile = LOCAL\n".to_vec();
    typed.extend(data);
    refuse(
        d,
        "type.mha",
        &typed,
        "MetaImage field ElementType = MET_STRING: not a numeric type",
    );

    let err = read(&fixture("f32.mha"), &frame(1)).unwrap_err();
    assert_frame_out_of_range(&err, 1, "the file holds 1 volume (frames 0 to 0)");
}

#[test]
fn bad_data_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let head = "NDims = 3\nDimSize = 4 3 5\nElementType = MET_UCHAR\n";
    // A missing data file is the operating system's error, about that file.
    let p = d.join("gone.mhd");
    fs::write(&p, format!("{head}ElementDataFile = gone.raw\n")).unwrap();
    let err = error_about(&p, &ReadOptions::default(), &d.join("gone.raw"));
    assert!(err.is_io_failure(), "{err}");

    refuse(
        d,
        "list.mhd",
        format!("{head}ElementDataFile = LIST\na.raw\nb.raw\n").as_bytes(),
        "LIST names 2 files, but 5 pieces of 2-D data are needed",
    );
    refuse(
        d,
        "pattern.mhd",
        format!("{head}ElementDataFile = s%d.raw 1 3 1\n").as_bytes(),
        "3 numbered files, but DimSize needs 5 slices",
    );
    refuse(
        d,
        "pattern2.mhd",
        format!("{head}ElementDataFile = s%d.raw 5 1 1\n").as_bytes(),
        "5 to 1 in steps of 1 is not a series",
    );
    refuse(
        d,
        "pattern3.mhd",
        format!("{head}ElementDataFile = s%f.raw 1 5 1\n").as_bytes(),
        "only %d conversions are supported",
    );

    let raw = d.join("short.raw");
    fs::write(&raw, [0u8; 50]).unwrap();
    let p = d.join("short.mhd");
    fs::write(&p, format!("{head}ElementDataFile = short.raw\n")).unwrap();
    let err = error_about(&p, &ReadOptions::default(), &raw);
    assert!(!err.is_io_failure(), "{err}");
    assert!(
        err.to_string().contains("60 samples of u8 (60 bytes)"),
        "{err}"
    );
}

/// Hostile input: truncations of attached fixtures, and header bytes
/// replaced by characters that change numbers and structure, must give a
/// volume or a one-line error: never a panic, never an allocation the
/// file cannot back.
#[test]
fn no_panic_on_truncated_or_corrupted_files() {
    let fixtures = ["f32.mha", "i16_zlib.mha", "series4d.mha", "text.mha"].map(fixture);
    common::header_edits_never_panic(&fixtures, 0, b"9-\n =", |bytes| {
        let end = b"ElementDataFile = LOCAL\n";
        bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len()
    });
}

/// Sizes whose products overflow are refused, 4-D ones included.
#[test]
fn overflowing_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let max = u64::MAX;
    refuse(
        dir.path(),
        "o.mha",
        &mha(&format!("NDims = 4\nDimSize = {max} {max} 2 2"), &[0; 8]),
        "describe more data than this machine can address",
    );
}
