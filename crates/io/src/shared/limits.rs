//! The memory limit (`--max-memory`) and the size checks every reader
//! makes on a header's dimensions before it allocates anything.
//!
//! A header is a claim: `sizes 4000 4000 4000` asks for 238 GiB of `f32`.
//! Readers first check the claim against the file (each in its own terms:
//! raw bytes, deflate's ratio, text's shortest number), and all of them
//! check it here against the limit, in one arithmetic: the product of the
//! dimensions in `u128` (no product of a handful of `u64`s can wrap it
//! unnoticed: each multiplication is checked), times the bytes a value
//! takes while reading (the `f32` volume, plus any stored samples the
//! reader holds whole), compared with [`ReadOptions::max_memory`].
//!
//! The limit bounds what a reader keeps: the decoded volume and any whole
//! stored payload. Fixed scratch (chunks of 64 Ki samples), and the copy
//! [`grid_to_volume`] makes when it reorders axes, are not counted.
//!
//! [`ReadOptions::max_memory`]: crate::ReadOptions::max_memory
//! [`grid_to_volume`]: crate::grid_to_volume

use std::fmt::Write as _;
use std::path::Path;
use std::sync::OnceLock;

use crate::error::IoError;

/// The limit when physical memory cannot be read: 4 GiB.
pub const FALLBACK_MAX_MEMORY: u64 = 4 << 30;

/// Bytes of one decoded value: volumes are `f32`.
pub const F32_BYTES: u64 = 4;

/// The default `--max-memory`: half the physical memory (`MemTotal` in
/// `/proc/meminfo`), leaving the rest to the renderer's own structures and
/// the rest of the machine; [`FALLBACK_MAX_MEMORY`] where that cannot be
/// read. Read once per process.
pub fn default_max_memory() -> u64 {
    static DEFAULT: OnceLock<u64> = OnceLock::new();
    *DEFAULT.get_or_init(|| {
        std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| mem_total(&text))
            .map_or(FALLBACK_MAX_MEMORY, |total| total / 2)
    })
}

/// `MemTotal` of a `/proc/meminfo` text, in bytes (the file gives kB,
/// meaning KiB).
fn mem_total(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let mut words = line["MemTotal:".len()..].split_whitespace();
    let kib: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") | None => kib.checked_mul(1024).filter(|&b| b > 0),
        Some(_) => None,
    }
}

/// Parses a `--max-memory` size: plain bytes (`1000000`), or a number
/// (fractions allowed) with a binary unit `K`, `M`, `G`, `T`, each
/// optionally followed by `B` or `iB`, in either case (`512M`, `4G`,
/// `1.5GiB`, `64kb`); a trailing `B` alone means bytes. Every unit is a
/// power of 1024. Zero, negative, non-finite and unit-less fractions are
/// refused, as is anything past `u64::MAX` bytes.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let s = text.trim();
    let bad = || {
        format!(
            "\"{text}\" is not a size: give bytes, or a number with K, M, G or T (powers of 1024), e.g. 512M, 4G, 1.5GiB"
        )
    };
    let split = s
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(s.len());
    let (number, unit) = (&s[..split], s[split..].trim_start());
    if number.is_empty() {
        return Err(bad());
    }
    let shift = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => return Err(bad()),
    };
    let bytes = if let Ok(whole) = number.parse::<u64>() {
        whole
            .checked_mul(1 << shift)
            .ok_or_else(|| format!("\"{text}\" is more than {} bytes", u64::MAX))?
    } else {
        let value: f64 = number.parse().map_err(|_| bad())?;
        if shift == 0 {
            return Err(format!("\"{text}\": a number of bytes must be whole"));
        }
        let bytes = value * (1u64 << shift) as f64;
        if !(bytes.is_finite() && bytes < u64::MAX as f64) {
            return Err(format!("\"{text}\" is more than {} bytes", u64::MAX));
        }
        bytes.floor() as u64
    };
    if bytes == 0 {
        return Err(format!(
            "\"{text}\": the memory limit must be at least 1 byte"
        ));
    }
    Ok(bytes)
}

/// `bytes` for messages, in the largest binary unit that keeps a number of
/// at least 1: `1000 bytes`, `1.5 KiB`, `12 GiB`, `238 GiB` (one decimal
/// below 10, none above).
pub fn format_bytes(bytes: u128) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if bytes < 1024 {
        return format!("{bytes} bytes");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    let number = if value < 10.0 {
        let s = format!("{value:.1}");
        s.strip_suffix(".0").map(str::to_string).unwrap_or(s)
    } else {
        format!("{value:.0}")
    };
    format!("{number} {}", UNITS[unit])
}

/// A count of values for messages: exact below a million, else in
/// scientific notation with two significant digits (`6.4e10`).
fn format_count(count: u128) -> String {
    if count < 1_000_000 {
        return count.to_string();
    }
    let text = format!("{:.1e}", count as f64);
    text.replace(".0e", "e")
}

/// `dims` as a header writes them: separated by spaces.
fn dims_text(dims: &[u64]) -> String {
    let mut s = String::new();
    for (i, d) in dims.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{d}");
    }
    s
}

/// The number of values an array of `dims` holds, refused (naming the
/// file, `field` and the values) if a dimension is 0 or the product does
/// not fit this machine's `usize`. The product is taken in `u128` with
/// checked multiplications, so it never wraps.
pub fn count_values(path: &Path, field: &str, dims: &[u64]) -> Result<usize, IoError> {
    if let Some(axis) = dims.iter().position(|&d| d == 0) {
        return Err(IoError::invalid(
            path,
            format!(
                "{field} {}: axis {axis} has size 0, so the file holds no volume",
                dims_text(dims)
            ),
        ));
    }
    let product = dims
        .iter()
        .try_fold(1u128, |acc, &d| acc.checked_mul(u128::from(d)));
    product
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "{field} {}: {} values, more than this machine can address",
                    dims_text(dims),
                    product.map_or_else(|| "over 3.4e38".to_string(), format_count)
                ),
            )
        })
}

/// Refuses `values` values of `bytes_per_value` bytes each if they exceed
/// `max_memory`. `what` is the field and its value as the file gives them
/// (`sizes 4000 4000 4000`), for the message.
pub fn check_memory(
    path: &Path,
    what: &str,
    values: u128,
    bytes_per_value: u64,
    max_memory: u64,
) -> Result<(), IoError> {
    let bytes = values.saturating_mul(u128::from(bytes_per_value));
    let held = if bytes_per_value == F32_BYTES {
        format!("{} as f32", format_bytes(bytes))
    } else {
        format!(
            "{} at {bytes_per_value} byte{} a value",
            format_bytes(bytes),
            if bytes_per_value == 1 { "" } else { "s" }
        )
    };
    check_held(path, what, values, bytes, &held, max_memory)
}

/// [`check_memory`] for a reader whose peak is not a whole number of
/// bytes per value: `bytes` in all, described by `held`.
pub(crate) fn check_held(
    path: &Path,
    what: &str,
    values: u128,
    bytes: u128,
    held: &str,
    max_memory: u64,
) -> Result<(), IoError> {
    if bytes <= u128::from(max_memory) {
        return Ok(());
    }
    Err(IoError::over_memory_limit(
        path,
        format!("{what} ({} values, {held}) exceed", format_count(values)),
        max_memory,
    ))
}

/// Refuses a file of `len` bytes that a reader must hold whole in memory
/// (an XML or text format whose parser needs all of it) if it exceeds
/// `max_memory`.
pub fn check_file_held(path: &Path, len: u64, max_memory: u64) -> Result<(), IoError> {
    if len <= max_memory {
        return Ok(());
    }
    Err(IoError::over_memory_limit(
        path,
        format!(
            "the file is {} and is read whole: more than",
            format_bytes(u128::from(len))
        ),
        max_memory,
    ))
}

/// The one check every reader makes on a header's dimensions before
/// allocating: `dims` (as `field` gives them) must be non-zero and their
/// product must fit (see [`count_values`]), and that many values of
/// `element_bytes` each (4 for the `f32` volume, plus the stored sample
/// size where the reader holds the stored data whole) must fit
/// `max_memory`. Returns the number of values.
///
/// ```
/// # use std::path::Path;
/// let err = volray_io::check_volume_size(
///     Path::new("a.nrrd"), "sizes", &[4000, 4000, 4000], 4, 12 << 30,
/// ).unwrap_err();
/// assert_eq!(
///     err.to_string(),
///     "a.nrrd: sizes 4000 4000 4000 (6.4e10 values, 238 GiB as f32) exceed the memory limit of 12 GiB"
/// );
/// assert!(matches!(err, volray_io::IoError::OverMemoryLimit { limit, .. } if limit == 12 << 30));
/// ```
pub fn check_volume_size(
    path: &Path,
    field: &str,
    dims: &[u64],
    element_bytes: u64,
    max_memory: u64,
) -> Result<usize, IoError> {
    let count = count_values(path, field, dims)?;
    check_memory(
        path,
        &format!("{field} {}", dims_text(dims)),
        count as u128,
        element_bytes,
        max_memory,
    )?;
    Ok(count)
}

/// [`check_volume_size`] for a file of `frames` volumes (`dims` includes
/// the frame axis) of which one is kept: every dimension is checked, the
/// memory one volume needs is compared with the limit. Returns the number
/// of values of the whole file.
pub fn check_frame_size(
    path: &Path,
    field: &str,
    dims: &[u64],
    frames: u64,
    element_bytes: u64,
    max_memory: u64,
) -> Result<usize, IoError> {
    let count = count_values(path, field, dims)?;
    let what = if frames > 1 {
        format!("{field} {}, one volume of {frames}", dims_text(dims))
    } else {
        format!("{field} {}", dims_text(dims))
    };
    let kept = count as u128 / u128::from(frames.max(1));
    check_memory(path, &what, kept, element_bytes, max_memory)?;
    Ok(count)
}

/// [`check_volume_size`] for dimensions a reader holds as `usize`.
pub(crate) fn check_dims(
    path: &Path,
    field: &str,
    dims: &[usize],
    element_bytes: u64,
    max_memory: u64,
) -> Result<usize, IoError> {
    check_volume_size(path, field, &to_u64(dims), element_bytes, max_memory)
}

/// [`check_frame_size`] for dimensions a reader holds as `usize`.
pub(crate) fn check_frame_dims(
    path: &Path,
    field: &str,
    dims: &[usize],
    frames: usize,
    element_bytes: u64,
    max_memory: u64,
) -> Result<usize, IoError> {
    let dims = to_u64(dims);
    check_frame_size(path, field, &dims, frames as u64, element_bytes, max_memory)
}

fn to_u64(dims: &[usize]) -> Vec<u64> {
    dims.iter().map(|&d| d as u64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        assert_eq!(parse_size("1000000"), Ok(1_000_000));
        assert_eq!(parse_size("1K"), Ok(1024));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("4g"), Ok(4 << 30));
        assert_eq!(parse_size("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_size("2 TB"), Ok(2 << 40));
        assert_eq!(parse_size("64kb"), Ok(64 << 10));
        assert_eq!(parse_size("7B"), Ok(7));
        assert_eq!(parse_size("0.5K"), Ok(512));
        for junk in [
            "",
            "0",
            "0G",
            "-1",
            "-4G",
            "G",
            "4X",
            "4GG",
            "1.5",
            "nan",
            "inf",
            "1e9",
            "4 G B",
            "0.0001K",
            "99999999999999999999",
            "16777216T",
        ] {
            assert!(parse_size(junk).is_err(), "{junk:?} accepted");
        }
        assert_eq!(parse_size("16777215T"), Ok(16_777_215 << 40));
    }

    #[test]
    fn bytes_and_counts_read_well() {
        assert_eq!(format_bytes(1000), "1000 bytes");
        assert_eq!(format_bytes(1536), "1.5 KiB");
        assert_eq!(format_bytes(12 << 30), "12 GiB");
        assert_eq!(format_bytes(256_000_000_000), "238 GiB");
        assert_eq!(format_count(999_999), "999999");
        assert_eq!(format_count(64_000_000_000), "6.4e10");
        assert_eq!(format_count(1 << 120), "1.3e36");
    }

    #[test]
    fn meminfo_gives_bytes() {
        let text = "MemTotal:       16318480 kB\nMemFree:         1000 kB\n";
        assert_eq!(mem_total(text), Some(16_318_480 * 1024));
        assert_eq!(mem_total("MemFree: 5 kB\n"), None);
        assert_eq!(mem_total("MemTotal: x kB\n"), None);
        assert_eq!(mem_total("MemTotal: 0 kB\n"), None);
        let d = default_max_memory();
        assert!(d >= 1 << 20, "{d}");
    }

    #[test]
    fn the_limit_is_exact_and_overflow_is_refused() {
        let p = Path::new("v.nrrd");
        // 10·10·10 f32 = 4000 bytes: 4000 passes, 3999 does not.
        assert_eq!(
            check_volume_size(p, "sizes", &[10, 10, 10], 4, 4000).unwrap(),
            1000
        );
        let err = check_volume_size(p, "sizes", &[10, 10, 10], 4, 3999).unwrap_err();
        assert_eq!(
            err.to_string(),
            "v.nrrd: sizes 10 10 10 (1000 values, 3.9 KiB as f32) exceed the memory limit of 3.9 KiB"
        );
        assert!(matches!(err, IoError::OverMemoryLimit { limit: 3999, .. }));
        assert!(!err.is_io_failure());
        let err = check_volume_size(p, "dim", &[10, 10, 10], 6, 5999).unwrap_err();
        assert!(err.to_string().contains("at 6 bytes a value"), "{err}");

        let huge = 1u64 << 40;
        let err = check_volume_size(p, "sizes", &[huge, huge, huge], 4, u64::MAX).unwrap_err();
        assert_eq!(
            err.to_string(),
            "v.nrrd: sizes 1099511627776 1099511627776 1099511627776: 1.3e36 values, more than this machine can address"
        );
        let err = count_values(p, "sizes", &[u64::MAX, u64::MAX, u64::MAX]).unwrap_err();
        assert!(err.to_string().contains("over 3.4e38"), "{err}");
        let err = count_values(p, "sizes", &[4, 0, 4]).unwrap_err();
        assert!(err.to_string().contains("axis 1 has size 0"), "{err}");
    }
}
