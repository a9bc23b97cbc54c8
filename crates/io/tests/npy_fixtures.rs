//! Reads `.npy` files written by NumPy itself (see
//! `fixtures/make_npy_fixtures.py`) and checks every voxel against the
//! formula the fixture was made from. Each array has shape (2, 3, 4) and is
//! indexed `a[x, y, z]`, so a correct reader gives `dims == [2, 3, 4]` and
//! `get(x, y, z) == formula(x, y, z)` whatever the file's memory order.

mod common;

use std::path::PathBuf;

use common::check_voxels;
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{read_npy, read_volume, write_npy};

fn fixture(name: &str) -> PathBuf {
    common::fixture("", name)
}

fn ramp(x: usize, y: usize, z: usize) -> f32 {
    (x + 10 * y + 100 * z) as f32
}

fn check(name: &str, formula: impl Fn(usize, usize, usize) -> f32) {
    let v = read_npy(&fixture(name)).unwrap_or_else(|e| panic!("{e}"));
    check_voxels(name, &v, [2, 3, 4], formula);
    assert_eq!(v.spacing(), DVec3::ONE, "{name}");
    assert_eq!(v.origin(), DVec3::ZERO, "{name}");
}

#[test]
fn c_order_f4() {
    check("c_f4.npy", ramp);
}

#[test]
fn fortran_order_f4() {
    check("fortran_f4.npy", ramp);
}

#[test]
fn big_endian_f8() {
    check("be_f8.npy", ramp);
}

#[test]
fn unsigned_bytes() {
    check("u1.npy", |x, y, z| (x + 2 * y + 6 * z) as f32);
}

#[test]
fn negative_i2() {
    check("i2.npy", |x, y, z| -ramp(x, y, z));
}

#[test]
fn little_endian_u2_fortran() {
    check("le_u2.npy", |x, y, z| 100.0 * ramp(x, y, z));
}

#[test]
fn bool_as_zero_one() {
    check("bool.npy", |x, y, z| ((x + y + z) % 2) as f32);
}

#[test]
fn half_floats() {
    check("le_f2.npy", ramp);
}

#[test]
fn big_endian_i8_fortran() {
    check("be_i8.npy", ramp);
}

#[test]
fn format_version_2() {
    check("v2_f4.npy", ramp);
}

#[test]
fn format_version_3() {
    check("v3_f4.npy", ramp);
}

#[test]
fn read_volume_dispatches_to_npy() {
    let v = read_volume(&fixture("c_f4.npy"), None).unwrap();
    assert_eq!(v, read_npy(&fixture("fortran_f4.npy")).unwrap());
}

#[test]
fn write_npy_round_trips_a_numpy_file() {
    let dir = tempfile::tempdir().unwrap();
    let original = read_npy(&fixture("c_f4.npy")).unwrap();
    let p = dir.path().join("copy.npy");
    write_npy(&p, &original).unwrap();
    let back = read_npy(&p).unwrap();
    assert_eq!(back, original);
    // Written in Fortran order, x fastest: the data bytes are the volume's.
    let bytes = std::fs::read(&p).unwrap();
    let data: Vec<f32> = bytes[bytes.len() - 24 * 4..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(data, *original.values());
}

#[test]
fn write_npy_round_trips_odd_values() {
    let dir = tempfile::tempdir().unwrap();
    let data = vec![
        0.0,
        -0.0,
        1.5,
        -3.25e-20,
        f32::MAX,
        f32::MIN_POSITIVE,
        f32::INFINITY,
        1e-45,
    ];
    let v = Volume::new([2, 2, 2], data)
        .unwrap()
        .with_spacing(DVec3::new(2.0, 3.0, 4.0))
        .unwrap();
    let p = dir.path().join("odd.npy");
    write_npy(&p, &v).unwrap();
    let back = read_npy(&p).unwrap();
    // .npy stores no spacing: it comes back as 1.
    assert_eq!(back.spacing(), DVec3::ONE);
    let bits = |v: &Volume| v.values().iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back), bits(&v));
}
