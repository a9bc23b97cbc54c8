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

use std::path::Path;
use std::sync::Arc;

use serde_json::{Value, json};
use volray_core::glam::DVec3;
use volray_core::{SampleType, Samples, VolumeSource};
use zarrs::array::{Array, ArrayMetadata, ArraySubset, Element, ElementOwned};
use zarrs::filesystem::FilesystemStore;

use super::chunks::zarr_error;
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

/// A sample type written as stored.
trait Sample: Element + ElementOwned + Copy + Default + Send + Sync + 'static {
    /// The samples, if they are of this type.
    fn of(samples: &Samples) -> Option<&[Self]>;
    fn to_f64(self) -> f64;
    /// A block's mean in this type: rounded to the nearest integer
    /// (halves away from zero) for integer types.
    fn from_mean(mean: f64) -> Self;
}

macro_rules! integer_value {
    ($t:ty, $variant:ident) => {
        impl Sample for $t {
            fn of(samples: &Samples) -> Option<&[Self]> {
                match samples {
                    Samples::$variant(v) => Some(&**v),
                    _ => None,
                }
            }
            fn to_f64(self) -> f64 {
                f64::from(self)
            }
            fn from_mean(mean: f64) -> Self {
                // The mean of values of the type is within its range.
                mean.round() as $t
            }
        }
    };
}
integer_value!(u8, U8);
integer_value!(i8, I8);
integer_value!(u16, U16);
integer_value!(i16, I16);

impl Sample for f32 {
    fn of(samples: &Samples) -> Option<&[Self]> {
        match samples {
            Samples::F32(v) => Some(&**v),
            _ => None,
        }
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn from_mean(mean: f64) -> Self {
        mean as f32
    }
}

/// The value a block of a lower level gets: the mean of `block`, or for
/// labels its most common value (the smallest of those tied).
fn reduce<T: Sample>(block: &mut [T], labels: bool) -> T {
    if !labels {
        let sum: f64 = block.iter().map(|v| v.to_f64()).sum();
        return T::from_mean(sum / block.len() as f64);
    }
    block.sort_by(|a, b| a.to_f64().total_cmp(&b.to_f64()));
    let (mut best, mut best_count) = (block[0], 0);
    let mut i = 0;
    while i < block.len() {
        let v = block[i].to_f64();
        let run = block[i..]
            .iter()
            .take_while(|w| w.to_f64().total_cmp(&v).is_eq())
            .count();
        // Strictly more: a tie keeps the smaller value, found first.
        if run > best_count {
            best = block[i];
            best_count = run;
        }
        i += run;
    }
    best
}

/// A box `lo..hi` of a level, x, y, z.
#[derive(Debug, Clone, Copy)]
struct Box3 {
    lo: [usize; 3],
    hi: [usize; 3],
}

impl Box3 {
    fn dims(&self) -> [usize; 3] {
        std::array::from_fn(|a| self.hi[a] - self.lo[a])
    }

    /// As a zarrs subset, in the array's (z, y, x) order.
    fn subset(&self) -> ArraySubset {
        let d = self.dims();
        ArraySubset::new_with_start_shape(
            vec![self.lo[2] as u64, self.lo[1] as u64, self.lo[0] as u64],
            vec![d[2] as u64, d[1] as u64, d[0] as u64],
        )
        .expect("three axes")
    }
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

impl Image<'_> {
    /// The group's metadata: OME-Zarr `multiscales`.
    fn write_group(&self, root: &Path) -> Result<(), IoError> {
        let xyz_to_zyx = |v: DVec3| json!([v.z, v.y, v.x]);
        let datasets: Vec<Value> = self
            .levels
            .iter()
            .enumerate()
            .map(|(k, l)| {
                json!({
                    "path": k.to_string(),
                    "coordinateTransformations": [
                        {"type": "scale", "scale": xyz_to_zyx(l.spacing)},
                        {"type": "translation", "translation": xyz_to_zyx(l.origin)},
                    ],
                })
            })
            .collect();
        let name = self
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = name
            .strip_suffix(".zarr")
            .map(|n| n.strip_suffix(".ome").unwrap_or(n))
            .unwrap_or(&name)
            .to_string();
        let (kind, description) = if self.labels {
            (
                "mode",
                "each voxel of a lower level is the most common value of the 2x2x2 block (fewer at odd edges; 2 voxels are kept along an axis of 2) it covers, the smallest of those tied",
            )
        } else {
            (
                "mean",
                "each voxel of a lower level is the mean of the 2x2x2 block (fewer at odd edges; 2 voxels are kept along an axis of 2) it covers, rounded to the nearest integer for integer types",
            )
        };
        let mut multiscale = json!({
            "name": name,
            "axes": [
                {"name": "z", "type": "space"},
                {"name": "y", "type": "space"},
                {"name": "x", "type": "space"},
            ],
            "datasets": datasets,
            "type": kind,
            "metadata": {
                "description": description,
                "method": "volray convert",
                "version": env!("CARGO_PKG_VERSION"),
            },
        });
        match self.version {
            ZarrVersion::V3 => {
                let group = json!({
                    "zarr_format": 3,
                    "node_type": "group",
                    "attributes": {"ome": {"version": "0.5", "multiscales": [multiscale]}},
                });
                self.write_json(&root.join("zarr.json"), &group)
            }
            ZarrVersion::V2 => {
                multiscale["version"] = json!("0.4");
                self.write_json(&root.join(".zgroup"), &json!({"zarr_format": 2}))?;
                self.write_json(&root.join(".zattrs"), &json!({"multiscales": [multiscale]}))
            }
        }
    }

    fn write_json(&self, file: &Path, value: &Value) -> Result<(), IoError> {
        let mut text = serde_json::to_string_pretty(value).expect("JSON values serialise");
        text.push('\n');
        self.out
            .while_live(|_| std::fs::write(file, text))
            .map_err(|e| IoError::os(self.path, "write", e))
    }

    /// A level's array metadata.
    fn array_metadata(&self, level: &Level) -> Value {
        let zyx = |v: [usize; 3]| json!([v[2], v[1], v[0]]);
        let fill = if self.ty == SampleType::F32 {
            json!(0.0)
        } else {
            json!(0)
        };
        match self.version {
            ZarrVersion::V3 => {
                let data_type = match self.ty {
                    SampleType::U8 => "uint8",
                    SampleType::I8 => "int8",
                    SampleType::U16 => "uint16",
                    SampleType::I16 => "int16",
                    SampleType::F32 => "float32",
                };
                json!({
                    "zarr_format": 3,
                    "node_type": "array",
                    "shape": zyx(level.dims),
                    "data_type": data_type,
                    "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": zyx(level.tile)}},
                    "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
                    "fill_value": fill,
                    "codecs": [{"name": "sharding_indexed", "configuration": {
                        "chunk_shape": zyx(level.chunk),
                        "codecs": [
                            {"name": "bytes", "configuration": {"endian": "little"}},
                            {"name": "zstd", "configuration": {"level": ZSTD_LEVEL, "checksum": false}},
                        ],
                        "index_codecs": [
                            {"name": "bytes", "configuration": {"endian": "little"}},
                            {"name": "crc32c"},
                        ],
                        "index_location": "end",
                    }}],
                    "dimension_names": ["z", "y", "x"],
                    "attributes": {},
                })
            }
            ZarrVersion::V2 => {
                let dtype = match self.ty {
                    SampleType::U8 => "|u1",
                    SampleType::I8 => "|i1",
                    SampleType::U16 => "<u2",
                    SampleType::I16 => "<i2",
                    SampleType::F32 => "<f4",
                };
                json!({
                    "zarr_format": 2,
                    "shape": zyx(level.dims),
                    "chunks": zyx(level.chunk),
                    "dtype": dtype,
                    "compressor": {
                        "id": "blosc",
                        "cname": "zstd",
                        "clevel": ZSTD_LEVEL,
                        "shuffle": 1,
                        "blocksize": 0,
                    },
                    "fill_value": fill,
                    "order": "C",
                    "filters": null,
                    "dimension_separator": "/",
                })
            }
        }
    }

    /// Creates level `k`'s array: its directory, metadata file, and the
    /// `zarrs` array that encodes its chunks.
    fn create_array(&self, root: &Path, k: usize) -> Result<Array<FilesystemStore>, IoError> {
        let dir = root.join(k.to_string());
        self.out
            .while_live(|_| std::fs::create_dir(&dir))
            .map_err(|e| IoError::os(self.path, "write", e))?;
        let meta = self.array_metadata(&self.levels[k]);
        let file = match self.version {
            ZarrVersion::V3 => "zarr.json",
            ZarrVersion::V2 => ".zarray",
        };
        self.write_json(&dir.join(file), &meta)?;
        let bad =
            |e: &dyn std::fmt::Display| zarr_error(self.path, "cannot create a Zarr array", e);
        let metadata: ArrayMetadata = serde_json::from_value(meta).map_err(|e| bad(&e))?;
        let store = FilesystemStore::new(&dir).map_err(|e| bad(&e))?;
        Array::new_with_metadata(Arc::new(store), "/", metadata).map_err(|e| bad(&e))
    }

    /// Writes every level: level 0 from `source`, each next one from the
    /// one before, read back.
    fn write_levels<T: Sample>(
        &self,
        root: &Path,
        source: &dyn VolumeSource,
    ) -> Result<(), IoError> {
        let mut above: Option<Array<FilesystemStore>> = None;
        for (k, level) in self.levels.iter().enumerate() {
            let array = self.create_array(root, k)?;
            for tile in tiles(level) {
                let values = match &above {
                    None => self.read_source::<T>(source, level, tile)?,
                    Some(a) => self.downsample::<T>(a, &self.levels[k - 1], level, tile)?,
                };
                self.store_tile(&array, level, tile, values)?;
            }
            above = Some(array);
        }
        Ok(())
    }

    /// Level 0's tile `tile` (its box clipped to the volume) read from
    /// the source, padded with zeros to the whole tile, (z, y, x) order.
    fn read_source<T: Sample>(
        &self,
        source: &dyn VolumeSource,
        level: &Level,
        tile: Box3,
    ) -> Result<Vec<T>, IoError> {
        // The source gives boxes of at least 2 voxels a side: a thinner
        // last tile is read with the voxel before it, then skipped.
        let lo: [usize; 3] = std::array::from_fn(|a| tile.lo[a].min(tile.hi[a] - 2));
        let piece = source
            .read_box(lo, tile.hi)
            .map_err(|e| IoError::invalid(self.path, format!("cannot read the input: {e}")))?;
        let values = T::of(piece.samples()).ok_or_else(|| {
            IoError::invalid(
                self.path,
                format!(
                    "the input gave {} samples for a box of a {} volume",
                    piece.sample_type().name(),
                    self.ty.name()
                ),
            )
        })?;
        let got: [usize; 3] = std::array::from_fn(|a| tile.hi[a] - lo[a]);
        if piece.dims() != got {
            return Err(IoError::invalid(
                self.path,
                format!(
                    "the input gave a box of {:?} voxels for {got:?}",
                    piece.dims()
                ),
            ));
        }
        let [tx, ty, _] = level.tile;
        let mut out = vec![T::default(); level.tile.iter().product()];
        let d = tile.dims();
        for z in 0..d[2] {
            for y in 0..d[1] {
                let from = ((z + tile.lo[2] - lo[2]) * got[1] + (y + tile.lo[1] - lo[1])) * got[0]
                    + (tile.lo[0] - lo[0]);
                let to = (z * ty + y) * tx;
                out[to..to + d[0]].copy_from_slice(&values[from..from + d[0]]);
            }
        }
        Ok(out)
    }

    /// Tile `tile` of `level` made from the level above (`above`, read
    /// back from `array`), padded with zeros to the whole tile: read one
    /// output chunk's thickness at a time.
    fn downsample<T: Sample>(
        &self,
        array: &Array<FilesystemStore>,
        above: &Level,
        level: &Level,
        tile: Box3,
    ) -> Result<Vec<T>, IoError> {
        let f = level.factor;
        let [tx, ty, _] = level.tile;
        let mut out = vec![T::default(); level.tile.iter().product()];
        let mut block = Vec::with_capacity(8);
        let step = level.chunk[2];
        let mut z0 = tile.lo[2];
        while z0 < tile.hi[2] {
            let z1 = (z0 + step).min(tile.hi[2]);
            let part = Box3 {
                lo: [tile.lo[0], tile.lo[1], z0],
                hi: [tile.hi[0], tile.hi[1], z1],
            };
            let input = Box3 {
                lo: std::array::from_fn(|a| part.lo[a] * f[a]),
                hi: std::array::from_fn(|a| (part.hi[a] * f[a]).min(above.dims[a])),
            };
            let values: Vec<T> = array
                .retrieve_array_subset::<Vec<T>>(&input.subset())
                .map_err(|e| zarr_error(self.path, "cannot read back the level above", e))?;
            let [ix, iy, _] = input.dims();
            for z in z0..z1 {
                let zs = z * f[2]..((z + 1) * f[2]).min(above.dims[2]);
                for y in part.lo[1]..part.hi[1] {
                    let ys = y * f[1]..((y + 1) * f[1]).min(above.dims[1]);
                    let row = ((z - tile.lo[2]) * ty + (y - tile.lo[1])) * tx;
                    for x in part.lo[0]..part.hi[0] {
                        let xs = x * f[0]..((x + 1) * f[0]).min(above.dims[0]);
                        block.clear();
                        for zz in zs.clone() {
                            for yy in ys.clone() {
                                let r = ((zz - input.lo[2]) * iy + (yy - input.lo[1])) * ix;
                                for xx in xs.clone() {
                                    block.push(values[r + xx - input.lo[0]]);
                                }
                            }
                        }
                        out[row + x - tile.lo[0]] = reduce(&mut block, self.labels);
                    }
                }
            }
            z0 = z1;
        }
        Ok(out)
    }

    /// Stores a whole tile (z, y, x order): one shard (v3), or each of
    /// the chunks it holds that the array has (v2).
    fn store_tile<T: Sample>(
        &self,
        array: &Array<FilesystemStore>,
        level: &Level,
        tile: Box3,
        values: Vec<T>,
    ) -> Result<(), IoError> {
        let failed = |e| zarr_error(self.path, "cannot write a Zarr chunk", e);
        let index: [u64; 3] = std::array::from_fn(|a| (tile.lo[2 - a] / level.tile[2 - a]) as u64);
        if self.version == ZarrVersion::V3 {
            return self
                .out
                .while_live(|_| array.store_chunk(&index, values))
                .map_err(failed);
        }
        let c = level.chunk;
        let [tx, ty, tz] = level.tile;
        let mut chunk = Vec::with_capacity(c.iter().product());
        for cz in (0..tz).step_by(c[2]) {
            for cy in (0..ty).step_by(c[1]) {
                for cx in (0..tx).step_by(c[0]) {
                    let at = [tile.lo[0] + cx, tile.lo[1] + cy, tile.lo[2] + cz];
                    if (0..3).any(|a| at[a] >= level.dims[a]) {
                        continue;
                    }
                    chunk.clear();
                    for z in cz..cz + c[2] {
                        for y in cy..cy + c[1] {
                            let from = (z * ty + y) * tx + cx;
                            chunk.extend_from_slice(&values[from..from + c[0]]);
                        }
                    }
                    let index = [
                        (at[2] / c[2]) as u64,
                        (at[1] / c[1]) as u64,
                        (at[0] / c[0]) as u64,
                    ];
                    self.out
                        .while_live(|_| array.store_chunk(&index, &chunk[..]))
                        .map_err(failed)?;
                }
            }
        }
        Ok(())
    }
}

/// The tiles of a level, z slowest, each its box clipped to the level.
fn tiles(level: &Level) -> impl Iterator<Item = Box3> + '_ {
    let n: [usize; 3] = std::array::from_fn(|a| level.dims[a].div_ceil(level.tile[a]));
    (0..n[2]).flat_map(move |z| {
        (0..n[1]).flat_map(move |y| {
            (0..n[0]).map(move |x| {
                let lo = [x * level.tile[0], y * level.tile[1], z * level.tile[2]];
                Box3 {
                    lo,
                    hi: std::array::from_fn(|a| (lo[a] + level.tile[a]).min(level.dims[a])),
                }
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_take_the_smallest_of_those_tied_and_means_round() {
        assert_eq!(reduce(&mut [3u8, 1, 3, 1], true), 1);
        assert_eq!(reduce(&mut [3u8, 1, 3, 2], true), 3);
        assert_eq!(reduce(&mut [7i16], true), 7);
        assert_eq!(reduce(&mut [-5i8, 2, 9, 9, 2, -5], true), -5);
        assert_eq!(reduce(&mut [1u8, 2], false), 2);
        assert_eq!(reduce(&mut [-1i8, -2], false), -2);
        assert_eq!(reduce(&mut [1u16, 2, 2], false), 2);
        assert_eq!(reduce(&mut [0.5f32, 0.25], false), 0.375);
    }

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
