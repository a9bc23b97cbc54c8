//! What a volume file holds and how volray reads it, as `volray info`
//! says it: lines of text, or one JSON document ([`lines`]). The front end
//! prints them.

use crate::AppError;
use crate::input::{self, Described, Request};
use serde_json::{Value, json};
use volray_core::Histogram;
use volray_core::transfer::labels;
use volray_io::{FileInfo, FlatImage};

/// The most a chunked level may take in memory for `info` to read it for
/// its statistics (or a quarter of `--max-memory`, if less); a larger
/// one's statistics come from the finest level under it (block means:
/// within the level's range), and only its metadata is read, so that
/// `info` on a pyramid of any size answers at once.
const VALUES_READ_LIMIT: u64 = 64 << 20;

/// Adds a line to `out`, formatted as `format!` does.
macro_rules! outln {
    ($out:expr, $($arg:tt)*) => {
        $out.push(format!($($arg)*))
    };
}

/// The description of the input `request` names, with a histogram of
/// `bins` bins: lines of text, or one JSON document (`as_json`), each
/// without its newline.
pub fn lines(request: &Request, bins: u16, as_json: bool) -> Result<Vec<String>, AppError> {
    let mut out = Vec::new();
    // A chunked level larger than VALUES_READ_LIMIT: its metadata, and the
    // statistics of a smaller level.
    let chunked = large_chunked_level(request)?;
    let described = match &chunked {
        Some((_, k)) => input::describe(&request.at_level(Some(*k)))?,
        None => input::describe(request)?,
    };
    let input = match described {
        Described::Volume(input) => input,
        Described::Image { name, image } => {
            describe_image(&mut out, &name, &image, as_json);
            return Ok(out);
        }
    };
    let v = &input.volume;
    let hist = Histogram::of(v, usize::from(bins));
    // An integer volume with few distinct values, each on many voxels, is
    // likely a segmentation.
    let labels = (labels::labels_of(v, SUGGEST_LABELS).ok().flatten())
        .filter(|found| found.len() * 16 <= v.len());
    let (format, info) = match (&chunked, &input.file) {
        (Some((lazy, _)), _) => (lazy.format.description().to_string(), Some(&lazy.info)),
        (None, Some((format, info))) => (format.description().to_string(), Some(info)),
        (None, None) => ("built-in source".to_string(), None),
    };
    let mut info = info.map(with_bytes_stored);
    // What is shown of the volume: the level asked for, whichever level
    // the statistics came from.
    let grid = match &chunked {
        Some((lazy, _)) => lazy.source.grid(),
        None => volray_core::VolumeSource::grid(v),
    };
    // How `render` stretches axes in different units for drawing (the
    // spacing shown is as stored).
    if let Some(i) = info.as_mut() {
        let n = grid.dims.map(|n| n.saturating_sub(1) as f64);
        let extent = grid.spacing * volray_core::glam::DVec3::from(n);
        let stretch = crate::display::stretch(Some(i), extent, request.scale);
        if let Some(note) = stretch.and_then(|s| s.note) {
            i.notes.push(note);
        }
    }
    let info = info.as_ref();
    let values_from = chunked.as_ref().map(|(lazy, k)| {
        let l = &lazy.info.levels[*k];
        (*k, l.dims)
    });
    let kept = match &chunked {
        Some((lazy, _)) => lazy.source.sample_type(),
        None => v.sample_type(),
    };
    let mapped = chunked.is_none() && v.samples().is_external();
    let points: usize = grid.dims.iter().product();
    let unit = info.and_then(|i| i.length_unit.clone());
    let [nx, ny, nz] = grid.dims;
    let (s, o) = (grid.spacing, grid.origin);

    if as_json {
        let histogram = hist.as_ref().map(|h| {
            json!({
                "min": h.min, "max": h.max, "mean": h.mean,
                "non_finite": h.non_finite,
                "edges": (0..=h.counts.len()).map(|b| h.edge(b)).collect::<Vec<_>>(),
                "counts": h.counts,
            })
        });
        let mut doc = json!({
            "input": input.name,
            "format": format,
            "dims": [nx, ny, nz],
            "sample_type": kept.name(),
            "mapped": mapped,
            "spacing": [s.x, s.y, s.z],
            "origin": [o.x, o.y, o.z],
            "length_unit": unit,
            "values": histogram,
            "values_level": values_from.map(|(k, _)| k),
            "labels": labels,
        });
        if let Some(i) = info {
            add_file_json(&mut doc, i);
        }
        outln!(
            out,
            "{}",
            serde_json::to_string_pretty(&doc).expect("JSON of plain values")
        );
        return Ok(out);
    }

    let unit_suffix = unit.as_deref().map(|u| format!(" {u}")).unwrap_or_default();
    outln!(out, "input:     {}", input.name);
    outln!(out, "format:    {format}");
    if let Some(i) = info {
        print_stored(&mut out, i, &input.name);
    }
    outln!(out, "dims:      {nx} x {ny} x {nz} ({points} points)");
    outln!(
        out,
        "in memory: {}{} ({} a voxel, {})",
        if mapped { "mapped from the file, " } else { "" },
        kept.name(),
        match kept.bytes() {
            1 => "1 byte".to_string(),
            n => format!("{n} bytes"),
        },
        volray_io::format_bytes((kept.bytes() * points) as u128)
    );
    outln!(out, "spacing:   {}, {}, {}{unit_suffix}", s.x, s.y, s.z);
    outln!(out, "origin:    {}, {}, {}{unit_suffix}", o.x, o.y, o.z);
    let e = grid.extent();
    outln!(out, "extent:    {}, {}, {}{unit_suffix}", e.x, e.y, e.z);
    if let Some((k, [x, y, z])) = values_from {
        outln!(
            out,
            "           values below from level {k} ({x} x {y} x {z}), block means of this one: its range lies within this level's (only the metadata of a level this large is read)"
        );
    }
    match &hist {
        None => outln!(out, "values:    no finite values"),
        Some(h) => {
            outln!(
                out,
                "values:    min {}, max {}, mean {:.6e}",
                h.min,
                h.max,
                h.mean
            );
            if h.non_finite > 0 && info.is_some_and(|i| i.nan_is_empty) {
                outln!(
                    out,
                    "           {} NaN: no value (outside the file's grid, or fill or blank values; see the notes), rendered as empty",
                    h.non_finite
                );
            } else if h.non_finite > 0 {
                outln!(
                    out,
                    "           {} non-finite (NaN or infinite)",
                    h.non_finite
                );
            }
            outln!(out, "histogram: ({} bins)", h.counts.len());
            let peak = h.counts.iter().copied().max().unwrap_or(1).max(1);
            for (b, &c) in h.counts.iter().enumerate() {
                let bar = (c * 40).div_ceil(peak) as usize;
                outln!(
                    out,
                    "  [{:>12.5e}, {:>12.5e}{} {:<40} {c}",
                    h.edge(b),
                    h.edge(b + 1),
                    if b + 1 == h.counts.len() { "]" } else { ")" },
                    "#".repeat(bar)
                );
            }
        }
    }
    if let Some(found) = &labels {
        let shown: Vec<String> = found.iter().take(16).map(i64::to_string).collect();
        outln!(
            out,
            "labels:    {} distinct integer values ({}{}): a segmentation? render it with --labels",
            found.len(),
            shown.join(", "),
            if found.len() > 16 { ", ..." } else { "" }
        );
    }
    if let Some(i) = info {
        print_header_and_notes(&mut out, i);
    }
    Ok(out)
}

/// A chunked level (Zarr, OME-Zarr) over [`VALUES_READ_LIMIT`] in memory,
/// opened from its metadata, and the level whose statistics `info` reads
/// instead: the finest under the limit, else the coarsest.
fn large_chunked_level(request: &Request) -> Result<Option<(volray_io::Lazy, usize)>, AppError> {
    let spec = request.spec.name();
    if volray_data::is_source_spec(&spec) {
        return Ok(None);
    }
    let max_memory = request.max_memory();
    let path = std::path::PathBuf::from(spec);
    let opts = input::read_options(request, max_memory, volray_io::MapPolicy::IfLarger)?;
    let Some(lazy) = volray_io::open_lazy(&path, &opts)? else {
        return Ok(None);
    };
    let levels = &lazy.info.levels;
    let chosen = lazy.info.level;
    let limit = VALUES_READ_LIMIT.min(max_memory / 4);
    let small = |k: &usize| levels[*k].bytes_in_memory <= limit;
    if levels.is_empty() || small(&chosen) {
        return Ok(None);
    }
    let k = (chosen..levels.len())
        .find(small)
        .unwrap_or(levels.len() - 1);
    // No coarser level: the statistics are the level's own, read whole.
    Ok((k != chosen).then_some((lazy, k)))
}

/// `info` suggests `--labels` for integer volumes with at most this many
/// distinct values.
const SUGGEST_LABELS: usize = 256;

/// What a file holding one image, not a volume, holds, and why `render`
/// needs more.
fn describe_image(out: &mut Vec<String>, name: &str, image: &FlatImage, as_json: bool) {
    let i = &image.info;
    let [nx, ny, nz] = image.dims;
    let (s, o) = (image.spacing, image.origin);
    let (range, non_finite) = image.value_range();
    if as_json {
        let mut doc = json!({
            "input": name,
            "format": image.format.description(),
            "volume": false,
            "render": image.reason,
            "dims": [nx, ny, nz],
            "spacing": [s.x, s.y, s.z],
            "origin": [o.x, o.y, o.z],
            "length_unit": i.length_unit,
            "values": range.map(|(min, max, mean)| json!({
                "min": min, "max": max, "mean": mean, "non_finite": non_finite,
            })),
        });
        add_file_json(&mut doc, i);
        outln!(
            out,
            "{}",
            serde_json::to_string_pretty(&doc).expect("JSON of plain values")
        );
        return;
    }
    let unit = i
        .length_unit
        .as_deref()
        .map(|u| format!(" {u}"))
        .unwrap_or_default();
    outln!(out, "input:     {name}");
    outln!(out, "format:    {}", image.format.description());
    print_stored(out, i, name);
    outln!(
        out,
        "dims:      {nx} x {ny} x {nz} ({} points: an image, not a volume)",
        image.values.len()
    );
    outln!(out, "spacing:   {}, {}, {}{unit}", s.x, s.y, s.z);
    outln!(out, "origin:    {}, {}, {}{unit}", o.x, o.y, o.z);
    match range {
        None => outln!(out, "values:    no finite values"),
        Some((min, max, mean)) => outln!(out, "values:    min {min}, max {max}, mean {mean:.6e}"),
    }
    if non_finite > 0 {
        outln!(out, "           {non_finite} non-finite (NaN or infinite)");
    }
    outln!(out, "render:    refused: {}", image.reason);
    print_header_and_notes(out, i);
}

/// The stored type, and the frames and arrays a file holds.
/// The most chunk files `volray info` counts a level's stored bytes over.
const COUNTED_FILES: usize = volray_io::LevelInfo::COUNTED_FILES;

/// `info` with each level's stored bytes counted, where it has no more
/// than [`COUNTED_FILES`] files.
fn with_bytes_stored(info: &FileInfo) -> FileInfo {
    let mut info = info.clone();
    for l in &mut info.levels {
        l.bytes_stored = l
            .bytes_stored
            .or_else(|| l.count_bytes_stored(COUNTED_FILES));
    }
    info
}

/// A level's stored bytes as `volray info` says them.
fn stored(l: &volray_io::LevelInfo) -> String {
    l.bytes_stored.map_or_else(
        || match l.dir.is_dir() {
            true => format!("over {COUNTED_FILES} chunk files (not counted)"),
            false => "an uncounted share of the file".into(),
        },
        |b| volray_io::format_bytes(u128::from(b)),
    )
}

fn print_stored(out: &mut Vec<String>, i: &FileInfo, name: &str) {
    outln!(out, "stored as: {}", i.stored_type);
    if let Some(m) = &i.modality {
        outln!(out, "modality:  {m}");
    }
    let (t, c) = (i.time_points, i.channels);
    if i.frames_are_series {
        // A DICOM directory's series: each its own grid, so neither an
        // animation nor channels of one picture.
        outln!(
            out,
            "series:    {t} (read: {}, counted from 1; --series N or a SeriesInstanceUID picks another: the notes list them)",
            i.time_point + 1
        );
    } else if t > 1 {
        outln!(
            out,
            "time points: {t} (read: {}; --frame picks another; as an animation: volray render {name} --frames all -o OUT.gif)",
            i.time_point
        );
    }
    if c > 1 {
        outln!(
            out,
            "channels:  {c} (read: {}; --channel picks another; together: volray render {name} --channels all)",
            i.channel
        );
    } else if t > 1 && !i.frames_are_series {
        outln!(
            out,
            "channels:  1 (its {t} time points rendered together as channels: volray render {name} --channels all)"
        );
    }
    if !i.levels.is_empty() {
        outln!(
            out,
            "levels:    {} (read: {}; --level picks another)",
            i.levels.len(),
            i.level
        );
        let shape = |s: &Option<Vec<u64>>| {
            s.as_ref().map_or("-".to_string(), |s| {
                s.iter().map(u64::to_string).collect::<Vec<_>>().join("x")
            })
        };
        for (n, l) in i.levels.iter().enumerate() {
            let [x, y, z] = l.dims;
            let [sx, sy, sz] = l.spacing;
            outln!(
                out,
                "  {n}: {x} x {y} x {z}, spacing {sx}, {sy}, {sz}; chunks {}, shards {}; codecs {}; {} stored, {} in memory",
                shape(&l.chunk_shape),
                shape(&l.shard_shape),
                l.codecs,
                stored(l),
                volray_io::format_bytes(u128::from(l.bytes_in_memory))
            );
        }
    }
    if let Some(o) = &i.omero {
        let mut parts = Vec::new();
        if let Some((start, end, min, max)) = o.window {
            let range = match (min, max) {
                (Some(lo), Some(hi)) => format!(" of {lo}..{hi}"),
                _ => String::new(),
            };
            parts.push(format!("window {start}..{end}{range}"));
        }
        if let Some(c) = &o.color {
            parts.push(format!("colour #{c}"));
        }
        if let Some(l) = &o.label {
            parts.push(format!("label \"{l}\""));
        }
        if let Some(a) = o.active {
            parts.push(if a { "shown" } else { "hidden" }.to_string());
        }
        outln!(
            out,
            "omero:     channel {}: {}",
            o.channel,
            parts.join(", ")
        );
    }
    if !i.segments.is_empty() {
        let segments: Vec<String> = (i.segments.iter())
            .map(|s| {
                let colour = (s.colour)
                    .map(|[r, g, b]| format!(" #{r:02X}{g:02X}{b:02X}"))
                    .unwrap_or_default();
                format!("{} \"{}\"{colour}", s.label, s.name)
            })
            .collect();
        outln!(
            out,
            "segments:  {} (label value, name, colour; --labels renders them)",
            segments.join(", ")
        );
    }
    if !i.arrays.is_empty() {
        outln!(
            out,
            "arrays:    {} (read: {}; --array picks another)",
            i.arrays.join(", "),
            i.array.as_deref().unwrap_or("-")
        );
    }
}

/// The header as written and the notes of how the file was read.
fn print_header_and_notes(out: &mut Vec<String>, i: &FileInfo) {
    if !i.header.is_empty() {
        outln!(out, "header (as written):");
        for (k, val) in &i.header {
            outln!(out, "  {k}: {val}");
        }
    }
    if !i.notes.is_empty() {
        outln!(out, "how it was read:");
        for n in &i.notes {
            outln!(out, "  - {n}");
        }
    }
}

/// The file's own fields in `volray info --json`.
fn add_file_json(out: &mut Value, i: &FileInfo) {
    out["stored_type"] = json!(i.stored_type);
    // The volumes: `frames` = time points × channels, `frame` the one
    // read (t·C + c); `channels` counts the channels alone.
    out["frames"] = json!(i.frames);
    out["frame"] = json!(i.frame);
    out["time_points"] = json!(i.time_points);
    out["time_point"] = json!(i.time_point);
    out["channels"] = json!(i.channels);
    out["channel"] = json!(i.channel);
    out["arrays"] = json!(i.arrays);
    out["array"] = json!(i.array);
    // A segmentation's segments: label value, name, sRGB colour `RRGGBB`.
    out["segments"] = json!(
        (i.segments.iter())
            .map(|s| json!({
                "label": s.label,
                "name": s.name,
                "color": s.colour.map(|[r, g, b]| format!("{r:02X}{g:02X}{b:02X}")),
            }))
            .collect::<Vec<_>>()
    );
    out["header"] = json!(
        i.header
            .iter()
            .map(|(k, v)| json!({"key": k, "value": v}))
            .collect::<Vec<_>>()
    );
    out["notes"] = json!(i.notes);
    // The imaging modality the file names (DICOM's `CT`, `MR`), if any.
    out["modality"] = json!(i.modality);
    out["nan_is_empty"] = json!(i.nan_is_empty);
    // OME-Zarr's rendering hints for the channel read.
    out["omero"] = json!(i.omero.as_ref().map(|o| json!({
        "channel": o.channel,
        "label": o.label,
        "color": o.color,
        "active": o.active,
        "window": o.window.map(|(start, end, min, max)| json!({
            "start": start, "end": end, "min": min, "max": max,
        })),
    })));
    // Multiscale images (OME-Zarr): every level; the keys above describe
    // the one read.
    out["level"] = json!(i.level);
    out["levels"] = json!(
        i.levels
            .iter()
            .map(|l| json!({
                "path": l.path,
                "shape": l.shape,
                "dims": l.dims,
                "spacing": l.spacing,
                "origin": l.origin,
                "chunk_shape": l.chunk_shape,
                "shard_shape": l.shard_shape,
                "codecs": l.codecs,
                "bytes_stored": l.bytes_stored,
                "bytes_in_memory": l.bytes_in_memory,
            }))
            .collect::<Vec<_>>()
    );
}
