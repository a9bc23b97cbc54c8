//! The files an input reads, so that volray never writes to its inputs:
//! before any work, each output path is compared with every file the
//! command will read, by identity (device and inode on Unix, so hard
//! links and symbolic links count, and `./a.png` is `a.png`), not by name.
//!
//! The files an input spec reads ([`files_read`]) are its file (every
//! volume of a series is a spec of its own), each file of a DICOM
//! directory (its DICOMDIR and every file that lists, or every file of
//! its subfolders), and the detached data files a `.nhdr` or `.mhd` header names
//! (one name or a `LIST`; numbered `%d` patterns are not expanded); a
//! front end adds its own plain input files (`--tf`).

use std::fs;
use std::path::{Path, PathBuf};

/// An output that is one of the files read: bad input, refused before
/// any work. Its message names the output, and the input where it is
/// another name for it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: the output is {}; refusing to overwrite it", output.display(), match input {
    None => "the input file".to_string(),
    Some(input) => format!("the input file {}", input.display()),
})]
pub struct Overwrites {
    pub output: PathBuf,
    /// The input by the name it was given, where that is not the
    /// output's.
    pub input: Option<PathBuf>,
}

/// Refuses any of `outputs` that is one of the files `inputs` (specs as
/// given: built-in sources are skipped) or `others` (plain input files)
/// name.
pub fn refuse_overwriting_inputs(
    outputs: &[PathBuf],
    inputs: &[String],
    others: &[&Path],
) -> Result<(), Overwrites> {
    // Outputs that do not exist yet cannot be inputs; most runs stop here.
    let existing: Vec<(&PathBuf, Identity)> = outputs
        .iter()
        .filter_map(|o| Some((o, Identity::of(o)?)))
        .collect();
    if existing.is_empty() {
        return Ok(());
    }
    let mut read: Vec<PathBuf> = others.iter().map(|p| p.to_path_buf()).collect();
    for spec in inputs {
        if !volray_data::is_source_spec(spec) {
            read.extend(files_read(&input_path(spec)));
        }
    }
    for input in &read {
        let Some(id) = Identity::of(input) else {
            continue;
        };
        if let Some((output, _)) = existing.iter().find(|(_, o)| *o == id) {
            return Err(Overwrites {
                output: output.to_path_buf(),
                input: (input != output.as_path()).then(|| input.clone()),
            });
        }
    }
    Ok(())
}

/// The file an input spec names: the spec itself, or for an HDF5 dataset
/// `file.h5:/path` the file before the colon.
fn input_path(spec: &str) -> PathBuf {
    let path = PathBuf::from(spec);
    if !path.exists()
        && let Some((file, _)) = spec.split_once(":/")
    {
        return PathBuf::from(file);
    }
    path
}

/// The files reading `path` touches: the file itself, the files of a
/// directory (DICOM: every series it may read, volray-io's walk), and a
/// text header's detached data files.
pub fn files_read(path: &Path) -> Vec<PathBuf> {
    let mut files = vec![path.to_path_buf()];
    if path.is_dir() {
        if let Ok(entries) = fs::read_dir(path) {
            files.extend(entries.flatten().map(|e| e.path()));
        }
        files.extend(volray_io::dicom_directory_files(path));
        return files;
    }
    let is_dicomdir = (path.file_name().and_then(|n| n.to_str()))
        .is_some_and(|n| n.eq_ignore_ascii_case("DICOMDIR"));
    if is_dicomdir && let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        files.extend(volray_io::dicom_directory_files(dir));
        return files;
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let key = match ext.as_deref() {
        Some("nhdr") | Some("nrrd") => DataFileKey::Nrrd,
        Some("mhd") | Some("mha") => DataFileKey::MetaImage,
        _ => return files,
    };
    let dir = path.parent().unwrap_or(Path::new(""));
    files.extend(detached_data_files(&header_text(path), key).map(|name| dir.join(name)));
    files
}

/// How a header names its data file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum DataFileKey {
    /// `data file: NAME` (or `datafile:`).
    Nrrd,
    /// `ElementDataFile = NAME`.
    MetaImage,
}

/// The start of a text header, enough for any real header's fields and a
/// `LIST` of data files; a binary file gives noise that names no file.
fn header_text(path: &Path) -> String {
    use std::io::Read;
    const HEADER_BYTES: u64 = 256 * 1024;
    let mut bytes = Vec::new();
    // Only regular files: opening a FIFO would block until a writer came.
    if fs::metadata(path).is_ok_and(|m| m.is_file())
        && let Ok(f) = fs::File::open(path)
    {
        let _ = f.take(HEADER_BYTES).read_to_end(&mut bytes);
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The data file names `header` gives: one name, or the names of a `LIST`
/// (the lines after it, up to a blank line). `LOCAL` and numbered
/// patterns (`name%03d.raw 1 10 1`) give none.
fn detached_data_files(header: &str, key: DataFileKey) -> impl Iterator<Item = String> + '_ {
    let mut lines = header.lines();
    let value = lines.by_ref().find_map(|line| match key {
        DataFileKey::Nrrd => line
            .strip_prefix("data file:")
            .or_else(|| line.strip_prefix("datafile:")),
        DataFileKey::MetaImage => line
            .split_once('=')
            .filter(|(k, _)| k.trim() == "ElementDataFile")
            .map(|(_, v)| v),
    });
    let value = value.map(str::trim).unwrap_or("");
    let list = value == "LIST" || value.starts_with("LIST ");
    let single = !list && !value.is_empty() && value != "LOCAL" && !value.contains(' ');
    let first = single.then(|| value.to_string());
    let rest = lines
        .take_while(move |l| list && !l.trim().is_empty())
        .map(|l| l.trim().to_string());
    first.into_iter().chain(rest)
}

/// What makes two paths the same file.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Identity {
    #[cfg(unix)]
    Inode { dev: u64, ino: u64 },
    #[cfg(not(unix))]
    Canonical(PathBuf),
}

impl Identity {
    /// The identity of the file at `path`, if it exists.
    fn of(path: &Path) -> Option<Identity> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let m = fs::metadata(path).ok()?;
            Some(Identity::Inode {
                dev: m.dev(),
                ino: m.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            path.canonicalize().ok().map(Identity::Canonical)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(header: &str, key: DataFileKey) -> Vec<String> {
        detached_data_files(header, key).collect()
    }

    #[test]
    fn detached_data_file_names_are_read_from_headers() {
        let nrrd = "NRRD0004\ntype: float\ndata file: ./vol.raw\n";
        assert_eq!(names(nrrd, DataFileKey::Nrrd), ["./vol.raw"]);
        let list = "NRRD0004\ndatafile: LIST\na.raw\n b.raw \n\nnoise";
        assert_eq!(names(list, DataFileKey::Nrrd), ["a.raw", "b.raw"]);
        let pattern = "NRRD0004\ndata file: s%03d.raw 1 10 1\n";
        assert!(names(pattern, DataFileKey::Nrrd).is_empty());
        let mhd = "NDims = 3\nElementDataFile = head.raw\n";
        assert_eq!(names(mhd, DataFileKey::MetaImage), ["head.raw"]);
        let mha = "NDims = 3\nElementDataFile = LOCAL\n\x01\x02";
        assert!(names(mha, DataFileKey::MetaImage).is_empty());
        let mlist = "ElementDataFile = LIST 2\nz0.raw\nz1.raw\n";
        assert_eq!(names(mlist, DataFileKey::MetaImage), ["z0.raw", "z1.raw"]);
    }

    #[test]
    fn the_same_file_by_another_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.npy");
        fs::write(&input, b"data").unwrap();
        let other = dir.path().join("other.png");
        fs::write(&other, b"x").unwrap();
        let spec = input.display().to_string();
        // Another existing file, or one that does not exist, is fine.
        let fine = [other.clone(), dir.path().join("new.png")];
        assert!(refuse_overwriting_inputs(&fine, std::slice::from_ref(&spec), &[]).is_ok());
        // The input through `..`, and a hard link to it, are not.
        let dotted = dir.path().join("sub/../in.npy");
        fs::create_dir(dir.path().join("sub")).unwrap();
        let link = dir.path().join("link.png");
        fs::hard_link(&input, &link).unwrap();
        for output in [dotted, link] {
            let err = refuse_overwriting_inputs(
                std::slice::from_ref(&output),
                std::slice::from_ref(&spec),
                &[],
            )
            .unwrap_err();
            assert_eq!(err.output, output);
            assert_eq!(err.input.as_ref(), Some(&input));
            assert!(err.to_string().ends_with(&format!(
                ": the output is the input file {}; refusing to overwrite it",
                input.display()
            )));
        }
        // A plain input file such as --tf, by its own name.
        let err =
            refuse_overwriting_inputs(std::slice::from_ref(&other), &[], &[&other]).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!(
                "{}: the output is the input file; refusing to overwrite it",
                other.display()
            )
        );
        // A built-in source names no file, even when one has its name.
        fs::write(dir.path().join("blobs:8"), b"x").unwrap();
        assert!(refuse_overwriting_inputs(&[other], &["blobs:8".to_string()], &[]).is_ok());
    }
}
