//! Reads FreeSurfer MGH and MGZ files written by nibabel (see
//! `fixtures/make_mgh_fixtures.py`): every voxel of both frames, the
//! geometry against the affine nibabel's `get_affine` gives, detection by
//! name and by content (an `.mgz` is a gzip file that inflates to an MGH
//! header, not a `.nii.gz`); then broken variants made here, each refused
//! with a one-line message.

mod common;

use std::io::Write;
use std::path::PathBuf;

use common::{Grid, frame, has_note, header_value, ramp, refused_file, typed};
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

const SHAPE: [usize; 3] = [12, 10, 8];

/// The affine the script gave nibabel, which its `get_affine` gives back.
const AFFINE: [[f64; 4]; 3] = [
    [-1.5, 0.0, 0.0, 20.0],
    [0.0, 0.0, 0.75, -31.0],
    [0.0, -2.0, 0.0, 17.5],
];

fn fixture(name: &str) -> PathBuf {
    common::fixture("mgh", name)
}

fn load_with(name: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&fixture(name), opts).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Mgh, "{name}");
    l
}

const TYPES: [(&str, &str, &str); 5] = [
    ("u8", "uint8 (MRI_UCHAR)", "0"),
    ("i16", "int16 (MRI_SHORT)", "4"),
    ("i32", "int32 (MRI_INT)", "1"),
    ("f32", "float32 (MRI_FLOAT)", "3"),
    ("u16", "uint16 (MRI_USHRT)", "10"),
];

#[test]
fn every_type_in_mgh_and_mgz_reads_both_frames_where_nibabel_puts_them() {
    let grid = Grid::from_affine(SHAPE, &AFFINE);
    for (name, type_name, code) in TYPES {
        for ext in ["mgh", "mgz"] {
            let file = format!("{name}.{ext}");
            for f in 0..2 {
                let l = load_with(&file, &frame(f));
                let what = format!("{file} frame {f}");
                // i along -x, j along -z, k along +y: 12 x 8 x 10 in world axes.
                assert_eq!(l.volume.dims(), [12, 8, 10], "{what}");
                assert_eq!(l.volume.spacing(), DVec3::new(1.5, 0.75, 2.0), "{what}");
                // The corner voxel: i = 11 (x = 20 - 16.5), k = 0 (y = -31),
                // j = 9 (z = 17.5 - 18).
                assert_eq!(l.volume.origin(), DVec3::new(3.5, -31.0, -0.5), "{what}");
                common::check_world(&what, &l.volume, &grid, 1e-9, |i, j, k| {
                    typed(name, ramp(i, j, k) + 1000 * f as i64)
                });
                assert_eq!(l.info.stored_type, format!("{type_name} (big-endian)"));
                assert_eq!((l.info.frames, l.info.frame), (2, f), "{what}");
                assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
                assert_eq!(header_value(&l, "type"), code);
                assert_eq!(header_value(&l, "dims"), "12 10 8 2");
                assert_eq!(header_value(&l, "delta"), "1.5 2 0.75");
                assert_eq!(header_value(&l, "Pxyz_c"), "11 -28 7.5");
                assert_eq!(has_note(&l, "MGZ"), ext == "mgz", "{:?}", l.info.notes);
            }
        }
    }
}

#[test]
fn without_frame_the_first_is_read_and_a_note_says_so() {
    let l = load_with("f32.mgz", &ReadOptions::default());
    assert_eq!(l.info.frame, 0);
    assert!(
        has_note(&l, "2 frames (dims[3]); frame 0 was read"),
        "{:?}",
        l.info.notes
    );
    let err = read(&fixture("f32.mgz"), &frame(2)).unwrap_err();
    common::assert_frame_out_of_range(&err, 2, "the file holds 2 frames (dims[3])");
}

#[test]
fn good_ras_flag_0_takes_nibabels_default_affine() {
    let l = load_with("no_ras.mgh", &ReadOptions::default());
    let default = [
        [-1.0, 0.0, 0.0, 6.0],
        [0.0, 0.0, -1.0, 4.0],
        [0.0, 1.0, 0.0, -5.0],
    ];
    common::check_world(
        "no_ras.mgh",
        &l.volume,
        &Grid::from_affine(SHAPE, &default),
        1e-9,
        |i, j, k| typed("f32", ramp(i, j, k)),
    );
    assert!(has_note(&l, "goodRASFlag is 0"), "{:?}", l.info.notes);
}

#[test]
fn mgz_is_no_nifti_by_name_or_by_content() {
    assert_eq!(
        VolumeFormat::from_path(&fixture("u8.mgz")),
        Some(VolumeFormat::Mgh)
    );
    assert_eq!(
        VolumeFormat::from_path(&PathBuf::from("b.MGH")),
        Some(VolumeFormat::Mgh)
    );
    let dir = tempfile::tempdir().unwrap();
    for (from, to) in [
        ("u8.mgz", "brain"),
        ("i16.mgh", "brain.dat"),
        ("f32.mgz", "x.gz"),
    ] {
        let path = dir.path().join(to);
        std::fs::copy(fixture(from), &path).unwrap();
        let head = std::fs::read(&path).unwrap();
        assert_eq!(
            VolumeFormat::sniff(&head[..head.len().min(1024)]),
            Some(VolumeFormat::Mgh),
            "{to}"
        );
        assert_eq!(
            read(&path, &ReadOptions::default()).unwrap().format,
            VolumeFormat::Mgh
        );
    }
    // A .nii.gz is still a NIfTI.
    let nii = std::fs::read(common::fixture("nifti", "f32.nii.gz")).unwrap();
    assert_eq!(
        VolumeFormat::sniff(&nii[..1024.min(nii.len())]),
        Some(VolumeFormat::Nifti)
    );
}

/// `bytes` gzip-compressed.
fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn with_dims(bytes: &[u8], dims: [i32; 4]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for (n, d) in dims.iter().enumerate() {
        b[4 + 4 * n..8 + 4 * n].copy_from_slice(&d.to_be_bytes());
    }
    b
}

#[test]
fn lying_and_truncated_files_are_refused_in_one_line() {
    let mgh = std::fs::read(fixture("i16.mgh")).unwrap();
    let none = ReadOptions::default();
    // More samples than the file holds.
    let msg = refused_file("a.mgh", &with_dims(&mgh, [12, 10, 9, 2]), &none);
    assert!(msg.contains("file is 4144 bytes, but the MGH header (dims 12 10 9 2, int16 (MRI_SHORT)) implies 4604"), "{msg}");
    // Cut inside the data, and inside the header.
    let msg = refused_file("a.mgh", &mgh[..3000], &none);
    assert!(msg.contains("implies 4124"), "{msg}");
    let msg = refused_file("a.mgh", &mgh[..100], &none);
    assert!(
        msg.contains("file ends after 100 bytes, inside the 284-byte MGH header"),
        "{msg}"
    );
    // The same in a gzip stream: the stream ends before the data does.
    let msg = refused_file("a.mgz", &gzip(&mgh[..3000]), &frame(1));
    assert!(
        msg.contains("gzip data ends after 3000 bytes, but the MGH header implies at least 4124"),
        "{msg}"
    );
    let msg = refused_file("a.mgz", &gzip(&mgh[..100]), &none);
    assert!(msg.contains("gzip data ends after 100 bytes"), "{msg}");
    let gz = gzip(&mgh);
    let msg = refused_file("a.mgz", &gz[..gz.len() / 2], &none);
    assert!(msg.contains("gzip"), "{msg}");
    // Zero, negative and huge dimensions; a bad version and type.
    let msg = refused_file("a.mgh", &with_dims(&mgh, [12, 0, 8, 2]), &none);
    assert!(msg.contains("MGH field \"dims\" is 12 0 8 2"), "{msg}");
    let msg = refused_file("a.mgh", &with_dims(&mgh, [-5, 10, 8, 2]), &none);
    assert!(msg.contains("at least 1, not -5"), "{msg}");
    let huge = [i32::MAX; 4];
    let msg = refused_file("a.mgh", &with_dims(&mgh, huge), &none);
    assert!(
        msg.contains("implies 42535295785889145473997720539375862046"),
        "{msg}"
    );
    let msg = refused_file("a.mgz", &gzip(&with_dims(&mgh, huge)), &none);
    assert!(msg.contains("more than a"), "{msg}");
    let mut bad = mgh.clone();
    bad[3] = 2;
    let msg = refused_file("a.mgh", &bad, &none);
    assert!(msg.contains("MGH field \"version\" is 2"), "{msg}");
    let mut bad = mgh.clone();
    bad[23] = 2;
    let msg = refused_file("a.mgh", &bad, &none);
    assert!(msg.contains("\"type\" is 2 (MRI_LONG)"), "{msg}");
    let mut bad = mgh.clone();
    bad[30..34].copy_from_slice(&f32::NAN.to_be_bytes());
    let msg = refused_file("a.mgh", &bad, &none);
    assert!(msg.contains("MGH field \"delta\""), "{msg}");
}

#[test]
fn a_gzip_bomb_is_refused_before_inflating() {
    // A 16 MiB volume of zeros compresses to about 16 KB: within the
    // deflate ratio, so only the memory limit stops it, before any sample
    // is inflated.
    let mut mgh = with_dims(
        &std::fs::read(fixture("u8.mgh")).unwrap()[..284],
        [256, 256, 256, 1],
    );
    mgh.resize(284 + (1 << 24), 0);
    let bomb = gzip(&mgh);
    assert!(bomb.len() < 100_000, "{}", bomb.len());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bomb.mgz");
    std::fs::write(&path, &bomb).unwrap();
    let opts = ReadOptions {
        max_memory: 1 << 20,
        ..ReadOptions::default()
    };
    let err = read(&path, &opts).unwrap_err();
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    assert!(!err.to_string().contains('\n'));
    assert!(
        err.to_string().contains("MGH field \"dims\" 256 256 256 1"),
        "{err}"
    );
    // Allowed the memory, it reads.
    let l = read(&path, &ReadOptions::default()).unwrap();
    assert_eq!(l.volume.dims(), [256, 256, 256]);
}

/// Deterministic byte flips and truncations of the MGH and MGZ fixtures,
/// each read with and without a frame: a volume or a one-line message,
/// never a panic.
#[test]
fn no_panic_on_truncation_or_corruption() {
    let fixtures = ["i16.mgh", "f32.mgz", "u8.mgz", "no_ras.mgh"].map(fixture);
    common::byte_flips_never_panic(
        &fixtures,
        0x9e37_79b9_7f4a_7c15,
        &[ReadOptions::default(), frame(1)],
    );
}
