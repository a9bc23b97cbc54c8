//! Reads NIfTI-1 and NIfTI-2 files written by nibabel (see
//! `fixtures/make_nifti_fixtures.py`) and checks every voxel, the geometry
//! and what `FileInfo` reports; then feeds the reader broken variants made
//! here and checks that each is refused with a specific one-line message.
//!
//! Every fixture has shape (4, 3, 5) with ramp(i, j, k) = i + 10j + 100k,
//! stored through a per-type formula (the script's `TYPES` table). The
//! geometry check is independent of how the reader lays out the volume:
//! for each file index (i, j, k) it computes the world position from the
//! affine nibabel was given, finds the volume voxel at that position, and
//! compares the value there.

mod common;

use std::io::Write;
use std::path::PathBuf;

use common::{
    Grid, assert_frame_out_of_range, error_about, frame, has_note, header_value, ramp,
    refused_file, scrambled, typed,
};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

const SHAPE: [usize; 3] = [4, 3, 5];

type Affine = [[f64; 4]; 3];

const ALIGNED: Affine = [
    [0.5, 0.0, 0.0, -1.0],
    [0.0, 2.0, 0.0, 2.0],
    [0.0, 0.0, 1.5, 3.0],
];
const FLIPPED: Affine = [
    [-1.0, 0.0, 0.0, 3.0],
    [0.0, -1.0, 0.0, 2.0],
    [0.0, 0.0, 2.0, 0.0],
];
const PERMUTED: Affine = [
    [0.0, -0.5, 0.0, 4.0],
    [2.0, 0.0, 0.0, -3.0],
    [0.0, 0.0, 1.0, 1.0],
];

fn fixture(name: &str) -> PathBuf {
    common::fixture("nifti", name)
}

fn load(name: &str) -> Loaded {
    load_with(name, &ReadOptions::default())
}

fn load_with(name: &str, opts: &ReadOptions) -> Loaded {
    let loaded = read(&fixture(name), opts).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(loaded.format, VolumeFormat::Nifti);
    loaded
}

/// Checks that the file's voxel (i, j, k), at world position
/// `affine · (i, j, k, 1)`, holds `want(i, j, k)` in the volume (to 1e-5:
/// qform quaternions are stored as f32).
fn check_world(name: &str, l: &Loaded, affine: &Affine, want: impl Fn(usize, usize, usize) -> f32) {
    let grid = Grid::from_affine(SHAPE, affine);
    common::check_world(name, &l.volume, &grid, 1e-5, want);
}

#[test]
fn every_scalar_type_nibabel_writes() {
    let names = [
        ("u8", "uint8"),
        ("i8", "int8"),
        ("u16", "uint16"),
        ("i16", "int16"),
        ("u32", "uint32"),
        ("i32", "int32"),
        ("u64", "uint64"),
        ("i64", "int64"),
        ("f32", "float32"),
        ("f64", "float64"),
    ];
    for (name, type_name) in names {
        let file = format!("{name}.nii");
        let l = load(&file);
        assert_eq!(l.volume.dims(), SHAPE, "{file}");
        assert_eq!(l.volume.spacing(), DVec3::new(0.5, 2.0, 1.5), "{file}");
        assert_eq!(l.volume.origin(), DVec3::new(-1.0, 2.0, 3.0), "{file}");
        check_world(&file, &l, &ALIGNED, |i, j, k| typed(name, ramp(i, j, k)));
        assert_eq!(l.info.stored_type, format!("{type_name} (little-endian)"));
        assert_eq!(l.info.length_unit.as_deref(), Some("mm"), "{file}");
        assert_eq!((l.info.frames, l.info.frame), (1, 0));
        assert_eq!(header_value(&l, "sizeof_hdr"), "348");
        assert_eq!(header_value(&l, "magic"), "n+1");
        assert_eq!(header_value(&l, "dim"), "3 4 3 5 1 1 1 1");
        assert_eq!(header_value(&l, "sform_code"), "2");
        assert_eq!(header_value(&l, "srow_x"), "0.5 0 0 -1");
        assert_eq!(l.info.header[0].0, "sizeof_hdr");
        assert_eq!(l.info.header.last().unwrap().0, "magic");
        assert!(
            has_note(&l, "sform (sform_code 2 = aligned)"),
            "{:?}",
            l.info.notes
        );
        // Aligned geometry needs no reordering, and nothing was scaled.
        assert!(
            !has_note(&l, "reordered") && !has_note(&l, "scaled"),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn big_endian_files() {
    for (name, type_name) in [("i16", "int16"), ("f64", "float64")] {
        let file = format!("{name}_be.nii");
        let l = load(&file);
        check_world(&file, &l, &ALIGNED, |i, j, k| typed(name, ramp(i, j, k)));
        assert_eq!(l.info.stored_type, format!("{type_name} (big-endian)"));
        assert_eq!(l.volume.spacing(), DVec3::new(0.5, 2.0, 1.5));
    }
}

#[test]
fn gzip_file_and_micrometres() {
    let l = load("f32.nii.gz");
    check_world("f32.nii.gz", &l, &ALIGNED, |i, j, k| {
        typed("f32", ramp(i, j, k))
    });
    assert_eq!(l.info.length_unit.as_deref(), Some("um"));
    assert!(has_note(&l, "gzip"), "{:?}", l.info.notes);
}

#[test]
fn scl_slope_and_inter_are_applied() {
    let l = load("scaled_i16.nii");
    check_world("scaled_i16.nii", &l, &ALIGNED, |i, j, k| {
        0.5 * ramp(i, j, k) as f32 - 10.0
    });
    assert_eq!(header_value(&l, "scl_slope"), "0.5");
    assert_eq!(header_value(&l, "scl_inter"), "-10");
    assert!(
        has_note(&l, "value = 0.5 * stored + -10"),
        "{:?}",
        l.info.notes
    );
    assert_eq!(l.info.stored_type, "int16 (little-endian)");
}

#[test]
fn qform_quaternion_permutes_axes() {
    let l = load("qform_permuted.nii");
    // i runs along +y, j along -x: the volume is 3 x 4 x 5 in world axes.
    assert_eq!(l.volume.dims(), [3, 4, 5]);
    assert!((l.volume.spacing() - DVec3::new(0.5, 2.0, 1.0)).length() < 1e-6);
    check_world("qform_permuted.nii", &l, &PERMUTED, |i, j, k| {
        typed("f32", ramp(i, j, k))
    });
    assert_eq!(l.info.length_unit.as_deref(), Some("m"));
    assert!(
        has_note(&l, "qform quaternion (qform_code 1 = scanner"),
        "{:?}",
        l.info.notes
    );
    assert!(
        has_note(&l, "index axis 0 -> +y, index axis 1 -> -x"),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn pixdim_only_without_transforms() {
    let l = load("pixdim_only.nii");
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 2.0, 1.5));
    assert_eq!(l.volume.origin(), DVec3::ZERO);
    let affine = [
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 2.0, 0.0, 0.0],
        [0.0, 0.0, 1.5, 0.0],
    ];
    check_world("pixdim_only.nii", &l, &affine, |i, j, k| {
        typed("f32", ramp(i, j, k))
    });
    assert!(has_note(&l, "method 1"), "{:?}", l.info.notes);
    assert_eq!(l.info.length_unit, None);
}

#[test]
fn flipped_lps_like_affine_is_reordered_exactly() {
    let l = load("flipped.nii");
    // i along -x from x = 3, j along -y from y = 2: the origin moves to the
    // other corner, (3 - 3, 2 - 2, 0).
    assert_eq!(l.volume.dims(), SHAPE);
    assert_eq!(l.volume.origin(), DVec3::new(0.0, 0.0, 0.0));
    assert_eq!(l.volume.spacing(), DVec3::new(1.0, 1.0, 2.0));
    check_world("flipped.nii", &l, &FLIPPED, |i, j, k| {
        typed("f32", ramp(i, j, k))
    });
    assert!(has_note(&l, "index axis 0 -> -x"), "{:?}", l.info.notes);
}

#[test]
fn oblique_affine_keeps_index_axes_and_says_so() {
    let l = load("oblique.nii");
    assert_eq!(l.volume.dims(), SHAPE);
    assert!((l.volume.spacing() - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
    assert!((l.volume.origin() - DVec3::new(5.0, 6.0, 7.0)).length() < 1e-6);
    for (n, &value) in l.volume.values().iter().enumerate() {
        let (i, j, k) = (n % 4, (n / 4) % 3, n / 12);
        assert_eq!(value, typed("f32", ramp(i, j, k)));
    }
    assert!(
        has_note(&l, "rotation is not applied"),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn four_d_files_pick_a_frame() {
    let l = load("frames4d.nii.gz");
    assert_eq!((l.info.frames, l.info.frame), (3, 0));
    check_world("frames4d", &l, &ALIGNED, |i, j, k| ramp(i, j, k) as f32);
    assert!(has_note(&l, "3 volumes"), "{:?}", l.info.notes);
    for t in 0..3 {
        let l = load_with("frames4d.nii.gz", &frame(t));
        assert_eq!((l.info.frames, l.info.frame), (3, t));
        check_world("frames4d", &l, &ALIGNED, |i, j, k| {
            (ramp(i, j, k) + 1000 * t as i64) as f32
        });
        assert!(!has_note(&l, "volume 0 was read"));
    }
    // Without a frame asked for, the note says which was read.
    assert!(has_note(&load("frames4d.nii.gz"), "volume 0 was read"));
    let err = read(&fixture("frames4d.nii.gz"), &frame(3)).unwrap_err();
    assert_frame_out_of_range(&err, 3, "the file holds 3 volumes (dim[4])");

    // A 3-D file has one frame: frame 1 is out of range, frame 0 fine.
    let err = read(&fixture("f32.nii"), &frame(1)).unwrap_err();
    assert_frame_out_of_range(&err, 1, "the file holds 1 volume (dim[4])");
}

#[test]
fn five_d_vector_components_are_channels_and_dim4_the_time_points() {
    // (4, 3, 5, 1, 3): three components, one time point.
    let l = load("vector5d.nii");
    assert_eq!((l.info.time_points, l.info.channels), (1, 3));
    assert_eq!((l.info.frames, l.info.frame), (3, 0));
    assert_eq!(header_value(&l, "dim"), "5 4 3 5 1 3 1 1");
    assert!(
        has_note(
            &l,
            "5-D: 3 components (dim[5], intent_code 1007 = vector) read as channels, x 1 time point (dim[4])"
        ),
        "{:?}",
        l.info.notes
    );
    for c in 0..3 {
        let l = load_with("vector5d.nii", &common::at(0, c));
        check_world("vector5d", &l, &ALIGNED, |i, j, k| {
            (ramp(i, j, k) + 10000 * c as i64) as f32
        });
        assert_eq!((l.info.channel, l.info.frame), (c, c));
    }
    let err = read(&fixture("vector5d.nii"), &common::at(0, 3)).unwrap_err();
    assert!(
        err.to_string().ends_with(
            "channel 3 is out of range: the file holds 3 channels (dim[5]), numbered from 0"
        ),
        "{err}"
    );
    let err = read(&fixture("vector5d.nii"), &frame(1)).unwrap_err();
    assert_frame_out_of_range(
        &err,
        1,
        "the file holds 1 time point (dim[4]) of 3 channels (dim[5]), numbered from 0",
    );
    // (4, 3, 5, 2, 3), gzip: the file's block t + 2c holds time point t
    // of component c.
    for (t, c) in (0..2).flat_map(|t| (0..3).map(move |c| (t, c))) {
        let l = load_with("vector5d_t2.nii.gz", &common::at(t, c));
        assert_eq!((l.info.frames, l.info.frame), (6, 3 * t + c));
        check_world("vector5d_t2", &l, &ALIGNED, |i, j, k| {
            (ramp(i, j, k) + 1000 * t as i64 + 10000 * c as i64) as f32
        });
        assert!(
            has_note(&l, &format!("this is time point {t}, component {c}")),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn sheared_sform_is_resampled_onto_an_orthogonal_grid() {
    // The file holds 3x - 2y + 0.5z + 7 at each voxel's world position;
    // trilinear resampling reproduces a linear function exactly inside the
    // grid's box, and the box's corners outside it are NaN.
    let sheared: Affine = [
        [1.0, 0.5, 0.0, -2.0],
        [0.0, 1.5, 0.3, 1.0],
        [0.2, 0.0, 2.0, 4.0],
    ];
    let linear = |w: DVec3| 3.0 * w.x - 2.0 * w.y + 0.5 * w.z + 7.0;
    let l = load("sheared.nii");
    assert!(l.info.nan_is_empty);
    assert!(has_note(&l, "the sform is sheared"), "{:?}", l.info.notes);
    assert!(has_note(&l, "resampled trilinearly"), "{:?}", l.info.notes);
    // About the shortest step, |(1, 0, 0.2)|, fitted to each axis's extent
    // (3 + 1 = 4 along x: 4 steps of 1; 3 + 1.2 along y; 0.6 + 8 along z).
    let s = l.volume.spacing();
    assert!((s - DVec3::new(1.0, 1.05, 1.075)).length() < 1e-6, "{s}");
    assert_eq!(l.volume.dims(), [5, 5, 9]);
    let grid = Grid::from_affine(SHAPE, &sheared);
    let to_grid =
        volray_core::glam::DMat3::from_cols(grid.steps[0], grid.steps[1], grid.steps[2]).inverse();
    // The bounding box of the sheared box: its lowest corner is the origin.
    let lo = DVec3::new(-2.0, 1.0, 4.0);
    assert!(
        (l.volume.origin() - lo).length() < 1e-6,
        "{}",
        l.volume.origin()
    );
    let [nx, ny, nz] = l.volume.dims();
    let (mut inside, mut outside) = (0, 0);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let w = l.volume.world_position(x, y, z);
                let g = to_grid * (w - grid.origin);
                let v = l.volume.get(x, y, z);
                let eps = 1e-9;
                if (0..3).all(|a| g[a] >= eps && g[a] <= (SHAPE[a] - 1) as f64 - eps) {
                    assert!(
                        (f64::from(v) - linear(w)).abs() < 1e-3,
                        "({x}, {y}, {z}): {v} vs {}",
                        linear(w)
                    );
                    inside += 1;
                } else if (0..3).any(|a| g[a] < -1e-6 || g[a] > (SHAPE[a] - 1) as f64 + 1e-6) {
                    assert!(v.is_nan(), "({x}, {y}, {z}) outside the box holds {v}");
                    outside += 1;
                }
            }
        }
    }
    assert!(
        inside > 20 && outside > 20,
        "{inside} inside, {outside} outside"
    );
    // A limit below the resampled grid refuses it, naming the sform.
    let opts = ReadOptions {
        max_memory: 1000,
        ..ReadOptions::default()
    };
    let err = read(&fixture("sheared.nii"), &opts).unwrap_err();
    assert!(err.to_string().contains("NIfTI sform (sheared)"), "{err}");
}

#[test]
fn nifti2_files() {
    let l = load("nifti2_i32.nii");
    check_world("nifti2_i32.nii", &l, &ALIGNED, |i, j, k| {
        typed("i32", ramp(i, j, k))
    });
    assert_eq!(header_value(&l, "sizeof_hdr"), "540");
    assert_eq!(header_value(&l, "magic"), "n+2");
    assert_eq!(header_value(&l, "dim"), "3 4 3 5 1 1 1 1");
    assert_eq!(l.info.header[1].0, "magic");
    assert!(has_note(&l, "NIfTI-2 header"), "{:?}", l.info.notes);

    let l = load("nifti2_f64_be.nii.gz");
    check_world("nifti2_f64_be", &l, &FLIPPED, |i, j, k| {
        typed("f64", ramp(i, j, k))
    });
    assert_eq!(l.info.stored_type, "float64 (big-endian)");

    let l = load_with("nifti2_frames4d.nii", &frame(1));
    assert_eq!(l.info.frames, 3);
    check_world("nifti2_frames4d", &l, &ALIGNED, |i, j, k| {
        (ramp(i, j, k) + 1000) as f32
    });
}

#[test]
fn header_image_pairs() {
    let l = load("pair.hdr");
    check_world("pair.hdr", &l, &ALIGNED, |i, j, k| {
        typed("u16", ramp(i, j, k))
    });
    assert_eq!(header_value(&l, "magic"), "ni1");
    assert!(has_note(&l, "header/image pair"), "{:?}", l.info.notes);

    // Without its .img the pair cannot be read: the OS error names the .img.
    let dir = tempfile::tempdir().unwrap();
    let hdr = dir.path().join("lonely.hdr");
    std::fs::copy(fixture("pair.hdr"), &hdr).unwrap();
    let err = error_about(
        &hdr,
        &ReadOptions::default(),
        &dir.path().join("lonely.img"),
    );
    assert!(err.is_io_failure(), "{err}");
}

#[test]
fn complex_data_is_refused() {
    let err = read(&fixture("complex64.nii"), &ReadOptions::default()).unwrap_err();
    assert!(!err.is_io_failure());
    assert!(
        err.to_string().contains("\"datatype\" is 32 (complex64)"),
        "{err}"
    );
}

#[test]
fn found_by_content_under_other_names() {
    let dir = tempfile::tempdir().unwrap();
    for (src, dst) in [("f32.nii", "scan.bin"), ("f32.nii.gz", "scan.dat")] {
        let p = dir.path().join(dst);
        std::fs::copy(fixture(src), &p).unwrap();
        let l = read(&p, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(l.format, VolumeFormat::Nifti);
        check_world(dst, &l, &ALIGNED, |i, j, k| typed("f32", ramp(i, j, k)));
    }
}

// ---- broken files ----

/// Writes `bytes` to a temporary `name` and returns the reader's message.
fn error_for(name: &str, bytes: &[u8]) -> String {
    refused_file(name, bytes, &ReadOptions::default())
}

fn f32_nii() -> Vec<u8> {
    std::fs::read(fixture("f32.nii")).unwrap()
}

fn put_i16(bytes: &mut [u8], offset: usize, value: i16) {
    bytes[offset..offset + 2].copy_from_slice(&value.to_le_bytes());
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

#[test]
fn truncated_data_is_refused_before_reading() {
    let mut b = f32_nii();
    b.truncate(b.len() - 10);
    let msg = error_for("t.nii", &b);
    assert!(
        msg.contains("file is 582 bytes") && msg.contains("implies 592"),
        "{msg}"
    );
}

#[test]
fn lying_dims_are_refused_without_allocating() {
    let mut b = f32_nii();
    for a in 1..=3 {
        put_i16(&mut b, 40 + 2 * a, 30000);
    }
    let msg = error_for("huge.nii", &b);
    assert!(msg.contains("implies 108000000000352"), "{msg}");

    // The same header gzipped: more than any 1 KB gzip stream can hold.
    let msg = error_for("huge.nii.gz", &gzip(&b));
    assert!(
        msg.contains("more than a") && msg.contains("gzip file can hold"),
        "{msg}"
    );

    // Dims a gzip stream could hold but does not have: the stream ends.
    let mut b = f32_nii();
    put_i16(&mut b, 46, 50);
    let msg = error_for("short.nii.gz", &gzip(&b));
    assert!(msg.contains("gzip data ends after 592 bytes"), "{msg}");
}

#[test]
fn corrupt_gzip_is_bad_input() {
    let gz = gzip(&f32_nii());
    let msg = error_for("bad.nii.gz", &scrambled(&gz, 20..gz.len() - 8));
    assert!(msg.contains("gzip"), "{msg}");
}

#[test]
fn bad_header_fields() {
    let mut b = f32_nii();
    b[0..4].copy_from_slice(&349i32.to_le_bytes());
    let msg = error_for("a.nii", &b);
    assert!(msg.contains("NIfTI field \"sizeof_hdr\" is 349"), "{msg}");

    let mut b = f32_nii();
    b[344..348].copy_from_slice(b"n+3\0");
    let msg = error_for("b.nii", &b);
    assert!(msg.contains("\"magic\" is \"n+3\\0\""), "{msg}");

    let mut b = f32_nii();
    b[344..348].copy_from_slice(&[0; 4]);
    let msg = error_for("c.nii", &b);
    assert!(msg.contains("Analyze 7.5"), "{msg}");

    let mut b = f32_nii();
    put_i16(&mut b, 40, 6);
    put_i16(&mut b, 52, 2);
    let msg = error_for("d.nii", &b);
    assert!(
        msg.contains("\"dim[6]\" is 2") && msg.contains("6-D"),
        "{msg}"
    );
    // A 5-D header whose components the file does not hold.
    let mut b = f32_nii();
    put_i16(&mut b, 40, 5);
    put_i16(&mut b, 50, 2);
    let msg = error_for("d5.nii", &b);
    assert!(
        msg.contains("file is 592 bytes") && msg.contains("implies 832"),
        "{msg}"
    );
    put_i16(&mut b, 48, 30000);
    put_i16(&mut b, 50, 30000);
    let msg = error_for("d5.nii", &b);
    assert!(msg.contains("implies 216000000352"), "{msg}");

    // dim[0] 2: the first slice, a 2-D image (tests/flat.rs), described
    // but not a volume; dim[0] 1 is no image at all.
    let mut b = f32_nii();
    put_i16(&mut b, 40, 2);
    let msg = error_for("e.nii", &b);
    assert!(
        msg.contains("a 2-D image (4 x 3 samples), not a volume"),
        "{msg}"
    );
    put_i16(&mut b, 40, 1);
    let msg = error_for("e.nii", &b);
    assert!(msg.contains("\"dim[0]\" is 1"), "{msg}");

    let mut b = f32_nii();
    put_i16(&mut b, 40, 9);
    let msg = error_for("f.nii", &b);
    assert!(msg.contains("\"dim[0]\" is 9"), "{msg}");

    let mut b = f32_nii();
    put_i16(&mut b, 44, -4);
    let msg = error_for("g.nii", &b);
    assert!(msg.contains("\"dim[2]\" is -4"), "{msg}");

    let mut b = f32_nii();
    put_i16(&mut b, 46, 1);
    let msg = error_for("h.nii", &b);
    assert!(msg.contains("a 2-D image (4 x 3 samples)"), "{msg}");

    let mut b = f32_nii();
    put_i16(&mut b, 70, 128);
    let msg = error_for("i.nii", &b);
    assert!(msg.contains("\"datatype\" is 128 (RGB24)"), "{msg}");

    let mut b = f32_nii();
    b[108..112].copy_from_slice(&100f32.to_le_bytes());
    let msg = error_for("j.nii", &b);
    assert!(msg.contains("\"vox_offset\" is 100"), "{msg}");

    // vox_offset 0 in a single file means "right after the header".
    let mut b = f32_nii();
    b[108..112].copy_from_slice(&0f32.to_le_bytes());
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("zero_offset.nii");
    std::fs::write(&p, &b).unwrap();
    let l = read(&p, &ReadOptions::default()).unwrap();
    check_world("zero_offset", &l, &ALIGNED, |i, j, k| {
        typed("f32", ramp(i, j, k))
    });
    assert!(has_note(&l, "vox_offset 0"), "{:?}", l.info.notes);

    let mut b = f32_nii();
    b[108..112].copy_from_slice(&f32::NAN.to_le_bytes());
    let msg = error_for("k.nii", &b);
    assert!(msg.contains("\"vox_offset\" is NaN"), "{msg}");

    // No sform: the qform's pixdim must be usable.
    let mut b = f32_nii();
    put_i16(&mut b, 254, 0);
    b[80..84].copy_from_slice(&0f32.to_le_bytes());
    let msg = error_for("l.nii", &b);
    assert!(msg.contains("\"pixdim[1]\" is 0"), "{msg}");

    let msg = error_for("m.nii", &f32_nii()[..200]);
    assert!(msg.contains("inside the NIfTI header"), "{msg}");
}

/// Deterministic byte flips and truncations of a few fixtures, each read
/// with and without a frame: a volume or a one-line message, never a panic.
#[test]
fn no_panic_on_truncation_or_corruption() {
    let fixtures = [
        "f32.nii",
        "nifti2_i32.nii",
        "frames4d.nii.gz",
        "qform_permuted.nii",
    ]
    .map(fixture);
    common::byte_flips_never_panic(
        &fixtures,
        0x2545_f491_4f6c_dd1d,
        &[ReadOptions::default(), frame(1)],
    );
}
