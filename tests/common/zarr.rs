//! Zarr v3 arrays written byte by byte (a `zarr.json` and one file per
//! chunk), for the tests that read a chunked level whole or in pieces.

use std::fs;
use std::path::Path;

/// The side of every chunk.
pub const CHUNK: usize = 16;

/// One level of `dims` (x, y, z) at `dir` in chunks of 16³ (z, y, x):
/// samples of `data_type`, `at(x, y, z)` the little-endian bytes of each,
/// zeros (the fill value `fill`) past the array's edge.
pub fn write_level<const N: usize>(
    dir: &Path,
    dims: [usize; 3],
    data_type: &str,
    fill: serde_json::Value,
    at: &dyn Fn(usize, usize, usize) -> [u8; N],
) {
    let shape = [dims[2], dims[1], dims[0]];
    let meta = serde_json::json!({
        "zarr_format": 3,
        "node_type": "array",
        "shape": shape,
        "data_type": data_type,
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [CHUNK, CHUNK, CHUNK]}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": fill,
        "codecs": [{"name": "bytes", "configuration": {"endian": "little"}}],
    });
    fs::create_dir_all(dir).unwrap();
    fs::write(dir.join("zarr.json"), meta.to_string()).unwrap();
    let chunks = shape.map(|n| n.div_ceil(CHUNK));
    for cz in 0..chunks[0] {
        for cy in 0..chunks[1] {
            for cx in 0..chunks[2] {
                let mut bytes = Vec::with_capacity(N * CHUNK.pow(3));
                for z in cz * CHUNK..(cz + 1) * CHUNK {
                    for y in cy * CHUNK..(cy + 1) * CHUNK {
                        for x in cx * CHUNK..(cx + 1) * CHUNK {
                            let inside = x < dims[0] && y < dims[1] && z < dims[2];
                            let v = if inside { at(x, y, z) } else { [0; N] };
                            bytes.extend_from_slice(&v);
                        }
                    }
                }
                let file = dir.join(format!("c/{cz}/{cy}/{cx}"));
                fs::create_dir_all(file.parent().unwrap()).unwrap();
                fs::write(file, bytes).unwrap();
            }
        }
    }
}
