//! What `zarrs` is given to read only after volray has checked it: the
//! bytes of a chunk, the index of a shard, the ranges of a file.
//!
//! `zarrs` trusts what it reads in four places where a hostile store can
//! make it allocate from a header's word or panic:
//!
//! - `zstd` allocates the content size a frame's header declares (or, for
//!   a frame without one, 128 KiB per block) before decoding: 20 bytes can
//!   ask for a terabyte;
//! - `blosc` allocates the `nbytes` of its 16-byte header (up to 2 GiB);
//! - `gzip` inflates to whatever the stream holds (a bomb);
//! - a shard's index is read as it is: an offset plus a length past
//!   `u64::MAX` panics (overflow, or a slice out of range), and a length
//!   past the end of the file is allocated before the read fails.
//!
//! So these codecs are registered with `zarrs` again, at run time (which
//! takes precedence over its own registration), as wrappers that check
//! first: the compressors against the size their output must have (the
//! decoded representation `zarrs` passes down: the chunk's bytes, or a
//! bound on them), the sharding codec its index against the shard's
//! length. Both decode whole chunks only (the default partial decoder),
//! so every byte they are handed has passed the check. [`CheckedStore`]
//! refuses reads past the end of a file and reads larger than the memory
//! limit (a sparse chunk file of a terabyte), and metadata files over
//! [`MAX_METADATA_BYTES`].

use std::any::Any;
use std::borrow::Cow;
use std::io::Read;
use std::num::NonZeroU64;
use std::sync::{Arc, Once};

use zarrs::array::codec::api::{
    ArrayBytes, ArrayBytesDecodeIntoTarget, ArrayBytesRaw, ArrayCodecTraits,
    ArrayPartialDecoderTraits, ArrayToBytesCodecTraits, BytesPartialDecoderTraits,
    BytesRepresentation, BytesToBytesCodecTraits, Codec, CodecError, CodecMetadataOptions,
    CodecOptions, CodecRuntimePluginV2, CodecRuntimePluginV3, CodecTraits, CodecTraitsV2,
    CodecTraitsV3, PartialDecoderCapability, PartialEncoderCapability, RecommendedConcurrency,
    StoragePartialDecoder, register_codec_v2, register_codec_v3,
};
use zarrs::array::codec::{
    BloscCodec, CodecChain, Crc32cCodec, GzipCodec, ShardingCodec, ShardingCodecConfiguration,
    ShardingIndexLocation, ZstdCodec,
};
use zarrs::array::data_type::uint64;
use zarrs::array::{ChunkShape, DataType, FillValue};
use zarrs::filesystem::FilesystemStore;
use zarrs::metadata::Configuration;
use zarrs::metadata::v3::MetadataV3;
use zarrs::plugin::{
    ExtensionAliasesV2, ExtensionAliasesV3, ExtensionName, PluginCreateError, ZarrVersion,
};
use zarrs::storage::byte_range::{ByteRange, ByteRangeIterator};
use zarrs::storage::{MaybeBytesIterator, ReadableStorageTraits, StorageError, StoreKey};

use super::store::{MARKERS, MAX_METADATA_BYTES};

/// Registers the checked codecs with `zarrs`, once per process.
pub(crate) fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        register_codec_v3(CodecRuntimePluginV3::new(ZstdCodec::matches_name_v3, |m| {
            Ok(bounded(
                <ZstdCodec as CodecTraitsV3>::create(m)?,
                Kind::Zstd,
            ))
        }));
        register_codec_v2(CodecRuntimePluginV2::new(ZstdCodec::matches_name_v2, |m| {
            Ok(bounded(
                <ZstdCodec as CodecTraitsV2>::create(m)?,
                Kind::Zstd,
            ))
        }));
        register_codec_v3(CodecRuntimePluginV3::new(GzipCodec::matches_name_v3, |m| {
            Ok(bounded(
                <GzipCodec as CodecTraitsV3>::create(m)?,
                Kind::Gzip,
            ))
        }));
        register_codec_v2(CodecRuntimePluginV2::new(GzipCodec::matches_name_v2, |m| {
            Ok(bounded(
                <GzipCodec as CodecTraitsV2>::create(m)?,
                Kind::Gzip,
            ))
        }));
        // A Zarr v2 blosc compressor is built by zarrs without the
        // registry: `chunks.rs` opens such arrays through v3 metadata.
        register_codec_v3(CodecRuntimePluginV3::new(
            BloscCodec::matches_name_v3,
            |m| {
                Ok(bounded(
                    <BloscCodec as CodecTraitsV3>::create(m)?,
                    Kind::Blosc,
                ))
            },
        ));
        register_codec_v2(CodecRuntimePluginV2::new(
            BloscCodec::matches_name_v2,
            |m| {
                Ok(bounded(
                    <BloscCodec as CodecTraitsV2>::create(m)?,
                    Kind::Blosc,
                ))
            },
        ));
        // crc32c's own partial decoder subtracts its 4 bytes from a
        // subchunk's length unchecked; wrapped, it decodes whole.
        register_codec_v3(CodecRuntimePluginV3::new(
            Crc32cCodec::matches_name_v3,
            |m| {
                Ok(bounded(
                    <Crc32cCodec as CodecTraitsV3>::create(m)?,
                    Kind::Crc32c,
                ))
            },
        ));
        register_codec_v2(CodecRuntimePluginV2::new(
            Crc32cCodec::matches_name_v2,
            |m| {
                Ok(bounded(
                    <Crc32cCodec as CodecTraitsV2>::create(m)?,
                    Kind::Crc32c,
                ))
            },
        ));
        register_codec_v3(CodecRuntimePluginV3::new(
            ShardingCodec::matches_name_v3,
            CheckedSharding::create,
        ));
    });
}

fn bounded(codec: Codec, kind: Kind) -> Codec {
    match codec {
        Codec::BytesToBytes(inner) => Codec::BytesToBytes(Arc::new(Bounded { inner, kind })),
        other => other,
    }
}

/// A compressor wrapped by [`Bounded`].
#[derive(Debug, Clone, Copy)]
enum Kind {
    Zstd,
    Gzip,
    Blosc,
    /// Checked by zarrs; wrapped only to be decoded whole.
    Crc32c,
}

/// The slack a zstd frame without a content size is allowed over the
/// size it must decode to: zstd bounds such a frame by its blocks times
/// their largest size (128 KiB), so a few partly filled blocks of a
/// small chunk ask for more than the chunk; a megabyte, or the chunk's
/// size again if that is more.
const ZSTD_SLACK: u64 = 1 << 20;

/// A `zstd`, `gzip` or `blosc` codec that decodes nothing larger than its
/// decoded representation allows (and `crc32c`), each decoding whole
/// chunks only.
#[derive(Debug)]
struct Bounded {
    inner: Arc<dyn BytesToBytesCodecTraits>,
    kind: Kind,
}

impl Bounded {
    /// Refuses `encoded` where it would make the codec allocate more than
    /// `limit` bytes (zstd, blosc), or inflates it to at most `limit`
    /// bytes (gzip, returned).
    fn check(&self, encoded: &[u8], limit: u64) -> Result<Option<Vec<u8>>, CodecError> {
        match self.kind {
            Kind::Crc32c => Ok(None),
            Kind::Zstd => {
                let bound = zstd_bound(encoded).map_err(CodecError::Other)?;
                let allowed = limit.saturating_add(limit.max(ZSTD_SLACK));
                if bound > allowed {
                    return Err(CodecError::Other(format!(
                        "zstd data would inflate to up to {bound} bytes, more than the {limit} bytes it decodes to"
                    )));
                }
                Ok(None)
            }
            Kind::Blosc => {
                let Some(header) = encoded.get(..16) else {
                    return Err(CodecError::Other(format!(
                        "blosc data of {} bytes is shorter than its 16-byte header",
                        encoded.len()
                    )));
                };
                let nbytes = u32::from_le_bytes(header[4..8].try_into().expect("4 bytes"));
                if u64::from(nbytes) > limit {
                    return Err(CodecError::Other(format!(
                        "blosc header declares {nbytes} bytes, more than the {limit} bytes it decodes to"
                    )));
                }
                Ok(None)
            }
            Kind::Gzip => {
                // As zarrs' gzip codec reads it (one member), stopping one
                // byte past the limit.
                let mut out = Vec::new();
                flate2::read::GzDecoder::new(encoded)
                    .take(limit.saturating_add(1))
                    .read_to_end(&mut out)
                    .map_err(|e| CodecError::Other(format!("gzip data: {e}")))?;
                if out.len() as u64 > limit {
                    return Err(CodecError::Other(format!(
                        "gzip data inflates to more than the {limit} bytes it decodes to"
                    )));
                }
                Ok(Some(out))
            }
        }
    }
}

impl ExtensionName for Bounded {
    fn name(&self, version: ZarrVersion) -> Option<Cow<'static, str>> {
        self.inner.name(version)
    }
}

impl CodecTraits for Bounded {
    fn as_any(&self) -> &dyn Any {
        self.inner.as_any()
    }

    fn configuration(
        &self,
        version: ZarrVersion,
        options: &CodecMetadataOptions,
    ) -> Option<Configuration> {
        self.inner.configuration(version, options)
    }

    fn partial_decoder_capability(&self) -> PartialDecoderCapability {
        PartialDecoderCapability {
            partial_read: false,
            partial_decode: false,
        }
    }

    fn partial_encoder_capability(&self) -> PartialEncoderCapability {
        PartialEncoderCapability {
            partial_encode: false,
        }
    }
}

impl BytesToBytesCodecTraits for Bounded {
    fn into_dyn(self: Arc<Self>) -> Arc<dyn BytesToBytesCodecTraits> {
        self
    }

    fn recommended_concurrency(
        &self,
        decoded_representation: &BytesRepresentation,
    ) -> Result<RecommendedConcurrency, CodecError> {
        self.inner.recommended_concurrency(decoded_representation)
    }

    fn encoded_representation(
        &self,
        decoded_representation: &BytesRepresentation,
    ) -> BytesRepresentation {
        self.inner.encoded_representation(decoded_representation)
    }

    fn encode<'a>(
        &self,
        decoded_value: ArrayBytesRaw<'a>,
        options: &CodecOptions,
    ) -> Result<ArrayBytesRaw<'a>, CodecError> {
        self.inner.encode(decoded_value, options)
    }

    fn decode<'a>(
        &self,
        encoded_value: ArrayBytesRaw<'a>,
        decoded_representation: &BytesRepresentation,
        options: &CodecOptions,
    ) -> Result<ArrayBytesRaw<'a>, CodecError> {
        // Unbounded only for variable-sized data types, which volray
        // refuses before reading.
        if let Some(limit) = decoded_representation.size()
            && let Some(decoded) = self.check(&encoded_value, limit)?
        {
            return Ok(Cow::Owned(decoded));
        }
        self.inner
            .decode(encoded_value, decoded_representation, options)
    }
}

/// The most bytes zstd allocates to decode `data` (`ZSTD_decompressBound`,
/// which `zarrs` passes to zstd's bulk decoder): per frame its declared
/// content size, or else its blocks times their largest size; skippable
/// frames add nothing. Data that is no sequence of whole zstd frames is
/// refused here (zstd would refuse it too, after decoding what it could).
fn zstd_bound(data: &[u8]) -> Result<u64, String> {
    let cut = |what: &str| format!("zstd data of {} bytes ends inside {what}", data.len());
    let bytes = |at: usize, n: usize, what: &str| {
        at.checked_add(n)
            .and_then(|end| data.get(at..end))
            .ok_or_else(|| cut(what))
    };
    let le = |b: &[u8]| b.iter().rev().fold(0u64, |v, &x| (v << 8) | u64::from(x));
    if data.is_empty() {
        return Err("zstd data is empty".to_string());
    }
    let mut at = 0;
    let mut total = 0u64;
    while at < data.len() {
        let magic = le(bytes(at, 4, "a frame's magic number")?);
        if magic & 0xffff_fff0 == 0x184d_2a50 {
            let size = le(bytes(at + 4, 4, "a skippable frame")?) as usize;
            bytes(at + 8, size, "a skippable frame")?;
            at += 8 + size;
            continue;
        }
        if magic != 0xfd2f_b528 {
            return Err(format!("no zstd frame at byte {at} (magic {magic:#010x})"));
        }
        at += 4;
        let descriptor = bytes(at, 1, "a frame header")?[0];
        at += 1;
        if descriptor & 0x08 != 0 {
            return Err(format!(
                "zstd frame header at byte {} sets its reserved bit",
                at - 1
            ));
        }
        let single_segment = descriptor & 0x20 != 0;
        let mut window = 0;
        if !single_segment {
            let w = bytes(at, 1, "a frame header")?[0];
            at += 1;
            let base = 1u64 << (10 + (w >> 3));
            window = base + base / 8 * u64::from(w & 7);
        }
        at += [0, 1, 2, 4][usize::from(descriptor & 3)];
        let content = match (descriptor >> 6, single_segment) {
            (0, false) => None,
            (0, true) => Some(le(bytes(at, 1, "a frame header")?)),
            (1, _) => Some(le(bytes(at, 2, "a frame header")?) + 256),
            (2, _) => Some(le(bytes(at, 4, "a frame header")?)),
            _ => Some(le(bytes(at, 8, "a frame header")?)),
        };
        at += match descriptor >> 6 {
            0 => usize::from(single_segment),
            1 => 2,
            2 => 4,
            _ => 8,
        };
        if single_segment {
            window = content.unwrap_or(0);
        }
        let block_max = window.min(128 << 10);
        let mut blocks = 0u64;
        loop {
            let header = le(bytes(at, 3, "a block header")?);
            at += 3;
            let size = (header >> 3) as usize;
            let stored = match (header >> 1) & 3 {
                0 | 2 => size,
                1 => 1,
                _ => {
                    return Err(format!(
                        "zstd block at byte {} has the reserved type",
                        at - 3
                    ));
                }
            };
            bytes(at, stored, "a block")?;
            at += stored;
            blocks += 1;
            if header & 1 != 0 {
                break;
            }
        }
        if descriptor & 0x04 != 0 {
            bytes(at, 4, "a frame's checksum")?;
            at += 4;
        }
        total = total.saturating_add(content.unwrap_or(blocks.saturating_mul(block_max)));
    }
    Ok(total)
}

/// The sharding codec, checking a shard's index before `zarrs` uses it:
/// against the shard's length when it decodes a whole shard, and when it
/// decodes part of one (reading only the subchunks a box needs, through
/// the store, which refuses reads past the file's end), against overflow
/// and the subchunks' fixed size.
#[derive(Debug)]
struct CheckedSharding {
    inner: Arc<dyn ArrayToBytesCodecTraits>,
    /// The codecs of the subchunks and of the index, as configured.
    subchunk_codecs: Arc<CodecChain>,
    index_codecs: Arc<CodecChain>,
    index_at_end: bool,
}

impl CheckedSharding {
    fn create(metadata: &MetadataV3) -> Result<Codec, PluginCreateError> {
        let Codec::ArrayToBytes(inner) = <ShardingCodec as CodecTraitsV3>::create(metadata)? else {
            return Err(PluginCreateError::from(
                "sharding_indexed is no array-to-bytes codec",
            ));
        };
        let ShardingCodecConfiguration::V1(config) = metadata.to_typed_configuration()? else {
            return Err(PluginCreateError::from(
                "unknown sharding_indexed configuration",
            ));
        };
        Ok(Codec::ArrayToBytes(Arc::new(CheckedSharding {
            inner,
            subchunk_codecs: Arc::new(CodecChain::from_metadata(&config.codecs)?),
            index_codecs: Arc::new(CodecChain::from_metadata(&config.index_codecs)?),
            index_at_end: config.index_location == ShardingIndexLocation::End,
        })))
    }

    /// Subchunks per shard of `shape`, or `None` where they do not divide
    /// it (which zarrs refuses, saying so).
    fn per_shard(&self, shape: &[NonZeroU64]) -> Option<ChunkShape> {
        let subchunk = self.inner.partial_decode_granularity(shape);
        if subchunk.len() != shape.len() {
            return None;
        }
        shape
            .iter()
            .zip(&subchunk)
            .map(|(s, c)| (s.get() % c.get() == 0).then(|| NonZeroU64::new(s.get() / c.get()))?)
            .collect()
    }

    /// The shard's index, decoded from `encoded` (the shard, or its
    /// index alone).
    fn index(
        &self,
        encoded: &[u8],
        per_shard: &[NonZeroU64],
        options: &CodecOptions,
    ) -> Result<Vec<u64>, CodecError> {
        match self.inner.as_any().downcast_ref::<ShardingCodec>() {
            Some(sharding) => sharding.decode_index(encoded, per_shard, options),
            None => Err(CodecError::Other("not the sharding codec".to_string())),
        }
    }

    /// Refuses an index entry that does not fit `len` bytes (or, where
    /// the length is not known, overflows), or that differs from the
    /// `fixed` size every subchunk encodes to.
    fn check_entries(
        index: &[u64],
        len: Option<u64>,
        fixed: Option<u64>,
    ) -> Result<(), CodecError> {
        for (i, pair) in index.chunks_exact(2).enumerate() {
            let (offset, nbytes) = (pair[0], pair[1]);
            if (offset, nbytes) == (u64::MAX, u64::MAX) {
                continue; // a missing subchunk: the fill value
            }
            let end = offset.checked_add(nbytes);
            if end.is_none_or(|end| len.is_some_and(|len| end > len)) {
                let within = len.map_or(String::new(), |len| {
                    format!(", past the shard's {len} bytes")
                });
                return Err(CodecError::Other(format!(
                    "the shard index places subchunk {i} at bytes {offset} to {offset} + {nbytes}{within}"
                )));
            }
            if let Some(fixed) = fixed.filter(|&f| f != nbytes) {
                return Err(CodecError::Other(format!(
                    "the shard index gives subchunk {i} {nbytes} bytes, but each is {fixed}"
                )));
            }
        }
        Ok(())
    }

    /// Refuses a whole shard whose index points a subchunk outside it.
    fn check_shard(
        &self,
        shard: &[u8],
        shape: &[NonZeroU64],
        options: &CodecOptions,
    ) -> Result<(), CodecError> {
        let Some(per_shard) = self.per_shard(shape) else {
            return Ok(());
        };
        let index = self.index(shard, &per_shard, options)?;
        Self::check_entries(&index, Some(shard.len() as u64), None)
    }
}

impl ExtensionName for CheckedSharding {
    fn name(&self, version: ZarrVersion) -> Option<Cow<'static, str>> {
        self.inner.name(version)
    }
}

impl CodecTraits for CheckedSharding {
    fn as_any(&self) -> &dyn Any {
        // The sharding codec itself, so that `zarrs` knows the array is
        // sharded (`ArrayShardedExt`).
        self.inner.as_any()
    }

    fn configuration(
        &self,
        version: ZarrVersion,
        options: &CodecMetadataOptions,
    ) -> Option<Configuration> {
        self.inner.configuration(version, options)
    }

    fn partial_decoder_capability(&self) -> PartialDecoderCapability {
        self.inner.partial_decoder_capability()
    }

    fn partial_encoder_capability(&self) -> PartialEncoderCapability {
        self.inner.partial_encoder_capability()
    }
}

impl ArrayCodecTraits for CheckedSharding {
    fn recommended_concurrency(
        &self,
        shape: &[NonZeroU64],
        data_type: &DataType,
    ) -> Result<RecommendedConcurrency, CodecError> {
        self.inner.recommended_concurrency(shape, data_type)
    }

    fn partial_decode_granularity(&self, shape: &[NonZeroU64]) -> ChunkShape {
        self.inner.partial_decode_granularity(shape)
    }
}

impl ArrayToBytesCodecTraits for CheckedSharding {
    fn into_dyn(self: Arc<Self>) -> Arc<dyn ArrayToBytesCodecTraits> {
        self
    }

    fn encoded_representation(
        &self,
        shape: &[NonZeroU64],
        data_type: &DataType,
        fill_value: &FillValue,
    ) -> Result<BytesRepresentation, CodecError> {
        self.inner
            .encoded_representation(shape, data_type, fill_value)
    }

    fn encode<'a>(
        &self,
        bytes: ArrayBytes<'a>,
        shape: &[NonZeroU64],
        data_type: &DataType,
        fill_value: &FillValue,
        options: &CodecOptions,
    ) -> Result<ArrayBytesRaw<'a>, CodecError> {
        self.inner
            .encode(bytes, shape, data_type, fill_value, options)
    }

    fn decode<'a>(
        &self,
        bytes: ArrayBytesRaw<'a>,
        shape: &[NonZeroU64],
        data_type: &DataType,
        fill_value: &FillValue,
        options: &CodecOptions,
    ) -> Result<ArrayBytes<'a>, CodecError> {
        self.check_shard(&bytes, shape, options)?;
        self.inner
            .decode(bytes, shape, data_type, fill_value, options)
    }

    fn decode_into(
        &self,
        bytes: ArrayBytesRaw<'_>,
        shape: &[NonZeroU64],
        data_type: &DataType,
        fill_value: &FillValue,
        output_target: ArrayBytesDecodeIntoTarget<'_>,
        options: &CodecOptions,
    ) -> Result<(), CodecError> {
        self.check_shard(&bytes, shape, options)?;
        self.inner
            .decode_into(bytes, shape, data_type, fill_value, output_target, options)
    }

    fn partial_decoder(
        self: Arc<Self>,
        input_handle: Arc<dyn BytesPartialDecoderTraits>,
        shape: &[NonZeroU64],
        data_type: &DataType,
        fill_value: &FillValue,
        options: &CodecOptions,
    ) -> Result<Arc<dyn ArrayPartialDecoderTraits>, CodecError> {
        // Without an index (no shard: the fill value), or with subchunks
        // that do not divide the shard (refused by zarrs), there is
        // nothing to check.
        self.check_partial(&*input_handle, shape, data_type, fill_value, options)?;
        self.inner
            .clone()
            .partial_decoder(input_handle, shape, data_type, fill_value, options)
    }
}

impl CheckedSharding {
    /// Checks the index of the shard `input` reads before zarrs' partial
    /// decoder takes subchunks' byte ranges from it. A shard in a file is
    /// read index first, as zarrs reads it (the store has refused an index
    /// outside the file, and refuses subchunks outside it); a shard within
    /// a shard is read whole, so that its index is checked against its
    /// length (zarrs reads an index from the end of a byte interval by
    /// subtracting, unchecked).
    fn check_partial(
        &self,
        input: &dyn BytesPartialDecoderTraits,
        shape: &[NonZeroU64],
        data_type: &DataType,
        fill_value: &FillValue,
        options: &CodecOptions,
    ) -> Result<(), CodecError> {
        let Some(per_shard) = self.per_shard(shape) else {
            return Ok(());
        };
        let in_file = (input as &dyn Any).is::<StoragePartialDecoder>();
        let (encoded, len) = if in_file {
            let count = per_shard.iter().map(|n| n.get()).product::<u64>();
            let index_shape = [
                NonZeroU64::new(count).expect("a product of non-zero sizes"),
                NonZeroU64::MIN.saturating_add(1),
            ];
            let size = self
                .index_codecs
                .encoded_representation(&index_shape, &uint64(), &FillValue::from(u64::MAX))?
                .size()
                .ok_or_else(|| CodecError::Other("a shard index of unbounded size".to_string()))?;
            let range = if self.index_at_end {
                ByteRange::Suffix(size)
            } else {
                ByteRange::FromStart(0, Some(size))
            };
            (input.partial_decode(range, options)?, None)
        } else {
            let whole = input.partial_decode(ByteRange::FromStart(0, None), options)?;
            let len = whole.as_ref().map(|w| w.len() as u64);
            (whole, len)
        };
        let Some(encoded) = encoded else {
            return Ok(());
        };
        let index = self.index(&encoded, &per_shard, options)?;
        let subchunk = self.inner.partial_decode_granularity(shape);
        let fixed = match self
            .subchunk_codecs
            .encoded_representation(&subchunk, data_type, fill_value)?
        {
            BytesRepresentation::FixedSize(n) => Some(n),
            _ => None,
        };
        Self::check_entries(&index, len, fixed)
    }
}

/// A directory store whose reads are checked before any buffer is made
/// for them: inside the file, no larger than `max_read` bytes (metadata
/// files: [`MAX_METADATA_BYTES`]).
#[derive(Debug)]
pub(crate) struct CheckedStore {
    inner: FilesystemStore,
    max_read: u64,
}

impl CheckedStore {
    pub(crate) fn new(inner: FilesystemStore, max_read: u64) -> Self {
        CheckedStore { inner, max_read }
    }
}

impl ReadableStorageTraits for CheckedStore {
    fn get_partial_many<'a>(
        &'a self,
        key: &StoreKey,
        byte_ranges: ByteRangeIterator<'a>,
    ) -> Result<MaybeBytesIterator<'a>, StorageError> {
        let Some(size) = self.inner.size_key(key)? else {
            return Ok(None);
        };
        // A directory where a chunk's file should be: the system cannot
        // read it (an I/O failure, as a file read whole that is not a
        // file), not bytes to decode.
        if !self.inner.key_to_fspath(key).is_file() {
            return Err(StorageError::IOError(Arc::new(std::io::Error::other(
                format!("{key}: not a regular file"),
            ))));
        }
        let name = key.as_str().rsplit('/').next().unwrap_or_default();
        let limit = if MARKERS.contains(&name) {
            MAX_METADATA_BYTES.min(self.max_read)
        } else {
            self.max_read
        };
        let ranges: Vec<ByteRange> = byte_ranges.collect();
        for range in &ranges {
            let (start, length) = match *range {
                ByteRange::FromStart(start, Some(length)) => (start, length),
                ByteRange::FromStart(start, None) => (start, size.saturating_sub(start)),
                ByteRange::Suffix(length) => (size.saturating_sub(length), length),
            };
            if start.checked_add(length).is_none_or(|end| end > size) {
                return Err(StorageError::Other(format!(
                    "{key}: bytes {start} to {start} + {length} are past its end ({size} bytes)"
                )));
            }
            if length > limit {
                return Err(StorageError::Other(format!(
                    "{key}: {length} bytes to read at once, more than {limit}"
                )));
            }
        }
        self.inner
            .get_partial_many(key, Box::new(ranges.into_iter()))
    }

    fn size_key(&self, key: &StoreKey) -> Result<Option<u64>, StorageError> {
        self.inner.size_key(key)
    }

    fn supports_get_partial(&self) -> bool {
        self.inner.supports_get_partial()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zstd_bounds_are_zstds() {
        // One RLE block of 48 bytes, content size declared (8 bytes).
        let mut f = vec![0x28, 0xb5, 0x2f, 0xfd, 0xe0];
        f.extend(48u64.to_le_bytes());
        f.extend([0x83, 0x01, 0x00, 0x07]);
        assert_eq!(zstd_bound(&f), Ok(48));
        // Twice, with a skippable frame between.
        let mut two = f.clone();
        two.extend([0x5a, 0x2a, 0x4d, 0x18, 2, 0, 0, 0, 9, 9]);
        two.extend(&f);
        assert_eq!(zstd_bound(&two), Ok(96));
        // No content size, window 2^17: 128 KiB a block.
        let g = [
            0x28, 0xb5, 0x2f, 0xfd, 0x00, 0x38, 0x82, 0x01, 0x00, 0x07, 0x83, 0x01, 0x00, 0x07,
        ];
        assert_eq!(zstd_bound(&g), Ok(2 << 17));
        for cut in 0..f.len() {
            assert!(zstd_bound(&f[..cut]).is_err(), "{cut}");
        }
        let mut reserved = f.clone();
        reserved[13] = 0x87; // block type 3
        assert!(zstd_bound(&reserved).unwrap_err().contains("reserved type"));
        assert!(
            zstd_bound(b"garbage!")
                .unwrap_err()
                .contains("no zstd frame")
        );
    }
}
