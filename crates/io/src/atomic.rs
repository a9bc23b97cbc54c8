//! Atomic file replacement: a destination is either left as it was or
//! replaced by the complete new contents, never half written.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::IoError;

/// Writes a file at `path` through `write`, atomically.
///
/// The contents go to a temporary file in the destination's directory (so
/// the final rename stays on one file system and is atomic), which is
/// flushed and synced to disk, then renamed over `path`. If `write` or
/// any step fails, the temporary file is removed and an existing file at
/// `path` is left untouched. A destination whose directory does not exist,
/// or that is itself a directory, is refused with a clear error.
///
/// The new file gets the permissions an ordinary newly created file would
/// (`0o666` less the umask on Unix).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), IoError> {
    let mut file = AtomicFile::create(path)?;
    {
        let mut out = BufWriter::new(file.file());
        write(&mut out).map_err(|e| IoError::os(path, "write", e))?;
        out.flush().map_err(|e| IoError::os(path, "write", e))?;
    }
    file.commit()
}

/// A file being written that appears at its path only when complete: for
/// outputs written piece by piece (animations), where
/// [`write_atomically`]'s single closure does not fit.
///
/// The contents go to a temporary file beside the destination; dropping
/// an `AtomicFile` without [`commit`](AtomicFile::commit) deletes it and
/// leaves any existing file at the path untouched.
#[derive(Debug)]
pub struct AtomicFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
    dir: PathBuf,
}

impl AtomicFile {
    /// Starts writing `path`: checks its directory and creates the
    /// temporary file.
    pub fn create(path: &Path) -> Result<Self, IoError> {
        let dir = destination_dir(path)?;
        let mut builder = tempfile::Builder::new();
        let prefix = match path.file_name() {
            Some(name) => format!(".{}.", name.to_string_lossy()),
            None => ".volray.".to_string(),
        };
        builder.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = builder
            .tempfile_in(&dir)
            .map_err(|e| IoError::os(path, "create a temporary file for", e))?;
        Ok(AtomicFile {
            tmp,
            path: path.to_path_buf(),
            dir,
        })
    }

    /// The temporary file, to write the contents to.
    pub fn file(&mut self) -> &mut std::fs::File {
        self.tmp.as_file_mut()
    }

    /// The path the file will have.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Syncs the contents to disk and renames the temporary file over the
    /// destination.
    pub fn commit(self) -> Result<(), IoError> {
        let path = self.path;
        self.tmp
            .as_file()
            .sync_all()
            .map_err(|e| IoError::os(&path, "sync", e))?;
        // On failure the PersistError holds the temporary file; dropping it
        // deletes the file.
        self.tmp
            .persist(&path)
            .map_err(|e| IoError::os(&path, "replace", e.error))?;
        sync_dir(&self.dir);
        Ok(())
    }
}

/// The directory `path` will be created in, checked to exist, with `path`
/// checked not to be a directory itself.
fn destination_dir(path: &Path) -> Result<PathBuf, IoError> {
    let bad = |reason: &str| IoError::BadDestination {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    if path.as_os_str().is_empty() {
        return Err(bad("empty file name"));
    }
    if path.is_dir() {
        return Err(bad("it is a directory"));
    }
    if path.file_name().is_none() {
        // "..", "/", "a/.." and the like name no file.
        return Err(bad("the path does not name a file"));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => Ok(dir),
        Ok(_) => Err(bad(&format!("{} is not a directory", dir.display()))),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Err(IoError::NoSuchDirectory {
            path: path.to_path_buf(),
            dir,
        }),
        Err(e) => Err(IoError::os(path, "access the directory of", e)),
    }
}

/// Makes the rename durable where the platform allows; best effort.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn writes_and_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.bin");
        write_atomically(&p, |w| w.write_all(b"first")).unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"first");
        write_atomically(&p, |w| w.write_all(b"second, longer")).unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"second, longer");
        assert_eq!(entries(dir.path()), ["out.bin"]);
    }

    #[test]
    fn failed_write_leaves_destination_and_no_temp_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("keep.png");
        fs::write(&p, b"original").unwrap();
        let err = write_atomically(&p, |w| {
            w.write_all(&[7u8; 100_000])?;
            Err(io::Error::other("encoder gave up"))
        })
        .unwrap_err();
        assert!(err.is_io_failure());
        let msg = err.to_string();
        assert!(
            msg.contains("keep.png: cannot write: encoder gave up"),
            "{msg}"
        );
        assert_eq!(fs::read(&p).unwrap(), b"original");
        assert_eq!(entries(dir.path()), ["keep.png"]);

        // Also when there was no destination before.
        let q = dir.path().join("new.png");
        assert!(write_atomically(&q, |_| Err(io::Error::other("no"))).is_err());
        assert!(!q.exists());
        assert_eq!(entries(dir.path()), ["keep.png"]);
    }

    #[test]
    fn missing_directory_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/dir/out.png");
        let err = write_atomically(&p, |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(err, IoError::NoSuchDirectory { .. }), "{err}");
        assert!(err.is_io_failure());
        let msg = err.to_string();
        assert!(msg.contains("out.png: cannot write: directory"), "{msg}");
        assert!(msg.contains("does not exist"), "{msg}");
        assert!(!dir.path().join("no").exists());
    }

    #[test]
    fn directory_destination_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        fs::create_dir(&sub).unwrap();
        let err = write_atomically(&sub, |w| w.write_all(b"x")).unwrap_err();
        assert!(
            err.to_string().ends_with("cannot write: it is a directory"),
            "{err}"
        );
        assert!(sub.is_dir());
        assert_eq!(entries(dir.path()), ["sub"]);

        // A parent that is a file.
        let file = dir.path().join("file");
        fs::write(&file, b"f").unwrap();
        let err = write_atomically(&file.join("out.png"), |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("is not a directory"), "{err}");
        assert_eq!(fs::read(&file).unwrap(), b"f");
    }
}
