//! Decoding a DICOM file's pixel data (through `dicom-pixeldata`) and
//! turning each frame into values: bits outside BitsStored masked off,
//! sign extended for PixelRepresentation 1, then the modality rescale
//! `value = slope·stored + intercept` (PS3.3 C.11.1.1.2), kept in the
//! integer type [`kept_type`] finds when every value fits it exactly (a CT
//! series in `i16`), as `f32` otherwise.

use std::path::Path;

use dicom_dictionary_std::tags;
use dicom_object::DefaultDicomObject;
use dicom_pixeldata::PixelDecoder;

use volray_core::SampleType;

use super::codecs::{self, Codec};
use super::header::{ImageFormat, Plane};
use crate::dtype::Stored;
use crate::error::IoError;
use crate::shared::panics::guarded;
use crate::shared::rescale::{integer_type, rescaled_range};

/// The decoded frames of one file.
pub(super) enum Frames {
    /// Integer samples, native byte order, `bits_allocated` wide.
    Int(Vec<u8>),
    Float32(Vec<f32>),
    Float64(Vec<f64>),
}

/// Decodes all frames of `obj` (a file whose header gave `format` and
/// `frames`), checking that the decoder produced what the header declared.
pub(super) fn decode(
    path: &Path,
    obj: &DefaultDicomObject,
    format: &ImageFormat,
    frames: usize,
) -> Result<Frames, IoError> {
    let samples = format.rows * format.columns * frames;
    if let Some(bits) = format.float {
        let tag = if bits == 32 {
            tags::FLOAT_PIXEL_DATA
        } else {
            tags::DOUBLE_FLOAT_PIXEL_DATA
        };
        let element = obj
            .get(tag)
            .ok_or_else(|| IoError::invalid(path, "DICOM float pixel data is missing"))?;
        let decoded = if bits == 32 {
            element.to_multi_float32().map(Frames::Float32)
        } else {
            element.to_multi_float64().map(Frames::Float64)
        }
        .map_err(|e| IoError::invalid(path, format!("DICOM float pixel data: {e}")))?;
        let len = match &decoded {
            Frames::Float32(v) => v.len(),
            Frames::Float64(v) => v.len(),
            Frames::Int(_) => unreachable!("float pixel data decodes to floats"),
        };
        if len < samples {
            return Err(short(path, len, samples, format, frames));
        }
        return Ok(decoded);
    }

    let syntax = obj.meta().transfer_syntax();
    if let Some(codec) = Codec::of(syntax) {
        return decode_encapsulated(path, obj, format, frames, codec).map(Frames::Int);
    }
    if syntax == RLE_LOSSLESS {
        check_rle(path, obj, format)?;
    }
    let result = guarded(|| obj.decode_pixel_data()).ok();
    let decoded = match result {
        Some(Ok(d)) => d,
        Some(Err(e)) => {
            // The error's sources say why ("Could not decode pixel data"
            // alone does not).
            let mut reason = e.to_string();
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                reason = format!("{reason}: {s}");
                source = s.source();
            }
            return Err(IoError::invalid(
                path,
                format!(
                    "cannot decode the pixel data ({}): {reason}",
                    transfer_syntax_name(syntax)
                ),
            ));
        }
        None => {
            return Err(IoError::invalid(
                path,
                "the DICOM pixel data decoder failed on this file",
            ));
        }
    };
    let (rows, columns) = (decoded.rows() as usize, decoded.columns() as usize);
    if (rows, columns) != (format.rows, format.columns)
        || decoded.samples_per_pixel() != 1
        || decoded.bits_allocated() != format.bits_allocated
    {
        return Err(IoError::invalid(
            path,
            format!(
                "decoded pixel data is {columns}x{rows} with {} sample(s) of {} bits, but the header declares {}x{} with 1 sample of {} bits",
                decoded.samples_per_pixel(),
                decoded.bits_allocated(),
                format.columns,
                format.rows,
                format.bits_allocated
            ),
        ));
    }
    let bytes = decoded.into_data();
    let have = bytes.len() / format.sample_bytes();
    if have < samples {
        return Err(short(path, have, samples, format, frames));
    }
    Ok(Frames::Int(bytes))
}

/// Decodes the JPEG or JPEG 2000 frames of `obj` ([`codecs`]) into a
/// buffer of `frames` frames of `format`, sized from the header (which the
/// caller checked against `--max-memory`) before anything is decoded.
fn decode_encapsulated(
    path: &Path,
    obj: &DefaultDicomObject,
    format: &ImageFormat,
    frames: usize,
    codec: Codec,
) -> Result<Vec<u8>, IoError> {
    let syntax = transfer_syntax_name(obj.meta().transfer_syntax());
    let fail = |reason: String| {
        IoError::invalid(
            path,
            format!("cannot decode the pixel data ({syntax}): {reason}"),
        )
    };
    let value = obj
        .get(tags::PIXEL_DATA)
        .ok_or_else(|| fail("no PixelData (7FE0,0010)".into()))?
        .value();
    let (Some(offsets), Some(fragments)) = (value.offset_table(), value.fragments()) else {
        return Err(fail(
            "PixelData (7FE0,0010) is not encapsulated (no fragments), as the transfer syntax requires".into(),
        ));
    };
    let split = codecs::split(codec, offsets, fragments, frames).map_err(fail)?;
    let bytes = format
        .rows
        .checked_mul(format.columns)
        .and_then(|n| n.checked_mul(frames))
        .and_then(|n| n.checked_mul(format.sample_bytes()))
        .ok_or_else(|| fail("the decoded size is too large to address".into()))?;
    let mut out = Vec::new();
    out.try_reserve_exact(bytes)
        .map_err(|_| fail(format!("cannot allocate {bytes} bytes")))?;
    codecs::decode_frames(codec, &split, format, &mut out).map_err(fail)?;
    Ok(out)
}

/// The transfer syntax of RLE Lossless (PS3.5 A.4.2, Annex G).
const RLE_LOSSLESS: &str = "1.2.840.10008.1.2.5";

/// Checks the RLE header of each fragment (one frame each, PS3.5 A.4.2)
/// before `dicom-pixeldata` decodes them: it trusts the header (a garbled
/// segment count made it allocate 6 GB, and some offsets made it panic).
/// The header (G.5) is 16 little-endian `u32`s: the number of segments,
/// one per byte of a sample (G.2: most significant first; one sample a
/// pixel here), then each segment's offset, the first 64, increasing,
/// inside the fragment.
fn check_rle(path: &Path, obj: &DefaultDicomObject, format: &ImageFormat) -> Result<(), IoError> {
    let fail = |reason: String| {
        IoError::invalid(
            path,
            format!("cannot decode the pixel data (RLE Lossless, {RLE_LOSSLESS}): {reason}"),
        )
    };
    let fragments = obj
        .get(tags::PIXEL_DATA)
        .and_then(|e| e.value().fragments())
        .ok_or_else(|| fail("PixelData (7FE0,0010) is not encapsulated (no fragments)".into()))?;
    let segments = format.sample_bytes();
    for (f, fragment) in fragments.iter().enumerate() {
        let word = |i: usize| {
            fragment
                .get(4 * i..4 * i + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        };
        let Some(n) = word(0) else {
            return Err(fail(format!(
                "fragment {f} of {} bytes is shorter than the 64-byte RLE header",
                fragment.len()
            )));
        };
        if n != segments || fragment.len() < 64 {
            return Err(fail(format!(
                "fragment {f} ({} bytes) declares {n} RLE segment(s), but one {}-bit sample a pixel takes {segments}",
                fragment.len(),
                format.bits_allocated
            )));
        }
        let mut previous = 63;
        for s in 1..=n {
            let offset = word(s).unwrap_or(0);
            if offset <= previous || offset >= fragment.len() || (s == 1 && offset != 64) {
                return Err(fail(format!(
                    "fragment {f}: RLE segment {} starts at byte {offset}, which is not after the header and the segment before it, inside the fragment's {} bytes",
                    s - 1,
                    fragment.len()
                )));
            }
            previous = offset;
        }
    }
    Ok(())
}

fn short(path: &Path, have: usize, want: usize, format: &ImageFormat, frames: usize) -> IoError {
    IoError::invalid(
        path,
        format!(
            "pixel data holds {have} samples, but Rows {} x Columns {} x {frames} frame(s) need {want}",
            format.rows, format.columns
        ),
    )
}

/// The type the volume keeps: the narrowest integer type that holds every
/// value BitsStored and PixelRepresentation allow, rescaled by any of
/// `planes`, where slopes and intercepts are integers; `f32` otherwise
/// (and for float pixel data).
pub(super) fn kept_type(format: &ImageFormat, planes: &[Plane]) -> SampleType {
    if format.float.is_some() || format.bits_stored == 0 || format.bits_stored > 32 {
        return SampleType::F32;
    }
    let bits = i32::from(format.bits_stored);
    let (lo, hi) = if format.signed {
        (-(2f64.powi(bits - 1)), 2f64.powi(bits - 1) - 1.0)
    } else {
        (0.0, 2f64.powi(bits) - 1.0)
    };
    let mut range: Option<(f64, f64)> = None;
    for plane in planes {
        let Some((a, b)) = rescaled_range(lo, hi, plane.slope, plane.intercept) else {
            return SampleType::F32;
        };
        range = Some(range.map_or((a, b), |(l, h)| (l.min(a), h.max(b))));
    }
    range
        .and_then(|(l, h)| integer_type(l, h))
        .unwrap_or(SampleType::F32)
}

/// Writes frame `frame` of `frames`, rescaled by `plane`, into `out`
/// (`rows·columns` values), as `T`: [`kept_type`]'s type for these planes.
pub(super) fn frame_values<T: Stored>(
    frames: &Frames,
    frame: usize,
    format: &ImageFormat,
    plane: &Plane,
    out: &mut Vec<T>,
) {
    let n = format.rows * format.columns;
    let (slope, intercept) = (plane.slope, plane.intercept);
    // Exact in an integer T (kept_type checked the range); one rounding to f32.
    let rescale = |v: f64| T::from_f64(slope * v + intercept);
    match frames {
        Frames::Float32(v) => out.extend(
            v[frame * n..(frame + 1) * n]
                .iter()
                .map(|&x| rescale(f64::from(x))),
        ),
        Frames::Float64(v) => out.extend(v[frame * n..(frame + 1) * n].iter().map(|&x| rescale(x))),
        Frames::Int(bytes) => {
            let size = format.sample_bytes();
            let slice = &bytes[frame * n * size..(frame + 1) * n * size];
            // Each sample is masked and rescaled in integers and f64, so
            // 32-bit values keep their precision until the final f32.
            out.extend(slice.chunks_exact(size).map(|c| {
                let raw = match size {
                    1 => u32::from(c[0]),
                    2 => u32::from(u16::from_ne_bytes([c[0], c[1]])),
                    _ => u32::from_ne_bytes([c[0], c[1], c[2], c[3]]),
                };
                rescale(stored_value(raw, format) as f64)
            }));
        }
    }
}

/// The value of a raw sample: the `bits_stored` bits ending at `high_bit`
/// (PS3.5 §8.1.1), two's complement if signed.
fn stored_value(raw: u32, format: &ImageFormat) -> i64 {
    let bits = u32::from(format.bits_stored);
    let shift = u32::from(format.high_bit + 1 - format.bits_stored);
    let mask = if bits >= 32 {
        u32::MAX
    } else {
        (1u32 << bits) - 1
    };
    let v = (raw >> shift) & mask;
    if format.signed && v >> (bits - 1) & 1 == 1 {
        i64::from(v) - (1i64 << bits)
    } else {
        i64::from(v)
    }
}

/// A readable name for a transfer syntax UID, for messages.
pub(super) fn transfer_syntax_name(uid: &str) -> String {
    let name = match uid {
        "1.2.840.10008.1.2" => "Implicit VR Little Endian",
        "1.2.840.10008.1.2.1" => "Explicit VR Little Endian",
        "1.2.840.10008.1.2.1.98" => "Encapsulated Uncompressed",
        "1.2.840.10008.1.2.1.99" => "Deflated Explicit VR Little Endian",
        "1.2.840.10008.1.2.2" => "Explicit VR Big Endian",
        "1.2.840.10008.1.2.5" => "RLE Lossless",
        "1.2.840.10008.1.2.4.50" => "JPEG Baseline",
        "1.2.840.10008.1.2.4.51" => "JPEG Extended",
        "1.2.840.10008.1.2.4.57" => "JPEG Lossless",
        "1.2.840.10008.1.2.4.70" => "JPEG Lossless SV1",
        "1.2.840.10008.1.2.4.80" => "JPEG-LS Lossless",
        "1.2.840.10008.1.2.4.81" => "JPEG-LS Near-Lossless",
        "1.2.840.10008.1.2.4.90" => "JPEG 2000 Lossless",
        "1.2.840.10008.1.2.4.91" => "JPEG 2000",
        "1.2.840.10008.1.2.4.201" => "HTJ2K Lossless",
        "1.2.840.10008.1.2.4.202" => "HTJ2K Lossless RPCL",
        "1.2.840.10008.1.2.4.203" => "HTJ2K",
        "1.2.840.10008.1.2.4.100" | "1.2.840.10008.1.2.4.101" => "MPEG-2",
        "1.2.840.10008.1.2.4.102" | "1.2.840.10008.1.2.4.103" => "MPEG-4",
        "1.2.840.10008.1.2.4.110" | "1.2.840.10008.1.2.4.111" | "1.2.840.10008.1.2.4.112" => {
            "JPEG XL"
        }
        _ => return format!("transfer syntax {uid}"),
    };
    format!("{name}, {uid}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(bits_allocated: u16, bits_stored: u16, high_bit: u16, signed: bool) -> ImageFormat {
        ImageFormat {
            rows: 1,
            columns: 2,
            bits_allocated,
            bits_stored,
            high_bit,
            signed,
            photometric: "MONOCHROME2".into(),
            float: None,
        }
    }

    #[test]
    fn stored_bits_are_masked_and_sign_extended() {
        // 12 of 16 bits, junk above.
        let f = format(16, 12, 11, false);
        assert_eq!(stored_value(0xA123, &f), 0x123);
        let f = format(16, 12, 11, true);
        assert_eq!(stored_value(0xF800, &f), -2048);
        assert_eq!(stored_value(0x07FF, &f), 2047);
        // High bit not at BitsStored - 1: the field sits higher up.
        let f = format(16, 12, 15, false);
        assert_eq!(stored_value(0xABC5, &f), 0xABC);
        let f = format(32, 32, 31, true);
        assert_eq!(stored_value(0xFFFF_FFFF, &f), -1);
        assert_eq!(stored_value(0xFFFF, &format(16, 16, 15, false)), 65535);
    }

    #[test]
    fn ct_values_are_kept_in_the_narrowest_integer_type() {
        let plane = |slope: f64, intercept: f64| Plane {
            position: None,
            position_decimals: None,
            orientation: None,
            pixel_spacing: None,
            slope,
            intercept,
        };
        let ct = format(16, 12, 11, false);
        assert_eq!(kept_type(&ct, &[plane(1.0, -1024.0)]), SampleType::I16);
        assert_eq!(kept_type(&ct, &[plane(1.0, 0.0)]), SampleType::U16);
        assert_eq!(
            kept_type(&ct, &[plane(1.0, 0.0), plane(1.0, -1024.0)]),
            SampleType::I16
        );
        assert_eq!(kept_type(&ct, &[plane(0.5, -1024.0)]), SampleType::F32);
        assert_eq!(
            kept_type(&format(8, 8, 7, false), &[plane(1.0, 0.0)]),
            SampleType::U8
        );
        assert_eq!(
            kept_type(&format(16, 16, 15, false), &[plane(1.0, -1.0)]),
            SampleType::F32
        );
        assert_eq!(
            kept_type(&format(32, 32, 31, true), &[plane(1.0, 0.0)]),
            SampleType::F32
        );
    }

    #[test]
    fn frames_are_rescaled() {
        let f = format(16, 16, 15, true);
        let raw: Vec<u8> = [-3i16, 5, 7, -1]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        let plane = Plane {
            position: None,
            position_decimals: None,
            orientation: None,
            pixel_spacing: None,
            slope: 2.0,
            intercept: -1024.0,
        };
        let mut out: Vec<f32> = Vec::new();
        frame_values(&Frames::Int(raw.clone()), 1, &f, &plane, &mut out);
        assert_eq!(out, [2.0 * 7.0 - 1024.0, -2.0 - 1024.0]);
        // 16 bits signed, times 2, minus 1024, need more than 16 bits.
        assert_eq!(kept_type(&f, std::slice::from_ref(&plane)), SampleType::F32);
        let mut ints: Vec<i16> = Vec::new();
        frame_values(&Frames::Int(raw), 1, &f, &plane, &mut ints);
        assert_eq!(ints, [2 * 7 - 1024, -2 - 1024]);
        assert_eq!(
            transfer_syntax_name("1.2.840.10008.1.2.4.90"),
            "JPEG 2000 Lossless, 1.2.840.10008.1.2.4.90"
        );
    }
}
