//! A dataset's samples as the box-by-box reader decodes them itself: a
//! whole-byte integer or an IEEE binary32/binary64 float, either byte
//! order, each sample's bytes to the `f64` `hdf5-pure` would give (the
//! eager reader's value). Other types (bit fields, VAX floats, packed
//! precisions) go through `hdf5-pure`'s row windows.

use hdf5_pure::{Datatype, DatatypeByteOrder, FloatingPointLayout};

/// A fixed-point or IEEE float sample of a standard layout: its size,
/// byte order, and how its bytes become a `f64`.
#[derive(Clone, Copy)]
pub(super) struct Element {
    pub size: usize,
    pub value: fn(&[u8]) -> f64,
}

macro_rules! decoder {
    ($name:ident, $t:ty, $n:expr, $from:ident) => {
        fn $name(b: &[u8]) -> f64 {
            let mut a = [0u8; $n];
            a.copy_from_slice(&b[..$n]);
            <$t>::$from(a) as f64
        }
    };
}
decoder!(u16_le, u16, 2, from_le_bytes);
decoder!(u16_be, u16, 2, from_be_bytes);
decoder!(i16_le, i16, 2, from_le_bytes);
decoder!(i16_be, i16, 2, from_be_bytes);
decoder!(u32_le, u32, 4, from_le_bytes);
decoder!(u32_be, u32, 4, from_be_bytes);
decoder!(i32_le, i32, 4, from_le_bytes);
decoder!(i32_be, i32, 4, from_be_bytes);
decoder!(u64_le, u64, 8, from_le_bytes);
decoder!(u64_be, u64, 8, from_be_bytes);
decoder!(i64_le, i64, 8, from_le_bytes);
decoder!(i64_be, i64, 8, from_be_bytes);
decoder!(f32_le, f32, 4, from_le_bytes);
decoder!(f32_be, f32, 4, from_be_bytes);
decoder!(f64_le, f64, 8, from_le_bytes);
decoder!(f64_be, f64, 8, from_be_bytes);

fn u8_value(b: &[u8]) -> f64 {
    f64::from(b[0])
}

fn i8_value(b: &[u8]) -> f64 {
    f64::from(b[0] as i8)
}

impl Element {
    /// The element of `dt`, if it is a whole-byte integer or an IEEE
    /// binary32/binary64 float in little- or big-endian order.
    pub fn of(dt: &Datatype) -> Option<Element> {
        let big = |order: &DatatypeByteOrder| match order {
            DatatypeByteOrder::LittleEndian => Some(false),
            DatatypeByteOrder::BigEndian => Some(true),
            _ => None,
        };
        let value: fn(&[u8]) -> f64 = match dt {
            Datatype::FixedPoint {
                size,
                byte_order,
                layout,
            } if layout.bit_offset == 0 && u32::from(layout.bit_precision) == size * 8 => {
                match (*size, layout.signed, big(byte_order)?) {
                    (1, false, _) => u8_value,
                    (1, true, _) => i8_value,
                    (2, false, false) => u16_le,
                    (2, false, true) => u16_be,
                    (2, true, false) => i16_le,
                    (2, true, true) => i16_be,
                    (4, false, false) => u32_le,
                    (4, false, true) => u32_be,
                    (4, true, false) => i32_le,
                    (4, true, true) => i32_be,
                    (8, false, false) => u64_le,
                    (8, false, true) => u64_be,
                    (8, true, false) => i64_le,
                    (8, true, true) => i64_be,
                    _ => return None,
                }
            }
            Datatype::FloatingPoint {
                size,
                byte_order,
                layout,
            } => match (*size, big(byte_order)?) {
                (4, false) if *layout == FloatingPointLayout::IEEE754_BINARY32 => f32_le,
                (4, true) if *layout == FloatingPointLayout::IEEE754_BINARY32 => f32_be,
                (8, false) if *layout == FloatingPointLayout::IEEE754_BINARY64 => f64_le,
                (8, true) if *layout == FloatingPointLayout::IEEE754_BINARY64 => f64_be,
                _ => return None,
            },
            _ => return None,
        };
        let size = match dt {
            Datatype::FixedPoint { size, .. } | Datatype::FloatingPoint { size, .. } => {
                *size as usize
            }
            _ => return None,
        };
        Some(Element { size, value })
    }
}
