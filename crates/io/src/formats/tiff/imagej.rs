//! ImageJ metadata (an `ImageDescription` starting with `ImageJ=`): the
//! hyperstack shape ([`Shape`]), the value calibration and the spacing,
//! unit and origin of the voxels.

use std::path::Path;

use volray_core::glam::DVec3;

use crate::FileInfo;
use crate::error::IoError;

/// The hyperstack layout: how many channels, slices and time points the
/// pages hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Shape {
    pub(super) channels: usize,
    pub(super) slices: usize,
    pub(super) times: usize,
}

/// The stack's shape from ImageJ's counts, checked against the pages.
pub(super) fn stack_shape(
    path: &Path,
    imagej: Option<&ImageJ>,
    pages: usize,
) -> Result<Shape, IoError> {
    let Some(ij) = imagej else {
        return Ok(Shape {
            channels: 1,
            slices: pages,
            times: 1,
        });
    };
    let count = |key: &str| -> Result<Option<usize>, IoError> {
        match ij.get(key) {
            None => Ok(None),
            Some(v) => match v.parse::<usize>() {
                Ok(n) if n >= 1 => Ok(Some(n)),
                _ => Err(IoError::invalid(
                    path,
                    format!("ImageJ description field \"{key}\": \"{v}\" is not a positive count"),
                )),
            },
        }
    };
    let channels = count("channels")?.unwrap_or(1);
    let times = count("frames")?.unwrap_or(1);
    let images = count("images")?;
    let slices = match count("slices")? {
        Some(s) => s,
        None => {
            let n = images.unwrap_or(pages);
            n / (channels * times).max(1)
        }
    };
    let declared = channels
        .checked_mul(slices)
        .and_then(|n| n.checked_mul(times));
    if declared != Some(pages) {
        let hint = if pages == 1 {
            " (ImageJ's contiguous layout for stacks over 4 GB, with one page, is not supported)"
        } else {
            ""
        };
        return Err(IoError::invalid(
            path,
            format!(
                "ImageJ description says channels={channels} slices={slices} frames={times} but the file has {pages} full-resolution page(s){hint}"
            ),
        ));
    }
    Ok(Shape {
        channels,
        slices,
        times,
    })
}

/// The `key=value` lines of an ImageJ `ImageDescription`, in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct ImageJ {
    fields: Vec<(String, String)>,
}

impl ImageJ {
    pub(super) fn parse(description: &str) -> Self {
        let fields = description
            .lines()
            .filter_map(|line| {
                let (k, v) = line.split_once('=')?;
                Some((k.trim().to_string(), v.trim().to_string()))
            })
            .collect();
        ImageJ { fields }
    }

    pub(super) fn get(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// A finite number under `key`, if present and readable.
    pub(super) fn number(&self, key: &str) -> Option<f64> {
        self.get(key)?.parse::<f64>().ok().filter(|v| v.is_finite())
    }

    /// The length unit, with ImageJ's `\u00B5` escape decoded.
    pub(super) fn unit(&self) -> Option<String> {
        let raw = self.get("unit")?;
        Some(
            raw.replace("\\u00B5", "\u{b5}")
                .replace("\\u00b5", "\u{b5}"),
        )
    }
}

/// ImageJ's linear calibration `value = c0 + c1·stored` (`cf=0`, ImageJ's
/// `Calibration.STRAIGHT_LINE`) as `(c0, c1)` when there is one to apply,
/// and the note to give about it.
pub(super) fn calibration(ij: &ImageJ) -> (Option<(f64, f64)>, Option<String>) {
    let Some(cf) = ij.get("cf") else {
        return (None, None);
    };
    if cf != "0" {
        let note = format!(
            "ImageJ calibration function cf={cf} (not a straight line) ignored: stored values kept"
        );
        return (None, Some(note));
    }
    let (c0, c1) = (
        ij.number("c0").unwrap_or(0.0),
        ij.number("c1").unwrap_or(1.0),
    );
    if c0 == 0.0 && c1 == 1.0 {
        return (None, None);
    }
    let unit = ij
        .get("vunit")
        .map(|u| format!(" ({u})"))
        .unwrap_or_default();
    let note = format!("ImageJ calibration applied: value = {c0} + {c1} x stored{unit}");
    (Some((c0, c1)), Some(note))
}

/// Spacing and origin from ImageJ's calibration: see the module docs.
pub(super) fn imagej_geometry(
    ij: &ImageJ,
    resolution: [Option<f64>; 2],
    spacing: &mut DVec3,
    origin: &mut DVec3,
    info: &mut FileInfo,
) {
    let unit = ij.unit().filter(|u| u != "pixel" && !u.is_empty());
    let Some(unit) = unit else {
        info.notes
            .push("ImageJ stack without a length unit: spacing 1, 1, 1 (pixels)".into());
        return;
    };
    for (a, res) in resolution.into_iter().enumerate() {
        match res {
            Some(r) if r.is_finite() && r > 0.0 => spacing[a] = 1.0 / r,
            Some(r) => info.notes.push(format!(
                "{} {r} is not a positive number of pixels per {unit}: spacing 1 used",
                ["XResolution", "YResolution"][a]
            )),
            None => {}
        }
    }
    match ij.number("spacing") {
        Some(s) if s > 0.0 => spacing.z = s,
        Some(s) => info.notes.push(format!(
            "ImageJ spacing={s} is not positive: z spacing 1 used"
        )),
        None => {}
    }
    for (a, key) in ["xorigin", "yorigin", "zorigin"].into_iter().enumerate() {
        if let Some(o) = ij.number(key) {
            origin[a] = -o * spacing[a];
        }
    }
    info.notes.push(format!(
        "spacing {}, {}, {} {unit} from ImageJ metadata (x, y: 1/XResolution, 1/YResolution; z: spacing=){}",
        spacing.x,
        spacing.y,
        spacing.z,
        if *origin != DVec3::ZERO {
            format!(
                "; origin {}, {}, {} from xorigin/yorigin/zorigin (pixels)",
                origin.x, origin.y, origin.z
            )
        } else {
            String::new()
        }
    ));
    info.length_unit = Some(unit);
}
