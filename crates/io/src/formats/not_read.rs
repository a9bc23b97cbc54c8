//! Formats volray recognises but does not read: each is named in an
//! [`IoError::NotRead`] with a hint saying which tool converts it to one
//! volray reads, instead of an "unknown volume format" (or, for a
//! directory, of being taken for a DICOM series).
//!
//! Recognised by content, and by name where the data file has no magic
//! (a `.REC` or `.BRIK` beside its header):
//!
//! | format        | recognised by |
//! |---------------|---------------|
//! | Philips PAR/REC | a `.PAR` whose text holds `DATA DESCRIPTION FILE` (the export tool's first line, `# === DATA DESCRIPTION FILE ===`), or a `.REC` beside such a `.PAR` |
//! | ECAT 7        | `MATRIX7` at byte 0 (`MATRIX72v`, `MATRIX71`, ...: the main header's magic number, ECAT 7 file format) |
//! | AFNI BRIK/HEAD | a `.HEAD` whose text holds `type = ...-attribute` and `name = BRICK_TYPES` or `DATASET_RANK` (AFNI's attribute format, README.attributes), or a `.BRIK`/`.BRIK.gz` beside such a `.HEAD` |
//! | OpenVDB       | bytes `20 42 44 56` (" BDV") at byte 0: `OPENVDB_MAGIC` 0x56444220 written as a little-endian int64 by `io::File` |
//! | N5            | a directory whose `attributes.json` has an `"n5"` version, or `dimensions`, `blockSize` and `dataType` (the N5 specification) |
//!
//! ECAT 6 has no magic number (its main header starts with a file name),
//! so it is not recognised: it stays an unknown format.

use std::path::{Path, PathBuf};

use crate::error::IoError;

/// A recognised format volray does not read, and how to convert it.
struct NotRead {
    format: &'static str,
    hint: &'static str,
}

const PAR_REC: NotRead = NotRead {
    format: "Philips PAR/REC",
    hint: "convert it to NIfTI with nibabel's parrec2nii or dcm2niix, and read the .nii",
};
const ECAT7: NotRead = NotRead {
    format: "ECAT 7",
    hint: "convert it to NIfTI with nibabel (nibabel.save(nibabel.load(\"file.v\"), \"file.nii\")), and read the .nii",
};
const AFNI: NotRead = NotRead {
    format: "AFNI BRIK/HEAD",
    hint: "convert it to NIfTI with AFNI's 3dAFNItoNIFTI (or nibabel), and read the .nii",
};
const OPENVDB: NotRead = NotRead {
    format: "OpenVDB",
    hint: "copy the grid to a dense array (OpenVDB's Python module: grid.copyToArray) and save it as .npy, NRRD or VTK",
};
const N5: NotRead = NotRead {
    format: "N5",
    hint: "convert it to Zarr (e.g. zarr-python 2's N5Store copied into a Zarr store, or BigDataViewer/n5-utils), and read the .zarr",
};

impl NotRead {
    fn error(&self, path: &Path) -> IoError {
        IoError::NotRead {
            path: path.to_path_buf(),
            format: self.format,
            hint: self.hint,
        }
    }
}

/// The lower-case extension of `path` (`brik.gz` for `x.BRIK.gz`).
fn extension(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if let Some(stem) = name.strip_suffix(".gz") {
        return Path::new(stem)
            .extension()
            .map(|e| format!("{}.gz", e.to_string_lossy()))
            .unwrap_or_default();
    }
    Path::new(&name)
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The first 1024 bytes of `path`, or nothing if it cannot be read.
fn head_of(path: &Path) -> Vec<u8> {
    use std::io::Read;
    let mut head = Vec::with_capacity(1024);
    if let Ok(f) = std::fs::File::open(path) {
        let _ = f.take(1024).read_to_end(&mut head);
    }
    head
}

fn is_par_text(head: &[u8]) -> bool {
    contains(head, b"DATA DESCRIPTION FILE")
}

fn is_afni_head(head: &[u8]) -> bool {
    contains(head, b"-attribute")
        && contains(head, b"type = ")
        && (contains(head, b"name = BRICK_TYPES")
            || contains(head, b"name = DATASET_RANK")
            || contains(head, b"name = DATASET_DIMENSIONS")
            || contains(head, b"name = TYPESTRING"))
}

fn contains(head: &[u8], needle: &[u8]) -> bool {
    head.windows(needle.len()).any(|w| w == needle)
}

/// The sibling of `path` with extension `ext` in either case, if it exists.
fn sibling(path: &Path, strip: usize, ext: &str) -> Option<PathBuf> {
    let name = path.file_name()?.to_string_lossy().into_owned();
    let stem = name.get(..name.len().checked_sub(strip)?)?;
    [ext.to_ascii_uppercase(), ext.to_ascii_lowercase()]
        .iter()
        .map(|e| path.with_file_name(format!("{stem}{e}")))
        .find(|p| p.is_file())
}

/// The refusal of the file at `path` (whose first bytes are `head`), if
/// it is one of the formats above.
pub(crate) fn refuse_file(path: &Path, head: &[u8]) -> Option<IoError> {
    if head.starts_with(b"MATRIX7") {
        return Some(ECAT7.error(path));
    }
    if head.starts_with(b" BDV") {
        return Some(OPENVDB.error(path));
    }
    if is_par_text(head) {
        return Some(PAR_REC.error(path));
    }
    if is_afni_head(head) {
        return Some(AFNI.error(path));
    }
    match extension(path).as_str() {
        "rec" => sibling(path, 4, ".par")
            .filter(|par| is_par_text(&head_of(par)))
            .map(|_| PAR_REC.error(path)),
        "brik" => sibling(path, 5, ".head")
            .filter(|h| is_afni_head(&head_of(h)))
            .map(|_| AFNI.error(path)),
        "brik.gz" => sibling(path, 8, ".head")
            .filter(|h| is_afni_head(&head_of(h)))
            .map(|_| AFNI.error(path)),
        _ => None,
    }
}

/// Whether `dir` holds N5 metadata (an `attributes.json` with the N5
/// version or an N5 array's fields).
fn is_n5_dir(dir: &Path) -> bool {
    let file = dir.join("attributes.json");
    let Ok(meta) = std::fs::metadata(&file) else {
        return false;
    };
    // Attributes are small; a huge file is not read to find out.
    if !meta.is_file() || meta.len() > 1 << 20 {
        return false;
    }
    let Ok(text) = std::fs::read(&file) else {
        return false;
    };
    let Ok(serde_json::Value::Object(attrs)) = serde_json::from_slice(&text) else {
        return false;
    };
    attrs.contains_key("n5")
        || ["dimensions", "blockSize", "dataType"]
            .iter()
            .all(|k| attrs.contains_key(*k))
}

/// The refusal of the directory at `dir` if it is an N5 container, group
/// or array.
pub(crate) fn refuse_dir(dir: &Path) -> Option<IoError> {
    is_n5_dir(dir).then(|| N5.error(dir))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_are_lower_case_and_keep_gz() {
        assert_eq!(extension(Path::new("a/x+orig.BRIK.gz")), "brik.gz");
        assert_eq!(extension(Path::new("T1.REC")), "rec");
        assert_eq!(extension(Path::new("noext")), "");
    }

    #[test]
    fn magic_numbers_name_the_format() {
        let p = Path::new("f");
        let named = |head: &[u8]| refuse_file(p, head).map(|e| e.to_string());
        assert!(
            named(b"MATRIX72v\0\0")
                .unwrap()
                .contains("ECAT 7 is not read")
        );
        assert!(
            named(b" BDV\0\0\0\0\xe0\0\0\0")
                .unwrap()
                .contains("OpenVDB")
        );
        assert!(
            named(b"# === DATA DESCRIPTION FILE ===")
                .unwrap()
                .contains("PAR/REC")
        );
        assert!(
            named(b"\ntype = integer-attribute\nname = DATASET_RANK\n")
                .unwrap()
                .contains("AFNI")
        );
        assert_eq!(named(b"MATRIX6"), None);
        assert_eq!(named(b"BDV "), None);
    }
}
