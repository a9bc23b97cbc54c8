//! DICOM Segmentation objects (SEG, SOP class 1.2.840.10008.5.1.4.1.1.66.4;
//! PS3.3 A.51 and C.8.20) read as a label volume.
//!
//! A SEG file holds one frame per segment and slice: each frame's
//! per-frame functional groups name its segment
//! (SegmentIdentificationSequence → ReferencedSegmentNumber) and its
//! place (PlanePositionSequence → ImagePositionPatient), with the
//! orientation and pixel spacing shared or per frame, as in any enhanced
//! image (read by [`header`](super::header)). The volume has a voxel per
//! pixel of the distinct positions, stacked along the slice normal at
//! SpacingBetweenSlices (PixelMeasuresSequence) or the smallest gap
//! between positions (frames left out because empty, as highdicom does by
//! default, leave zeros); each voxel holds the SegmentNumber of the
//! segment its frame marks there, 0 where none. Pixels are BINARY (1 bit,
//! packed across frames, first pixel in the lowest bit: PS3.5 8.1.1),
//! FRACTIONAL (8 bits, a voxel belongs to the segment where its fraction
//! exceeds one half of MaximumFractionalValue) or LABELMAP (8 or 16 bits,
//! the segment number itself). Where segments overlap the frame later in
//! the file wins, with a note counting the voxels (a label volume holds
//! one label per voxel; highdicom's `get_volume(combine_segments=True)`
//! refuses overlaps instead). Segment names (SegmentLabel) and colours
//! (RecommendedDisplayCIELabValue, CIELab to sRGB) go to
//! [`FileInfo::segments`].

use std::path::Path;

use dicom_core::Tag;
use dicom_dictionary_std::tags;
use dicom_object::InMemDicomObject;
use volray_core::glam::DVec3;

use super::header::{FileHeader, PER_FRAME_GROUPS, read_all, text};
use super::parse_whole;
use super::pixels::transfer_syntax_name;
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::check_volume_size;
use crate::{FileInfo, Loaded, Segment, VolumeFormat};

/// Segmentation Storage.
pub(super) const SEGMENTATION: &str = "1.2.840.10008.5.1.4.1.1.66.4";

const SEGMENTATION_TYPE: Tag = Tag(0x0062, 0x0001);
const SEGMENT_SEQUENCE: Tag = Tag(0x0062, 0x0002);
const SEGMENT_NUMBER: Tag = Tag(0x0062, 0x0004);
const SEGMENT_LABEL: Tag = Tag(0x0062, 0x0005);
const SEGMENT_IDENTIFICATION: Tag = Tag(0x0062, 0x000A);
const REFERENCED_SEGMENT_NUMBER: Tag = Tag(0x0062, 0x000B);
const RECOMMENDED_CIELAB: Tag = Tag(0x0062, 0x000D);
const MAXIMUM_FRACTIONAL_VALUE: Tag = Tag(0x0062, 0x000E);

/// How a SEG stores its pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Binary,
    Fractional(u32),
    Labelmap,
}

/// Reads the Segmentation `path` whose header is `header`.
pub(super) fn read(
    path: &Path,
    header: FileHeader,
    max_memory: u64,
    mut info: FileInfo,
) -> Result<Loaded, IoError> {
    let bad = |r: String| IoError::invalid(path, format!("DICOM Segmentation: {r}"));
    let syntax = header.transfer_syntax.trim_end_matches('\0').to_string();
    let native = matches!(
        syntax.as_str(),
        "1.2.840.10008.1.2" | "1.2.840.10008.1.2.1" | "1.2.840.10008.1.2.1.99"
    );
    if !native {
        return Err(bad(format!(
            "pixel data in {} ({syntax}): volray reads uncompressed segmentations only",
            transfer_syntax_name(&syntax)
        )));
    }
    let bytes = read_all(path)?;
    let obj = parse_whole(path, &bytes)?;
    drop(bytes);
    let required =
        |tag: Tag, name: &str| uint(&obj, tag).ok_or_else(|| bad(format!("{name} is missing")));
    let rows = required(tags::ROWS, "Rows (0028,0010)")? as usize;
    let columns = required(tags::COLUMNS, "Columns (0028,0011)")? as usize;
    let bits = required(tags::BITS_ALLOCATED, "BitsAllocated (0028,0100)")? as usize;
    let frames = header.frames;
    let pixels = (rows as u64)
        .checked_mul(columns as u64)
        .filter(|&n| n > 0)
        .ok_or_else(|| bad(format!("Rows {rows} x Columns {columns} holds no pixel")))?;
    let need = pixels
        .checked_mul(frames as u64)
        .and_then(|n| n.checked_mul(bits as u64))
        .ok_or_else(|| bad("Rows x Columns x NumberOfFrames is too large".into()))?
        .div_ceil(8);
    let data = obj
        .get(tags::PIXEL_DATA)
        .ok_or_else(|| bad("no pixel data".into()))?
        .to_bytes()
        .map_err(|e| bad(format!("pixel data: {e}")))?;
    if (data.len() as u64) < need {
        return Err(bad(format!(
            "pixel data holds {} bytes, but Rows {rows} x Columns {columns} x {frames} frame(s) of {bits} bit(s) need {need}",
            data.len()
        )));
    }

    let kind = match text(&obj, SEGMENTATION_TYPE).as_deref() {
        Some("BINARY") if bits == 1 => Kind::Binary,
        Some("FRACTIONAL") if bits == 8 => Kind::Fractional(
            uint(&obj, MAXIMUM_FRACTIONAL_VALUE)
                .filter(|&m| m > 0)
                .ok_or_else(|| {
                    bad("FRACTIONAL without a positive MaximumFractionalValue (0062,000E)".into())
                })?,
        ),
        Some("LABELMAP") if bits == 8 || bits == 16 => Kind::Labelmap,
        Some(t) => {
            return Err(bad(format!(
                "SegmentationType {t} with BitsAllocated {bits}: volray reads BINARY (1 bit), FRACTIONAL (8 bits) and LABELMAP (8 or 16 bits)"
            )));
        }
        None => return Err(bad("SegmentationType (0062,0001) is missing".into())),
    };
    info.segments = segments(&obj);
    let numbers = frame_segments(&obj, frames, kind).map_err(bad)?;
    let grid = grid(&header, measures(&obj)).map_err(bad)?;
    let (dims, slice_of) = ([columns, rows, grid.slices], grid.slice_of);
    let largest = match kind {
        Kind::Labelmap if bits == 16 => u16::MAX as i64,
        Kind::Labelmap => u8::MAX as i64,
        _ => numbers.iter().copied().max().unwrap_or(0),
    };
    let wide = largest > i64::from(u8::MAX);
    let voxels = check_volume_size(
        path,
        "Columns x Rows x slices",
        &[columns as u64, rows as u64, grid.slices as u64],
        if wide { 2 } else { 1 },
        max_memory,
    )?;
    let mut labels = vec![0u16; if wide { voxels } else { 0 }];
    let mut small = vec![0u8; if wide { 0 } else { voxels }];
    let plane = rows * columns;
    let mut overlaps = 0u64;
    for f in 0..frames {
        let base = slice_of[f] * plane;
        for p in 0..plane {
            let i = f * plane + p;
            let value: i64 = match kind {
                Kind::Binary => {
                    if data[i / 8] >> (i % 8) & 1 == 1 {
                        numbers[f]
                    } else {
                        0
                    }
                }
                Kind::Fractional(max) => {
                    if 2 * u64::from(data[i]) > u64::from(max) {
                        numbers[f]
                    } else {
                        0
                    }
                }
                Kind::Labelmap if bits == 16 => {
                    i64::from(u16::from_le_bytes([data[2 * i], data[2 * i + 1]]))
                }
                Kind::Labelmap => i64::from(data[i]),
            };
            if value == 0 {
                continue;
            }
            let old = if wide {
                std::mem::replace(&mut labels[base + p], value as u16) as i64
            } else {
                std::mem::replace(&mut small[base + p], value as u8) as i64
            };
            if old != 0 && old != value {
                overlaps += 1;
            }
        }
    }
    drop(data);

    info.stored_type = match kind {
        Kind::Binary => "1-bit BINARY segmentation".into(),
        Kind::Fractional(max) => {
            format!("uint8 FRACTIONAL segmentation (MaximumFractionalValue {max})")
        }
        Kind::Labelmap => format!("uint{bits} LABELMAP segmentation"),
    };
    info.header = header.fields.clone();
    let names: Vec<String> = info
        .segments
        .iter()
        .map(|s| format!("{} \"{}\"", s.label, s.name))
        .collect();
    info.notes.push(format!(
        "DICOM Segmentation: a label volume, each voxel the SegmentNumber of its segment, 0 outside every segment ({} segment(s): {}); render it as labels",
        info.segments.len(),
        names.join(", ")
    ));
    if let Kind::Fractional(max) = kind {
        info.notes.push(format!(
            "FRACTIONAL segments: a voxel belongs to a segment where its value exceeds half of MaximumFractionalValue {max}"
        ));
    }
    if overlaps > 0 {
        info.notes.push(format!(
            "{overlaps} voxel(s) lie in more than one segment: each keeps the segment of the frame latest in the file"
        ));
    }
    info.notes.extend(grid.notes);
    info.notes.push(
        "world coordinates are DICOM patient coordinates (LPS: +x to the patient's left, +y posterior, +z head), in mm".into(),
    );
    info.length_unit = Some("mm".into());
    let volume = if wide {
        grid_to_volume(path, dims, labels, grid.steps, grid.origin, &mut info)?
    } else {
        grid_to_volume(path, dims, small, grid.steps, grid.origin, &mut info)?
    };
    Ok(Loaded {
        volume,
        format: VolumeFormat::Dicom,
        info,
    })
}

fn uint(obj: &InMemDicomObject, tag: Tag) -> Option<u32> {
    obj.get(tag)?.to_int::<u32>().ok()
}

/// The segments of the SegmentSequence: number, label, colour.
fn segments(obj: &InMemDicomObject) -> Vec<Segment> {
    let items = obj
        .get(SEGMENT_SEQUENCE)
        .and_then(|e| e.items())
        .unwrap_or(&[]);
    items
        .iter()
        .filter_map(|item| {
            let label = i64::from(uint(item, SEGMENT_NUMBER)?);
            let colour = item
                .get(RECOMMENDED_CIELAB)
                .and_then(|e| e.to_multi_int::<u16>().ok())
                .filter(|v| v.len() == 3)
                .map(|v| lab_to_srgb([v[0], v[1], v[2]]));
            Some(Segment {
                label,
                name: text(item, SEGMENT_LABEL).unwrap_or_default(),
                colour,
            })
        })
        .collect()
}

/// Each frame's ReferencedSegmentNumber (per frame, else shared); for a
/// LABELMAP, whose pixels are the numbers, none is needed.
fn frame_segments(obj: &InMemDicomObject, frames: usize, kind: Kind) -> Result<Vec<i64>, String> {
    if kind == Kind::Labelmap {
        return Ok(vec![0; frames]);
    }
    let number_in = |group: &InMemDicomObject| -> Option<i64> {
        let item = group.get(SEGMENT_IDENTIFICATION)?.items()?.first()?;
        uint(item, REFERENCED_SEGMENT_NUMBER).map(i64::from)
    };
    let shared = obj
        .get(tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|e| e.items())
        .and_then(|items| items.first())
        .and_then(number_in);
    let per_frame = obj
        .get(PER_FRAME_GROUPS.0)
        .and_then(|e| e.items())
        .unwrap_or(&[]);
    (0..frames)
        .map(|f| {
            let n = per_frame
                .get(f)
                .and_then(number_in)
                .or(shared)
                .ok_or_else(|| {
                    format!(
                        "frame {f} names no segment (SegmentIdentificationSequence (0062,000A))"
                    )
                })?;
            if !(1..=i64::from(u16::MAX)).contains(&n) {
                return Err(format!("frame {f} names segment {n}, outside 1..65535"));
            }
            Ok(n)
        })
        .collect()
}

/// Where a SEG's frames go: the grid's steps and origin, its slices, and
/// each frame's slice.
struct Grid {
    steps: [DVec3; 3],
    origin: DVec3,
    slices: usize,
    slice_of: Vec<usize>,
    notes: Vec<String>,
}

/// SpacingBetweenSlices and SliceThickness of the shared
/// PixelMeasuresSequence (else the first frame's, else the top level's).
fn measures(obj: &InMemDicomObject) -> [Option<f64>; 2] {
    let group = |seq: Tag| {
        obj.get(seq)?
            .items()?
            .first()?
            .get(tags::PIXEL_MEASURES_SEQUENCE)?
            .items()?
            .first()
    };
    let found =
        group(tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE).or_else(|| group(PER_FRAME_GROUPS.0));
    let value = |tag: Tag| -> Option<f64> {
        found
            .and_then(|g| g.get(tag))
            .or_else(|| obj.get(tag))?
            .to_float64()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
    };
    [
        value(tags::SPACING_BETWEEN_SLICES),
        value(tags::SLICE_THICKNESS),
    ]
}

/// The grid of the frames' planes (see the module documentation), with
/// the slice spacing and thickness `measures` gives.
fn grid(header: &FileHeader, [spacing, thickness]: [Option<f64>; 2]) -> Result<Grid, String> {
    let first = &header.planes[0];
    let [along_row, along_column] = first.orientation.ok_or(
        "no ImageOrientationPatient (PlaneOrientationSequence): the frames cannot be placed",
    )?;
    let [row_gap, column_gap] = first.pixel_spacing.unwrap_or([1.0, 1.0]);
    let mut notes = Vec::new();
    if first.pixel_spacing.is_none() {
        notes.push("no PixelSpacing: 1 mm between rows and between columns assumed".into());
    }
    let normal = along_row.cross(along_column);
    let mut depth = Vec::with_capacity(header.planes.len());
    let mut in_plane = None;
    for (f, p) in header.planes.iter().enumerate() {
        if p.orientation.is_some_and(|o| {
            (o[0] - along_row).length() > 1e-3 || (o[1] - along_column).length() > 1e-3
        }) {
            return Err(format!("frame {f}'s orientation differs from frame 0's"));
        }
        let pos = p.position.ok_or_else(|| {
            format!("frame {f} has no ImagePositionPatient (PlanePositionSequence)")
        })?;
        let d = pos.dot(normal);
        let flat = pos - normal * d;
        match in_plane {
            None => in_plane = Some(flat),
            Some(q) if (flat - q).length() > 0.05 * row_gap.min(column_gap) => {
                return Err(format!(
                    "frame {f} is shifted within its plane from frame 0: the frames are not one grid"
                ));
            }
            _ => {}
        }
        depth.push(d);
    }
    let mut distinct = depth.clone();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
    let lowest = distinct[0];
    let smallest_gap = distinct
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    let step = match spacing {
        Some(s) => s,
        None if smallest_gap.is_finite() => smallest_gap,
        None => thickness.unwrap_or(1.0),
    };
    let mut slice_of = Vec::with_capacity(depth.len());
    let mut slices = 1;
    for (f, &d) in depth.iter().enumerate() {
        let at = (d - lowest) / step;
        let k = at.round();
        if (at - k).abs() > 0.05 || k > 1e7 {
            return Err(format!(
                "frame {f} lies {:.4} mm along the slice normal from the first position, not a whole number of {step} mm slices",
                d - lowest
            ));
        }
        slice_of.push(k as usize);
        slices = slices.max(k as usize + 1);
    }
    if slices > distinct.len() {
        notes.push(format!(
            "{} of {slices} slices have no frame (left out as empty): they hold 0",
            slices - distinct.len()
        ));
    }
    let origin = in_plane.unwrap_or(DVec3::ZERO) + normal * lowest;
    Ok(Grid {
        steps: [
            along_row * column_gap,
            along_column * row_gap,
            normal * step,
        ],
        origin,
        slices,
        slice_of,
        notes,
    })
}

/// The sRGB colour (0..255) of a DICOM CIELab value (PS3.3 C.10.7.1.1:
/// L* 0..100 and a*, b* -128..127 scaled to 0..65535): Lab to XYZ (CIE
/// 15) with the D65 white (0.95047, 1, 1.08883), XYZ to linear sRGB (IEC
/// 61966-2-1's matrix), then sRGB's transfer curve. The standard names
/// the ICC connection space (D50), but the tools that write and read
/// segmentations (dcmqi's `Helper::getRGBFromCIELab`, 3D Slicer through
/// it, highdicom's `CIELabColor`) take D65 without adaptation, so the
/// colours given to them come back here.
pub(crate) fn lab_to_srgb(v: [u16; 3]) -> [u8; 3] {
    let l = f64::from(v[0]) * 100.0 / 65535.0;
    let a = f64::from(v[1]) * 255.0 / 65535.0 - 128.0;
    let b = f64::from(v[2]) * 255.0 / 65535.0 - 128.0;
    let fy = (l + 16.0) / 116.0;
    let (fx, fz) = (fy + a / 500.0, fy - b / 200.0);
    let delta: f64 = 6.0 / 29.0;
    let inverse = |t: f64| {
        if t > delta {
            t * t * t
        } else {
            3.0 * delta * delta * (t - 4.0 / 29.0)
        }
    };
    let (x, y, z) = (0.95047 * inverse(fx), inverse(fy), 1.08883 * inverse(fz));
    let linear = [
        3.2406 * x - 1.5372 * y - 0.4986 * z,
        -0.9689 * x + 1.8758 * y + 0.0415 * z,
        0.0557 * x - 0.2040 * y + 1.0570 * z,
    ];
    linear.map(|c| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.0031308 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    })
}

#[cfg(test)]
mod tests {
    use super::lab_to_srgb;

    #[test]
    fn white_black_and_primaries_come_back_from_cielab() {
        // L* 100, a* = b* = 0 (0x8080 is 128.5/255 of the range: a* ≈ 0).
        assert_eq!(lab_to_srgb([0xFFFF, 0x8080, 0x8080]), [255, 255, 255]);
        assert_eq!(lab_to_srgb([0, 0x8080, 0x8080]), [0, 0, 0]);
        // What highdicom's CIELabColor.from_rgb writes for sRGB red,
        // blue and (128, 64, 200).
        let near = |got: [u8; 3], want: [u8; 3]| (0..3).all(|c| got[c].abs_diff(want[c]) <= 1);
        assert!(near(lab_to_srgb([34886, 53484, 50172]), [255, 0, 0]));
        assert!(near(lab_to_srgb([21170, 53250, 5175]), [0, 0, 255]));
        assert!(near(lab_to_srgb([27450, 46654, 17381]), [128, 64, 200]));
    }
}
