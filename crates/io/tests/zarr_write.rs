//! `write_ome_zarr`: a volume of every sample type, written as OME-Zarr
//! 0.5 (Zarr v3) and 0.4 (Zarr v2) with odd dimensions, reads back through
//! volray's own reader level by level: level 0 the volume itself, each
//! lower level the block means (labels: modes) computed here
//! independently, with each level's spacing and origin as the writer
//! documents them; the source is read a tile at a time, never whole; a
//! memory limit too small for a tile is refused with one line and leaves
//! nothing behind; an existing store is replaced, anything else refused.

use std::sync::Mutex;

use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{SampleType, Samples, Volume, VolumeSource};
use volray_io::{IoError, OmeZarrOptions, ReadOptions, ZarrVersion, read, write_ome_zarr};

const DIMS: [usize; 3] = [37, 20, 9];
const SPACING: DVec3 = DVec3::new(0.5, 1.25, 2.0);
const ORIGIN: DVec3 = DVec3::new(-3.0, 4.0, 10.5);

/// A scrambled but reproducible value in `0..m` for voxel `i`.
fn scramble(i: usize, m: u64) -> u64 {
    let mut h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x5851_F42D;
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    (h ^ (h >> 32)) % m
}

/// A volume of type `t` over its whole range, its extremes included; for
/// labels, values among a few (so that blocks hold ties).
fn volume(t: SampleType, labels: bool) -> Volume {
    let n = DIMS.iter().product::<usize>();
    let pick = |i: usize, lo: i64, hi: i64| -> i64 {
        if labels {
            lo.max(-2) + scramble(i, 4) as i64
        } else if i == 0 {
            lo
        } else if i == n - 1 {
            hi
        } else {
            lo + scramble(i, (hi - lo + 1) as u64) as i64
        }
    };
    let samples: Samples = match t {
        SampleType::U8 => (0..n)
            .map(|i| pick(i, 0, 255) as u8)
            .collect::<Vec<_>>()
            .into(),
        SampleType::I8 => (0..n)
            .map(|i| pick(i, -128, 127) as i8)
            .collect::<Vec<_>>()
            .into(),
        SampleType::U16 => (0..n)
            .map(|i| pick(i, 0, 65535) as u16)
            .collect::<Vec<_>>()
            .into(),
        SampleType::I16 => (0..n)
            .map(|i| pick(i, -32768, 32767) as i16)
            .collect::<Vec<_>>()
            .into(),
        SampleType::F32 => (0..n)
            .map(|i| {
                if labels {
                    pick(i, 0, 3) as f32
                } else {
                    (scramble(i, 1 << 20) as f32 - 5e5) * 1.0e-3
                }
            })
            .collect::<Vec<f32>>()
            .into(),
    };
    let mut v = Volume::from_samples(DIMS, samples)
        .unwrap()
        .with_spacing(SPACING)
        .unwrap()
        .with_origin(ORIGIN)
        .unwrap();
    v.set_labels(labels);
    v
}

/// The next level of `values` (dims `d`, x fastest), as documented: axes
/// of more than 2 voxels halve (`ceil`), each voxel the mean of the
/// voxels of its block present (rounded, halves away from zero, for
/// integers) or, for labels, the most common (the smallest of those
/// tied).
fn next_level(
    values: &[f64],
    d: [usize; 3],
    t: SampleType,
    labels: bool,
) -> (Vec<f64>, [usize; 3]) {
    let f = d.map(|n| if n > 2 { 2 } else { 1 });
    let e: [usize; 3] = std::array::from_fn(|a| d[a].div_ceil(f[a]));
    let mut out = Vec::with_capacity(e.iter().product());
    for z in 0..e[2] {
        for y in 0..e[1] {
            for x in 0..e[0] {
                let mut block = Vec::new();
                for zz in z * f[2]..((z + 1) * f[2]).min(d[2]) {
                    for yy in y * f[1]..((y + 1) * f[1]).min(d[1]) {
                        for xx in x * f[0]..((x + 1) * f[0]).min(d[0]) {
                            block.push(values[xx + d[0] * (yy + d[1] * zz)]);
                        }
                    }
                }
                let v = if labels {
                    let mut best = (0usize, f64::INFINITY);
                    for &v in &block {
                        let count = block.iter().filter(|&&w| w == v).count();
                        if count > best.0 || (count == best.0 && v < best.1) {
                            best = (count, v);
                        }
                    }
                    best.1
                } else {
                    let mean = block.iter().sum::<f64>() / block.len() as f64;
                    match t {
                        SampleType::F32 => f64::from(mean as f32),
                        _ => mean.round(),
                    }
                };
                out.push(v);
            }
        }
    }
    (out, e)
}

fn options(version: ZarrVersion) -> OmeZarrOptions {
    OmeZarrOptions {
        zarr_version: version,
        chunk: 8,
        shard: 16,
        ..OmeZarrOptions::default()
    }
}

/// A volume that records the largest box read from it.
struct Recording {
    volume: Volume,
    largest: Mutex<usize>,
}

impl VolumeSource for Recording {
    fn grid(&self) -> GridFrame {
        self.volume.grid()
    }
    fn sample_type(&self) -> SampleType {
        self.volume.sample_type()
    }
    fn is_labels(&self) -> bool {
        self.volume.is_labels()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        let n = (0..3).map(|a| hi[a] - lo[a]).product::<usize>();
        let mut largest = self.largest.lock().unwrap();
        *largest = (*largest).max(n);
        self.volume.read_box(lo, hi)
    }
}

/// Writes `volume` and checks every level read back against the pyramid
/// computed here, and each level's geometry and chunking.
fn round_trip(volume: Volume, version: ZarrVersion) {
    let t = volume.sample_type();
    let labels = volume.is_labels();
    let what = format!("{} {version:?} labels={labels}", t.name());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.ome.zarr");
    let source = Recording {
        volume: volume.clone(),
        largest: Mutex::new(0),
    };
    let written = write_ome_zarr(&path, &source, &options(version)).unwrap();
    // Read a tile at a time (16x16x9 at most), never whole.
    assert_eq!(*source.largest.lock().unwrap(), 16 * 16 * 9, "{what}");
    assert_eq!(written.labels, labels);
    let dims: Vec<[usize; 3]> = written.levels.iter().map(|l| l.dims).collect();
    assert_eq!(
        dims,
        [[37, 20, 9], [19, 10, 5], [10, 5, 3], [5, 3, 2]],
        "{what}"
    );
    let marker = match version {
        ZarrVersion::V3 => "zarr.json",
        ZarrVersion::V2 => ".zgroup",
    };
    assert!(path.join(marker).is_file(), "{what}");
    assert!(path.join("3").is_dir(), "{what}");

    let mut expect: Vec<f64> = volume.values().iter().map(|&v| f64::from(v)).collect();
    let mut d = DIMS;
    let (mut spacing, mut origin) = (SPACING, ORIGIN);
    for (k, level) in written.levels.iter().enumerate() {
        if k > 0 {
            for a in 0..3 {
                if d[a] > 2 {
                    origin[a] += 0.5 * spacing[a];
                    spacing[a] *= 2.0;
                }
            }
            (expect, d) = next_level(&expect, d, t, labels);
        }
        let opts = ReadOptions {
            level: Some(k),
            ..ReadOptions::default()
        };
        let loaded = read(&path, &opts).unwrap_or_else(|e| panic!("{what}: {e}"));
        let v = &loaded.volume;
        assert_eq!(v.dims(), d, "{what} level {k}");
        assert_eq!(v.sample_type(), t, "{what} level {k}");
        let got: Vec<f64> = v.values().iter().map(|&x| f64::from(x)).collect();
        if let Some(i) = (0..got.len()).find(|&i| got[i] != expect[i]) {
            panic!(
                "{what} level {k}: voxel {i} is {} but the block gives {}",
                got[i], expect[i]
            );
        }
        assert!(
            (v.spacing() - spacing).abs().max_element() < 1e-12,
            "{what} {k}"
        );
        assert!(
            (v.origin() - origin).abs().max_element() < 1e-12,
            "{what} {k}"
        );
        assert_eq!(level.spacing, spacing.to_array());
        assert_eq!(level.origin, origin.to_array());

        let info = &loaded.info.levels[k];
        let zyx = |n: [usize; 3]| vec![n[2] as u64, n[1] as u64, n[0] as u64];
        assert_eq!(info.chunk_shape, Some(zyx(level.chunk)), "{what} {k}");
        match version {
            ZarrVersion::V3 => {
                assert_eq!(info.codecs, "sharding_indexed(bytes, zstd)", "{what}");
                assert_eq!(info.shard_shape, level.shard.map(zyx), "{what}");
            }
            ZarrVersion::V2 => {
                assert_eq!(info.codecs, "blosc (zstd)", "{what}");
                assert_eq!(level.shard, None);
            }
        }
    }
    let first = &written.levels[0];
    assert_eq!(first.chunk, [8, 8, 8]);
    if version == ZarrVersion::V3 {
        assert_eq!(first.shard, Some([16, 16, 16]));
        assert_eq!(written.levels[3].chunk, [5, 3, 2]);
    }
    // Only the store is left in the directory: no temporary.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "{what}");
}

#[test]
fn every_sample_type_reads_back_level_by_level_in_v3_and_v2() {
    for t in [
        SampleType::U8,
        SampleType::I8,
        SampleType::U16,
        SampleType::I16,
        SampleType::F32,
    ] {
        for version in [ZarrVersion::V3, ZarrVersion::V2] {
            round_trip(volume(t, false), version);
        }
    }
}

#[test]
fn label_volumes_get_block_modes() {
    for t in [SampleType::U8, SampleType::I16, SampleType::F32] {
        round_trip(volume(t, true), ZarrVersion::V3);
    }
    round_trip(volume(SampleType::U16, true), ZarrVersion::V2);
    // The option overrides the source: the same u8 labels as intensities
    // give means, which differ from the modes.
    let dir = tempfile::tempdir().unwrap();
    let labels = volume(SampleType::U8, true);
    let mut level1 = Vec::new();
    for as_labels in [true, false] {
        let path = dir.path().join(format!("{as_labels}.zarr"));
        let opts = OmeZarrOptions {
            labels: Some(as_labels),
            ..options(ZarrVersion::V3)
        };
        assert_eq!(
            write_ome_zarr(&path, &labels, &opts).unwrap().labels,
            as_labels
        );
        let read1 = ReadOptions {
            level: Some(1),
            ..ReadOptions::default()
        };
        level1.push(read(&path, &read1).unwrap().volume.values().to_vec());
    }
    assert_ne!(level1[0], level1[1]);
}

#[test]
fn a_memory_limit_under_a_tile_is_refused_in_one_line_leaving_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("small.ome.zarr");
    let opts = OmeZarrOptions {
        max_memory: 4096,
        ..options(ZarrVersion::V3)
    };
    let err = write_ome_zarr(&path, &volume(SampleType::U16, false), &opts).unwrap_err();
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    assert!(msg.contains("tiles of 16x16x16"), "{msg}");
    assert!(msg.contains("the memory limit of 4 KiB"), "{msg}");
    assert_eq!(msg.lines().count(), 1);
    assert!(!path.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn an_existing_store_is_replaced_and_anything_else_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.zarr");
    let opts = options(ZarrVersion::V3);
    write_ome_zarr(&path, &volume(SampleType::U8, false), &opts).unwrap();
    // A v2 store over the v3 one: nothing of the v3 one is left.
    let v = volume(SampleType::I16, false);
    write_ome_zarr(&path, &v, &options(ZarrVersion::V2)).unwrap();
    assert!(!path.join("zarr.json").exists());
    let back = read(&path, &ReadOptions::default()).unwrap().volume;
    assert_eq!(back.values(), v.values());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    // A directory that is no Zarr store, and a file, are left alone.
    let other = dir.path().join("photos");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join("a.jpg"), b"jpeg").unwrap();
    let file = dir.path().join("notes.zarr");
    std::fs::write(&file, b"text").unwrap();
    for target in [&other, &file] {
        let err = write_ome_zarr(target, &v, &opts).unwrap_err();
        assert!(err.to_string().contains("is not a Zarr store"), "{err}");
    }
    assert_eq!(std::fs::read(other.join("a.jpg")).unwrap(), b"jpeg");
    assert_eq!(std::fs::read(&file).unwrap(), b"text");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}

#[test]
fn a_source_that_fails_leaves_no_store() {
    struct Failing(Volume);
    impl VolumeSource for Failing {
        fn grid(&self) -> GridFrame {
            self.0.grid()
        }
        fn sample_type(&self) -> SampleType {
            self.0.sample_type()
        }
        fn read_box(
            &self,
            lo: [usize; 3],
            hi: [usize; 3],
        ) -> Result<Volume, volray_core::SourceError> {
            if lo[0] > 0 {
                return Err(volray_core::SourceError::io(
                    "disk.raw: cannot read: input/output error",
                ));
            }
            self.0.read_box(lo, hi)
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.ome.zarr");
    let source = Failing(volume(SampleType::U8, false));
    let err = write_ome_zarr(&path, &source, &options(ZarrVersion::V3)).unwrap_err();
    assert!(err.to_string().contains("input/output error"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
