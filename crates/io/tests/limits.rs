//! The memory limit ([`ReadOptions::max_memory`]) in every reader, and
//! headers whose dimensions overflow.
//!
//! For each format a valid fixture is read with the limit at exactly the
//! bytes the reader holds (accepted) and one byte less (refused, naming the
//! header field and the limit), reading into memory only
//! ([`MapPolicy::Never`]: by default a volume over the limit that its file
//! stores plainly is mapped instead, which `tests/mapped.rs` covers). What a reader holds is its documented
//! rule: the volume in the type it keeps (1, 2 or 4 bytes a voxel) for the
//! streaming readers, plus the whole-payload buffers of those that keep one
//! (DICOM multi-frame, VTK XML, CHGCAR, HDF5) and the `f32` values a
//! rescaling builds beside the stored ones (NIfTI's scl_slope, ImageJ's
//! calibration). Then a header per format is written by hand
//! with dimensions of 2^40 (or the format's largest) per axis, whose
//! product overflows: each is refused in one line naming the value.

mod common;

use std::fs;
use std::path::Path;

use common::{fixture, refused_error};
use volray_io::{IoError, Loaded, MapPolicy, ReadOptions, read};

/// Reads `path` with `base`'s options: with the limit at `need(&loaded)`
/// bytes it reads, with one byte less it is refused
/// ([`IoError::OverMemoryLimit`]) naming `field` and the limit. Returns the
/// limit found.
fn limit_is_exact(
    path: &Path,
    base: ReadOptions,
    need: impl Fn(&Loaded) -> u64,
    field: &str,
) -> u64 {
    let loaded = read(path, &base).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let need = need(&loaded);
    let at = |max_memory| ReadOptions {
        max_memory,
        map: MapPolicy::Never,
        ..base.clone()
    };
    let again = read(path, &at(need)).unwrap_or_else(|e| panic!("limit {need}: {e}"));
    assert_eq!(again.volume, loaded.volume);
    assert_over_limit(&refused_error(path, &at(need - 1)), field, need - 1);
    need
}

/// Asserts that `err` is the refusal of data over the memory limit `limit`,
/// its message naming `field` and the limit.
fn assert_over_limit(err: &IoError, field: &str, limit: u64) {
    assert!(
        matches!(err, IoError::OverMemoryLimit { limit: l, .. } if *l == limit),
        "{err}"
    );
    let msg = err.to_string();
    assert!(msg.contains(field), "{msg}\n  wanted field: {field}");
    assert!(msg.contains("the memory limit of"), "{msg}");
}

/// The streaming readers hold the volume only, in the type it keeps.
fn volume_bytes(l: &Loaded) -> u64 {
    (l.volume.sample_type().bytes() * l.volume.len()) as u64
}

#[test]
fn raw_and_npy() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("v.raw");
    fs::write(&p, vec![0u8; 2 * 4 * 3 * 5]).unwrap();
    let raw = ReadOptions {
        raw: Some(volray_io::RawOptions::new([4, 3, 5], volray_io::DType::U16)),
        ..ReadOptions::default()
    };
    // 16-bit samples stay 16-bit: 2 bytes a voxel.
    assert_eq!(
        limit_is_exact(&p, raw, volume_bytes, "raw layout dims 4 3 5"),
        120
    );

    let npy = fixture("", "fortran_f4.npy");
    limit_is_exact(&npy, ReadOptions::default(), volume_bytes, "shape");
    limit_is_exact(
        &fixture("", "c_f4.npy"),
        ReadOptions::default(),
        volume_bytes,
        "shape",
    );
}

#[test]
fn nrrd_and_metaimage() {
    let nrrd = |n| fixture("nrrd", n);
    assert_eq!(
        limit_is_exact(
            &nrrd("f32_lps.nrrd"),
            ReadOptions::default(),
            volume_bytes,
            "NRRD field \"sizes\" 4 3 5"
        ),
        240
    );
    // Compressed and detached: still the volume only (streamed).
    limit_is_exact(
        &nrrd("u8_gzip.nrrd"),
        ReadOptions::default(),
        volume_bytes,
        "\"sizes\"",
    );
    limit_is_exact(
        &nrrd("list.nhdr"),
        ReadOptions::default(),
        volume_bytes,
        "\"sizes\"",
    );
    // A 4-D file: one volume of its frames is held.
    let four = nrrd("time4d.nrrd");
    let frames = read(&four, &ReadOptions::default()).unwrap().info.frames;
    assert!(frames > 1);
    limit_is_exact(
        &four,
        common::frame(1),
        volume_bytes,
        &format!("one volume of {frames}"),
    );

    let mha = |n| fixture("metaimage", n);
    limit_is_exact(
        &mha("f32.mha"),
        ReadOptions::default(),
        volume_bytes,
        "MetaImage field DimSize",
    );
    limit_is_exact(
        &mha("i16_zlib.mha"),
        ReadOptions::default(),
        volume_bytes,
        "DimSize",
    );
}

#[test]
fn nifti() {
    let nii = |n| fixture("nifti", n);
    limit_is_exact(
        &nii("f32.nii"),
        ReadOptions::default(),
        volume_bytes,
        "NIfTI field \"dim\"",
    );
    limit_is_exact(
        &nii("f32.nii.gz"),
        ReadOptions::default(),
        volume_bytes,
        "\"dim\"",
    );
    limit_is_exact(
        &nii("nifti2_i32.nii"),
        ReadOptions::default(),
        volume_bytes,
        "\"dim\"",
    );
    limit_is_exact(
        &nii("frames4d.nii.gz"),
        common::frame(1),
        volume_bytes,
        "one volume of",
    );
}

#[test]
fn vtk_legacy_and_xml() {
    let vtk = |n| fixture("vtk", n);
    limit_is_exact(
        &vtk("legacy_f32.vtk"),
        ReadOptions::default(),
        volume_bytes,
        "array \"",
    );
    limit_is_exact(
        &vtk("legacy_i16_ascii.vtk"),
        ReadOptions::default(),
        volume_bytes,
        "array \"",
    );
    // Legacy VTK is never mapped: the refusal says why and what to do.
    for (name, why) in [
        ("legacy_f32.vtk", "big-endian"),
        ("legacy_i16_ascii.vtk", "ASCII text"),
    ] {
        let over = ReadOptions {
            max_memory: 8,
            ..ReadOptions::default()
        };
        let msg = refused_error(&vtk(name), &over).to_string();
        assert!(
            msg.contains("cannot be mapped from the file instead")
                && msg.contains(why)
                && msg.contains("save the volume as raw NRRD"),
            "{msg}"
        );
    }

    // VTK XML is read whole: for these tiny grids the file is what binds
    // (each value takes its stored bytes and an f32, 8 + 4 at most).
    for name in [
        "vti_binary_zlib.vti",
        "vti_appended_raw.vti",
        "vti_pieces.vti",
    ] {
        let p = vtk(name);
        let len = fs::metadata(&p).unwrap().len();
        let l = read(&p, &ReadOptions::default()).unwrap();
        assert!(len > 16 * l.volume.len() as u64, "{name}");
        limit_is_exact(&p, ReadOptions::default(), |_| len, "is read whole");
    }
}

#[test]
fn dicom() {
    let dcm = |n| fixture("dicom", n);
    limit_is_exact(
        &dcm("ct"),
        ReadOptions::default(),
        volume_bytes,
        "Columns x Rows x slices",
    );
    // Multi-frame, 16-bit samples: every frame held as parsed and as
    // decoded (2 + 2 bytes) beside the volume.
    let l = read(&dcm("enhanced_ct.dcm"), &ReadOptions::default()).unwrap();
    assert_eq!(common::header_value(&l, "BitsAllocated (0028,0100)"), "16");
    limit_is_exact(
        &dcm("enhanced_ct.dcm"),
        ReadOptions::default(),
        |l| 4 * l.volume.len() as u64 + volume_bytes(l),
        "Rows x Columns x NumberOfFrames",
    );
}

#[test]
fn tiff_cube_mrc_chgcar() {
    let tif = fixture("tiff", "imagej_u16.tif");
    limit_is_exact(
        &tif,
        ReadOptions::default(),
        volume_bytes,
        "ImageWidth x ImageLength x pages",
    );
    let tif = fixture("tiff", "pillow_lzw_u16.tif");
    limit_is_exact(&tif, ReadOptions::default(), volume_bytes, "ImageWidth");

    let cube = fixture("cube", "ramp_bohr.cube");
    limit_is_exact(&cube, ReadOptions::default(), volume_bytes, "N1 x N2 x N3");

    let mrc = fixture("mrc", "mode2_f32.mrc");
    limit_is_exact(&mrc, ReadOptions::default(), volume_bytes, "NX NY NZ");

    // CHGCAR: the NG grid and its copy closed by the periodic planes, so
    // the volume is (NG + 1)^3 points.
    let chg = fixture("chgcar", "CHGCAR_ortho");
    limit_is_exact(
        &chg,
        ReadOptions::default(),
        |l| {
            let [x, y, z] = l.volume.dims().map(|n| n as u64);
            4 * ((x - 1) * (y - 1) * (z - 1) + x * y * z)
        },
        "NGX NGY NGZ",
    );
}

/// A skewed cell is resampled onto a new grid: that grid and the file's
/// values, held together, must fit the limit too.
#[test]
fn resampled_cells_fit_the_limit() {
    let cube = fixture("cube", "hexagonal.cube");
    let l = read(&cube, &ReadOptions::default()).unwrap();
    let file_points: u64 = (1..=3)
        .map(|a| {
            let axis = common::header_value(&l, &format!("axis {a}"));
            axis.split_whitespace()
                .next()
                .unwrap()
                .parse::<i64>()
                .unwrap()
                .unsigned_abs()
        })
        .product();
    let need = limit_is_exact(
        &cube,
        ReadOptions::default(),
        |l| 4 * (l.volume.len() as u64 + file_points),
        "axis steps: resampling onto",
    );
    assert!(need > 4 * file_points);
}

#[test]
fn hdf5() {
    // The f32 volume and one slab of f64 values beside the slab's stored
    // samples (f32 here): a tiny dataset is one slab. Errors name the
    // file, not the dataset.
    let file = fixture("hdf5", "one.h5");
    let p = std::path::PathBuf::from(format!("{}:/fields/density", file.display()));
    let l = read(&p, &ReadOptions::default()).unwrap();
    let need = (4 + 8 + 4) * l.volume.len() as u64;
    let at = |max_memory| ReadOptions {
        max_memory,
        ..ReadOptions::default()
    };
    assert_eq!(read(&p, &at(need)).unwrap().volume, l.volume);
    let err = common::error_about(&p, &at(need - 1), &file);
    assert!(!err.is_io_failure());
    assert_over_limit(&err, "dataset shape [4, 3, 5]", need - 1);
}

// ---- dimensions whose product overflows, per header format ----

const HUGE: u64 = 1 << 40;

fn refuse_bytes(name: &str, bytes: &[u8], want: &str) {
    let msg = common::refused_file(name, bytes, &ReadOptions::default());
    assert!(msg.contains(want), "{name}: {msg}\n  wanted: {want}");
}

#[test]
fn overflowing_dims_are_refused_in_every_header() {
    let h = HUGE.to_string();
    let dims3 = format!("{h} {h} {h}");

    // raw: the layout comes from the raw options.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("v.raw");
    fs::write(&p, [0u8; 8]).unwrap();
    let n = HUGE as usize;
    let raw = ReadOptions {
        raw: Some(volray_io::RawOptions::new([n, n, n], volray_io::DType::F32)),
        ..ReadOptions::default()
    };
    let err = refused_error(&p, &raw);
    assert!(matches!(err, IoError::DimsOverflow { .. }), "{err}");
    assert!(
        err.to_string()
            .contains(&format!("raw layout {h}x{h}x{h} f32"))
    );

    // .npy
    let dict = format!("{{'descr': '<f4', 'fortran_order': True, 'shape': ({h}, {h}, {h}), }}");
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend((dict.len() as u16 + 1).to_le_bytes());
    npy.extend(dict.as_bytes());
    npy.push(b'\n');
    npy.extend([0u8; 16]);
    refuse_bytes("v.npy", &npy, &format!("({h}, {h}, {h})"));

    // NRRD and MetaImage
    let nrrd = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {dims3}\nendian: little\nencoding: raw\n\n\0\0\0\0"
    );
    refuse_bytes("v.nrrd", nrrd.as_bytes(), &h);
    let mha = format!(
        "ObjectType = Image\nNDims = 3\nDimSize = {dims3}\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n\0\0\0\0"
    );
    refuse_bytes("v.mha", mha.as_bytes(), "DimSize");

    // NIfTI-2 (64-bit dim): sizeof_hdr, magic, datatype float32, bitpix,
    // dim, pixdim, vox_offset; then the extension flag and 4 data bytes.
    let mut nii = vec![0u8; 548];
    nii[0..4].copy_from_slice(&540i32.to_le_bytes());
    nii[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
    nii[12..14].copy_from_slice(&16i16.to_le_bytes());
    nii[14..16].copy_from_slice(&32i16.to_le_bytes());
    for (i, d) in [3, HUGE, HUGE, HUGE, 1, 1, 1, 1].iter().enumerate() {
        nii[16 + 8 * i..24 + 8 * i].copy_from_slice(&(*d as i64).to_le_bytes());
    }
    for i in 0..8 {
        nii[104 + 8 * i..112 + 8 * i].copy_from_slice(&1f64.to_le_bytes());
    }
    nii[168..176].copy_from_slice(&544i64.to_le_bytes());
    refuse_bytes("v.nii", &nii, &format!("3 {dims3}"));

    // Legacy VTK and VTK XML
    let vtk = format!(
        "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS {dims3}\nPOINT_DATA 8\nSCALARS a float\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8\n"
    );
    refuse_bytes("v.vtk", vtk.as_bytes(), &dims3);
    let last = HUGE - 1;
    let extent = format!("0 {last} 0 {last} 0 {last}");
    let vti = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"{extent}\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece Extent=\"{extent}\">\n<PointData Scalars=\"a\">\n<DataArray type=\"Float32\" Name=\"a\" format=\"ascii\">1 2</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n"
    );
    refuse_bytes("v.vti", vti.as_bytes(), &extent);

    // CCP4/MRC: 32-bit sizes, so the largest, 2^31 − 1 each.
    let mut mrc = vec![0u8; 1024 + 16];
    for w in 0..3 {
        mrc[4 * w..4 * w + 4].copy_from_slice(&i32::MAX.to_le_bytes());
        mrc[64 + 4 * w..68 + 4 * w].copy_from_slice(&(w as i32 + 1).to_le_bytes());
    }
    mrc[12..16].copy_from_slice(&2i32.to_le_bytes());
    mrc[208..212].copy_from_slice(b"MAP ");
    mrc[212..216].copy_from_slice(&[0x44, 0x44, 0, 0]);
    let m = i32::MAX;
    refuse_bytes("v.mrc", &mrc, &format!("NX NY NZ {m} {m} {m}"));

    // Gaussian cube and CHGCAR
    let cube = format!(
        "c1\nc2\n    1 0.0 0.0 0.0\n{h} 1.0 0.0 0.0\n{h} 0.0 1.0 0.0\n{h} 0.0 0.0 1.0\n    1 1.0 0.0 0.0 0.0\n1.0 2.0\n"
    );
    refuse_bytes("v.cube", cube.as_bytes(), &format!("{h}x{h}x{h}"));
    let head: String = fs::read_to_string(fixture("chgcar", "CHGCAR_ortho"))
        .unwrap()
        .lines()
        .take(12)
        .map(|l| format!("{l}\n"))
        .collect();
    let chg = format!("{head}{dims3}\n1.0 2.0\n");
    refuse_bytes("CHGCAR", chg.as_bytes(), &format!("{h} x {h} x {h}"));
}

/// The default limit is half the physical memory (or 4 GiB), and every
/// reader's default options carry it.
#[test]
fn default_limit() {
    let d = ReadOptions::default().max_memory;
    assert_eq!(d, volray_io::default_max_memory());
    let total = fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        let line = t.lines().find(|l| l.starts_with("MemTotal:"))?.to_string();
        line.split_whitespace().nth(1)?.parse::<u64>().ok()
    });
    match total {
        Some(kib) => assert_eq!(d, kib * 1024 / 2),
        None => assert_eq!(d, volray_io::FALLBACK_MAX_MEMORY),
    }
}
