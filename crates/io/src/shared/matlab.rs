//! The real numeric matrices of a MATLAB `.mat` file, by name: what SPM
//! keeps beside an Analyze header (`mat`, `M`: the voxel-to-world
//! affine). Both layouts small files use:
//!
//! - **Level 4** (MATLAB 4, and what nibabel and `scipy.io.savemat(...,
//!   format='4')` write): a run of variables, each a 20-byte header
//!   (`type` = M·1000 + O·100 + P·10 + T, `mrows`, `ncols`, `imagf`,
//!   `namlen`), the name, then the real part column by column (P: 0
//!   double, 1 single, 2 int32, 3 int16, 4 uint16, 5 uint8; M: 0
//!   little-endian, 1 big-endian) and the imaginary part if `imagf`.
//! - **Level 5** (MATLAB 5 to 7, `-v6`, `-v7`, scipy's default): a
//!   128-byte header ending in the byte-order mark `IM` (little-endian) or
//!   `MI`, then data elements (8-byte tag, or a 4-byte "small element"
//!   tag, each padded to 8 bytes); a `miMATRIX` (14) holds array flags
//!   (class and complex bit), dimensions, the name and the real part,
//!   stored in any numeric type (MATLAB stores integral doubles as smaller
//!   integers); a `miCOMPRESSED` (15) element is a zlib stream of one
//!   element.
//!
//! MATLAB 7.3 files are HDF5 and are refused, with the way round. Every
//! count is checked against the bytes present before anything is
//! allocated, and an inflated element may not exceed [`MAX_BYTES`].

use std::io::Read;

/// The largest `.mat` (or inflated element) read: an affine needs 128
/// bytes; this leaves room for a few other small variables.
pub const MAX_BYTES: usize = 16 << 20;

/// A real matrix: its dimensions (rows, columns, then any more) and its
/// values in MATLAB's column-major order.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    pub dims: Vec<usize>,
    pub values: Vec<f64>,
}

impl Matrix {
    /// The value at row `r`, column `c` of the first page.
    pub fn at(&self, r: usize, c: usize) -> f64 {
        self.values[r + c * self.dims[0]]
    }
}

/// The real numeric matrices of the `.mat` bytes, with their names, in
/// file order; other variables (text, cells, structures, complex or
/// sparse arrays) are skipped. An error says what is wrong, in words for
/// a message that names the file.
pub fn matrices(bytes: &[u8]) -> Result<Vec<(String, Matrix)>, String> {
    if bytes.len() > MAX_BYTES {
        return Err(format!(
            "{} bytes: more than the {} a MATLAB file of small matrices needs",
            bytes.len(),
            MAX_BYTES
        ));
    }
    if bytes.len() >= 128 && bytes[..116].starts_with(b"MATLAB 7.3 MAT-file") {
        return Err(
            "a MATLAB 7.3 (HDF5) file: save it again with save(..., '-v6') or scipy.io.savemat"
                .into(),
        );
    }
    if bytes.len() >= 128 && bytes.starts_with(b"MATLAB 5.0 MAT-file") {
        return level5(bytes);
    }
    level4(bytes)
}

/// Level 4: variables one after another (see the module docs).
fn level4(mut rest: &[u8]) -> Result<Vec<(String, Matrix)>, String> {
    let mut out = Vec::new();
    while !rest.is_empty() {
        if rest.len() < 20 {
            return Err("truncated: a level-4 variable header needs 20 bytes".into());
        }
        let le = |i: usize| i32::from_le_bytes(rest[i..i + 4].try_into().unwrap());
        let be = |i: usize| i32::from_be_bytes(rest[i..i + 4].try_into().unwrap());
        // The type's thousands digit is the byte order; read it both ways.
        let little = (0..5000).contains(&le(0)) && le(0) / 1000 == 0;
        let word = |i: usize| if little { le(i) } else { be(i) };
        let (kind, rows, cols, imag, namlen) = (word(0), word(4), word(8), word(12), word(16));
        let ok = (0..5000).contains(&kind) && rows >= 0 && cols >= 0 && namlen > 0;
        if !ok || (kind / 1000 == 1) == little {
            return Err(format!(
                "not a MATLAB file: level-4 variable header type {kind}, {rows}x{cols}, name length {namlen}"
            ));
        }
        let (precision, text) = ((kind / 10) % 10, kind % 10);
        let size = match precision {
            0 => 8,
            1 | 2 => 4,
            3 | 4 => 2,
            5 => 1,
            p => return Err(format!("level-4 precision {p} is not one MATLAB defines")),
        };
        let count = (rows as usize) * (cols as usize);
        let parts = if imag != 0 { 2 } else { 1 };
        let data_len = count
            .checked_mul(size * parts)
            .filter(|&n| n <= rest.len())
            .ok_or("truncated: a level-4 variable claims more data than the file holds")?;
        let namlen = namlen as usize;
        let end = 20 + namlen + data_len;
        if end > rest.len() {
            return Err("truncated: a level-4 variable runs past the end of the file".into());
        }
        let name = c_string(&rest[20..20 + namlen]);
        let data = &rest[20 + namlen..20 + namlen + count * size];
        if text == 0 && imag == 0 {
            let values = data
                .chunks_exact(size)
                .map(|b| number4(b, precision, little))
                .collect();
            let dims = vec![rows as usize, cols as usize];
            out.push((name, Matrix { dims, values }));
        }
        rest = &rest[end..];
    }
    Ok(out)
}

/// One value of level-4 precision `p` from its bytes.
fn number4(b: &[u8], p: i32, little: bool) -> f64 {
    macro_rules! get {
        ($t:ty) => {{
            let a = b.try_into().unwrap();
            if little {
                <$t>::from_le_bytes(a) as f64
            } else {
                <$t>::from_be_bytes(a) as f64
            }
        }};
    }
    match p {
        0 => get!(f64),
        1 => get!(f32),
        2 => get!(i32),
        3 => get!(i16),
        4 => get!(u16),
        _ => f64::from(b[0]),
    }
}

/// A name up to its first NUL.
fn c_string(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).into_owned()
}

/// The byte order of a level-5 file.
#[derive(Clone, Copy)]
struct Order {
    little: bool,
}

impl Order {
    fn u32(self, b: &[u8]) -> u32 {
        let a = b[..4].try_into().unwrap();
        if self.little {
            u32::from_le_bytes(a)
        } else {
            u32::from_be_bytes(a)
        }
    }
}

/// Level 5: the header, then top-level data elements.
fn level5(bytes: &[u8]) -> Result<Vec<(String, Matrix)>, String> {
    let order = match &bytes[126..128] {
        b"IM" => Order { little: true },
        b"MI" => Order { little: false },
        m => {
            return Err(format!(
                "level-5 byte-order mark {m:?} is neither IM nor MI"
            ));
        }
    };
    let mut out = Vec::new();
    let mut rest = &bytes[128..];
    while rest.len() >= 8 {
        let (kind, body, next) = element(rest, order)?;
        match kind {
            14 => {
                if let Some(m) = matrix5(body, order)? {
                    out.push(m);
                }
            }
            15 => {
                let mut inflated = Vec::new();
                flate2::read::ZlibDecoder::new(body)
                    .take(MAX_BYTES as u64 + 1)
                    .read_to_end(&mut inflated)
                    .map_err(|e| format!("a compressed element does not inflate: {e}"))?;
                if inflated.len() > MAX_BYTES {
                    return Err(format!(
                        "a compressed element inflates to more than {MAX_BYTES} bytes"
                    ));
                }
                let (kind, body, _) = element(&inflated, order)?;
                if kind == 14
                    && let Some(m) = matrix5(body, order)?
                {
                    out.push(m);
                }
            }
            _ => {}
        }
        rest = next;
    }
    Ok(out)
}

/// The data element at the start of `b`: its type, its body and what
/// follows it (the body padded to 8 bytes, except a compressed one).
fn element(b: &[u8], order: Order) -> Result<(u32, &[u8], &[u8]), String> {
    if b.len() < 8 {
        return Err("truncated: a level-5 element tag needs 8 bytes".into());
    }
    let first = order.u32(b);
    if first >> 16 != 0 {
        // Small element: 2 bytes of size, 2 of type, 4 of data.
        let (kind, size) = (first & 0xffff, (first >> 16) as usize);
        if size > 4 {
            return Err(format!(
                "a small level-5 element claims {size} bytes (at most 4)"
            ));
        }
        return Ok((kind, &b[4..4 + size], &b[8..]));
    }
    let size = order.u32(&b[4..]) as usize;
    let padded = if first == 15 {
        size
    } else {
        size.div_ceil(8) * 8
    };
    if size > b.len() - 8 {
        return Err(format!(
            "truncated: a level-5 element of type {first} claims {size} bytes, {} remain",
            b.len() - 8
        ));
    }
    let next = &b[(8 + padded).min(b.len())..];
    Ok((first, &b[8..8 + size], next))
}

/// A `miMATRIX` body: its name and real values, or `None` for an array
/// that is not a real numeric one.
fn matrix5(body: &[u8], order: Order) -> Result<Option<(String, Matrix)>, String> {
    let (kind, flags, rest) = element(body, order)?;
    if kind != 6 || flags.len() < 8 {
        return Err("a level-5 matrix without its array flags".into());
    }
    let class = order.u32(flags) & 0xff;
    let complex = order.u32(flags) & 0x0800 != 0;
    // mxDOUBLE (6) to mxUINT64 (15) are numeric; cells, structures,
    // objects, text and sparse arrays are not.
    if !(6..=15).contains(&class) || complex {
        return Ok(None);
    }
    let (kind, dims_bytes, rest) = element(rest, order)?;
    if kind != 5 || dims_bytes.len() < 8 || dims_bytes.len() % 4 != 0 {
        return Err("a level-5 matrix without its dimensions".into());
    }
    let dims: Vec<usize> = dims_bytes
        .chunks_exact(4)
        .map(|d| order.u32(d) as i32)
        .map(|d| usize::try_from(d).map_err(|_| format!("a level-5 dimension of {d}")))
        .collect::<Result<_, _>>()?;
    let count = dims
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .filter(|&n| n <= MAX_BYTES)
        .ok_or("a level-5 matrix claims more values than the file could hold")?;
    let (_, name, rest) = element(rest, order)?;
    let name = c_string(name);
    let (kind, real, _) = element(rest, order)?;
    let size = match kind {
        1 | 2 => 1,
        3 | 4 => 2,
        5..=7 => 4,
        9 | 12 | 13 => 8,
        k => {
            return Err(format!(
                "matrix {name:?}: level-5 data type {k} is not numeric"
            ));
        }
    };
    if real.len() != count * size {
        return Err(format!(
            "matrix {name:?}: {} values declared, {} bytes of type {kind} stored",
            count,
            real.len()
        ));
    }
    let values = real
        .chunks_exact(size)
        .map(|b| number5(b, kind, order))
        .collect();
    Ok(Some((name, Matrix { dims, values })))
}

/// One value of level-5 data type `kind` from its bytes.
fn number5(b: &[u8], kind: u32, order: Order) -> f64 {
    macro_rules! get {
        ($t:ty) => {{
            let a = b.try_into().unwrap();
            if order.little {
                <$t>::from_le_bytes(a) as f64
            } else {
                <$t>::from_be_bytes(a) as f64
            }
        }};
    }
    match kind {
        1 => f64::from(b[0] as i8),
        2 => f64::from(b[0]),
        3 => get!(i16),
        4 => get!(u16),
        5 => get!(i32),
        6 => get!(u32),
        7 => get!(f32),
        9 => get!(f64),
        12 => get!(i64),
        _ => get!(u64),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level-4 variable: little-endian doubles, column-major.
    fn v4(name: &str, rows: usize, cols: usize, values: &[f64]) -> Vec<u8> {
        let mut b = Vec::new();
        for w in [0, rows as i32, cols as i32, 0, name.len() as i32 + 1] {
            b.extend(w.to_le_bytes());
        }
        b.extend(name.as_bytes());
        b.push(0);
        for v in values {
            b.extend(v.to_le_bytes());
        }
        b
    }

    #[test]
    fn level_4_matrices_are_read_column_by_column() {
        let mut b = v4("M", 2, 2, &[1.0, 2.0, 3.0, 4.0]);
        b.extend(v4("mat", 1, 3, &[5.0, 6.0, 7.0]));
        let m = matrices(&b).unwrap();
        assert_eq!(m[0].0, "M");
        assert_eq!(m[0].1.at(0, 1), 3.0);
        assert_eq!(m[1].1.dims, vec![1, 3]);
        assert_eq!(m[1].1.values, vec![5.0, 6.0, 7.0]);
    }

    #[test]
    fn truncated_or_lying_files_are_refused_in_words() {
        let b = v4("M", 4, 4, &[0.0; 16]);
        for n in [3, 19, 25, b.len() - 1] {
            assert!(matrices(&b[..n]).is_err(), "{n}");
        }
        let mut lying = b.clone();
        lying[4..8].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(matrices(&lying).unwrap_err().contains("claims more data"));
        let mut h5 = b"MATLAB 7.3 MAT-file".to_vec();
        h5.resize(128, b' ');
        assert!(matrices(&h5).unwrap_err().contains("HDF5"));
    }
}
