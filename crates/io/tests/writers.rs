//! The writers keep the volume's own sample type: a volume of each type
//! (`u8`, `i8`, `u16`, `i16`, `f32`, with each type's extremes) written as
//! NRRD, `.npy` and raw reads back as the same volume, in the same type,
//! with NRRD keeping spacing and origin exactly; the files are their
//! type's size, not `f32`'s.

use volray_core::glam::DVec3;
use volray_core::{SampleType, Samples, Volume};
use volray_io::{DType, RawOptions, ReadOptions, read, write_npy, write_nrrd, write_raw};

/// A 5×4×3 volume of type `t`, counting up from its smallest value and
/// ending on its largest.
fn volume(t: SampleType) -> Volume {
    let n = 60;
    let samples: Samples = match t {
        SampleType::U8 => (0..n)
            .map(|i| if i == n - 1 { 255 } else { i as u8 * 3 })
            .collect::<Vec<u8>>()
            .into(),
        SampleType::I8 => (0..n)
            .map(|i| {
                if i == 0 {
                    i8::MIN
                } else if i == n - 1 {
                    i8::MAX
                } else {
                    i as i8 - 30
                }
            })
            .collect::<Vec<i8>>()
            .into(),
        SampleType::U16 => (0..n)
            .map(|i| {
                if i == n - 1 {
                    u16::MAX
                } else {
                    i as u16 * 1000
                }
            })
            .collect::<Vec<u16>>()
            .into(),
        SampleType::I16 => (0..n)
            .map(|i| {
                if i == 0 {
                    i16::MIN
                } else if i == n - 1 {
                    i16::MAX
                } else {
                    i as i16 * 500 - 15000
                }
            })
            .collect::<Vec<i16>>()
            .into(),
        SampleType::F32 => (0..n)
            .map(|i| {
                if i == 0 {
                    f32::MIN_POSITIVE
                } else {
                    i as f32 * -0.37 + 1e6
                }
            })
            .collect::<Vec<f32>>()
            .into(),
    };
    Volume::from_samples([5, 4, 3], samples)
        .unwrap()
        .with_spacing(DVec3::new(0.3, 1.0 / 7.0, 2.5))
        .unwrap()
        .with_origin(DVec3::new(-4.0, 1e-3, 12.75))
        .unwrap()
}

fn dtype(t: SampleType) -> DType {
    match t {
        SampleType::U8 => DType::U8,
        SampleType::I8 => DType::I8,
        SampleType::U16 => DType::U16,
        SampleType::I16 => DType::I16,
        SampleType::F32 => DType::F32,
    }
}

#[test]
fn every_sample_type_is_written_in_its_own_type_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    for t in [
        SampleType::U8,
        SampleType::I8,
        SampleType::U16,
        SampleType::I16,
        SampleType::F32,
    ] {
        let v = volume(t);
        let data_bytes = (60 * t.bytes()) as u64;

        let nrrd = dir.path().join(format!("{}.nrrd", t.name()));
        write_nrrd(&nrrd, &v).unwrap();
        let back = read(&nrrd, &ReadOptions::default()).unwrap().volume;
        assert_eq!(back, v, "{}: NRRD", t.name());
        assert_eq!(back.sample_type(), t);

        let npy = dir.path().join(format!("{}.npy", t.name()));
        write_npy(&npy, &v).unwrap();
        let back = read(&npy, &ReadOptions::default()).unwrap().volume;
        assert_eq!(back.sample_type(), t, "{}: .npy", t.name());
        assert_eq!(back.values(), v.values(), "{}: .npy", t.name());
        // 128 bytes of preamble and header, then the samples.
        assert_eq!(std::fs::metadata(&npy).unwrap().len(), 128 + data_bytes);

        let raw = dir.path().join(format!("{}.raw", t.name()));
        write_raw(&raw, &v).unwrap();
        assert_eq!(std::fs::metadata(&raw).unwrap().len(), data_bytes);
        let opts = ReadOptions {
            raw: Some(RawOptions::new([5, 4, 3], dtype(t))),
            ..ReadOptions::default()
        };
        let back = read(&raw, &opts).unwrap().volume;
        assert_eq!(back.sample_type(), t, "{}: raw", t.name());
        assert_eq!(back.values(), v.values(), "{}: raw", t.name());
    }
}
