//! MINC2 files written by h5py in libminc's layout and checked with
//! nibabel's `Minc2Image` (`fixtures/make_minc_fixtures.py`): the values
//! and world positions volray reads are nibabel's.
//!
//! Stored values at file index (i0, i1, i2), slowest first: `i2 + 10·i1 +
//! 100·i0` (series: `i2 + 2·i1 + 6·i0 + 50·t`), mapped to real values by
//! the per-slice image-min and image-max.

mod common;

use common::{Grid, assert_frame_out_of_range, assert_note, check_voxels, check_world, frame};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

fn load(name: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&common::fixture("minc", name), opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.format, VolumeFormat::Minc);
    l
}

fn close(got: f32, want: f64) -> bool {
    (f64::from(got) - want).abs() <= 1e-5 * want.abs().max(1.0)
}

#[test]
fn per_slice_scaling_and_a_flipped_axis_match_nibabel() {
    let l = load("ramp_i16.mnc", &ReadOptions::default());
    // nibabel's affine, array axes (z, y, x): x step 1.5 from -3, y step
    // -2 from 10, z step 2.5 from 4.
    let affine = [
        [0.0, 0.0, 1.5, -3.0],
        [0.0, -2.0, 0.0, 10.0],
        [2.5, 0.0, 0.0, 4.0],
    ];
    let grid = Grid::from_affine([3, 4, 5], &affine);
    let real = |z: usize, y: usize, x: usize| {
        let raw = (x + 10 * y + 100 * z) as f64;
        let (lo, hi) = (-1.0 - z as f64, 100.0 + 10.0 * z as f64);
        raw * (hi - lo) / 1000.0 + lo
    };
    // Exact f32 of the real value (the reader computes in f64).
    check_world("ramp_i16", &l.volume, &grid, 1e-9, |z, y, x| {
        real(z, y, x) as f32
    });
    assert_eq!(l.volume.dims(), [5, 4, 3]);
    assert_eq!(l.volume.spacing(), DVec3::new(1.5, 2.0, 2.5));
    // y flipped: the lowest y is 10 - 2·3 = 4.
    assert_eq!(l.volume.origin(), DVec3::new(-3.0, 4.0, 4.0));
    assert_eq!(l.info.stored_type, "int16 (little-endian)");
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_note(&l, "valid_range");
    assert_note(&l, "per slice of zspace");
    assert_note(&l, "index axis 1 -> -y");
    assert!(
        l.info
            .header
            .contains(&("@dimorder".into(), "zspace,yspace,xspace".into())),
        "{:?}",
        l.info.header
    );
}

#[test]
fn direction_cosines_and_another_dimorder() {
    let l = load("oblique_f32.mnc", &ReadOptions::default());
    // dimorder yspace, zspace, xspace: index axis 0 is x (step 1), 1 is z
    // (step 3), 2 is y (step 2); float values unscaled.
    check_voxels("oblique_f32", &l.volume, [5, 3, 4], |x, z, y| {
        (x + 10 * z + 100 * y) as f32 + 0.5
    });
    assert_eq!(l.volume.spacing(), DVec3::new(1.0, 3.0, 2.0));
    // nibabel's affine, last column: R · starts.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let want = DVec3::new(c - 2.0 * s, s + 2.0 * c, 3.0);
    assert!(
        (l.volume.origin() - want).length() < 1e-12,
        "{}",
        l.volume.origin()
    );
    assert_note(&l, "rotated away from world x, y, z");
    assert_note(&l, "float image");
}

#[test]
fn a_time_series_scaled_per_time_and_slice() {
    for t in 0..2 {
        let l = load("series_u8.mnc", &frame(t));
        assert_eq!((l.info.frames, l.info.frame), (2, t));
        assert_eq!(l.volume.dims(), [5, 4, 3]);
        for (z, y, x) in
            (0..3).flat_map(|z| (0..4).flat_map(move |y| (0..5).map(move |x| (z, y, x))))
        {
            let raw = (x + 2 * y + 6 * z + 50 * t) as f64;
            let (lo, hi) = (-(t as f64) - z as f64, 10.0 + (t + z) as f64);
            let want = raw * (hi - lo) / 255.0 + lo;
            let got = l.volume.get(x, y, z);
            assert!(
                close(got, want),
                "frame {t} ({x}, {y}, {z}): {got} vs {want}"
            );
        }
        assert_eq!(l.volume.spacing(), DVec3::ONE);
        assert_note(&l, "the type's range");
        assert_note(&l, "per slice of time,zspace");
    }
    let path = common::fixture("minc", "series_u8.mnc");
    let err = common::error_about(&path, &frame(2), &path);
    assert_frame_out_of_range(&err, 2, "the MINC2 image holds 2 volume(s) along \"time\"");
}

#[test]
fn a_minc2_file_under_an_hdf5_name_is_read_as_minc2() {
    let dir = tempfile::tempdir().unwrap();
    let renamed = dir.path().join("scan.h5");
    std::fs::copy(common::fixture("minc", "ramp_i16.mnc"), &renamed).unwrap();
    let l = read(&renamed, &ReadOptions::default()).unwrap();
    assert_eq!(l.format, VolumeFormat::Minc);
    assert_eq!(
        l.volume,
        load("ramp_i16.mnc", &ReadOptions::default()).volume
    );
}

#[test]
fn not_minc2_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    // An HDF5 file without the MINC2 layout.
    let plain = dir.path().join("plain.mnc");
    std::fs::copy(common::fixture("hdf5", "one.h5"), &plain).unwrap();
    let msg = common::refused(&plain, &ReadOptions::default());
    assert!(msg.contains("MINC2: no group /minc-2.0/image/0"), "{msg}");
    // MINC1 is NetCDF-3: a truncated header is NetCDF's refusal.
    let msg = common::refused_at(
        dir.path(),
        "old.mnc",
        b"CDF\x01\0\0\0\0",
        &ReadOptions::default(),
    );
    assert!(msg.contains("NetCDF header (byte 8)"), "{msg}");
    let msg = common::refused_at(dir.path(), "junk.mnc", b"not hdf5", &ReadOptions::default());
    assert!(msg.contains("HDF5: cannot open"), "{msg}");
}

// ---- MINC1: NetCDF-3 in libminc's layout (make_minc1_fixtures.py,
// written by netCDF4-python and checked with nibabel's Minc1Image) ----

#[test]
fn minc1_reads_as_its_minc2_twin() {
    // The same image, geometry and scaling as ramp_i16.mnc, whose values
    // and affine are nibabel's (above).
    let l = load("ramp_minc1.mnc", &ReadOptions::default());
    let twin = load("ramp_i16.mnc", &ReadOptions::default());
    assert_eq!(l.volume, twin.volume);
    assert_eq!(l.volume.origin(), DVec3::new(-3.0, 4.0, 4.0));
    assert_eq!(l.info.stored_type, "int16 (big-endian)");
    assert_eq!(common::header_value(&l, "format"), "MINC1 (NetCDF-3)");
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_note(&l, "valid_range");
    assert_note(&l, "per slice of zspace");
    assert_note(&l, "index axis 1 -> -y");
}

#[test]
fn minc1_unsigned_bytes_in_a_time_series_with_rotated_axes() {
    for t in 0..2 {
        let l = load("series_minc1.mnc", &frame(t));
        assert_eq!((l.info.frames, l.info.frame), (2, t));
        assert_eq!(l.info.stored_type, "uint8 (big-endian)");
        // nibabel: raw (above 127: the signtype is "unsigned") scaled from
        // 0..255 onto image-min..image-max of (time, zspace).
        check_voxels("series_minc1", &l.volume, [5, 4, 3], |x, y, z| {
            let raw = (x + 2 * y + 6 * z + 50 * t + 100) as f64;
            let (lo, hi) = (-(t as f64) - z as f64, 10.0 + (t + z) as f64);
            (raw * (hi - lo) / 255.0 + lo) as f32
        });
        // x and y rotated 30° about z: kept in the grid's own axes.
        assert_eq!(l.volume.spacing(), DVec3::new(1.0, 2.0, 3.0));
        assert_note(&l, "rotated away from world x, y, z");
        assert_note(&l, "per slice of time,zspace");
    }
    let path = common::fixture("minc", "series_minc1.mnc");
    let err = common::error_about(&path, &frame(2), &path);
    assert_frame_out_of_range(&err, 2, "the MINC1 image holds 2 volume(s) along \"time\"");
}

#[test]
fn minc1_under_a_netcdf_name_or_none_is_read_as_minc() {
    let dir = tempfile::tempdir().unwrap();
    let want = load("ramp_minc1.mnc", &ReadOptions::default()).volume;
    for name in ["scan.nc", "scan"] {
        let p = dir.path().join(name);
        std::fs::copy(common::fixture("minc", "ramp_minc1.mnc"), &p).unwrap();
        let l = read(&p, &ReadOptions::default()).unwrap();
        assert_eq!(l.format, VolumeFormat::Minc, "{name}");
        assert_eq!(l.volume, want, "{name}");
    }
}

#[test]
fn broken_minc1_files_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(common::fixture("minc", "ramp_minc1.mnc")).unwrap();
    let bad = common::replace(&good, "signed__", "sined___");
    common::refuse(dir.path(), "sign.mnc", &bad, "signtype \"sined___\"");
    let files = ["ramp_minc1.mnc", "series_minc1.mnc"].map(|n| common::fixture("minc", n));
    common::byte_flips_never_panic(&files, 0x6d31, &[ReadOptions::default(), frame(1)]);
}

#[test]
fn a_dimension_in_cm_among_dimensions_in_mm_is_converted_to_mm() {
    // ramp_minc1.mnc with zspace's units "mm" rewritten "cm": its step 2.5
    // and start 4 are 25 and 40 mm; x and y stay in mm, the finest.
    let mut bytes = std::fs::read(common::fixture("minc", "ramp_minc1.mnc")).unwrap();
    let find = |from: usize, what: &[u8]| {
        from + bytes[from..]
            .windows(what.len())
            .position(|w| w == what)
            .unwrap()
    };
    // zspace's variable (its second mention: the first is its dimension).
    let var = find(find(0, b"zspace") + 6, b"zspace");
    let mm = find(find(var, b"units"), b"mm");
    bytes[mm..mm + 2].copy_from_slice(b"cm");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("z_in_cm.mnc");
    std::fs::write(&path, &bytes).unwrap();
    let l = read(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.volume.spacing(), DVec3::new(1.5, 2.0, 25.0));
    assert_eq!(l.volume.origin(), DVec3::new(-3.0, 4.0, 40.0));
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_note(
        &l,
        "zspace in cm, yspace/xspace in mm: spacing in mm (zspace × 10)",
    );
}
