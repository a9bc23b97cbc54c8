//! Decoding a DICOM file's pixel data (through `dicom-pixeldata`) and
//! turning each frame into `f32` values: bits outside BitsStored masked
//! off, sign extended for PixelRepresentation 1, then the modality
//! rescale `value = slope·stored + intercept` (PS3.3 C.11.1.1.2).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use dicom_dictionary_std::tags;
use dicom_object::DefaultDicomObject;
use dicom_pixeldata::PixelDecoder;

use super::header::{ImageFormat, Plane};
use crate::error::IoError;

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

    let result = catch_unwind(AssertUnwindSafe(|| obj.decode_pixel_data()));
    let decoded = match result {
        Ok(Ok(d)) => d,
        Ok(Err(e)) => {
            let ts = obj.meta().transfer_syntax();
            return Err(IoError::invalid(
                path,
                format!(
                    "cannot decode the pixel data ({}): {e}",
                    transfer_syntax_name(ts)
                ),
            ));
        }
        Err(_) => {
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

fn short(path: &Path, have: usize, want: usize, format: &ImageFormat, frames: usize) -> IoError {
    IoError::invalid(
        path,
        format!(
            "pixel data holds {have} samples, but Rows {} x Columns {} x {frames} frame(s) need {want}",
            format.rows, format.columns
        ),
    )
}

/// Writes frame `frame` of `frames`, rescaled by `plane`, into `out`
/// (`rows·columns` values).
pub(super) fn frame_values(
    frames: &Frames,
    frame: usize,
    format: &ImageFormat,
    plane: &Plane,
    out: &mut Vec<f32>,
) {
    let n = format.rows * format.columns;
    let (slope, intercept) = (plane.slope, plane.intercept);
    let rescale = |v: f64| (slope * v + intercept) as f32;
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
    fn frames_are_rescaled() {
        let f = format(16, 16, 15, true);
        let raw: Vec<u8> = [-3i16, 5, 7, -1]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        let plane = Plane {
            position: None,
            orientation: None,
            pixel_spacing: None,
            slope: 2.0,
            intercept: -1024.0,
        };
        let mut out = Vec::new();
        frame_values(&Frames::Int(raw), 1, &f, &plane, &mut out);
        assert_eq!(out, [2.0 * 7.0 - 1024.0, -2.0 - 1024.0]);
        assert_eq!(
            transfer_syntax_name("1.2.840.10008.1.2.4.90"),
            "JPEG 2000 Lossless, 1.2.840.10008.1.2.4.90"
        );
    }
}
