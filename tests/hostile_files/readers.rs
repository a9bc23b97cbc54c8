//! The readers the first cases of `hostile_files.rs` left out (NetCDF-3,
//! MINC1, NetCDF-4, FITS, MGH/MGZ, DICOM in each compressed transfer
//! syntax, raw), and for every reader a header that lies about its size
//! without tripping the memory limit (issue 41).
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
const FILE_MUST_REFUSE: &[&str] = &["--max-memory", "1T"];
/// The flags of a lie about compressed data: the memory limit refuses it.
const LIMIT_MUST_REFUSE: &[&str] = &["--max-memory", "1G"];

/// Every case of this module.
pub(super) fn all() -> Vec<Cases> {
    vec![
        netcdf3_cases(),
        minc1_cases(),
        netcdf4_cases(),
        fits_cases(),
        mgh_cases(),
        dicom_codec_cases(),
        raw_cases(),
        zarr_size_cases(),
        lying_cases(),
    ]
}

fn be32(v: u32) -> [u8; 4] {
    v.to_be_bytes()
}

/// `bytes` with every `from` replaced by `to`; there must be one.
fn replace_all(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
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
fn h5_dims(dims: &[u64]) -> Vec<u8> {
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
    let n = bytes.len();
    for (what, at) in [
        ("empty", 0),
        ("cut at 100 bytes", 100),
        ("cut in the middle", n / 2),
        ("one byte short", n - 1),
    ] {
        c.one(
            &format!("{f}: {what}"),
            f,
            bytes[..at].to_vec(),
            Expect::Bad,
        );
    }
    c.one(
        &format!("{f}: wrong magic"),
        f,
        put(&bytes, 1, b"XDF"),
        Expect::Bad,
    );
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

// ------------------------------------------------------- DICOM, encoded

/// The first fragment of the encapsulated pixel data of `bytes` (after
/// the Basic Offset Table item): the offset of its item's length field.
fn first_fragment(bytes: &[u8]) -> usize {
    let pixel = find(bytes, &[0xe0, 0x7f, 0x10, 0x00]).expect("pixel data");
    let item = [0xfe, 0xff, 0x00, 0xe0];
    let table = pixel + find(&bytes[pixel..], &item).expect("offset table item");
    let table_len = u32::from_le_bytes(bytes[table + 4..table + 8].try_into().unwrap()) as usize;
    let fragment = table + 8 + table_len;
    assert_eq!(bytes[fragment..fragment + 4], item, "a fragment item");
    fragment + 4
}

fn dicom_codec_cases() -> Cases {
    let mut c = Cases::new("dicom-codecs");
    // One file of each encapsulated transfer syntax volray decodes.
    for (dir, f) in [
        ("jpeg_baseline", "jpe0.dcm"),
        ("jpeg_extended_8bit", "jpe0.dcm"),
        ("jpeg_lossless", "jpe0.dcm"),
        ("jpeg_sv1", "jpe0.dcm"),
        ("jpegls", "jpe0.dcm"),
        ("jpegls_near", "jpe0.dcm"),
        ("j2k_lossless", "j2k0.dcm"),
        ("j2k_lossy", "j2k0.dcm"),
        ("rle", "r0.dcm"),
    ] {
        let bytes = fixture(&format!("dicom/{dir}/{f}"));
        let name = |what: &str| format!("{dir}/{f}: {what}");
        let len_at = first_fragment(&bytes);
        let start = len_at + 4;
        let n = bytes.len();
        c.one(
            &name("cut in the pixel data"),
            f,
            bytes[..(start + n) / 2].to_vec(),
            Expect::Bad,
        );
        c.one(
            &name("cut after the fragment's item tag"),
            f,
            bytes[..start].to_vec(),
            Expect::Bad,
        );
        c.one(
            &name("fragment length 2^31 - 2"),
            f,
            put(&bytes, len_at, &0x7fff_fffeu32.to_le_bytes()),
            Expect::Bad,
        );
        c.one(
            &name("fragment length 2"),
            f,
            put(&bytes, len_at, &2u32.to_le_bytes()),
            Expect::Bad,
        );
        // The codestream's opening bytes garbled, then its middle: a
        // decoder error, or (lossy codes have no checksum) other pixels.
        c.one(
            &name("codestream start garbled"),
            f,
            put(&bytes, start, &[0x5a; 12]),
            Expect::Bad,
        );
        let mid = (start + n) / 2;
        c.one(
            &name("codestream middle garbled"),
            f,
            put(
                &bytes,
                mid,
                &[0xff, 0x00, 0xff, 0xd9, 0x13, 0x37, 0xff, 0xff],
            ),
            Expect::Either,
        );
        for k in 0..6 {
            let at = start + k * (n - start) / 6;
            let mut b = bytes.clone();
            b[at] ^= 0x5a;
            b[at + 1] = 0xff;
            c.one(
                &name(&format!("bytes {at}-{} flipped", at + 1)),
                f,
                b,
                Expect::Either,
            );
        }
        let stream = &bytes[start..];
        if dir.starts_with("jpeg") {
            // The first SOF's height (Y) made 65535 and 0.
            let sof = (0..stream.len() - 1)
                .find(|&i| stream[i] == 0xff && matches!(stream[i + 1], 0xc0..=0xc3 | 0xf7))
                .expect("a SOF marker");
            for y in [0xffffu16, 0] {
                c.one(
                    &name(&format!("frame header height {y}")),
                    f,
                    put(&bytes, start + sof + 5, &y.to_be_bytes()),
                    Expect::Bad,
                );
            }
            let sos = find(stream, &[0xff, 0xda]).expect("a SOS marker");
            // The report: a JPEG-LS scan header whose length puts
            // the scan data past the stream's end.
            c.one(
                &name("scan header length 65535"),
                f,
                put(&bytes, start + sos + 2, &[0xff, 0xff]),
                Expect::Bad,
            );
            c.one(
                &name("scan header length 0"),
                f,
                put(&bytes, start + sos + 2, &[0, 0]),
                Expect::Bad,
            );
        }
        if dir.starts_with("jpegls") {
            // An LSE segment (preset parameters) before the scan: MAXVAL
            // 65535, T1..T3 65535, RESET 65535.
            let sos = start + find(stream, &[0xff, 0xda]).expect("a SOS marker");
            // A fill byte first keeps the fragment's length even.
            let lse = [
                0xff, 0xff, 0xf8, 0, 13, 1, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff,
                0xff,
            ];
            let mut b = [&bytes[..sos], &lse[..], &bytes[sos..]].concat();
            // The fragment and the pixel data grew by the segment.
            let grow = |b: &mut Vec<u8>, at: usize| {
                let v = u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
                if v != u32::MAX {
                    b[at..at + 4].copy_from_slice(&(v + lse.len() as u32).to_le_bytes());
                }
            };
            grow(&mut b, len_at);
            c.one(&name("extreme LSE preset parameters"), f, b, Expect::Either);
        }
        if dir.starts_with("j2k") {
            // SIZ: Xsiz and Ysiz (bytes 8..16 after SOC) made 2^32 - 1.
            let siz = find(stream, &[0xff, 0x4f, 0xff, 0x51]).expect("SOC SIZ");
            c.one(
                &name("SIZ 2^32 - 1 square"),
                f,
                put(&bytes, start + siz + 8, &[0xff; 8]),
                Expect::Bad,
            );
            c.one(
                &name("SIZ 0 components"),
                f,
                put(&bytes, start + siz + 40, &[0, 0]),
                Expect::Bad,
            );
        }
        if dir == "rle" {
            // The RLE header: a segment count and 15 offsets (PS3.5 G.5).
            for (what, header) in [
                ("15 segments far past the end", {
                    let mut h = rle_count(15);
                    h.extend((0..15).flat_map(|_| 0x7fff_fff0u32.to_le_bytes()));
                    h
                }),
                ("offsets decreasing", {
                    let mut h = rle_count(2);
                    h.extend(64u32.to_le_bytes());
                    h.extend(32u32.to_le_bytes());
                    h.resize(64, 0);
                    h
                }),
                ("99 segments", rle_count(99)),
            ] {
                c.one(&name(what), f, put(&bytes, start, &header), Expect::Bad);
            }
        }
    }
    c
}

fn rle_count(n: u32) -> Vec<u8> {
    n.to_le_bytes().to_vec()
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

// ----------------------------------------------------------------- Zarr

/// Zarr stores declaring more than can be addressed: bad input (exit 1),
/// by `info` and by `render` (which reads a chunked store in pieces).
fn zarr_size_cases() -> Cases {
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
    let stores: Vec<(&str, Vec<(&str, Vec<u8>)>)> = vec![
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
fn lying_cases() -> Cases {
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
    c
}
