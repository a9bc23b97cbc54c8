//! Atomic file replacement: a destination is either left as it was or
//! replaced by the complete new contents, never half written.
//!
//! Every temporary file is also listed in a process-wide registry while it
//! lives, so that a process stopped by a signal (Ctrl-C) can delete them
//! before it exits ([`remove_unfinished_files`]): destructors do not run
//! when a process exits from a signal handler.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

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

/// Writes a complete temporary file for `path` through `write`, like
/// [`write_atomically`], but leaves it unpublished: [`PendingFile::publish`]
/// or [`publish_all`] puts it in place later. For outputs made of several
/// files (PNG sequences) that must appear together or not at all.
pub(crate) fn write_pending(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<PendingFile, IoError> {
    let mut file = AtomicFile::create(path)?;
    {
        let mut out = BufWriter::new(file.file());
        write(&mut out).map_err(|e| IoError::os(path, "write", e))?;
        out.flush().map_err(|e| IoError::os(path, "write", e))?;
    }
    file.into_pending()
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
    /// Listed in the registry; dropped (unlisted) after `tmp` is renamed
    /// or deleted, as fields drop in declaration order.
    _registered: Registered,
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
        // Created and listed under the registry's lock, so that a signal
        // handler never misses a temporary file that exists.
        let mut live = registry();
        let tmp = builder
            .tempfile_in(&dir)
            .map_err(|e| IoError::os(path, "create a temporary file for", e))?;
        live.push(tmp.path().to_path_buf());
        let registered = Registered(tmp.path().to_path_buf());
        drop(live);
        Ok(AtomicFile {
            tmp,
            path: path.to_path_buf(),
            dir,
            _registered: registered,
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

    /// Syncs the contents to disk and closes the temporary file without
    /// publishing it: it stays listed (and is deleted on a signal or when
    /// the [`PendingFile`] is dropped), holding no file descriptor, so that
    /// a sequence of many frames can wait for its last one.
    pub(crate) fn into_pending(self) -> Result<PendingFile, IoError> {
        self.tmp
            .as_file()
            .sync_all()
            .map_err(|e| IoError::os(&self.path, "sync", e))?;
        Ok(PendingFile {
            tmp: self.tmp.into_temp_path(),
            path: self.path,
            dir: self.dir,
            _registered: self._registered,
        })
    }

    /// Syncs the contents to disk and renames the temporary file over the
    /// destination.
    pub fn commit(self) -> Result<(), IoError> {
        let path = self.path;
        self.tmp
            .as_file()
            .sync_all()
            .map_err(|e| IoError::os(&path, "sync", e))?;
        // Renamed under the registry's lock: a signal handler waits for the
        // rename, then finds the file either published whole or still
        // listed as temporary. On failure the PersistError holds the
        // temporary file; dropping it deletes the file.
        let live = registry();
        let persisted = self.tmp.persist(&path);
        drop(live);
        persisted.map_err(|e| IoError::os(&path, "replace", e.error))?;
        sync_dir(&self.dir);
        Ok(())
    }
}

/// A complete, closed temporary file waiting to be renamed to its path
/// (see [`write_pending`]); dropping it deletes the temporary file.
#[derive(Debug)]
pub(crate) struct PendingFile {
    tmp: tempfile::TempPath,
    path: PathBuf,
    dir: PathBuf,
    /// Dropped (unlisted) after `tmp`, as in [`AtomicFile`].
    _registered: Registered,
}

/// Renames every pending file to its path, in order, under the registry's
/// lock: a signal handler waits for the whole set, so an interrupted run
/// leaves either all of them published or none (the temporary files of
/// the rest are deleted). Stops at the first failure; the files not yet
/// renamed are then deleted.
pub(crate) fn publish_all(files: Vec<PendingFile>) -> Result<Vec<PathBuf>, IoError> {
    let mut published = Vec::with_capacity(files.len());
    // Unlisting takes the lock, so the entries are dropped after it is
    // released; so are the files not renamed after a failure.
    let mut entries = Vec::with_capacity(files.len());
    let mut failure = None;
    let mut dirs: Vec<PathBuf> = Vec::new();
    {
        let _live = registry();
        let mut rest = files.into_iter();
        for file in rest.by_ref() {
            let PendingFile {
                tmp,
                path,
                dir,
                _registered,
            } = file;
            entries.push(_registered);
            if let Err(e) = tmp.persist(&path) {
                // The PersistError holds the temporary path; dropped below.
                failure = Some((IoError::os(&path, "replace", e.error), e.path));
                break;
            }
            if !dirs.contains(&dir) {
                dirs.push(dir);
            }
            published.push(path);
        }
        let unrenamed: Vec<PendingFile> = rest.collect();
        drop(_live);
        drop(unrenamed);
    }
    drop(entries);
    for dir in &dirs {
        sync_dir(dir);
    }
    match failure {
        Some((error, tmp)) => {
            drop(tmp);
            Err(error)
        }
        None => Ok(published),
    }
}

/// The temporary files of the live [`AtomicFile`]s.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn registry() -> MutexGuard<'static, Vec<PathBuf>> {
    // A panic elsewhere while holding the lock leaves a list still valid.
    LIVE.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// An [`AtomicFile`]'s entry in the registry, unlisted when dropped.
#[derive(Debug)]
struct Registered(PathBuf);

impl Drop for Registered {
    fn drop(&mut self) {
        let mut live = registry();
        if let Some(i) = live.iter().position(|p| *p == self.0) {
            live.swap_remove(i);
        }
    }
}

/// Deletes the temporary file of every [`AtomicFile`] still being
/// written, and returns how many it deleted: for a process about to exit
/// without running destructors (on a signal, or when standard output is
/// closed), so that it leaves no partial output behind.
///
/// The registry stays locked afterwards, so that no other thread can start
/// or publish a file between this call and the exit: call it only right
/// before `std::process::exit`. Any other thread that then tries to create
/// or commit an [`AtomicFile`] waits for the exit.
pub fn remove_unfinished_files() -> usize {
    let live = registry();
    let mut removed = 0;
    for path in live.iter() {
        if std::fs::remove_file(path).is_ok() {
            removed += 1;
        }
    }
    std::mem::forget(live);
    removed
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

    fn listed(tmp: &Path) -> bool {
        registry().iter().any(|p| p == tmp)
    }

    #[test]
    fn temporary_files_are_listed_while_they_live() {
        let dir = tempfile::tempdir().unwrap();
        let mut committed = AtomicFile::create(&dir.path().join("a.bin")).unwrap();
        committed.file().write_all(b"a").unwrap();
        let tmp_a = committed.tmp.path().to_path_buf();
        let dropped = AtomicFile::create(&dir.path().join("b.bin")).unwrap();
        let tmp_b = dropped.tmp.path().to_path_buf();
        assert!(tmp_a.exists() && tmp_b.exists());
        assert!(listed(&tmp_a) && listed(&tmp_b));
        committed.commit().unwrap();
        drop(dropped);
        assert!(!listed(&tmp_a) && !listed(&tmp_b));
        assert_eq!(entries(dir.path()), ["a.bin"]);
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
