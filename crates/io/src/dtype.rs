//! Sample types and byte orders of raw data, and how they are kept in
//! memory: 8- and 16-bit integers and `f32` as they are (a volume keeps its
//! [`SampleType`]), everything else converted to `f32`.

use std::fmt;
use std::str::FromStr;

use thiserror::Error;
use volray_core::{Sample, SampleType, Samples};

/// The type of one sample in a raw file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    /// IEEE 754 half precision (MRC mode 12, NumPy `f2`, NRRD has none).
    F16,
    F32,
    F64,
}

impl DType {
    /// Every sample type, in the order of [`DType::NAMES`].
    pub const ALL: [DType; 11] = [
        DType::U8,
        DType::I8,
        DType::U16,
        DType::I16,
        DType::U32,
        DType::I32,
        DType::U64,
        DType::I64,
        DType::F16,
        DType::F32,
        DType::F64,
    ];

    /// The accepted names, as `FromStr` reads and `Display` writes them.
    pub const NAMES: [&'static str; 11] = [
        "u8", "i8", "u16", "i16", "u32", "i32", "u64", "i64", "f16", "f32", "f64",
    ];

    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            DType::U8 | DType::I8 => 1,
            DType::U16 | DType::I16 | DType::F16 => 2,
            DType::U32 | DType::I32 | DType::F32 => 4,
            DType::U64 | DType::I64 | DType::F64 => 8,
        }
    }

    /// The type a volume keeps samples of this type in: `u8`, `i8`, `u16`,
    /// `i16` and `f32` as they are; 32- and 64-bit integers, `f16` and
    /// `f64` as `f32` (rounded to nearest, as [`bytes_to_f32`] does).
    pub fn stored(self) -> SampleType {
        match self {
            DType::U8 => SampleType::U8,
            DType::I8 => SampleType::I8,
            DType::U16 => SampleType::U16,
            DType::I16 => SampleType::I16,
            _ => SampleType::F32,
        }
    }

    /// The name `FromStr` accepts: `u8`, `i8`, ..., `f64`.
    pub fn name(self) -> &'static str {
        match self {
            DType::U8 => "u8",
            DType::I8 => "i8",
            DType::U16 => "u16",
            DType::I16 => "i16",
            DType::U32 => "u32",
            DType::I32 => "i32",
            DType::U64 => "u64",
            DType::I64 => "i64",
            DType::F16 => "f16",
            DType::F32 => "f32",
            DType::F64 => "f64",
        }
    }
}

impl fmt::Display for DType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not one of the accepted spellings.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("unknown {what} '{given}': expected one of {accepted}")]
pub struct ParseNameError {
    /// What was being parsed: "dtype" or "endianness".
    pub what: &'static str,
    /// The text given.
    pub given: String,
    /// The accepted names, comma separated.
    pub accepted: &'static str,
}

impl FromStr for DType {
    type Err = ParseNameError;

    /// Accepts exactly `u8 i8 u16 i16 u32 i32 u64 i64 f16 f32 f64`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        DType::ALL
            .into_iter()
            .find(|d| d.name() == s)
            .ok_or_else(|| ParseNameError {
                what: "dtype",
                given: s.to_string(),
                accepted: "u8, i8, u16, i16, u32, i32, u64, i64, f16, f32, f64",
            })
    }
}

/// Byte order of multi-byte samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Endian {
    #[default]
    Little,
    Big,
}

impl Endian {
    /// The byte order of the machine running this code.
    pub const NATIVE: Endian = if cfg!(target_endian = "big") {
        Endian::Big
    } else {
        Endian::Little
    };
}

impl fmt::Display for Endian {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Endian::Little => "little",
            Endian::Big => "big",
        })
    }
}

impl FromStr for Endian {
    type Err = ParseNameError;

    /// Accepts exactly `little` or `big`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "little" => Ok(Endian::Little),
            "big" => Ok(Endian::Big),
            _ => Err(ParseNameError {
                what: "endianness",
                given: s.to_string(),
                accepted: "little, big",
            }),
        }
    }
}

/// Converts IEEE 754 binary16 bits to `f32` exactly (every half-precision
/// value is an `f32`).
pub fn f16_to_f32(h: u16) -> f32 {
    let negative = h & 0x8000 != 0;
    let exp = u32::from((h >> 10) & 0x1f);
    let mant = u32::from(h & 0x3ff);
    let magnitude = match exp {
        // Zero and subnormals: mant · 2^-24, exact in f32.
        0 => mant as f32 * f32::from_bits(0x3380_0000),
        0x1f => f32::from_bits(0x7f80_0000 | (mant << 13)),
        _ => f32::from_bits(((exp + 112) << 23) | (mant << 13)),
    };
    if negative { -magnitude } else { magnitude }
}

/// Converts `bytes`, a sequence of `dtype` samples in `endian` byte order,
/// to `f32` (32- and 64-bit integers and `f64` with `as f32`, i.e. rounded to the
/// nearest `f32`). Trailing bytes that do not make a whole sample are ignored.
pub fn bytes_to_f32(bytes: &[u8], dtype: DType, endian: Endian) -> Vec<f32> {
    let mut out = Vec::with_capacity(bytes.len() / dtype.size());
    extend_f32(&mut out, bytes, dtype, endian);
    out
}

/// Like [`bytes_to_f32`], appending to `out`.
pub fn extend_f32(out: &mut Vec<f32>, bytes: &[u8], dtype: DType, endian: Endian) {
    macro_rules! convert {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            let conv = match endian {
                Endian::Little => <$t>::from_le_bytes,
                Endian::Big => <$t>::from_be_bytes,
            };
            out.extend(bytes.chunks_exact(N).map(|c| {
                let mut a = [0u8; N];
                a.copy_from_slice(c);
                conv(a) as f32
            }));
        }};
    }
    match dtype {
        DType::U8 => out.extend(bytes.iter().map(|&b| f32::from(b))),
        DType::I8 => out.extend(bytes.iter().map(|&b| f32::from(b as i8))),
        DType::U16 => convert!(u16),
        DType::I16 => convert!(i16),
        DType::U32 => convert!(u32),
        DType::I32 => convert!(i32),
        DType::U64 => convert!(u64),
        DType::I64 => convert!(i64),
        DType::F16 => {
            let conv = match endian {
                Endian::Little => u16::from_le_bytes,
                Endian::Big => u16::from_be_bytes,
            };
            out.extend(
                bytes
                    .chunks_exact(2)
                    .map(|c| f16_to_f32(conv([c[0], c[1]]))),
            );
        }
        DType::F32 => convert!(f32),
        DType::F64 => convert!(f64),
    }
}

/// A type a volume keeps samples in, decoded from a file's bytes.
pub(crate) trait Stored: Sample {
    /// Appends `bytes`, samples of `dtype` in `endian` order, to `out`.
    /// `dtype.stored()` must be this type (`f32` takes every `dtype`).
    fn extend(out: &mut Vec<Self>, bytes: &[u8], dtype: DType, endian: Endian);

    /// A value the reader computed (a number read as text, a boolean, a
    /// type kept as `f32`), converted with `as`: readers pick a type that
    /// holds it exactly.
    fn from_f64(v: f64) -> Self;
}

macro_rules! stored_integer {
    ($t:ty, $dtype:ident) => {
        impl Stored for $t {
            fn extend(out: &mut Vec<Self>, bytes: &[u8], dtype: DType, endian: Endian) {
                debug_assert_eq!(dtype, DType::$dtype);
                const N: usize = std::mem::size_of::<$t>();
                let conv = match endian {
                    Endian::Little => <$t>::from_le_bytes,
                    Endian::Big => <$t>::from_be_bytes,
                };
                out.extend(bytes.chunks_exact(N).map(|c| {
                    let mut a = [0u8; N];
                    a.copy_from_slice(c);
                    conv(a)
                }));
            }

            fn from_f64(v: f64) -> Self {
                v as $t
            }
        }
    };
}

stored_integer!(u8, U8);
stored_integer!(i8, I8);
stored_integer!(u16, U16);
stored_integer!(i16, I16);

impl Stored for f32 {
    fn extend(out: &mut Vec<Self>, bytes: &[u8], dtype: DType, endian: Endian) {
        extend_f32(out, bytes, dtype, endian);
    }

    fn from_f64(v: f64) -> Self {
        v as f32
    }
}

/// Runs `$body` with the type alias `$t` naming the Rust type of the
/// [`SampleType`] `$stored`, and wraps the `Vec<$t>` the body gives (in a
/// `Result`) into [`Samples`]: a reader written once over [`Stored`]
/// keeps each type as it is.
macro_rules! read_as_stored {
    ($stored:expr, |$t:ident| $body:expr) => {{
        use volray_core::{SampleType, Samples};
        match $stored {
            SampleType::U8 => {
                type $t = u8;
                $body.map(Samples::from)
            }
            SampleType::I8 => {
                type $t = i8;
                $body.map(Samples::from)
            }
            SampleType::U16 => {
                type $t = u16;
                $body.map(Samples::from)
            }
            SampleType::I16 => {
                type $t = i16;
                $body.map(Samples::from)
            }
            SampleType::F32 => {
                type $t = f32;
                $body.map(Samples::from)
            }
        }
    }};
}
pub(crate) use read_as_stored;

/// Decodes `bytes` (samples of `dtype` in `endian` order) into the type a
/// volume keeps them in ([`DType::stored`]).
pub fn bytes_to_samples(bytes: &[u8], dtype: DType, endian: Endian) -> Samples {
    let decoded: Result<Samples, std::convert::Infallible> = read_as_stored!(dtype.stored(), |T| {
        let mut out = Vec::with_capacity(bytes.len() / dtype.size());
        <T as Stored>::extend(&mut out, bytes, dtype, endian);
        Ok(out)
    });
    match decoded {
        Ok(samples) => samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode<const N: usize>(
        values: &[f64],
        endian: Endian,
        le: impl Fn(f64) -> [u8; N],
    ) -> Vec<u8> {
        values
            .iter()
            .flat_map(|&v| {
                let mut b = le(v);
                if endian == Endian::Big {
                    b.reverse();
                }
                b
            })
            .collect()
    }

    /// Builds bytes for each dtype by hand in both byte orders and checks
    /// that they decode to the expected values.
    #[test]
    fn every_dtype_round_trips_in_both_byte_orders() {
        for endian in [Endian::Little, Endian::Big] {
            let cases: Vec<(DType, Vec<f64>, Vec<u8>)> = vec![
                (
                    DType::U8,
                    vec![0.0, 1.0, 200.0, 255.0],
                    vec![0, 1, 200, 255],
                ),
                (
                    DType::I8,
                    vec![0.0, -1.0, 127.0, -128.0],
                    vec![0, 0xff, 0x7f, 0x80],
                ),
                (DType::U16, vec![0.0, 258.0, 65535.0], {
                    let v = [0.0, 258.0, 65535.0];
                    encode(&v, endian, |x| (x as u16).to_le_bytes())
                }),
                (DType::I16, vec![-32768.0, -2.0, 32767.0], {
                    let v = [-32768.0, -2.0, 32767.0];
                    encode(&v, endian, |x| (x as i16).to_le_bytes())
                }),
                (DType::U32, vec![0.0, 70000.0, 16_777_216.0], {
                    let v = [0.0, 70000.0, 16_777_216.0];
                    encode(&v, endian, |x| (x as u32).to_le_bytes())
                }),
                (DType::I32, vec![-2_000_000.0, -1.0, 123_456.0], {
                    let v = [-2_000_000.0, -1.0, 123_456.0];
                    encode(&v, endian, |x| (x as i32).to_le_bytes())
                }),
                (DType::F32, vec![-1.5, 0.0, 3.25e10], {
                    let v = [-1.5, 0.0, 3.25e10];
                    encode(&v, endian, |x| (x as f32).to_le_bytes())
                }),
                (DType::F64, vec![-0.125, 1e300, 2.5], {
                    let v = [-0.125, 1e300, 2.5];
                    encode(&v, endian, |x| x.to_le_bytes())
                }),
            ];
            for (dtype, values, bytes) in cases {
                assert_eq!(bytes.len(), values.len() * dtype.size(), "{dtype}");
                let got = bytes_to_f32(&bytes, dtype, endian);
                let want: Vec<f32> = values.iter().map(|&v| v as f32).collect();
                assert_eq!(got, want, "{dtype} {endian}");
            }
        }
    }

    /// Samples kept in their own type decode to the same values as `f32`
    /// decoding gives, for every type and byte order.
    #[test]
    fn stored_types_hold_what_f32_decoding_gives() {
        let bytes: Vec<u8> = (0..64u32).map(|i| (i * 37 + 11) as u8).collect();
        for endian in [Endian::Little, Endian::Big] {
            for dtype in DType::ALL {
                let samples = bytes_to_samples(&bytes, dtype, endian);
                assert_eq!(samples.sample_type(), dtype.stored(), "{dtype}");
                let want = bytes_to_f32(&bytes, dtype, endian);
                let got = samples.to_f32_vec();
                assert_eq!(got.len(), want.len(), "{dtype}");
                for (g, w) in got.iter().zip(&want) {
                    assert!(
                        g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()),
                        "{dtype} {endian}"
                    );
                }
            }
        }
        let kept: Vec<_> = DType::ALL.iter().map(|d| d.stored().name()).collect();
        assert_eq!(
            kept,
            [
                "u8", "i8", "u16", "i16", "f32", "f32", "f32", "f32", "f32", "f32", "f32"
            ]
        );
    }

    #[test]
    fn byte_order_matters() {
        let bytes = [0x01, 0x02];
        assert_eq!(bytes_to_f32(&bytes, DType::U16, Endian::Little), [513.0]);
        assert_eq!(bytes_to_f32(&bytes, DType::U16, Endian::Big), [258.0]);
        // 1.0f64 big-endian is 3f f0 00 .. 00.
        let one_be = [0x3f, 0xf0, 0, 0, 0, 0, 0, 0];
        assert_eq!(bytes_to_f32(&one_be, DType::F64, Endian::Big), [1.0]);
        assert_ne!(bytes_to_f32(&one_be, DType::F64, Endian::Little), [1.0]);
    }

    #[test]
    fn wide_values_convert_with_as() {
        let big = u32::MAX.to_le_bytes();
        assert_eq!(
            bytes_to_f32(&big, DType::U32, Endian::Little),
            [u32::MAX as f32]
        );
        let tiny = 1e-300f64.to_be_bytes();
        assert_eq!(bytes_to_f32(&tiny, DType::F64, Endian::Big), [0.0]);
        let huge = 1e300f64.to_le_bytes();
        assert_eq!(
            bytes_to_f32(&huge, DType::F64, Endian::Little),
            [f32::INFINITY]
        );
    }

    #[test]
    fn trailing_partial_sample_is_ignored() {
        let bytes = [0, 0, 0x80, 0x3f, 0xaa];
        assert_eq!(bytes_to_f32(&bytes, DType::F32, Endian::Little), [1.0]);
    }

    #[test]
    fn names_parse_exactly() {
        for (d, name) in DType::ALL.into_iter().zip(DType::NAMES) {
            assert_eq!(name.parse::<DType>(), Ok(d));
            assert_eq!(d.to_string(), name);
        }
        let sizes: Vec<usize> = DType::ALL.iter().map(|d| d.size()).collect();
        assert_eq!(sizes, [1, 1, 2, 2, 4, 4, 8, 8, 2, 4, 8]);
        for bad in ["F32", "float", "f128", "u128", "", " u8"] {
            let err = bad.parse::<DType>().unwrap_err().to_string();
            assert!(
                err.contains("u8, i8, u16, i16, u32, i32, u64, i64, f16, f32, f64"),
                "{err}"
            );
        }
        assert_eq!("little".parse::<Endian>(), Ok(Endian::Little));
        assert_eq!("big".parse::<Endian>(), Ok(Endian::Big));
        let err = "Big".parse::<Endian>().unwrap_err().to_string();
        assert_eq!(err, "unknown endianness 'Big': expected one of little, big");
        assert_eq!(Endian::Big.to_string(), "big");
    }
}
