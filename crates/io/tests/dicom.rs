//! DICOM series and multi-frame files written by pydicom
//! (`fixtures/make_dicom_fixtures.py`), read through `volray_io::read`.
//!
//! Every image is 4 columns (x) by 3 rows (y); slice z stores
//! `v = x + 10y + 100z` transformed per fixture. Each test checks every
//! voxel's value and its world position against the geometry the fixture
//! script wrote: pixel (x, y) of slice z lies at
//! `IPP(z) + x·dx·ROW + y·dy·COL`.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use common::{assert_frame_out_of_range, assert_note, frame, refused};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("dicom", name)
}

fn load_path(path: &Path, opts: &ReadOptions) -> Loaded {
    let l = read(path, opts).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Dicom);
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    l
}

fn load(name: &str, opts: &ReadOptions) -> Loaded {
    load_path(&fixture(name), opts)
}

/// The refusal of fixture `name`.
fn error(name: &str, opts: &ReadOptions) -> String {
    refused(&fixture(name), opts)
}

/// The fixture geometry: IPP of slice z, and the world steps of x and y.
struct Geometry {
    ipp: fn(usize) -> DVec3,
    x_step: DVec3,
    y_step: DVec3,
}

/// Checks that every voxel holds `value(v)` for some (x, y, z) of the
/// 4x3xZ fixture grid, that each (x, y, z) appears exactly once, and that
/// the voxel's world position is the one the file gives that pixel.
fn check(volume: &Volume, slices: usize, value: impl Fn(usize) -> f32, g: &Geometry) {
    let [nx, ny, nz] = volume.dims();
    assert_eq!(nx * ny * nz, 4 * 3 * slices, "dims {:?}", volume.dims());
    let mut lookup = std::collections::HashMap::new();
    for z in 0..slices {
        for y in 0..3 {
            for x in 0..4 {
                let v = x + 10 * y + 100 * z;
                assert!(lookup.insert(value(v).to_bits(), (x, y, z)).is_none());
            }
        }
    }
    let mut seen = std::collections::HashSet::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let got = volume.get(i, j, k);
                let &(x, y, z) = lookup.get(&got.to_bits()).unwrap_or_else(|| {
                    panic!("voxel ({i}, {j}, {k}) holds {got}, not a fixture value")
                });
                assert!(seen.insert((x, y, z)));
                let want = (g.ipp)(z) + g.x_step * x as f64 + g.y_step * y as f64;
                let at = volume.world_position(i, j, k);
                assert!(
                    (at - want).length() < 1e-9,
                    "voxel ({i}, {j}, {k}) = pixel ({x}, {y}) of slice {z} lies at {at}, want {want}"
                );
            }
        }
    }
}

/// The CT stack: IPP (-10, 20, 30 + 2.5z), PixelSpacing 0.8\0.6, axial.
const CT: Geometry = Geometry {
    ipp: |z| DVec3::new(-10.0, 20.0, 30.0 + 2.5 * z as f64),
    x_step: DVec3::new(0.6, 0.0, 0.0),
    y_step: DVec3::new(0.0, 0.8, 0.0),
};

/// Unit-spaced axial stacks at IPP (0, 0, z).
const UNIT: Geometry = Geometry {
    ipp: |z| DVec3::new(0.0, 0.0, z as f64),
    x_step: DVec3::X,
    y_step: DVec3::Y,
};

#[test]
fn ct_series_sorted_by_position_with_rescale() {
    let l = load("ct", &ReadOptions::default());
    // Stored int16 v - 200; HU = 2 x stored - 1024.
    check(
        &l.volume,
        5,
        |v| (2.0 * (v as f64 - 200.0) - 1024.0) as f32,
        &CT,
    );
    assert_eq!(l.volume.dims(), [4, 3, 5]);
    assert!((l.volume.spacing() - DVec3::new(0.6, 0.8, 2.5)).length() < 1e-12);
    assert_eq!(l.volume.origin(), DVec3::new(-10.0, 20.0, 30.0));
    assert_eq!(
        l.info.stored_type,
        "int16 (Implicit VR Little Endian, 1.2.840.10008.1.2)"
    );
    assert_eq!((l.info.frames, l.info.frame), (1, 0));
    assert_note(&l, "skipped 1 file(s) not DICOM (README.txt)");
    assert_note(
        &l,
        "RescaleSlope (0028,1053) 2 and RescaleIntercept (0028,1052) -1024 applied",
    );
    assert_note(&l, "LPS");
    let keys: Vec<&str> = l.info.header.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys[0], "TransferSyntaxUID (0002,0010)");
    assert!(
        keys.contains(&"ImagePositionPatient (0020,0032)"),
        "{keys:?}"
    );
    let position = keys
        .iter()
        .position(|k| k.starts_with("ImagePositionPatient"))
        .unwrap();
    let spacing = keys
        .iter()
        .position(|k| k.starts_with("PixelSpacing"))
        .unwrap();
    assert!(position < spacing, "fields in file (tag) order");
    // The first slice along the normal is the one at z = 30.
    let ipp: Vec<f64> = l.info.header[position]
        .1
        .split('\\')
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(ipp, [-10.0, 20.0, 30.0]);
}

#[test]
fn sagittal_series_is_reordered_to_world_axes() {
    // ROW = +y, COL = -z: normal ROW x COL = -x; slices 1.5 mm apart.
    let l = load("sagittal", &ReadOptions::default());
    let g = Geometry {
        ipp: |z| DVec3::new(5.0 - 1.5 * z as f64, -3.0, 40.0),
        x_step: DVec3::new(0.0, 0.5, 0.0),
        y_step: DVec3::new(0.0, 0.0, -1.25),
    };
    // 12 of 16 bits stored under junk 0xA000: the junk is masked off.
    check(&l.volume, 5, |v| v as f32, &g);
    assert_eq!(l.volume.dims(), [5, 4, 3]);
    assert!((l.volume.spacing() - DVec3::new(1.5, 0.5, 1.25)).length() < 1e-12);
    assert_eq!(
        l.info.stored_type,
        "uint16 (12 bits stored) (Explicit VR Little Endian, 1.2.840.10008.1.2.1)"
    );
    assert_note(&l, "samples reordered");
}

#[test]
fn of_several_series_the_largest_is_read_then_others_picked_by_frame() {
    // Series are listed by SeriesNumber: B (1) is 1 (frame 0), A (2) is 2.
    let a = load("two_series", &ReadOptions::default());
    check(&a.volume, 3, |v| v as f32, &UNIT);
    assert_eq!((a.info.frames, a.info.frame), (2, 1));
    assert_note(
        &a,
        "2 series; read the largest, 2: SeriesNumber 2, CT \"series A\", 3 file(s), 4 x 3, UID ",
    );
    assert_note(
        &a,
        "the others: 1: SeriesNumber 1, CT \"series B\", 2 file(s)",
    );
    let b = load("two_series", &frame(0));
    check(&b.volume, 2, |v| (v + 7) as f32, &UNIT);
    assert_eq!((b.info.frames, b.info.frame), (2, 0));
    assert_note(&b, "series 1 of 2 read (frame 0)");
    let a = load("two_series", &frame(1));
    check(&a.volume, 3, |v| v as f32, &UNIT);
    let err = read(&fixture("two_series"), &frame(2)).unwrap_err();
    assert_frame_out_of_range(&err, 2, "there are 2 series");
}

#[test]
fn missing_slice_is_refused_with_the_gaps() {
    let msg = error("gap", &ReadOptions::default());
    assert!(
        msg.contains("slice gaps are uneven: 1 mm (between g0.dcm and g1.dcm) to 2 mm (between g2.dcm and g4.dcm), mean 1.25 mm"),
        "{msg}"
    );
}

/// The CT series (IPP z = 30, 32.5, 35, 37.5, 40 mm) with the slice at
/// 37.5 (IM1603.dcm) written at `z` instead (6 characters, as padded).
fn ct_with_slice_at(dir: &Path, z: &[u8; 6]) -> PathBuf {
    fs::create_dir_all(dir).unwrap();
    for e in fs::read_dir(fixture("ct")).unwrap() {
        let e = e.unwrap();
        let mut bytes = fs::read(e.path()).unwrap();
        if e.file_name() == "IM1603.dcm" {
            let at = find(&bytes, b"-10.0\\20.0\\37.5  ") + 11;
            bytes[at..at + 6].copy_from_slice(z);
        }
        fs::write(dir.join(e.file_name()), bytes).unwrap();
    }
    dir.to_path_buf()
}

#[test]
fn a_near_even_series_reads_at_the_mean_gap_with_a_note_and_a_20_percent_uneven_one_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    // 37.58: gaps 2.5, 2.5, 2.58, 2.42 mm, 0.08 mm (3.2 %) off their mean,
    // as a scanner's rounding leaves them; read at (40 − 30) / 4 = 2.5 mm.
    let near = ct_with_slice_at(&tmp.path().join("near"), b"37.58 ");
    let l = load_path(&near, &ReadOptions::default());
    assert_eq!(l.volume.dims(), [4, 3, 5]);
    assert!((l.volume.spacing() - DVec3::new(0.6, 0.8, 2.5)).length() < 1e-12);
    assert!((l.volume.origin() - DVec3::new(-10.0, 20.0, 30.0)).length() < 1e-12);
    assert_note(
        &l,
        "slice gaps vary from 2.42 to 2.58 mm around their mean 2.5 mm",
    );
    assert_note(
        &l,
        "0.08 mm (3.2 % of the mean) off it, within the tolerance of 0.135 mm (5 % of the mean gap plus 0.01 mm for positions written to 2 decimal(s))",
    );
    assert_note(
        &l,
        "places IM1603.dcm 0.08 mm (3.2 % of a gap) from its written position",
    );
    // The slices keep their order and values: slice z holds v(z).
    for k in 0..5 {
        assert_eq!(
            l.volume.get(1, 2, k),
            (2 * (21 + 100 * k as i64 - 200) - 1024) as f32
        );
    }

    // 38.0: gaps 2.5, 2.5, 3, 2 mm, 20 % off: refused, naming the slices.
    let uneven = ct_with_slice_at(&tmp.path().join("uneven"), b"38.0  ");
    let msg = refused(&uneven, &ReadOptions::default());
    assert!(msg.contains("slice gaps are uneven: 2 mm (between IM1603.dcm and IM1007) to 3 mm (between IM5286 and IM1603.dcm), mean 2.5 mm"), "{msg}");
    assert!(
        msg.contains("0.5 mm (20 %) off the mean, beyond the tolerance of 0.225 mm"),
        "{msg}"
    );
}

#[test]
fn rle_and_big_endian_series() {
    let l = load("rle", &ReadOptions::default());
    check(&l.volume, 5, |v| v as f32, &CT);
    assert_eq!(
        l.info.stored_type,
        "uint16 (RLE Lossless, 1.2.840.10008.1.2.5)"
    );
    let l = load("bigendian", &ReadOptions::default());
    check(&l.volume, 5, |v| -(v as i32) as f32, &UNIT);
    assert_eq!(
        l.info.stored_type,
        "int16 (Explicit VR Big Endian, 1.2.840.10008.1.2.2)"
    );
}

#[test]
fn corrupt_codestream_is_named_with_its_transfer_syntax() {
    // The fragment is SOC, SIZ and 20 zero bytes: a cut SIZ segment.
    let msg = refused(&fixture("j2k"), &ReadOptions::default());
    assert!(
        msg.contains("cannot decode the pixel data (JPEG 2000 Lossless, 1.2.840.10008.1.2.4.90): frame 0: the JPEG 2000 codestream ends inside its SIZ marker segment"),
        "{msg}"
    );
}

#[test]
fn single_slice_file_points_to_its_directory() {
    let msg = error("single.dcm", &ReadOptions::default());
    assert!(
        msg.contains(
            "a single DICOM slice (4 x 3), not a volume: pass the directory of the series"
        ),
        "{msg}"
    );
}

#[test]
fn enhanced_ct_frames_sorted_with_shared_rescale() {
    let l = load("enhanced_ct.dcm", &ReadOptions::default());
    check(&l.volume, 5, |v| (0.5 * v as f64 - 100.0) as f32, &CT);
    assert_eq!((l.info.frames, l.info.frame), (1, 0));
    assert_note(
        &l,
        "RescaleSlope (0028,1053) 0.5 and RescaleIntercept (0028,1052) -100 applied",
    );
    let number = l
        .info
        .header
        .iter()
        .find(|(k, _)| k.starts_with("NumberOfFrames"))
        .unwrap();
    assert_eq!(number.1, "5");
}

#[test]
fn enhanced_time_series_volumes_by_frame() {
    for t in 0..2 {
        let l = load("enhanced_4d.dcm", &frame(t));
        check(&l.volume, 5, |v| (v + 1000 * t) as f32, &CT);
        assert_eq!((l.info.frames, l.info.frame), (2, t));
        assert_note(&l, &format!("volume {t} of 2 read"));
    }
    let err = read(&fixture("enhanced_4d.dcm"), &frame(2)).unwrap_err();
    assert_frame_out_of_range(&err, 2, "there are 2 volume(s)");
}

#[test]
fn rt_dose_with_offsets_and_scaling() {
    let l = load("rtdose.dcm", &ReadOptions::default());
    let g = Geometry {
        ipp: |z| DVec3::new(100.0, -50.0, 12.0 - 3.0 * z as f64),
        x_step: DVec3::new(4.0, 0.0, 0.0),
        y_step: DVec3::new(0.0, 2.0, 0.0),
    };
    check(&l.volume, 5, |v| ((1000 * v + 5) as f64 * 1e-3) as f32, &g);
    assert_eq!(l.volume.origin(), DVec3::new(100.0, -50.0, 0.0));
    assert!((l.volume.spacing() - DVec3::new(4.0, 2.0, 3.0)).length() < 1e-12);
    assert_note(
        &l,
        "DoseGridScaling (3004,000E) 0.001 applied: values are dose in GY",
    );
    assert_note(&l, "GridFrameOffsetVector");
    assert_eq!(
        l.info.stored_type,
        "uint32 (Explicit VR Little Endian, 1.2.840.10008.1.2.1)"
    );
}

#[test]
fn float_pixel_data_and_deflated_data_sets() {
    let l = load("float_map.dcm", &ReadOptions::default());
    check(&l.volume, 5, |v| (0.25 * v as f64 - 1.0) as f32, &CT);
    assert_eq!(
        l.info.stored_type,
        "float32 (Explicit VR Little Endian, 1.2.840.10008.1.2.1)"
    );
    let l = load("deflated", &ReadOptions::default());
    check(&l.volume, 3, |v| v as f32, &UNIT);
    assert_eq!(
        l.info.stored_type,
        "uint16 (Deflated Explicit VR Little Endian, 1.2.840.10008.1.2.1.99)"
    );
}

#[test]
fn mutated_files_never_panic() {
    // Every fixture file with bytes overwritten at random: the reader
    // returns a volume or a one-line bad-input error, never panics.
    let mut files = Vec::new();
    for sub in ["", "ct", "rle", "sagittal", "deflated"] {
        for e in fs::read_dir(fixture(sub)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "dcm") {
                files.push(p);
            }
        }
    }
    common::mutations_never_panic(&files, "m.dcm", 7);
}

/// The offset of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len())
        .position(|w| w == needle)
        .unwrap_or_else(|| panic!("{needle:?} not found"))
}

#[test]
fn damaged_files_give_clean_errors() {
    let dir = tempfile::tempdir().unwrap();
    let dose = fs::read(fixture("rtdose.dcm")).unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        fs::write(&p, bytes).unwrap();
        p
    };

    // Cut short anywhere: a clean error naming the file.
    for cut in [100, 140, 400, dose.len() / 2, dose.len() - 3] {
        let p = write(&format!("cut{cut}.dcm"), &dose[..cut]);
        refused(&p, &ReadOptions::default());
    }

    // Pixel data declaring 4 GB in a 1 KB file: refused before parsing.
    let mut lying = dose.clone();
    let at = find(&lying, &[0xe0, 0x7f, 0x10, 0x00, b'O']);
    lying[at + 8..at + 12].copy_from_slice(&0xffff_fff0u32.to_le_bytes());
    let msg = refused(&write("lying.dcm", &lying), &ReadOptions::default());
    assert!(
        msg.contains("(7FE0,0010)") && msg.contains("declares 4294967280 bytes"),
        "{msg}"
    );

    // Rows 60000: the pixel data cannot hold it; refused before decoding.
    let mut rows = dose.clone();
    let at = find(&rows, &[0x28, 0x00, 0x10, 0x00, b'U', b'S', 0x02, 0x00]);
    rows[at + 8..at + 10].copy_from_slice(&60000u16.to_le_bytes());
    let msg = refused(&write("rows.dcm", &rows), &ReadOptions::default());
    assert!(
        msg.contains("pixel data (7FE0,0010) holds 240 bytes, but Rows 60000 x Columns 4 x 5 frame(s) x 4 byte(s) need 4800000"),
        "{msg}"
    );

    // A malformed number.
    let mut scaling = dose.clone();
    let at = find(&scaling, b"0.001");
    scaling[at..at + 5].copy_from_slice(b"0.0x1");
    let msg = refused(&write("scaling.dcm", &scaling), &ReadOptions::default());
    assert!(
        msg.contains("DoseGridScaling (3004,000E): \"0.0x1"),
        "{msg}"
    );

    // Not DICOM at all.
    let msg = refused(&write("text.dcm", &[b'x'; 300]), &ReadOptions::default());
    assert!(msg.contains("not a DICOM file"), "{msg}");
}

#[test]
fn inconsistent_directories_are_refused() {
    let copy = |from: &str, to: &Path| {
        fs::create_dir_all(to).unwrap();
        for e in fs::read_dir(fixture(from)).unwrap() {
            let e = e.unwrap();
            fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    };
    let tmp = tempfile::tempdir().unwrap();

    // One slice with 5 columns instead of 4 (explicit VR big endian).
    let dir = tmp.path().join("columns");
    copy("bigendian", &dir);
    let p = dir.join("b2.dcm");
    let mut bytes = fs::read(&p).unwrap();
    let at = find(&bytes, &[0x00, 0x28, 0x00, 0x11, b'U', b'S', 0x00, 0x02]);
    bytes[at + 8..at + 10].copy_from_slice(&5u16.to_be_bytes());
    fs::write(&p, bytes).unwrap();
    let msg = refused(&dir, &ReadOptions::default());
    assert!(msg.contains("b2.dcm is 5x3 int16"), "{msg}");
    assert!(
        msg.contains("every slice of a series must have the same size"),
        "{msg}"
    );

    // A duplicated slice.
    let dir = tmp.path().join("duplicate");
    copy("bigendian", &dir);
    fs::copy(dir.join("b1.dcm"), dir.join("b1_copy.dcm")).unwrap();
    let msg = refused(&dir, &ReadOptions::default());
    assert!(
        msg.contains("b1.dcm and b1_copy.dcm lie at the same position"),
        "{msg}"
    );

    // A corrupt slice is skipped, and the resulting gap says so.
    let dir = tmp.path().join("corrupt");
    copy("bigendian", &dir);
    let p = dir.join("b2.dcm");
    let bytes = fs::read(&p).unwrap();
    fs::write(&p, &bytes[..200]).unwrap();
    let msg = refused(&dir, &ReadOptions::default());
    assert!(msg.contains("slice gaps are uneven"), "{msg}");
    assert!(
        msg.contains("skipped 1 unreadable DICOM file(s) (b2.dcm: "),
        "{msg}"
    );

    // Nothing to read.
    let dir = tmp.path().join("empty");
    fs::create_dir(&dir).unwrap();
    fs::write(dir.join("notes.txt"), "x").unwrap();
    let msg = refused(&dir, &ReadOptions::default());
    assert!(
        msg.contains(
            "no DICOM image files in this directory or its subfolders (skipped 1 file(s) not DICOM (notes.txt))"
        ),
        "{msg}"
    );
}
