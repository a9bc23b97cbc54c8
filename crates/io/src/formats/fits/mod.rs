//! FITS images (`.fits`, `.fit`, `.fts`, `.fits.gz`): the astronomers'
//! format (FITS Standard 4.0, IAU FITS Working Group 2016), read with
//! volray's own parser.
//!
//! A file is a sequence of HDUs, each a header of 80-byte ASCII cards up
//! to END (`header.rs`) and its data, both padded to 2880-byte blocks;
//! images are big-endian samples with NAXIS1 fastest, which is volray's
//! x (NAXIS2 y, NAXIS3 z: no reordering). What volray takes:
//!
//! - the primary HDU and IMAGE extensions; BITPIX 8, 16, 32, 64, −32, −64,
//!   BSCALE and BZERO (the unsigned conventions and signed bytes kept
//!   exact), BLANK as NaN (`data.rs`);
//! - the linear WCS (CRPIX, CRVAL, CDELT, PC or CD, CUNIT): world spacing
//!   and origin where the three axes are one kind of length or angle,
//!   FITS pixel coordinates otherwise, as for a radio or optical spectral
//!   cube (RA, Dec, frequency or velocity); `wcs.rs` says why. A rotated
//!   grid is kept in its own axes and a sheared one resampled over its
//!   box, with a note, as for other formats. CTYPE, CUNIT and BUNIT are in
//!   the notes;
//! - NaN (BLANK, or IEEE NaN) marks undefined samples, which ds9 and yt
//!   leave blank: rendered as empty space ([`FileInfo::nan_is_empty`]).
//!
//! Axes and frames. Axes beyond NAXIS2 of length 1 are dropped (a radio
//! cube's STOKES axis of 1, wherever it sits); of the axes left, the third
//! is z and a fourth holds frames. An image whose axes left are more than
//! four is not read. The file's **frames** (`--frame`) are its volumes in
//! file order: each image HDU with a z axis gives one frame, or one per
//! step of its fourth axis. Without `--frame` the first is read (the
//! first HDU holding a 3-D image). `--array` names an HDU by EXTNAME
//! (`PRIMARY` for the primary HDU) or by its number, and `--frame` then
//! counts the frames of that HDU alone. A file whose only image is 2-D is
//! described as an image ([`IoError::FlatImage`]).
//!
//! A gzip file (`.fits.gz`) is inflated as a stream (`source.rs`), within
//! deflate's ratio and the memory limit. Tile-compressed images (§10: a
//! BINTABLE with ZIMAGE = T, written by fpack or astropy's CompImageHDU)
//! are decompressed as they are read (`tiled.rs`: Rice and gzip, dithered
//! quantisation undone); PLIO and HCOMPRESS are refused by name.
//!
//! Why a parser of volray's own rather than the `fitsrs` crate: reading a
//! FITS image is a header of fixed-width cards and one contiguous
//! big-endian block, which volray's shared machinery already streams,
//! maps and checks against the file and `--max-memory`; every size a
//! header declares is checked (in 128-bit, checked arithmetic) against the
//! file's length before a byte of data is read or allocated, and every
//! defect is one line naming the HDU and keyword. `fitsrs` (0.3, "under
//! development") would bring its own readers and error types around the
//! same few lines, without those checks being volray's to state, and
//! BSCALE/BZERO, BLANK, WCS units and frames would still be volray's code.

mod data;
mod header;
mod rice;
mod source;
mod tiled;
mod wcs;

use std::path::Path;

use volray_core::glam::DVec3;

use self::data::Scaling;
use self::header::{Hdu, next_hdu};
use self::source::Source;
use crate::dtype::Endian;
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::check_dims;
use crate::shared::mapped::{self, Plan};
use crate::shared::periodic_cell;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Grid axes whose cosine is below this are orthogonal (as in
/// `shared/geometry.rs`).
const COS_TOLERANCE: f64 = 1e-4;

/// How an image HDU's axes make a volume.
#[derive(Debug, Clone)]
struct Layout {
    /// Samples along x, y, z (z 1 for a 2-D image).
    dims: [usize; 3],
    /// The NAXIS numbers (1-based) of x, y, z.
    axes: [usize; 3],
    /// The NAXIS number of the frame axis, and its length.
    frame_axis: Option<(usize, usize)>,
    /// NAXIS numbers of the axes of length 1 dropped.
    dropped: Vec<usize>,
}

impl Layout {
    fn frames(&self) -> usize {
        self.frame_axis.map_or(1, |(_, n)| n)
    }

    fn is_volume(&self) -> bool {
        self.axes[2] != 0
    }
}

/// How `hdu`'s image makes a volume, a 2-D image, or nothing (no data);
/// `Err` says why it cannot be read.
fn layout(hdu: &Hdu) -> Result<Option<Layout>, String> {
    let n = &hdu.naxes;
    if n.is_empty() || n.contains(&0) {
        return Ok(None);
    }
    let size = |a: usize| {
        usize::try_from(n[a]).map_err(|_| format!("NAXIS{} = {}: too large", a + 1, n[a]))
    };
    let mut kept: Vec<usize> = (0..n.len().min(2)).collect();
    let mut dropped = Vec::new();
    for (a, &len) in n.iter().enumerate().skip(2) {
        if len > 1 {
            kept.push(a);
        } else {
            dropped.push(a + 1);
        }
    }
    if kept.len() > 4 {
        return Err(format!(
            "NAXIS = {} with {} axes longer than 1 (NAXISn {}): volray reads 3 axes and a 4th as frames",
            n.len(),
            kept.len(),
            n.iter().map(u64::to_string).collect::<Vec<_>>().join(" ")
        ));
    }
    let mut dims = [1; 3];
    let mut axes = [0; 3];
    for (d, &a) in kept.iter().take(3).enumerate() {
        dims[d] = size(a)?;
        axes[d] = a + 1;
    }
    let frame_axis = match kept.get(3) {
        Some(&a) => Some((a + 1, size(a)?)),
        None => None,
    };
    Ok(Some(Layout {
        dims,
        axes,
        frame_axis,
        dropped,
    }))
}

/// The names `--array` takes for an HDU: its EXTNAME (`PRIMARY` for the
/// primary HDU without one) and its number.
fn array_name(hdu: &Hdu) -> String {
    match hdu.header.string("EXTNAME").map(|n| n.trim().to_string()) {
        Some(n) if !n.is_empty() => n,
        _ if hdu.index == 0 => "PRIMARY".to_string(),
        _ => hdu.index.to_string(),
    }
}

fn matches_array(hdu: &Hdu, name: &str) -> bool {
    array_name(hdu).eq_ignore_ascii_case(name.trim()) || hdu.index.to_string() == name.trim()
}

/// What was read of the HDU chosen.
struct Chosen {
    hdu: Hdu,
    layout: Layout,
    frame_in_hdu: usize,
    data: volray_core::Samples,
    nan: usize,
    plan: Plan,
    notes: Vec<String>,
}

/// Reads the FITS image at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let mut src = Source::open(path)?;
    let want_frame = opts.frame.unwrap_or(0);
    let mut chosen: Option<Chosen> = None;
    // The volumes of the file (or of the HDU --array names), in order.
    let mut volumes: Vec<(String, usize)> = Vec::new();
    let mut arrays: Vec<String> = Vec::new();
    let mut frames_before = 0usize;
    let mut flat: Option<Hdu> = None;
    let mut refused: Vec<String> = Vec::new();
    let mut compressed: Vec<String> = Vec::new();
    let mut later = Vec::new();
    let mut trailing = 0u64;
    for index in 0.. {
        let hdu = match next_hdu(path, &mut src, index, &mut trailing) {
            Ok(Some(hdu)) => hdu,
            Ok(None) => break,
            Err(e) if chosen.is_some() => {
                later.push(format!(
                    "HDU {index} and any after it not read: {}",
                    e.to_string()
                        .strip_prefix(&format!("{}: ", path.display()))
                        .unwrap_or(&e.to_string())
                ));
                break;
            }
            Err(e) => return Err(e),
        };
        if index == 0 && hdu.header.logical("SIMPLE") != Some(true) {
            later.push("SIMPLE is not T: the file says it does not conform to the standard; read all the same".into());
        }
        // A tile-compressed image is laid out as the image it holds.
        let tiled = match hdu.is_compressed_image() {
            false => None,
            true => match tiled::image_of(&hdu) {
                Ok(image) => Some(image),
                Err(reason) => {
                    compressed.push(format!(
                        "{} is a tile-compressed image (ZIMAGE = T, ZCMPTYPE '{}') whose header is not read: {reason}",
                        hdu.name(),
                        hdu.header.string("ZCMPTYPE").unwrap_or_default().trim_end(),
                    ));
                    None
                }
            },
        };
        let image = tiled.as_ref().unwrap_or(&hdu);
        let layout = if hdu.is_image() || tiled.is_some() {
            match layout(image) {
                Ok(l) => l,
                Err(reason) => {
                    refused.push(format!("{}: {reason}", hdu.name()));
                    None
                }
            }
        } else {
            None
        };
        let mut wanted = None;
        if let Some(l) = layout.as_ref().filter(|l| l.is_volume()) {
            let frames = l.frames();
            arrays.push(array_name(&hdu));
            let counted = match &opts.array {
                Some(name) => matches_array(&hdu, name) && chosen.is_none() && volumes.is_empty(),
                None => true,
            };
            if counted {
                if chosen.is_none() && want_frame < frames_before + frames {
                    wanted = Some(want_frame - frames_before);
                }
                volumes.push((hdu.name(), frames));
                frames_before += frames;
            }
        } else if layout.is_some() && flat.is_none() && tiled.is_none() {
            flat = Some(hdu.clone());
        }
        if let (Some(frame_in_hdu), Some(l)) = (wanted, layout) {
            let c = match &tiled {
                None => read_chosen(path, &mut src, opts, hdu.clone(), l, frame_in_hdu)?,
                Some(image) => {
                    let bytes = tiled::decompress(path, &mut src, &hdu, image, opts.max_memory)?;
                    let mut memory = Source::from_bytes(bytes);
                    let mut c =
                        read_chosen(path, &mut memory, opts, image.clone(), l, frame_in_hdu)?;
                    c.notes.push(format!(
                        "{} is a tile-compressed image (ZCMPTYPE '{}', tiles {}): decompressed as read",
                        hdu.name(),
                        hdu.header.string("ZCMPTYPE").unwrap_or_default().trim_end(),
                        tiles_text(&hdu.header, &image.naxes),
                    ));
                    c
                }
            };
            chosen = Some(c);
        }
        let skipped = skip_rest(path, &mut src, &hdu);
        match skipped {
            Err(e) if chosen.is_some() && !e.is_io_failure() => {
                later.push(format!("{} is cut short: {e}", hdu.name()));
                break;
            }
            other => other?,
        }
    }

    let Some(c) = chosen else {
        return Err(nothing_chosen(
            path,
            opts,
            &volumes,
            &arrays,
            flat,
            &refused,
            &compressed,
        ));
    };
    finish(path, opts, c, volumes, arrays, compressed, later, trailing)
}

/// The tiles' size as `7x1x1` (`ZTILEn`, else the row: NAXIS1 by 1).
fn tiles_text(h: &header::Header, naxes: &[u64]) -> String {
    (naxes.iter().enumerate())
        .map(|(a, n)| match h.int(&format!("ZTILE{}", a + 1)) {
            Ok(Some(t)) => t.to_string(),
            _ if a == 0 => n.to_string(),
            _ => "1".to_string(),
        })
        .collect::<Vec<_>>()
        .join("x")
}

/// Skips the rest of `hdu`'s data and its padding to a whole block; the
/// padding of the last HDU may be missing (a common defect, which astropy
/// reads with a warning).
fn skip_rest(path: &Path, src: &mut Source, hdu: &Hdu) -> Result<(), IoError> {
    // next_hdu checked that the data fits the file: these are u64.
    let data_end = (u128::from(hdu.data_start) + hdu.data_bytes) as u64;
    let padding = (hdu.padded_bytes() - hdu.data_bytes) as usize;
    src.skip(
        path,
        data_end.saturating_sub(src.pos),
        &format!("{} data", hdu.name()),
    )?;
    let mut pad = vec![0u8; padding];
    src.fill_some(path, &mut pad, &format!("{} padding", hdu.name()))?;
    Ok(())
}

/// Reads frame `frame_in_hdu` of the image `hdu`, whose data starts where
/// `src` stands.
fn read_chosen(
    path: &Path,
    src: &mut Source,
    opts: &ReadOptions,
    hdu: Hdu,
    layout: Layout,
    frame_in_hdu: usize,
) -> Result<Chosen, IoError> {
    let bad = |reason: String| IoError::invalid(path, format!("{}: {reason}", hdu.name()));
    let (scaling, mut notes) = Scaling::from_header(&hdu.header, hdu.bitpix).map_err(bad)?;
    let dims = layout.dims;
    let field = format!(
        "NAXIS{} NAXIS{} NAXIS{}",
        layout.axes[0], layout.axes[1], layout.axes[2]
    );
    let held = data::held_bytes(hdu.bitpix, &scaling);
    let within_limit = match check_dims(path, &field, &dims, held, opts.max_memory) {
        Err(e) if !matches!(e, IoError::OverMemoryLimit { .. }) => return Err(e),
        other => other,
    };
    let count = dims[0] * dims[1] * dims[2];
    let size = hdu.bitpix.unsigned_abs() as u64 / 8;
    let frame_bytes = count as u64 * size;
    // An IMAGE extension's PCOUNT and GCOUNT (0 and 1) could say less.
    let needed = u128::from(frame_bytes) * (frame_in_hdu as u128 + 1);
    if needed > hdu.data_bytes {
        return Err(bad(format!(
            "the image needs {needed} bytes, but its header declares {} bytes of data (PCOUNT {}, GCOUNT {})",
            hdu.data_bytes,
            hdu.header.text("PCOUNT"),
            hdu.header.text("GCOUNT")
        )));
    }
    let offset = hdu.data_start + frame_bytes * frame_in_hdu as u64;
    let dtype = data::dtype(hdu.bitpix);
    let mappable = if src.is_gzip() {
        Err("gzip-compressed data: store it as .fits".to_string())
    } else if src.is_memory() {
        Err("tile-compressed data: decompressed as it is read".to_string())
    } else if !scaling.is_identity() {
        Err("BSCALE/BZERO scale the values as they are read".to_string())
    } else if scaling.blank.is_some() {
        Err("BLANK samples become NaN as they are read".to_string())
    } else {
        mapped::mappable(dtype, Endian::Big, offset)
    };
    let plan = mapped::plan(opts.map, mappable, within_limit)?;
    let (data, nan) = if plan == Plan::Map {
        (mapped::map_samples(path, offset, dtype, count)?, 0)
    } else {
        src.skip(path, offset - src.pos, &format!("{} data", hdu.name()))?;
        data::read_values(
            path,
            src,
            hdu.bitpix,
            &scaling,
            count,
            &format!("{} data", hdu.name()),
        )?
    };
    if nan > 0 {
        notes.push(format!(
            "{nan} samples are undefined ({}): NaN, rendered as empty space",
            match scaling.blank {
                Some(b) if hdu.bitpix > 0 => format!("BLANK = {b}"),
                _ => "IEEE NaN".to_string(),
            }
        ));
    }
    Ok(Chosen {
        hdu,
        layout,
        frame_in_hdu,
        data,
        nan,
        plan,
        notes,
    })
}

/// The refusal of a file where no volume was chosen.
fn nothing_chosen(
    path: &Path,
    opts: &ReadOptions,
    volumes: &[(String, usize)],
    arrays: &[String],
    flat: Option<Hdu>,
    refused: &[String],
    compressed: &[String],
) -> IoError {
    let listed = if arrays.is_empty() {
        "the file holds no image of 3 or more axes".to_string()
    } else {
        format!("the file's 3-D images are {}", arrays.join(", "))
    };
    if let Some(name) = &opts.array
        && volumes.is_empty()
    {
        return IoError::no_such_array(path, name, listed);
    }
    let total: usize = volumes.iter().map(|v| v.1).sum();
    if total > 0 {
        return IoError::frame_out_of_range(
            path,
            opts.frame.unwrap_or(0),
            format!("{}, numbered from 0", frame_list(volumes)),
        );
    }
    if let Some(c) = compressed.first() {
        return IoError::invalid(
            path,
            format!("{c}; write it uncompressed first (funpack, or astropy's ImageHDU)"),
        );
    }
    if let Some(r) = refused.first() {
        return IoError::invalid(path, r.clone());
    }
    if let Some(hdu) = flat {
        return read_flat(path, hdu);
    }
    IoError::invalid(
        path,
        "no image data: no HDU holds an image (tables and empty HDUs only)",
    )
}

/// `primary HDU (1 volume), HDU 4 (EXTNAME 'SERIES') (2 volumes along NAXIS4)`.
fn frame_list(volumes: &[(String, usize)]) -> String {
    let total: usize = volumes.iter().map(|v| v.1).sum();
    let parts: Vec<String> = volumes
        .iter()
        .map(|(name, n)| format!("{name}: {n}"))
        .collect();
    format!(
        "the file holds {total} volume{} ({})",
        if total == 1 { "" } else { "s" },
        parts.join(", ")
    )
}

/// A file whose only image is 2-D: read it to describe it as an image.
fn read_flat(path: &Path, hdu: Hdu) -> IoError {
    let describe = || -> Result<IoError, IoError> {
        let mut src = Source::open(path)?;
        let Ok(Some(layout)) = layout(&hdu) else {
            return Ok(IoError::invalid(path, "no image data"));
        };
        let opts = ReadOptions::default();
        let c = read_chosen(path, &mut src, &opts, hdu, layout, 0)?;
        let mut info = FileInfo::new(String::new());
        let g = geometry_of(path, &c, &mut info)?;
        let err = grid_to_volume(path, c.layout.dims, c.data, g.steps, g.origin, &mut info);
        Ok(match err {
            Err(e) => e,
            Ok(_) => IoError::invalid(path, "a 2-D image"),
        })
    };
    describe().unwrap_or_else(|e| e)
}

/// The WCS of the chosen image, its notes added to `info`.
fn geometry_of(path: &Path, c: &Chosen, info: &mut FileInfo) -> Result<wcs::Geometry, IoError> {
    let mut axes = c.layout.axes;
    // A 2-D image has no third axis: NAXIS3's keywords are absent anyway.
    if axes[2] == 0 {
        axes[2] = 3;
    }
    let g = wcs::geometry(&c.hdu.header, axes)
        .map_err(|e| IoError::invalid(path, format!("{}: {e}", c.hdu.name())))?;
    info.stored_type = data::stored_type(
        c.hdu.bitpix,
        &Scaling::from_header(&c.hdu.header, c.hdu.bitpix)
            .map(|s| s.0)
            .unwrap_or(Scaling {
                bscale: 1.0,
                bzero: 0.0,
                bzero_int: Some(0),
                blank: None,
            }),
    );
    info.header = c
        .hdu
        .header
        .cards
        .iter()
        .map(|card| (card.key.clone(), card.text.clone()))
        .collect();
    info.length_unit = g.unit.clone();
    Ok(g)
}

#[allow(clippy::too_many_arguments)]
fn finish(
    path: &Path,
    opts: &ReadOptions,
    c: Chosen,
    volumes: Vec<(String, usize)>,
    arrays: Vec<String>,
    compressed: Vec<String>,
    later: Vec<String>,
    trailing: u64,
) -> Result<Loaded, IoError> {
    let mut info = FileInfo::new(String::new());
    let g = geometry_of(path, &c, &mut info)?;
    let mut notes = Vec::new();
    if c.hdu.index > 0 {
        notes.push(format!("read {}", c.hdu.name()));
    }
    if !c.layout.dropped.is_empty() {
        let dropped: Vec<String> = c
            .layout
            .dropped
            .iter()
            .map(|a| {
                let t = c
                    .hdu
                    .header
                    .string(&format!("CTYPE{a}"))
                    .unwrap_or_default();
                if t.is_empty() {
                    format!("NAXIS{a}")
                } else {
                    format!("NAXIS{a} ('{t}')")
                }
            })
            .collect();
        notes.push(format!("axes of length 1 dropped: {}", dropped.join(", ")));
    }
    if let Some((a, n)) = c.layout.frame_axis {
        let t = c
            .hdu
            .header
            .string(&format!("CTYPE{a}"))
            .unwrap_or_default();
        notes.push(format!(
            "NAXIS{a} ({}) holds {n} volumes: step {} read",
            if t.is_empty() {
                "no CTYPE".to_string()
            } else {
                format!("'{t}'")
            },
            c.frame_in_hdu
        ));
    }
    notes.extend(c.notes.iter().cloned());
    notes.extend(g.notes.iter().cloned());
    notes.extend(
        compressed
            .iter()
            .map(|s| format!("{s}: not read (tile-compressed)")),
    );
    notes.extend(later);
    if trailing > 0 {
        notes.push(format!("{trailing} bytes after the last HDU ignored"));
    }
    let total: usize = volumes.iter().map(|v| v.1).sum();
    let before: usize = volumes
        .iter()
        .take_while(|(name, _)| *name != c.hdu.name())
        .map(|v| v.1)
        .sum();
    info.frames = total;
    info.frame = before + c.frame_in_hdu;
    if arrays.len() > 1 || opts.array.is_some() {
        info.arrays = arrays;
        info.array = Some(array_name(&c.hdu));
    }
    info.nan_is_empty = c.nan > 0;

    let volume = if is_sheared(g.steps) && c.layout.dims.iter().all(|&n| n >= 2) {
        info.nan_is_empty = true;
        let unit = g.unit.clone().unwrap_or_default();
        let (volume, note) = periodic_cell::resample_box(
            c.layout.dims,
            &c.data.to_f32_vec(),
            g.steps,
            g.origin,
            ["NAXIS1", "NAXIS2", "NAXIS3"],
            &unit,
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "PCi_j/CDi_j"))?;
        notes.push(note);
        volume
    } else {
        grid_to_volume(path, c.layout.dims, c.data, g.steps, g.origin, &mut info)?
    };
    if c.plan == Plan::Map {
        notes.push(mapped::mapped_note(&volume));
    }
    let geometry_notes = std::mem::take(&mut info.notes);
    info.notes = notes;
    info.notes.extend(geometry_notes);
    Ok(Loaded {
        volume,
        format: VolumeFormat::Fits,
        info,
    })
}

/// Whether two of the steps are not orthogonal.
fn is_sheared(steps: [DVec3; 3]) -> bool {
    [(0, 1), (0, 2), (1, 2)].iter().any(|&(a, b)| {
        let (u, v) = (steps[a].normalize_or_zero(), steps[b].normalize_or_zero());
        u.dot(v).abs() > COS_TOLERANCE
    })
}
