//! An OME-Zarr image's metadata as [`write_ome_zarr`] writes it: the
//! group's `multiscales` (OME-Zarr 0.5 in `zarr.json`, or 0.4 in
//! `.zattrs`), each level's array metadata (sharded zstd for Zarr v3,
//! blosc-zstd chunks for v2), and the `zarrs` array made from it.
//!
//! [`write_ome_zarr`]: super::write_ome_zarr

use std::path::Path;
use std::sync::Arc;

use serde_json::{Value, json};
use volray_core::SampleType;
use volray_core::glam::DVec3;
use zarrs::array::{Array, ArrayMetadata};
use zarrs::filesystem::FilesystemStore;

use super::{Image, Level, ZSTD_LEVEL, ZarrVersion};
use crate::IoError;
use crate::formats::zarr::chunks::zarr_error;

impl Image<'_> {
    /// The group's metadata: OME-Zarr `multiscales`.
    pub(super) fn write_group(&self, root: &Path) -> Result<(), IoError> {
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
    pub(super) fn create_array(
        &self,
        root: &Path,
        k: usize,
    ) -> Result<Array<FilesystemStore>, IoError> {
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
}
