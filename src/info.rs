//! `volray info`: what a volume file holds and how volray reads it.

use crate::error::CliError;
use crate::flags::InfoArgs;
use crate::input;
use serde_json::json;
use volray_core::Histogram;

pub fn run(args: &InfoArgs) -> Result<(), CliError> {
    let input = input::load(&args.input)?;
    let v = &input.volume;
    let hist = Histogram::of(v, usize::from(args.bins));
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
            "spacing": [s.x, s.y, s.z],
            "origin": [o.x, o.y, o.z],
            "length_unit": unit,
            "values": histogram,
        });
        if let Some(i) = info {
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
        outln!("stored as: {}", i.stored_type);
        if i.frames > 1 {
            outln!(
                "frame:     {} of {} (--frame picks another)",
                i.frame,
                i.frames
            );
        }
        if !i.arrays.is_empty() {
            outln!(
                "arrays:    {} (read: {}; --array picks another)",
                i.arrays.join(", "),
                i.array.as_deref().unwrap_or("-")
            );
        }
    }
    outln!("dims:      {nx} x {ny} x {nz} ({} points)", v.len());
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
            if h.non_finite > 0 {
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
    if let Some(i) = info {
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
    Ok(())
}
