//! Headers that lie about sizes: Zarr stores declaring more voxels than
//! can be counted (bad input, by `info` and `render`), and for every
//! reader a header of a few hundred bytes declaring 4 GiB or more, with
//! `--max-memory 1T` where only the file's length may refuse it (issue 41).

use super::readers::{FILE_MUST_REFUSE, LIMIT_MUST_REFUSE, h5_dims, replace_all};
use super::*;

// ----------------------------------------------------------------- Zarr

/// A store's files: (path in `s.zarr`, bytes).
type Store<'a> = Vec<(&'a str, Vec<u8>)>;

/// Zarr stores declaring more than can be addressed: bad input (exit 1),
/// by `info` and by `render` (which reads a chunked store in pieces).
pub(super) fn zarr_size_cases() -> Cases {
    use serde_json::json;
    let mut c = Cases::new("zarr sizes");
    let huge = 1u64 << 40;
    let bytes = json!([{"name": "bytes", "configuration": {"endian": "little"}}]);
    let v3 =
        |shape: serde_json::Value, chunk: serde_json::Value| zarr_v3(shape, chunk, bytes.clone());
    let zarray = |shape: serde_json::Value, chunks: serde_json::Value| {
        json!({
            "zarr_format": 2, "shape": shape, "chunks": chunks, "dtype": "<u2",
            "compressor": null, "fill_value": 0, "order": "C", "filters": null,
        })
        .to_string()
        .into_bytes()
    };
    let ome = json!({
        "zarr_format": 3, "node_type": "group",
        "attributes": {"ome": {"version": "0.5", "multiscales": [{
            "axes": ["z", "y", "x"],
            "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}],
        }]}},
    })
    .to_string()
    .into_bytes();
    let stores: Vec<(&str, Store)> = vec![
        (
            "v3 shape 2^40 cubed in 64^3 chunks",
            vec![(
                "zarr.json",
                v3(json!([huge, huge, huge]), json!([64, 64, 64])),
            )],
        ),
        (
            "v3 shape 2^40 x 2^40 x 1",
            vec![("zarr.json", v3(json!([1, huge, huge]), json!([1, 64, 64])))],
        ),
        (
            "v3 shape 2^63 x 2 x 2",
            vec![("zarr.json", v3(json!([1u64 << 63, 2, 2]), json!([1, 2, 2])))],
        ),
        (
            "v2 shape 2^40 cubed",
            vec![(
                ".zarray",
                zarray(json!([huge, huge, huge]), json!([64, 64, 64])),
            )],
        ),
        (
            "OME-Zarr level 2^40 cubed",
            vec![
                ("zarr.json", ome),
                (
                    "0/zarr.json",
                    v3(json!([huge, huge, huge]), json!([64, 64, 64])),
                ),
            ],
        ),
    ];
    for (what, files) in stores {
        let files = files
            .into_iter()
            .map(|(f, b)| (format!("s.zarr/{f}"), b))
            .collect();
        c.many(what, files, "s.zarr", Expect::Bad);
        c.rendered();
    }
    c
}

// --------------------------------------------------- lies, every reader

/// A one-file case that must be refused by the file's length alone.
fn lie(c: &mut Cases, name: &str, file: &str, bytes: Vec<u8>) {
    c.one(name, file, bytes, Expect::Bad);
    c.with_args(FILE_MUST_REFUSE);
}

/// Each reader's header declaring 1024^3 or more of uncompressed data in
/// a file of a few hundred bytes, with `--max-memory 1T`: the file's
/// length must refuse it before anything is allocated.
pub(super) fn cases() -> Cases {
    let mut c = Cases::new("lying sizes");
    // NumPy.
    let bytes = fixture("c_f4.npy");
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let dict = String::from_utf8(bytes[10..10 + hlen].to_vec()).unwrap();
    let at = dict.find("'shape': (").unwrap() + "'shape': ".len();
    let end = at + dict[at..].find(')').unwrap() + 1;
    let dict = format!("{}(1024, 1024, 1024){}", &dict[..at], &dict[end..]);
    lie(
        &mut c,
        "c_f4.npy: shape 1024^3",
        "c_f4.npy",
        npy(dict.trim_end(), &bytes[10 + hlen..]),
    );
    // NRRD, attached and detached.
    let f = "f32_lps.nrrd";
    let bytes = fixture(&format!("nrrd/{f}"));
    lie(
        &mut c,
        &format!("{f}: sizes 1024^3"),
        f,
        replace(&bytes, "sizes: 4 3 5", "sizes: 1024 1024 1024"),
    );
    let (h, r) = ("f64_be.nhdr", "f64_be.raw");
    c.many(
        &format!("{h}: sizes 1024^3"),
        vec![
            (
                h.into(),
                replace(
                    &fixture(&format!("nrrd/{h}")),
                    "sizes: 4 3 5",
                    "sizes: 1024 1024 1024",
                ),
            ),
            (r.into(), fixture(&format!("nrrd/{r}"))),
        ],
        h,
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    let f = "u16_ascii.nrrd";
    let bytes = fixture(&format!("nrrd/{f}"));
    let sizes = String::from_utf8_lossy(&bytes)
        .lines()
        .find(|l| l.starts_with("sizes: "))
        .expect("sizes")
        .to_string();
    lie(
        &mut c,
        &format!("{f}: (text) sizes 1024^3"),
        f,
        replace(&bytes, &sizes, "sizes: 1024 1024 1024"),
    );
    // MetaImage, local and detached.
    let f = "f32.mha";
    let bytes = fixture(&format!("metaimage/{f}"));
    lie(
        &mut c,
        &format!("{f}: DimSize 1024^3"),
        f,
        replace(&bytes, "DimSize = 4 3 5", "DimSize = 1024 1024 1024"),
    );
    // NIfTI-1: dim[1..3] (int16 at 42) 1024; and Analyze's pair.
    let f = "f32.nii";
    let bytes = fixture(&format!("nifti/{f}"));
    let dims: Vec<u8> = [1024i16; 3].iter().flat_map(|d| d.to_le_bytes()).collect();
    lie(
        &mut c,
        &format!("{f}: dim 1024^3"),
        f,
        put(&bytes, 42, &dims),
    );
    let (h, i) = ("pair.hdr", "pair.img");
    c.many(
        &format!("{h}: dim 1024^3"),
        vec![
            (h.into(), put(&fixture(&format!("nifti/{h}")), 42, &dims)),
            (i.into(), fixture(&format!("nifti/{i}"))),
        ],
        h,
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    // VTK legacy, binary and ASCII; VTK XML, inline binary, appended raw, ASCII.
    for f in ["legacy_f32.vtk", "legacy_f32_ascii.vtk"] {
        let bytes = fixture(&format!("vtk/{f}"));
        let b = replace(
            &replace(&bytes, "DIMENSIONS 4 3 5", "DIMENSIONS 1024 1024 1024"),
            "POINT_DATA 60",
            "POINT_DATA 1073741824",
        );
        lie(&mut c, &format!("{f}: DIMENSIONS 1024^3"), f, b);
    }
    for f in ["vti_binary.vti", "vti_appended_raw.vti", "vti_ascii.vti"] {
        let bytes = fixture(&format!("vtk/{f}"));
        let b = replace(
            &replace(
                &bytes,
                "WholeExtent=\"0 3 0 2 0 4\"",
                "WholeExtent=\"0 1023 0 1023 0 1023\"",
            ),
            "Extent=\"0 3 0 2 0 4\"",
            "Extent=\"0 1023 0 1023 0 1023\"",
        );
        lie(&mut c, &format!("{f}: extent 1024^3"), f, b);
    }
    // MRC: NX NY NZ (int32 at 0).
    let f = "mode2_f32.mrc";
    let bytes = fixture(&format!("mrc/{f}"));
    let dims: Vec<u8> = [1024i32; 3].iter().flat_map(|d| d.to_le_bytes()).collect();
    lie(
        &mut c,
        &format!("{f}: NX NY NZ 1024^3"),
        f,
        put(&bytes, 0, &dims),
    );
    // Gaussian cube and CHGCAR: text, at least two bytes a value.
    let f = "ramp_bohr.cube";
    let bytes = fixture(&format!("cube/{f}"));
    let b = set_token(
        &set_token(&set_token(&bytes, 3, 0, "1024"), 4, 0, "1024"),
        5,
        0,
        "1024",
    );
    lie(&mut c, &format!("{f}: 1024^3 points"), f, b);
    let f = "CHGCAR_ortho";
    let bytes = fixture(&format!("chgcar/{f}"));
    lie(
        &mut c,
        &format!("{f}: grid 1024^3"),
        f,
        replace(&bytes, "    4    3    5", " 1024 1024 1024"),
    );
    // TIFF: the first page 60000 x 60000 (its strips far too short).
    let f = "plain_i32.tif";
    let bytes = fixture(&format!("tiff/{f}"));
    let mut b = bytes.clone();
    for tag in [256, 257] {
        let (at, is_long) = tiff_entry(&b, tag);
        let little = &b[..2] == b"II";
        let value = match (is_long, little) {
            (true, true) => 60000u32.to_le_bytes().to_vec(),
            (true, false) => 60000u32.to_be_bytes().to_vec(),
            (false, true) => 60000u16.to_le_bytes().to_vec(),
            (false, false) => 60000u16.to_be_bytes().to_vec(),
        };
        b = put(&b, at, &value);
    }
    lie(&mut c, &format!("{f}: 60000 x 60000 pages"), f, b);
    // HDF5 and MINC2: the dataspace of the volume made 1024^3.
    let f = "one.h5";
    let bytes = fixture(&format!("hdf5/{f}"));
    c.many(
        &format!("{f}: /fields/density 1024^3"),
        vec![(
            f.into(),
            replace_all(&bytes, &h5_dims(&[4, 3, 5]), &h5_dims(&[1024, 1024, 1024])),
        )],
        &format!("{f}:/fields/density"),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    let f = "ramp_i16.mnc";
    let bytes = fixture(&format!("minc/{f}"));
    c.one(
        &format!("{f}: image 1024^3"),
        f,
        replace_all(&bytes, &h5_dims(&[3, 4, 5]), &h5_dims(&[1024, 1024, 1024])),
        Expect::Bad,
    );
    c.with_args(LIMIT_MUST_REFUSE);
    // Compressed payloads whose header declares 4 GiB, with the memory
    // limit out of the way: the reader grows the volume as the stream
    // inflates (nothing in the header says the stream is short), so it
    // must find the stream's end, not allocate the declaration.
    let f = "u8_gzip.nrrd";
    let bytes = fixture(&format!("nrrd/{f}"));
    let b = replace(&bytes, "sizes: 4 3 5", "sizes: 2048 2048 1024");
    lie(&mut c, &format!("{f}: sizes 2048 2048 1024 (gzip)"), f, b);
    let f = "i16_zlib.mha";
    let bytes = fixture(&format!("metaimage/{f}"));
    let b = replace(&bytes, "DimSize = 4 3 5", "DimSize = 2048 1024 1024");
    lie(&mut c, &format!("{f}: DimSize 2048 1024 1024 (zlib)"), f, b);
    let f = "f32.nii.gz";
    let plain = gunzip(&fixture(&format!("nifti/{f}")));
    let dims: Vec<u8> = [1024i16; 3].iter().flat_map(|d| d.to_le_bytes()).collect();
    lie(
        &mut c,
        &format!("{f}: dim 1024^3 (gzip)"),
        f,
        gzip(&put(&plain, 42, &dims)),
    );
    c
}
