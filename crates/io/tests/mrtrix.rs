//! MRtrix images (formats/mrtrix.rs), written here after MRtrix3's
//! documented layout (no independent writer is at hand: nibabel reads no
//! MRtrix format and MRtrix3 is not on PyPI): each file's samples are laid
//! out in memory order by loops written for its `layout`, independently
//! of the reader's strides, and every sample is checked at its world
//! position `R · diag(vox) · index + t` (`check_world`).

mod common;

use std::io::Write;
use std::path::Path;

use common::{Grid, check_world, read_or_refuse, refused, truncations};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

fn value(i: usize, j: usize, k: usize) -> f32 {
    (i + 10 * j + 100 * k) as f32
}

/// A `.mif`: `header` lines (without `file:` and `END`), then the data at
/// the next multiple of 16 bytes.
fn mif(header: &str, data: &[u8]) -> Vec<u8> {
    let mut text = format!("mrtrix image\n{header}");
    let len = text.len() + "file: . 0000\nEND\n".len();
    let offset = len.div_ceil(16) * 16;
    text.push_str(&format!("file: . {offset:04}\nEND\n"));
    let mut out = text.into_bytes();
    out.resize(offset, 0);
    out.extend_from_slice(data);
    out
}

fn load(path: &Path, opts: &ReadOptions) -> Loaded {
    read(path, opts).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_plain_layout_reads_with_its_voxel_sizes_and_translation() {
    let dir = tempfile::tempdir().unwrap();
    let mut data = Vec::new();
    for k in 0..5 {
        for j in 0..3 {
            for i in 0..4 {
                data.extend(value(i, j, k).to_le_bytes());
            }
        }
    }
    let header = "dim: 4,3,5\nvox: 0.5,0.25,2\nlayout: +0,+1,+2\ndatatype: Float32LE\ntransform: 1,0,0,1\ntransform: 0,1,0,-2\ntransform: 0,0,1,3.5\n";
    let path = dir.path().join("plain.mif");
    std::fs::write(&path, mif(header, &data)).unwrap();
    let l = load(&path, &ReadOptions::default());
    assert_eq!(l.format, VolumeFormat::Mrtrix);
    let grid = Grid {
        n: [4, 3, 5],
        steps: [DVec3::X * 0.5, DVec3::Y * 0.25, DVec3::Z * 2.0],
        origin: DVec3::new(1.0, -2.0, 3.5),
    };
    check_world("plain", &l.volume, &grid, 1e-9, value);
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    // Known by its first line under any name.
    let renamed = dir.path().join("image.data");
    std::fs::copy(&path, &renamed).unwrap();
    assert_eq!(
        load(&renamed, &ReadOptions::default()).format,
        VolumeFormat::Mrtrix
    );
}

#[test]
fn a_reversed_permuted_layout_and_a_permuting_transform_keep_world_positions() {
    let dir = tempfile::tempdir().unwrap();
    // layout -0,+2,+1: axis 0 fastest, stored from its last sample; then
    // axis 2; axis 1 slowest. Int16 big-endian.
    let mut data = Vec::new();
    for j in 0..3 {
        for k in 0..5 {
            for i_stored in 0..4 {
                let i = 3 - i_stored;
                data.extend((value(i, j, k) as i16 - 300).to_be_bytes());
            }
        }
    }
    // Image axis 0 along world y, axis 1 along world x, axis 2 along -z.
    let header = "dim: 4,3,5\nvox: 1.5,1,2\nlayout: -0,+2,+1\ndatatype: Int16BE\ntransform: 0,1,0,10\ntransform: 1,0,0,20\ntransform: 0,0,-1,30\n";
    let path = dir.path().join("permuted.mif");
    std::fs::write(&path, mif(header, &data)).unwrap();
    let l = load(&path, &ReadOptions::default());
    let grid = Grid {
        n: [4, 3, 5],
        steps: [DVec3::Y * 1.5, DVec3::X * 1.0, DVec3::Z * -2.0],
        origin: DVec3::new(10.0, 20.0, 30.0),
    };
    check_world("permuted", &l.volume, &grid, 1e-9, |i, j, k| {
        value(i, j, k) - 300.0
    });
    assert!(
        l.info.stored_type.starts_with("i16 (big"),
        "{}",
        l.info.stored_type
    );
}

#[test]
fn volumes_fastest_scaling_a_detached_header_and_gzip_read_alike() {
    let dir = tempfile::tempdir().unwrap();
    // layout +1,+2,+3,+0: the 2 volumes fastest (as MRtrix stores DWI).
    let mut data = Vec::new();
    for k in 0..5 {
        for j in 0..3 {
            for i in 0..4 {
                for t in 0..2 {
                    data.push((value(i, j, k) as u32 % 200 + 50 * t) as u8);
                }
            }
        }
    }
    let header = "dim: 4,3,5,2\nvox: 1,1,1,NaN\nlayout: +1,+2,+3,+0\ndatatype: UInt8\nscaling: -1,0.5\ntransform: 1,0,0,0\ntransform: 0,1,0,0\ntransform: 0,0,1,0\n";
    let want = |t: usize| {
        move |i, j, k| -1.0 + 0.5 * ((value(i, j, k) as u32 % 200 + 50 * t as u32) as f32)
    };
    let grid = Grid {
        n: [4, 3, 5],
        steps: [DVec3::X, DVec3::Y, DVec3::Z],
        origin: DVec3::ZERO,
    };
    let mif_path = dir.path().join("dwi.mif");
    std::fs::write(&mif_path, mif(header, &data)).unwrap();
    let mih_path = dir.path().join("dwi.mih");
    std::fs::write(
        &mih_path,
        format!("mrtrix image\n{header}file: dwi.dat 3\nEND\n"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("dwi.dat"),
        [&[9u8, 9, 9][..], &data].concat(),
    )
    .unwrap();
    let gz_path = dir.path().join("dwi.mif.gz");
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(&mif(header, &data)).unwrap();
    std::fs::write(&gz_path, e.finish().unwrap()).unwrap();
    for path in [&mif_path, &mih_path, &gz_path] {
        for t in 0..2 {
            let l = load(path, &common::frame(t));
            assert_eq!((l.info.frames, l.info.frame), (2, t));
            check_world("dwi", &l.volume, &grid, 1e-9, want(t));
        }
        let err = read(path, &common::frame(2)).unwrap_err();
        common::assert_frame_out_of_range(&err, 2, "the image holds 2 volume(s) (frames 0 to 1)");
    }
}

#[test]
fn lying_and_broken_mrtrix_headers_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mif");
    let refuse = |bytes: &[u8], want: &str| {
        std::fs::write(&path, bytes).unwrap();
        let msg = refused(&path, &ReadOptions::default());
        assert!(msg.contains(want), "{msg}\n  wanted: {want}");
    };
    let base = "vox: 1,1,1\nlayout: +0,+1,+2\ndatatype: Float32LE\n";
    let data = vec![0u8; 4 * 8];
    refuse(
        &mif(&format!("dim: 2,2,2\n{base}"), &data[..28]),
        "the header declares 8 samples of f32",
    );
    refuse(
        &mif(&format!("dim: 100000,100000,100000\n{base}"), &data),
        "the header declares 1000000000000000 samples",
    );
    refuse(
        &mif(
            "dim: 2,2,2\nvox: 1,1,1\nlayout: +0,+0,+2\ndatatype: Float32LE\n",
            &data,
        ),
        "layout: the ranks are not 0 to n-1",
    );
    refuse(
        &mif("dim: 2,2,2\nvox: 1,1,1\ndatatype: Bit\n", &data),
        "datatype Bit",
    );
    refuse(
        &mif("dim: 2,2\nvox: 1,1\ndatatype: Float32LE\n", &data),
        "dim has 2 axes: volray reads 3 or 4",
    );
    refuse(
        &mif("dim: 2,2,2\nvox: 1,-1,1\ndatatype: Float32LE\n", &data),
        "vox 2: -1 is no voxel size",
    );
    refuse(
        b"mrtrix image\ndim: 2,2,2\ndatatype: Float32LE\n",
        "file ends",
    );
    refuse(
        b"mrtrix image\ndim: 2,2,2\ndatatype: Float32LE\nEND\n",
        "no file line",
    );
    let good = mif(&format!("dim: 2,2,2\n{base}"), &data);
    for cut in truncations(&good, 7) {
        std::fs::write(&path, cut).unwrap();
        read_or_refuse(&path, &ReadOptions::default());
    }
}
