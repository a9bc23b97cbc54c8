//! `volray info`: what a volume file holds and how volray reads it.

use crate::error::CliError;
use crate::flags::InfoArgs;
use crate::input::{self, Described};
use serde_json::{Value, json};
use volray_core::Histogram;
use volray_core::transfer::labels;
use volray_io::{FileInfo, FlatImage};

pub fn run(args: &InfoArgs) -> Result<(), CliError> {
    let input = match input::describe(&args.input)? {
        Described::Volume(input) => input,
        Described::Image { name, image } => {
            describe_image(&name, &image, args.json);
            return Ok(());
        }
    };
    let v = &input.volume;
    let hist = Histogram::of(v, usize::from(args.bins));
    // An integer volume with few distinct values, each on many voxels, is
    // likely a segmentation.
    let labels = (labels::labels_of(v, SUGGEST_LABELS).ok().flatten())
        .filter(|found| found.len() * 16 <= v.len());
    let (format, info) = match &input.file {
        Some((format, info)) => (format.description().to_string(), Some(info)),
        None => ("built-in source".to_string(), None),
    };
    let unit = info.and_then(|i| i.length_unit.clone());
    let [nx, ny, nz] = v.dims();
    let (s, o) = (v.spacing(), v.origin());

    if args.json {
        let histogram = hist.as_ref().map(|h| {
            json!({
                "min": h.min, "max": h.max, "mean": h.mean,
                "non_finite": h.non_finite,
                "edges": (0..=h.counts.len()).map(|b| h.edge(b)).collect::<Vec<_>>(),
                "counts": h.counts,
            })
        });
        let mut out = json!({
            "input": input.name,
            "format": format,
            "dims": [nx, ny, nz],
            "sample_type": v.sample_type().name(),
            "mapped": v.samples().is_external(),
            "spacing": [s.x, s.y, s.z],
            "origin": [o.x, o.y, o.z],
            "length_unit": unit,
            "values": histogram,
            "labels": labels,
        });
        if let Some(i) = info {
            add_file_json(&mut out, i);
        }
        outln!(
            "{}",
            serde_json::to_string_pretty(&out).expect("JSON of plain values")
        );
        return Ok(());
    }

    let unit_suffix = unit.as_deref().map(|u| format!(" {u}")).unwrap_or_default();
    outln!("input:     {}", input.name);
    outln!("format:    {format}");
    if let Some(i) = info {
        print_stored(i);
    }
    outln!("dims:      {nx} x {ny} x {nz} ({} points)", v.len());
    let kept = v.sample_type();
    outln!(
        "in memory: {}{} ({} a voxel, {})",
        if v.samples().is_external() {
            "mapped from the file, "
        } else {
            ""
        },
        kept.name(),
        match kept.bytes() {
            1 => "1 byte".to_string(),
            n => format!("{n} bytes"),
        },
        volray_io::format_bytes((kept.bytes() * v.len()) as u128)
    );
    outln!("spacing:   {}, {}, {}{unit_suffix}", s.x, s.y, s.z);
    outln!("origin:    {}, {}, {}{unit_suffix}", o.x, o.y, o.z);
    let e = v.extent();
    outln!("extent:    {}, {}, {}{unit_suffix}", e.x, e.y, e.z);
    match &hist {
        None => outln!("values:    no finite values"),
        Some(h) => {
            outln!(
                "values:    min {}, max {}, mean {:.6e}",
                h.min,
                h.max,
                h.mean
            );
            if h.non_finite > 0 && info.is_some_and(|i| i.nan_is_empty) {
                outln!(
                    "           {} NaN: space the file does not cover, rendered as empty",
                    h.non_finite
                );
            } else if h.non_finite > 0 {
                outln!("           {} non-finite (NaN or infinite)", h.non_finite);
            }
            outln!("histogram: ({} bins)", h.counts.len());
            let peak = h.counts.iter().copied().max().unwrap_or(1).max(1);
            for (b, &c) in h.counts.iter().enumerate() {
                let bar = (c * 40).div_ceil(peak) as usize;
                outln!(
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
            "labels:    {} distinct integer values ({}{}): a segmentation? render it with --labels",
            found.len(),
            shown.join(", "),
            if found.len() > 16 { ", ..." } else { "" }
        );
    }
    if let Some(i) = info {
        print_header_and_notes(i);
    }
    Ok(())
}

/// `info` suggests `--labels` for integer volumes with at most this many
/// distinct values.
const SUGGEST_LABELS: usize = 256;

/// What a file holding one image, not a volume, holds, and why `render`
/// needs more.
fn describe_image(name: &str, image: &FlatImage, as_json: bool) {
    let i = &image.info;
    let [nx, ny, nz] = image.dims;
    let (s, o) = (image.spacing, image.origin);
    let (range, non_finite) = image.value_range();
    if as_json {
        let mut out = json!({
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
        add_file_json(&mut out, i);
        outln!(
            "{}",
            serde_json::to_string_pretty(&out).expect("JSON of plain values")
        );
        return;
    }
    let unit = i
        .length_unit
        .as_deref()
        .map(|u| format!(" {u}"))
        .unwrap_or_default();
    outln!("input:     {name}");
    outln!("format:    {}", image.format.description());
    print_stored(i);
    outln!(
        "dims:      {nx} x {ny} x {nz} ({} points: an image, not a volume)",
        image.values.len()
    );
    outln!("spacing:   {}, {}, {}{unit}", s.x, s.y, s.z);
    outln!("origin:    {}, {}, {}{unit}", o.x, o.y, o.z);
    match range {
        None => outln!("values:    no finite values"),
        Some((min, max, mean)) => outln!("values:    min {min}, max {max}, mean {mean:.6e}"),
    }
    if non_finite > 0 {
        outln!("           {non_finite} non-finite (NaN or infinite)");
    }
    outln!("render:    refused: {}", image.reason);
    print_header_and_notes(i);
}

/// The stored type, and the frames and arrays a file holds.
fn print_stored(i: &FileInfo) {
    outln!("stored as: {}", i.stored_type);
    if i.frames > 1 {
        outln!(
            "frame:     {} of {} (--frame picks another)",
            i.frame,
            i.frames
        );
    }
    if !i.levels.is_empty() {
        outln!(
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
                "  {n}: {x} x {y} x {z}, spacing {sx}, {sy}, {sz}; chunks {}, shards {}; codecs {}; {} stored, {} in memory",
                shape(&l.chunk_shape),
                shape(&l.shard_shape),
                l.codecs,
                volray_io::format_bytes(u128::from(l.bytes_stored)),
                volray_io::format_bytes(u128::from(l.bytes_in_memory))
            );
        }
    }
    if !i.arrays.is_empty() {
        outln!(
            "arrays:    {} (read: {}; --array picks another)",
            i.arrays.join(", "),
            i.array.as_deref().unwrap_or("-")
        );
    }
}

/// The header as written and the notes of how the file was read.
fn print_header_and_notes(i: &FileInfo) {
    if !i.header.is_empty() {
        outln!("header (as written):");
        for (k, val) in &i.header {
            outln!("  {k}: {val}");
        }
    }
    if !i.notes.is_empty() {
        outln!("how it was read:");
        for n in &i.notes {
            outln!("  - {n}");
        }
    }
}

/// The file's own fields in `volray info --json`.
fn add_file_json(out: &mut Value, i: &FileInfo) {
    out["stored_type"] = json!(i.stored_type);
    out["frames"] = json!(i.frames);
    out["frame"] = json!(i.frame);
    out["arrays"] = json!(i.arrays);
    out["array"] = json!(i.array);
    out["header"] = json!(
        i.header
            .iter()
            .map(|(k, v)| json!({"key": k, "value": v}))
            .collect::<Vec<_>>()
    );
    out["notes"] = json!(i.notes);
    out["nan_is_empty"] = json!(i.nan_is_empty);
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
