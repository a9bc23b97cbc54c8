//! HDF5 datasets and NetCDF-4 variables read box by box (`open_lazy`):
//! files written at test time by h5py, netCDF4 (netCDF-C) and h5netcdf
//! (`tests/hdf5_lazy/write_files.py`), every box compared sample for
//! sample with the same box of the volume the eager reader reads whole,
//! and the whole with the array numpy saved beside it. Boxes: the whole,
//! one chunk, boxes across chunk boundaries, edge chunks, two-sample
//! slivers at every corner, and pseudo-random boxes; every sample type,
//! both byte orders, deflate, shuffle, LZF and Fletcher-32 (checked: a
//! damaged chunk refused by name), every chunk index hdf5-pure
//! enumerates and the version 2 B-tree it cannot (listed through
//! hdf5-reader), contiguous data, chunks and data never written (the fill
//! value), a (t, z, y, x) series box by box within a memory limit one
//! frame would exceed, a NetCDF-4 variable along a decreasing latitude,
//! and szip refused by name. Then hostile files: a chunk stored past the
//! end of the file, a shape of 2^40 samples, a chunk inflating past its
//! size: one-line errors.
//!
//! The writers run in `target/pyenv` (h5py, netCDF4, h5netcdf and numpy
//! from PyPI, which `.ci/run` installs); without them these tests fail
//! under `CI=true` and are skipped elsewhere.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use volray_core::{SourceErrorKind, Volume, VolumeSource};
use volray_io::{IoError, Lazy, ReadOptions, VolumeFormat, open_lazy, read};

/// The directory the writers filled, or `None` (with the reason printed)
/// where they are missing outside CI.
fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["h5py", "netCDF4", "h5netcdf", "numpy"],
        "tests/hdf5_lazy/write_files.py",
    )
}

fn opts(frame: Option<usize>, max_memory: u64) -> ReadOptions {
    ReadOptions {
        frame,
        max_memory,
        ..ReadOptions::default()
    }
}

fn lazy(spec: &Path, o: &ReadOptions) -> Lazy {
    open_lazy(spec, o)
        .unwrap_or_else(|e| panic!("{}: {e}", spec.display()))
        .unwrap_or_else(|| panic!("{}: not opened box by box", spec.display()))
}

/// The boxes every dataset is read in, for a volume of `dims` in chunks
/// of `chunk` (x, y, z).
fn boxes(dims: [usize; 3], chunk: [usize; 3]) -> Vec<([usize; 3], [usize; 3])> {
    let mut out = vec![([0; 3], dims)];
    // One chunk, and one chunk and a bit on each side.
    let c = chunk.map(|k| k.max(2));
    let one: [usize; 3] = std::array::from_fn(|a| c[a].min(dims[a]));
    out.push(([0; 3], one));
    let across_lo: [usize; 3] = std::array::from_fn(|a| c[a].saturating_sub(1).min(dims[a] - 2));
    let across_hi: [usize; 3] =
        std::array::from_fn(|a| (2 * c[a] + 1).min(dims[a]).max(across_lo[a] + 2));
    out.push((across_lo, across_hi));
    // The edge chunks: the last samples of every axis.
    out.push((dims.map(|n| n - 3), dims));
    out.push((dims.map(|n| n / 2), dims));
    // Two-sample slivers at the eight corners.
    for corner in 0..8 {
        let lo: [usize; 3] =
            std::array::from_fn(|a| if corner >> a & 1 == 1 { dims[a] - 2 } else { 0 });
        out.push((lo, lo.map(|v| v + 2)));
    }
    // Slabs along each axis, the whole of the other two.
    for a in 0..3 {
        let mut lo = [0; 3];
        let mut hi = dims;
        lo[a] = dims[a] / 3;
        hi[a] = lo[a] + 2;
        out.push((lo, hi));
    }
    // Pseudo-random boxes (a 64-bit LCG).
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = |n: usize| {
        s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        ((s >> 33) as usize) % n
    };
    for _ in 0..24 {
        let lo: [usize; 3] = std::array::from_fn(|a| next(dims[a] - 1));
        let hi: [usize; 3] = std::array::from_fn(|a| {
            let lo = lo[a].min(dims[a] - 2);
            lo + 2 + next(dims[a] - lo - 1)
        });
        let lo: [usize; 3] = std::array::from_fn(|a| lo[a].min(dims[a] - 2));
        out.push((lo, hi.map(|v| v)));
    }
    out.retain(|(lo, hi)| (0..3).all(|a| lo[a] + 2 <= hi[a] && hi[a] <= dims[a]));
    out
}

/// Reads `spec` whole and box by box (`frame`), checks every box against
/// the whole and the whole against `npy`; returns the lazy source's notes.
fn check_boxes(spec: &Path, frame: Option<usize>, npy: &Path, chunk: [usize; 3]) -> Vec<String> {
    let o = opts(frame, 1 << 30);
    let eager = read(spec, &o).unwrap_or_else(|e| panic!("{}: {e}", spec.display()));
    // `file.nc:/var` is a NetCDF-4 variable, read with its CF geometry
    // (formats/netcdf4.rs) over the same HDF5 layer.
    let netcdf = spec.to_string_lossy().contains(".nc:");
    let format = if netcdf {
        VolumeFormat::Netcdf
    } else {
        VolumeFormat::Hdf5
    };
    assert_eq!(eager.format, format, "{}", spec.display());
    let expected = read(npy, &ReadOptions::default()).unwrap().volume;
    assert_eq!(eager.volume.dims(), expected.dims(), "{}", spec.display());
    assert!(
        eager.volume.samples() == expected.samples(),
        "{}: the eager volume differs from numpy's array",
        spec.display()
    );
    let l = lazy(spec, &o);
    let grid = l.source.grid();
    assert_eq!(grid.dims, eager.volume.dims());
    assert_eq!(grid.spacing, eager.volume.spacing());
    assert_eq!(grid.origin, eager.volume.origin());
    assert_eq!(l.source.sample_type(), eager.volume.sample_type());
    assert_eq!(l.info.frames, eager.info.frames);
    for (lo, hi) in boxes(grid.dims, chunk) {
        let got = l
            .source
            .read_box(lo, hi)
            .unwrap_or_else(|e| panic!("{} {lo:?}..{hi:?}: {e}", spec.display()));
        let want: Volume = VolumeSource::read_box(&eager.volume, lo, hi).unwrap();
        assert!(
            got == want,
            "{} box {lo:?}..{hi:?} differs from the eager reader's",
            spec.display()
        );
    }
    l.info.notes
}

fn note_of(notes: &[String]) -> &str {
    notes
        .iter()
        .find(|n| n.starts_with("read box by box"))
        .map(|s| s.as_str())
        .unwrap_or("")
}

#[test]
fn every_sample_type_reads_box_by_box_as_the_eager_reader_reads_it_whole() {
    let Some(dir) = files() else { return };
    let h5 = dir.join("types.h5");
    for (name, chunk, decoded) in [
        ("uint8", [8, 7, 5], ""),
        ("int8", [8, 7, 5], " (shuffle, deflate decoded here)"),
        ("uint16", [8, 7, 5], " (shuffle, deflate decoded here)"),
        ("int16", [16, 16, 16], ""),
        ("be_int16", [5, 9, 11], " (deflate decoded here)"),
        ("uint32", [8, 7, 5], " (shuffle decoded here)"),
        ("int32", [8, 7, 5], " (shuffle, deflate decoded here)"),
        ("uint64", [8, 7, 5], " (shuffle, deflate decoded here)"),
        ("be_int64", [8, 7, 5], ""),
        ("float32", [8, 7, 5], " (shuffle, deflate decoded here)"),
        ("be_float32", [37, 29, 23], " (deflate decoded here)"),
        ("float64", [8, 7, 5], " (shuffle, deflate decoded here)"),
        ("be_float64", [1, 29, 23], " (shuffle decoded here)"),
    ] {
        let spec = PathBuf::from(format!("{}:/{name}", h5.display()));
        let notes = check_boxes(&spec, None, &dir.join(format!("{name}.npy")), chunk);
        let want = format!(
            "read box by box: the chunks of shape {chunk:?} a box touches, from the chunk index{decoded}"
        );
        assert_eq!(note_of(&notes), want, "{name}");
    }
    for name in ["contiguous_f32", "contiguous_be_i16"] {
        let spec = PathBuf::from(format!("{}:/{name}", h5.display()));
        let notes = check_boxes(&spec, None, &dir.join(format!("{name}.npy")), [8, 8, 8]);
        assert!(
            note_of(&notes).contains("from its place in the contiguous data"),
            "{name}: {notes:?}"
        );
    }
}

#[test]
fn every_volume_of_a_series_reads_box_by_box_with_frame() {
    let Some(dir) = files() else { return };
    for t in 0..3 {
        for (name, chunk) in [("s", [7, 6, 5]), ("c", [8, 8, 8])] {
            let spec = PathBuf::from(format!("{}:/{name}", dir.join("series.h5").display()));
            let notes = check_boxes(&spec, Some(t), &dir.join(format!("{name}_t{t}.npy")), chunk);
            assert!(note_of(&notes).starts_with("read box by box"), "{notes:?}");
        }
    }
    let spec = PathBuf::from(format!("{}:/s", dir.join("series.h5").display()));
    let Err(err) = open_lazy(&spec, &opts(Some(3), 1 << 30)) else {
        panic!("frame 3 of 3 opened")
    };
    assert!(
        matches!(err, IoError::FrameOutOfRange { frame: 3, .. }),
        "{err}"
    );
}

#[test]
fn other_chunk_indexes_and_filters_read_box_by_box_too() {
    let Some(dir) = files() else { return };
    let h5 = dir.join("latest.h5");
    for (name, how) in [
        (
            "fixed",
            "from the chunk index (shuffle, deflate decoded here)",
        ),
        ("extensible", "from the chunk index (deflate decoded here)"),
        ("fletcher", "from the chunk index (fletcher32 decoded here)"),
        ("lzf", "from the chunk index (lzf decoded here)"),
        (
            "sparse",
            "from the chunk index; 105 of its 125 chunks are not written and read as the fill value -7",
        ),
    ] {
        let spec = PathBuf::from(format!("{}:/{name}", h5.display()));
        let notes = check_boxes(&spec, None, &dir.join(format!("{name}.npy")), [8, 7, 5]);
        assert!(note_of(&notes).contains(how), "{name}: {notes:?}");
    }
    // hdf5-pure 0.47 reads no dataset indexed by a B-tree v2: its chunks
    // are listed through hdf5-reader (shared/hdf5_index.rs), then read as
    // the others'.
    let spec = PathBuf::from(format!("{}:/btree2", h5.display()));
    let notes = check_boxes(&spec, None, &dir.join("btree2.npy"), [8, 7, 5]);
    assert!(
        notes.iter().any(|n| n.starts_with(
            "hdf5-pure 0.47 cannot read a version 2 B-tree chunk index: its chunk index (a version 2 B-tree) listed through hdf5-reader"
        )),
        "{notes:?}"
    );
}

#[test]
fn lzf_fletcher32_and_unwritten_chunks_read_box_by_box_from_the_chunks() {
    let Some(dir) = files() else { return };
    let h5 = dir.join("filters.h5");
    for (name, chunk, how) in [
        (
            "lzf_f32",
            [8, 7, 5],
            "[8, 7, 5] a box touches, from the chunk index (lzf decoded here)",
        ),
        (
            "shuffle_lzf_i16",
            [16, 9, 11],
            "from the chunk index (shuffle, lzf decoded here)",
        ),
        (
            "fletcher_u8",
            [9, 9, 11],
            "from the chunk index (fletcher32 decoded here)",
        ),
        (
            "gzip_fletcher_f64",
            [8, 7, 5],
            "from the chunk index (shuffle, deflate, fletcher32 decoded here)",
        ),
        (
            "lzf_fletcher_u16",
            [8, 7, 5],
            "from the chunk index (lzf, fletcher32 decoded here)",
        ),
        (
            "sparse_lzf_f32",
            [8, 7, 5],
            "(lzf decoded here); 109 of its 125 chunks are not written and read as the fill value -2.5",
        ),
        (
            "unwritten_chunked_u8",
            [8, 7, 5],
            "; 125 of its 125 chunks are not written and read as the fill value 0",
        ),
        (
            "unwritten_i16",
            [8, 8, 8],
            "read box by box: no data is written, every sample is the fill value -300",
        ),
    ] {
        let spec = PathBuf::from(format!("{}:/{name}", h5.display()));
        let notes = check_boxes(&spec, None, &dir.join(format!("{name}.npy")), chunk);
        assert!(note_of(&notes).contains(how), "{name}: {notes:?}");
    }
}

#[test]
fn a_chunk_failing_its_fletcher32_checksum_is_refused_naming_file_dataset_and_chunk() {
    let Some(dir) = files() else { return };
    // 32³ u16 in 16³ chunks; one byte of the chunk at (16, 0, 16) changed.
    let file = dir.join("fletcher_bad.h5");
    let spec = PathBuf::from(format!("{}:/v", file.display()));
    let o = opts(None, 1 << 30);
    let eager = read(&spec, &o).unwrap_err().to_string();
    assert_eq!(eager.lines().count(), 1, "{eager}");
    let l = lazy(&spec, &o);
    let expected = read(&dir.join("v_fletcher.npy"), &ReadOptions::default())
        .unwrap()
        .volume;
    // The boxes clear of the damaged chunk read; its seven neighbours too.
    for (lo, hi) in [
        ([0, 0, 0], [16, 32, 32]),
        ([16, 16, 0], [32, 32, 32]),
        ([16, 0, 0], [32, 16, 16]),
    ] {
        let got = l.source.read_box(lo, hi).unwrap();
        assert!(
            got == VolumeSource::read_box(&expected, lo, hi).unwrap(),
            "{lo:?}..{hi:?}"
        );
    }
    let err = l.source.read_box([15, 0, 15], [17, 2, 17]).unwrap_err();
    assert_eq!(err.kind, SourceErrorKind::BadData, "{err}");
    let err = err.message;
    assert!(
        err.starts_with(&file.display().to_string())
            && err.contains("HDF5 dataset \"/v\": the chunk at offset [16, 0, 16] fails its Fletcher-32 checksum (stored 0x")
            && err.ends_with("): the file is damaged"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn each_frame_of_an_lzf_series_reads_box_by_box_within_a_limit_one_frame_exceeds() {
    let Some(dir) = files() else { return };
    let spec = PathBuf::from(format!("{}:/s", dir.join("series_lzf.h5").display()));
    for t in 0..4 {
        let notes = check_boxes(
            &spec,
            Some(t),
            &dir.join(format!("s_lzf_t{t}.npy")),
            [7, 8, 5],
        );
        assert!(
            note_of(&notes).contains("the chunks of shape [1, 5, 8, 7] a box touches"),
            "{notes:?}"
        );
    }
    // One frame is 20·18·12 samples: 17 kB as f32, 69 kB as the f64 and
    // stored samples hdf5-pure's row windows would hold. 12 KiB holds a
    // box and an LZF chunk (1.1 kB) stored and decoded, not a frame.
    let o = opts(Some(2), 12 << 10);
    let err = read(&spec, &o).unwrap_err();
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    let l = lazy(&spec, &o);
    let expected = read(&dir.join("s_lzf_t2.npy"), &ReadOptions::default())
        .unwrap()
        .volume;
    for (lo, hi) in [
        ([0, 0, 0], [10, 10, 10]),
        ([3, 4, 2], [20, 18, 7]),
        ([10, 8, 5], [20, 18, 12]),
    ] {
        let got = l.source.read_box(lo, hi).unwrap();
        assert!(
            got == VolumeSource::read_box(&expected, lo, hi).unwrap(),
            "{lo:?}..{hi:?}"
        );
    }
}

#[test]
fn a_decreasing_latitude_reads_box_by_box_flipped_as_the_whole_is() {
    let Some(dir) = files() else { return };
    let spec = PathBuf::from(format!("{}:/t", dir.join("latdown.nc").display()));
    for t in 0..2 {
        let notes = check_boxes(
            &spec,
            Some(t),
            &dir.join(format!("t_latdown_t{t}.npy")),
            [8, 5, 2],
        );
        assert!(
            note_of(&notes).contains("the chunks of shape [1, 2, 5, 8] a box touches"),
            "{notes:?}"
        );
        assert!(
            notes
                .iter()
                .any(|n| n.contains("mirrored range along y (its coordinate decreases)")),
            "{notes:?}"
        );
    }
}

#[test]
fn szip_is_refused_by_name_whole_and_box_by_box() {
    let Some(dir) = files() else { return };
    let file = dir.join("szip.h5");
    let spec = PathBuf::from(format!("{}:/v", file.display()));
    let o = opts(None, 1 << 30);
    let eager = read(&spec, &o).unwrap_err().to_string();
    let Err(lazy) = open_lazy(&spec, &o) else {
        panic!("szip opened box by box")
    };
    for err in [eager, lazy.to_string()] {
        assert!(
            err.starts_with(&file.display().to_string())
                && err.contains("HDF5 dataset \"/v\": its chunks are szip-compressed (filter 4)")
                && err.contains("h5repack -f NONE"),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

#[test]
fn netcdf4_variables_read_box_by_box_over_the_hdf5_layer() {
    let Some(dir) = files() else { return };
    for (file, var, npy, how) in [
        (
            "netcdf4.nc",
            "rho",
            "rho",
            "from the chunk index (shuffle, deflate decoded here)",
        ),
        ("netcdf4.nc", "temp", "temp", "contiguous data"),
        (
            "h5netcdf.nc",
            "rho",
            "rho",
            "from the chunk index (shuffle, deflate decoded here)",
        ),
    ] {
        let spec = PathBuf::from(format!("{}:/{var}", dir.join(file).display()));
        let notes = check_boxes(&spec, None, &dir.join(format!("{npy}.npy")), [8, 8, 8]);
        assert!(note_of(&notes).contains(how), "{file}:{var}: {notes:?}");
    }
}

#[test]
fn a_box_reads_only_the_chunks_it_touches() {
    let Some(dir) = files() else { return };
    // The chunk at (16, 16, 16) of 32³ in 16³ chunks is garbage.
    let spec = PathBuf::from(format!("{}:/v", dir.join("one_bad_chunk.h5").display()));
    let o = opts(None, 1 << 30);
    let err = read(&spec, &o).unwrap_err().to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    let l = lazy(&spec, &o);
    let expected = read(&dir.join("v.npy"), &ReadOptions::default())
        .unwrap()
        .volume;
    for (lo, hi) in [
        ([0, 0, 0], [16, 32, 32]),
        ([16, 0, 0], [32, 16, 32]),
        ([0, 16, 16], [16, 32, 32]),
    ] {
        let got = l.source.read_box(lo, hi).unwrap();
        assert!(
            got == VolumeSource::read_box(&expected, lo, hi).unwrap(),
            "{lo:?}..{hi:?}"
        );
    }
    let err = l.source.read_box([15, 15, 15], [17, 17, 17]).unwrap_err();
    assert_eq!(err.kind, SourceErrorKind::BadData, "{err}");
    let err = err.message;
    assert!(
        err.starts_with(&dir.join("one_bad_chunk.h5").display().to_string())
            && err.contains(
                "HDF5 dataset \"/v\": deflated chunk at offset [16, 16, 16]: corrupt zlib stream"
            ),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn a_box_is_held_to_max_memory_and_not_the_whole_volume() {
    let Some(dir) = files() else { return };
    // 37·29·23 u16 samples take 49 kB whole; 16 kB holds the boxes and one
    // chunk (560 bytes decoded) but not the whole.
    let spec = PathBuf::from(format!("{}:/uint16", dir.join("types.h5").display()));
    let o = opts(None, 16 << 10);
    let err = read(&spec, &o).unwrap_err();
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    let l = lazy(&spec, &o);
    let expected = read(&dir.join("uint16.npy"), &ReadOptions::default())
        .unwrap()
        .volume;
    let got = l.source.read_box([3, 4, 5], [30, 20, 15]).unwrap();
    assert!(got == VolumeSource::read_box(&expected, [3, 4, 5], [30, 20, 15]).unwrap());
    let err = l.source.read_box([0, 0, 0], [37, 29, 23]).unwrap_err();
    assert_eq!(err.kind, SourceErrorKind::OverMemory, "{err}");
    assert!(
        err.message.contains("exceed the memory limit of 16 KiB"),
        "{err}"
    );
    // Contiguous data: its scratch is one x row (29·23·4 bytes).
    let spec = PathBuf::from(format!(
        "{}:/contiguous_f32",
        dir.join("types.h5").display()
    ));
    let l = lazy(&spec, &o);
    let expected = read(&dir.join("contiguous_f32.npy"), &ReadOptions::default())
        .unwrap()
        .volume;
    let got = l.source.read_box([3, 4, 5], [20, 20, 15]).unwrap();
    assert!(got == VolumeSource::read_box(&expected, [3, 4, 5], [20, 20, 15]).unwrap());
}

/// The one-line error opening or reading `file:/v` box by box gives.
fn refused(path: &Path, read_box: bool) -> String {
    let spec = PathBuf::from(format!("{}:/v", path.display()));
    let o = opts(None, 1 << 30);
    let err = match open_lazy(&spec, &o) {
        Err(e) => e.to_string(),
        Ok(Some(l)) if read_box => {
            let dims = l.source.grid().dims;
            let err = l.source.read_box([0; 3], dims).unwrap_err();
            assert!(!err.is_io_failure(), "{err}");
            err.message
        }
        Ok(_) => panic!("{} opened", path.display()),
    };
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with(&path.display().to_string()), "{err}");
    err
}

#[test]
fn hostile_files_are_refused_in_one_line_before_any_large_allocation() {
    let Some(dir) = files() else { return };
    let err = refused(&dir.join("past_end.h5"), false);
    assert!(
        err.contains("HDF5 dataset \"/v\": the chunk at offset [8, 8, 8] is stored at byte")
            && err.contains("past the end of the"),
        "{err}"
    );
    let err = refused(&dir.join("huge.h5"), false);
    assert!(
        err.contains("dataset shape [16384, 8192, 8192] of 1-byte samples is 1099511627776 bytes, more than a"),
        "{err}"
    );
    let err = refused(&dir.join("inflates.h5"), true);
    assert!(
        err.ends_with("HDF5 dataset \"/v\": deflated chunk at offset [0, 0, 0]: zlib stream inflates past the 512 bytes the header declares"),
        "{err}"
    );
}
