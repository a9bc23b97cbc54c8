//! The series of a DICOM directory, and which one is read.
//!
//! A directory with a `DICOMDIR` (a CD or DVD as scanners export them, an
//! archive folder) is read through its directory records ([`dicomdir`]):
//! the files each SERIES record lists, their ReferencedFileIDs resolved
//! against the DICOMDIR's folder whatever the case of the names on disk
//! (ISO 9660 writes them upper case, a mounted disc may show them lower
//! case, with or without a `;1` version). Any other directory is searched
//! with its subfolders, at most [`MAX_DEPTH`] levels deep and
//! [`MAX_ENTRIES`] entries in all, each folder once (so a symbolic link
//! that loops back is not followed twice), and its files are grouped by
//! SeriesInstanceUID.
//!
//! Series are listed in the order of (SeriesNumber, SeriesInstanceUID)
//! and numbered from 1. The one read is the one named
//! ([`ReadOptions::series`]: its number in that list or its UID), else
//! the one `--frame` names (counted from 0, as before series could be
//! named), else the largest (the most voxels), with a note naming the
//! others and how to pick one.
//!
//! [`dicomdir`]: super::dicomdir

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fs;
use std::path::{Path, PathBuf};

use super::dicomdir::{self, DirSeries};
use super::header::{FileHeader, HeaderError, read_all, read_header};
use super::{file_name, list};
use crate::ReadOptions;
use crate::error::IoError;

/// Entries (files and folders) a directory search visits, at most: a
/// DVD holds some 10⁴ to 10⁵ files.
pub(super) const MAX_ENTRIES: usize = 100_000;

/// Folder levels below the one named that a search enters, at most
/// (discs nest 2 to 4: `DICOM/PAT1/STUDY1/SER1/IM1`).
pub(super) const MAX_DEPTH: usize = 8;

/// A DICOMDIR larger than this is refused before it is read.
const MAX_DICOMDIR_BYTES: u64 = 1 << 30;

/// One series found in a directory.
#[derive(Debug, Clone)]
pub(super) struct Found {
    pub uid: String,
    pub number: Option<i64>,
    pub modality: String,
    pub description: String,
    pub files: Vec<PathBuf>,
    /// The files' headers, where read (every file of a searched folder;
    /// the first file only of a DICOMDIR's series).
    pub headers: Vec<FileHeader>,
}

impl Found {
    /// Voxels of the series, from its headers: files × frames × rows ×
    /// columns (the first header's, for a DICOMDIR's series).
    fn voxels(&self) -> u64 {
        let per_file = |h: &FileHeader| {
            h.format.as_ref().map_or(0, |f| {
                (f.rows as u64)
                    .saturating_mul(f.columns as u64)
                    .saturating_mul(h.frames as u64)
            })
        };
        if self.headers.len() == self.files.len() {
            self.headers.iter().map(per_file).sum()
        } else {
            self.headers
                .first()
                .map_or(0, |h| per_file(h).saturating_mul(self.files.len() as u64))
        }
    }

    /// `"2: SeriesNumber 3, CT \"chest\", 120 file(s), 512 x 512, UID ..."`.
    pub fn describe(&self, number: usize) -> String {
        let n = self
            .number
            .map(|n| format!("SeriesNumber {n}, "))
            .unwrap_or_default();
        let modality = if self.modality.is_empty() {
            "?"
        } else {
            &self.modality
        };
        let description = if self.description.is_empty() {
            String::new()
        } else {
            format!(" \"{}\"", self.description)
        };
        let dims = self
            .headers
            .first()
            .and_then(|h| h.format.as_ref().ok())
            .map(|f| format!(", {} x {}", f.columns, f.rows))
            .unwrap_or_default();
        format!(
            "{number}: {n}{modality}{description}, {} file(s){dims}, UID {}",
            self.files.len(),
            self.uid
        )
    }
}

/// What a directory holds: its series and what was skipped.
pub(super) struct Listing {
    pub series: Vec<Found>,
    /// What was not read, for a note and for errors (`skipped ...`).
    pub skipped: Option<String>,
    /// The DICOMDIR the series came from, if any.
    pub dicomdir: Option<PathBuf>,
}

/// The DICOMDIR of `dir`, if it has one (any case).
pub(super) fn dicomdir_in(dir: &Path) -> Option<PathBuf> {
    let exact = dir.join("DICOMDIR");
    if exact.is_file() {
        return Some(exact);
    }
    fs::read_dir(dir).ok()?.flatten().find_map(|e| {
        let name = e.file_name();
        let name = name.to_str()?;
        (name.eq_ignore_ascii_case("DICOMDIR") || name.eq_ignore_ascii_case("DICOMDIR;1"))
            .then(|| e.path())
            .filter(|p| p.is_file())
    })
}

/// Lists the series of `dir`: through `dicomdir` (its DICOMDIR) if
/// given, else by searching it.
pub(super) fn list_series(dir: &Path, dicomdir: Option<PathBuf>) -> Result<Listing, IoError> {
    match dicomdir {
        Some(d) => from_dicomdir(&d),
        None => search(dir),
    }
}

/// Every file reading `dir` might open: its DICOMDIR and the files it
/// lists, or the files a search finds (volray's overwrite check).
pub fn files_read(dir: &Path) -> Vec<PathBuf> {
    if let Some(d) = dicomdir_in(dir) {
        let mut files = vec![d.clone()];
        if let Ok(listing) = from_dicomdir_files(&d) {
            files.extend(listing.into_iter().flat_map(|s| s.files));
        }
        return files;
    }
    let mut files = Vec::new();
    let _ = walk(dir, &mut |p| {
        files.push(p.to_path_buf());
        Ok(())
    });
    files
}

/// The series of the DICOMDIR `path`, their files resolved on disk but
/// no header read.
fn from_dicomdir_files(path: &Path) -> Result<Vec<Found>, IoError> {
    let len = fs::metadata(path)
        .map_err(|e| IoError::os(path, "read", e))?
        .len();
    if len > MAX_DICOMDIR_BYTES {
        return Err(IoError::invalid(
            path,
            format!("DICOMDIR of {len} bytes: more than volray reads ({MAX_DICOMDIR_BYTES})"),
        ));
    }
    let bytes = read_all(path)?;
    let records =
        dicomdir::series(&bytes).map_err(|r| IoError::invalid(path, format!("DICOMDIR: {r}")))?;
    let root = path.parent().unwrap_or(Path::new("."));
    let mut names = Names::default();
    let mut found = Vec::new();
    for s in records {
        let DirSeries {
            uid,
            number,
            modality,
            description,
            files,
            offset,
        } = s;
        let mut paths = Vec::with_capacity(files.len());
        for id in &files {
            paths.push(names.resolve(path, root, id, offset)?);
        }
        found.push(Found {
            uid,
            number,
            modality,
            description,
            files: paths,
            headers: Vec::new(),
        });
    }
    Ok(found)
}

/// The series of the DICOMDIR `path`, each with its first file's header.
fn from_dicomdir(path: &Path) -> Result<Listing, IoError> {
    let mut series = from_dicomdir_files(path)?;
    for s in &mut series {
        let first = &s.files[0];
        match read_header(first) {
            Ok(Some(h)) => {
                // A SERIES record need hold no description (PS3.3 F.5.3).
                if s.description.is_empty() {
                    s.description = h.series_description.clone();
                }
                if s.modality.is_empty() {
                    s.modality = h.modality.clone();
                }
                s.headers.push(h)
            }
            Ok(None) => {
                return Err(IoError::invalid(
                    first,
                    "listed by the DICOMDIR but not a DICOM file: no DICM magic at byte 128",
                ));
            }
            Err(HeaderError::Io(e)) => return Err(e),
            Err(HeaderError::Bad(reason)) => {
                return Err(IoError::invalid(first, format!("DICOM: {reason}")));
            }
        }
    }
    if series.is_empty() {
        return Err(IoError::invalid(
            path,
            "DICOMDIR lists no series with image files",
        ));
    }
    sort(&mut series);
    Ok(Listing {
        series,
        skipped: None,
        dicomdir: Some(path.to_path_buf()),
    })
}

/// The files on disk of ReferencedFileIDs, matched whatever their case.
#[derive(Default)]
struct Names {
    /// Each folder's entries by upper-case name (`;1` versions dropped).
    folders: HashMap<PathBuf, HashMap<String, PathBuf>>,
}

impl Names {
    /// The file `components` names below `root` (the DICOMDIR `dicomdir`'s
    /// folder; the record at byte `offset` for messages).
    fn resolve(
        &mut self,
        dicomdir: &Path,
        root: &Path,
        components: &[String],
        offset: u32,
    ) -> Result<PathBuf, IoError> {
        let shown = components.join("\\");
        if components
            .iter()
            .any(|c| c.is_empty() || c == "." || c == ".." || c.contains(['/', '\0']))
        {
            return Err(IoError::invalid(
                dicomdir,
                format!(
                    "DICOMDIR: the series record at byte {offset} lists file {shown:?}, which is not a path inside the file-set"
                ),
            ));
        }
        let mut at = root.to_path_buf();
        for c in components {
            let exact = at.join(c);
            if exact.exists() {
                at = exact;
                continue;
            }
            let entries = self.folders.entry(at.clone()).or_insert_with(|| {
                let mut by_name = HashMap::new();
                for e in fs::read_dir(&at).into_iter().flatten().flatten() {
                    let name = e.file_name().to_string_lossy().to_ascii_uppercase();
                    let name = name.strip_suffix(";1").unwrap_or(&name).to_string();
                    by_name.entry(name).or_insert(e.path());
                }
                by_name
            });
            match entries.get(&c.to_ascii_uppercase()) {
                Some(p) => at = p.clone(),
                None => {
                    return Err(IoError::invalid(
                        dicomdir,
                        format!(
                            "DICOMDIR lists file {shown} (series record at byte {offset}), which is missing: {} does not exist",
                            exact.display()
                        ),
                    ));
                }
            }
        }
        Ok(at)
    }
}

/// Visits every file under `dir` (see the module documentation).
fn walk(
    dir: &Path,
    visit: &mut dyn FnMut(&Path) -> Result<(), IoError>,
) -> Result<Walked, IoError> {
    let mut walked = Walked::default();
    let mut seen = HashSet::new();
    let mut folders = vec![(dir.to_path_buf(), 0)];
    while let Some((folder, depth)) = folders.pop() {
        let key = fs::canonicalize(&folder).unwrap_or_else(|_| folder.clone());
        if !seen.insert(key) {
            walked.loops += 1;
            continue;
        }
        let listing =
            fs::read_dir(&folder).map_err(|e| IoError::os(&folder, "read directory", e))?;
        let mut entries = Vec::new();
        for entry in listing {
            let entry = entry.map_err(|e| IoError::os(&folder, "read directory", e))?;
            walked.entries += 1;
            if walked.entries > MAX_ENTRIES {
                return Err(IoError::invalid(
                    dir,
                    format!(
                        "directory holds more than {MAX_ENTRIES} entries (subfolders included): too many to search for DICOM series; pass the folder of one series"
                    ),
                ));
            }
            entries.push(entry.path());
        }
        entries.sort();
        let mut below = Vec::new();
        for p in entries {
            if p.is_dir() {
                if depth < MAX_DEPTH {
                    below.push((p, depth + 1));
                } else {
                    walked.too_deep += 1;
                }
            } else {
                visit(&p)?;
            }
        }
        // Depth first, in name order.
        folders.extend(below.into_iter().rev());
    }
    Ok(walked)
}

/// What a search passed by.
#[derive(Debug, Default)]
struct Walked {
    entries: usize,
    too_deep: usize,
    loops: usize,
}

/// Searches `dir` and its subfolders for DICOM images, grouped by series.
fn search(dir: &Path) -> Result<Listing, IoError> {
    let mut images: Vec<FileHeader> = Vec::new();
    let mut not_dicom = Vec::new();
    let mut unreadable = Vec::new();
    let mut no_pixels = Vec::new();
    let name = |p: &Path| {
        p.strip_prefix(dir)
            .map(|r| r.display().to_string())
            .unwrap_or_else(|_| file_name(p))
    };
    let walked = walk(dir, &mut |p| {
        match read_header(p) {
            Ok(None) => not_dicom.push(name(p)),
            Ok(Some(h)) if h.pixel_data.is_none() => no_pixels.push(name(p)),
            Ok(Some(h)) => images.push(h),
            Err(HeaderError::Bad(reason)) => unreadable.push(format!("{}: {reason}", name(p))),
            Err(HeaderError::Io(e)) => return Err(e),
        }
        Ok(())
    })?;
    let mut skipped = Vec::new();
    if !not_dicom.is_empty() {
        skipped.push(format!(
            "{} file(s) not DICOM ({})",
            not_dicom.len(),
            list(&not_dicom, |s| s.clone())
        ));
    }
    if !no_pixels.is_empty() {
        skipped.push(format!(
            "{} DICOM file(s) without pixel data ({})",
            no_pixels.len(),
            list(&no_pixels, |s| s.clone())
        ));
    }
    if !unreadable.is_empty() {
        skipped.push(format!(
            "{} unreadable DICOM file(s) ({})",
            unreadable.len(),
            list(&unreadable, |s| s.clone())
        ));
    }
    if walked.too_deep > 0 {
        skipped.push(format!(
            "{} folder(s) more than {MAX_DEPTH} levels down not searched",
            walked.too_deep
        ));
    }
    if walked.loops > 0 {
        skipped.push(format!(
            "{} folder(s) reached a second time through a link",
            walked.loops
        ));
    }
    let skipped = (!skipped.is_empty()).then(|| format!("skipped {}", skipped.join("; ")));
    let mut by_uid: BTreeMap<String, Vec<FileHeader>> = BTreeMap::new();
    for h in images {
        by_uid.entry(h.series_uid.clone()).or_default().push(h);
    }
    let mut series: Vec<Found> = by_uid
        .into_values()
        .map(|headers| {
            let h = &headers[0];
            Found {
                uid: h.series_uid.clone(),
                number: h.series_number,
                modality: h.modality.clone(),
                description: h.series_description.clone(),
                files: headers.iter().map(|h| h.path.clone()).collect(),
                headers,
            }
        })
        .collect();
    sort(&mut series);
    Ok(Listing {
        series,
        skipped,
        dicomdir: None,
    })
}

/// Orders series by (SeriesNumber, UID), unnumbered last.
fn sort(series: &mut [Found]) {
    series.sort_by(|a, b| {
        (a.number.unwrap_or(i64::MAX), &a.uid).cmp(&(b.number.unwrap_or(i64::MAX), &b.uid))
    });
}

/// Which series of `series` (at least one) to read, counted from 0, and
/// the note that says so when there are several.
pub(super) fn choose(
    dir: &Path,
    series: &[Found],
    opts: &ReadOptions,
) -> Result<(usize, Option<String>), IoError> {
    let count = series.len();
    let listed = || {
        series
            .iter()
            .enumerate()
            .map(|(i, s)| s.describe(i + 1))
            .collect::<Vec<_>>()
            .join("; ")
    };
    if let Some(named) = &opts.series {
        let by_number = named
            .parse::<usize>()
            .ok()
            .filter(|n| (1..=count).contains(n));
        let picked = by_number
            .map(|n| n - 1)
            .or_else(|| series.iter().position(|s| s.uid == named.trim()));
        return match picked {
            Some(i) => {
                let note = (count > 1).then(|| {
                    format!(
                        "series {} of {count} read, as named: {}",
                        i + 1,
                        series[i].describe(i + 1)
                    )
                });
                Ok((i, note))
            }
            None => Err(IoError::invalid(
                dir,
                format!(
                    "no series {named:?}: name one by its number (1 to {count}) or its UID: {}",
                    listed()
                ),
            )),
        };
    }
    if count == 1 {
        return Ok((0, None));
    }
    if let Some(n) = opts.frame {
        if n >= count {
            return Err(IoError::frame_out_of_range(
                dir,
                n,
                format!("there are {count} series, numbered from 0"),
            ));
        }
        return Ok((
            n,
            Some(format!(
                "series {} of {count} read (frame {n}): {}",
                n + 1,
                series[n].describe(n + 1)
            )),
        ));
    }
    // The largest image series (a segmentation, whose frames repeat
    // each slice once per segment, only where there is nothing else);
    // the first of equals.
    let key = |s: &Found| {
        let seg = (s.headers.first()).is_some_and(|h| h.sop_class == super::seg::SEGMENTATION);
        (!seg, s.voxels())
    };
    let mut best = 0;
    for (i, s) in series.iter().enumerate() {
        if key(s) > key(&series[best]) {
            best = i;
        }
    }
    let others: Vec<String> = (series.iter().enumerate())
        .filter(|(i, _)| *i != best)
        .map(|(i, s)| s.describe(i + 1))
        .collect();
    Ok((
        best,
        Some(format!(
            "{count} series; read the largest, {}; the others: {}; pick one by its number or UID (--series N|UID; Python: series=)",
            series[best].describe(best + 1),
            others.join("; ")
        )),
    ))
}
