//! Writing a volume as an OME-Zarr image, its pyramid made in bounded
//! memory: [`write_ome_zarr`].
//!
//! Layout. One multiscale image of three space axes `z`, `y`, `x` (no
//! unit: volray's volumes carry none), each level an array in C order
//! `(z, y, x)`, so that volray's x-fastest samples are the array's last
//! axis, fastest: no transpose. Level 0 is the volume, in its own sample
//! type (`uint8`, `int8`, `uint16`, `int16`, `float32`; fill value 0).
//! Each next level halves every axis of more than 2 voxels (`ceil(n/2)`;
//! an axis of 2 is kept, so that every level is a volume volray renders),
//! down to the first level whose largest side fits in one chunk. A voxel
//! of a lower level is the mean of the block of up to 2×2×2 voxels it
//! covers (the voxels present, at odd edges), computed in `f64` and
//! rounded to the nearest integer (halves away from zero) for integer
//! types; for a label volume ([`VolumeSource::is_labels`]) it is the
//! block's most common value, the smallest of those tied.
//!
//! Geometry. Volray's voxels are grid points at `origin + i·spacing`; a
//! level's `scale` is its spacing (`spacing·2^k` along an axis halved
//! `k` times) and its `translation` the world position of its first
//! voxel: the mean of points `2j` and `2j+1` sits at `origin + (2j +
//! 0.5)·s`, so each halving moves the translation by half the finer
//! spacing. volray's reader (`ome.rs`) reads these back as each level's
//! spacing and origin.
//!
//! Encoding. [`ZarrVersion::V3`] writes OME-Zarr 0.5 (Zarr v3): chunks of
//! 64³ (`chunk`, clipped to the level) inside shards of 256³
//! (`sharding_indexed`, a multiple of the chunk, clipped to the level),
//! each chunk `bytes` (little-endian) then `zstd` level 3, the shard index
//! with `crc32c`. [`ZarrVersion::V2`] writes OME-Zarr 0.4 (Zarr v2): the
//! same chunks, unsharded, `blosc` with `zstd` level 3 and byte shuffle,
//! `/` as dimension separator (as 0.4 requires).
//!
//! Bounded memory. Level 0 is read from the source box by box, one shard
//! (v3) or one run of chunks as large (v2), a *tile*, at a time, never
//! the whole volume; each lower level is made from the level above read
//! back from the store just written, a tile at a time, that tile's block
//! of the level above read one chunk's thickness of output at a time. So
//! memory is a few tiles whatever the volume's size, and every level's
//! need is checked against `max_memory` before anything is written. The
//! store is written into a temporary directory beside the destination and
//! renamed into place when complete ([`AtomicDir`]): a failure or a signal
//! leaves no half-written store (each write into it is made through
//! [`AtomicDir::while_live`], so none follows a signal's deletion).
//!
//! Here: the options, the plan of the levels and its memory check, the
//! write as a whole; `write/metadata.rs`: the group's and arrays' JSON;
//! `write/tiles.rs`: the samples, tile by tile.

mod metadata;
mod tiles;

use std::path::Path;

use volray_core::glam::DVec3;
use volray_core::{SampleType, VolumeSource};

use super::store::{is_zarr_dir, stored_bytes};
use crate::IoError;
use crate::atomic::AtomicDir;
use crate::shared::limits::{check_held, count_values, format_bytes};

/// The Zarr version (and so the OME-Zarr version) to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZarrVersion {
    /// Zarr v2, OME-Zarr 0.4: chunks, no shards, blosc-zstd.
    V2,
    /// Zarr v3, OME-Zarr 0.5: chunks in shards, zstd.
    V3,
}

/// How [`write_ome_zarr`] writes an image.
#[derive(Debug, Clone, PartialEq)]
pub struct OmeZarrOptions {
    /// Zarr v3 (OME-Zarr 0.5, the default) or v2 (OME-Zarr 0.4).
    pub zarr_version: ZarrVersion,
    /// The side of a chunk (64): at least 2; a level's chunk is clipped to
    /// its shape. Levels are made down to the first whose largest side is
    /// no more than this.
    pub chunk: usize,
    /// The side of a shard (256; v3), rounded up to a multiple of `chunk`,
    /// clipped to the level. Also the side of the box read and written at
    /// a time, for either version.
    pub shard: usize,
    /// Whether the values are labels (lower levels take block modes, not
    /// means); `None`: as the source says ([`VolumeSource::is_labels`]).
    pub labels: Option<bool>,
    /// The most bytes the writer may hold at a time.
    pub max_memory: u64,
}

impl Default for OmeZarrOptions {
    fn default() -> Self {
        OmeZarrOptions {
            zarr_version: ZarrVersion::V3,
            chunk: 64,
            shard: 256,
            labels: None,
            max_memory: crate::default_max_memory(),
        }
    }
}

/// One level as written.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenLevel {
    /// The array's path in the image (`0`, `1`, ...).
    pub path: String,
    /// Samples along x, y and z.
    pub dims: [usize; 3],
    /// Spacing and origin (world position of the first voxel), x, y, z.
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    /// The chunk shape, x, y, z.
    pub chunk: [usize; 3],
    /// The shard shape, x, y, z (v3).
    pub shard: Option<[usize; 3]>,
    /// The bytes its chunk (or shard) files take on disk.
    pub bytes_stored: u64,
}

/// What [`write_ome_zarr`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct OmeZarrWritten {
    /// `0.5` or `0.4`.
    pub ome_version: &'static str,
    /// The levels, finest first.
    pub levels: Vec<WrittenLevel>,
    /// The chunk codecs, e.g. `zstd (level 3)`.
    pub codec: &'static str,
    /// Whether lower levels are block modes (labels) rather than means.
    pub labels: bool,
    /// The bytes every file of the store takes, metadata included.
    pub bytes_stored: u64,
}

/// zstd's level, for either version.
const ZSTD_LEVEL: i64 = 3;

/// Writes `source` at `path` as an OME-Zarr image (see the module
/// documentation), atomically. An existing Zarr store at `path` is
/// replaced; anything else there is refused. Refused before anything is
/// written, with a one-line error naming `path`, when a level's tiles
/// would not fit `options.max_memory`.
pub fn write_ome_zarr(
    path: &Path,
    source: &dyn VolumeSource,
    options: &OmeZarrOptions,
) -> Result<OmeZarrWritten, IoError> {
    // The checked codecs registered before this thread builds any codec
    // (their registration takes zarrs' registry lock once, here, not
    // while another thread's writer holds it).
    super::guard::install();
    if options.chunk < 2 || options.shard < 2 {
        return Err(IoError::invalid(
            path,
            format!(
                "chunk side {} and shard side {}: each must be at least 2",
                options.chunk, options.shard
            ),
        ));
    }
    let grid = source.grid();
    if grid.dims.iter().any(|&n| n < 2) {
        return Err(IoError::invalid(
            path,
            format!(
                "a {}x{}x{} grid: every axis needs at least 2 voxels",
                grid.dims[0], grid.dims[1], grid.dims[2]
            ),
        ));
    }
    let ty = source.sample_type();
    let labels = options.labels.unwrap_or_else(|| source.is_labels());
    let levels = plan(grid.dims, grid.spacing, grid.origin, options);
    for (k, level) in levels.iter().enumerate() {
        let above = k.checked_sub(1).map(|a| &levels[a]);
        check_level(path, k, level, above, ty, options.max_memory)?;
    }
    let out = AtomicDir::create(path, replaceable)?;
    let root = out.dir();
    let image = Image {
        out: &out,
        path,
        levels: &levels,
        version: options.zarr_version,
        ty,
        labels,
    };
    image.write_group(root)?;
    match ty {
        SampleType::U8 => image.write_levels::<u8>(root, source)?,
        SampleType::I8 => image.write_levels::<i8>(root, source)?,
        SampleType::U16 => image.write_levels::<u16>(root, source)?,
        SampleType::I16 => image.write_levels::<i16>(root, source)?,
        SampleType::F32 => image.write_levels::<f32>(root, source)?,
    }
    let written = OmeZarrWritten {
        ome_version: match options.zarr_version {
            ZarrVersion::V2 => "0.4",
            ZarrVersion::V3 => "0.5",
        },
        levels: levels
            .iter()
            .enumerate()
            .map(|(k, l)| WrittenLevel {
                path: k.to_string(),
                dims: l.dims,
                spacing: l.spacing.to_array(),
                origin: l.origin.to_array(),
                chunk: l.chunk,
                shard: (options.zarr_version == ZarrVersion::V3).then_some(l.tile),
                bytes_stored: stored_bytes(&root.join(k.to_string()), usize::MAX).unwrap_or(0),
            })
            .collect(),
        codec: match options.zarr_version {
            ZarrVersion::V2 => "blosc (zstd level 3, byte shuffle)",
            ZarrVersion::V3 => "zstd (level 3)",
        },
        labels,
        bytes_stored: tree_bytes(root),
    };
    out.commit()?;
    Ok(written)
}

/// An existing destination is replaced only if it is a Zarr store.
fn replaceable(path: &Path) -> Result<(), String> {
    if is_zarr_dir(path) {
        Ok(())
    } else {
        Err("it exists and is not a Zarr store (no zarr.json, .zgroup, .zattrs or .zarray); refusing to replace it".to_string())
    }
}

/// One level to write, its axes x, y, z.
#[derive(Debug, Clone, PartialEq)]
struct Level {
    dims: [usize; 3],
    /// How many voxels of the level above a voxel covers along each axis
    /// (1 or 2; 1 for level 0).
    factor: [usize; 3],
    spacing: DVec3,
    origin: DVec3,
    chunk: [usize; 3],
    /// The shard (v3), and the box read and written at a time.
    tile: [usize; 3],
}

/// The levels of the pyramid (see the module documentation).
fn plan(dims: [usize; 3], spacing: DVec3, origin: DVec3, options: &OmeZarrOptions) -> Vec<Level> {
    let c = options.chunk;
    // A multiple of the chunk, at least one.
    let s = options.shard.div_ceil(c) * c;
    let level = |dims: [usize; 3], factor, spacing, origin| {
        let chunk = dims.map(|n| n.min(c));
        let tile = std::array::from_fn(|a| s.min(dims[a].div_ceil(chunk[a]) * chunk[a]));
        Level {
            dims,
            factor,
            spacing,
            origin,
            chunk,
            tile,
        }
    };
    let mut levels = vec![level(dims, [1; 3], spacing, origin)];
    loop {
        let last = levels.last().expect("level 0");
        if last.dims.iter().all(|&n| n <= c) {
            return levels;
        }
        let factor = last.dims.map(|n| if n > 2 { 2 } else { 1 });
        let dims = std::array::from_fn(|a| last.dims[a].div_ceil(factor[a]));
        let f = DVec3::new(factor[0] as f64, factor[1] as f64, factor[2] as f64);
        // A block of 2 points is centred half a spacing past the first.
        let shift = (f - DVec3::ONE) * 0.5 * last.spacing;
        let next = level(dims, factor, last.spacing * f, last.origin + shift);
        levels.push(next);
    }
}

/// The values a level's tile holds at once, and the values of the level
/// above read at a time to make it (level 0: the box read from the
/// source, at most a tile).
fn tile_values(level: &Level, above: Option<&Level>) -> (u128, u128) {
    let tile = level.tile.iter().map(|&n| n as u128).product::<u128>();
    let input = above.map_or(tile, |a| {
        // A tile's block of the level above, one output chunk thick.
        (0..3)
            .map(|i| {
                let n = if i == 2 {
                    level.chunk[2]
                } else {
                    level.tile[i]
                };
                (n * level.factor[i]).min(a.dims[i]) as u128
            })
            .product()
    });
    (tile, input)
}

/// Refuses a level whose tiles would not fit `max_memory`: the input box
/// (the source's, or the level above's block), the tile, and the
/// encoder's copies of it (about two tiles).
fn check_level(
    path: &Path,
    k: usize,
    level: &Level,
    above: Option<&Level>,
    ty: SampleType,
    max_memory: u64,
) -> Result<(), IoError> {
    let [x, y, z] = level.tile.map(|n| n as u64);
    count_values(path, "OME-Zarr tile", &[z, y, x])?;
    let (tile, input) = tile_values(level, above);
    let values = 3 * tile + input;
    let bytes = values * ty.bytes() as u128;
    check_held(
        path,
        &format!("writing level {k} in tiles of {x}x{y}x{z}"),
        values,
        bytes,
        &format!(
            "{} of {} with the block read and the encoder's copies",
            format_bytes(bytes),
            ty.name()
        ),
        max_memory,
    )
}

/// The bytes every file under `dir` takes.
fn tree_bytes(dir: &Path) -> u64 {
    let mut total = 0;
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            match entry.file_type() {
                Ok(t) if t.is_dir() => pending.push(entry.path()),
                Ok(t) if t.is_file() => total += entry.metadata().map_or(0, |m| m.len()),
                _ => {}
            }
        }
    }
    total
}

/// The image being written: its levels and how.
struct Image<'a> {
    /// The temporary directory, written to only while it lives.
    out: &'a AtomicDir,
    /// The destination, for messages.
    path: &'a Path,
    levels: &'a [Level],
    version: ZarrVersion,
    ty: SampleType,
    labels: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_axes_over_two_voxels_down_to_one_chunk() {
        let options = OmeZarrOptions {
            chunk: 8,
            shard: 20,
            ..OmeZarrOptions::default()
        };
        let levels = plan(
            [37, 20, 2],
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::ZERO,
            &options,
        );
        let dims: Vec<[usize; 3]> = levels.iter().map(|l| l.dims).collect();
        assert_eq!(dims, [[37, 20, 2], [19, 10, 2], [10, 5, 2], [5, 3, 2]]);
        // The shard rounds up to a multiple of the chunk, then clips.
        assert_eq!(levels[0].tile, [24, 24, 2]);
        assert_eq!(levels[0].chunk, [8, 8, 2]);
        assert_eq!(levels[3].chunk, [5, 3, 2]);
        assert_eq!(levels[3].tile, [5, 3, 2]);
        assert_eq!(levels[2].spacing, DVec3::new(4.0, 8.0, 3.0));
        // Half a finer spacing per halving: 0.5 + 1, then 0.5·(2 + 4).
        assert_eq!(levels[2].origin, DVec3::new(1.5, 3.0, 0.0));
        let one = plan(
            [64, 64, 64],
            DVec3::ONE,
            DVec3::ZERO,
            &OmeZarrOptions::default(),
        );
        assert_eq!(one.len(), 1);
    }
}
