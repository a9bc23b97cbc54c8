//! Volumes mapped from their file (`MapPolicy`): the same samples as read
//! into memory, for every fixture whose format and layout allow it; a
//! refusal that says why for those that do not; a volume over the memory
//! limit mapped rather than refused; and a mapped file changed under the
//! renderer an error of the frame.

mod common;

use std::fs;
use std::path::{Path, PathBuf};
use volray_core::{FrameRequest, Render};

use common::fixture;
use volray_core::{RenderError, RenderSettings, Renderer};
use volray_io::{IoError, MapPolicy, RawOptions, ReadOptions, read};

fn with(map: MapPolicy, frame: Option<usize>) -> ReadOptions {
    ReadOptions {
        map,
        frame,
        ..ReadOptions::default()
    }
}

/// A raw file `v.raw` in `dir` holding `values`' bytes in order.
fn raw_file<const N: usize>(dir: &Path, values: impl IntoIterator<Item = [u8; N]>) -> PathBuf {
    let p = dir.join("v.raw");
    fs::write(&p, values.into_iter().flatten().collect::<Vec<u8>>()).unwrap();
    p
}

/// Every fixture of the formats that map, read both ways: mapped where
/// the layout allows (same samples, same everything else), read where it
/// does not; returns the fixtures mapped.
fn mapped_where_allowed(files: &[(PathBuf, Option<usize>)]) -> Vec<String> {
    let mut mapped = Vec::new();
    for (path, frame) in files {
        let name = path.display().to_string();
        let read_in = read(path, &with(MapPolicy::Never, *frame)).unwrap_or_else(|e| panic!("{e}"));
        assert!(!read_in.volume.samples().is_external(), "{name}");
        match read(path, &with(MapPolicy::Always, *frame)) {
            Ok(m) => {
                assert_eq!(m.volume, read_in.volume, "{name}");
                if m.volume.samples().is_external() {
                    assert!(
                        m.info
                            .notes
                            .iter()
                            .any(|n| n.starts_with("mapped from the file")),
                        "{name}: {:?}",
                        m.info.notes
                    );
                    mapped.push(name);
                }
            }
            // Axes to reorder: a mapping cannot be reordered.
            Err(e) => assert!(
                e.to_string().contains("cannot be: store it with x fastest"),
                "{name}: {e}"
            ),
        }
    }
    mapped
}

#[test]
fn mapped_samples_are_the_samples_read() {
    let files: Vec<(PathBuf, Option<usize>)> = [
        ("nrrd", "i8.nrrd", None),
        ("nrrd", "f32_lps.nrrd", None),
        ("nrrd", "tail.nhdr", None),
        ("nrrd", "skips.nhdr", None),
        ("nrrd", "time4d.nrrd", Some(1)),
        ("nrrd", "u8_gzip.nrrd", None),
        ("nrrd", "list.nhdr", None),
        ("metaimage", "u8.mhd", None),
        ("metaimage", "i8.mha", None),
        ("metaimage", "f32.mha", None),
        ("metaimage", "headersize.mhd", None),
        ("metaimage", "tail.mhd", None),
        ("metaimage", "be_i16.mhd", None),
        ("metaimage", "series4d.mha", Some(2)),
        ("nifti", "i16.nii", None),
        ("nifti", "u16.nii", None),
        ("nifti", "f32.nii", None),
        ("nifti", "pair.hdr", None),
        ("nifti", "f32.nii.gz", None),
        ("nifti", "scaled_i16.nii", None),
        ("nifti", "nifti2_frames4d.nii", Some(1)),
        ("", "fortran_f4.npy", None),
        ("", "c_f4.npy", None),
        ("", "u1.npy", None),
        ("mrc", "mode2_f32.mrc", None),
        ("mrc", "mode6_u16_ext.mrc", None),
        ("mrc", "mode1_i16_be.mrc", None),
        ("mrc", "permuted.mrc", None),
    ]
    .into_iter()
    .map(|(dir, name, frame)| (fixture(dir, name), frame))
    .collect();
    let mapped = mapped_where_allowed(&files);
    // At least one fixture of each format maps; the others say why not.
    for format in [
        ".nrrd", ".nhdr", ".mhd", ".mha", ".nii", ".hdr", ".npy", ".mrc",
    ] {
        assert!(
            mapped.iter().any(|m| m.ends_with(format)),
            "no {format} mapped: {mapped:?}"
        );
    }
    for name in [
        "u8_gzip.nrrd",
        "list.nhdr",
        "be_i16.mhd",
        "f32.nii.gz",
        "scaled_i16.nii",
        "c_f4.npy",
        "mode1_i16_be.mrc",
    ] {
        assert!(!mapped.iter().any(|m| m.ends_with(name)), "{name} mapped");
    }
}

/// Files whose axes run in another order or sense (NIfTI with a flipped
/// or permuted qform, a C-order `.npy`, a CCP4
/// map with MAPC/MAPR/MAPS 2,1,3) map in their own axis order under
/// `AlwaysInFileOrder`, and every box of the world-aligned volume taken
/// from that mapping, reordered box by box as an MPI rank takes its
/// piece, equals the same box of the volume read into memory and
/// reordered whole: samples, spacing, origin.
#[test]
fn boxes_of_a_file_mapped_in_its_own_axis_order_are_the_boxes_read() {
    for name in [
        ("nifti", "flipped.nii"),
        ("nifti", "qform_permuted.nii"),
        ("mrc", "permuted.mrc"),
        ("", "c_f4.npy"),
    ] {
        let path = fixture(name.0, name.1);
        let whole = read(&path, &with(MapPolicy::Never, None)).unwrap().volume;
        // Under the other policies it is refused (mapped, it could not be
        // reordered) or read into memory and reordered (the .npy).
        match read(&path, &with(MapPolicy::Always, None)) {
            Err(e) => assert!(
                e.to_string().contains("cannot be: store it with x fastest"),
                "{e}"
            ),
            Ok(m) => {
                assert!(!m.volume.samples().is_external(), "{}", name.1);
                assert!(m.info.reorientation.is_none());
                assert_eq!(m.volume, whole);
            }
        }
        let mapped = read(&path, &with(MapPolicy::AlwaysInFileOrder, None)).unwrap();
        assert!(mapped.volume.samples().is_external(), "{}", name.1);
        let r = mapped.info.reorientation.expect("axes to reorder");
        assert_eq!(r.dims(), whole.dims(), "{}", name.1);
        assert_eq!(mapped.volume.dims(), r.file_dims, "{}", name.1);
        let [nx, ny, nz] = whole.dims();
        let boxes = [
            ([0, 0, 0], [nx, ny, nz]),
            ([0, 0, 0], [2, 2, 2]),
            ([nx - 2, ny - 2, nz - 2], [nx, ny, nz]),
            ([1, 0, nz / 2 - 1], [nx, ny / 2 + 1, nz]),
            ([nx / 3, ny / 3, 0], [nx / 3 + 2, ny, nz / 2 + 1]),
        ];
        for (lo, hi) in boxes {
            // At least 2 samples a side, on the smallest fixtures too.
            let lo: [usize; 3] = std::array::from_fn(|a| lo[a].min(hi[a] - 2));
            let from_map = r.sub_box(&mapped.volume, lo, hi).unwrap();
            let expect = whole.sub_box(lo, hi);
            assert_eq!(
                from_map.values(),
                expect.values(),
                "{} {lo:?}..{hi:?}",
                name.1
            );
            assert_eq!(from_map.dims(), expect.dims());
            assert_eq!(from_map.sample_type(), expect.sample_type());
            assert!((from_map.spacing() - expect.spacing()).length() < 1e-12);
            assert!(
                (from_map.origin() - expect.origin()).length() < 1e-9,
                "{} {lo:?}",
                name.1
            );
        }
    }
}

/// A raw file over the limit maps; one that cannot be mapped is refused
/// with the reason.
#[test]
fn a_volume_over_the_limit_is_mapped_or_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let values: Vec<i16> = (0..16 * 16 * 16)
        .map(|i| (i % 3000) as i16 - 1000)
        .collect();
    let p = raw_file(dir.path(), values.iter().map(|v| v.to_le_bytes()));
    let raw = |dtype, endian| {
        let mut r = RawOptions::new([16, 16, 16], dtype);
        r.endian = endian;
        ReadOptions {
            raw: Some(r),
            max_memory: 4000,
            ..ReadOptions::default()
        }
    };
    let little = raw(volray_io::DType::I16, volray_io::Endian::Little);
    let m = read(&p, &little).unwrap();
    assert!(m.volume.samples().is_external());
    assert_eq!(
        m.volume
            .values()
            .iter()
            .map(|&v| v as i16)
            .collect::<Vec<_>>(),
        values
    );
    let never = ReadOptions {
        map: MapPolicy::Never,
        ..little.clone()
    };
    assert!(matches!(
        read(&p, &never),
        Err(IoError::OverMemoryLimit { .. })
    ));
    let big = raw(volray_io::DType::I16, volray_io::Endian::Big);
    let err = read(&p, &big).unwrap_err();
    assert!(matches!(err, IoError::OverMemoryLimit { .. }));
    assert!(
        err.to_string().contains("which cannot be mapped from the file instead (big-endian samples on a little-endian machine: store them little-endian)"),
        "{err}"
    );
    let gz = fixture("nrrd", "u8_gzip.nrrd");
    let err = read(
        &gz,
        &ReadOptions {
            max_memory: 10,
            ..ReadOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("gzip-compressed data: store it uncompressed"),
        "{err}"
    );
}

/// A frame of a mapped file truncated before it renders is an error of
/// the frame, naming the file: not a crash, not a picture of zeros.
#[test]
fn a_mapped_file_truncated_before_a_frame_fails_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let n = 48usize;
    let values: Vec<u16> = (0..n * n * n)
        .map(|i| ((i * 7919) % 60000) as u16)
        .collect();
    let p = raw_file(dir.path(), values.iter().map(|v| v.to_le_bytes()));
    let opts = ReadOptions {
        raw: Some(RawOptions::new([n, n, n], volray_io::DType::U16)),
        map: MapPolicy::Always,
        ..ReadOptions::default()
    };
    let volume = read(&p, &opts).unwrap().volume;
    assert!(volume.samples().is_external());
    let renderer = Renderer::new(&volume).unwrap();
    let settings = RenderSettings {
        width: 32,
        height: 32,
        ..RenderSettings::default()
    };
    let mapped_frame = renderer
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    let read_in = read(
        &p,
        &ReadOptions {
            map: MapPolicy::Never,
            ..opts.clone()
        },
    )
    .unwrap()
    .volume;
    let in_memory = Renderer::new(&read_in)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    assert_eq!(mapped_frame, in_memory);
    fs::OpenOptions::new()
        .write(true)
        .open(&p)
        .unwrap()
        .set_len(4096)
        .unwrap();
    let err = Renderer::new(&volume)
        .err()
        .or_else(|| renderer.render(FrameRequest::new(&settings)).err());
    match err {
        Some(RenderError::SamplesChanged(why)) => {
            assert!(why.contains(&p.display().to_string()), "{why}");
        }
        other => panic!("{other:?}"),
    }
}
