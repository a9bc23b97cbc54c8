//! Malformed files against the `volray` binary: truncations, bit flips in
//! header fields, headers that lie about sizes, huge, zero and negative
//! dimensions, non-finite spacings, unknown types, wrong magic numbers and
//! compressed streams cut short, all made at test time from the valid
//! fixtures in `crates/io/tests/fixtures` (written by each format's own
//! tools), and Zarr stores written here by hand. `hostile_files/readers.rs`
//! covers the readers added since (NetCDF-3, MINC1, NetCDF-4, FITS,
//! MGH/MGZ, each compressed DICOM transfer syntax, raw) and, for every
//! reader, a small header declaring gigabytes while the memory limit is
//! set out of the way, so that only the reader's own checks stand
//! between the lie and the allocation.
//!
//! Each case runs `volray info FILE` (some also `volray render FILE -o
//! out.png`) as a child process under `ulimit -v` (a lying header must not
//! make volray allocate gigabytes) with a wall-clock limit (a hang is a
//! failure), and checks: exit code 1 (bad input), one line on standard
//! error starting `volray: error:` and naming a file of the case, no
//! panic, and nothing left in the output directory. Mutations that may
//! still leave a valid file (random bit flips, edits the format tolerates)
//! only assert exit 0 or 1, never a crash, with the same hygiene.

#[path = "hostile_files/dicomdir.rs"]
mod dicomdir;
#[path = "hostile_files/encoded_dicom.rs"]
mod encoded_dicom;
#[path = "hostile_files/lying.rs"]
mod lying;
#[path = "hostile_files/readers.rs"]
mod readers;

use std::collections::BTreeMap;
use std::fs;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Virtual memory limit of each child, KiB (`ulimit -v`): far above what
/// the tiny fixtures need, far below what a lying header asks for.
const MEMORY_LIMIT_KIB: u64 = 2_000_000;
/// A child still running after this is a hang.
const TIME_LIMIT: Duration = Duration::from_secs(20);
/// Children run at once.
const WORKERS: usize = 4;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/crates/io/tests/fixtures");

fn fixture(rel: &str) -> Vec<u8> {
    fs::read(Path::new(FIXTURES).join(rel)).unwrap_or_else(|e| panic!("fixture {rel}: {e}"))
}

/// What a case must do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expect {
    /// Refused as bad input: exit 1 with a one-line error.
    Bad,
    /// Either read (exit 0) or refused (exit 1); nothing else.
    Either,
}

/// One malformed input: the files of its directory, the one named on the
/// command line, and what volray must do with it.
#[derive(Debug, Clone)]
struct Case {
    format: &'static str,
    name: String,
    files: Vec<(String, Vec<u8>)>,
    /// The input, relative to the case's directory (a file, or a
    /// directory for DICOM series); an HDF5 dataset path may follow.
    input: String,
    expect: Expect,
    /// Also run `volray render INPUT -o out.png`.
    render: bool,
    /// Flags after the input (`--max-memory 1T`: a lying header must be
    /// caught by the file's size, not by the memory limit).
    args: Vec<String>,
}

/// The cases of one format, built from its valid files.
struct Cases {
    format: &'static str,
    list: Vec<Case>,
}

impl Cases {
    fn new(format: &'static str) -> Self {
        Cases {
            format,
            list: Vec::new(),
        }
    }

    /// A one-file case named `file`.
    fn one(&mut self, name: &str, file: &str, bytes: Vec<u8>, expect: Expect) {
        self.many(name, vec![(file.to_string(), bytes)], file, expect);
    }

    /// An HDF5 file (HDF5, NetCDF-4, MINC2) `file` cut short four ways
    /// (empty, at 100 bytes, in the middle, one byte short) and with its
    /// signature garbled, `input` naming what to read of it.
    fn cut_and_unsigned(&mut self, file: &str, input: &str, bytes: &[u8]) {
        let n = bytes.len();
        for (what, at) in [
            ("empty", 0),
            ("cut at 100 bytes", 100),
            ("cut in the middle", n / 2),
            ("one byte short", n - 1),
        ] {
            self.many(
                &format!("{file}: {what}"),
                vec![(file.into(), bytes[..at].to_vec())],
                input,
                Expect::Bad,
            );
        }
        self.many(
            &format!("{file}: wrong magic"),
            vec![(file.into(), put(bytes, 1, b"XDF"))],
            input,
            Expect::Bad,
        );
    }

    /// A case of several files, `input` naming the one to read.
    fn many(&mut self, name: &str, files: Vec<(String, Vec<u8>)>, input: &str, expect: Expect) {
        let render = self.list.len().is_multiple_of(4);
        self.list.push(Case {
            format: self.format,
            name: name.to_string(),
            files,
            input: input.to_string(),
            expect,
            render,
            args: Vec::new(),
        });
    }

    /// The last case, also rendered.
    fn rendered(&mut self) {
        self.list.last_mut().expect("a case").render = true;
    }

    /// The last case, run with `args` after the input.
    fn with_args(&mut self, args: &[&str]) {
        let case = self.list.last_mut().expect("a case");
        case.args = args.iter().map(|a| a.to_string()).collect();
    }

    /// Truncations of `bytes` in the middle of the header, at its end, in
    /// the middle of the data and one byte short, and the empty file. A
    /// text format may still parse one byte short (a lost newline), so
    /// `last` says what to expect there, and `mid` in the data's middle (a
    /// cut past the part read may leave it whole).
    fn truncations(
        &mut self,
        file: &str,
        bytes: &[u8],
        header_end: usize,
        mid: Expect,
        last: Expect,
    ) {
        let n = bytes.len();
        assert!(
            0 < header_end && header_end < n,
            "{file}: header end {header_end} of {n}"
        );
        let points = [
            ("empty", 0, Expect::Bad),
            ("cut in the header", header_end / 2, Expect::Bad),
            ("cut at the header's end", header_end, Expect::Bad),
            ("cut in the data", (header_end + n) / 2, mid),
            ("one byte short", n - 1, last),
        ];
        for (what, at, expect) in points {
            self.one(
                &format!("{file}: {what} ({at} of {n} bytes)"),
                file,
                bytes[..at].to_vec(),
                expect,
            );
        }
    }

    /// Text edits of a header: each `(from, to)` replaces the first
    /// `from` (which must be there) in `bytes`.
    fn edits<S: AsRef<str>>(&mut self, file: &str, bytes: &[u8], edits: &[(S, S, Expect)]) {
        for (from, to, expect) in edits {
            let (from, to, expect) = (from.as_ref(), to.as_ref(), *expect);
            self.one(
                &format!("{file}: '{from}' -> '{to}'"),
                file,
                replace(bytes, from, to),
                expect,
            );
        }
    }

    /// `count` random bit flips in `bytes[..span]`, each its own case: the
    /// result may still be valid, so only a clean exit is asked for.
    fn flips(&mut self, file: &str, bytes: &[u8], span: usize, count: usize, seed: u64) {
        let mut rng = seed;
        for _ in 0..count {
            let r = xorshift(&mut rng);
            let at = (r % span as u64) as usize;
            let bit = (r >> 32) % 8;
            let mut b = bytes.to_vec();
            b[at] ^= 1 << bit;
            self.one(
                &format!("{file}: bit {bit} of byte {at} flipped"),
                file,
                b,
                Expect::Either,
            );
        }
    }
}

fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// `bytes` with the first `from` replaced by `to`; `from` must be there, so
/// that a fixture's change cannot silently turn a case into a valid file.
fn replace(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let at = find(bytes, from.as_bytes()).unwrap_or_else(|| panic!("'{from}' not in the fixture"));
    [&bytes[..at], to.as_bytes(), &bytes[at + from.len()..]].concat()
}

fn find(bytes: &[u8], what: &[u8]) -> Option<usize> {
    bytes.windows(what.len()).position(|w| w == what)
}

/// `bytes` with `value` written at `offset`.
fn put(bytes: &[u8], offset: usize, value: &[u8]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    b[offset..offset + value.len()].copy_from_slice(value);
    b
}

/// Where the text header ends: just past the first `marker`.
fn after(bytes: &[u8], marker: &str) -> usize {
    find(bytes, marker.as_bytes()).unwrap_or_else(|| panic!("'{marker}' not in the fixture"))
        + marker.len()
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(bytes), &mut out).unwrap();
    out
}

/// Huge dimension triples, each with what it tests.
const HUGE: [(&str, &str); 3] = [
    ("2^31", "2147483648 3 5"),
    ("2^62", "4611686018427387904 4 4"),
    ("product overflow", "4294967296 4294967296 4294967296"),
];

// ---------------------------------------------------------------- NumPy

/// A `.npy` file: version 1.0 with `dict` as its header, padded as NumPy
/// pads it, then `data`.
fn npy(dict: &str, data: &[u8]) -> Vec<u8> {
    let mut header = dict.to_string();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend((header.len() as u16).to_le_bytes());
    b.extend(header.as_bytes());
    b.extend(data);
    b
}

fn npy_cases() -> Cases {
    let mut c = Cases::new("npy");
    let f = "c_f4.npy";
    let bytes = fixture(f);
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let dict = String::from_utf8(bytes[10..10 + hlen].to_vec()).unwrap();
    let dict = dict.trim_end().to_string();
    let data = &bytes[10 + hlen..];
    let shape_at = dict.find("'shape': (").unwrap() + "'shape': ".len();
    let shape_end = shape_at + dict[shape_at..].find(')').unwrap() + 1;
    let shape = &dict[shape_at..shape_end];
    let with_shape = |s: &str| format!("{}{s}{}", &dict[..shape_at], &dict[shape_end..]);
    assert_eq!(npy(&dict, data), bytes, "the fixture is NumPy's own layout");

    c.truncations(f, &bytes, 10 + hlen, Expect::Bad, Expect::Bad);
    for (what, s, expect) in [
        ("2^31", "(2147483648, 3, 4)", Expect::Bad),
        ("2^62", "(4611686018427387904, 4, 4)", Expect::Bad),
        (
            "product overflow",
            "(4294967296, 4294967296, 4294967296)",
            Expect::Bad,
        ),
        ("beyond u64", "(99999999999999999999999, 2, 2)", Expect::Bad),
        ("zero", "(0, 3, 4)", Expect::Bad),
        ("negative", "(-2, 3, 4)", Expect::Bad),
        ("data too short", "(20, 30, 40)", Expect::Bad),
        ("2-D", "(6, 10)", Expect::Either),
        ("not a tuple", "'three'", Expect::Bad),
    ] {
        c.one(
            &format!("{f}: shape {what} {shape} -> {s}"),
            f,
            npy(&with_shape(s), data),
            expect,
        );
    }
    for (from, to) in [
        ("'<f4'", "'<x4'"),
        ("'<f4'", "'|V8'"),
        ("'<f4'", "'<f3'"),
        ("'fortran_order': False", "'fortran_order': 'maybe'"),
    ] {
        c.one(
            &format!("{f}: {from} -> {to}"),
            f,
            npy(&dict.replace(from, to), data),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: header not a dict"),
        f,
        npy("garbage", data),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: header length 65535"),
        f,
        put(&bytes, 8, &[0xff, 0xff]),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: version 9.0"),
        f,
        put(&bytes, 6, &[9, 0]),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: wrong magic"),
        f,
        put(&bytes, 0, b"XNUMPY"),
        Expect::Bad,
    );
    c.flips(f, &bytes, 10 + hlen, 4, 1);
    c
}

// ----------------------------------------------------------------- NRRD

fn nrrd_cases() -> Cases {
    let mut c = Cases::new("nrrd");
    let f = "f32_lps.nrrd";
    let bytes = fixture(&format!("nrrd/{f}"));
    let header_end = after(&bytes, "\n\n");
    c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Bad);
    let sizes = "sizes: 4 3 5";
    let mut edits: Vec<(String, String, Expect)> = HUGE
        .iter()
        .map(|(_, s)| (sizes.to_string(), format!("sizes: {s}"), Expect::Bad))
        .collect();
    for (from, to) in [
        (sizes, "sizes: 0 3 5"),
        (sizes, "sizes: -4 3 5"),
        (sizes, "sizes: 4 3"),
        (sizes, "sizes: 40 30 50"),
        (sizes, "sizes: 4 3 x"),
        ("type: float", "type: quaternion"),
        ("encoding: raw", "encoding: zip7"),
        ("dimension: 3", "dimension: 0"),
        ("dimension: 3", "dimension: 99999999999"),
        ("(0.5,0,0)", "(nan,0,0)"),
        ("(0.5,0,0)", "(inf,0,0)"),
        ("(0.5,0,0)", "(0,0,0)"),
        ("NRRD0005", "XRRD0005"),
    ] {
        edits.push((from.to_string(), to.to_string(), Expect::Bad));
    }
    c.edits(f, &bytes, &edits);
    c.flips(f, &bytes, header_end, 4, 2);

    // gzip encoding: the stream cut, the sizes lying either way.
    let f = "u8_gzip.nrrd";
    let bytes = fixture(&format!("nrrd/{f}"));
    let header_end = after(&bytes, "\n\n");
    c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Either);
    c.edits(
        f,
        &bytes,
        &[
            ("sizes: 4 3 5", "sizes: 4 3 6", Expect::Bad),
            ("sizes: 4 3 5", "sizes: 400 300 500", Expect::Bad),
            (
                "sizes: 4 3 5",
                "sizes: 4611686018427387904 4 4",
                Expect::Bad,
            ),
            ("sizes: 4 3 5", "sizes: 4 3 4", Expect::Either),
            ("spacings: 0.5 1 2", "spacings: nan 1 2", Expect::Either),
            ("spacings: 0.5 1 2", "spacings: 0.5 inf 2", Expect::Bad),
            ("spacings: 0.5 1 2", "spacings: 0.5 -inf 2", Expect::Bad),
            ("encoding: gzip", "encoding: bzip2", Expect::Bad),
        ],
    );
    // The deflate data garbled: an error, or (if the garbage still
    // inflates) a checksum the reader may not check.
    let mid = (header_end + bytes.len()) / 2;
    c.one(
        &format!("{f}: deflate data garbled"),
        f,
        put(&bytes, mid, &[0xff; 4]),
        Expect::Either,
    );

    // Detached data: the data file short, empty, missing its size.
    let (h, r) = ("f64_be.nhdr", "f64_be.raw");
    let header = fixture(&format!("nrrd/{h}"));
    let raw = fixture(&format!("nrrd/{r}"));
    let pair = |hdr: Vec<u8>, data: Vec<u8>| vec![(h.to_string(), hdr), (r.to_string(), data)];
    c.many(
        &format!("{h}: {r} one byte short"),
        pair(header.clone(), raw[..raw.len() - 1].to_vec()),
        h,
        Expect::Bad,
    );
    c.many(
        &format!("{h}: {r} empty"),
        pair(header.clone(), Vec::new()),
        h,
        Expect::Bad,
    );
    c.many(
        &format!("{h}: {r} half"),
        pair(header.clone(), raw[..raw.len() / 2].to_vec()),
        h,
        Expect::Bad,
    );
    for (from, to) in [
        ("sizes: 4 3 5", "sizes: 4 3 6"),
        ("sizes: 4 3 5", "sizes: 4611686018427387904 4 4"),
        ("spacings: 1 1 1", "spacings: 1 inf 1"),
        ("type: double", "type: double-double"),
        ("endian: big", "endian: middle"),
        ("encoding: raw", "encoding: raw\nbyte skip: 100000"),
        ("encoding: raw", "encoding: raw\nbyte skip: -7"),
        ("encoding: raw", "encoding: raw\nline skip: 99999999999"),
    ] {
        c.many(
            &format!("{h}: '{from}' -> '{to}'"),
            pair(replace(&header, from, to), raw.clone()),
            h,
            Expect::Bad,
        );
    }

    // Detached gzip: the stream cut in the middle and just before its end.
    let (h, z) = ("i32_gz.nhdr", "i32_gz.raw.gz");
    let header = fixture(&format!("nrrd/{h}"));
    let gz = fixture(&format!("nrrd/{z}"));
    for (what, at) in [
        ("in the middle", gz.len() / 2),
        ("after the gzip header", 10),
    ] {
        c.many(
            &format!("{h}: {z} cut {what}"),
            vec![
                (h.to_string(), header.clone()),
                (z.to_string(), gz[..at].to_vec()),
            ],
            h,
            Expect::Bad,
        );
    }
    // A stream that inflates to far more than the header declares.
    let bomb = gzip(&vec![0u8; 8 << 20]);
    c.many(
        &format!("{h}: {z} inflates to 8 MiB"),
        vec![(h.to_string(), header.clone()), (z.to_string(), bomb)],
        h,
        Expect::Either,
    );
    c
}

// ------------------------------------------------------------ MetaImage

fn metaimage_cases() -> Cases {
    let mut c = Cases::new("metaimage");
    let f = "f32.mha";
    let bytes = fixture(&format!("metaimage/{f}"));
    let header_end = after(&bytes, "ElementDataFile = LOCAL\n");
    c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Bad);
    let dims = "DimSize = 4 3 5";
    let mut edits: Vec<(String, String, Expect)> = HUGE
        .iter()
        .map(|(_, s)| (dims.to_string(), format!("DimSize = {s}"), Expect::Bad))
        .collect();
    for (from, to) in [
        (dims, "DimSize = 0 3 5"),
        (dims, "DimSize = 4 -3 5"),
        (dims, "DimSize = 40 30 50"),
        (dims, "DimSize = 4 3"),
        ("ElementType = MET_FLOAT", "ElementType = MET_FOO"),
        ("ElementType = MET_FLOAT", "ElementType = MET_STRING"),
        ("ElementSpacing = 0.5 1.25 2", "ElementSpacing = nan 1.25 2"),
        ("ElementSpacing = 0.5 1.25 2", "ElementSpacing = 0.5 inf 2"),
        ("NDims = 3", "NDims = 0"),
        ("NDims = 3", "NDims = 99999999999"),
        (
            "TransformMatrix = 1 0 0 0 1 0 0 0 1",
            "TransformMatrix = nan 0 0 0 1 0 0 0 1",
        ),
        (
            "TransformMatrix = 1 0 0 0 1 0 0 0 1",
            "TransformMatrix = 1 1 0 0 1 0 0 0 1",
        ),
        ("Offset = 1 -2 3", "Offset = 1 inf 3"),
        (
            "ElementDataFile = LOCAL",
            "ElementDataFile = LIST 99999999999",
        ),
    ] {
        edits.push((from.to_string(), to.to_string(), Expect::Bad));
    }
    c.edits(f, &bytes, &edits);
    c.flips(f, &bytes, header_end, 4, 3);

    // zlib: the compressed size lying, the stream cut.
    let f = "i16_zlib.mha";
    let bytes = fixture(&format!("metaimage/{f}"));
    let header_end = after(&bytes, "ElementDataFile = LOCAL\n");
    c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Bad);
    c.edits(
        f,
        &bytes,
        &[
            (
                "CompressedDataSize = 109",
                "CompressedDataSize = 4611686018427387904",
                Expect::Bad,
            ),
            (
                "CompressedDataSize = 109",
                "CompressedDataSize = 99999",
                Expect::Bad,
            ),
            (
                "CompressedDataSize = 109",
                "CompressedDataSize = 5",
                Expect::Bad,
            ),
            (
                "CompressedDataSize = 109",
                "CompressedDataSize = -109",
                Expect::Bad,
            ),
            ("DimSize = 4 3 5", "DimSize = 4 3 6", Expect::Bad),
            ("DimSize = 4 3 5", "DimSize = 2147483648 3 5", Expect::Bad),
            ("DimSize = 4 3 5", "DimSize = 4 3 4", Expect::Either),
        ],
    );

    // Detached raw data.
    let (h, r) = ("be_i16.mhd", "be_i16.raw");
    let header = fixture(&format!("metaimage/{h}"));
    let raw = fixture(&format!("metaimage/{r}"));
    let pair = |hdr: Vec<u8>, data: Vec<u8>| vec![(h.to_string(), hdr), (r.to_string(), data)];
    c.many(
        &format!("{h}: {r} one byte short"),
        pair(header.clone(), raw[..raw.len() - 1].to_vec()),
        h,
        Expect::Bad,
    );
    c.many(
        &format!("{h}: {r} empty"),
        pair(header.clone(), Vec::new()),
        h,
        Expect::Bad,
    );
    c.many(
        &format!("{h}: DimSize 2^62"),
        pair(
            replace(
                &header,
                "DimSize = 4 3 5",
                "DimSize = 4611686018427387904 4 4",
            ),
            raw.clone(),
        ),
        h,
        Expect::Bad,
    );
    c.many(
        &format!("{h}: HeaderSize beyond the data"),
        pair(
            replace(&header, "ElementType", "HeaderSize = 100000\nElementType"),
            raw,
        ),
        h,
        Expect::Bad,
    );
    c
}

// ---------------------------------------------------------------- NIfTI

fn nifti_cases() -> Cases {
    let mut c = Cases::new("nifti");
    let f = "f32.nii";
    let bytes = fixture(&format!("nifti/{f}"));
    c.truncations(f, &bytes, 348, Expect::Bad, Expect::Bad);
    let i16le = |v: i16| v.to_le_bytes().to_vec();
    let f32le = |v: f32| v.to_le_bytes().to_vec();
    for (what, offset, value) in [
        ("sizeof_hdr 0", 0, 0i32.to_le_bytes().to_vec()),
        ("dim[0] 0", 40, i16le(0)),
        ("dim[0] 9", 40, i16le(9)),
        ("dim[1] 32767 (data too short)", 42, i16le(32767)),
        ("dim[1] 0", 42, i16le(0)),
        ("dim[1] -4", 42, i16le(-4)),
        ("dim[3] -32768", 46, i16le(-32768)),
        ("datatype 9999", 70, i16le(9999)),
        ("datatype 2304 (RGBA)", 70, i16le(2304)),
        ("vox_offset 1e12", 108, f32le(1e12)),
        ("vox_offset NaN", 108, f32le(f32::NAN)),
        ("vox_offset -352", 108, f32le(-352.0)),
        ("srow_x NaN", 280, f32le(f32::NAN)),
        ("srow_y infinite", 296, f32le(f32::INFINITY)),
        ("magic", 344, b"xx1\0".to_vec()),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            put(&bytes, offset, &value),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: scl_slope NaN"),
        f,
        put(&bytes, 112, &f32le(f32::NAN)),
        Expect::Either,
    );
    c.flips(f, &bytes, 348, 4, 4);

    // pixdim only (no sform or qform): the spacing comes from pixdim.
    let f = "pixdim_only.nii";
    let bytes = fixture(&format!("nifti/{f}"));
    for (what, value) in [("NaN", f32::NAN), ("infinite", f32::INFINITY)] {
        c.one(
            &format!("{f}: pixdim[1] {what}"),
            f,
            put(&bytes, 80, &f32le(value)),
            Expect::Bad,
        );
    }

    // NIfTI-2: 64-bit dims and offsets.
    let f = "nifti2_i32.nii";
    let bytes = fixture(&format!("nifti/{f}"));
    c.truncations(f, &bytes, 540, Expect::Bad, Expect::Bad);
    let i64le = |v: i64| v.to_le_bytes().to_vec();
    for (what, offset, value) in [
        ("dim[1] 2^62", 24, i64le(1 << 62)),
        ("dim[1] 2^31", 24, i64le(1 << 31)),
        ("dim[1] -1", 24, i64le(-1)),
        (
            "dims 2^32 each (product overflow)",
            24,
            [i64le(1 << 32), i64le(1 << 32), i64le(1 << 32)].concat(),
        ),
        ("datatype 9999", 12, i16le(9999)),
        ("vox_offset 2^62", 168, i64le(1 << 62)),
        ("vox_offset -1", 168, i64le(-1)),
        ("magic", 4, b"n+9\0".to_vec()),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            put(&bytes, offset, &value),
            Expect::Bad,
        );
    }

    // gzip: the stream cut; a header lying inside a valid stream.
    let f = "f32.nii.gz";
    let gz = fixture(&format!("nifti/{f}"));
    let plain = gunzip(&gz);
    for (what, at) in [
        ("in the middle", gz.len() / 2),
        ("after the gzip header", 10),
        ("8 bytes short (no trailer)", gz.len() - 8),
    ] {
        let expect = if at == gz.len() - 8 {
            Expect::Either
        } else {
            Expect::Bad
        };
        c.one(
            &format!("{f}: stream cut {what}"),
            f,
            gz[..at].to_vec(),
            expect,
        );
    }
    for (what, offset, value) in [
        (
            "dim[1..3] 32767 each",
            42,
            [i16le(32767), i16le(32767), i16le(32767)].concat(),
        ),
        ("dim[1] 0", 42, i16le(0)),
        ("datatype 9999", 70, i16le(9999)),
        ("vox_offset 1e12", 108, f32le(1e12)),
    ] {
        c.one(
            &format!("{f}: {what} inside the stream"),
            f,
            gzip(&put(&plain, offset, &value)),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: stream of only the header"),
        f,
        gzip(&plain[..352]),
        Expect::Bad,
    );
    // 1 GiB of u8 declared, a few bytes given: refused before allocating.
    let gib = put(
        &put(
            &plain,
            42,
            &[i16le(1024), i16le(1024), i16le(1024)].concat(),
        ),
        70,
        &[i16le(2), i16le(8)].concat(),
    );
    c.one(
        &format!("{f}: 1024^3 u8 declared, 240 bytes given"),
        f,
        gzip(&gib),
        Expect::Bad,
    );
    c
}

// ----------------------------------------------------------- VTK legacy

fn vtk_cases() -> Cases {
    let mut c = Cases::new("vtk legacy");
    for f in ["legacy_f32.vtk", "legacy_f32_ascii.vtk"] {
        let bytes = fixture(&format!("vtk/{f}"));
        let header_end = after(&bytes, "LOOKUP_TABLE default\n");
        // The file ends in a newline after the data: without it the data
        // are whole; one byte more and the binary data are not.
        c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Either);
        assert_eq!(bytes.last(), Some(&b'\n'));
        let short = if f.contains("ascii") {
            Expect::Either
        } else {
            Expect::Bad
        };
        c.one(
            &format!("{f}: data one byte short"),
            f,
            bytes[..bytes.len() - 2].to_vec(),
            short,
        );
        let dims = "DIMENSIONS 4 3 5";
        let mut edits: Vec<(String, String, Expect)> = HUGE
            .iter()
            .map(|(_, s)| (dims.to_string(), format!("DIMENSIONS {s}"), Expect::Bad))
            .collect();
        for (from, to) in [
            (dims, "DIMENSIONS 0 3 5"),
            (dims, "DIMENSIONS 4 -3 5"),
            (dims, "DIMENSIONS 40 30 50"),
            ("SPACING 0.5 2 1.5", "SPACING nan 2 1.5"),
            ("SPACING 0.5 2 1.5", "SPACING 0.5 2 inf"),
            ("SCALARS v float", "SCALARS v quux"),
            ("SCALARS v float", "SCALARS v float 99999999999"),
            ("POINT_DATA 60", "POINT_DATA 6000000000"),
            ("POINT_DATA 60", "POINT_DATA 59"),
            ("DATASET STRUCTURED_POINTS", "DATASET POLYDATA"),
            ("# vtk DataFile", "# xyz DataFile"),
        ] {
            edits.push((from.to_string(), to.to_string(), Expect::Bad));
        }
        if f.contains("ascii") {
            edits.push(("10.25".into(), "ten".into(), Expect::Bad));
            edits.push(("ASCII".into(), "ASCIX".into(), Expect::Bad));
        } else {
            edits.push(("BINARY".into(), "BINARX".into(), Expect::Bad));
        }
        c.edits(f, &bytes, &edits);
        c.flips(f, &bytes, header_end, 2, 5);
    }
    c
}

// -------------------------------------------------------------- VTK XML

fn vti_cases() -> Cases {
    let mut c = Cases::new("vti");
    let whole = "WholeExtent=\"0 3 0 2 0 4\"";
    for f in [
        "vti_ascii.vti",
        "vti_binary.vti",
        "vti_appended_raw.vti",
        "vti_appended_base64.vti",
        "vti_binary_zlib.vti",
        "vti_appended_raw_zlib.vti",
    ] {
        let bytes = fixture(&format!("vtk/{f}"));
        let header_end = after(&bytes, "<PointData");
        // A cut past the array read may leave it whole, and the XML parser
        // forgives a missing end tag: only a clean exit is asked there.
        c.truncations(f, &bytes, header_end, Expect::Either, Expect::Either);
        // A cut inside the data of the array read (the first).
        let data = if f.contains("appended") {
            after(&bytes, "<AppendedData encoding=")
        } else {
            let array = header_end + after(&bytes[header_end..], "<DataArray");
            array + after(&bytes[array..], ">")
        };
        c.one(
            &format!("{f}: cut 40 bytes into the data"),
            f,
            bytes[..data + 40].to_vec(),
            Expect::Bad,
        );
        // The extents appear twice (image and piece): edit both.
        let both = |from: &str, to: &str| {
            let piece = from.replace("WholeExtent", "Extent");
            let b = replace(&bytes, from, to);
            replace(
                &b,
                &format!(" {piece}"),
                &format!(" {}", to.replace("WholeExtent", "Extent")),
            )
        };
        for (what, to) in [
            ("2^31", "WholeExtent=\"0 2147483647 0 2147483647 0 4\""),
            ("2^62", "WholeExtent=\"0 4611686018427387903 0 3 0 3\""),
            ("inverted", "WholeExtent=\"3 0 0 2 0 4\""),
            ("larger than the data", "WholeExtent=\"0 30 0 20 0 40\""),
        ] {
            c.one(
                &format!("{f}: extent {what}"),
                f,
                both(whole, to),
                Expect::Bad,
            );
        }
        c.edits(
            f,
            &bytes,
            &[
                (
                    "Spacing=\"0.5 2 1.5\"",
                    "Spacing=\"nan 2 1.5\"",
                    Expect::Bad,
                ),
                (
                    "Spacing=\"0.5 2 1.5\"",
                    "Spacing=\"0.5 -inf 1.5\"",
                    Expect::Bad,
                ),
                ("type=\"Float32\"", "type=\"Float99\"", Expect::Bad),
                (
                    "<VTKFile type=\"ImageData\"",
                    "<VTKFile type=\"PolyData\"",
                    Expect::Bad,
                ),
            ],
        );
        if f.contains("appended") {
            c.edits(
                f,
                &bytes,
                &[("offset=\"0\"", "offset=\"99999999999\"", Expect::Bad)],
            );
        }
        if f == "vti_appended_raw_zlib.vti" {
            // The block header (UInt64): block count, block size, last
            // block size, compressed sizes; each made to lie.
            let at = after(&bytes, "<AppendedData encoding=\"raw\">\n   _");
            for (what, field, value) in [
                ("block count 2^62", 0, 1u64 << 62),
                ("last block size 2^40", 2, 1 << 40),
                ("compressed size 2^62", 3, 1 << 62),
                ("compressed size 3", 3, 3),
            ] {
                c.one(
                    &format!("{f}: zlib header {what}"),
                    f,
                    put(&bytes, at + 8 * field, &value.to_le_bytes()),
                    Expect::Bad,
                );
            }
        }
    }
    c
}

// ---------------------------------------------------------------- DICOM

fn dicom_cases() -> Cases {
    let mut c = Cases::new("dicom");
    let f = "single.dcm";
    let bytes = fixture(&format!("dicom/{f}"));
    let pixel_tag = find(&bytes, &[0xe0, 0x7f, 0x10, 0x00, b'O', b'W']).expect("pixel data");
    c.truncations(f, &bytes, pixel_tag, Expect::Bad, Expect::Bad);
    // Explicit VR little endian: tag, VR, 2-byte length, value.
    let us = |group: u16, element: u16, value: u16| {
        let tag = [group.to_le_bytes(), element.to_le_bytes()].concat();
        let at = find(&bytes, &[&tag[..], b"US\x02\x00"].concat()).expect("US element");
        put(&bytes, at + 8, &value.to_le_bytes())
    };
    for (what, group, element, value) in [
        ("Rows 65535", 0x0028, 0x0010, 65535),
        ("Rows 0", 0x0028, 0x0010, 0),
        ("Columns 65535", 0x0028, 0x0011, 65535),
        ("BitsAllocated 13", 0x0028, 0x0100, 13),
        ("BitsAllocated 0", 0x0028, 0x0100, 0),
        ("SamplesPerPixel 7", 0x0028, 0x0002, 7),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            us(group, element, value),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: pixel data length 0xfffffff0"),
        f,
        put(&bytes, pixel_tag + 8, &0xfffffff0u32.to_le_bytes()),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: pixel data length 2^31"),
        f,
        put(&bytes, pixel_tag + 8, &(1u32 << 31).to_le_bytes()),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: wrong magic and preamble"),
        f,
        put(&bytes, 128, b"XXXX"),
        Expect::Bad,
    );
    c.flips(f, &bytes, pixel_tag, 4, 6);

    // A directory of slices.
    let dir = Path::new(FIXTURES).join("dicom/ct");
    let mut slices: Vec<(String, Vec<u8>)> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap() != "README.txt")
        .map(|p| {
            (
                format!("ct/{}", p.file_name().unwrap().to_string_lossy()),
                fs::read(&p).unwrap(),
            )
        })
        .collect();
    slices.sort();
    let with = |i: usize, b: Vec<u8>| {
        let mut s = slices.clone();
        s[i].1 = b;
        s
    };
    let first = &slices[0].1;
    let pixel_tag = find(first, &[0xe0, 0x7f, 0x10, 0x00]).expect("pixel data");
    c.many(
        "ct/: one slice cut in its pixel data",
        with(0, first[..(pixel_tag + first.len()) / 2].to_vec()),
        "ct",
        Expect::Bad,
    );
    c.many(
        "ct/: one slice empty",
        with(1, Vec::new()),
        "ct",
        Expect::Either,
    );
    c.many(
        "ct/: every slice cut in the header",
        slices
            .iter()
            .map(|(n, b)| (n.clone(), b[..200.min(b.len())].to_vec()))
            .collect(),
        "ct",
        Expect::Bad,
    );
    c.many(
        "ct/: only a text file",
        vec![("ct/notes.txt".into(), b"not DICOM\n".to_vec())],
        "ct",
        Expect::Bad,
    );
    c
}

// ----------------------------------------------------------------- TIFF

/// The offset of the value field of tag `tag` in the first IFD of a
/// classic little- or big-endian TIFF, and whether the value is a LONG
/// (else a SHORT).
fn tiff_entry(bytes: &[u8], tag: u16) -> (usize, bool) {
    let little = &bytes[..2] == b"II";
    let u16_at = |at: usize| {
        let b = [bytes[at], bytes[at + 1]];
        if little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        }
    };
    let u32_at = |at: usize| {
        let b = [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]];
        if little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        }
    };
    let ifd = u32_at(4) as usize;
    let count = u16_at(ifd) as usize;
    let entry = (0..count)
        .map(|i| ifd + 2 + 12 * i)
        .find(|&e| u16_at(e) == tag)
        .unwrap_or_else(|| panic!("no tag {tag} in the first IFD"));
    (entry + 8, u16_at(entry + 2) == 4)
}

fn tiff_cases() -> Cases {
    let mut c = Cases::new("tiff");
    for f in [
        "plain_i16_be.tif",
        "pillow_lzw_u16.tif",
        "imagej_f32_zlib.tif",
    ] {
        let bytes = fixture(&format!("tiff/{f}"));
        // Cut points about the first IFD's StripOffsets entry; the last
        // byte may be padding the reader never needs.
        let (strip_offsets, _) = tiff_entry(&bytes, 273);
        c.truncations(f, &bytes, strip_offsets, Expect::Bad, Expect::Either);
        let little = &bytes[..2] == b"II";
        let short = |v: u16| {
            if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            }
        };
        let long = |v: u32| {
            if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            }
        };
        c.one(
            &format!("{f}: first IFD beyond the end"),
            f,
            put(&bytes, 4, &long(0xffff_fff0)),
            Expect::Bad,
        );
        c.one(
            &format!("{f}: first IFD at 0"),
            f,
            put(&bytes, 4, &long(0)),
            Expect::Bad,
        );
        c.one(
            &format!("{f}: wrong magic"),
            f,
            put(&bytes, 2, &short(43)),
            Expect::Bad,
        );
        for (what, tag, value) in [
            ("ImageWidth 65535", 256, 65535u16),
            ("ImageWidth 0", 256, 0),
            ("BitsPerSample 13", 258, 13),
            ("Compression 50000", 259, 50000),
        ] {
            let (at, is_long) = tiff_entry(&bytes, tag);
            let value = if is_long {
                long(u32::from(value)).to_vec()
            } else {
                short(value).to_vec()
            };
            c.one(
                &format!("{f}: {what}"),
                f,
                put(&bytes, at, &value),
                Expect::Bad,
            );
        }
        c.flips(f, &bytes, strip_offsets, 2, 7);
    }
    c
}

// ------------------------------------------------------- Gaussian cube

/// `text` with token `token` of line `line` (both from 0) set to `value`.
fn set_token(text: &[u8], line: usize, token: usize, value: &str) -> Vec<u8> {
    let text = std::str::from_utf8(text).unwrap();
    let mut lines: Vec<String> = text.split('\n').map(String::from).collect();
    let mut tokens: Vec<String> = lines[line].split_whitespace().map(String::from).collect();
    tokens[token] = value.to_string();
    lines[line] = tokens.join(" ");
    lines.join("\n").into_bytes()
}

/// Where line `line` (from 0) of `text` starts.
fn line_start(text: &[u8], line: usize) -> usize {
    text.iter()
        .enumerate()
        .filter(|&(_, &b)| b == b'\n')
        .nth(line - 1)
        .map(|(i, _)| i + 1)
        .unwrap()
}

fn cube_cases() -> Cases {
    let mut c = Cases::new("cube");
    let f = "ramp_bohr.cube";
    let bytes = fixture(&format!("cube/{f}"));
    let natoms = 3;
    let header_end = line_start(&bytes, 6 + natoms);
    c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Either);
    for (what, line, token, value) in [
        ("natoms 2^31", 2, 0, "2147483648"),
        ("natoms 2^62", 2, 0, "4611686018427387904"),
        ("origin NaN", 2, 1, "nan"),
        ("nx 2^31", 3, 0, "2147483648"),
        ("nx 2^62", 3, 0, "4611686018427387904"),
        ("nx 0", 3, 0, "0"),
        ("ny 40 (data too short)", 4, 0, "40"),
        ("nz not a number", 5, 0, "five"),
        ("x step NaN", 3, 1, "nan"),
        ("y step infinite", 4, 2, "inf"),
        ("x step zero (singular cell)", 3, 1, "0"),
        ("first value not a number", 6 + natoms, 0, "abc"),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            set_token(&bytes, line, token, value),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: product overflow"),
        f,
        set_token(
            &set_token(&set_token(&bytes, 3, 0, "4294967296"), 4, 0, "4294967296"),
            5,
            0,
            "4294967296",
        ),
        Expect::Bad,
    );
    c
}

// -------------------------------------------------------------- CCP4/MRC

fn mrc_cases() -> Cases {
    let mut c = Cases::new("mrc");
    let f = "mode2_f32.mrc";
    let bytes = fixture(&format!("mrc/{f}"));
    let nsymbt = i32::from_le_bytes(bytes[92..96].try_into().unwrap()) as usize;
    c.truncations(f, &bytes, 1024 + nsymbt, Expect::Bad, Expect::Bad);
    let i32le = |v: i32| v.to_le_bytes().to_vec();
    let f32le = |v: f32| v.to_le_bytes().to_vec();
    for (what, offset, value) in [
        ("nx 2^31 - 1", 0, i32le(i32::MAX)),
        ("nx 0", 0, i32le(0)),
        ("ny -5", 4, i32le(-5)),
        (
            "nx, ny, nz 2^31 - 1",
            0,
            [i32le(i32::MAX), i32le(i32::MAX), i32le(i32::MAX)].concat(),
        ),
        ("nz 40 (data too short)", 8, i32le(40)),
        ("mode 99", 12, i32le(99)),
        ("mode 3 (complex i16)", 12, i32le(3)),
        ("mapc 4", 64, i32le(4)),
        ("mapc = mapr", 64, [i32le(2), i32le(2)].concat()),
        ("nsymbt 2^31 - 1", 92, i32le(i32::MAX)),
        ("nsymbt -1", 92, i32le(-1)),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            put(&bytes, offset, &value),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: MAP tag garbled"),
        f,
        put(&bytes, 208, b"XXXX"),
        Expect::Either,
    );
    // Non-finite cell lengths and origins are refused (a cell of 0 is read
    // as 1 angstrom voxels, with a note: mrc.rs).
    for (what, offset, value) in [
        ("cell a NaN", 40, f32::NAN),
        ("cell b infinite", 44, f32::INFINITY),
        ("origin x NaN", 196, f32::NAN),
        ("origin z -infinite", 204, f32::NEG_INFINITY),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            put(&bytes, offset, &f32le(value)),
            Expect::Bad,
        );
    }
    c.flips(f, &bytes, 1024, 4, 8);
    // A skewed map of part of a cell, its box resampled: cells that make
    // the box huge, flat or degenerate.
    let f = "part_triclinic.ccp4";
    let bytes = fixture(&format!("mrc/{f}"));
    c.truncations(f, &bytes, 1024, Expect::Bad, Expect::Bad);
    for (what, offset, value, expect) in [
        ("angle beta 179.9", 56, f32le(179.9), Expect::Either),
        (
            "angles 1 1 1 (a flat cell)",
            52,
            [f32le(1.0), f32le(1.0), f32le(1.0)].concat(),
            Expect::Either,
        ),
        (
            "angles 60 60 179 (no cell)",
            52,
            [f32le(60.0), f32le(60.0), f32le(179.0)].concat(),
            Expect::Either,
        ),
        ("cell a 1e30", 40, f32le(1e30), Expect::Either),
        ("cell c 1e-30", 48, f32le(1e-30), Expect::Either),
        ("mx 1", 28, i32le(1), Expect::Either),
        ("nz 1 (one section)", 8, i32le(1), Expect::Either),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            put(&bytes, offset, &value),
            expect,
        );
    }
    c.flips(f, &bytes, 1024, 4, 8);
    c
}

// ---------------------------------------------------------------- VASP

fn chgcar_cases() -> Cases {
    let mut c = Cases::new("chgcar");
    let f = "CHGCAR";
    let bytes = fixture("chgcar/CHGCAR_ortho");
    let text = std::str::from_utf8(&bytes).unwrap();
    // The grid line follows the positions and a blank line.
    let grid = text.lines().position(|l| l.trim().is_empty()).unwrap() + 1;
    let header_end = line_start(&bytes, grid + 1);
    c.truncations(f, &bytes, header_end, Expect::Bad, Expect::Either);
    for (what, line, token, value) in [
        ("scale NaN", 1, 0, "nan"),
        ("scale infinite", 1, 0, "inf"),
        ("scale 0", 1, 0, "0"),
        ("lattice row NaN", 2, 0, "nan"),
        ("lattice singular", 2, 0, "0"),
        ("atom count 2^31", 6, 0, "2147483648"),
        ("atom count -1", 6, 0, "-1"),
        ("grid x 2^31", grid, 0, "2147483648"),
        ("grid x 2^62", grid, 0, "4611686018427387904"),
        ("grid x 0", grid, 0, "0"),
        ("grid y -3", grid, 1, "-3"),
        ("grid z 50 (data too short)", grid, 2, "50"),
        ("first value not a number", grid + 1, 0, "abc"),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            set_token(&bytes, line, token, value),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: grid product overflow"),
        f,
        set_token(
            &set_token(
                &set_token(&bytes, grid, 0, "4294967296"),
                grid,
                1,
                "4294967296",
            ),
            grid,
            2,
            "4294967296",
        ),
        Expect::Bad,
    );
    c
}

// ---------------------------------------------------------------- HDF5

fn hdf5_cases() -> Cases {
    let mut c = Cases::new("hdf5");
    let f = "one.h5";
    let bytes = fixture(&format!("hdf5/{f}"));
    let input = format!("{f}:/fields/density");
    c.cut_and_unsigned(f, &input, &bytes);
    let n = bytes.len();
    // Bit flips through the metadata (superblock, object headers, heaps,
    // B-trees) of the pure-Rust reader: read or refused, never a crash.
    c.flips(f, &bytes, n / 2, 24, 5);
    // HDF5 2.0's chunk indexes (libver='latest'): /u8 under a version 2
    // B-tree and a layout message of version 5, which hdf5-pure cannot
    // read and hdf5-reader walks; cut short, and bit-flipped anywhere.
    let f = "latest.h5";
    let bytes = fixture(&format!("hdf5/{f}"));
    let input = format!("{f}:/u8");
    c.cut_and_unsigned(f, &input, &bytes);
    let mut rng = 43;
    for _ in 0..24 {
        let r = xorshift(&mut rng);
        let at = (r % bytes.len() as u64) as usize;
        let mut b = bytes.clone();
        b[at] ^= 1 << ((r >> 32) % 8);
        c.many(
            &format!("{input}: byte {at} flipped"),
            vec![(f.into(), b)],
            &input,
            Expect::Either,
        );
    }
    c
}

// ------------------------------------------------------------ 2-D images

/// Images, not volumes: `info` describes them (exit 0), `render` refuses
/// them (exit 1); damaged ones are refused by both.
fn flat_cases() -> Cases {
    let mut c = Cases::new("2-D");
    let f = "image.nrrd";
    let bytes = fixture(&format!("flat/{f}"));
    let end = after(&bytes, "\n\n");
    c.truncations(f, &bytes, end, Expect::Bad, Expect::Bad);
    c.edits(
        f,
        &bytes,
        &[
            ("sizes: 5 4", "sizes: 5 400000000", Expect::Bad),
            ("sizes: 5 4", "sizes: 5 0", Expect::Bad),
            ("(0.5,0) (0,0.25)", "(nan,0) (0,0.25)", Expect::Either),
            ("space dimension: 2", "space dimension: 7", Expect::Bad),
        ],
    );
    let f = "image.mha";
    let bytes = fixture(&format!("flat/{f}"));
    let end = after(&bytes, "ElementDataFile = LOCAL\n");
    c.truncations(f, &bytes, end, Expect::Bad, Expect::Bad);
    c.edits(
        f,
        &bytes,
        &[
            ("DimSize = 5 4", "DimSize = 5 4000000000", Expect::Bad),
            (
                "TransformMatrix = 1 0 0 1",
                "TransformMatrix = 1 0 0",
                Expect::Bad,
            ),
        ],
    );
    let f = "image.nii";
    let bytes = fixture(&format!("flat/{f}"));
    c.truncations(f, &bytes, 348, Expect::Bad, Expect::Bad);
    c
}

// ---------------------------------------------------------------- MINC2

fn minc_cases() -> Cases {
    let mut c = Cases::new("minc");
    for f in ["ramp_i16.mnc", "series_u8.mnc"] {
        let bytes = fixture(&format!("minc/{f}"));
        c.cut_and_unsigned(f, f, &bytes);
        let n = bytes.len();
        // Names the reader looks up, made unknown: a dimension nobody
        // declared, the image's dataset gone.
        c.one(
            &format!("{f}: an unknown dimension"),
            f,
            replace(&bytes, "yspace,xspace", "yspace,qspace"),
            Expect::Bad,
        );
        c.one(
            &format!("{f}: no image-max"),
            f,
            replace(&bytes, "image-max", "image-mox"),
            Expect::Either,
        );
        // Bytes flipped through the metadata: read or refused, never a crash.
        for k in 0..6 {
            let at = 96 + k * (n / 2 - 96) / 6;
            let mut flipped = bytes.clone();
            flipped[at] ^= 0xa5;
            flipped[at + 1] = 0xff;
            c.one(
                &format!("{f}: bytes {at}-{} flipped", at + 1),
                f,
                flipped,
                Expect::Either,
            );
        }
    }
    c.one(
        "old.mnc: MINC1 (netCDF)",
        "old.mnc",
        b"CDF\x01\0\0\0\0".to_vec(),
        Expect::Bad,
    );
    c
}

// ----------------------------------------------------------------- Zarr

/// `zarr.json` of a Zarr v3 uint16 array of `shape`, one chunk of
/// `chunk`, through `codecs`.
fn zarr_v3(
    shape: serde_json::Value,
    chunk: serde_json::Value,
    codecs: serde_json::Value,
) -> Vec<u8> {
    serde_json::json!({
        "zarr_format": 3,
        "node_type": "array",
        "shape": shape,
        "data_type": "uint16",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": chunk}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": 0,
        "codecs": codecs,
    })
    .to_string()
    .into_bytes()
}

/// Hand-written Zarr and OME-Zarr stores that lie (the reader's own tests,
/// `crates/io/tests/zarr_hostile.rs`, have many more): each a directory
/// `s.zarr` read by the command.
fn zarr_cases() -> Cases {
    use serde_json::json;
    let mut c = Cases::new("zarr");
    let bytes = || json!([{"name": "bytes", "configuration": {"endian": "little"}}]);
    let with = |codec: serde_json::Value| json!([{"name": "bytes", "configuration": {"endian": "little"}}, codec]);
    let small = |codecs| zarr_v3(json!([2, 3, 4]), json!([2, 3, 4]), codecs);
    let ramp: Vec<u8> = (0..24u16).flat_map(u16::to_le_bytes).collect();
    let mut case = |name: &str, files: Vec<(&str, Vec<u8>)>| {
        let files = files
            .into_iter()
            .map(|(f, b)| (format!("s.zarr/{f}"), b))
            .collect();
        c.many(name, files, "s.zarr", Expect::Bad);
    };
    case(
        "zarr.json cut short",
        vec![("zarr.json", small(bytes())[..40].to_vec())],
    );
    case("zarr.json a list", vec![("zarr.json", b"[]".to_vec())]);
    let huge = 1u64 << 40;
    case(
        "shape 2^40 cubed",
        vec![(
            "zarr.json",
            zarr_v3(json!([huge, huge, huge]), json!([huge, 1, 1]), bytes()),
        )],
    );
    case(
        "chunk shape 0",
        vec![(
            "zarr.json",
            zarr_v3(json!([2, 3, 4]), json!([2, 0, 4]), bytes()),
        )],
    );
    // A zstd frame declaring 2^40 bytes (one RLE block of 48).
    let mut zstd = vec![0x28, 0xb5, 0x2f, 0xfd, 0xe0];
    zstd.extend(huge.to_le_bytes());
    zstd.extend([0x83, 0x01, 0x00, 0x07]);
    case(
        "a zstd chunk declaring 2^40 bytes",
        vec![
            (
                "zarr.json",
                small(with(
                    json!({"name": "zstd", "configuration": {"level": 3, "checksum": false}}),
                )),
            ),
            ("c/0/0/0", zstd),
        ],
    );
    // A blosc header declaring 2 GiB.
    let mut blosc = vec![2, 1, 1, 2];
    blosc.extend(0x7fff_ff00u32.to_le_bytes());
    blosc.extend(0x1_0000u32.to_le_bytes());
    blosc.extend(32u32.to_le_bytes());
    blosc.resize(32, 0);
    let blosc_config = json!({"name": "blosc", "configuration": {
        "cname": "lz4", "clevel": 5, "shuffle": "shuffle", "typesize": 2, "blocksize": 0
    }});
    case(
        "a blosc chunk declaring 2 GiB",
        vec![
            ("zarr.json", small(with(blosc_config))),
            ("c/0/0/0", blosc.clone()),
        ],
    );
    let zarray = json!({
        "zarr_format": 2, "shape": [2, 3, 4], "chunks": [2, 3, 4], "dtype": "<u2",
        "compressor": {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1, "blocksize": 0},
        "fill_value": 0, "order": "C", "filters": null,
    });
    case(
        "a v2 blosc chunk declaring 2 GiB",
        vec![
            (".zarray", zarray.to_string().into_bytes()),
            ("0.0.0", blosc),
        ],
    );
    let gz = gzip(&ramp);
    case(
        "a gzip chunk cut short",
        vec![
            (
                "zarr.json",
                small(with(json!({"name": "gzip", "configuration": {"level": 5}}))),
            ),
            ("c/0/0/0", gz[..gz.len() - 6].to_vec()),
        ],
    );
    // A shard of 2 x 4 x 4 in subchunks of 2 x 2 x 2 (16 bytes each), its
    // index (offset, nbytes) at the end.
    let sharded = |inner: serde_json::Value| {
        zarr_v3(
            json!([2, 4, 4]),
            json!([2, 4, 4]),
            json!([{"name": "sharding_indexed", "configuration": {
                "chunk_shape": inner, "codecs": bytes(), "index_codecs": bytes(),
            }}]),
        )
    };
    let shard = |index: [u64; 8]| {
        let mut s: Vec<u8> = (0..32u16).flat_map(u16::to_le_bytes).collect();
        s.extend(index.iter().flat_map(|v| v.to_le_bytes()));
        s
    };
    for (what, index) in [
        ("past the end", [0, 16, 16, 16, 32, 16, 48, 1000]),
        ("overflowing", [0, 16, u64::MAX - 8, 16, 32, 16, 48, 16]),
        ("of 2^40 bytes", [0, huge, 16, 16, 32, 16, 48, 16]),
    ] {
        case(
            &format!("a shard index {what}"),
            vec![
                ("zarr.json", sharded(json!([2, 2, 2]))),
                ("c/0/0/0", shard(index)),
            ],
        );
    }
    case(
        "subchunks not dividing the shard",
        vec![
            ("zarr.json", sharded(json!([2, 3, 4]))),
            ("c/0/0/0", shard([0, 16, 16, 16, 32, 16, 48, 16])),
        ],
    );
    // OME-Zarr 0.5: one level "0".
    let ome = |datasets: serde_json::Value| {
        json!({
            "zarr_format": 3, "node_type": "group",
            "attributes": {"ome": {"version": "0.5", "multiscales": [{
                "axes": ["z", "y", "x"], "datasets": datasets,
            }]}},
        })
        .to_string()
        .into_bytes()
    };
    let level = |path: &str, scale: serde_json::Value| json!({"path": path, "coordinateTransformations": [{"type": "scale", "scale": scale}]});
    for (what, datasets) in [
        (
            "a level outside the store",
            json!([level("../..", json!([1, 1, 1]))]),
        ),
        (
            "a missing level",
            json!([level("0", json!([1, 1, 1])), level("1", json!([2, 2, 2]))]),
        ),
        ("a scale of 0", json!([level("0", json!([1, 0, 1]))])),
        ("no levels", json!([])),
    ] {
        case(
            &format!("OME-Zarr with {what}"),
            vec![
                ("zarr.json", ome(datasets)),
                ("0/zarr.json", small(bytes())),
                ("0/c/0/0/0", ramp.clone()),
            ],
        );
    }
    c
}

// -------------------------------------------------------------- running

/// What one run of a case did wrong, if anything.
fn run_case(case: &Case, root: &Path, index: usize, render: bool) -> Result<(), String> {
    let dir = root.join(format!("case{index:03}{}", if render { "r" } else { "" }));
    let out_dir = dir.join("out");
    fs::create_dir_all(&out_dir).unwrap();
    for (name, bytes) in &case.files {
        let path = dir.join(name);
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(path, bytes).unwrap();
    }
    let input = dir.join(&case.input).display().to_string();
    let output = out_dir.join("out.png");
    let mut args = vec![env!("CARGO_BIN_EXE_volray").to_string()];
    if render {
        args.extend([
            "render".into(),
            input.clone(),
            "--size".into(),
            "24".into(),
            "-o".into(),
        ]);
        args.push(output.display().to_string());
    } else {
        args.extend(["info".into(), input.clone()]);
    }
    args.extend(case.args.iter().cloned());
    let stdout = fs::File::create(dir.join("stdout")).unwrap();
    let stderr = fs::File::create(dir.join("stderr")).unwrap();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_LIMIT_KIB} && exec \"$@\""))
        .arg("sh")
        .args(&args)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .spawn()
        .expect("sh runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {TIME_LIMIT:?} (a hang)"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let err = fs::read_to_string(dir.join("stderr")).unwrap_or_default();
    let code = status.code();
    let ok_codes: &[i32] = match case.expect {
        Expect::Bad => &[1],
        Expect::Either => &[0, 1],
    };
    let problem = if err.contains("panicked") {
        Some("panicked".to_string())
    } else if !code.is_some_and(|c| ok_codes.contains(&c)) {
        Some(format!("exit {code:?} ({status}), expected {ok_codes:?}"))
    } else if code == Some(1) {
        let named = case.files.iter().any(|(name, _)| {
            let file = Path::new(name).file_name().unwrap().to_string_lossy();
            err.contains(&*file)
        }) || err.contains(&case.input);
        if err.lines().count() != 1 || !err.starts_with("volray: error: ") {
            Some("the error is not one line starting 'volray: error: '".to_string())
        } else if !named {
            Some("the error names no file of the case".to_string())
        } else {
            None
        }
    } else {
        None
    };
    let left: Vec<String> = fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| !(code == Some(0) && render && name == "out.png"))
        .collect();
    let problem = problem.or_else(|| {
        (!left.is_empty()).then(|| format!("left behind in the output directory: {left:?}"))
    });
    match problem {
        None => {
            let _ = fs::remove_dir_all(&dir);
            Ok(())
        }
        Some(p) => Err(format!("{p}; stderr: {}", err.trim_end())),
    }
}

#[test]
fn malformed_files_are_refused_cleanly_under_a_memory_limit() {
    let mut all: Vec<Case> = Vec::new();
    let groups = vec![
        npy_cases(),
        nrrd_cases(),
        metaimage_cases(),
        nifti_cases(),
        vtk_cases(),
        vti_cases(),
        dicom_cases(),
        dicomdir::cases(),
        tiff_cases(),
        cube_cases(),
        mrc_cases(),
        chgcar_cases(),
        hdf5_cases(),
        minc_cases(),
        flat_cases(),
        zarr_cases(),
    ];
    for g in groups.into_iter().chain(readers::all()) {
        all.extend(g.list);
    }
    // Each run: (case index, render?).
    let runs: Vec<(usize, bool)> = (0..all.len())
        .map(|i| (i, false))
        .chain((0..all.len()).filter(|&i| all[i].render).map(|i| (i, true)))
        .collect();
    let root = tempfile::tempdir().unwrap();
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..WORKERS {
            s.spawn(|| {
                loop {
                    let n = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(i, render)) = runs.get(n) else {
                        break;
                    };
                    let case = &all[i];
                    if let Err(why) = run_case(case, root.path(), i, render) {
                        let cmd = if render { "render" } else { "info" };
                        failures
                            .lock()
                            .unwrap()
                            .push(format!("[{}] {cmd} {}: {why}", case.format, case.name));
                    }
                }
            });
        }
    });

    let mut per_format: BTreeMap<&str, (usize, usize, usize)> = BTreeMap::new();
    for case in &all {
        let e = per_format.entry(case.format).or_default();
        match case.expect {
            Expect::Bad => e.0 += 1,
            Expect::Either => e.1 += 1,
        }
        e.2 += usize::from(case.render);
    }
    println!(
        "malformed files: {} cases, {} runs (ulimit -v {MEMORY_LIMIT_KIB} KiB)",
        all.len(),
        runs.len()
    );
    for (format, (bad, either, render)) in &per_format {
        println!(
            "  {format:<12} {bad:>3} must be refused, {either:>2} may be read; {render:>2} also rendered"
        );
    }
    let failures = failures.into_inner().unwrap();
    let bad_total: usize = per_format.values().map(|v| v.0).sum();
    assert!(bad_total >= 100, "only {bad_total} cases must be refused");
    assert!(
        failures.is_empty(),
        "{} of {} runs failed:\n{}",
        failures.len(),
        runs.len(),
        failures.join("\n")
    );
}

/// The harness itself: a valid file passes, and a case that should fail
/// but reads fine is caught (so the suite cannot pass by not looking).
#[test]
fn the_harness_tells_valid_files_from_refused_ones() {
    let root = tempfile::tempdir().unwrap();
    let valid = Case {
        format: "npy",
        name: "valid".into(),
        files: vec![("v.npy".into(), fixture("c_f4.npy"))],
        input: "v.npy".into(),
        expect: Expect::Either,
        render: true,
        args: Vec::new(),
    };
    assert_eq!(run_case(&valid, root.path(), 0, false), Ok(()));
    assert_eq!(run_case(&valid, root.path(), 1, true), Ok(()));
    let wrongly_bad = Case {
        expect: Expect::Bad,
        ..valid.clone()
    };
    let err = run_case(&wrongly_bad, root.path(), 2, false).unwrap_err();
    assert!(err.starts_with("exit Some(0)"), "{err}");
}
