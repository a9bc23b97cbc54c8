//! Reading the samples of a frame from its regions, or mapping them from
//! their one file where the layout allows ([`plan_frame`]).

use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use bzip2::read::MultiBzDecoder;
use flate2::read::{MultiGzDecoder, ZlibDecoder};
use volray_core::Samples;

use super::decode::{read_hex, read_inflated, read_text};
use super::frame::FrameSelect;
use super::layout::{Encoding, Layout};
use super::region::Region;
use crate::dtype::{Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::input::{open_input, read_samples};
use crate::shared::mapped::{self, MapPolicy, Plan};

/// Output samples allocated up front for a compressed stream; beyond this
/// the output grows with the data actually inflated.
const COMPRESSED_PREALLOC: usize = 1 << 20;

/// Reads `per_region` samples from each region in turn (all checked with
/// [`check_region`](super::check_region) first), keeping those `frame`
/// selects, in the type [`Layout::stored`] names.
pub(crate) fn read_regions(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
) -> Result<Samples, IoError> {
    read_as_stored!(layout.stored(), |T| read_regions_as::<T>(
        regions, per_region, layout, frame
    ))
}

/// Where the samples `frame` selects lie in the one file they can be
/// mapped from: a single region, raw encoding, the kept volume contiguous
/// (the frame axis of a 4-D file is its slowest), the samples stored as a
/// volume keeps them ([`mapped::mappable`]); otherwise why not.
fn mappable(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
) -> Result<(PathBuf, u64), String> {
    let [region] = regions else {
        return Err(format!(
            "the data is split over {} files: store it in one",
            regions.len()
        ));
    };
    let encoding = match layout.encoding {
        Encoding::Raw => None,
        Encoding::Gzip => Some("gzip-compressed"),
        Encoding::Zlib => Some("zlib-compressed"),
        Encoding::Bzip2 => Some("bzip2-compressed"),
        Encoding::Text => Some("text"),
        Encoding::Hex => Some("hex"),
    };
    if let Some(e) = encoding {
        return Err(format!("{e} data: store it uncompressed (raw encoding)"));
    }
    let size = layout.dtype.size() as u64;
    let offset = if frame.count <= 1 {
        region.start
    } else if frame.stride.checked_mul(frame.count) == Some(per_region) {
        region.start + (frame.index * frame.stride) as u64 * size
    } else {
        return Err(
            "the volumes of the 4-D file are interleaved (its frame axis is not the slowest)"
                .into(),
        );
    };
    mapped::mappable(layout.dtype, layout.endian, offset)?;
    Ok((region.path.clone(), offset))
}

/// The samples `frame` selects from `regions` (each checked with
/// [`check_region`](super::check_region) first), mapped from their file
/// where `policy`, the layout and `within_limit` (the reader's check of
/// the frame against the memory limit) allow, read into memory otherwise;
/// with the plan followed.
pub(crate) fn plan_frame(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
    policy: MapPolicy,
    within_limit: Result<usize, IoError>,
) -> Result<(Samples, Plan), IoError> {
    let mappable = mappable(regions, per_region, layout, frame);
    let plan = mapped::plan(
        policy,
        mappable.as_ref().map(|_| ()).map_err(Clone::clone),
        within_limit,
    )?;
    let data = match (plan, mappable) {
        // Mapped: one region, of which the frame is a `1 / frame.count`th.
        (Plan::Map, Ok((file, offset))) => {
            mapped::map_samples(&file, offset, layout.dtype, per_region / frame.count.max(1))?
        }
        _ => read_regions(regions, per_region, layout, frame)?,
    };
    Ok((data, plan))
}

/// [`read_regions`] as `T`.
fn read_regions_as<T: Stored>(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
) -> Result<Vec<T>, IoError> {
    let total = per_region.checked_mul(regions.len()).ok_or_else(|| {
        IoError::invalid(
            regions.first().map_or(Path::new(""), |r| r.path.as_path()),
            "the header describes more samples than this machine can address",
        )
    })?;
    let kept = total / frame.count.max(1);
    let capacity = if layout.encoding.is_compressed() {
        kept.min(COMPRESSED_PREALLOC)
    } else {
        kept
    };
    let mut out = Vec::with_capacity(capacity);
    let mut seen = 0usize;
    for region in regions {
        let mut sink = |values: &[T]| {
            frame.keep_into(seen, values, &mut out);
            seen += values.len();
        };
        read_region(region, per_region, layout, &mut sink)?;
    }
    Ok(out)
}

/// Decodes the `samples` samples of one region, passing them to `sink` in
/// chunks.
fn read_region<T: Stored>(
    region: &Region,
    samples: usize,
    layout: &Layout,
    sink: &mut dyn FnMut(&[T]),
) -> Result<(), IoError> {
    let path = region.path.as_path();
    let (mut file, _) = open_input(path)?;
    file.seek(SeekFrom::Start(region.start))
        .map_err(|e| IoError::os(path, "seek in", e))?;
    let bounded = file.take(region.len);
    let (dtype, endian) = (layout.dtype, layout.endian);
    match layout.encoding {
        Encoding::Raw => read_samples(
            path,
            &mut BufReader::new(bounded),
            samples,
            dtype.size(),
            region.start,
            |bytes, out| T::extend(out, bytes, dtype, endian),
            |values| sink(values),
        ),
        Encoding::Gzip | Encoding::Zlib => {
            let mut buffered = BufReader::new(bounded);
            let head = buffered
                .fill_buf()
                .map_err(|e| IoError::os(path, "read", e))?;
            let gzip = layout.encoding == Encoding::Gzip || head.starts_with(&[0x1f, 0x8b]);
            let (name, mut decoder): (&str, Box<dyn Read>) = if gzip {
                ("gzip", Box::new(MultiGzDecoder::new(buffered)))
            } else {
                ("zlib", Box::new(ZlibDecoder::new(buffered)))
            };
            read_inflated(path, name, &mut decoder, samples, layout, sink)
        }
        Encoding::Bzip2 => {
            let mut decoder = MultiBzDecoder::new(BufReader::new(bounded));
            read_inflated(path, "bzip2", &mut decoder, samples, layout, sink)
        }
        Encoding::Text => read_text(path, BufReader::new(bounded), samples, sink),
        Encoding::Hex => read_hex(path, &mut BufReader::new(bounded), samples, layout, sink),
    }
}
