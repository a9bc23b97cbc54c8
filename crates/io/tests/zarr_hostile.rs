//! Hostile Zarr and OME-Zarr stores, written here by hand (a few lines of
//! JSON and the bytes of a chunk or shard each, so no Python is needed):
//! missing, truncated and garbage chunks; compressed chunks whose headers
//! lie about their size; metadata that lies (huge, zero or negative
//! shapes, chunk shapes of 0, unknown or unsupported data types and
//! codecs, malformed codec configurations, fill values of the wrong type,
//! invalid or non-object JSON); shards whose index points outside the
//! file; OME-Zarr multiscales that climb out of the store, disagree with
//! their arrays, or scale by 0 or a non-finite number. Each is refused
//! with a one-line error naming the store and the problem (the stable part
//! of each message is asserted), or, for missing chunks, read as the fill
//! value.
//!
//! This binary's allocator refuses any single allocation over
//! [`MALLOC_LIMIT`], as `ulimit -v` does for the command
//! (`tests/hostile_files.rs`) and `-malloc_limit_mb` for the fuzzers: an
//! allocation sized from a header's word aborts the run ("memory
//! allocation of N bytes failed") instead of passing unnoticed on a
//! machine that overcommits.

use std::alloc::{GlobalAlloc, Layout, System};
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::{Value, json};
use volray_core::SourceErrorKind;
use volray_io::{IoError, Loaded, ReadOptions, open_lazy, read};
use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;

/// The largest single allocation this binary allows: far above what the
/// tiny stores here need, far below what their lying headers ask for.
const MALLOC_LIMIT: usize = 256 << 20;

/// The system allocator, refusing (null, so the process aborts) any
/// allocation over [`MALLOC_LIMIT`].
struct Capped;

// SAFETY: forwards to `System`, or returns null, which `GlobalAlloc` allows.
unsafe impl GlobalAlloc for Capped {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > MALLOC_LIMIT {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > MALLOC_LIMIT {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > MALLOC_LIMIT {
            return std::ptr::null_mut();
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Capped = Capped;

/// `--max-memory` for every read here.
const LIMIT: u64 = 64 << 20;

fn opts() -> ReadOptions {
    ReadOptions {
        max_memory: LIMIT,
        ..ReadOptions::default()
    }
}

/// A store `s.zarr` in a new temporary directory, holding `files` (a path
/// in the store, its bytes).
fn store(files: &[(&str, Vec<u8>)]) -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("s.zarr");
    fs::create_dir(&root).unwrap();
    for (name, bytes) in files {
        let path = root.join(name);
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(path, bytes).unwrap();
    }
    (tmp, root)
}

fn text(value: &Value) -> Vec<u8> {
    value.to_string().into_bytes()
}

/// `zarr.json` of a Zarr v3 uint16 array: `shape` in chunks of `chunk`,
/// through `codecs`, fill value 7.
fn v3(shape: Value, chunk: Value, codecs: Value) -> Value {
    json!({
        "zarr_format": 3,
        "node_type": "array",
        "shape": shape,
        "data_type": "uint16",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": chunk}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": 7,
        "codecs": codecs,
    })
}

/// `.zarray` of a Zarr v2 little-endian uint16 array, fill value 7.
fn v2(shape: Value, chunks: Value, compressor: Value) -> Value {
    json!({
        "zarr_format": 2,
        "shape": shape,
        "chunks": chunks,
        "dtype": "<u2",
        "compressor": compressor,
        "fill_value": 7,
        "order": "C",
        "filters": null,
    })
}

fn bytes_codec() -> Value {
    json!([{"name": "bytes", "configuration": {"endian": "little"}}])
}

/// The codecs `bytes`, then `compressor`.
fn with(compressor: Value) -> Value {
    json!([{"name": "bytes", "configuration": {"endian": "little"}}, compressor])
}

fn zstd() -> Value {
    json!({"name": "zstd", "configuration": {"level": 3, "checksum": false}})
}

fn gzip() -> Value {
    json!({"name": "gzip", "configuration": {"level": 5}})
}

fn blosc() -> Value {
    json!({"name": "blosc", "configuration": {
        "cname": "lz4", "clevel": 5, "shuffle": "shuffle", "typesize": 2, "blocksize": 0
    }})
}

/// The uint16 values `0, 1, ... n - 1`, little-endian.
fn ramp(n: u16) -> Vec<u8> {
    (0..n).flat_map(u16::to_le_bytes).collect()
}

/// The 2 x 3 x 4 uint16 chunk `0..24` encoded by zarrs through `codecs`
/// (the reader's own codecs, so a valid chunk to cut or corrupt).
fn encoded(codecs: Value) -> Vec<u8> {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(
        tmp.path().join("zarr.json"),
        text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), codecs)),
    )
    .unwrap();
    let array = Array::open(Arc::new(FilesystemStore::new(tmp.path()).unwrap()), "/").unwrap();
    let values: Vec<u16> = (0..24).collect();
    array.store_chunk(&[0, 0, 0], values.as_slice()).unwrap();
    fs::read(tmp.path().join("c/0/0/0")).unwrap()
}

fn load(path: &Path) -> Loaded {
    read(path, &opts()).unwrap_or_else(|e| panic!("{e}"))
}

/// Reads `path`, which must be refused as bad input in one line that
/// starts with the store's path and holds `fragment`; returns the error.
fn refused(path: &Path, fragment: &str) -> IoError {
    let err = match read(path, &opts()) {
        Ok(loaded) => panic!(
            "{}: read as {:?}, expected a refusal with {fragment:?}",
            path.display(),
            loaded.volume.dims()
        ),
        Err(err) => err,
    };
    let message = err.to_string();
    assert!(!message.contains('\n'), "{message}");
    assert!(
        message.starts_with(&path.display().to_string()),
        "{message}"
    );
    assert!(!err.is_io_failure(), "{message}");
    assert!(
        message.contains(fragment),
        "expected {fragment:?} in: {message}"
    );
    err
}

// ------------------------------------------------------------------ chunks

#[test]
fn missing_chunks_read_as_the_fill_value() {
    // v3: two chunks along z, the second missing.
    let (_t, path) = store(&[
        (
            "zarr.json",
            text(&v3(json!([2, 3, 4]), json!([1, 3, 4]), bytes_codec())),
        ),
        ("c/0/0/0", ramp(12)),
    ]);
    let values = load(&path).volume.values().to_vec();
    let expected: Vec<f32> = (0..12).map(|v| v as f32).chain([7.0; 12]).collect();
    assert_eq!(values, expected);

    // The shape larger than the chunks present: every chunk missing.
    let (_t, path) = store(&[(
        "zarr.json",
        text(&v3(json!([4, 6, 8]), json!([2, 3, 4]), with(zstd()))),
    )]);
    let loaded = load(&path);
    assert_eq!(loaded.volume.dims(), [8, 6, 4]);
    assert!(loaded.volume.values().iter().all(|&v| v == 7.0));

    // v2, the first chunk missing.
    let (_t, path) = store(&[
        (
            ".zarray",
            text(&v2(json!([2, 3, 4]), json!([1, 3, 4]), Value::Null)),
        ),
        ("1.0.0", ramp(12)),
    ]);
    let values = load(&path).volume.values().to_vec();
    let expected: Vec<f32> = [7.0; 12]
        .into_iter()
        .chain((0..12).map(|v| v as f32))
        .collect();
    assert_eq!(values, expected);
}

#[test]
fn valid_hand_written_stores_read_their_values() {
    // The controls for the cases below: the same stores, unbroken.
    let ramp24: Vec<f32> = (0..24).map(|v| v as f32).collect();
    for codecs in [bytes_codec(), with(zstd()), with(gzip()), with(blosc())] {
        let chunk = encoded(codecs.clone());
        let (_t, path) = store(&[
            (
                "zarr.json",
                text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), codecs.clone())),
            ),
            ("c/0/0/0", chunk),
        ]);
        assert_eq!(load(&path).volume.values().to_vec(), ramp24, "{codecs}");
    }
    // A zstd frame written here: one RLE block of 48 bytes 0x07, its
    // content size declared.
    let (_t, path) = store(&[
        (
            "zarr.json",
            text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), with(zstd()))),
        ),
        ("c/0/0/0", zstd_rle_frame(Some(48), &[48])),
    ]);
    assert!(load(&path).volume.values().iter().all(|&v| v == 1799.0));
    // ... and without it.
    let (_t, path) = store(&[
        (
            "zarr.json",
            text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), with(zstd()))),
        ),
        ("c/0/0/0", zstd_rle_frame(None, &[40, 8])),
    ]);
    assert!(load(&path).volume.values().iter().all(|&v| v == 1799.0));
    let (_t, path) = sharded(&shard(&ramp(32), None), json!([2, 2, 2]));
    let values = load(&path).volume.values().to_vec();
    assert_eq!(values, sharded_values());
}

#[test]
fn truncated_and_garbage_chunks_are_refused() {
    let garbage = b"this is not a chunk of any codec at all!".to_vec();
    // What each cut gives: (cut in half, one byte short, empty, garbage).
    for (codecs, fragments) in [
        (
            bytes_codec(),
            [
                "the size of a decoded chunk is 24, expected 48",
                "the size of a decoded chunk is 47, expected 48",
                "the size of a decoded chunk is 0, expected 48",
                "the size of a decoded chunk is 40, expected 48",
            ],
        ),
        (
            with(zstd()),
            [
                "ends inside a block",
                "ends inside a block",
                "zstd data is empty",
                "no zstd frame at byte 0",
            ],
        ),
        (
            with(gzip()),
            [
                "gzip data: ",
                "gzip data: ",
                "gzip data: ",
                "gzip data: invalid gzip header",
            ],
        ),
        (
            with(blosc()),
            [
                "blosc encoded value is invalid",
                "blosc encoded value is invalid",
                "blosc data of 0 bytes is shorter than its 16-byte header",
                // "this is not a chunk": bytes 4..8 read as nbytes.
                "blosc header declares 544434464 bytes, more than the 48",
            ],
        ),
    ] {
        let meta = text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), codecs.clone()));
        let chunk = encoded(codecs.clone());
        let cuts = [
            chunk[..chunk.len() / 2].to_vec(),
            chunk[..chunk.len() - 1].to_vec(),
            Vec::new(),
            garbage.clone(),
        ];
        for (bytes, fragment) in cuts.into_iter().zip(fragments) {
            let (_t, path) = store(&[("zarr.json", meta.clone()), ("c/0/0/0", bytes)]);
            eprintln!("{codecs}");
            let message = refused(&path, fragment).to_string();
            assert!(message.contains(": cannot read Zarr chunks: "), "{message}");
        }
    }
    // v2: a gzip chunk cut short.
    let chunk = encoded(with(gzip()));
    let (_t, path) = store(&[
        (
            ".zarray",
            text(&v2(
                json!([2, 3, 4]),
                json!([2, 3, 4]),
                json!({"id": "gzip", "level": 5}),
            )),
        ),
        ("0.0.0", chunk[..chunk.len() - 5].to_vec()),
    ]);
    refused(&path, "cannot read Zarr chunks: gzip data: ");
}

/// A zstd frame of RLE blocks of 0x07, `sizes` bytes each, declaring
/// `content` bytes (or no content size: then a 128 KiB window).
fn zstd_rle_frame(content: Option<u64>, sizes: &[u32]) -> Vec<u8> {
    let mut f = vec![0x28, 0xb5, 0x2f, 0xfd];
    match content {
        // Frame header: 8-byte content size, single segment.
        Some(n) => {
            f.push(0b1110_0000);
            f.extend(n.to_le_bytes());
        }
        // No content size; window descriptor 2^17.
        None => f.extend([0, 7 << 3]),
    }
    for (i, &size) in sizes.iter().enumerate() {
        let last = u32::from(i + 1 == sizes.len());
        let header = last | (1 << 1) | (size << 3);
        f.extend(&header.to_le_bytes()[..3]);
        f.push(7);
    }
    f
}

#[test]
fn compressed_chunks_larger_than_their_chunk_are_refused_before_allocating() {
    let meta = |codecs| text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), codecs));
    // zstd declaring 2^40 bytes: zarrs would allocate that before decoding.
    let (_t, path) = store(&[
        ("zarr.json", meta(with(zstd()))),
        ("c/0/0/0", zstd_rle_frame(Some(1 << 40), &[48])),
    ]);
    refused(
        &path,
        "zstd data would inflate to up to 1099511627776 bytes, more than the 48 bytes it decodes to",
    );
    // zstd without a content size, 3000 blocks of 128 KiB: 375 MiB from
    // 12 KB, for a chunk of 48 bytes.
    let (_t, path) = store(&[
        ("zarr.json", meta(with(zstd()))),
        ("c/0/0/0", zstd_rle_frame(None, &[128 << 10; 3000])),
    ]);
    refused(&path, "more than the 48 bytes");
    // blosc declaring 2 GiB (its header's nbytes), compressed, in 32 bytes.
    let mut b = vec![2, 1, 0x01, 2];
    b.extend(0x7fff_ff00u32.to_le_bytes()); // nbytes
    b.extend(0x1_0000u32.to_le_bytes()); // blocksize
    b.extend(32u32.to_le_bytes()); // cbytes: the whole buffer
    b.resize(32, 0);
    let (_t, path) = store(&[("zarr.json", meta(with(blosc()))), ("c/0/0/0", b.clone())]);
    refused(
        &path,
        "blosc header declares 2147483392 bytes, more than the 48 bytes it decodes to",
    );
    // The same in Zarr v2 (whose blosc compressor zarrs builds apart).
    let v2_blosc =
        json!({"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1, "blocksize": 0});
    let (_t, path) = store(&[
        (
            ".zarray",
            text(&v2(json!([2, 3, 4]), json!([2, 3, 4]), v2_blosc)),
        ),
        ("0.0.0", b),
    ]);
    refused(&path, "blosc header declares 2147483392 bytes");
    // ... and zstd.
    let (_t, path) = store(&[
        (
            ".zarray",
            text(&v2(
                json!([2, 3, 4]),
                json!([2, 3, 4]),
                json!({"id": "zstd", "level": 3}),
            )),
        ),
        ("0.0.0", zstd_rle_frame(Some(1 << 40), &[48])),
    ]);
    refused(
        &path,
        "zstd data would inflate to up to 1099511627776 bytes",
    );
    // gzip inflating to 16 MiB for a chunk of 48 bytes.
    let mut z = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&vec![0; 16 << 20]).unwrap();
    let (_t, path) = store(&[
        ("zarr.json", meta(with(gzip()))),
        ("c/0/0/0", z.finish().unwrap()),
    ]);
    refused(&path, "more than the 48 bytes");
}

#[test]
fn sparse_files_of_a_terabyte_are_refused_before_reading() {
    // A chunk file of 2^40 bytes (sparse: nothing written).
    let (_t, path) = store(&[(
        "zarr.json",
        text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), with(zstd()))),
    )]);
    let chunk = path.join("c/0/0/0");
    fs::create_dir_all(chunk.parent().unwrap()).unwrap();
    fs::File::create(&chunk).unwrap().set_len(1 << 40).unwrap();
    refused(
        &path,
        "c/0/0/0: 1099511627776 bytes to read at once, more than 67108864",
    );
    // A level's metadata file of 2^40 bytes.
    let (_t, path) = ome(image(json!([level("0", json!([1, 1, 1]))])));
    fs::File::create(path.join("0/zarr.json"))
        .unwrap()
        .set_len(1 << 40)
        .unwrap();
    refused(
        &path,
        "zarr.json: 1099511627776 bytes to read at once, more than 16777216",
    );
}

// ---------------------------------------------------------------- metadata

#[test]
fn huge_declared_shapes_are_refused_before_allocating() {
    let huge = 1u64 << 40;
    for (shape, chunk) in [
        (json!([huge, huge, huge]), json!([huge, huge, huge])),
        (json!([huge, huge, huge]), json!([4, 4, 4])),
        (json!([huge, 3, 4]), json!([huge, 3, 4])),
        (json!([u64::MAX, u64::MAX, u64::MAX]), json!([1, 1, 1])),
        (json!([2, 3, 4]), json!([huge, huge, huge])),
        (json!([2, 3, 4]), json!([u64::MAX, u64::MAX, u64::MAX])),
    ] {
        let (_t, path) = store(&[
            ("zarr.json", text(&v3(shape, chunk, with(zstd())))),
            ("c/0/0/0", encoded(with(zstd()))),
        ]);
        let err = refused(&path, "");
        let message = err.to_string();
        assert!(
            matches!(err, IoError::OverMemoryLimit { .. })
                || message.contains("more than this machine can address"),
            "{message}"
        );
    }
    // v2 alike.
    let (_t, path) = store(&[(
        ".zarray",
        text(&v2(
            json!([huge, huge, huge]),
            json!([huge, 1, 1]),
            Value::Null,
        )),
    )]);
    let err = refused(&path, "");
    assert!(
        matches!(err, IoError::OverMemoryLimit { .. })
            || err
                .to_string()
                .contains("more than this machine can address"),
        "{err}"
    );
    // A shard of 2^30 subchunks of one value: its index alone is 16 GiB.
    let (_t, path) = store(&[(
        "zarr.json",
        text(&v3(
            json!([1024, 1024, 1024]),
            json!([1024, 1024, 1024]),
            json!([{"name": "sharding_indexed", "configuration": {
                "chunk_shape": [1, 1, 1],
                "codecs": bytes_codec(),
                "index_codecs": bytes_codec(),
            }}]),
        )),
    )]);
    let err = refused(&path, "");
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
}

#[test]
fn zero_and_negative_shapes_and_chunk_shapes_are_refused() {
    let (_t, path) = store(&[(
        "zarr.json",
        text(&v3(json!([2, 0, 4]), json!([2, 3, 4]), bytes_codec())),
    )]);
    refused(&path, "axis 1 has size 0");
    for (shape, chunk) in [
        (json!([2, -3, 4]), json!([2, 3, 4])),
        (json!([2, 3, 4]), json!([2, 0, 4])),
        (json!([2, 3, 4]), json!([2, -3, 4])),
        (json!([2, 3, 4]), json!([2, 3])),
        (json!([2.5, 3, 4]), json!([2, 3, 4])),
        (json!("2, 3, 4"), json!([2, 3, 4])),
    ] {
        let (_t, path) = store(&[("zarr.json", text(&v3(shape, chunk, bytes_codec())))]);
        refused(&path, "not a readable Zarr array");
    }
    for chunks in [json!([2, 0, 4]), json!([2, -1, 4])] {
        let (_t, path) = store(&[(".zarray", text(&v2(json!([2, 3, 4]), chunks, Value::Null)))]);
        refused(&path, "not a readable Zarr array");
    }
}

/// `meta` with `key` set to `value`.
fn set(mut meta: Value, key: &str, value: Value) -> Value {
    meta[key] = value;
    meta
}

#[test]
fn unknown_and_unsupported_data_types_are_refused() {
    let base = v3(json!([2, 3, 4]), json!([2, 3, 4]), bytes_codec());
    for (dtype, fill, fragment) in [
        (json!("uint128"), json!(0), "uint128"),
        (json!("float128x"), json!(0), "float128x"),
        (json!(""), json!(0), "not a readable Zarr array"),
        (json!(16), json!(0), "not a readable Zarr array"),
        (json!({"name": "frobnicate"}), json!(0), "frobnicate"),
        (
            json!("bool"),
            json!(false),
            "Zarr data type \"bool\" is not supported",
        ),
        (
            json!("float16"),
            json!(0.0),
            "Zarr data type \"float16\" is not supported",
        ),
        (
            json!("complex64"),
            json!([0.0, 0.0]),
            "Zarr data type \"complex64\" is not supported",
        ),
        (json!("string"), json!(""), "not supported"),
        // Of the wrong type for the data type: refused as such.
        (json!("bool"), json!(0), "invalid fill value"),
    ] {
        let meta = set(set(base.clone(), "data_type", dtype), "fill_value", fill);
        let (_t, path) = store(&[("zarr.json", text(&meta))]);
        refused(&path, fragment);
    }
    let base = v2(json!([2, 3, 4]), json!([2, 3, 4]), Value::Null);
    for (dtype, fill, fragment) in [
        (json!("<q9"), json!(0), "not a readable Zarr array"),
        (
            json!("|b1"),
            json!(false),
            "Zarr data type \"|b1\" is not supported",
        ),
        (
            json!("<c8"),
            json!([0.0, 0.0]),
            "Zarr data type \"<c8\" is not supported",
        ),
        (json!([["a", "<u2"]]), json!(null), "not"),
    ] {
        let meta = set(set(base.clone(), "dtype", dtype), "fill_value", fill);
        let (_t, path) = store(&[(".zarray", text(&meta))]);
        refused(&path, fragment);
    }
}

#[test]
fn unknown_codecs_and_malformed_codec_configurations_are_refused() {
    for (codecs, fragment) in [
        (with(json!({"name": "frobnicate"})), "frobnicate"),
        (json!([{"name": "frobnicate"}]), "frobnicate"),
        (
            with(json!({"name": "zstd", "configuration": {"level": "high"}})),
            "Zstd compression level",
        ),
        (
            with(
                json!({"name": "blosc", "configuration": {"cname": "nope", "clevel": 5, "shuffle": "shuffle", "typesize": 2, "blocksize": 0}}),
            ),
            "BloscCodecConfiguration",
        ),
        (
            with(json!({"name": "gzip", "configuration": {"level": 99}})),
            "GzipCodecConfiguration",
        ),
        (
            with(json!({"name": "gzip", "configuration": [5]})),
            "error parsing metadata for zarr.json",
        ),
        (
            json!([{"name": "bytes", "configuration": {"endian": "middle"}}]),
            "BytesCodecConfiguration",
        ),
        (json!([]), "missing array to bytes codec"),
        (json!("zstd"), "expected a sequence"),
        (json!([zstd()]), "missing array to bytes codec"),
        (
            json!([{"name": "bytes"}, {"name": "bytes"}]),
            "multiple array to bytes codecs",
        ),
    ] {
        let (_t, path) = store(&[(
            "zarr.json",
            text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), codecs.clone())),
        )]);
        eprintln!("{codecs}");
        refused(&path, fragment);
    }
    for (compressor, fragment) in [
        (
            json!({"id": "frobnicate"}),
            "codec frobnicate is not supported",
        ),
        (json!("zstd"), "error parsing metadata for .zarray"),
        (
            json!({"id": "blosc", "cname": "nope", "clevel": 5, "shuffle": 1}),
            "unknown variant `nope`",
        ),
        (
            json!({"id": "zstd", "level": "high"}),
            "ZstdCodecConfiguration",
        ),
    ] {
        let (_t, path) = store(&[(
            ".zarray",
            text(&v2(json!([2, 3, 4]), json!([2, 3, 4]), compressor)),
        )]);
        refused(&path, fragment);
    }
    let meta = set(
        v2(json!([2, 3, 4]), json!([2, 3, 4]), Value::Null),
        "order",
        json!("X"),
    );
    let (_t, path) = store(&[(".zarray", text(&meta))]);
    refused(&path, "not a readable Zarr array");
}

#[test]
fn fill_values_of_the_wrong_type_are_refused() {
    let base = v3(json!([2, 3, 4]), json!([2, 3, 4]), bytes_codec());
    for fill in [
        json!("abc"),
        json!(70000),
        json!(-1),
        json!(1.5),
        json!([1, 2]),
        json!({"a": 1}),
        json!(null),
        json!(true),
        json!("NaN"),
    ] {
        let (_t, path) = store(&[("zarr.json", text(&set(base.clone(), "fill_value", fill)))]);
        refused(&path, "not a readable Zarr array");
    }
    let base = v2(json!([2, 3, 4]), json!([2, 3, 4]), Value::Null);
    for fill in [json!("abc"), json!(70000), json!([1, 2])] {
        let (_t, path) = store(&[(".zarray", text(&set(base.clone(), "fill_value", fill)))]);
        refused(&path, "not a readable Zarr array");
    }
}

#[test]
fn metadata_that_is_not_a_json_object_is_refused() {
    for (bytes, fragment) in [
        (&b"{\"zarr_format\": 3, "[..], "invalid JSON"),
        (b"", "invalid JSON"),
        (b"\xff\xfe{}", "invalid JSON"),
        (b"[]", "\"node_type\" is missing"),
        (b"[1, 2, 3]", "\"node_type\" is missing"),
        (b"null", "\"node_type\" is missing"),
        (b"42", "\"node_type\" is missing"),
        (b"{}", "\"node_type\" is missing"),
        (b"{\"node_type\": \"tree\"}", "\"node_type\" is \"tree\""),
        (
            b"{\"zarr_format\": 3, \"node_type\": \"array\"}",
            "not a readable Zarr array",
        ),
    ] {
        let (_t, path) = store(&[("zarr.json", bytes.to_vec())]);
        refused(&path, fragment);
    }
    let meta = set(
        v3(json!([2, 3, 4]), json!([2, 3, 4]), bytes_codec()),
        "zarr_format",
        json!(4),
    );
    let (_t, path) = store(&[("zarr.json", text(&meta))]);
    refused(&path, "not a readable Zarr array");
    // v2: .zarray empty, a list, invalid; .zattrs invalid.
    for (bytes, fragment) in [
        (&b""[..], "not a readable Zarr array"),
        (b"[]", "not a readable Zarr array"),
        (b"{\"shape\": [2, 3", "not a readable Zarr array"),
    ] {
        let (_t, path) = store(&[(".zarray", bytes.to_vec())]);
        refused(&path, fragment);
    }
    let (_t, path) = store(&[
        (".zgroup", b"{\"zarr_format\": 2}".to_vec()),
        (".zattrs", b"{".to_vec()),
    ]);
    refused(&path, "invalid JSON");
}

// ---------------------------------------------------------------- sharding

/// A shard of the 2 x 4 x 4 uint16 array `0..32` in subchunks of 2 x 2 x
/// 2 (uncompressed, 16 bytes each, in C order of the 1 x 2 x 2 subchunk
/// grid), its index (offset, nbytes per subchunk, `bytes` little-endian)
/// at the end; `index` replaces the index's values where given.
fn shard(values: &[u8], index: Option<[u64; 8]>) -> Vec<u8> {
    let value = |z: usize, y: usize, x: usize| &values[2 * (z * 16 + y * 4 + x)..][..2];
    let mut data = Vec::new();
    let mut offsets = Vec::new();
    for cy in 0..2 {
        for cx in 0..2 {
            offsets.extend([data.len() as u64, 16]);
            for z in 0..2 {
                for y in 2 * cy..2 * cy + 2 {
                    for x in 2 * cx..2 * cx + 2 {
                        data.extend(value(z, y, x));
                    }
                }
            }
        }
    }
    let index = index.map_or(offsets, |i| i.to_vec());
    data.extend(index.iter().flat_map(|v| v.to_le_bytes()));
    data
}

/// What [`shard`] holds, as read.
fn sharded_values() -> Vec<f32> {
    (0..32).map(|v| v as f32).collect()
}

/// A sharded Zarr v3 uint16 array of shape 2 x 4 x 4, one shard `bytes`
/// at `c/0/0/0`, subchunks of `inner`.
fn sharded(bytes: &[u8], inner: Value) -> (tempfile::TempDir, PathBuf) {
    let meta = v3(
        json!([2, 4, 4]),
        json!([2, 4, 4]),
        json!([{"name": "sharding_indexed", "configuration": {
            "chunk_shape": inner,
            "codecs": bytes_codec(),
            "index_codecs": bytes_codec(),
            "index_location": "end",
        }}]),
    );
    store(&[("zarr.json", text(&meta)), ("c/0/0/0", bytes.to_vec())])
}

#[test]
fn shard_indexes_pointing_outside_their_file_are_refused() {
    let values = ramp(32);
    let len = shard(&values, None).len() as u64; // 64 bytes of data, 64 of index
    let max = u64::MAX;
    let past = |i: usize, offset: u64, nbytes: u64| {
        format!(
            "the shard index places subchunk {i} at bytes {offset} to {offset} + {nbytes}, past the shard's {len} bytes"
        )
    };
    for (index, fragment) in [
        // The offset past the end, then nbytes.
        (
            [0, 16, 16, 16, 32, 16, len + 100, 16],
            past(3, len + 100, 16),
        ),
        ([0, 16, 16, 16, 32, 16, 48, 1000], past(3, 48, 1000)),
        // Huge: the sum past 2^64 panicked in zarrs.
        ([0, 16, max - 8, 16, 32, 16, 48, 16], past(1, max - 8, 16)),
        ([0, 16, 16, max - 1, 32, 16, 48, 16], past(1, 16, max - 1)),
        (
            [0, 16, 1 << 63, 1 << 63, 32, 16, 48, 16],
            past(1, 1 << 63, 1 << 63),
        ),
        ([0, 1 << 40, 16, 16, 32, 16, 48, 16], past(0, 0, 1 << 40)),
        // Half of the missing mark (2^64 - 1 twice) is no mark.
        ([0, 16, max, 16, 32, 16, 48, 16], past(1, max, 16)),
        // Within the shard, but short of a subchunk's 16 bytes.
        (
            [0, 3, 16, 16, 32, 16, 48, 16],
            "the size of a decoded chunk is 3, expected 16".to_string(),
        ),
    ] {
        let (_t, path) = sharded(&shard(&values, Some(index)), json!([2, 2, 2]));
        refused(&path, &fragment);
    }
    // Subchunks marked missing (offset and nbytes both 2^64 - 1) are the
    // fill value.
    let (_t, path) = sharded(
        &shard(&values, Some([0, 16, max, max, 32, 16, max, max])),
        json!([2, 2, 2]),
    );
    let read = load(&path).volume.values().to_vec();
    // Subchunks 1 and 3 hold x = 2, 3.
    let expected: Vec<f32> = sharded_values()
        .into_iter()
        .enumerate()
        .map(|(i, v)| if i % 4 >= 2 { 7.0 } else { v })
        .collect();
    assert_eq!(read, expected);
}

/// Boxes of a shard read lazily: `zarrs` then reads the index and only
/// the subchunks a box needs (its partial decoder), another path than a
/// whole shard's.
#[test]
fn lazy_boxes_of_shards_with_lying_indexes_are_refused() {
    let values = ramp(32);
    let read_box = |bytes: &[u8], lo: [usize; 3], hi: [usize; 3]| {
        let (_t, path) = sharded(bytes, json!([2, 2, 2]));
        let lazy = open_lazy(&path, &opts()).unwrap().expect("opens lazily");
        lazy.source.read_box(lo, hi).map(|v| v.values().to_vec())
    };
    // The control: subchunk 0 (x, y < 2) and subchunk 3 (x, y >= 2).
    let whole = sharded_values();
    let pick = |xs: std::ops::Range<usize>, ys: std::ops::Range<usize>| -> Vec<f32> {
        let mut out = Vec::new();
        for z in 0..2 {
            for y in ys.clone() {
                for x in xs.clone() {
                    out.push(whole[z * 16 + y * 4 + x]);
                }
            }
        }
        out
    };
    let good = shard(&values, None);
    assert_eq!(read_box(&good, [0, 0, 0], [2, 2, 2]), Ok(pick(0..2, 0..2)));
    assert_eq!(read_box(&good, [2, 2, 0], [4, 4, 2]), Ok(pick(2..4, 2..4)));
    let max = u64::MAX;
    let len = good.len() as u64;
    for (what, index, fragment) in [
        (
            "offset past the end",
            [len + 100, 16, 16, 16, 32, 16, 48, 16],
            "past its end",
        ),
        (
            "nbytes of 2^40",
            [0, 1 << 40, 16, 16, 32, 16, 48, 16],
            "each is 16",
        ),
        (
            "huge offset",
            [max - 8, 16, 16, 16, 32, 16, 48, 16],
            "the shard index places subchunk 0",
        ),
        (
            "offset + nbytes wrapping",
            [1 << 63, 1 << 63, 16, 16, 32, 16, 48, 16],
            "the shard index places subchunk 0",
        ),
        (
            "nbytes short of a subchunk",
            [0, 3, 16, 16, 32, 16, 48, 16],
            "each is 16",
        ),
    ] {
        let err = read_box(&shard(&values, Some(index)), [0, 0, 0], [2, 2, 2]).expect_err(what);
        assert_eq!(err.kind, SourceErrorKind::BadData, "{what}: {err}");
        let err = err.message;
        assert!(!err.contains('\n'), "{what}: {err}");
        assert!(err.contains("s.zarr"), "{what}: {err}");
        assert!(
            err.contains(fragment),
            "{what}: expected {fragment:?} in {err}"
        );
    }
    // A shard too short for its index.
    let err = read_box(&good[..40], [0, 0, 0], [2, 2, 2]).expect_err("cut shard");
    assert_eq!(err.kind, SourceErrorKind::BadData, "{err}");
    assert!(err.message.contains("past its end"), "{err}");
}

#[test]
fn truncated_shard_indexes_and_uneven_subchunks_are_refused() {
    let whole = shard(&ramp(32), None);
    for cut in [0, 10, 63] {
        let (_t, path) = sharded(&whole[..cut], json!([2, 2, 2]));
        refused(
            &path,
            "The encoded shard is smaller than the expected size of its index",
        );
    }
    // One byte short: the index, read from the end, is shifted.
    let (_t, path) = sharded(&whole[..whole.len() - 1], json!([2, 2, 2]));
    refused(&path, "past the shard's 127 bytes");
    // Subchunks of 2 x 3 x 4 do not divide a shard of 2 x 4 x 4.
    let (_t, path) = sharded(&whole, json!([2, 3, 4]));
    refused(
        &path,
        "the subchunk shape [2, 3, 4] does not divide the shard shape [2, 4, 4]",
    );
    for (inner, fragment) in [
        (json!([2, 0, 2]), "ShardingCodecConfiguration"),
        (
            json!([2, 2]),
            "the subchunk shape [2, 2] does not divide the shard shape [2, 4, 4]",
        ),
        (
            json!([4, 4, 4]),
            "the subchunk shape [4, 4, 4] does not divide the shard shape [2, 4, 4]",
        ),
    ] {
        let (_t, path) = sharded(&whole, inner);
        refused(&path, fragment);
    }
}

// ---------------------------------------------------------------- OME-Zarr

/// An OME-Zarr 0.5 image: the group's `multiscales` (the list, as given)
/// and one 2 x 3 x 4 uint16 level at `0/`.
fn ome(multiscales: Value) -> (tempfile::TempDir, PathBuf) {
    let group = json!({
        "zarr_format": 3,
        "node_type": "group",
        "attributes": {"ome": {"version": "0.5", "multiscales": multiscales}},
    });
    store(&[
        ("zarr.json", text(&group)),
        (
            "0/zarr.json",
            text(&v3(json!([2, 3, 4]), json!([2, 3, 4]), bytes_codec())),
        ),
        ("0/c/0/0/0", ramp(24)),
    ])
}

fn axes3() -> Value {
    json!([
        {"name": "z", "type": "space"},
        {"name": "y", "type": "space"},
        {"name": "x", "type": "space"},
    ])
}

/// One multiscale of `axes3` and `datasets`.
fn image(datasets: Value) -> Value {
    json!([{"axes": axes3(), "datasets": datasets}])
}

fn level(path: &str, scale: Value) -> Value {
    json!({"path": path, "coordinateTransformations": [{"type": "scale", "scale": scale}]})
}

#[test]
fn ome_zarr_multiscales_that_lie_are_refused() {
    // The control: a valid image.
    let (_t, path) = ome(image(json!([level("0", json!([3.0, 2.0, 1.0]))])));
    let loaded = load(&path);
    assert_eq!(loaded.volume.spacing().to_array(), [1.0, 2.0, 3.0]);

    for (multiscales, fragment) in [
        (json!({"axes": axes3()}), "expected a non-empty list"),
        (json!("0"), "expected a non-empty list"),
        (json!([]), "expected a non-empty list"),
        (json!([{"axes": axes3()}]), "no \"datasets\" list"),
        (image(json!([])), "no \"datasets\" list"),
        (image(json!({"path": "0"})), "no \"datasets\" list"),
        (image(json!([{"scale": 1}])), "dataset 0 has no \"path\""),
        (
            image(json!([level("../..", json!([1, 1, 1]))])),
            "dataset 0 has path \"../..\"",
        ),
        (
            image(json!([level("0/../../..", json!([1, 1, 1]))])),
            "dataset 0 has path \"0/../../..\"",
        ),
        (
            image(json!([level("/etc", json!([1, 1, 1]))])),
            "dataset 0 has path \"/etc\"",
        ),
        (
            image(json!([level("", json!([1, 1, 1]))])),
            "dataset 0 has path \"\"",
        ),
        (
            image(json!([level("0", json!([1, 0, 1]))])),
            "must be positive",
        ),
        (
            image(json!([level("0", json!([1, -2, 1]))])),
            "must be positive",
        ),
        (
            image(json!([level("0", json!([1, "NaN", 1]))])),
            "scale value \"NaN\" is not a finite number",
        ),
        (
            image(json!([level("0", json!([1, 1]))])),
            "scale has 2 values for 3 axes",
        ),
        (
            image(json!([{"path": "0", "coordinateTransformations": [
                {"type": "scale", "scale": [1, 1, 1]},
                {"type": "translation", "translation": [0, "nan", 0]},
            ]}])),
            "translation value \"nan\" is not a finite number",
        ),
        (
            image(json!([{"path": "0", "coordinateTransformations": {"type": "scale"}}])),
            "expected a list",
        ),
        (
            image(json!([{"path": "0", "coordinateTransformations": [
                {"type": "affine", "affine": [1, 2, 3]},
            ]}])),
            "transformation type \"affine\" is not supported",
        ),
        (
            json!([{"axes": "zyx", "datasets": [level("0", json!([1, 1, 1]))]}]),
            "no \"axes\" list",
        ),
        (
            json!([{"axes": [{"type": "space"}, "y", "x"], "datasets": [level("0", json!([1, 1, 1]))]}]),
            "has no name",
        ),
        // Axes that disagree with the array: four for a 3-D array, two.
        (
            json!([{
                "axes": [{"name": "t", "type": "time"}, "z", "y", "x"],
                "datasets": [level("0", json!([1, 1, 1, 1]))],
            }]),
            "the array has 3 dimensions but the image has 4 axes",
        ),
        (
            json!([{"axes": ["y", "x"], "datasets": [level("0", json!([1, 1]))]}]),
            "volray reads three space axes",
        ),
        (
            json!([{"axes": [], "datasets": [level("0", json!([]))]}]),
            "volray reads three space axes",
        ),
        // A level whose array is missing.
        (
            image(json!([
                level("0", json!([1, 1, 1])),
                level("1", json!([2, 2, 2]))
            ])),
            "not a readable Zarr array",
        ),
    ] {
        eprintln!("{multiscales}");
        let (_t, path) = ome(multiscales);
        refused(&path, fragment);
        assert!(!path.join("1").exists(), "a missing level was created");
    }
}

#[test]
fn ome_zarr_scales_overflowing_to_infinity_are_refused() {
    // Each finite, their product (the multiscale's scale times the
    // level's) not.
    let multiscales = json!([{
        "axes": axes3(),
        "coordinateTransformations": [{"type": "scale", "scale": [1e300, 1, 1]}],
        "datasets": [level("0", json!([1e300, 1, 1]))],
    }]);
    let (_t, path) = ome(multiscales);
    refused(&path, "spacing");
    let multiscales = json!([{
        "axes": axes3(),
        "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1e300]}],
        "datasets": [{"path": "0", "coordinateTransformations": [
            {"type": "scale", "scale": [1, 1, 1]},
            {"type": "translation", "translation": [0, 0, 1e300]},
        ]}],
    }]);
    let (_t, path) = ome(multiscales);
    refused(&path, "origin");
}

#[test]
fn ome_zarr_0_4_on_zarr_v2_with_a_missing_level_is_refused() {
    let attrs = json!({"multiscales": [{
        "version": "0.4",
        "axes": axes3(),
        "datasets": [level("s0", json!([1, 1, 1])), level("s1", json!([2, 2, 2]))],
    }]});
    let (_t, path) = store(&[
        (".zgroup", b"{\"zarr_format\": 2}".to_vec()),
        (".zattrs", text(&attrs)),
        (
            "s0/.zarray",
            text(&v2(json!([2, 3, 4]), json!([2, 3, 4]), Value::Null)),
        ),
        ("s0/0.0.0", ramp(24)),
    ]);
    refused(&path, "not a readable Zarr array");
    assert!(!path.join("s1").exists());
    // multiscales that is not a list.
    let (_t, path) = store(&[
        (".zgroup", b"{\"zarr_format\": 2}".to_vec()),
        (".zattrs", b"{\"multiscales\": {\"datasets\": []}}".to_vec()),
    ]);
    refused(&path, "expected a non-empty list");
}

// ------------------------------------------------------------ fuzz seeds

/// The zarr fuzz target's seeds (`fuzz/seeds/zarr/`, stores written by
/// zarr-python), unpacked as the target unpacks its input
/// (`fuzz/fuzz_targets/zarr.rs`), all read: the values `0, 1, 2, ...`
/// (mod 200), or the fill value 7 where the seed has no chunk file; a
/// lazy seed's box of half the array equals that part of the whole.
#[test]
fn the_zarr_fuzz_seeds_are_valid_stores() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/zarr");
    let mut seeds: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    seeds.sort();
    assert!(seeds.len() >= 10, "{} seeds", seeds.len());
    let mut kinds = [0; 8];
    for seed in &seeds {
        let data = fs::read(seed).unwrap();
        let (control, len) = (data[0], usize::from(u16::from_le_bytes([data[1], data[2]])));
        let (meta, chunk) = data[3..].split_at(len);
        kinds[usize::from(control & 7)] += 1;
        let (meta_name, chunk_name) = if control & 1 != 0 {
            (".zarray", "0.0.0")
        } else {
            ("zarr.json", "c/0/0/0")
        };
        let mut files = vec![(meta_name, meta.to_vec())];
        if control & 2 == 0 {
            files.push((chunk_name, chunk.to_vec()));
        }
        let (_t, path) = store(&files);
        let whole = load(&path).volume;
        let n = whole.values().len();
        let expected: Vec<f32> = if control & 2 != 0 {
            vec![7.0; n]
        } else {
            (0..n).map(|i| (i % 200) as f32).collect()
        };
        assert_eq!(whole.values().to_vec(), expected, "{}", seed.display());
        if control & 4 != 0 {
            let lazy = open_lazy(&path, &opts()).unwrap().expect("opens lazily");
            let hi = whole.dims().map(|d| d.div_ceil(2).max(2).min(d));
            let part = lazy.source.read_box([0; 3], hi).unwrap();
            for k in 0..hi[2] {
                for j in 0..hi[1] {
                    for i in 0..hi[0] {
                        assert_eq!(part.get(i, j, k), whole.get(i, j, k), "{}", seed.display());
                    }
                }
            }
        }
    }
    // v3 and v2, a missing chunk, a lazy read.
    assert!(
        kinds[0] > 0 && kinds[1] > 0 && kinds[2] > 0 && kinds[4] > 0,
        "{kinds:?}"
    );
}
