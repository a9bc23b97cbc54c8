//! The readers the first cases of `hostile_files.rs` left out (NetCDF-3,
//! MINC1, NetCDF-4, FITS, MGH/MGZ, raw; DICOM in each compressed transfer
//! syntax in `encoded_dicom.rs`), and for every reader a header that lies
//! about its size without tripping the memory limit (`lying.rs`; issue 41).
//!
//! A lie about an uncompressed volume runs with `--max-memory 1T`, so
//! that only the reader's check of the file's length stands between the
//! header and an allocation of gigabytes (which `ulimit -v` turns into an
//! abort); a lie about a compressed or chunked one runs with
//! `--max-memory 1G`, which the reader must check before it allocates.
//! Either way the volumes declared are of 4 GiB or more, above the
//! harness's memory limit, so a reader that allocates first aborts.

use super::*;

/// The flags of a lie about an uncompressed volume: only the file's
/// length may refuse it.
pub(super) const FILE_MUST_REFUSE: &[&str] = &["--max-memory", "1T"];
/// The flags of a lie about compressed data: the memory limit refuses it.
pub(super) const LIMIT_MUST_REFUSE: &[&str] = &["--max-memory", "1G"];

/// Every case of this module.
pub(super) fn all() -> Vec<Cases> {
    vec![
        netcdf3_cases(),
        minc1_cases(),
        netcdf4_cases(),
        fits_cases(),
        mgh_cases(),
        super::encoded_dicom::cases(),
        raw_cases(),
        super::lying::zarr_size_cases(),
        super::lying::cases(),
    ]
}

fn be32(v: u32) -> [u8; 4] {
    v.to_be_bytes()
}

/// `bytes` with every `from` replaced by `to`; there must be one.
pub(super) fn replace_all(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    assert!(find(bytes, from).is_some(), "{from:?} not in the fixture");
    let mut out = Vec::with_capacity(bytes.len());
    let mut at = 0;
    while at < bytes.len() {
        if bytes[at..].starts_with(from) {
            out.extend_from_slice(to);
            at += from.len();
        } else {
            out.push(bytes[at]);
            at += 1;
        }
    }
    out
}

/// Dimensions as an HDF5 dataspace message stores them: 8-byte
/// little-endian lengths.
pub(super) fn h5_dims(dims: &[u64]) -> Vec<u8> {
    dims.iter().flat_map(|d| d.to_le_bytes()).collect()
}

// ------------------------------------------------------------ NetCDF-3

/// The byte offset of each dimension's length in a NetCDF-3 header
/// (CDF-1 and CDF-2: 4-byte counts; CDF-5: 8-byte), by name.
fn nc3_dim_lengths(bytes: &[u8]) -> Vec<(String, usize)> {
    let w = if bytes[3] == 5 { 8 } else { 4 };
    let read = |at: usize| {
        bytes[at..at + w]
            .iter()
            .fold(0usize, |v, &b| (v << 8) | usize::from(b))
    };
    // Magic, numrecs, then NC_DIMENSION and the count.
    let mut at = 4 + w + 4;
    let n = read(at);
    at += w;
    let mut out = Vec::new();
    for _ in 0..n {
        let len = read(at);
        at += w;
        let name = String::from_utf8_lossy(&bytes[at..at + len]).into_owned();
        at += len.div_ceil(4) * 4;
        out.push((name, at));
        at += w;
    }
    out
}

/// `bytes` with the NetCDF-3 dimension `name`'s length set to `len`.
fn nc3_with_dim(bytes: &[u8], name: &str, len: u64) -> Vec<u8> {
    let (_, at) = nc3_dim_lengths(bytes)
        .into_iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no dimension {name}"));
    if bytes[3] == 5 {
        put(bytes, at, &len.to_be_bytes())
    } else {
        put(bytes, at, &be32(len as u32))
    }
}

fn netcdf3_cases() -> Cases {
    let mut c = Cases::new("netcdf-3");
    // uneven.nc: dimensions z, y, x = 3, 4, 5; a coordinate variable x
    // (begin 148), then w(z, y, x) float (begin 168).
    let f = "uneven.nc";
    let bytes = fixture(&format!("netcdf/{f}"));
    assert_eq!(
        nc3_dim_lengths(&bytes),
        [
            ("z".to_string(), 24),
            ("y".to_string(), 36),
            ("x".to_string(), 48)
        ]
    );
    c.truncations(f, &bytes, 148, Expect::Bad, Expect::Bad);
    // The report: a small header declaring a volume of gigabytes
    // was allocated before its extent was checked against the file. The
    // coordinate variable x (unevenly spaced, the fixture's point) renamed
    // q, so that nothing else refuses the file first.
    let name_x = b"\0\0\0\x01x\0\0\0";
    let var_x = 4 + 44 + find(&bytes[44..], name_x).expect("variable x");
    let plain = put(&bytes, var_x, b"q");
    let lie = nc3_with_dim(&nc3_with_dim(&plain, "z", 1 << 20), "y", 1024);
    c.one(
        &format!("{f}: z 2^20, y 1024 (20 GiB)"),
        f,
        lie,
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: z 2^31"),
        f,
        nc3_with_dim(&bytes, "z", 1 << 31),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: 2^31 - 1 dimensions"),
        f,
        put(&bytes, 12, &be32(0x7fff_ffff)),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: w begins at 2^31 - 1"),
        f,
        put(&bytes, 144, &be32(0x7fff_ffff)),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: w begins inside the header"),
        f,
        put(&bytes, 144, &be32(16)),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: version 9"),
        f,
        put(&bytes, 3, &[9]),
        Expect::Bad,
    );
    c.flips(f, &bytes, 148, 6, 11);

    // classic.nc: a record (time) dimension: numrecs lying.
    let f = "classic.nc";
    let bytes = fixture(&format!("netcdf/{f}"));
    c.one(
        &format!("{f}: numrecs 2^31 - 1"),
        f,
        put(&bytes, 4, &be32(0x7fff_ffff)),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: x 2^20"),
        f,
        nc3_with_dim(&bytes, "x", 1 << 20),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: cut in the middle"),
        f,
        bytes[..bytes.len() / 2].to_vec(),
        Expect::Bad,
    );
    // data64.nc: CDF-5, 8-byte lengths.
    let f = "data64.nc";
    let bytes = fixture(&format!("netcdf/{f}"));
    c.one(
        &format!("{f}: z 2^40"),
        f,
        nc3_with_dim(&bytes, "z", 1 << 40),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: x 2^62"),
        f,
        nc3_with_dim(&bytes, "x", 1 << 62),
        Expect::Bad,
    );
    c
}

// ---------------------------------------------------------------- MINC1

fn minc1_cases() -> Cases {
    let mut c = Cases::new("minc1");
    // ramp_minc1.mnc: image(zspace, yspace, xspace) short, 3 x 4 x 5 at
    // byte 2020; image-min and image-max over zspace after it.
    let f = "ramp_minc1.mnc";
    let bytes = fixture(&format!("minc/{f}"));
    c.truncations(f, &bytes, 1992, Expect::Bad, Expect::Bad);
    // The report: 1024^3 (4 GiB as f32) in a 2 KiB file. Without
    // image-max the scaling variables (read, and checked, first) are not
    // in the way.
    let mut lie = replace_all(&bytes, b"image-max", b"image-mox");
    for d in ["zspace", "yspace", "xspace"] {
        lie = nc3_with_dim(&lie, d, 1024);
    }
    c.one(&format!("{f}: 1024^3, no image-max"), f, lie, Expect::Bad);
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: zspace 2^31"),
        f,
        nc3_with_dim(&bytes, "zspace", 1 << 31),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: no variable image"),
        f,
        replace_all(&bytes, b"\0\0\0\x05image\0\0\0", b"\0\0\0\x05imagf\0\0\0"),
        Expect::Bad,
    );
    c.flips(f, &bytes, 1992, 6, 12);
    // series_minc1.mnc: time, zspace, yspace, xspace = 2, 3, 4, 5.
    let f = "series_minc1.mnc";
    let bytes = fixture(&format!("minc/{f}"));
    c.one(
        &format!("{f}: 2^30 frames"),
        f,
        nc3_with_dim(&bytes, "time", 1 << 30),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: one byte short"),
        f,
        bytes[..bytes.len() - 1].to_vec(),
        Expect::Bad,
    );
    c
}

// ------------------------------------------------------------ NetCDF-4

fn netcdf4_cases() -> Cases {
    let mut c = Cases::new("netcdf-4");
    // cf_tzyx.nc: rho(time, z, y, x) = (2, 3, 4, 5) float32, zlib, chunked.
    let f = "cf_tzyx.nc";
    let bytes = fixture(&format!("netcdf4/{f}"));
    c.cut_and_unsigned(f, f, &bytes);
    let n = bytes.len();
    // Every (z, y, x) = (3, 4, 5) dataspace made 1024^3: 8 GiB of
    // compressed chunks the file does not hold.
    c.one(
        &format!("{f}: z, y, x 1024^3"),
        f,
        replace_all(&bytes, &h5_dims(&[3, 4, 5]), &h5_dims(&[1024, 1024, 1024])),
        Expect::Bad,
    );
    c.with_args(LIMIT_MUST_REFUSE);
    c.flips(f, &bytes, n / 2, 8, 13);
    c
}

// ----------------------------------------------------------------- FITS

/// A FITS header card's value field: `key` padded to 8, `= `, the value
/// right-justified to column 30.
fn fits_card(key: &str, value: &str) -> String {
    format!("{key:<8}= {value:>20}")
}

fn fits_cases() -> Cases {
    let mut c = Cases::new("fits");
    // f32.fits: BITPIX -32, NAXIS 3, 8 x 6 x 5, one 2880-byte header
    // block, the data's 960 bytes padded to a block: a cut in the padding
    // may be read.
    let f = "f32.fits";
    let bytes = fixture(&format!("fits/{f}"));
    c.truncations(f, &bytes, 2880, Expect::Either, Expect::Either);
    c.one(
        &format!("{f}: cut in the data (3000 bytes)"),
        f,
        bytes[..3000].to_vec(),
        Expect::Bad,
    );
    let naxis = |k: usize, v: &str| {
        let key = format!("NAXIS{k}");
        let was = ["8", "6", "5"][k - 1];
        (fits_card(&key, was), fits_card(&key, v))
    };
    let mut lie = bytes.clone();
    for k in 1..=3 {
        let (from, to) = naxis(k, "1024");
        lie = replace(&lie, &from, &to);
    }
    c.one(&format!("{f}: NAXISn 1024^3"), f, lie, Expect::Bad);
    c.with_args(FILE_MUST_REFUSE);
    let edits: Vec<(String, String, Expect)> = vec![
        {
            let (a, b) = naxis(1, "4294967296");
            (a, b, Expect::Bad)
        },
        {
            let (a, b) = naxis(2, "0");
            (a, b, Expect::Bad)
        },
        {
            let (a, b) = naxis(3, "-5");
            (a, b, Expect::Bad)
        },
        (
            fits_card("BITPIX", "-32"),
            fits_card("BITPIX", "12"),
            Expect::Bad,
        ),
        (
            fits_card("NAXIS", "3"),
            fits_card("NAXIS", "999"),
            Expect::Bad,
        ),
        ("SIMPLE  =".into(), "SIMPLX  =".into(), Expect::Bad),
    ];
    c.edits(f, &bytes, &edits);
    c.one(
        &format!("{f}: no END card"),
        f,
        replace(&bytes, "END     ", "ENX     "),
        Expect::Bad,
    );
    c.flips(f, &bytes, 2880, 4, 14);

    // compressed.fits: a tile-compressed (RICE_1) image in a binary table.
    let f = "compressed.fits";
    let bytes = fixture(&format!("fits/{f}"));
    let mut lie = bytes.clone();
    for (k, was) in [(1, "8"), (2, "6"), (3, "5")] {
        let key = format!("ZNAXIS{k}");
        lie = replace(&lie, &fits_card(&key, was), &fits_card(&key, "1024"));
    }
    c.one(&format!("{f}: ZNAXISn 1024^3"), f, lie, Expect::Bad);
    c.with_args(LIMIT_MUST_REFUSE);
    let key = "ZNAXIS3";
    c.one(
        &format!("{f}: ZNAXIS3 2^40"),
        f,
        replace(
            &bytes,
            &fits_card(key, "5"),
            &fits_card(key, "1099511627776"),
        ),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: heap cut"),
        f,
        bytes[..bytes.len() - 2880].to_vec(),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: NAXIS2 (rows) 2^31"),
        f,
        replace(
            &bytes,
            &fits_card("NAXIS2", "30"),
            &fits_card("NAXIS2", "2147483648"),
        ),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    let n = bytes.len();
    c.flips(f, &bytes, n, 6, 15);

    // i16.fits.gz: the whole file gzipped.
    let f = "i16.fits.gz";
    let gz = fixture(&format!("fits/{f}"));
    let plain = gunzip(&gz);
    let mut lie = plain.clone();
    for (k, was) in [(1, "8"), (2, "6"), (3, "5")] {
        let key = format!("NAXIS{k}");
        lie = replace(&lie, &fits_card(&key, was), &fits_card(&key, "1024"));
    }
    c.one(&format!("{f}: NAXISn 1024^3"), f, gzip(&lie), Expect::Bad);
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: cut in the middle"),
        f,
        gz[..gz.len() / 2].to_vec(),
        Expect::Bad,
    );
    c
}

// -------------------------------------------------------------- MGH/MGZ

fn mgh_cases() -> Cases {
    let mut c = Cases::new("mgh");
    // f32.mgh: version 1, width 12, height 10, depth 8, 2 frames, type 3
    // (float), each a big-endian int at 0, 4, 8, 12, 16, 20; 284-byte
    // header; optional tags (which may be cut) after the data.
    let f = "f32.mgh";
    let bytes = fixture(&format!("mgh/{f}"));
    assert_eq!(
        &bytes[..24],
        [[0, 0, 0, 1], be32(12), be32(10), be32(8), be32(2), be32(3)].concat()
    );
    c.truncations(f, &bytes, 284, Expect::Bad, Expect::Either);
    let dims = |w: u32, h: u32, d: u32| put(&bytes, 4, &[be32(w), be32(h), be32(d)].concat());
    c.one(
        &format!("{f}: 1024^3"),
        f,
        dims(1024, 1024, 1024),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    for (what, b) in [
        ("width 0", dims(0, 10, 8)),
        ("width -1", dims(u32::MAX, 10, 8)),
        (
            "2^31 - 1 cubed",
            dims(0x7fff_ffff, 0x7fff_ffff, 0x7fff_ffff),
        ),
        ("2^31 - 1 frames", put(&bytes, 16, &be32(0x7fff_ffff))),
        ("type 99", put(&bytes, 20, &be32(99))),
        ("version 9", put(&bytes, 0, &be32(9))),
    ] {
        c.one(&format!("{f}: {what}"), f, b, Expect::Bad);
        c.with_args(FILE_MUST_REFUSE);
    }
    c.flips(f, &bytes, 284, 4, 16);

    // f32.mgz: the same, gzipped: the lie must meet the memory limit
    // before anything of its size is allocated.
    let f = "f32.mgz";
    let gz = fixture(&format!("mgh/{f}"));
    let plain = gunzip(&gz);
    let lie = put(&plain, 4, &[be32(1024), be32(1024), be32(1024)].concat());
    c.one(&format!("{f}: 1024^3"), f, gzip(&lie), Expect::Bad);
    c.with_args(LIMIT_MUST_REFUSE);
    c.one(
        &format!("{f}: 1024^3 under --max-memory 1T"),
        f,
        gzip(&lie),
        Expect::Bad,
    );
    c.with_args(FILE_MUST_REFUSE);
    c.one(
        &format!("{f}: cut in the middle"),
        f,
        gz[..gz.len() / 2].to_vec(),
        Expect::Bad,
    );
    c.one(
        &format!("{f}: one byte short"),
        f,
        gz[..gz.len() - 1].to_vec(),
        Expect::Either,
    );
    c
}

// ------------------------------------------------------------------ raw

fn raw_cases() -> Cases {
    let mut c = Cases::new("raw");
    let data: Vec<u8> = (0..240u32).map(|v| v as u8).collect();
    let raw = |c: &mut Cases, what: &str, bytes: Vec<u8>, args: &[&str], expect: Expect| {
        c.one(&format!("v.raw: {what}"), "v.raw", bytes, expect);
        c.with_args(args);
    };
    raw(
        &mut c,
        "--dims 1024^3 of a 240-byte file",
        data.clone(),
        &[
            "--dims",
            "1024,1024,1024",
            "--dtype",
            "f32",
            "--max-memory",
            "1T",
        ],
        Expect::Bad,
    );
    raw(
        &mut c,
        "--dims 2^21 cubed",
        data.clone(),
        &[
            "--dims",
            "2097152,2097152,2097152",
            "--dtype",
            "u8",
            "--max-memory",
            "1T",
        ],
        Expect::Bad,
    );
    raw(
        &mut c,
        "--dims 4,6,10 of 239 bytes",
        data[..239].to_vec(),
        &["--dims", "4,6,10", "--dtype", "u8"],
        Expect::Bad,
    );
    raw(
        &mut c,
        "--dims 4,6,10, empty",
        Vec::new(),
        &["--dims", "4,6,10", "--dtype", "u8"],
        Expect::Bad,
    );
    raw(
        &mut c,
        "--dims 4,6,10 read",
        data,
        &["--dims", "4,6,10", "--dtype", "u8"],
        Expect::Either,
    );
    c
}
