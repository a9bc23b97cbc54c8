//! NetCDF-3 files written by netCDF4-python (CDF-1, CDF-2, CDF-5) and
//! xarray (CF packing), `fixtures/make_netcdf_fixtures.py`: the values
//! and coordinates volray reads are what those tools read back.
//!
//! Stored at (t, k, j, i) (time, z, y, x): `i + 10j + 100k + 1000t`.

mod common;

use common::{
    Grid, assert_frame_out_of_range, assert_note, byte_flips_never_panic, check_world, fixture,
    frame, header_value, read_or_refuse, refuse, refused, refused_at, refused_error, truncations,
    with_array,
};
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn load(name: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&fixture("netcdf", name), opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.format, VolumeFormat::Netcdf);
    l
}

fn array_frame(array: &str, frame: usize) -> ReadOptions {
    ReadOptions {
        frame: Some(frame),
        ..with_array(Some(array))
    }
}

/// [`check_world`] where NaN equals NaN: the volume is checked with its
/// NaN and the wanted NaN both replaced by a value no sample holds.
fn check_world_nan(
    what: &str,
    vol: &volray_core::Volume,
    grid: &Grid,
    want: impl Fn(usize, usize, usize) -> f32,
) {
    const HOLE: f32 = -1.0e30;
    let values: Vec<f32> = (0..vol.len())
        .map(|n| {
            let [nx, ny, _] = vol.dims();
            let v = vol.get(n % nx, (n / nx) % ny, n / (nx * ny));
            if v.is_nan() { HOLE } else { v }
        })
        .collect();
    let holes = volray_core::Volume::new(vol.dims(), values)
        .unwrap()
        .with_spacing(vol.spacing())
        .unwrap()
        .with_origin(vol.origin())
        .unwrap();
    check_world(what, &holes, grid, 1e-9, |i, j, k| {
        let v = want(i, j, k);
        if v.is_nan() { HOLE } else { v }
    });
}

fn ramp(i: usize, j: usize, k: usize, t: usize) -> f64 {
    (i + 10 * j + 100 * k + 1000 * t) as f64
}

/// The file's grid: x = -3 + 0.5 i mm, y = 20 - 2 j mm, z = 10 + 4 k mm
/// (0.01 + 0.004 k m).
fn classic_grid() -> Grid {
    Grid {
        n: [12, 10, 8],
        steps: [DVec3::X * 0.5, DVec3::Y * -2.0, DVec3::Z * 4.0],
        origin: DVec3::new(-3.0, 20.0, 10.0),
    }
}

#[test]
fn the_three_versions_read_alike_with_coordinates_in_mm_and_m() {
    for (name, version) in [
        ("classic.nc", "CDF-1"),
        ("offset64.nc", "CDF-2"),
        ("data64.nc", "CDF-5"),
    ] {
        let l = load(name, &with_array(Some("rho")));
        assert!(header_value(&l, "format").contains(version), "{name}");
        check_world(name, &l.volume, &classic_grid(), 1e-9, |i, j, k| {
            (ramp(i, j, k, 0) + 0.25) as f32
        });
        assert_eq!(l.volume.dims(), [12, 10, 8]);
        assert!((l.volume.spacing() - DVec3::new(0.5, 2.0, 4.0)).length() < 1e-9);
        // y decreases: flipped, its lowest value 20 - 2·9 = 2.
        assert!((l.volume.origin() - DVec3::new(-3.0, 2.0, 10.0)).length() < 1e-9);
        assert_eq!(l.info.length_unit.as_deref(), Some("mm"), "{name}");
        // Lengths brought to one unit: nothing for the display scale.
        assert_eq!(l.info.axis_units, None, "{name}");
        assert_note(
            &l,
            "x (x)/y (y) in mm, z (z) in m: spacing in mm (z (z) × 1000)",
        );
        assert_note(&l, "index axis 1 -> -y");
        assert_eq!(l.info.stored_type, "float32 (big-endian)");
        assert_eq!(l.info.array.as_deref(), Some("rho"));
        assert_eq!(l.info.arrays, ["rho", "temp"]);
        assert_eq!(
            header_value(&l, "dimensions"),
            "time = 2 (unlimited), z = 8, y = 10, x = 12"
        );
        assert_eq!(
            header_value(&l, "variable rho"),
            "float32 (time, z, y, x) [kg m-3]"
        );
        assert_eq!(header_value(&l, ":title"), "\"volray NetCDF-3 fixture\"");
    }
}

#[test]
fn time_is_the_record_dimension_and_frame_picks_a_record() {
    let l = load("classic.nc", &array_frame("rho", 1));
    assert_eq!((l.info.frames, l.info.frame), (2, 1));
    check_world("frame 1", &l.volume, &classic_grid(), 1e-9, |i, j, k| {
        (ramp(i, j, k, 1) + 0.25) as f32
    });
    assert_note(&l, "time = 3600 (seconds since 2000-01-01)");
    let err = refused_error(&fixture("netcdf", "classic.nc"), &array_frame("rho", 2));
    assert_frame_out_of_range(&err, 2, "variable rho holds 2 volume(s) along \"time\"");
}

#[test]
fn several_volume_variables_need_array_and_the_refusal_lists_them() {
    let path = fixture("netcdf", "classic.nc");
    let msg = refused(&path, &ReadOptions::default());
    assert!(
        msg.contains("rho(time, z, y, x), temp(time, z, y, x)") && msg.contains("--array"),
        "{msg}"
    );
    let err = refused_error(&path, &with_array(Some("salt")));
    assert!(matches!(err, IoError::NoSuchArray { .. }), "{err}");
}

#[test]
fn values_outside_valid_range_are_nan_and_empty() {
    for (name, stored) in [("classic.nc", "int16"), ("data64.nc", "uint16")] {
        let l = load(name, &array_frame("temp", 1));
        assert_eq!(l.info.stored_type, format!("{stored} (big-endian)"));
        assert!(l.info.nan_is_empty);
        assert_note(&l, "outside [0, 1500]");
        check_world_nan(name, &l.volume, &classic_grid(), |i, j, k| {
            let v = ramp(i, j, k, 1);
            if v > 1500.0 { f32::NAN } else { v as f32 }
        });
    }
}

#[test]
fn xarray_packing_and_fill_values_with_latitude_and_longitude() {
    let l = load("packed.nc", &frame(1));
    // lon 10 + 1.5 i (degrees_east), lat 40 - 0.5 j (degrees_north), lev
    // 100 k (m, positive up): not one length unit, each axis in its own.
    let grid = Grid {
        n: [6, 5, 4],
        steps: [DVec3::X * 1.5, DVec3::Y * -0.5, DVec3::Z * 100.0],
        origin: DVec3::new(10.0, 40.0, 0.0),
    };
    check_world_nan("packed", &l.volume, &grid, |i, j, k| {
        let r = ramp(i, j, k, 1);
        if r % 7.0 == 0.0 {
            return f32::NAN;
        }
        // xarray's encoding: stored = round((v - 5) / 0.1); CF decoding:
        // stored · 0.1 + 5 (the script checks xarray reads the same).
        let stored = ((r / 2.0 - 5.0) / 0.1).round();
        (stored * 0.1 + 5.0) as f32
    });
    assert_eq!(l.info.length_unit, None);
    // Each world axis's name and unit, for the display scale.
    let units = l.info.axis_units.clone().expect("kept apart");
    let named = units.map(|a| (a.name, a.unit.unwrap_or_default()));
    assert_eq!(
        named,
        [
            ("lon", "degrees_east"),
            ("lat", "degrees_north"),
            ("lev", "m")
        ]
        .map(|(n, u)| (n.to_string(), u.to_string()))
    );
    assert_note(
        &l,
        "x (lon) in degrees_east, y (lat) in degrees_north: not length units, kept as written",
    );
    assert_note(&l, "real = stored · 0.1 + 5 (scale_factor, add_offset)");
    assert_note(&l, "-32767");
    assert_note(&l, "lon is x (standard_name = \"longitude\")");
    assert!(l.info.nan_is_empty);
    assert_eq!(l.info.stored_type, "int16 (big-endian)");
    assert!(header_value(&l, "format").contains("CDF-2"));
}

#[test]
fn unevenly_spaced_coordinates_are_refused_naming_the_axis() {
    let msg = refused(&fixture("netcdf", "uneven.nc"), &ReadOptions::default());
    assert!(
        msg.contains(
            "coordinate variable x (x axis) is unevenly spaced: value 1 is 1, 2 at the mean step 2"
        ),
        "{msg}"
    );
}

#[test]
fn a_netcdf_file_is_known_by_its_magic_under_any_name() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("model_output.dat");
    std::fs::copy(fixture("netcdf", "offset64.nc"), &p).unwrap();
    let l = read(&p, &array_frame("rho", 0)).unwrap();
    assert_eq!(l.format, VolumeFormat::Netcdf);
    assert_eq!(l.volume.get(1, 9, 1), (ramp(1, 0, 1, 0) + 0.25) as f32);
}

// ---- malformed files: one line, no panic ----

/// A CDF-1 file with dimensions `dims` (length 0: the record dimension)
/// and one float variable `v` over all of them whose data begin at
/// `begin` (`None`: right after the header), `numrecs` records, and
/// `data` floats after the header.
fn cdf1(dims: &[(&str, u32)], numrecs: u32, begin: Option<u32>, data: usize) -> Vec<u8> {
    let mut b = b"CDF\x01".to_vec();
    let word = |b: &mut Vec<u8>, w: u32| b.extend_from_slice(&w.to_be_bytes());
    let name = |b: &mut Vec<u8>, n: &str| {
        b.extend_from_slice(&(n.len() as u32).to_be_bytes());
        b.extend_from_slice(n.as_bytes());
        b.resize(b.len().div_ceil(4) * 4, 0);
    };
    word(&mut b, numrecs);
    word(&mut b, 0x0A);
    word(&mut b, dims.len() as u32);
    for (n, len) in dims {
        name(&mut b, n);
        word(&mut b, *len);
    }
    word(&mut b, 0);
    word(&mut b, 0); // no global attributes
    word(&mut b, 0x0B);
    word(&mut b, 1);
    name(&mut b, "v");
    word(&mut b, dims.len() as u32);
    for d in 0..dims.len() {
        word(&mut b, d as u32);
    }
    word(&mut b, 0);
    word(&mut b, 0); // no attributes
    word(&mut b, 5); // float
    word(&mut b, (data * 4) as u32);
    let at = b.len() as u32 + 4;
    word(&mut b, begin.unwrap_or(at));
    for i in 0..data {
        b.extend_from_slice(&(i as f32).to_be_bytes());
    }
    b
}

#[test]
fn a_hand_made_file_reads() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("ok.nc");
    std::fs::write(&p, cdf1(&[("z", 2), ("y", 3), ("x", 4)], 0, None, 24)).unwrap();
    let l = read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(l.volume.dims(), [4, 3, 2]);
    assert_eq!(l.volume.get(3, 2, 1), 23.0);
    assert_note(&l, "x (x): no coordinate variable, spacing 1 from 0");
}

#[test]
fn lying_dimensions_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = cdf1(&[("z", 2), ("y", 3), ("x", 40)], 0, None, 24);
    refuse(dir.path(), "lying.nc", &bytes, "past the end of the file");
}

#[test]
fn truncated_data_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = cdf1(&[("z", 2), ("y", 3), ("x", 4)], 0, None, 24);
    refuse(
        dir.path(),
        "short.nc",
        &bytes[..bytes.len() - 5],
        "truncated",
    );
}

#[test]
fn huge_declared_sizes_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let big = i32::MAX as u32;
    let bytes = cdf1(&[("z", big), ("y", big), ("x", big)], 0, None, 24);
    refuse(
        dir.path(),
        "huge.nc",
        &bytes,
        "more than this machine can address",
    );
    let bytes = cdf1(&[("z", 1000), ("y", 1000), ("x", 1000)], 0, None, 24);
    let small = ReadOptions {
        max_memory: 1 << 30,
        ..ReadOptions::default()
    };
    let msg = refused_at(dir.path(), "big.nc", &bytes, &small);
    assert!(msg.contains("exceed the memory limit of 1 GiB"), "{msg}");
    // A list or a name longer than the file.
    let mut bytes = cdf1(&[("z", 2), ("y", 3), ("x", 4)], 0, None, 24);
    bytes[15] = 0x7f; // the dimension count, 0x0000_007f... → 127
    bytes[12] = 0x7f;
    refuse(dir.path(), "count.nc", &bytes, "more than the");
    let mut bytes = cdf1(&[("z", 2), ("y", 3), ("x", 4)], 0, None, 24);
    bytes[16..20].copy_from_slice(&0x7fff_fff0u32.to_be_bytes()); // name length
    refuse(dir.path(), "name.nc", &bytes, "left in the file");
    // Negative: a count with the sign bit set.
    let mut bytes = cdf1(&[("z", 2), ("y", 3), ("x", 4)], 0, None, 24);
    bytes[16..20].copy_from_slice(&0x8000_0001u32.to_be_bytes());
    refuse(dir.path(), "negative.nc", &bytes, "is negative");
    // Too many records for the file.
    let bytes = cdf1(&[("t", 0), ("y", 3), ("x", 4)], 1 << 30, None, 24);
    refuse(dir.path(), "records.nc", &bytes, "numrecs");
}

#[test]
fn bad_offsets_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let dims = [("z", 2), ("y", 3), ("x", 4)];
    refuse(
        dir.path(),
        "far.nc",
        &cdf1(&dims, 0, Some(0xffff_0000), 24),
        "past the end of the file",
    );
    refuse(
        dir.path(),
        "inside.nc",
        &cdf1(&dims, 0, Some(8), 24),
        "inside the header",
    );
    // A version volray does not know, and a type code no version has.
    let mut bytes = cdf1(&dims, 0, None, 24);
    bytes[3] = 3;
    refuse(dir.path(), "v3.nc", &bytes, "not NetCDF-3");
    let bytes = cdf1(&dims, 0, None, 24);
    let at = bytes.len() - 24 * 4 - 12;
    let mut bad = bytes.clone();
    bad[at..at + 4].copy_from_slice(&99u32.to_be_bytes());
    refuse(dir.path(), "type.nc", &bad, "type code 99");
}

#[test]
fn broken_fixtures_never_panic() {
    for name in ["classic.nc", "data64.nc", "packed.nc"] {
        let good = std::fs::read(fixture("netcdf", name)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(name);
        for t in truncations(&good, 97) {
            std::fs::write(&p, t).unwrap();
            assert!(!read_or_refuse(&p, &with_array(Some("rho"))) || t.len() > 1000);
        }
    }
    let files: Vec<_> = ["classic.nc", "offset64.nc", "data64.nc", "packed.nc"]
        .iter()
        .map(|n| fixture("netcdf", n))
        .collect();
    byte_flips_never_panic(
        &files,
        0x6e63,
        &[
            ReadOptions::default(),
            with_array(Some("rho")),
            array_frame("temp", 1),
        ],
    );
}

#[test]
fn a_netcdf4_file_is_read_by_the_netcdf4_reader_and_opened_box_by_box() {
    // HDF5 underneath: the file, `file.nc:/var` and `--format netcdf` all
    // go to formats/netcdf4.rs, the right way round (x the last dimension).
    let path = fixture("netcdf", "netcdf4.nc");
    let spec = std::path::PathBuf::from(format!("{}:/r", path.display()));
    let forced = ReadOptions {
        format: Some(VolumeFormat::Netcdf),
        ..ReadOptions::default()
    };
    for (p, opts) in [
        (&path, ReadOptions::default()),
        (&spec, ReadOptions::default()),
        (&path, forced),
    ] {
        let l = read(p, &opts).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert_eq!(l.format, VolumeFormat::Netcdf, "{}", p.display());
        common::check_voxels("netcdf4", &l.volume, [4, 3, 2], |x, y, z| {
            ramp(x, y, z, 0) as f32
        });
    }
    // `--format hdf5` names the bare dataset, its axes from the scales.
    let bare = ReadOptions {
        format: Some(VolumeFormat::Hdf5),
        ..ReadOptions::default()
    };
    let l = read(&spec, &bare).unwrap();
    assert_eq!(l.format, VolumeFormat::Hdf5);
    common::check_voxels("netcdf4 as hdf5", &l.volume, [4, 3, 2], |x, y, z| {
        ramp(x, y, z, 0) as f32
    });
    let lazy = volray_io::open_lazy(&path, &ReadOptions::default()).unwrap();
    assert!(lazy.is_some_and(|l| l.format == VolumeFormat::Netcdf));
}
