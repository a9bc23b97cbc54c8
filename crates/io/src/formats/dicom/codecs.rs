//! Encapsulated pixel data in JPEG (baseline, extended 8-bit, lossless
//! process 14 and SV1), JPEG-LS (lossless and near-lossless) and JPEG 2000
//! (lossless and lossy), decoded frame by frame.
//!
//! The frames are split out of the fragments here (PS3.5 A.4, [`split`]),
//! each frame's codestream header is read ([`jpeg_header`] for JPEG and
//! JPEG-LS, [`j2k_header`]) and checked against the image header (Rows, Columns,
//! one sample, at most BitsAllocated bits) before the decoder runs, and
//! the decoded samples go into a buffer sized from the image header, which
//! the caller has checked against `--max-memory` before allocating it.
//!
//! The JPEG and JPEG 2000 decoders are the crates `dicom-pixeldata`'s own
//! adapters use — `jpeg-decoder` (pure Rust) and `jpeg2k` on `openjp2` (a
//! pure-Rust port of OpenJPEG) — called directly rather than through the
//! adapters, which
//! cannot split a frame spread over several fragments without a Basic
//! Offset Table, and index out of bounds (a panic) when a stream decodes
//! to more samples than the header declares. Both decoders can still panic
//! on some corrupt streams (jpeg-decoder's `info` on an unexpected
//! component count, arithmetic in openjp2's tier-1 decoder): each call is
//! run through [`panics::guarded`] (the panic caught, its message kept off
//! standard error), so a corrupt codestream is a one-line error naming
//! the file and frame, never a crash or a backtrace. volray's own JPEG-LS
//! decoder is caught too, but not kept quiet: a panic there is a bug.
//!
//! JPEG-LS is decoded by volray's own [`jpegls`] (dicom-pixeldata's adapter
//! needs the C++ CharLS, built with CMake).
//!
//! 12-bit DCT JPEG (JPEG Extended, process 4: `jpeg-decoder` reads 8-bit
//! DCT only) is decoded by volray's own [`jpeg12`]; 12-bit progressive or
//! hierarchical DCT (processes 6 to 12, never seen in DICOM files) are
//! refused by name.

use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::shared::panics;

use super::header::ImageFormat;
use super::{jpeg12, jpegls};

/// The codec family of a transfer syntax decoded here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Codec {
    /// ISO 10918-1: baseline, extended, lossless (PS3.5 A.4.1).
    Jpeg,
    /// ISO 14495-1 (PS3.5 A.4.3).
    JpegLs,
    /// ISO 15444-1 (PS3.5 A.4.4).
    Jpeg2000,
}

impl Codec {
    /// The codec of transfer syntax `uid`, if it is one of these.
    pub fn of(uid: &str) -> Option<Codec> {
        match uid {
            "1.2.840.10008.1.2.4.50"
            | "1.2.840.10008.1.2.4.51"
            | "1.2.840.10008.1.2.4.57"
            | "1.2.840.10008.1.2.4.70" => Some(Codec::Jpeg),
            "1.2.840.10008.1.2.4.80" | "1.2.840.10008.1.2.4.81" => Some(Codec::JpegLs),
            "1.2.840.10008.1.2.4.90" | "1.2.840.10008.1.2.4.91" => Some(Codec::Jpeg2000),
            _ => None,
        }
    }

    /// Whether `fragment` begins a codestream of this codec: the JPEG SOI
    /// marker (JPEG-LS too), or a JPEG 2000 codestream's SOC and SIZ
    /// markers or a JP2 file's signature box.
    fn starts(self, fragment: &[u8]) -> bool {
        match self {
            Codec::Jpeg | Codec::JpegLs => fragment.starts_with(&[0xFF, 0xD8]),
            Codec::Jpeg2000 => {
                fragment.starts_with(&[0xFF, 0x4F, 0xFF, 0x51])
                    || fragment.starts_with(&[0, 0, 0, 12, b'j', b'P', b' ', b' '])
            }
        }
    }
}

/// Splits `fragments` into `frames` frames (PS3.5 A.4): by the Basic
/// Offset Table `offsets` where it is filled (each offset the distance
/// from the first fragment's item tag to the frame's first fragment's);
/// one fragment per frame where there are as many; else a frame starts at
/// each fragment that begins a codestream. A single frame is all
/// fragments.
pub(super) fn split<'a>(
    codec: Codec,
    offsets: &[u32],
    fragments: &'a [Vec<u8>],
    frames: usize,
) -> Result<Vec<Vec<&'a [u8]>>, String> {
    if fragments.is_empty() {
        return Err("the encapsulated pixel data holds no fragment".into());
    }
    if frames == 1 {
        return Ok(vec![fragments.iter().map(Vec::as_slice).collect()]);
    }
    if !offsets.is_empty() {
        if offsets.len() != frames {
            return Err(format!(
                "the Basic Offset Table lists {} frame(s), but NumberOfFrames is {frames}",
                offsets.len()
            ));
        }
        let mut out: Vec<Vec<&[u8]>> = Vec::with_capacity(frames);
        let mut at = 0u64;
        for fragment in fragments {
            let starts = offsets.iter().position(|&o| u64::from(o) == at);
            match starts {
                Some(f) if f == out.len() => out.push(vec![fragment]),
                Some(f) => {
                    return Err(format!(
                        "the Basic Offset Table is out of order: frame {f} starts at byte {at}, but frame {} comes first",
                        out.len()
                    ));
                }
                None if out.is_empty() => {
                    return Err(format!(
                        "the Basic Offset Table's first offset is {}, not 0",
                        offsets[0]
                    ));
                }
                None => out.last_mut().expect("a frame").push(fragment),
            }
            at += 8 + fragment.len() as u64;
        }
        if out.len() != frames {
            return Err(format!(
                "the Basic Offset Table's offset {} is not where a fragment starts",
                offsets[out.len()]
            ));
        }
        return Ok(out);
    }
    if fragments.len() == frames {
        return Ok(fragments.iter().map(|f| vec![f.as_slice()]).collect());
    }
    if fragments.len() < frames {
        return Err(format!(
            "{} fragment(s) cannot hold {frames} frames",
            fragments.len()
        ));
    }
    let mut out: Vec<Vec<&[u8]>> = Vec::with_capacity(frames);
    for fragment in fragments {
        match out.last_mut() {
            Some(frame) if !codec.starts(fragment) => frame.push(fragment),
            _ => out.push(vec![fragment]),
        }
    }
    if out.len() != frames {
        return Err(format!(
            "{} fragment(s) without a Basic Offset Table begin {} codestream(s), but NumberOfFrames is {frames}",
            fragments.len(),
            out.len()
        ));
    }
    Ok(out)
}

/// What a codestream's header declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct StreamHeader {
    pub width: usize,
    pub height: usize,
    pub components: usize,
    /// Bits per sample.
    pub precision: u8,
    /// The JPEG start-of-frame marker's low byte (0xC0 baseline, 0xC1
    /// extended, 0xC3 lossless, ...; 0xF7 JPEG-LS); 0 for JPEG 2000.
    pub process: u8,
}

/// The first start-of-frame segment of a JPEG (or JPEG-LS) stream
/// (ISO 10918-1 B.2.2: SOFn = Lf, P, Y, X, Nf; ISO 14495-1 C.2.2 the same
/// for SOF55), skipping the segments before it by their lengths.
pub(super) fn jpeg_header(stream: &[u8]) -> Result<StreamHeader, String> {
    if !stream.starts_with(&[0xFF, 0xD8]) {
        return Err("the frame does not start with a JPEG SOI marker (FFD8)".into());
    }
    let mut at = 2;
    loop {
        // Markers may be preceded by fill bytes 0xFF (B.1.1.2).
        while stream.get(at) == Some(&0xFF) && stream.get(at + 1) == Some(&0xFF) {
            at += 1;
        }
        let (Some(&0xFF), Some(&marker)) = (stream.get(at), stream.get(at + 1)) else {
            return Err(format!(
                "no JPEG frame header (SOF marker) before byte {at}"
            ));
        };
        let len = match stream.get(at + 2..at + 4) {
            Some(b) => usize::from(u16::from_be_bytes([b[0], b[1]])),
            None => return Err("the JPEG stream ends inside a marker segment".into()),
        };
        let is_sof = matches!(marker, 0xC0..=0xC3 | 0xC5..=0xC7 | 0xC9..=0xCB | 0xCD..=0xCF | 0xF7);
        if is_sof {
            let Some(s) = stream.get(at + 4..at + 10) else {
                return Err("the JPEG stream ends inside its frame header".into());
            };
            return Ok(StreamHeader {
                precision: s[0],
                height: usize::from(u16::from_be_bytes([s[1], s[2]])),
                width: usize::from(u16::from_be_bytes([s[3], s[4]])),
                components: usize::from(s[5]),
                process: marker,
            });
        }
        if marker == 0xDA || marker == 0xD9 || len < 2 {
            return Err(format!(
                "no JPEG frame header (SOF marker) before marker FF{marker:02X} at byte {at}"
            ));
        }
        at += 2 + len;
    }
}

/// A JPEG 2000 codestream's image and tile size (ISO 15444-1 A.5.1: SOC,
/// then SIZ = Lsiz, Rsiz, Xsiz, Ysiz, XOsiz, YOsiz, XTsiz, YTsiz, XTOsiz,
/// YTOsiz, Csiz, and Ssiz per component: sign bit and precision − 1). In a
/// JP2 file the codestream is found after its first SOC+SIZ markers.
pub(super) fn j2k_header(stream: &[u8]) -> Result<StreamHeader, String> {
    const SOC_SIZ: [u8; 4] = [0xFF, 0x4F, 0xFF, 0x51];
    let start = stream
        .windows(4)
        .position(|w| w == SOC_SIZ)
        .ok_or("no JPEG 2000 codestream (SOC and SIZ markers FF4F FF51) in the frame")?;
    let siz = &stream[start + 4..];
    let u32_at = |i: usize| {
        siz.get(i..i + 4)
            .map(|b| u64::from(u32::from_be_bytes([b[0], b[1], b[2], b[3]])))
    };
    let (Some(x), Some(y), Some(x0), Some(y0), Some(components), Some(ssiz)) = (
        u32_at(4),
        u32_at(8),
        u32_at(12),
        u32_at(16),
        siz.get(36..38)
            .map(|b| usize::from(u16::from_be_bytes([b[0], b[1]]))),
        siz.get(38),
    ) else {
        return Err("the JPEG 2000 codestream ends inside its SIZ marker segment".into());
    };
    if x0 > x || y0 > y {
        return Err(format!(
            "the JPEG 2000 image offset ({x0}, {y0}) lies beyond its size ({x}, {y})"
        ));
    }
    Ok(StreamHeader {
        width: (x - x0) as usize,
        height: (y - y0) as usize,
        components,
        precision: (ssiz & 0x7F) + 1,
        process: 0,
    })
}

/// Checks that `h`, frame `frame`'s codestream header, declares the image
/// `format` does: Columns × Rows, one component, at most BitsAllocated bits.
pub(super) fn check_header(
    h: &StreamHeader,
    format: &ImageFormat,
    frame: usize,
    codec: &str,
) -> Result<(), String> {
    if (h.width, h.height, h.components) != (format.columns, format.rows, 1) {
        return Err(format!(
            "the {codec} stream of frame {frame} is {}x{} with {} component(s), but the header declares Columns {} x Rows {} with SamplesPerPixel 1",
            h.width, h.height, h.components, format.columns, format.rows
        ));
    }
    if h.precision == 0 || u16::from(h.precision) > format.bits_allocated {
        return Err(format!(
            "the {codec} stream of frame {frame} holds {}-bit samples, but BitsAllocated is {}",
            h.precision, format.bits_allocated
        ));
    }
    Ok(())
}

/// Decodes `frames` (each a list of fragments) into `out`: one sample of
/// BitsAllocated bits per pixel, native byte order, frame after frame.
/// `out` must be empty with room for every frame (the caller sized it from
/// the header).
pub(super) fn decode_frames(
    codec: Codec,
    frames: &[Vec<&[u8]>],
    format: &ImageFormat,
    out: &mut Vec<u8>,
) -> Result<(), String> {
    let pixels = format.rows * format.columns;
    for (f, fragments) in frames.iter().enumerate() {
        let stream = fragments.concat();
        let start = out.len();
        match codec {
            Codec::Jpeg => {
                let h = jpeg_header(&stream).map_err(|e| format!("frame {f}: {e}"))?;
                check_header(&h, format, f, "JPEG")?;
                let samples = if (h.precision, h.process) == (12, 0xC1) {
                    // Extended sequential DCT at 12 bits: volray's own decoder.
                    guarded(f, "JPEG", false, || {
                        jpeg12::decode(&stream, pixels).map(Samples::U16)
                    })?
                } else if h.precision <= 8 || matches!(h.process, 0xC3 | 0xC7) {
                    guarded(f, "JPEG", true, || jpeg(&stream, pixels))?
                } else {
                    return Err(format!(
                        "frame {f} is {}-bit DCT JPEG (SOF{} marker FF{:02X}), which volray does not decode: 8-bit DCT, 12-bit extended sequential DCT (SOF1) and lossless JPEG are decoded",
                        h.precision,
                        h.process - 0xC0,
                        h.process
                    ));
                };
                push(samples, format, out);
            }
            Codec::Jpeg2000 => {
                let h = j2k_header(&stream).map_err(|e| format!("frame {f}: {e}"))?;
                check_header(&h, format, f, "JPEG 2000")?;
                let samples = guarded(f, "JPEG 2000", true, || j2k(&stream, format))?;
                push(samples, format, out);
            }
            Codec::JpegLs => {
                let h = jpeg_header(&stream).map_err(|e| format!("frame {f}: {e}"))?;
                check_header(&h, format, f, "JPEG-LS")?;
                if h.process != 0xF7 {
                    return Err(format!(
                        "frame {f} holds a JPEG (SOF marker FF{:02X}), not a JPEG-LS stream (SOF55, FFF7)",
                        h.process
                    ));
                }
                let samples = guarded(f, "JPEG-LS", false, || {
                    jpegls::decode(&stream, pixels).map(Samples::U16)
                })?;
                push(samples, format, out);
            }
        }
        if out.len() - start != pixels * format.sample_bytes() {
            return Err(format!(
                "frame {f} decoded to {} samples, but Columns {} x Rows {} need {pixels}",
                (out.len() - start) / format.sample_bytes(),
                format.columns,
                format.rows
            ));
        }
    }
    Ok(())
}

/// Decoded samples of one frame, one per pixel.
enum Samples {
    U8(Vec<u8>),
    U16(Vec<u16>),
    I32(Vec<i32>),
}

/// Runs a decoder, turning a panic inside it into an error: third-party
/// decoders may panic on corrupt input, and run `quiet` (nothing printed).
fn guarded(
    frame: usize,
    codec: &str,
    quiet: bool,
    decode: impl FnOnce() -> Result<Samples, String>,
) -> Result<Samples, String> {
    let result = if quiet {
        panics::guarded(decode).ok()
    } else {
        catch_unwind(AssertUnwindSafe(decode)).ok()
    };
    match result {
        Some(Ok(s)) => Ok(s),
        Some(Err(e)) => Err(format!(
            "the {codec} stream of frame {frame} is corrupt: {e}"
        )),
        None => Err(format!(
            "the {codec} decoder failed on frame {frame} (a corrupt stream)"
        )),
    }
}

/// Appends `samples` to `out` as BitsAllocated-wide native-endian values
/// (bit patterns: signed values are two's complement, which the caller
/// masks to BitsStored and sign-extends). The header check bounds every
/// value to BitsAllocated bits.
fn push(samples: Samples, format: &ImageFormat, out: &mut Vec<u8>) {
    match (samples, format.sample_bytes()) {
        (Samples::U8(v), 1) => out.extend_from_slice(&v),
        (Samples::U8(v), 2) => out.extend(v.iter().flat_map(|&s| u16::from(s).to_ne_bytes())),
        (Samples::U8(v), _) => out.extend(v.iter().flat_map(|&s| u32::from(s).to_ne_bytes())),
        (Samples::U16(v), 1) => out.extend(v.iter().map(|&s| s as u8)),
        (Samples::U16(v), 2) => out.extend(v.iter().flat_map(|&s| s.to_ne_bytes())),
        (Samples::U16(v), _) => out.extend(v.iter().flat_map(|&s| u32::from(s).to_ne_bytes())),
        (Samples::I32(v), 1) => out.extend(v.iter().map(|&s| s as u8)),
        (Samples::I32(v), 2) => out.extend(v.iter().flat_map(|&s| (s as u16).to_ne_bytes())),
        (Samples::I32(v), _) => out.extend(v.iter().flat_map(|&s| s.to_ne_bytes())),
    }
}

/// Decodes one JPEG frame of `pixels` pixels (one component, checked).
fn jpeg(stream: &[u8], pixels: usize) -> Result<Samples, String> {
    let mut decoder = jpeg_decoder::Decoder::new(stream);
    // Decoding needs at most the image (two bytes a sample) and its
    // coefficients; the header check bounded the image by the DICOM header.
    decoder.set_max_decoding_buffer_size(pixels.saturating_mul(8).max(1 << 16));
    let bytes = decoder.decode().map_err(|e| e.to_string())?;
    let info = decoder.info().ok_or("no image information")?;
    Ok(match info.pixel_format {
        jpeg_decoder::PixelFormat::L8 => Samples::U8(bytes),
        jpeg_decoder::PixelFormat::L16 => Samples::U16(
            bytes
                .chunks_exact(2)
                .map(|c| u16::from_ne_bytes([c[0], c[1]]))
                .collect(),
        ),
        other => return Err(format!("decoded as {other:?}, not greyscale")),
    })
}

/// Decodes one JPEG 2000 frame (one component of the header's size, checked).
fn j2k(stream: &[u8], format: &ImageFormat) -> Result<Samples, String> {
    let image = jpeg2k::Image::from_bytes(stream).map_err(|e| e.to_string())?;
    let [component] = image.components() else {
        return Err(format!("{} components", image.components().len()));
    };
    let (w, h) = (component.width() as usize, component.height() as usize);
    if (w, h) != (format.columns, format.rows) {
        return Err(format!("decoded to {w}x{h}"));
    }
    Ok(Samples::I32(component.data().to_vec()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames_of(split: Vec<Vec<&[u8]>>) -> Vec<Vec<u8>> {
        split.into_iter().map(|f| f.concat()).collect()
    }

    #[test]
    fn fragments_split_by_offset_table_count_or_start_markers() {
        let soi = |b: u8| vec![0xFF, 0xD8, b, b];
        let tail = |b: u8| vec![b, b];
        // Frame 0 = fragments 0-1, frame 1 = fragment 2: offsets 0 and
        // (8 + 4) + (8 + 2) = 22.
        let fragments = vec![soi(1), tail(2), soi(3)];
        let by_table = split(Codec::Jpeg, &[0, 22], &fragments, 2).unwrap();
        assert_eq!(frames_of(by_table), [vec![0xFF, 0xD8, 1, 1, 2, 2], soi(3)]);
        let by_marker = split(Codec::Jpeg, &[], &fragments, 2).unwrap();
        assert_eq!(frames_of(by_marker), [vec![0xFF, 0xD8, 1, 1, 2, 2], soi(3)]);
        let one_each = split(Codec::Jpeg, &[], &fragments[..2], 2).unwrap();
        assert_eq!(frames_of(one_each), [soi(1), tail(2)]);
        let single = split(Codec::Jpeg, &[], &fragments, 1).unwrap();
        assert_eq!(single[0].len(), 3);

        let err = split(Codec::Jpeg, &[0, 21], &fragments, 2).unwrap_err();
        assert!(
            err.contains("offset 21 is not where a fragment starts"),
            "{err}"
        );
        let err = split(Codec::Jpeg, &[4, 22], &fragments, 2).unwrap_err();
        assert!(err.contains("first offset is 4"), "{err}");
        let err = split(Codec::Jpeg, &[0], &fragments, 2).unwrap_err();
        assert!(
            err.contains("lists 1 frame(s), but NumberOfFrames is 2"),
            "{err}"
        );
        let err = split(Codec::Jpeg, &[], &fragments, 3 + 1).unwrap_err();
        assert!(err.contains("3 fragment(s) cannot hold 4 frames"), "{err}");
        let err = split(Codec::Jpeg2000, &[], &fragments, 2).unwrap_err();
        assert!(err.contains("begin 1 codestream(s)"), "{err}");
        assert!(split(Codec::Jpeg, &[], &[], 1).is_err());
    }

    #[test]
    fn a_panicking_decoder_is_one_error() {
        let err = guarded(2, "JPEG", true, || panic!("index out of bounds")).err();
        assert_eq!(
            err.as_deref(),
            Some("the JPEG decoder failed on frame 2 (a corrupt stream)")
        );
        let err = guarded(0, "JPEG 2000", true, || Err("bad marker".into())).err();
        assert_eq!(
            err.as_deref(),
            Some("the JPEG 2000 stream of frame 0 is corrupt: bad marker")
        );
    }

    #[test]
    fn stream_headers_are_read_without_decoding() {
        // SOI, APP0 (length 4), SOF3: 16 bits, 12 rows, 16 columns, 1 component.
        let jpeg = [
            0xFF, 0xD8, 0xFF, 0xE0, 0, 4, 0, 0, 0xFF, 0xC3, 0, 11, 16, 0, 12, 0, 16, 1, 1, 0x11, 0,
        ];
        let h = jpeg_header(&jpeg).unwrap();
        assert_eq!(
            (h.width, h.height, h.components, h.precision, h.process),
            (16, 12, 1, 16, 0xC3)
        );
        assert!(
            jpeg_header(&jpeg[..12])
                .unwrap_err()
                .contains("ends inside")
        );
        assert!(jpeg_header(&[0xFF, 0xD8, 0xFF, 0xDA, 0, 2]).is_err());
        assert!(jpeg_header(b"not a jpeg").is_err());

        let mut j2k = vec![0xFF, 0x4F, 0xFF, 0x51, 0, 41, 0, 0];
        for v in [20u32, 14, 4, 2, 20, 14, 0, 0] {
            j2k.extend(v.to_be_bytes());
        }
        j2k.extend([0, 1, 0x8B, 1, 1]);
        let h = j2k_header(&j2k).unwrap();
        assert_eq!(
            (h.width, h.height, h.components, h.precision),
            (16, 12, 1, 12)
        );
        assert!(j2k_header(&j2k[..30]).unwrap_err().contains("ends inside"));

        let format = ImageFormat {
            rows: 12,
            columns: 16,
            bits_allocated: 8,
            bits_stored: 8,
            high_bit: 7,
            signed: false,
            photometric: "MONOCHROME2".into(),
            float: None,
        };
        let err = check_header(&h, &format, 3, "JPEG 2000").unwrap_err();
        assert_eq!(
            err,
            "the JPEG 2000 stream of frame 3 holds 12-bit samples, but BitsAllocated is 8"
        );
        let wide = StreamHeader { width: 17, ..h };
        let err = check_header(&wide, &format, 0, "JPEG").unwrap_err();
        assert!(
            err.contains(
                "is 17x12 with 1 component(s), but the header declares Columns 16 x Rows 12"
            ),
            "{err}"
        );
    }
}
