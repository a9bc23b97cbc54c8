//! gOpenMol plot files (`.plt`): the binary 3-D grids gOpenMol, VMD's
//! pltplugin and AutoDock-era tools exchange (orbitals, densities, probe
//! surfaces), read with volray's own parser.
//!
//! The layout (CSC, "gOpenMol plt file format", 2003, as quoted by
//! GridDataFormats' `gOpenMol.py`), either byte order:
//!
//! ```text
//! int32   rank                 always 3 (which tells the byte order)
//! int32   type of surface      1..50 user-defined, 100 OpenMol, 200.. programs: kept in the header
//! int32   nz, ny, nx           points along z, y, x
//! float32 zmin zmax ymin ymax xmin xmax
//! float32 values, x fastest, then y, then z
//! ```
//!
//! The grid runs from min to max inclusive: point `i` of `n` along x is at
//! `xmin + i·(xmax − xmin)/(n − 1)`, as gOpenMol and VMD's pltplugin place
//! it. (GridDataFormats instead takes min and max as the outer edges of
//! the cells, its origin half a cell in and its spacing `(max − min)/n`;
//! a note gives the difference.) Lengths are in ångström. A Fortran
//! "unformatted" file, whose records carry length words, and the
//! formatted text variant are refused by name.

use std::io::Read;
use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::{read_exact_at, read_samples};
use crate::shared::limits::{F32_BYTES, check_dims};
use crate::shared::packed::open_unpacked;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// The header's bytes: five int32 and six float32.
const HEADER: usize = 44;

/// The header's fields in one byte order.
struct Header {
    little: bool,
    surface: i32,
    /// nz, ny, nx as the file gives them.
    counts: [i32; 3],
    /// zmin, zmax, ymin, ymax, xmin, xmax.
    bounds: [f32; 6],
}

impl Header {
    /// The header in the byte order whose rank word reads 3.
    fn parse(head: &[u8]) -> Option<Header> {
        let head: &[u8; HEADER] = head.get(..HEADER)?.try_into().ok()?;
        [true, false].into_iter().find_map(|little| {
            let word = |i: usize| {
                let b = [
                    head[4 * i],
                    head[4 * i + 1],
                    head[4 * i + 2],
                    head[4 * i + 3],
                ];
                if little {
                    u32::from_le_bytes(b)
                } else {
                    u32::from_be_bytes(b)
                }
            };
            (word(0) == 3).then(|| Header {
                little,
                surface: word(1) as i32,
                counts: [word(2) as i32, word(3) as i32, word(4) as i32],
                bounds: [5, 6, 7, 8, 9, 10].map(|i| f32::from_bits(word(i))),
            })
        })
    }
}

/// Whether a file's first bytes are a plausible gOpenMol header: rank 3 in
/// either byte order, a surface type gOpenMol documents (1 to 50, 100,
/// 200 to 205), point counts from 1 to 2^20 and finite bounds, each
/// axis's max above its min.
pub(crate) fn sniff(head: &[u8]) -> bool {
    let Some(h) = Header::parse(head) else {
        return false;
    };
    let surface = matches!(h.surface, 1..=50 | 100 | 200..=205);
    let counts = h.counts.iter().all(|&n| (1..=1 << 20).contains(&n));
    let bounds = h.bounds.iter().all(|b| b.is_finite())
        && (0..3).all(|a| h.bounds[2 * a] < h.bounds[2 * a + 1]);
    surface && counts && bounds
}

/// Reads the gOpenMol plot file at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let mut info = FileInfo::new("float32");
    info.notes.extend(opened.note());
    let (len, packed) = (opened.len, opened.packing.is_some());
    let mut reader = opened.reader;
    let invalid = |reason: String| IoError::invalid(path, reason);

    let mut head = [0u8; HEADER];
    if len < HEADER as u64 {
        return Err(invalid(format!(
            "{len} bytes: shorter than the {HEADER}-byte gOpenMol plt header"
        )));
    }
    read_exact_at(path, &mut reader, &mut head, 0, HEADER as u64).map_err(|_| {
        invalid(format!(
            "shorter than the {HEADER}-byte gOpenMol plt header"
        ))
    })?;
    let Some(h) = Header::parse(&head) else {
        let first = u32::from_le_bytes([head[0], head[1], head[2], head[3]]);
        let why = if head[..8]
            .iter()
            .all(|b| b.is_ascii_digit() || b.is_ascii_whitespace())
        {
            "it starts with text: a formatted (text) plt file, which volray does not read; gOpenMol's pltfile converts it to binary".to_string()
        } else if first == 8 || first == 20 {
            format!(
                "its first word is {first}, a Fortran record length: a Fortran unformatted plt file, which volray does not read; gOpenMol's pltfile rewrites it as plain binary"
            )
        } else {
            "its first word is not 3 in either byte order".to_string()
        };
        return Err(invalid(format!("not a gOpenMol plt file (rank 3): {why}")));
    };
    info.stored_type = format!(
        "float32 ({}-endian)",
        if h.little { "little" } else { "big" }
    );
    let [nz, ny, nx] = h.counts;
    if let Some(&bad) = h.counts.iter().find(|&&n| n < 1) {
        return Err(invalid(format!(
            "point counts nz ny nx {nz} {ny} {nx}: {bad} is not a count"
        )));
    }
    let names = ["zmin", "zmax", "ymin", "ymax", "xmin", "xmax"];
    if let Some(i) = h.bounds.iter().position(|b| !b.is_finite()) {
        return Err(invalid(format!(
            "{} is {}: not a coordinate",
            names[i], h.bounds[i]
        )));
    }
    info.header = vec![
        ("rank".into(), "3".into()),
        ("surface type".into(), h.surface.to_string()),
        ("nz ny nx".into(), format!("{nz} {ny} {nx}")),
    ];
    for (name, b) in names.iter().zip(h.bounds) {
        info.header.push((name.to_string(), b.to_string()));
    }
    let dims = [nx as usize, ny as usize, nz as usize];
    let count = dims.iter().map(|&n| n as u64).product::<u64>();
    let need = HEADER as u64 + 4 * count;
    if need > len || (!packed && need != len) {
        return Err(invalid(format!(
            "the header declares {nx} x {ny} x {nz} float32 values ({need} bytes with the header), but the file {} {len} bytes",
            if packed {
                "can decompress to at most"
            } else {
                "holds"
            }
        )));
    }
    check_dims(path, "nz ny nx", &dims, F32_BYTES, opts.max_memory)?;
    let mut data = Vec::with_capacity(count as usize);
    let little = h.little;
    read_samples(
        path,
        &mut reader,
        count as usize,
        4,
        HEADER as u64,
        |bytes, out: &mut Vec<f32>| {
            out.extend(bytes.chunks_exact(4).map(|b| {
                let b = [b[0], b[1], b[2], b[3]];
                if little {
                    f32::from_le_bytes(b)
                } else {
                    f32::from_be_bytes(b)
                }
            }))
        },
        |values| data.extend_from_slice(values),
    )?;
    if packed
        && reader
            .read(&mut [0u8; 1])
            .map_err(|e| IoError::os(path, "read", e))?
            > 0
    {
        return Err(invalid(format!(
            "data follow the {count} float32 values the header declares"
        )));
    }

    // From min to max inclusive along each axis (x, y, z).
    let (lo, hi) = (
        DVec3::new(h.bounds[4].into(), h.bounds[2].into(), h.bounds[0].into()),
        DVec3::new(h.bounds[5].into(), h.bounds[3].into(), h.bounds[1].into()),
    );
    let mut steps = [DVec3::X, DVec3::Y, DVec3::Z];
    for a in 0..3 {
        if dims[a] > 1 {
            if lo[a] == hi[a] {
                return Err(invalid(format!(
                    "{} = {} = {}: an axis of {} points with no extent",
                    names[4 - 2 * a],
                    names[5 - 2 * a],
                    lo[a],
                    dims[a]
                )));
            }
            steps[a] *= (hi[a] - lo[a]) / (dims[a] - 1) as f64;
        }
    }
    info.length_unit = Some("angstrom".into());
    info.notes.push(
        "the grid runs from min to max inclusive (gOpenMol, VMD); GridDataFormats takes min and max as the cells' outer edges, half a cell out".into(),
    );
    let volume = grid_to_volume(path, dims, data, steps, lo, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Plt,
        info,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(little: bool, words: [u32; 5], bounds: [f32; 6]) -> Vec<u8> {
        let mut out = Vec::new();
        for w in words.into_iter().chain(bounds.map(f32::to_bits)) {
            out.extend(if little {
                w.to_le_bytes()
            } else {
                w.to_be_bytes()
            });
        }
        out
    }

    #[test]
    fn the_sniffer_takes_either_byte_order_and_plausible_fields_only() {
        let b = [0.0, 1.0, 0.0, 2.0, 0.0, 3.0];
        assert!(sniff(&header(true, [3, 200, 2, 3, 4], b)));
        assert!(sniff(&header(false, [3, 2, 2, 3, 4], b)));
        assert!(!sniff(&header(true, [4, 200, 2, 3, 4], b)));
        assert!(!sniff(&header(true, [3, 99, 2, 3, 4], b)));
        assert!(!sniff(&header(true, [3, 200, 0, 3, 4], b)));
        assert!(!sniff(&header(
            true,
            [3, 200, 2, 3, 4],
            [1.0, 0.0, 0.0, 2.0, 0.0, 3.0]
        )));
        assert!(!sniff(&header(true, [3, 200, 2, 3, 4], b)[..40]));
    }
}
