//! What one DICOM file says about its image: the attributes volray needs,
//! read from the elements before the pixel data, with the checks that
//! name the attribute and its value when one is wrong.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
use dicom_dictionary_std::{StandardDataDictionary, tags};
use dicom_object::{DefaultDicomObject, InMemDicomObject, OpenFileOptions, Tag};
use volray_core::glam::DVec3;

use super::prescan::{PixelData, Prescan, prescan};
use crate::error::IoError;
use crate::shared::input::{open_input, read_exact_at};
use crate::shared::panics::guarded;

/// Header bytes read at first; doubled until the pixel data is reached.
const FIRST_READ: usize = 64 << 10;

/// Values longer than this are shortened in `FileInfo::header`.
const MAX_HEADER_VALUE: usize = 120;

/// An attribute: its tag and keyword, for lookups and messages.
#[derive(Debug, Clone, Copy)]
pub(super) struct Attr(pub Tag, pub &'static str);

impl std::fmt::Display for Attr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({:04X},{:04X})", self.1, self.0.0, self.0.1)
    }
}

pub(super) const ROWS: Attr = Attr(tags::ROWS, "Rows");
pub(super) const COLUMNS: Attr = Attr(tags::COLUMNS, "Columns");
const SAMPLES_PER_PIXEL: Attr = Attr(tags::SAMPLES_PER_PIXEL, "SamplesPerPixel");
const PHOTOMETRIC: Attr = Attr(
    tags::PHOTOMETRIC_INTERPRETATION,
    "PhotometricInterpretation",
);
const BITS_ALLOCATED: Attr = Attr(tags::BITS_ALLOCATED, "BitsAllocated");
const BITS_STORED: Attr = Attr(tags::BITS_STORED, "BitsStored");
const HIGH_BIT: Attr = Attr(tags::HIGH_BIT, "HighBit");
const PIXEL_REPRESENTATION: Attr = Attr(tags::PIXEL_REPRESENTATION, "PixelRepresentation");
pub(super) const NUMBER_OF_FRAMES: Attr = Attr(tags::NUMBER_OF_FRAMES, "NumberOfFrames");
pub(super) const IPP: Attr = Attr(tags::IMAGE_POSITION_PATIENT, "ImagePositionPatient");
pub(super) const IOP: Attr = Attr(tags::IMAGE_ORIENTATION_PATIENT, "ImageOrientationPatient");
pub(super) const PIXEL_SPACING: Attr = Attr(tags::PIXEL_SPACING, "PixelSpacing");
const IMAGER_PIXEL_SPACING: Attr = Attr(tags::IMAGER_PIXEL_SPACING, "ImagerPixelSpacing");
pub(super) const SPACING_BETWEEN_SLICES: Attr =
    Attr(tags::SPACING_BETWEEN_SLICES, "SpacingBetweenSlices");
pub(super) const SLICE_THICKNESS: Attr = Attr(tags::SLICE_THICKNESS, "SliceThickness");
const RESCALE_SLOPE: Attr = Attr(tags::RESCALE_SLOPE, "RescaleSlope");
const RESCALE_INTERCEPT: Attr = Attr(tags::RESCALE_INTERCEPT, "RescaleIntercept");
const RESCALE_TYPE: Attr = Attr(tags::RESCALE_TYPE, "RescaleType");
pub(super) const GRID_FRAME_OFFSETS: Attr =
    Attr(tags::GRID_FRAME_OFFSET_VECTOR, "GridFrameOffsetVector");
const DOSE_GRID_SCALING: Attr = Attr(tags::DOSE_GRID_SCALING, "DoseGridScaling");
const DOSE_UNITS: Attr = Attr(tags::DOSE_UNITS, "DoseUnits");
const SHARED_GROUPS: Attr = Attr(
    tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE,
    "SharedFunctionalGroupsSequence",
);
pub(super) const PER_FRAME_GROUPS: Attr = Attr(
    tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE,
    "PerFrameFunctionalGroupsSequence",
);

/// The pixel layout of a file's frames.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct ImageFormat {
    pub rows: usize,
    pub columns: usize,
    pub bits_allocated: u16,
    pub bits_stored: u16,
    pub high_bit: u16,
    pub signed: bool,
    pub photometric: String,
    /// Float (7FE0,0008) or double (7FE0,0009) pixel data instead of integers.
    pub float: Option<u16>,
}

impl ImageFormat {
    /// Bytes per sample as stored.
    pub fn sample_bytes(&self) -> usize {
        usize::from(self.bits_allocated / 8)
    }

    /// The stored type for `FileInfo::stored_type`, e.g. `int16 (12 bits stored)`.
    pub fn describe(&self) -> String {
        if let Some(bits) = self.float {
            return format!("float{bits}");
        }
        let base = format!(
            "{}int{}",
            if self.signed { "" } else { "u" },
            self.bits_allocated
        );
        if self.bits_stored < self.bits_allocated {
            format!("{base} ({} bits stored)", self.bits_stored)
        } else {
            base
        }
    }
}

/// The position and value scaling of one frame (one slice).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Plane {
    /// ImagePositionPatient: the centre of the first pixel, in mm.
    pub position: Option<DVec3>,
    /// The most decimals written in any of ImagePositionPatient's values
    /// ("11.25" has 2): the positions' rounding. `None` without a
    /// position, or with an exponent.
    pub position_decimals: Option<u32>,
    /// ImageOrientationPatient: the directions of increasing column and row index.
    pub orientation: Option<[DVec3; 2]>,
    /// PixelSpacing: (between rows, between columns), in mm.
    pub pixel_spacing: Option<[f64; 2]>,
    /// Modality LUT (or dose scaling): value = slope·stored + intercept.
    pub slope: f64,
    pub intercept: f64,
}

/// Everything volray reads from one file before its pixel data.
#[derive(Debug, Clone)]
pub(super) struct FileHeader {
    pub path: PathBuf,
    pub file_len: u64,
    pub transfer_syntax: String,
    /// SOPClassUID (or the file meta's MediaStorageSOPClassUID).
    pub sop_class: String,
    pub series_uid: String,
    pub series_number: Option<i64>,
    pub series_description: String,
    pub modality: String,
    pub instance_number: Option<i64>,
    pub format: Result<ImageFormat, String>,
    pub frames: usize,
    /// One per frame.
    pub planes: Vec<Plane>,
    /// SpacingBetweenSlices and SliceThickness at the top level, for
    /// stacks without positions.
    pub slice_spacing: Option<f64>,
    pub slice_thickness: Option<f64>,
    /// How the planes' positions were found, if not from per-frame
    /// attributes (for a note).
    pub geometry_note: Option<String>,
    /// How the values are scaled (for a note), if they are.
    pub scaling_note: Option<String>,
    /// The pixel data element the file ends with, if any.
    pub pixel_data: Option<PixelData>,
    /// The top-level elements as written, for `FileInfo::header`.
    pub fields: Vec<(String, String)>,
}

/// Reads the header of `path`: `Ok(None)` if it is not a DICOM file (no
/// `DICM` magic); `Err(reason)` if it claims to be one but cannot be read.
/// Reads only as far as the pixel data, checking every element length
/// against the file first.
pub(super) fn read_header(path: &Path) -> Result<Option<FileHeader>, HeaderError> {
    let (mut file, file_len) = open_input(path).map_err(HeaderError::Io)?;
    if file_len < 132 {
        return Ok(None);
    }
    let mut bytes = vec![0u8; 132];
    read_exact_at(path, &mut file, &mut bytes, 0, file_len).map_err(HeaderError::Io)?;
    if &bytes[128..132] != b"DICM" {
        return Ok(None);
    }
    let mut want = FIRST_READ;
    let scan = loop {
        let target = (want as u64).min(file_len) as usize;
        extend_to(path, &mut file, &mut bytes, target, file_len)?;
        let whole = bytes.len() as u64 == file_len;
        match prescan(&bytes, whole, true).map_err(HeaderError::Bad)? {
            Prescan::Done(scan) => break scan,
            Prescan::NeedMore if whole => {
                return Err(HeaderError::Bad("file ends inside an element".into()));
            }
            Prescan::NeedMore => want = want.saturating_mul(4),
        }
    };
    let head = &bytes[..scan.end.min(bytes.len())];
    let obj = parse(head, true).map_err(HeaderError::Bad)?;
    let float = scan.pixel_data.and_then(|p| match p.element {
        0x0008 => Some(32),
        0x0009 => Some(64),
        _ => None,
    });
    let mut header = extract(path, &obj, float).map_err(HeaderError::Bad)?;
    header.file_len = file_len;
    header.pixel_data = scan.pixel_data;
    Ok(Some(header))
}

/// Why a header could not be read.
#[derive(Debug)]
pub(super) enum HeaderError {
    /// The operating system failed.
    Io(IoError),
    /// The file claims to be DICOM but is malformed.
    Bad(String),
}

/// Reads more of `file` until `bytes` holds `target` bytes.
fn extend_to(
    path: &Path,
    file: &mut File,
    bytes: &mut Vec<u8>,
    target: usize,
    file_len: u64,
) -> Result<(), HeaderError> {
    let start = bytes.len();
    if target <= start {
        return Ok(());
    }
    bytes.resize(target, 0);
    read_exact_at(path, file, &mut bytes[start..], start as u64, file_len).map_err(HeaderError::Io)
}

/// Parses DICOM file `bytes` (preamble included) whose lengths were
/// checked; `head_only` stops before the pixel data. A panic inside the
/// parser becomes an error.
pub(super) fn parse(bytes: &[u8], head_only: bool) -> Result<DefaultDicomObject, String> {
    let result = guarded(|| {
        let mut options = OpenFileOptions::new();
        if head_only {
            options = options.read_until(tags::FLOAT_PIXEL_DATA);
        }
        options.from_reader(bytes)
    })
    .ok();
    match result {
        Some(Ok(obj)) => Ok(obj),
        Some(Err(e)) => Err(format!("cannot parse: {e}")),
        None => Err("the DICOM parser failed on this file".into()),
    }
}

/// The attributes of a parsed file.
/// `float_bits`: the file's pixel data is Float (32) or Double Float (64)
/// Pixel Data, which the header parse stops before.
fn extract(
    path: &Path,
    obj: &DefaultDicomObject,
    float_bits: Option<u16>,
) -> Result<FileHeader, String> {
    let frames = match uint(obj, NUMBER_OF_FRAMES)? {
        None => 1,
        Some(0) => return Err(format!("{NUMBER_OF_FRAMES} is 0")),
        Some(n) => n as usize,
    };
    let format = image_format(obj, float_bits);
    let mut header = FileHeader {
        path: path.to_path_buf(),
        file_len: 0,
        transfer_syntax: obj.meta().transfer_syntax().to_string(),
        sop_class: text(obj, tags::SOP_CLASS_UID)
            .unwrap_or_else(|| obj.meta().media_storage_sop_class_uid().to_string()),
        series_uid: text(obj, tags::SERIES_INSTANCE_UID).unwrap_or_default(),
        series_number: int(obj, tags::SERIES_NUMBER),
        series_description: text(obj, tags::SERIES_DESCRIPTION).unwrap_or_default(),
        modality: text(obj, tags::MODALITY).unwrap_or_default(),
        instance_number: int(obj, tags::INSTANCE_NUMBER),
        format,
        frames,
        planes: Vec::new(),
        slice_spacing: float(obj, SPACING_BETWEEN_SLICES).ok().flatten(),
        slice_thickness: float(obj, SLICE_THICKNESS).ok().flatten(),
        geometry_note: None,
        scaling_note: None,
        pixel_data: None,
        fields: fields(obj),
    };
    planes(obj, &mut header)?;
    let scaled = header
        .planes
        .iter()
        .any(|p| p.slope != 1.0 || p.intercept != 0.0);
    if header.scaling_note.is_none() && scaled {
        header.scaling_note = Some(rescale_note(&header.planes, obj));
    }
    Ok(header)
}

/// The pixel layout, or why volray cannot use it.
fn image_format(obj: &InMemDicomObject, float: Option<u16>) -> Result<ImageFormat, String> {
    let rows = uint(obj, ROWS)?.ok_or(format!("{ROWS} is missing"))? as usize;
    let columns = uint(obj, COLUMNS)?.ok_or(format!("{COLUMNS} is missing"))? as usize;
    let samples = uint(obj, SAMPLES_PER_PIXEL)?.unwrap_or(1);
    let photometric = text(obj, tags::PHOTOMETRIC_INTERPRETATION).unwrap_or_default();
    if samples != 1 {
        return Err(format!(
            "{SAMPLES_PER_PIXEL} is {samples} ({photometric}): volray reads greyscale images only"
        ));
    }
    if photometric.starts_with("PALETTE") {
        return Err(format!(
            "{PHOTOMETRIC} is {photometric}: palette-colour images are not scalar data"
        ));
    }
    let bits_allocated =
        uint(obj, BITS_ALLOCATED)?.ok_or(format!("{BITS_ALLOCATED} is missing"))?;
    let bits_stored = uint(obj, BITS_STORED)?.unwrap_or(bits_allocated);
    let high_bit = uint(obj, HIGH_BIT)?.unwrap_or(bits_stored.saturating_sub(1));
    let signed = uint(obj, PIXEL_REPRESENTATION)?.unwrap_or(0) == 1;
    if float.is_none() {
        if !matches!(bits_allocated, 8 | 16 | 32) {
            return Err(format!(
                "{BITS_ALLOCATED} is {bits_allocated}: volray reads 8-, 16- and 32-bit samples"
            ));
        }
        if bits_stored == 0
            || bits_stored > bits_allocated
            || high_bit >= bits_allocated
            || high_bit + 1 < bits_stored
        {
            return Err(format!(
                "{BITS_STORED} {bits_stored} and {HIGH_BIT} {high_bit} do not fit {BITS_ALLOCATED} {bits_allocated}"
            ));
        }
    }
    Ok(ImageFormat {
        rows,
        columns,
        bits_allocated: bits_allocated as u16,
        bits_stored: bits_stored as u16,
        high_bit: high_bit as u16,
        signed,
        photometric,
        float,
    })
}

/// Fills `header.planes`, one per frame, from (in order of preference)
/// the functional groups of an enhanced multi-frame file, the
/// GridFrameOffsetVector of an RT dose, the top-level attributes with
/// SpacingBetweenSlices for other multi-frame files, or the top-level
/// attributes of a single-frame file.
fn planes(obj: &DefaultDicomObject, header: &mut FileHeader) -> Result<(), String> {
    let frames = header.frames;
    let mut top = top_plane(obj)?;
    if let Some(dose) = float(obj, DOSE_GRID_SCALING)? {
        // PS3.3 C.8.8.3.4.2: dose = DoseGridScaling x stored value.
        let units = text(obj, DOSE_UNITS.0).unwrap_or_else(|| "unknown units".into());
        header.scaling_note = Some(format!(
            "{DOSE_GRID_SCALING} {dose} applied: values are dose in {units}"
        ));
        top.slope *= dose;
        top.intercept *= dose;
    }

    if let Some(per_frame) = obj.get(PER_FRAME_GROUPS.0) {
        let items = per_frame.items().unwrap_or(&[]);
        if items.len() != frames {
            return Err(format!(
                "{PER_FRAME_GROUPS} has {} item(s) but {NUMBER_OF_FRAMES} is {frames}",
                items.len()
            ));
        }
        let shared = obj
            .get(SHARED_GROUPS.0)
            .and_then(|e| e.items())
            .and_then(|items| items.first());
        for item in items {
            let group = |seq: Tag| -> Option<&InMemDicomObject> {
                [Some(item), shared]
                    .into_iter()
                    .flatten()
                    .find_map(|g| g.get(seq)?.items()?.first())
            };
            let position_group = group(tags::PLANE_POSITION_SEQUENCE);
            let position = position_group
                .map(|g| vector(g, IPP))
                .transpose()?
                .flatten()
                .or(top.position);
            let position_decimals = match position_group {
                Some(g) if g.get(IPP.0).is_some() => decimals(g, IPP),
                _ => top.position_decimals,
            };
            let orientation = group(tags::PLANE_ORIENTATION_SEQUENCE)
                .map(orientation)
                .transpose()?
                .flatten()
                .or(top.orientation);
            let pixel_spacing = group(tags::PIXEL_MEASURES_SEQUENCE)
                .map(pixel_spacing)
                .transpose()?
                .flatten()
                .or(top.pixel_spacing);
            let (slope, intercept) = match group(tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE) {
                Some(g) => rescale(g)?,
                None => (top.slope, top.intercept),
            };
            header.planes.push(Plane {
                position,
                position_decimals,
                orientation,
                pixel_spacing,
                slope,
                intercept,
            });
        }
        return Ok(());
    }

    if let Some(offsets) = floats(obj, GRID_FRAME_OFFSETS)? {
        if offsets.len() != frames {
            return Err(format!(
                "{GRID_FRAME_OFFSETS} has {} values but {NUMBER_OF_FRAMES} is {frames}",
                offsets.len()
            ));
        }
        let (Some(position), Some(orientation)) = (top.position, top.orientation) else {
            return Err(format!("{GRID_FRAME_OFFSETS} needs {IPP} and {IOP}"));
        };
        let normal = orientation[0].cross(orientation[1]);
        // PS3.3 C.8.8.3.2: offsets relative to the first frame when the
        // first is 0; otherwise absolute z, allowed only for axial
        // (1,0,0,0,1,0) orientations.
        let relative = offsets[0] == 0.0;
        let axial = (orientation[0] - DVec3::X).length() < 1e-4
            && (orientation[1] - DVec3::Y).length() < 1e-4;
        if !relative && !axial {
            return Err(format!(
                "{GRID_FRAME_OFFSETS} starts at {} (absolute z positions) but the orientation is not axial",
                offsets[0]
            ));
        }
        header.geometry_note = Some(format!(
            "frame positions from {GRID_FRAME_OFFSETS} ({} along the slice normal)",
            if relative {
                "offsets from ImagePositionPatient"
            } else {
                "absolute z"
            }
        ));
        for &o in &offsets {
            let p = if relative {
                position + normal * o
            } else {
                DVec3::new(position.x, position.y, o)
            };
            header.planes.push(Plane {
                position: Some(p),
                ..top.clone()
            });
        }
        return Ok(());
    }

    if frames > 1 {
        let spacing = float(obj, SPACING_BETWEEN_SLICES)?;
        if let (Some(position), Some(orientation), Some(step)) =
            (top.position, top.orientation, spacing)
        {
            let normal = orientation[0].cross(orientation[1]);
            header.geometry_note = Some(format!(
                "frame k placed at {IPP} + k x {SPACING_BETWEEN_SLICES} {step} mm along the slice normal (no per-frame positions)"
            ));
            for k in 0..frames {
                header.planes.push(Plane {
                    position: Some(position + normal * (step * k as f64)),
                    ..top.clone()
                });
            }
        } else {
            header.planes = vec![
                Plane {
                    position: None,
                    ..top.clone()
                };
                frames
            ];
        }
        return Ok(());
    }
    header.planes.push(top);
    Ok(())
}

/// The geometry and rescale of the top level of a file.
fn top_plane(obj: &InMemDicomObject) -> Result<Plane, String> {
    let (slope, intercept) = rescale(obj)?;
    Ok(Plane {
        position: vector(obj, IPP)?,
        position_decimals: decimals(obj, IPP),
        orientation: orientation(obj)?,
        pixel_spacing: pixel_spacing(obj)?,
        slope,
        intercept,
    })
}

fn rescale_note(planes: &[Plane], obj: &InMemDicomObject) -> String {
    let first = &planes[0];
    let same = planes
        .iter()
        .all(|p| p.slope == first.slope && p.intercept == first.intercept);
    let kind = text(obj, RESCALE_TYPE.0)
        .map(|t| format!(" ({t})"))
        .unwrap_or_default();
    if same {
        format!(
            "{RESCALE_SLOPE} {} and {RESCALE_INTERCEPT} {} applied: value = {} x stored + {}{kind}",
            first.slope, first.intercept, first.slope, first.intercept
        )
    } else {
        format!(
            "{RESCALE_SLOPE}/{RESCALE_INTERCEPT} applied per frame (they differ between frames){kind}"
        )
    }
}

/// RescaleSlope and RescaleIntercept of `obj` (1 and 0 if absent).
fn rescale(obj: &InMemDicomObject) -> Result<(f64, f64), String> {
    let slope = float(obj, RESCALE_SLOPE)?.unwrap_or(1.0);
    let intercept = float(obj, RESCALE_INTERCEPT)?.unwrap_or(0.0);
    Ok((slope, intercept))
}

fn orientation(obj: &InMemDicomObject) -> Result<Option<[DVec3; 2]>, String> {
    let Some(v) = fixed(obj, IOP, 6)? else {
        return Ok(None);
    };
    let row = DVec3::new(v[0], v[1], v[2]);
    let col = DVec3::new(v[3], v[4], v[5]);
    for (d, name) in [(row, "row"), (col, "column")] {
        if (d.length() - 1.0).abs() > 1e-3 {
            return Err(format!(
                "{IOP}: the {name} direction ({}, {}, {}) is not a unit vector",
                d.x, d.y, d.z
            ));
        }
    }
    if row.normalize().dot(col.normalize()).abs() > 1e-3 {
        return Err(format!(
            "{IOP}: the row and column directions are not perpendicular"
        ));
    }
    Ok(Some([row.normalize(), col.normalize()]))
}

fn pixel_spacing(obj: &InMemDicomObject) -> Result<Option<[f64; 2]>, String> {
    let v = match fixed(obj, PIXEL_SPACING, 2)? {
        Some(v) => v,
        None => match fixed(obj, IMAGER_PIXEL_SPACING, 2)? {
            Some(v) => v,
            None => return Ok(None),
        },
    };
    if v.iter().any(|&s| s <= 0.0) {
        return Err(format!(
            "{PIXEL_SPACING} {}\\{} is not positive",
            v[0], v[1]
        ));
    }
    Ok(Some([v[0], v[1]]))
}

/// The most digits after the decimal point in any of `attr`'s decimal
/// strings (PS3.5 6.2, DS); `None` if absent or written with an exponent.
fn decimals(obj: &InMemDicomObject, attr: Attr) -> Option<u32> {
    let text = obj.get(attr.0)?.to_str().ok()?;
    let mut most = None;
    for value in text.split('\\') {
        let value = value.trim_matches(['\0', ' ']);
        if value.is_empty() || value.contains(['e', 'E']) {
            return None;
        }
        let d = value.split_once('.').map_or(0, |(_, f)| f.len() as u32);
        most = most.max(Some(d));
    }
    most
}

fn vector(obj: &InMemDicomObject, attr: Attr) -> Result<Option<DVec3>, String> {
    Ok(fixed(obj, attr, 3)?.map(|v| DVec3::new(v[0], v[1], v[2])))
}

/// Exactly `n` finite numbers, if the attribute is present and not empty.
fn fixed(obj: &InMemDicomObject, attr: Attr, n: usize) -> Result<Option<Vec<f64>>, String> {
    let Some(v) = floats(obj, attr)? else {
        return Ok(None);
    };
    if v.len() != n {
        return Err(format!("{attr} has {} value(s), needs {n}", v.len()));
    }
    Ok(Some(v))
}

/// The numbers of an attribute, if present and not empty; all finite.
pub(super) fn floats(obj: &InMemDicomObject, attr: Attr) -> Result<Option<Vec<f64>>, String> {
    let Some(e) = obj.get(attr.0) else {
        return Ok(None);
    };
    if e.to_str()
        .is_ok_and(|s| s.trim_matches(['\0', ' ']).is_empty())
    {
        return Ok(None);
    }
    let v = e.to_multi_float64().map_err(|_| {
        let raw = e.to_str().map(|s| s.to_string()).unwrap_or_default();
        format!("{attr}: \"{}\" is not a list of numbers", shorten(&raw))
    })?;
    if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("{attr} holds {bad}"));
    }
    Ok(Some(v))
}

fn float(obj: &InMemDicomObject, attr: Attr) -> Result<Option<f64>, String> {
    match floats(obj, attr)? {
        None => Ok(None),
        Some(v) if v.len() == 1 => Ok(Some(v[0])),
        Some(v) => Err(format!("{attr} has {} values, needs 1", v.len())),
    }
}

fn uint(obj: &InMemDicomObject, attr: Attr) -> Result<Option<u32>, String> {
    let Some(e) = obj.get(attr.0) else {
        return Ok(None);
    };
    if e.to_str()
        .is_ok_and(|s| s.trim_matches(['\0', ' ']).is_empty())
    {
        return Ok(None);
    }
    e.to_int::<u32>().map(Some).map_err(|_| {
        let raw = e.to_str().map(|s| s.to_string()).unwrap_or_default();
        format!(
            "{attr}: \"{}\" is not a non-negative integer",
            shorten(&raw)
        )
    })
}

fn int(obj: &InMemDicomObject, tag: Tag) -> Option<i64> {
    obj.get(tag)?.to_int::<i64>().ok()
}

pub(super) fn text(obj: &InMemDicomObject, tag: Tag) -> Option<String> {
    let s = obj.get(tag)?.to_str().ok()?;
    let s = s.trim_matches(['\0', ' ']);
    (!s.is_empty()).then(|| s.to_string())
}

/// The top-level elements, in file order, as `FileInfo::header` shows them.
fn fields(obj: &DefaultDicomObject) -> Vec<(String, String)> {
    let mut out = vec![(
        "TransferSyntaxUID (0002,0010)".to_string(),
        obj.meta().transfer_syntax().to_string(),
    )];
    for e in obj.iter() {
        let tag = e.header().tag;
        let name = StandardDataDictionary
            .by_tag(tag)
            .map(|d| d.alias().to_string())
            .unwrap_or_else(|| "private".into());
        let value = if let Some(items) = e.items() {
            format!("sequence of {} item(s)", items.len())
        } else if matches!(
            e.vr().to_string(),
            "OB" | "OW" | "OF" | "OD" | "OL" | "OV" | "UN"
        ) {
            "binary".to_string()
        } else {
            e.to_str()
                .map(|s| shorten(s.trim_matches(['\0', ' '])))
                .unwrap_or_default()
        };
        out.push((format!("{name} ({:04X},{:04X})", tag.0, tag.1), value));
    }
    out
}

fn shorten(text: &str) -> String {
    if text.chars().count() <= MAX_HEADER_VALUE {
        return text.to_string();
    }
    let head: String = text.chars().take(MAX_HEADER_VALUE).collect();
    format!("{head}...")
}

/// Reads the whole of `path` into memory.
pub(super) fn read_all(path: &Path) -> Result<Vec<u8>, IoError> {
    let (mut file, len) = open_input(path)?;
    let len_usize = usize::try_from(len)
        .map_err(|_| IoError::invalid(path, format!("file of {len} bytes is too large")))?;
    let mut bytes = Vec::new();
    bytes.try_reserve_exact(len_usize).map_err(|_| {
        IoError::invalid(path, format!("cannot hold the {len}-byte file in memory"))
    })?;
    (&mut file)
        .take(len)
        .read_to_end(&mut bytes)
        .map_err(|e| IoError::os(path, "read", e))?;
    if bytes.len() as u64 != len {
        return Err(IoError::Truncated {
            path: path.to_path_buf(),
            read: bytes.len() as u64,
            expected: len,
        });
    }
    Ok(bytes)
}
