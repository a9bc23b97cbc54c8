//! Tile-compressed FITS images (FITS Standard 4.0 §10; Pence, Seaman &
//! White 2010): an image cut into tiles, each tile compressed into one
//! row of a BINTABLE marked `ZIMAGE = T`, as `fpack` and astropy's
//! `CompImageHDU` write them, and as archives ship solar and survey images
//! (SDO/AIA, Pan-STARRS, DECam).
//!
//! The table's header describes the image with Z keywords (`ZBITPIX`,
//! `ZNAXISn`, `ZTILEn`, `ZCMPTYPE`, `ZNAMEi`/`ZVALi`, `ZQUANTIZ`,
//! `ZDITHER0`, `ZBLANK`), and keeps the image's other keywords (BSCALE,
//! BZERO, the WCS) as they were. [`image_of`] makes the image's HDU from
//! them, which the reader lays out as any image; [`decompress`] reads the
//! table and gives the image's samples as the big-endian bytes an
//! uncompressed image of `ZBITPIX` would hold, which the reader then
//! scales as any (BSCALE, BZERO, BLANK).
//!
//! Per tile, in the order the rows run (NAXIS1's tiles fastest):
//! 1. the bytes: the `COMPRESSED_DATA` column's array in the heap; where it
//!    is empty, `GZIP_COMPRESSED_DATA` (a tile that did not quantise,
//!    gzipped as it was) or `UNCOMPRESSED_DATA` (§10.1.2);
//! 2. the integers: Rice (`RICE_1`, §10.4.1: blocks of `BLOCKSIZE`
//!    differences, each with its split, `BYTEPIX` wide) or gzip
//!    (`GZIP_1`; `GZIP_2` with the bytes shuffled by significance);
//! 3. for a floating-point image, the values: integer · `ZSCALE` + `ZZERO`
//!    of the row, with subtractive dithering undone (§10.2:
//!    `SUBTRACTIVE_DITHER_1`/`_2`, the standard's random sequence), and the
//!    null integer as NaN.
//!
//! `PLIO_1` and `HCOMPRESS_1` are refused by name (`funpack` writes the
//! image uncompressed). Every size is checked: the table against its
//! declared length (which the reader checked against the file), every heap
//! array against the heap, the image against `--max-memory` before it is
//! allocated, and each tile's decoded length against its tile.

use std::path::Path;

use super::header::{Hdu, Kind};
use super::rice::rice;
use super::source::Source;
use crate::error::IoError;
use crate::shared::compress::{Compression, inflate_exact};

/// §10.2: the integer that marks an undefined value of a quantised tile.
const NULL_VALUE: i64 = -2_147_483_647;
/// §10.2: `SUBTRACTIVE_DITHER_2`'s integer for an exact zero.
const ZERO_VALUE: i64 = -2_147_483_646;
/// §10.2: the length of the dithering's random sequence.
const RANDOMS: usize = 10_000;

/// The image a compressed table holds, as an image HDU: its BITPIX and
/// axes from `ZBITPIX` and `ZNAXISn`, its header the table's (BSCALE,
/// BZERO and the WCS are the image's), with `ZBLANK` as the BLANK of an
/// integer image.
pub(super) fn image_of(table: &Hdu) -> Result<Hdu, String> {
    let h = &table.header;
    let bitpix = match h.int("ZBITPIX")? {
        Some(b @ (8 | 16 | 32 | 64 | -32 | -64)) => b as i32,
        Some(b) => return Err(format!("ZBITPIX = {b} is not a FITS sample type")),
        None => return Err("a compressed image without ZBITPIX".into()),
    };
    let naxis = h
        .int("ZNAXIS")?
        .ok_or("a compressed image without ZNAXIS")?;
    if !(0..=999).contains(&naxis) {
        return Err(format!("ZNAXIS = {naxis}"));
    }
    let mut naxes = Vec::new();
    for a in 1..=naxis {
        let n = h
            .int(&format!("ZNAXIS{a}"))?
            .ok_or(format!("ZNAXIS{a} is missing"))?;
        naxes.push(u64::try_from(n).map_err(|_| format!("ZNAXIS{a} = {n}"))?);
    }
    let mut header = h.clone();
    if bitpix > 0
        && h.get("BLANK").is_none()
        && let Some(card) = h.cards.iter().find(|c| c.key == "ZBLANK")
    {
        let mut blank = card.clone();
        blank.key = "BLANK".into();
        header.cards.push(blank);
    }
    let samples: u128 = naxes.iter().map(|&n| u128::from(n)).product();
    Ok(Hdu {
        index: table.index,
        kind: Kind::Image,
        header,
        bitpix,
        naxes,
        data_start: 0,
        data_bytes: samples * u128::from(bitpix.unsigned_abs() / 8),
    })
}

/// How the tiles are compressed.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Method {
    Rice { block: usize, bytepix: usize },
    Gzip { shuffled: bool },
}

/// How a floating-point image's tiles were quantised.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Quantised {
    No,
    Dither { zero_exact: bool, seed: i64 },
}

/// A column of the table: where it sits in a row, and its TFORM type.
#[derive(Debug, Clone, Copy)]
struct Column {
    offset: usize,
    /// `P` or `Q`: an array in the heap; else the fixed type's letter.
    kind: u8,
    /// For an array, the type of its elements.
    element: u8,
}

/// The bytes of TFORM type `t`, repeated `r` times (Table 18).
fn width(t: u8, r: usize) -> Option<usize> {
    let each = match t {
        b'L' | b'B' | b'A' => 1,
        b'X' => return Some(r.div_ceil(8)),
        b'I' => 2,
        b'J' | b'E' => 4,
        b'K' | b'D' | b'C' | b'P' => 8,
        b'M' | b'Q' => 16,
        _ => return None,
    };
    r.checked_mul(each)
}

/// The table's columns by TTYPE, with their offsets in a row.
fn columns(table: &Hdu) -> Result<Vec<(String, Column)>, String> {
    let h = &table.header;
    let fields = h.int("TFIELDS")?.unwrap_or(0);
    if !(0..=999).contains(&fields) {
        return Err(format!("TFIELDS = {fields}"));
    }
    let mut offset = 0usize;
    let mut out = Vec::new();
    for i in 1..=fields {
        let form = h.string(&format!("TFORM{i}")).unwrap_or_default();
        let form = form.trim();
        let digits = form.bytes().take_while(u8::is_ascii_digit).count();
        let repeat = match digits {
            0 => 1,
            _ => form[..digits]
                .parse()
                .map_err(|_| format!("TFORM{i} = '{form}'"))?,
        };
        let kind = *form
            .as_bytes()
            .get(digits)
            .ok_or(format!("TFORM{i} = '{form}'"))?;
        let element = form.as_bytes().get(digits + 1).copied().unwrap_or(0);
        let bytes = width(kind, repeat).ok_or(format!("TFORM{i} = '{form}'"))?;
        let name = h.string(&format!("TTYPE{i}")).unwrap_or_default();
        out.push((
            name.trim().to_ascii_uppercase(),
            Column {
                offset,
                kind,
                element,
            },
        ));
        offset = offset.checked_add(bytes).ok_or("the columns overflow")?;
    }
    Ok(out)
}

/// The table's bytes: rows, then the heap.
struct Table<'a> {
    rows: &'a [u8],
    row_bytes: usize,
    heap: &'a [u8],
}

impl Table<'_> {
    fn row(&self, r: usize) -> &[u8] {
        &self.rows[r * self.row_bytes..(r + 1) * self.row_bytes]
    }

    /// The heap array of column `c` in row `r` (`P`: two 32-bit, `Q`: two
    /// 64-bit integers, the count and the offset; §7.3.5).
    fn array(&self, r: usize, c: &Column) -> Result<&[u8], String> {
        let row = self.row(r);
        let field = |n: usize| {
            row.get(c.offset..c.offset + n)
                .ok_or("a descriptor past its row")
        };
        let (count, offset) = match c.kind {
            b'P' => {
                let b = field(8)?;
                let count = i32::from_be_bytes([b[0], b[1], b[2], b[3]]);
                let offset = i32::from_be_bytes([b[4], b[5], b[6], b[7]]);
                (i64::from(count), i64::from(offset))
            }
            b'Q' => {
                let b = field(16)?;
                let at = |i: usize| {
                    let mut a = [0u8; 8];
                    a.copy_from_slice(&b[i..i + 8]);
                    i64::from_be_bytes(a)
                };
                (at(0), at(8))
            }
            _ => return Err("a compressed-data column that is not an array (P or Q)".into()),
        };
        let size = width(c.element, 1).ok_or("an array of an unknown type")?;
        let (Ok(count), Ok(offset)) = (usize::try_from(count), usize::try_from(offset)) else {
            return Err(format!("row {r}: an array of {count} at {offset}"));
        };
        let end = count.checked_mul(size).and_then(|n| n.checked_add(offset));
        end.and_then(|end| self.heap.get(offset..end)).ok_or(format!(
            "row {r}: an array of {count} elements at heap byte {offset} runs past the {}-byte heap",
            self.heap.len()
        ))
    }

    /// A fixed-width number of column `c` in row `r` (`D`, `E`, `J`, `K`,
    /// `I`, `B`), as `f64`.
    fn number(&self, r: usize, c: &Column) -> Result<f64, String> {
        let row = self.row(r);
        let n = width(c.kind, 1).ok_or("a column of an unknown type")?;
        let b = row
            .get(c.offset..c.offset + n)
            .ok_or("a column past its row")?;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        Ok(match c.kind {
            b'D' => f64::from_be_bytes(a),
            b'E' => f64::from(f32::from_be_bytes([a[0], a[1], a[2], a[3]])),
            b'K' => i64::from_be_bytes(a) as f64,
            b'J' => f64::from(i32::from_be_bytes([a[0], a[1], a[2], a[3]])),
            b'I' => f64::from(i16::from_be_bytes([a[0], a[1]])),
            b'B' => f64::from(a[0]),
            _ => return Err("a scale column that is not a number".into()),
        })
    }
}

/// Reads the compressed table `table` (`src` at its data) and gives the
/// samples of `image` ([`image_of`]) as big-endian bytes of its BITPIX.
pub(super) fn decompress(
    path: &Path,
    src: &mut Source,
    table: &Hdu,
    image: &Hdu,
    max_memory: u64,
) -> Result<Vec<u8>, IoError> {
    let bad = |reason: String| IoError::invalid(path, format!("{}: {reason}", table.name()));
    let need = table.data_bytes + image.data_bytes;
    if need > u128::from(max_memory) {
        return Err(IoError::invalid(
            path,
            format!(
                "{}: the compressed table ({} bytes) and the image it holds ({} bytes) are more than the memory limit of {max_memory} bytes",
                table.name(),
                table.data_bytes,
                image.data_bytes
            ),
        ));
    }
    let mut data = vec![0u8; table.data_bytes as usize];
    src.fill(path, &mut data, &format!("{} data", table.name()))?;
    tiles(path, table, image, &data).map_err(bad)
}

/// The image's bytes from the table's `data` (see the module doc).
fn tiles(path: &Path, table: &Hdu, image: &Hdu, data: &[u8]) -> Result<Vec<u8>, String> {
    let h = &table.header;
    let row_bytes =
        usize::try_from(*table.naxes.first().unwrap_or(&0)).map_err(|e| e.to_string())?;
    let rows = usize::try_from(*table.naxes.get(1).unwrap_or(&0)).map_err(|e| e.to_string())?;
    let main = row_bytes
        .checked_mul(rows)
        .filter(|&m| m <= data.len())
        .ok_or("the rows run past the data")?;
    let heap_start = match h.int("THEAP")? {
        Some(t) => usize::try_from(t).map_err(|_| format!("THEAP = {t}"))?,
        None => main,
    };
    let table_bytes = Table {
        rows: &data[..main],
        row_bytes,
        heap: data
            .get(heap_start..)
            .ok_or(format!("THEAP = {heap_start} is past the data"))?,
    };
    let cols = columns(table)?;
    let col = |name: &str| cols.iter().find(|(n, _)| n == name).map(|(_, c)| *c);
    let compressed = col("COMPRESSED_DATA").ok_or("no COMPRESSED_DATA column")?;
    let gzip_column = col("GZIP_COMPRESSED_DATA");
    let raw_column = col("UNCOMPRESSED_DATA");
    let (zscale, zzero, zblank) = (col("ZSCALE"), col("ZZERO"), col("ZBLANK"));

    let method_name = h.string("ZCMPTYPE").unwrap_or_default().trim().to_string();
    let param = |name: &str| -> Result<Option<i128>, String> {
        for i in 1..=99 {
            match h.string(&format!("ZNAME{i}")) {
                Some(n) if n.trim().eq_ignore_ascii_case(name) => {
                    return h.int(&format!("ZVAL{i}"));
                }
                Some(_) => {}
                None => break,
            }
        }
        Ok(None)
    };
    let float = image.bitpix < 0;
    let int_bytes = if float {
        4
    } else {
        image.bitpix.unsigned_abs() as usize / 8
    };
    let method = match method_name.as_str() {
        "RICE_1" | "RICE_ONE" => {
            let block = param("BLOCKSIZE")?.unwrap_or(32);
            let bytepix = param("BYTEPIX")?.unwrap_or(int_bytes as i128);
            if !(1..=1024).contains(&block) || !matches!(bytepix, 1 | 2 | 4 | 8) {
                return Err(format!("Rice BLOCKSIZE {block}, BYTEPIX {bytepix}"));
            }
            Method::Rice {
                block: block as usize,
                bytepix: bytepix as usize,
            }
        }
        "GZIP_1" => Method::Gzip { shuffled: false },
        "GZIP_2" => Method::Gzip { shuffled: true },
        other => {
            return Err(format!(
                "ZCMPTYPE '{other}' is not read (RICE_1, GZIP_1 and GZIP_2 are): write the image uncompressed first (funpack, or astropy's ImageHDU)"
            ));
        }
    };
    let quantised = match h.string("ZQUANTIZ").map(|q| q.trim().to_ascii_uppercase()) {
        _ if !float => Quantised::No,
        Some(q) if q == "NO_DITHER" || q == "NONE" => Quantised::No,
        Some(q) if q == "SUBTRACTIVE_DITHER_1" || q == "SUBTRACTIVE_DITHER_2" => {
            let seed = h.int("ZDITHER0")?.unwrap_or(1);
            Quantised::Dither {
                zero_exact: q.ends_with('2'),
                seed: i64::try_from(seed).map_err(|_| format!("ZDITHER0 = {seed}"))?,
            }
        }
        Some(q) => {
            return Err(format!(
                "ZQUANTIZ = '{q}' is not a quantisation volray knows"
            ));
        }
        None => Quantised::No,
    };
    if !float && zblank.is_some() {
        return Err("a ZBLANK column in an integer image (one BLANK per tile) is not read".into());
    }

    // The tile grid.
    let dims: Vec<usize> = (image.naxes.iter())
        .map(|&n| usize::try_from(n).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let mut tile = Vec::with_capacity(dims.len());
    for (a, &n) in dims.iter().enumerate() {
        let t = h
            .int(&format!("ZTILE{}", a + 1))?
            .unwrap_or(if a == 0 { n as i128 } else { 1 });
        if t < 1 {
            return Err(format!("ZTILE{} = {t}", a + 1));
        }
        tile.push((t as usize).min(n.max(1)));
    }
    let counts: Vec<usize> = dims
        .iter()
        .zip(&tile)
        .map(|(&n, &t)| n.div_ceil(t))
        .collect();
    let total_tiles: usize = counts.iter().product();
    if total_tiles != rows {
        return Err(format!(
            "{rows} rows for {total_tiles} tiles of ZTILEn {tile:?}"
        ));
    }
    let size = image.bitpix.unsigned_abs() as usize / 8;
    let samples: usize = dims.iter().product();
    let mut out = vec![0u8; samples * size];
    let randoms = matches!(quantised, Quantised::Dither { .. }).then(randoms);
    let mut corner = vec![0usize; dims.len()];
    for row in 0..rows {
        // The tile's box, and its samples.
        let extent: Vec<usize> = (0..dims.len())
            .map(|a| tile[a].min(dims[a] - corner[a] * tile[a]))
            .collect();
        let n: usize = extent.iter().product();
        let what = |e: String| format!("tile {row}: {e}");
        let ints_bytes = table_bytes.array(row, &compressed).map_err(what)?;
        if float && zscale.is_none() && !ints_bytes.is_empty() {
            // Not quantised: the floats themselves, gzipped (`ZQUANTIZ =
            // 'NONE'`), their bytes shuffled by significance for GZIP_2.
            let Method::Gzip { shuffled } = method else {
                return Err(what(
                    "Rice-coded floats that were not quantised (no ZSCALE)".into(),
                ));
            };
            let raw = gunzip(path, ints_bytes, n * size).map_err(what)?;
            let raw = match shuffled {
                false => raw,
                true => (0..n * size)
                    .map(|j| raw[(j % size) * n + j / size])
                    .collect(),
            };
            place(&mut out, &raw, size, &dims, &corner, &tile, &extent);
            advance(&mut corner, &counts);
            continue;
        }
        let values: Vec<f64> = if !ints_bytes.is_empty() {
            let ints = match method {
                Method::Rice { block, bytepix } => rice(ints_bytes, n, block, bytepix),
                Method::Gzip { shuffled } => gunzip_ints(path, ints_bytes, n, int_bytes, shuffled),
            }
            .map_err(what)?;
            match (float, quantised) {
                (false, _) => ints.iter().map(|&i| i as f64).collect(),
                (true, q) => {
                    let number = |c: Option<Column>, name: &str| {
                        let c = c.ok_or(format!("a quantised tile without a {name} column"))?;
                        table_bytes.number(row, &c)
                    };
                    let scale = number(zscale, "ZSCALE").map_err(what)?;
                    let zero = number(zzero, "ZZERO").map_err(what)?;
                    let null = match zblank {
                        Some(c) => Some(table_bytes.number(row, &c).map_err(what)? as i64),
                        None => h.int("ZBLANK")?.map(|b| b as i64),
                    };
                    let null = null.unwrap_or(NULL_VALUE);
                    unquantise(&ints, scale, zero, null, q, row, randoms.as_deref())
                }
            }
        } else if let Some(c) = gzip_column.or(raw_column) {
            let bytes = table_bytes.array(row, &c).map_err(what)?;
            let raw = match gzip_column {
                Some(_) => gunzip(path, bytes, n * size).map_err(what)?,
                None => bytes.to_vec(),
            };
            if raw.len() != n * size {
                return Err(what(format!("{} bytes for {n} samples", raw.len())));
            }
            // Written as stored: the samples' bytes as they go out.
            place(&mut out, &raw, size, &dims, &corner, &tile, &extent);
            advance(&mut corner, &counts);
            continue;
        } else {
            return Err(what("no data in any column".into()));
        };
        let raw = to_bytes(&values, image.bitpix);
        place(&mut out, &raw, size, &dims, &corner, &tile, &extent);
        advance(&mut corner, &counts);
    }
    Ok(out)
}

/// The next tile's grid position (NAXIS1 fastest).
fn advance(corner: &mut [usize], counts: &[usize]) {
    for (c, &n) in corner.iter_mut().zip(counts) {
        *c += 1;
        if *c < n {
            return;
        }
        *c = 0;
    }
}

/// Copies a tile's samples (`raw`, `size` bytes each, its first axis
/// fastest over `extent`) into the image at tile position `corner`.
fn place(
    out: &mut [u8],
    raw: &[u8],
    size: usize,
    dims: &[usize],
    corner: &[usize],
    tile: &[usize],
    extent: &[usize],
) {
    let run = extent[0] * size;
    let lines: usize = extent[1..].iter().product();
    let mut at = vec![0usize; extent.len()];
    for line in 0..lines {
        // The image index of the line's first sample.
        let mut index = 0;
        let mut stride = 1;
        for a in 0..dims.len() {
            index += (corner[a] * tile[a] + at[a]) * stride;
            stride *= dims[a];
        }
        out[index * size..index * size + run].copy_from_slice(&raw[line * run..(line + 1) * run]);
        for a in 1..extent.len() {
            at[a] += 1;
            if at[a] < extent[a] {
                break;
            }
            at[a] = 0;
        }
    }
}

/// `values` as big-endian samples of `bitpix`.
fn to_bytes(values: &[f64], bitpix: i32) -> Vec<u8> {
    let mut out = Vec::with_capacity(values.len() * bitpix.unsigned_abs() as usize / 8);
    for &v in values {
        match bitpix {
            8 => out.push(v as i64 as u8),
            16 => out.extend((v as i64 as i16).to_be_bytes()),
            32 => out.extend((v as i64 as i32).to_be_bytes()),
            64 => out.extend((v as i64).to_be_bytes()),
            -32 => out.extend((v as f32).to_be_bytes()),
            _ => out.extend(v.to_be_bytes()),
        }
    }
    out
}

/// Inflates a gzip (or zlib) stream of the file `path` that should hold
/// exactly `expected` bytes (volray-io's `inflate_exact`: bounded by
/// deflate's ratio before it allocates), its refusal without the path,
/// which the caller names.
fn gunzip(path: &Path, bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    let kind = match bytes.starts_with(&[0x1f, 0x8b]) {
        true => Compression::Gzip,
        false => Compression::Zlib,
    };
    inflate_exact(path, bytes, kind, expected, "the tile").map_err(|e| {
        let message = e.to_string();
        let prefix = format!("{}: ", path.display());
        message
            .strip_prefix(&prefix)
            .map_or(message.clone(), str::to_string)
    })
}

/// `GZIP_1`/`GZIP_2`: `n` big-endian integers of `bytes` bytes, the
/// bytes grouped by significance (most significant of every value first)
/// where `shuffled`.
fn gunzip_ints(
    path: &Path,
    data: &[u8],
    n: usize,
    bytes: usize,
    shuffled: bool,
) -> Result<Vec<i64>, String> {
    let raw = gunzip(path, data, n * bytes)?;
    let byte = |i: usize, k: usize| {
        if shuffled {
            raw[k * n + i]
        } else {
            raw[i * bytes + k]
        }
    };
    Ok((0..n)
        .map(|i| {
            let mut a = [0u8; 8];
            for k in 0..bytes {
                a[8 - bytes + k] = byte(i, k);
            }
            // Sign-extended from `bytes` bytes; a byte image is unsigned.
            let v = i64::from_be_bytes(a);
            match bytes {
                1 => v,
                2 => i64::from(v as u16 as i16),
                4 => i64::from(v as u32 as i32),
                _ => v,
            }
        })
        .collect())
}

/// The standard's random sequence for dithering (§10.2, Park and Miller's
/// minimal standard generator from seed 1): 10,000 values in (0, 1).
fn randoms() -> Vec<f64> {
    let (a, m) = (16_807.0f64, 2_147_483_647.0f64);
    let mut seed = 1.0f64;
    (0..RANDOMS)
        .map(|_| {
            let t = a * seed;
            seed = t - m * (t / m).floor();
            seed / m
        })
        .collect()
}

/// A quantised tile's values (§10.2): `(i − r + 0.5)·scale + zero` with
/// subtractive dithering, `i·scale + zero` without; `null` is NaN and,
/// for `SUBTRACTIVE_DITHER_2`, its zero integer an exact 0. The tile's
/// random start is `(row + ZDITHER0 − 1) mod 10000` (rows from 0).
fn unquantise(
    ints: &[i64],
    scale: f64,
    zero: f64,
    null: i64,
    q: Quantised,
    row: usize,
    randoms: Option<&[f64]>,
) -> Vec<f64> {
    let (Quantised::Dither { zero_exact, seed }, Some(r)) = (q, randoms) else {
        return (ints.iter())
            .map(|&i| {
                if i == null {
                    f64::NAN
                } else {
                    i as f64 * scale + zero
                }
            })
            .collect();
    };
    let mut iseed = (row as i64 + seed - 1).rem_euclid(RANDOMS as i64) as usize;
    let mut next = (r[iseed] * 500.0) as usize;
    let mut out = Vec::with_capacity(ints.len());
    for &i in ints {
        out.push(if i == null {
            f64::NAN
        } else if zero_exact && i == ZERO_VALUE {
            0.0
        } else {
            (i as f64 - r[next] + 0.5) * scale + zero
        });
        next += 1;
        if next == RANDOMS {
            iseed = (iseed + 1) % RANDOMS;
            next = (r[iseed] * 500.0) as usize;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dithering_sequence_is_the_standards() {
        // §10.2: the 10,000th seed of the generator is 1043618065.
        let r = randoms();
        assert_eq!((r[RANDOMS - 1] * 2_147_483_647.0).round(), 1_043_618_065.0);
        assert!(r.iter().all(|&v| v > 0.0 && v < 1.0));
    }

    #[test]
    fn unquantising_without_dither_is_affine_and_null_is_nan() {
        let v = unquantise(
            &[0, 2, NULL_VALUE],
            0.5,
            10.0,
            NULL_VALUE,
            Quantised::No,
            0,
            None,
        );
        assert_eq!(&v[..2], &[10.0, 11.0]);
        assert!(v[2].is_nan());
    }
}
