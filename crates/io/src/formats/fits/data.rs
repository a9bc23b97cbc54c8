//! A FITS image's samples (FITS Standard 4.0, §5.2 and §5.3): big-endian
//! integers of 8 (unsigned), 16, 32 or 64 bits (two's complement), or IEEE
//! floats of 32 or 64 bits, by BITPIX; the value a sample means is
//!
//! ```text
//! value = BZERO + BSCALE · stored      (§5.3; BSCALE 1, BZERO 0 by default)
//! ```
//!
//! and an integer sample equal to BLANK is undefined (§5.3): read as NaN,
//! as astropy does, and rendered as empty space. IEEE NaN in a float image
//! is kept (§5.3: floats use NaN, not BLANK).
//!
//! Kept exact where the values allow (see `shared/rescale.rs`): 8- and
//! 16-bit samples, with integer BSCALE and BZERO, stay in the narrowest of
//! `u8`, `i8`, `u16`, `i16` that holds them, so astropy's unsigned 16-bit
//! convention (BZERO 32768) reads as `u16` and its signed bytes (BZERO
//! −128) as `i8`. 32- and 64-bit samples become `f32`, rounded once: an
//! integer BZERO with BSCALE 1 (the unsigned conventions BZERO 2^31 and
//! 2^63) is added in 128-bit integers, other scalings in `f64`.

use std::path::Path;

use volray_core::{Sample, Samples};

use super::header::Header;
use super::source::Source;
use crate::dtype::DType;
use crate::error::IoError;
use crate::shared::rescale::rescale;

/// Samples decoded per chunk.
const CHUNK: usize = 1 << 16;

/// BSCALE, BZERO and BLANK.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Scaling {
    pub bscale: f64,
    pub bzero: f64,
    /// BZERO as an integer, where it is one (2^63 does not fit an `i64`).
    pub bzero_int: Option<i128>,
    /// BLANK, for integer images.
    pub blank: Option<i128>,
}

impl Scaling {
    /// The header's scaling; `Err` names a keyword that is not a number.
    pub fn from_header(h: &Header, bitpix: i32) -> Result<(Scaling, Vec<String>), String> {
        let mut notes = Vec::new();
        let bscale = h.float("BSCALE")?.unwrap_or(1.0);
        if bscale == 0.0 {
            notes.push("BSCALE = 0 would make every value BZERO: read as 1".to_string());
        }
        let bscale = if bscale == 0.0 { 1.0 } else { bscale };
        let bzero_int = match h.int("BZERO") {
            Ok(Some(v)) => Some(v),
            Ok(None) => Some(0),
            Err(_) => None,
        };
        let bzero = h.float("BZERO")?.unwrap_or(0.0);
        let bzero_int = bzero_int.filter(|&v| v as f64 == bzero || v.unsigned_abs() > 1 << 53);
        let blank = if bitpix > 0 {
            h.int("BLANK")?
        } else {
            if h.get("BLANK").is_some() {
                notes.push(
                    "BLANK ignored: a float image marks undefined samples with NaN (§5.3)"
                        .to_string(),
                );
            }
            None
        };
        Ok((
            Scaling {
                bscale,
                bzero,
                bzero_int,
                blank,
            },
            notes,
        ))
    }

    /// Whether stored values are the values.
    pub fn is_identity(&self) -> bool {
        self.bscale == 1.0 && self.bzero == 0.0
    }

    /// The value of an integer sample (not BLANK), rounded once to `f32`.
    fn int_value(&self, v: i64) -> f32 {
        match self.bzero_int {
            Some(z) if self.bscale == 1.0 => (i128::from(v) + z) as f32,
            _ => (self.bzero + self.bscale * v as f64) as f32,
        }
    }
}

/// The sample type BITPIX names.
pub(super) fn dtype(bitpix: i32) -> DType {
    match bitpix {
        8 => DType::U8,
        16 => DType::I16,
        32 => DType::I32,
        64 => DType::I64,
        -32 => DType::F32,
        _ => DType::F64,
    }
}

/// How `info` names the stored type: `int16 (BITPIX 16, big-endian)`,
/// `uint16 (BITPIX 16, BZERO 32768, big-endian)`.
pub(super) fn stored_type(bitpix: i32, s: &Scaling) -> String {
    let unsigned = s.bscale == 1.0
        && match bitpix {
            8 => s.bzero_int == Some(-128),
            16 => s.bzero_int == Some(1 << 15),
            32 => s.bzero_int == Some(1 << 31),
            64 => s.bzero_int == Some(1 << 63),
            _ => false,
        };
    let name = match (bitpix, unsigned) {
        (8, false) => "uint8",
        (8, true) => "int8",
        (16, false) => "int16",
        (16, true) => "uint16",
        (32, false) => "int32",
        (32, true) => "uint32",
        (64, false) => "int64",
        (64, true) => "uint64",
        (-32, _) => "float32",
        _ => "float64",
    };
    let mut parts = vec![format!("BITPIX {bitpix}")];
    if !s.is_identity() {
        if s.bscale != 1.0 {
            parts.push(format!("BSCALE {}", s.bscale));
        }
        match s.bzero_int {
            Some(z) if z != 0 => parts.push(format!("BZERO {z}")),
            Some(_) => {}
            None => parts.push(format!("BZERO {}", s.bzero)),
        }
    }
    if let Some(b) = s.blank {
        parts.push(format!("BLANK {b}"));
    }
    parts.push("big-endian".into());
    format!("{name} ({})", parts.join(", "))
}

/// Bytes a value takes while reading: the stored 8- or 16-bit samples and,
/// where scaling or BLANK may turn them into `f32`, those too; `f32` for
/// the others.
pub(super) fn held_bytes(bitpix: i32, s: &Scaling) -> u64 {
    match bitpix {
        8 | 16 if s.is_identity() && s.blank.is_none() => (bitpix / 8) as u64,
        8 | 16 => (bitpix / 8) as u64 + 4,
        _ => 4,
    }
}

/// Reads `count` samples from `src` and gives their values, with the
/// number of NaN among them. `what` names the data in messages.
pub(super) fn read_values(
    path: &Path,
    src: &mut Source,
    bitpix: i32,
    s: &Scaling,
    count: usize,
    what: &str,
) -> Result<(Samples, usize), IoError> {
    let size = bitpix.unsigned_abs() as usize / 8;
    // A gzip stream grows the output as data arrives (its length is not
    // known); a plain file was checked to hold it all.
    let capacity = if src.is_gzip() {
        count.min(CHUNK)
    } else {
        count
    };
    let mut bytes = vec![0u8; count.min(CHUNK) * size];
    let mut chunks = |each: &mut dyn FnMut(&[u8])| -> Result<(), IoError> {
        let mut done = 0;
        while done < count {
            let n = (count - done).min(CHUNK);
            src.fill(path, &mut bytes[..n * size], what)?;
            each(&bytes[..n * size]);
            done += n;
        }
        Ok(())
    };
    match bitpix {
        8 | 16 => {
            let (raw, blank_hits) = if bitpix == 8 {
                let mut v: Vec<u8> = Vec::with_capacity(capacity);
                chunks(&mut |b| v.extend_from_slice(b))?;
                let hits = s
                    .blank
                    .map_or(0, |k| v.iter().filter(|&&x| i128::from(x) == k).count());
                (Samples::from(v), hits)
            } else {
                let mut v: Vec<i16> = Vec::with_capacity(capacity);
                chunks(&mut |b| {
                    v.extend(b.chunks_exact(2).map(|c| i16::from_be_bytes([c[0], c[1]])));
                })?;
                let hits = s
                    .blank
                    .map_or(0, |k| v.iter().filter(|&&x| i128::from(x) == k).count());
                (Samples::from(v), hits)
            };
            if blank_hits == 0 {
                return Ok((rescale(raw, s.bscale, s.bzero), 0));
            }
            // BLANK samples become NaN: the values are f32.
            let blank = s.blank.unwrap_or_default();
            let values: Vec<f32> = volray_core::with_samples!(&raw, |data| data
                .iter()
                .map(|&x| {
                    // 8- and 16-bit samples are exact in f32 and f64.
                    let v = f64::from(x.to_f32());
                    if v == blank as f64 {
                        f32::NAN
                    } else {
                        (s.bzero + s.bscale * v) as f32
                    }
                })
                .collect());
            Ok((Samples::from(values), blank_hits))
        }
        _ => {
            let mut out: Vec<f32> = Vec::with_capacity(capacity);
            let int = |v: i64| {
                if s.blank == Some(i128::from(v)) {
                    f32::NAN
                } else {
                    s.int_value(v)
                }
            };
            let float = |v: f64| {
                if s.is_identity() {
                    v as f32
                } else {
                    (s.bzero + s.bscale * v) as f32
                }
            };
            match bitpix {
                32 => chunks(&mut |b| {
                    out.extend(
                        b.chunks_exact(4)
                            .map(|c| int(i64::from(i32::from_be_bytes([c[0], c[1], c[2], c[3]])))),
                    );
                })?,
                64 => chunks(&mut |b| {
                    out.extend(b.chunks_exact(8).map(|c| {
                        let mut a = [0u8; 8];
                        a.copy_from_slice(c);
                        int(i64::from_be_bytes(a))
                    }));
                })?,
                -32 => {
                    chunks(&mut |b| {
                        out.extend(b.chunks_exact(4).map(|c| {
                            float(f64::from(f32::from_be_bytes([c[0], c[1], c[2], c[3]])))
                        }));
                    })?
                }
                _ => chunks(&mut |b| {
                    out.extend(b.chunks_exact(8).map(|c| {
                        let mut a = [0u8; 8];
                        a.copy_from_slice(c);
                        float(f64::from_be_bytes(a))
                    }));
                })?,
            }
            let nan = out.iter().filter(|v| v.is_nan()).count();
            Ok((Samples::from(out), nan))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scaling(bscale: f64, bzero: Option<i128>, blank: Option<i128>) -> Scaling {
        Scaling {
            bscale,
            bzero: bzero.unwrap_or(0) as f64,
            bzero_int: bzero.or(Some(0)),
            blank,
        }
    }

    #[test]
    fn unsigned_conventions_are_added_exactly() {
        let u64 = scaling(1.0, Some(1 << 63), None);
        // The largest uint64 is stored as i64::MAX.
        assert_eq!(u64.int_value(i64::MAX), u64::MAX as f32);
        assert_eq!(u64.int_value(i64::MIN), 0.0);
        let u32 = scaling(1.0, Some(1 << 31), None);
        assert_eq!(
            u32.int_value(-(1 << 31) + 3_000_000_123),
            3_000_000_123u32 as f32
        );
        assert_eq!(
            stored_type(64, &u64),
            "uint64 (BITPIX 64, BZERO 9223372036854775808, big-endian)"
        );
        assert_eq!(
            stored_type(8, &scaling(1.0, Some(-128), None)),
            "int8 (BITPIX 8, BZERO -128, big-endian)"
        );
        assert_eq!(
            stored_type(16, &scaling(1.0, None, Some(-1))),
            "int16 (BITPIX 16, BLANK -1, big-endian)"
        );
        assert_eq!(held_bytes(16, &scaling(1.0, None, None)), 2);
        assert_eq!(held_bytes(16, &scaling(1.0, Some(1 << 15), None)), 6);
        assert_eq!(held_bytes(-64, &scaling(1.0, None, None)), 4);
    }
}
