//! DICOM files in each encapsulated transfer syntax volray decodes (JPEG
//! baseline, extended, lossless, SV1; JPEG-LS lossless and near-lossless;
//! JPEG 2000 lossless and lossy; RLE), cut, garbled and lying in their
//! fragments and codestream headers (issue 41: a JPEG-LS scan header's
//! length panicked; an RLE header made dicom-pixeldata allocate 6 GB).

use super::*;

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

pub(super) fn cases() -> Cases {
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
