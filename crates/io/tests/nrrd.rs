//! Reads the NRRD files that pynrrd (and, for the forms pynrrd cannot
//! write, the fixture script around NumPy bytes) wrote, see
//! `fixtures/make_nrrd_fixtures.py`, which also checks each file with
//! pynrrd and SimpleITK. Every voxel is compared with the formula the file
//! was made from; geometry and `FileInfo` with what the header says.
//! Malformed variants made here must fail with specific one-line errors.

mod common;

use std::fs;
use std::path::PathBuf;

use common::{
    Grid, assert_frame_out_of_range, check_voxels, check_world, error_about, frame, has_note,
    header_value, ramp, refuse, replace, scrambled,
};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read, write_nrrd};

fn fixture(name: &str) -> PathBuf {
    common::fixture("nrrd", name)
}

fn load(name: &str) -> Loaded {
    read(&fixture(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The fixtures' 4 x 3 x 5 grid, file index (i, j, k), i fastest.
const SIZES: [usize; 3] = [4, 3, 5];

fn small(i: usize, j: usize, k: usize) -> i64 {
    (i + 2 * j + 6 * k) as i64
}

/// Every voxel of a volume whose axes are the file's axes.
fn check_values(v: &Volume, f: impl Fn(usize, usize, usize) -> f32) {
    check_voxels("", v, SIZES, f);
}

#[test]
fn float_lps_with_origin_units_and_key_values() {
    let l = load("f32_lps.nrrd");
    assert_eq!(l.format, VolumeFormat::Nrrd);
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 1.25, 2.0));
    assert_eq!(l.volume.origin(), DVec3::new(1.0, -2.0, 3.0));
    assert_eq!(l.info.stored_type, "float (f32, little-endian)");
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_eq!((l.info.frames, l.info.frame), (1, 0));
    assert_eq!(header_value(&l, "space"), "left-posterior-superior");
    assert_eq!(
        header_value(&l, "space directions"),
        "(0.5,0,0) (0,1.25,0) (0,0,2)"
    );
    assert_eq!(header_value(&l, "patient"), "anonymous");
    assert_eq!(l.info.header[0].0, "type");
    assert!(has_note(
        &l,
        "left-posterior-superior space (+x left, +y posterior, +z superior), kept as written"
    ));
}

#[test]
fn uchar_gzip_with_spacings_and_node_axis_mins() {
    let l = load("u8_gzip.nrrd");
    check_values(&l.volume, |i, j, k| small(i, j, k) as f32);
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 1.0, 2.0));
    assert_eq!(l.volume.origin(), DVec3::new(10.0, 20.0, 30.0));
    assert_eq!(l.info.stored_type, "uint8 (u8)");
    assert_eq!(l.info.length_unit.as_deref(), Some("cm"));
    assert!(l.info.notes.is_empty(), "{:?}", l.info.notes);
}

#[test]
fn short_big_endian_gzip_with_permuted_flipped_axes() {
    let l = load("i16_be_gzip.nrrd");
    let steps = [
        DVec3::new(0.0, 0.0, -2.0),
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.0, 1.5, 0.0),
    ];
    let grid = Grid {
        n: SIZES,
        steps,
        origin: DVec3::new(10.0, 20.0, 30.0),
    };
    // Index axis 1 runs along x, 2 along y, 0 backwards along z.
    assert_eq!(l.volume.dims(), [3, 5, 4]);
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 1.5, 2.0));
    assert_eq!(l.volume.origin(), DVec3::new(10.0, 20.0, 24.0));
    check_world("", &l.volume, &grid, 1e-12, |i, j, k| -ramp(i, j, k) as f32);
    assert_eq!(l.info.stored_type, "int16 (i16, big-endian)");
    assert!(
        has_note(
            &l,
            "index axis 0 -> -z, index axis 1 -> +x, index axis 2 -> +y"
        ),
        "{:?}",
        l.info.notes
    );
    assert!(has_note(&l, "right-anterior-superior space"));
}

#[test]
fn ushort_ascii_cell_centred_by_default() {
    let l = load("u16_ascii.nrrd");
    check_values(&l.volume, |i, j, k| (100 * ramp(i, j, k)) as f32);
    assert_eq!(l.volume.spacing(), DVec3::splat(2.0));
    // Without centers, axis mins are cell edges: the first sample is half a spacing in.
    assert_eq!(l.volume.origin(), DVec3::splat(1.0));
    assert_eq!(l.info.stored_type, "uint16 (u16)");
    assert!(has_note(&l, "cell-centred"), "{:?}", l.info.notes);
}

#[test]
fn detached_raw_and_gzip() {
    let l = load("f64_be.nhdr");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32 / 8.0);
    assert_eq!(l.info.stored_type, "double (f64, big-endian)");
    let l = load("i32_gz.nhdr");
    check_values(&l.volume, |i, j, k| (1000 * ramp(i, j, k) - 50000) as f32);
    assert_eq!(l.info.stored_type, "int32 (i32, little-endian)");
}

#[test]
fn bzip2_attached_and_detached() {
    let l = load("bz2_i16.nrrd");
    check_values(&l.volume, |i, j, k| -(ramp(i, j, k) as f32));
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 1.0, 2.0));
    assert_eq!(l.info.stored_type, "int16 (i16, little-endian)");
    let l = load("bz2_f32.nhdr");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32 / 4.0);
    assert_eq!(l.info.stored_type, "float (f32, big-endian)");
}

/// bzip2 data whose header lies about its size, or whose stream is cut or
/// garbled: one line naming the file, nothing allocated for the lie.
#[test]
fn lying_truncated_and_corrupt_bzip2_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bz = fs::read(fixture("bz2_i16.nrrd")).unwrap();
    let sizes = |to: &str| replace(&bz, "sizes: 4 3 5", to);
    refuse(
        d,
        "bzshort.nrrd",
        &sizes("sizes: 4 3 6"),
        "bzip2 data inflates to 120 bytes, but the header declares 144",
    );
    refuse(
        d,
        "bzlong.nrrd",
        &sizes("sizes: 4 3 4"),
        "bzip2 data inflates past the 96 bytes",
    );
    // Far more than the stream's bytes could ever decode to: refused
    // before reading; within bzip2's ratio but over --max-memory: refused
    // by the memory limit, not by decoding into a huge buffer.
    refuse(
        d,
        "bzhuge.nrrd",
        &sizes("sizes: 100000 100000 100000"),
        "bzip2-compressed bytes cannot decode to more than",
    );
    let big = sizes("sizes: 1000 1000 100");
    let path = d.join("bzbig.nrrd");
    fs::write(&path, &big).unwrap();
    let opts = ReadOptions {
        max_memory: 1 << 20,
        ..ReadOptions::default()
    };
    let err = common::error_about(&path, &opts, &path).to_string();
    assert!(err.contains("memory"), "{err}");
    // Cut short, and garbled.
    let n = bz.len();
    refuse(d, "bzcut.nrrd", &bz[..n - 20], "corrupt bzip2 data");
    refuse(
        d,
        "bzgarbled.nrrd",
        &scrambled(&bz, n - 60..n - 30),
        "bzip2 data",
    );
}

#[test]
fn other_sample_types() {
    check_values(&load("i8.nrrd").volume, |i, j, k| {
        (small(i, j, k) - 16) as f32
    });
    check_values(&load("u32_be.nrrd").volume, |i, j, k| {
        (100_000 * ramp(i, j, k)) as u32 as f32
    });
    check_values(&load("i64.nrrd").volume, |i, j, k| {
        (1_000_000_000_000 * ramp(i, j, k) - 7) as f32
    });
    let l = load("u64_be.nrrd");
    check_values(&l.volume, |i, j, k| {
        ((1u64 << 40) * ramp(i, j, k) as u64 + 3) as f32
    });
    assert_eq!(l.info.stored_type, "uint64 (u64, big-endian)");
}

#[test]
fn four_d_vector_axis_first_holds_the_channels() {
    let path = fixture("vector4d.nrrd");
    let l = load("vector4d.nrrd");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    assert_eq!((l.info.frames, l.info.frame), (2, 0));
    assert_eq!((l.info.time_points, l.info.channels), (1, 2));
    assert!(
        has_note(&l, "channel 0 of 2 along axis 0 (kind 2-vector)"),
        "{:?}",
        l.info.notes
    );
    let l = read(&path, &common::at(0, 1)).unwrap();
    check_values(&l.volume, |i, j, k| (ramp(i, j, k) + 1000) as f32);
    assert_eq!((l.info.channel, l.info.frame), (1, 1));
    let err = read(&path, &common::at(0, 2)).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: channel 2 is out of range: the file holds 2 channels (kind 2-vector, frames 0 to 1), numbered from 0",
            path.display()
        )
    );
    // Its one time point: --frame 1 is out of range.
    let err = read(&path, &frame(1)).unwrap_err();
    assert_frame_out_of_range(&err, 1, "the file holds 1 time point");
}

#[test]
fn four_d_time_axis_last_picks_frames() {
    let path = fixture("time4d.nrrd");
    for t in 0..3 {
        let l = read(&path, &frame(t)).unwrap();
        check_values(&l.volume, |i, j, k| {
            (ramp(i, j, k) + 1000 * t as i64) as f32
        });
        assert_eq!(l.volume.spacing(), DVec3::ONE);
        assert_eq!(l.info.frames, 3);
        assert!(
            has_note(&l, "along axis 3 (kind time)"),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn line_skip_byte_skip_and_data_at_the_end() {
    check_values(&load("skips.nhdr").volume, |i, j, k| ramp(i, j, k) as f32);
    check_values(&load("tail.nhdr").volume, |i, j, k| ramp(i, j, k) as f32);
    // With gzip the byte skip applies to the inflated stream.
    check_values(&load("gz_skip.nhdr").volume, |i, j, k| ramp(i, j, k) as f32);
}

#[test]
fn hex_encoding() {
    check_values(&load("hex_i16.nrrd").volume, |i, j, k| {
        -ramp(i, j, k) as f32
    });
}

#[test]
fn list_and_numbered_data_files() {
    let l = load("list.nhdr");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    assert_eq!(l.volume.spacing(), DVec3::new(1.0, 1.0, 3.0));
    assert!(has_note(&l, "data read from 5 files, 12 samples each"));
    let l = load("series.nhdr");
    check_values(&l.volume, |i, j, k| small(i, j, k) as f32);
}

#[test]
fn rotated_axes_are_kept_and_noted() {
    let l = load("rotated.nrrd");
    check_values(&l.volume, |i, j, k| ramp(i, j, k) as f32);
    assert!((l.volume.spacing() - DVec3::ONE).length() < 1e-12);
    assert!(
        has_note(&l, "rotation is not applied"),
        "{:?}",
        l.info.notes
    );
}

/// The volume of `volray_written.nrrd` (see the fixture script).
fn written_volume() -> Volume {
    Volume::from_fn(
        [4, 3, 2],
        DVec3::new(0.5, 0.25, 2.0),
        DVec3::new(-1.0, 2.0, 0.5),
        |p| (p.x + 2.0 * p.y + 3.0 * p.z) as f32,
    )
    .unwrap()
}

/// `volray_written.nrrd` was written by `write_nrrd` and checked by the
/// fixture script with pynrrd and SimpleITK; the writer must still write
/// exactly those bytes, and they must read back to the volume.
#[test]
fn writer_output_is_stable_and_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("w.nrrd");
    let v = written_volume();
    write_nrrd(&out, &v).unwrap();
    assert_eq!(
        fs::read(&out).unwrap(),
        fs::read(fixture("volray_written.nrrd")).unwrap()
    );
    let back = read(&out, &ReadOptions::default()).unwrap();
    assert_eq!(back.volume, v);
    assert_eq!(back.info.frames, 1);
}

#[test]
fn found_by_magic_without_extension() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("volume.dat");
    fs::copy(fixture("u8_gzip.nrrd"), &p).unwrap();
    let l = read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(l.format, VolumeFormat::Nrrd);
    check_values(&l.volume, |i, j, k| small(i, j, k) as f32);
}

// ---- malformed files ----

fn header(fields: &str) -> Vec<u8> {
    format!("NRRD0004\n{fields}\n").into_bytes()
}

#[test]
fn truncated_and_lying_sizes_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = fs::read(fixture("f32_lps.nrrd")).unwrap();
    refuse(
        d,
        "short.nrrd",
        &good[..good.len() - 10],
        "60 samples of f32 (240 bytes)",
    );
    refuse(
        d,
        "short2.nrrd",
        &good[..good.len() - 10],
        "the file has only 230 bytes there",
    );

    let mut lying = header(
        "type: float\ndimension: 3\nsizes: 100000 100000 100000\nendian: little\nencoding: raw\n",
    );
    lying.extend([0u8; 64]);
    refuse(d, "lying.nrrd", &lying, "the file has only 64 bytes there");
    let mut huge = header(
        "type: float\ndimension: 3\nsizes: 18446744073709551615 2 2\nendian: little\nencoding: raw\n",
    );
    huge.extend([0u8; 64]);
    refuse(
        d,
        "huge.nrrd",
        &huge,
        "describe more data than this machine can address",
    );

    // gzip: a lying size is caught by deflate's ratio or by the stream's end.
    let gz = fs::read(fixture("u8_gzip.nrrd")).unwrap();
    let sizes = |to: &str| replace(&gz, "sizes: 4 3 5", to);
    refuse(
        d,
        "gzbig.nrrd",
        &sizes("sizes: 400 300 500"),
        "cannot inflate to more than",
    );
    refuse(
        d,
        "gzshort.nrrd",
        &sizes("sizes: 4 3 6"),
        "gzip data inflates to 60 bytes, but the header declares 72",
    );
    refuse(
        d,
        "gzlong.nrrd",
        &sizes("sizes: 4 3 4"),
        "gzip data inflates past the 48 bytes",
    );
    let n = gz.len();
    refuse(
        d,
        "corrupt.nrrd",
        &scrambled(&gz, n - 30..n - 10),
        "gzip data",
    );
}

#[test]
fn bad_header_fields_name_field_and_value() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data = [0u8; 480];
    let with_data = |fields: &str| {
        let mut b = header(fields);
        b.extend(data);
        b
    };
    refuse(
        d,
        "magic.nrrd",
        b"NRRX0004\n\n",
        "not a NRRD file: it starts with \"NRRX0004\"",
    );
    refuse(
        d,
        "notype.nrrd",
        &with_data("dimension: 3\nsizes: 4 3 5\nencoding: raw\n"),
        "NRRD header has no \"type\" field",
    );
    refuse(
        d,
        "sizes.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3\nencoding: raw\n"),
        "NRRD field \"sizes\": 2 values but dimension is 3",
    );
    refuse(
        d,
        "size0.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 0 5\nencoding: raw\n"),
        "NRRD field \"sizes\": axis 1 has size 0",
    );
    refuse(
        d,
        "dim2.nrrd",
        &with_data("type: uchar\ndimension: 2\nsizes: 4 3\nencoding: raw\n"),
        "a 2-D image (4 x 3 samples), not a volume",
    );
    refuse(
        d,
        "dim1.nrrd",
        &with_data("type: uchar\ndimension: 1\nsizes: 12\nencoding: raw\n"),
        "NRRD field \"dimension\": 1: volray reads 3-D volumes",
    );
    refuse(
        d,
        "block.nrrd",
        &with_data("type: block\nblock size: 4\ndimension: 3\nsizes: 4 3 5\nencoding: raw\n"),
        "\"block\" samples are opaque",
    );
    refuse(
        d,
        "bz.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: bzip2\n"),
        "corrupt bzip2 data",
    );
    refuse(
        d,
        "enc.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: zip\n"),
        "unknown encoding \"zip\"",
    );
    refuse(
        d,
        "endian.nrrd",
        &with_data("type: short\ndimension: 3\nsizes: 4 3 5\nencoding: raw\n"),
        "NRRD field \"endian\" is missing: short data in raw encoding needs it",
    );
    refuse(
        d,
        "endian2.nrrd",
        &with_data("type: short\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nendian: middle\n"),
        "\"middle\" is neither little nor big",
    );
    refuse(
        d,
        "skip.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: gzip\nbyte skip: -1\n"),
        "works with raw encoding only, not gzip",
    );
    refuse(
        d,
        "skip2.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nbyte skip: 1000\n"),
        "skipping 1000 bytes",
    );
    refuse(
        d,
        "lines.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nline skip: 3\n"),
        "3 lines to skip but the file ends after 0",
    );
    refuse(
        d,
        "spacings.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspacings: 1 x 1\n"),
        "NRRD field \"spacings\": \"x\" is not a number",
    );
    refuse(
        d,
        "zero.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspacings: 1 0 1\n"),
        "grid step along index axis 1",
    );
    refuse(
        d,
        "kind.nrrd",
        &with_data(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nkinds: domain RGB-color domain\n",
        ),
        "axis 1 has kind RGB-color, but a 3-D file needs three spatial axes",
    );
    refuse(
        d,
        "kind2.nrrd",
        &with_data(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nkinds: domain banana domain\n",
        ),
        "unknown kind \"banana\"",
    );
    refuse(
        d,
        "none3.nrrd",
        &with_data(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspace dimension: 3\nspace directions: (1,0,0) none (0,0,1)\n",
        ),
        "axis 1 has no spatial direction",
    );
    refuse(
        d,
        "none4.nrrd",
        &with_data(
            "type: uchar\ndimension: 4\nsizes: 2 2 3 5\nencoding: raw\nspace dimension: 3\nspace directions: none none (0,1,0) (0,0,1)\n",
        ),
        "2 axes have no spatial direction",
    );
    refuse(
        d,
        "nospace.nrrd",
        &with_data(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n",
        ),
        "given without \"space\" or \"space dimension\"",
    );
    refuse(
        d,
        "sd2.nrrd",
        &with_data("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspace dimension: 2\n"),
        "NRRD field \"space dimension\": 2",
    );
    refuse(
        d,
        "space.nrrd",
        &with_data(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspace: up-down-sideways\n",
        ),
        "unknown space \"up-down-sideways\"",
    );
    refuse(
        d,
        "skew.nrrd",
        &with_data(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\nspace: RAS\nspace directions: (1,0,0) (1,1,0) (0,0,1)\n",
        ),
        "grid axes 0 and 1 meet at 45.000 degrees",
    );
    refuse(
        d,
        "noblank.nrrd",
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw",
        "ends without the blank line",
    );
    refuse(
        d,
        "hex.nrrd",
        &[
            header("type: uchar\ndimension: 3\nsizes: 1 1 2\nencoding: hex\n"),
            b"0g".to_vec(),
            vec![b'0'; 10],
        ]
        .concat(),
        "'g', not a hex digit",
    );
    refuse(
        d,
        "text.nrrd",
        &[
            header("type: float\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n"),
            b"1 2 3 4 5 6 7 eight".to_vec(),
        ]
        .concat(),
        "text value 8 is \"eight\", not a number",
    );
}

#[test]
fn frame_on_a_single_volume_and_bad_data_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let err = read(&fixture("f32_lps.nrrd"), &frame(1)).unwrap_err();
    assert_frame_out_of_range(&err, 1, "the file holds 1 volume (frames 0 to 0)");

    // A missing data file is the operating system's error, about that file.
    let p = d.join("gone.nhdr");
    fs::write(
        &p,
        header("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: gone.raw\n"),
    )
    .unwrap();
    let err = error_about(&p, &ReadOptions::default(), &d.join("gone.raw"));
    assert!(err.is_io_failure(), "{err}");

    refuse(
        d,
        "list.nhdr",
        &header(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: LIST\na.raw\nb.raw\n",
        ),
        "2 files, but 5 pieces of 2-D data are needed",
    );
    refuse(
        d,
        "list0.nhdr",
        &header("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: LIST\n"),
        "LIST names no files",
    );
    refuse(
        d,
        "series.nhdr",
        &header(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: s%d.raw 1 4 1\n",
        ),
        "4 numbered files, but 5 pieces of 2-D data are needed",
    );
    refuse(
        d,
        "series2.nhdr",
        &header(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: s%d.raw 5 1 1\n",
        ),
        "5 to 1 in steps of 1 is not a series",
    );
    refuse(
        d,
        "series3.nhdr",
        &header(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: s%s.raw 1 5 1\n",
        ),
        "only %d conversions are supported",
    );
    refuse(
        d,
        "series4.nhdr",
        &header(
            "type: uchar\ndimension: 3\nsizes: 4 3 4294967296\nencoding: raw\ndata file: s%d.raw 1 4294967296 1\n",
        ),
        "more than volray reads",
    );
    refuse(
        d,
        "subdim.nhdr",
        &header(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: LIST 7\na.raw\n",
        ),
        "data file dimension \"7\" is not 1 to 3",
    );

    // A data file shorter than its share names the data file.
    let raw = d.join("short.raw");
    fs::write(&raw, [0u8; 50]).unwrap();
    let p = d.join("short.nhdr");
    fs::write(
        &p,
        header("type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: raw\ndata file: short.raw\n"),
    )
    .unwrap();
    let err = error_about(&p, &ReadOptions::default(), &raw);
    assert!(!err.is_io_failure(), "{err}");
    assert!(
        err.to_string().contains("60 samples of u8 (60 bytes)"),
        "{err}"
    );
}

/// Hostile input: truncations of attached fixtures, and header bytes
/// (after the magic) replaced by characters that change numbers and
/// structure, must give a volume or a one-line error: never a panic, never
/// an allocation the file cannot back.
#[test]
fn no_panic_on_truncated_or_corrupted_files() {
    let fixtures = [
        "f32_lps.nrrd",
        "u8_gzip.nrrd",
        "vector4d.nrrd",
        "u16_ascii.nrrd",
        "hex_i16.nrrd",
    ]
    .map(fixture);
    common::header_edits_never_panic(&fixtures, 9, b"9-\n ", |bytes| {
        bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2
    });
}

/// Sizes whose products overflow are refused, whichever axis holds the
/// volumes and whatever the encoding.
#[test]
fn overflowing_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let max = u64::MAX;
    refuse(
        d,
        "o1.nrrd",
        &header(&format!(
            "type: uchar\ndimension: 4\nsizes: {max} {max} 2 2\nkinds: domain domain domain time\nencoding: raw\n"
        )),
        "describe more data than this machine can address",
    );
    refuse(
        d,
        "o2.nrrd",
        &header(&format!(
            "type: uchar\ndimension: 3\nsizes: {max} 1 1\nencoding: ascii\n"
        )),
        "cannot hold that many numbers",
    );
    refuse(
        d,
        "o3.nrrd",
        &header(&format!(
            "type: uchar\ndimension: 3\nsizes: 4 3 5\nencoding: gzip\nbyte skip: {}\n",
            i64::MAX
        )),
        "cannot inflate to more than",
    );
}
