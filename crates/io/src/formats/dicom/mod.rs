//! DICOM volumes: a directory of single-slice files (CT, MR, ...), a
//! file-set with a DICOMDIR (a CD or DVD export), or one multi-frame file
//! (enhanced CT/MR, RT dose, a Segmentation read as labels: [`seg`]).
//!
//! A directory: with a `DICOMDIR`, the files its directory records list
//! ([`dicomdir`]); without, every file in it and its subfolders (bounded
//! depth and count, each folder once) that parses as DICOM and holds pixel
//! data (others are skipped and counted in a note). The files are grouped
//! by SeriesInstanceUID and listed in the order of (SeriesNumber,
//! SeriesInstanceUID); the series read is the one named by number or UID
//! (`ReadOptions::series`), else by `--frame N` (from 0), else the largest,
//! with a note naming the others ([`series`]). A `DICOMDIR` named as the
//! input reads its file-set. The slices are sorted
//! along their normal by ImagePositionPatient ([`stack`]); they must share
//! Rows, Columns, sample layout, orientation and PixelSpacing, and be
//! equally spaced: every gap within 1 % of the mean gap plus what rounding
//! the positions to the decimals they are written with can do (gaps of 1.1
//! and 1.2 mm from positions written to 0.1 mm are one 1.16 mm spacing);
//! such a stack is read at the mean gap with a note, and beyond the
//! tolerance it is refused naming the farthest gap ([`stack`] compares
//! this with ITK's rule). Slices without any position are ordered by
//! InstanceNumber and spaced by SpacingBetweenSlices or SliceThickness (or
//! 1 mm), with a note.
//!
//! A multi-frame file: frame positions come from the per-frame functional
//! groups (enhanced images), from GridFrameOffsetVector (RT dose), or from
//! SpacingBetweenSlices. Frames that repeat positions (a time series)
//! form several volumes: volume `v` is the `v`-th occurrence of each
//! position in frame order, picked with `--frame`. A file holding a single
//! slice is refused with a hint to pass its directory.
//!
//! Values: the stored bits (BitsStored, HighBit, PixelRepresentation) times
//! RescaleSlope plus RescaleIntercept (per frame where the functional
//! groups give them), or times DoseGridScaling for RT dose. World
//! coordinates are the DICOM patient coordinates (LPS: +x towards the
//! patient's left, +y posterior, +z head) in mm, mapped to the volume by
//! [`grid_to_volume`]: column index along the row direction,
//! row index along the column direction, slices along the normal.
//!
//! Compressed pixel data: JPEG (baseline, 8-bit extended, lossless and
//! SV1), JPEG-LS (lossless, near-lossless) and JPEG 2000 (lossless, lossy)
//! are decoded frame by frame in [`codecs`] (jpeg-decoder, volray's own
//! [`jpegls`], openjp2: all pure Rust), each frame's codestream header
//! checked against the image header first; RLE Lossless by
//! `dicom-pixeldata`. 12-bit DCT JPEG and other syntaxes (HTJ2K, MPEG,
//! JPEG XL) are refused with their name. Before anything
//! is parsed, every element length is checked against the file
//! ([`prescan`]), and before the volume is allocated every file's pixel
//! data is checked to be able to hold what its header declares.

mod codecs;
mod dicomdir;
mod header;
mod jpeg12;
mod jpegls;
mod pixels;
mod prescan;
mod seg;
mod series;
mod stack;

use std::path::{Path, PathBuf};

use volray_core::glam::DVec3;
use volray_core::{Sample, Samples};

use self::header::{FileHeader, HeaderError, ImageFormat, Plane, read_all, read_header};
use self::pixels::{decode, frame_values, kept_type, transfer_syntax_name};
use self::prescan::{Prescan, prescan};
use self::stack::{Stack, stack, volumes};
use crate::dtype::read_as_stored;
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::check_volume_size;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Encapsulated (compressed) pixel data may decode to at most this many
/// times the file's length (or [`SMALL_FILE_ALLOWANCE`]): RLE inflates at
/// most 64:1 and JPEG far less on real images, so a header declaring more
/// is lying.
const MAX_INFLATION: u64 = crate::shared::compress::MAX_DEFLATE_RATIO;
const SMALL_FILE_ALLOWANCE: u64 = 64 << 20;

/// Skipped file names listed in a note, at most.
const LISTED: usize = 5;

/// Reads the DICOM volume at `path`: a directory of slices or one
/// multi-frame file.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    if path.is_dir() {
        read_directory(path, None, opts)
    } else if is_dicomdir(path) {
        let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
        read_directory(
            dir.unwrap_or(Path::new(".")),
            Some(path.to_path_buf()),
            opts,
        )
    } else {
        let header = match read_header(path) {
            Ok(Some(h)) => h,
            Ok(None) => {
                return Err(IoError::invalid(
                    path,
                    "not a DICOM file: no DICM magic at byte 128",
                ));
            }
            Err(HeaderError::Io(e)) => return Err(e),
            Err(HeaderError::Bad(reason)) => {
                return Err(IoError::invalid(path, format!("DICOM: {reason}")));
            }
        };
        read_multiframe(path, header, opts.frame, opts.max_memory, FileInfo::new(""))
    }
}

/// Whether `path` is named as a DICOMDIR is (`DICOMDIR`, any case, or
/// an ISO 9660 `DICOMDIR;1`).
fn is_dicomdir(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.eq_ignore_ascii_case("DICOMDIR") || n.eq_ignore_ascii_case("DICOMDIR;1"))
}

/// Every file reading the DICOM directory `dir` might open (its
/// subfolders' files, or those its DICOMDIR lists): for the overwrite
/// check of the command line.
pub fn directory_files(dir: &Path) -> Vec<PathBuf> {
    series::files_read(dir)
}

/// The headers of the files a DICOMDIR lists for one series; a file that
/// is not DICOM or holds no pixel data is refused by name.
fn dicomdir_headers(files: &[PathBuf]) -> Result<Vec<FileHeader>, IoError> {
    let mut headers = Vec::with_capacity(files.len());
    for p in files {
        match read_header(p) {
            Ok(Some(h)) if h.pixel_data.is_some() => headers.push(h),
            Ok(Some(_)) => {
                return Err(IoError::invalid(
                    p,
                    "listed by the DICOMDIR as an image of the series, but holds no pixel data",
                ));
            }
            Ok(None) => {
                return Err(IoError::invalid(
                    p,
                    "listed by the DICOMDIR but not a DICOM file: no DICM magic at byte 128",
                ));
            }
            Err(HeaderError::Io(e)) => return Err(e),
            Err(HeaderError::Bad(reason)) => {
                return Err(IoError::invalid(p, format!("DICOM: {reason}")));
            }
        }
    }
    Ok(headers)
}

/// Reads the volume `volume` (default 0) of the multi-frame file whose
/// header is `header`. `info` may carry notes from a directory scan.
fn read_multiframe(
    path: &Path,
    header: FileHeader,
    volume: Option<usize>,
    max_memory: u64,
    mut info: FileInfo,
) -> Result<Loaded, IoError> {
    if header.sop_class == seg::SEGMENTATION {
        return seg::read(path, header, max_memory, info);
    }
    let format = header
        .format
        .clone()
        .map_err(|r| IoError::invalid(path, format!("DICOM: {r}")))?;
    check_pixel_data(&header, &format)?;
    if header.frames == 1 {
        return read_single_slice(path, header, format, max_memory, info);
    }
    let groups = volumes(&header.planes).map_err(|r| IoError::invalid(path, r))?;
    info.frames = groups.len();
    let v = pick(
        path,
        volume,
        groups.len(),
        "volume(s) (frames repeating the same positions)",
    )?;
    info.frame = v;
    if groups.len() > 1 {
        info.notes.push(format!(
            "volume {v} of {} read: frames {}",
            groups.len(),
            list(&groups[v], |f| f.to_string())
        ));
    }
    let frames = &groups[v];
    let planes: Vec<Plane> = frames.iter().map(|&f| header.planes[f].clone()).collect();
    let names = |i: usize| format!("frame {}", frames[i]);
    let grid = geometry(path, &planes, &names, &header, &mut info)?;

    // Every frame is held twice (the parsed element and the decoded
    // samples) beside the f32 volume: bound them all by the limit.
    let stored = format
        .float
        .map_or(format.sample_bytes(), |b| usize::from(b / 8));
    check_volume_size(
        path,
        "Rows x Columns x NumberOfFrames",
        &[
            format.rows as u64,
            format.columns as u64,
            header.frames as u64,
        ],
        2 * stored as u64 + kept_type(&format, &planes).bytes() as u64,
        max_memory,
    )?;
    let bytes = read_all(path)?;
    let obj = parse_whole(path, &bytes)?;
    drop(bytes);
    let decoded = decode(path, &obj, &format, header.frames)?;
    let data = read_as_stored!(kept_type(&format, &planes), |T| {
        allocate::<T>(path, &format, grid.order.len(), max_memory).map(|mut data| {
            for &k in &grid.order {
                frame_values(&decoded, frames[k], &format, &planes[k], &mut data);
            }
            data
        })
    })?;
    finish(path, &header, &format, grid, data, info)
}

/// A file of one slice: read, and refused as a volume with what it holds
/// ([`IoError::FlatImage`]), naming the directory to pass instead.
fn read_single_slice(
    path: &Path,
    header: FileHeader,
    format: ImageFormat,
    max_memory: u64,
    info: FileInfo,
) -> Result<Loaded, IoError> {
    let plane = header.planes[0].clone();
    let [row_step, column_step] = plane.pixel_spacing.unwrap_or([1.0, 1.0]);
    let [along_row, along_column] = plane.orientation.unwrap_or([DVec3::X, DVec3::Y]);
    let grid = Stack {
        order: vec![0],
        steps: [
            along_row * column_step,
            along_column * row_step,
            along_row.cross(along_column),
        ],
        origin: plane.position.unwrap_or(DVec3::ZERO),
        notes: Vec::new(),
    };
    let mut data: Vec<f32> = allocate(path, &format, 1, max_memory)?;
    let bytes = read_all(path)?;
    let obj = parse_whole(path, &bytes)?;
    drop(bytes);
    let decoded = decode(path, &obj, &format, 1)?;
    frame_values(&decoded, 0, &format, &plane, &mut data);
    let data = Samples::from(data);
    match finish(path, &header, &format, grid, data, info) {
        Err(IoError::FlatImage { path, mut image }) => {
            let dir = path
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .map(|p| p.display().to_string())
                .unwrap_or_else(|| ".".into());
            image.reason = format!(
                "a single DICOM slice ({} x {}), not a volume: pass the directory of the series ({dir}) to read a volume",
                format.columns, format.rows
            );
            Err(IoError::FlatImage { path, image })
        }
        other => other,
    }
}

/// Reads the series in directory `dir` (see the module documentation and
/// [`series`]); `dicomdir` is its DICOMDIR when named as the input.
fn read_directory(
    dir: &Path,
    dicomdir: Option<PathBuf>,
    opts: &ReadOptions,
) -> Result<Loaded, IoError> {
    let dicomdir = dicomdir.or_else(|| series::dicomdir_in(dir));
    let listing = series::list_series(dir, dicomdir)?;
    let skipped = listing.skipped.clone();
    // Errors about the series carry what was skipped: a skipped file may
    // be the reason.
    let with_skips = |reason: String| match &skipped {
        Some(s) => IoError::invalid(dir, format!("{reason} ({s})")),
        None => IoError::invalid(dir, reason),
    };
    if listing.series.is_empty() {
        return Err(with_skips(
            "no DICOM image files in this directory or its subfolders".into(),
        ));
    }
    let count = listing.series.len();
    let (s, note) = series::choose(dir, &listing.series, opts)?;
    let found = listing.series.into_iter().nth(s).expect("chosen in range");
    let mut files = if found.headers.len() == found.files.len() {
        found.headers
    } else {
        dicomdir_headers(&found.files)?
    };
    let mut info = FileInfo::new("");
    info.frames = count;
    info.frame = s;
    info.frames_are_series = count > 1;
    if let Some(d) = &listing.dicomdir {
        info.notes.push(format!(
            "read through {} ({count} series listed)",
            d.display()
        ));
    }
    if let Some(note) = skipped.clone() {
        info.notes.push(note);
    }
    if let Some(note) = note {
        info.notes.push(note);
    }

    if files
        .iter()
        .any(|h| h.frames > 1 || h.sop_class == seg::SEGMENTATION)
    {
        if files.len() == 1 {
            let header = files.pop().expect("one file");
            let path = header.path.clone();
            let volume = if count == 1 { opts.frame } else { None };

            let mut loaded =
                read_multiframe(&path, header, volume, opts.max_memory, FileInfo::new(""))?;
            if count > 1 {
                loaded.info.notes.extend(info.notes);
            } else {
                loaded.info.notes.splice(0..0, info.notes);
            }
            return Ok(loaded);
        }
        return Err(with_skips(format!(
            "series {} mixes multi-frame files with others: pass one multi-frame file instead of the directory",
            files[0].series_uid
        )));
    }

    let first = &files[0];
    let format = first
        .format
        .clone()
        .map_err(|r| IoError::invalid(&first.path, format!("DICOM: {r}")))?;
    for h in &files {
        let f = h
            .format
            .as_ref()
            .map_err(|r| IoError::invalid(&h.path, format!("DICOM: {r}")))?;
        if *f != format {
            return Err(IoError::invalid(
                dir,
                format!(
                    "{} is {}x{} {} ({}) but {} is {}x{} {} ({}): every slice of a series must have the same size and sample layout",
                    file_name(&h.path),
                    f.columns,
                    f.rows,
                    f.describe(),
                    f.photometric,
                    file_name(&first.path),
                    format.columns,
                    format.rows,
                    format.describe(),
                    format.photometric
                ),
            ));
        }
        check_pixel_data(h, f)?;
    }
    if files.len() < 2 {
        return Err(with_skips(format!(
            "series {} has 1 slice ({}): a volume needs at least 2",
            files[0].series_uid,
            file_name(&files[0].path)
        )));
    }
    if files.iter().all(|h| h.planes[0].position.is_none()) {
        // Without positions, InstanceNumber orders the slices (stable: by
        // file name among equal numbers).
        files.sort_by_key(|h| h.instance_number.unwrap_or(i64::MAX));
    }
    let planes: Vec<Plane> = files.iter().map(|h| h.planes[0].clone()).collect();
    let names = |i: usize| file_name(&files[i].path);
    let grid =
        geometry(dir, &planes, &names, &files[0], &mut info).map_err(|e| match (e, &skipped) {
            (IoError::Invalid { path, reason }, Some(s)) => {
                IoError::invalid(&path, format!("{reason} ({s})"))
            }
            (e, _) => e,
        })?;

    let data = read_as_stored!(kept_type(&format, &planes), |T| {
        let mut data = allocate::<T>(dir, &format, files.len(), opts.max_memory)?;
        for &k in &grid.order {
            let h = &files[k];
            let bytes = read_all(&h.path)?;
            let obj = parse_whole(&h.path, &bytes)?;
            drop(bytes);
            let decoded = decode(&h.path, &obj, &format, 1)?;
            frame_values(&decoded, 0, &format, &planes[k], &mut data);
        }
        Ok::<_, IoError>(data)
    })?;
    let header = &files[grid.order[0]];
    finish(dir, header, &format, grid, data, info)
}

/// The stack's grid: from the positions if the planes have them, else in
/// the given order with SpacingBetweenSlices, SliceThickness or 1 mm.
fn geometry(
    path: &Path,
    planes: &[Plane],
    names: &dyn Fn(usize) -> String,
    first: &FileHeader,
    info: &mut FileInfo,
) -> Result<Stack, IoError> {
    if let Some(note) = &first.geometry_note {
        info.notes.push(note.clone());
    }
    if planes.iter().any(|p| p.position.is_some()) {
        let grid = stack(planes, names).map_err(|r| IoError::invalid(path, r))?;
        info.notes.extend(grid.notes.iter().cloned());
        return Ok(grid);
    }
    let ps = planes[0].pixel_spacing.unwrap_or([1.0, 1.0]);
    let (gap, source) = match (first.slice_spacing, first.slice_thickness) {
        (Some(s), _) if s > 0.0 => (s, "SpacingBetweenSlices"),
        (_, Some(t)) if t > 0.0 => (t, "SliceThickness"),
        _ => (1.0, "a default"),
    };
    info.notes.push(format!(
        "no ImagePositionPatient: slices in InstanceNumber (or frame) order, {gap} mm apart from {source}, on world axes from the origin"
    ));
    Ok(Stack {
        order: (0..planes.len()).collect(),
        steps: [DVec3::X * ps[1], DVec3::Y * ps[0], DVec3::Z * gap],
        origin: DVec3::ZERO,
        notes: Vec::new(),
    })
}

/// Builds the volume and fills in the rest of `info`.
fn finish(
    path: &Path,
    header: &FileHeader,
    format: &ImageFormat,
    grid: Stack,
    data: Samples,
    mut info: FileInfo,
) -> Result<Loaded, IoError> {
    info.stored_type = format!(
        "{} ({})",
        format.describe(),
        transfer_syntax_name(&header.transfer_syntax)
    );
    info.header = header.fields.clone();
    if let Some(note) = &header.scaling_note {
        info.notes.push(note.clone());
    }
    if header.planes.iter().any(|p| p.pixel_spacing.is_none()) {
        info.notes
            .push("no PixelSpacing: 1 mm between rows and between columns assumed".into());
    }
    if format.photometric == "MONOCHROME1" {
        info.notes.push(
            "PhotometricInterpretation MONOCHROME1 (low values display white): values kept as stored, not inverted".into(),
        );
    }
    info.notes.push(
        "world coordinates are DICOM patient coordinates (LPS: +x to the patient's left, +y posterior, +z head), in mm".into(),
    );
    info.length_unit = Some("mm".into());
    // Modality (0008,0060): `CT` picks a CT's default look (volray-app).
    let modality = header.modality.trim();
    info.modality = (!modality.is_empty()).then(|| modality.to_string());
    let dims = [format.columns, format.rows, grid.order.len()];
    let volume = grid_to_volume(path, dims, data, grid.steps, grid.origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Dicom,
        info,
    })
}

/// Checks that `header`'s pixel data can hold what it declares, before
/// anything is allocated for it: native data by its length, compressed
/// data by a bound on its compression ratio.
fn check_pixel_data(header: &FileHeader, format: &ImageFormat) -> Result<(), IoError> {
    let path = &header.path;
    let sample_bytes = match format.float {
        Some(bits) => usize::from(bits / 8),
        None => format.sample_bytes(),
    };
    let need = format
        .rows
        .checked_mul(format.columns)
        .and_then(|n| n.checked_mul(header.frames))
        .and_then(|n| n.checked_mul(sample_bytes))
        .ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "Rows {} x Columns {} x {} frame(s) is too large to address",
                    format.rows, format.columns, header.frames
                ),
            )
        })?;
    let Some(pixel_data) = header.pixel_data else {
        return Err(IoError::invalid(path, "DICOM file has no pixel data"));
    };
    let element = format!("(7FE0,{:04X})", pixel_data.element);
    match pixel_data.length {
        Some(len) if (len as usize) < need => Err(IoError::invalid(
            path,
            format!(
                "pixel data {element} holds {len} bytes, but Rows {} x Columns {} x {} frame(s) x {} byte(s) need {need}",
                format.rows, format.columns, header.frames, sample_bytes
            ),
        )),
        Some(_) => Ok(()),
        None => {
            let budget = header
                .file_len
                .saturating_mul(MAX_INFLATION)
                .max(SMALL_FILE_ALLOWANCE);
            if need as u64 > budget {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "compressed pixel data would decode to {need} bytes (Rows {} x Columns {} x {} frame(s)), more than a {}-byte file can hold",
                        format.rows, format.columns, header.frames, header.file_len
                    ),
                ));
            }
            Ok(())
        }
    }
}

/// The output buffer for `slices` slices of `format` as `T`, refused if it
/// would take more than `max_memory`.
fn allocate<T: Sample>(
    path: &Path,
    format: &ImageFormat,
    slices: usize,
    max_memory: u64,
) -> Result<Vec<T>, IoError> {
    let n = check_volume_size(
        path,
        "Columns x Rows x slices",
        &[format.columns as u64, format.rows as u64, slices as u64],
        T::TYPE.bytes() as u64,
        max_memory,
    )?;
    let mut data = Vec::new();
    data.try_reserve_exact(n).map_err(|_| {
        IoError::invalid(
            path,
            format!(
                "cannot allocate {}x{}x{slices} voxels",
                format.columns, format.rows
            ),
        )
    })?;
    Ok(data)
}

/// Parses the whole file `bytes` after checking every element length.
fn parse_whole(path: &Path, bytes: &[u8]) -> Result<dicom_object::DefaultDicomObject, IoError> {
    match prescan(bytes, true, false) {
        Ok(Prescan::Done(_)) => {}
        Ok(Prescan::NeedMore) => {
            return Err(IoError::invalid(path, "DICOM: file ends inside an element"));
        }
        Err(reason) => return Err(IoError::invalid(path, format!("DICOM: {reason}"))),
    }
    header::parse(bytes, false).map_err(|r| IoError::invalid(path, format!("DICOM: {r}")))
}

/// Checks the frame asked for ([`ReadOptions::frame`]) against `count`
/// choices of `what`.
fn pick(path: &Path, frame: Option<usize>, count: usize, what: &str) -> Result<usize, IoError> {
    let n = frame.unwrap_or(0);
    if n >= count {
        return Err(IoError::frame_out_of_range(
            path,
            n,
            format!("there are {count} {what}, numbered from 0"),
        ));
    }
    Ok(n)
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Up to [`LISTED`] items, then how many more.
fn list<T>(items: &[T], show: impl Fn(&T) -> String) -> String {
    let shown: Vec<String> = items.iter().take(LISTED).map(show).collect();
    let more = items.len().saturating_sub(LISTED);
    if more > 0 {
        format!("{}, and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}
