//! FITS files written by astropy.io.fits and checked with astropy and
//! astropy.wcs (`fixtures/make_fits_fixtures.py`): the values, dims,
//! spacing and origin volray reads are astropy's.
//!
//! Every volume is 8 x 6 x 5 (NAXIS1 NAXIS2 NAXIS3) and holds at (i, j, k)
//! the ramp i + 10j + 100k moved into its type's range (`common::typed`).

mod common;

use std::fs;

use common::{Grid, assert_note, check_voxels, check_world, frame, header_value, ramp, typed};
use volray_core::SampleType;
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

const DIMS: [usize; 3] = [8, 6, 5];

fn load(name: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&common::fixture("fits", name), opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.format, VolumeFormat::Fits);
    l
}

fn fixture_bytes(name: &str) -> Vec<u8> {
    fs::read(common::fixture("fits", name)).unwrap()
}

#[test]
fn every_bitpix_and_astropys_unsigned_conventions_read_exactly() {
    let cases = [
        ("u8", SampleType::U8, "uint8 (BITPIX 8, big-endian)"),
        (
            "i8",
            SampleType::I8,
            "int8 (BITPIX 8, BZERO -128, big-endian)",
        ),
        (
            "u16",
            SampleType::U16,
            "uint16 (BITPIX 16, BZERO 32768, big-endian)",
        ),
        ("i16", SampleType::I16, "int16 (BITPIX 16, big-endian)"),
        (
            "u32",
            SampleType::F32,
            "uint32 (BITPIX 32, BZERO 2147483648, big-endian)",
        ),
        ("i32", SampleType::F32, "int32 (BITPIX 32, big-endian)"),
        (
            "u64",
            SampleType::F32,
            "uint64 (BITPIX 64, BZERO 9223372036854775808, big-endian)",
        ),
        ("i64", SampleType::F32, "int64 (BITPIX 64, big-endian)"),
        ("f32", SampleType::F32, "float32 (BITPIX -32, big-endian)"),
        ("f64", SampleType::F32, "float64 (BITPIX -64, big-endian)"),
    ];
    for (name, kept, stored) in cases {
        let l = load(&format!("{name}.fits"), &ReadOptions::default());
        check_voxels(name, &l.volume, DIMS, |i, j, k| typed(name, ramp(i, j, k)));
        assert_eq!(l.volume.sample_type(), kept, "{name}");
        assert_eq!(l.info.stored_type, stored, "{name}");
        // No WCS: CDELT 1 and CRPIX 0 put sample 0 at pixel 1 (astropy.wcs).
        assert_eq!(l.volume.spacing(), DVec3::ONE, "{name}");
        assert_eq!(l.volume.origin(), DVec3::ONE, "{name}");
        assert_eq!((l.info.frames, l.info.frame), (1, 0));
        assert!(!l.info.nan_is_empty);
    }
}

#[test]
fn bscale_and_bzero_give_the_values_astropy_gives() {
    let l = load("scaled_i16.fits", &ReadOptions::default());
    check_voxels("scaled", &l.volume, DIMS, |i, j, k| {
        (10.0 + 0.5 * (ramp(i, j, k) as f64 - 1000.0)) as f32
    });
    assert_eq!(
        l.info.stored_type,
        "int16 (BITPIX 16, BSCALE 0.5, BZERO 10, big-endian)"
    );
    assert_eq!(header_value(&l, "BSCALE"), "0.5");
}

#[test]
fn blank_and_nan_samples_are_undefined_and_render_as_empty_space() {
    let l = load("blank_i16.fits", &ReadOptions::default());
    assert!(l.info.nan_is_empty);
    assert_note(&l, "30 samples are undefined (BLANK = -32768)");

    let l = load("nan_f32.fits", &ReadOptions::default());
    let nan = (0..5)
        .flat_map(|k| (0..6).map(move |j| (j, k)))
        .filter(|&(j, k)| l.volume.get(j, j, k).is_nan())
        .count();
    assert_eq!(nan, 30);
    assert_eq!(l.volume.get(1, 0, 2), ramp(1, 0, 2) as f32 + 0.25);
    assert!(l.info.nan_is_empty);
    assert_note(&l, "30 samples are undefined (IEEE NaN)");
}

/// [`check_voxels`] where NaN is wanted too (`==` never holds for NaN).
fn check_voxels_nan(what: &str, l: &Loaded, want: impl Fn(usize, usize, usize) -> f32) {
    assert_eq!(l.volume.dims(), DIMS, "{what}");
    for (i, j, k) in (0..5).flat_map(|k| (0..6).flat_map(move |j| (0..8).map(move |i| (i, j, k)))) {
        let (got, w) = (l.volume.get(i, j, k), want(i, j, k));
        assert!(
            got == w || (got.is_nan() && w.is_nan()),
            "{what} at ({i}, {j}, {k}): {got} vs {w}"
        );
    }
}

#[test]
fn blank_positions_are_nan_and_nowhere_else() {
    let l = load("blank_i16.fits", &ReadOptions::default());
    check_voxels_nan("blank", &l, |i, j, k| {
        if i == j {
            f32::NAN
        } else {
            (ramp(i, j, k) - 1000) as f32
        }
    });
    for (i, j, k) in [(0, 0, 0), (3, 3, 4), (5, 5, 1)] {
        assert!(l.volume.get(i, j, k).is_nan());
    }
}

#[test]
fn a_linear_wcs_in_mm_gives_astropys_world_coordinates() {
    let l = load("wcs_mm.fits", &ReadOptions::default());
    // astropy.wcs: pixel (0, 0, 0) at (9, -5, 98) mm; steps 0.5, -0.75, 2.
    let grid = Grid {
        n: DIMS,
        steps: [
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.0, -0.75, 0.0),
            DVec3::new(0.0, 0.0, 2.0),
        ],
        origin: DVec3::new(9.0, -5.0, 98.0),
    };
    check_world("wcs_mm", &l.volume, &grid, 1e-9, |i, j, k| {
        ramp(i, j, k) as f32 + 0.25
    });
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 0.75, 2.0));
    // y runs backwards: its lowest world y is pixel 5's, astropy's -8.75.
    assert_eq!(l.volume.origin(), DVec3::new(9.0, -8.75, 98.0));
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_note(
        &l,
        "axes: x = NAXIS1 'X' (mm), y = NAXIS2 'Y' (mm), z = NAXIS3 'Z' (mm)",
    );
    assert_note(&l, "index axis 1 -> -y");
}

#[test]
fn a_radio_cube_drops_its_stokes_axis_and_is_rendered_in_pixels() {
    let l = load("radio_cube.fits", &ReadOptions::default());
    check_voxels_nan("radio", &l, |i, j, k| {
        if (i, j) == (0, 0) {
            f32::NAN
        } else {
            ramp(i, j, k) as f32 + 0.25
        }
    });
    assert!(l.volume.get(0, 0, 3).is_nan());
    assert!(l.info.nan_is_empty);
    // Degrees and Hz are not one length: FITS pixel coordinates.
    assert_eq!(l.volume.spacing(), DVec3::ONE);
    assert_eq!(l.volume.origin(), DVec3::ONE);
    assert_eq!(l.info.length_unit.as_deref(), Some("pixel"));
    assert_note(&l, "axes of length 1 dropped: NAXIS4 ('STOKES')");
    assert_note(
        &l,
        "axes: x = NAXIS1 'RA---SIN' (deg), y = NAXIS2 'DEC--SIN' (deg), z = NAXIS3 'FREQ' (Hz); values in BUNIT 'Jy/beam'",
    );
    // astropy.wcs: the first channel at 1.42 GHz, 100 kHz a channel.
    assert_note(&l, "z from 1420000000 Hz, step 100000 Hz");
    assert_note(
        &l,
        "x from 180.0035 deg, step -0.001 deg (linear near the reference pixel)",
    );
    assert_eq!(header_value(&l, "CTYPE3"), "FREQ");
    assert_eq!(header_value(&l, "BUNIT"), "Jy/beam");
}

#[test]
fn the_frames_of_a_multi_extension_file_are_its_volumes_in_order() {
    // HDU 2 'SCI' (3-D) is frame 0; HDU 4 'SERIES' (4-D, NAXIS4 2) frames 1, 2.
    let l = load("multi.fits", &ReadOptions::default());
    check_voxels("SCI", &l.volume, DIMS, |i, j, k| {
        (ramp(i, j, k) - 1000) as f32
    });
    assert_eq!((l.info.frames, l.info.frame), (3, 0));
    assert_eq!(l.info.arrays, ["SCI", "SERIES"]);
    assert_eq!(l.info.array.as_deref(), Some("SCI"));
    assert_note(&l, "read HDU 2 (EXTNAME 'SCI')");
    for t in 0..2 {
        let l = load("multi.fits", &frame(1 + t));
        check_voxels("SERIES", &l.volume, [4, 3, 2], |i, j, k| {
            (ramp(i, j, k) + 1000 * t as i64) as f32
        });
        assert_eq!((l.info.frames, l.info.frame), (3, 1 + t));
        assert_note(
            &l,
            &format!("NAXIS4 (no CTYPE) holds 2 volumes: step {t} read"),
        );
    }
    let path = common::fixture("fits", "multi.fits");
    let err = common::error_about(&path, &frame(3), &path);
    common::assert_frame_out_of_range(
        &err,
        3,
        "the file holds 3 volumes (HDU 2 (EXTNAME 'SCI'): 1, HDU 4 (EXTNAME 'SERIES'): 2), numbered from 0",
    );
}

#[test]
fn array_names_an_hdu_and_frame_counts_within_it() {
    let by_name = |name: &str, f: Option<usize>| ReadOptions {
        array: Some(name.to_string()),
        frame: f,
        ..ReadOptions::default()
    };
    let l = load("multi.fits", &by_name("series", Some(1)));
    check_voxels("SERIES 1", &l.volume, [4, 3, 2], |i, j, k| {
        (ramp(i, j, k) + 1000) as f32
    });
    assert_eq!((l.info.frames, l.info.frame), (2, 1));
    assert_eq!(l.info.array.as_deref(), Some("SERIES"));
    // By number.
    let l = load("multi.fits", &by_name("2", None));
    assert_eq!(l.volume.dims(), DIMS);
    let path = common::fixture("fits", "multi.fits");
    let err = common::refused_error(&path, &by_name("THUMB", None));
    assert!(matches!(err, IoError::NoSuchArray { .. }), "{err}");
    assert!(
        err.to_string()
            .ends_with("no array named \"THUMB\": the file's 3-D images are SCI, SERIES"),
        "{err}"
    );
}

#[test]
fn a_gzipped_file_reads_as_the_plain_one() {
    let gz = load("i16.fits.gz", &ReadOptions::default());
    let plain = load("i16.fits", &ReadOptions::default());
    assert_eq!(gz.volume, plain.volume);
    // Cut short: one line, no panic.
    let bytes = fixture_bytes("i16.fits.gz");
    let msg = common::refused_file(
        "cut.fits.gz",
        &bytes[..bytes.len() / 2],
        &ReadOptions::default(),
    );
    assert!(msg.contains("gzip"), "{msg}");
}

#[test]
fn fits_is_known_by_its_extensions_and_its_first_card() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = fixture_bytes("i16.fits");
    for name in ["a.FTS", "a.fit", "no_extension", "a.dat"] {
        let p = dir.path().join(name);
        fs::write(&p, &bytes).unwrap();
        let l = read(&p, &ReadOptions::default()).unwrap();
        assert_eq!(l.format, VolumeFormat::Fits, "{name}");
    }
    assert_eq!(
        VolumeFormat::from_path(std::path::Path::new("cube.FITS.gz")),
        Some(VolumeFormat::Fits)
    );
}

#[test]
fn a_tile_compressed_image_reads_as_the_plain_one() {
    // The i16 volume as astropy's RICE_1 CompImageHDU (fits_tiled.rs
    // checks every method against astropy's values).
    let tiled = load("compressed.fits", &ReadOptions::default());
    let plain = load("i16.fits", &ReadOptions::default());
    assert_eq!(tiled.volume, plain.volume);
    assert_note(
        &tiled,
        "HDU 1 (EXTNAME 'COMPRESSED_IMAGE') is a tile-compressed image (ZCMPTYPE 'RICE_1', tiles 8x1x1): decompressed as read",
    );
    // Cut short in its table's rows or heap: one line, no panic (the
    // primary header, then the table's, then its data).
    let bytes = fixture_bytes("compressed.fits");
    for cut in [2880 * 2 + 10, 2880 * 2 + 300] {
        let msg = common::refused_file("cut.fits", &bytes[..cut], &ReadOptions::default());
        assert!(msg.contains("HDU 1"), "{msg}");
    }
}

#[test]
fn a_two_d_image_is_described_not_rendered() {
    // The THUMB extension alone: a copy of multi.fits cut after it.
    let bytes = fixture_bytes("multi.fits");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("thumb.fits");
    // Primary (1 block) + THUMB header (1 block) + data (1 block).
    fs::write(&p, &bytes[..3 * 2880]).unwrap();
    match read(&p, &ReadOptions::default()) {
        Err(IoError::FlatImage { image, .. }) => {
            assert_eq!(image.dims, [8, 6, 1]);
            assert_eq!(image.values[8 + 3], 13.0);
            assert_eq!(image.format, VolumeFormat::Fits);
        }
        other => panic!("{:?}", other.map(|l| l.volume.dims())),
    }
}

// ---- malformed files: one line naming the file and the keyword ----

/// The fixture's bytes with header text `from` replaced by `to` (same length).
fn edited(name: &str, from: &str, to: &str) -> Vec<u8> {
    assert_eq!(from.len(), to.len());
    common::replace(&fixture_bytes(name), from, to)
}

#[test]
fn lying_and_huge_sizes_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let lying = edited(
        "i16.fits",
        "NAXIS3  =                    5",
        "NAXIS3  =                   99",
    );
    common::refuse(
        dir.path(),
        "lying.fits",
        &lying,
        "primary HDU: NAXISn 8 6 99 of BITPIX 16 declare 9504 bytes of data from byte 2880, but the file is 5760 bytes",
    );
    let huge = edited(
        "i16.fits",
        "NAXIS1  =                    8",
        "NAXIS1  =          99999999999",
    );
    common::refuse(dir.path(), "huge.fits", &huge, "NAXISn 99999999999 6 5");
    let overflow = edited(
        "i16.fits",
        "NAXIS1  =                    8",
        "NAXIS1  = 99999999999999999999",
    );
    common::refuse(
        dir.path(),
        "overflow.fits",
        &overflow,
        "NAXIS1 = 99999999999999999999: not a size",
    );
    let negative = edited(
        "i16.fits",
        "NAXIS2  =                    6",
        "NAXIS2  =                   -6",
    );
    common::refuse(
        dir.path(),
        "negative.fits",
        &negative,
        "NAXIS2 = -6: not a size",
    );
    let bitpix = edited(
        "i16.fits",
        "BITPIX  =                   16",
        "BITPIX  =                   12",
    );
    common::refuse(
        dir.path(),
        "bitpix.fits",
        &bitpix,
        "BITPIX = 12: not one of 8, 16, 32, 64, -32, -64",
    );
    // Within the file, over the memory limit.
    let small = ReadOptions {
        max_memory: 100,
        ..ReadOptions::default()
    };
    let err = common::refused_error(&common::fixture("fits", "i16.fits"), &small);
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    assert!(
        err.to_string().contains("NAXIS1 NAXIS2 NAXIS3 8 6 5"),
        "{err}"
    );
    // A gzip file cannot declare more than deflate can inflate to.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    std::io::Write::write_all(&mut gz, &huge[..2880]).unwrap();
    common::refuse(
        dir.path(),
        "huge.fits.gz",
        &gz.finish().unwrap(),
        "cannot inflate to that much",
    );
}

#[test]
fn truncated_data_and_headers_without_end_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = fixture_bytes("f64.fits");
    common::refuse(
        dir.path(),
        "short.fits",
        &bytes[..2880 + 1000],
        "declare 1920 bytes of data from byte 2880, but the file is 3880 bytes",
    );
    let no_end = common::replace(&bytes[..2880], "END     ", "ENX     ");
    common::refuse(
        dir.path(),
        "no_end.fits",
        &no_end,
        "primary HDU: the file ends inside the header (36 cards read, no END card)",
    );
    let mut binary = bytes.clone();
    binary[80 * 2 + 20] = 0xff;
    common::refuse(
        dir.path(),
        "binary.fits",
        &binary,
        "card 3 (keyword NAXIS) holds byte 0xff at column 21: header cards are printable ASCII",
    );
    common::refuse(
        dir.path(),
        "empty.fits",
        b"",
        "the file ends inside the header",
    );
    let not_simple = common::replace(&bytes, "SIMPLE  =", "SIMPLY  =");
    common::refuse(
        dir.path(),
        "simply.fits",
        &not_simple,
        "the first card is not SIMPLE",
    );
    let no_naxis = common::replace(&bytes, "NAXIS3  =", "NAXIS9  =");
    common::refuse(
        dir.path(),
        "naxis.fits",
        &no_naxis,
        "no NAXIS3 card (NAXIS = 3)",
    );
    // THUMB, the 2-D image read when nothing else is left, declares no data.
    let gcount = common::replace(
        &fixture_bytes("multi.fits")[..3 * 2880],
        "GCOUNT  =                    1",
        "GCOUNT  =                    0",
    );
    common::refuse(
        dir.path(),
        "gcount.fits",
        &gcount,
        "HDU 1 (EXTNAME 'THUMB'): the image needs 96 bytes, but its header declares 0 bytes of data (PCOUNT 0, GCOUNT 0)",
    );
    let bad_cdelt = common::replace(
        &fixture_bytes("wcs_mm.fits"),
        "CDELT1  =                  0.5",
        "CDELT1  =                  0.0",
    );
    common::refuse(
        dir.path(),
        "cdelt.fits",
        &bad_cdelt,
        "CDELT1 = 0.0 gives NAXIS1 a world step of 0",
    );
}

#[test]
fn broken_copies_never_panic() {
    let names = [
        "i16.fits",
        "u64.fits",
        "multi.fits",
        "radio_cube.fits",
        "i16.fits.gz",
        "scaled_i16.fits",
    ];
    let fixtures: Vec<_> = names.iter().map(|n| common::fixture("fits", n)).collect();
    common::byte_flips_never_panic(&fixtures, 0x5eed_f175, &[ReadOptions::default(), frame(2)]);
    common::mutations_never_panic(&fixtures[..4], "m.fits", 7);
    // Every 5th header byte of the first block replaced, and truncations.
    common::header_edits_never_panic(&fixtures[..2], 0, b"0 9-'=E\xff", |_| 2880);
}

#[test]
fn a_rotated_pc_matrix_keeps_the_grid_in_its_own_axes() {
    let l = load("rotated_mm.fits", &ReadOptions::default());
    check_voxels("rotated", &l.volume, DIMS, |i, j, k| {
        ramp(i, j, k) as f32 + 0.25
    });
    // astropy.wcs: pixel (1, 0, 0) at (√3, 1, 0), |step| 2 mm; origin 0.
    assert_eq!(l.volume.spacing(), DVec3::splat(2.0));
    assert_eq!(l.volume.origin(), DVec3::ZERO);
    assert_note(&l, "rotated away from world x, y, z");
}

#[test]
fn a_sheared_cd_matrix_is_resampled_over_its_box() {
    let l = load("sheared_mm.fits", &ReadOptions::default());
    assert!(l.info.nan_is_empty);
    assert_note(&l, "resampled trilinearly");
    // astropy.wcs: steps (1, 0, 0), (0.5, 1, 0), (0, 0, 1) mm from 0.
    let to_grid =
        volray_core::glam::DMat3::from_cols(DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::Z)
            .inverse();
    let inside = common::check_resampled(&l.volume, to_grid, [7.0, 5.0, 4.0], 1e-3, |g| {
        g.x + 10.0 * g.y + 100.0 * g.z + 0.25
    });
    assert!(inside > 100, "{inside}");
}

#[test]
fn unscaled_bytes_are_mapped_from_the_file() {
    let opts = ReadOptions {
        map: volray_io::MapPolicy::Always,
        ..ReadOptions::default()
    };
    let l = load("u8.fits", &opts);
    assert_note(&l, "mapped from the file");
    assert_eq!(l.volume, load("u8.fits", &ReadOptions::default()).volume);
    // Big-endian 16-bit samples cannot be: read into memory.
    let l = load("i16.fits", &opts);
    assert!(!common::has_note(&l, "mapped from the file"));
}
