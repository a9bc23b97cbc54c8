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

/// A directory being written (a Zarr store: many files) that appears at
/// its path only when complete, as [`AtomicFile`] does for one file.
///
/// The contents go to a temporary directory beside the destination
/// (`.NAME.XXXXXX.tmp`), listed in the registry, so that a failure
/// (dropping the `AtomicDir`) or a signal ([`remove_unfinished_files`])
/// deletes it and leaves any existing directory at the path untouched.
/// [`commit`](AtomicDir::commit) syncs every file, then renames the
/// directory into place; an existing directory at the path is renamed
/// aside first and deleted after, both renames under the registry's lock,
/// so a signal finds either the old directory or the new one in place.
/// Only what `replaceable` accepts is ever replaced.
#[derive(Debug)]
pub struct AtomicDir {
    tmp: PathBuf,
    path: PathBuf,
    parent: PathBuf,
    replaceable: fn(&Path) -> Result<(), String>,
    committed: bool,
    /// Dropped (unlisted) after the directory is renamed or deleted.
    _registered: Registered,
}

impl AtomicDir {
    /// Starts writing the directory `path`: checks its parent, and that an
    /// existing `path` may be replaced (`replaceable` returns why not),
    /// then creates the temporary directory, with the permissions an
    /// ordinary new directory gets (`0o777` less the umask on Unix).
    pub fn create(
        path: &Path,
        replaceable: fn(&Path) -> Result<(), String>,
    ) -> Result<Self, IoError> {
        let parent = destination_parent(path)?;
        check_replaceable(path, replaceable)?;
        let mut builder = tempfile::Builder::new();
        let prefix = match path.file_name() {
            Some(name) => format!(".{}.", name.to_string_lossy()),
            None => ".volray.".to_string(),
        };
        builder.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o777));
        }
        let mut live = registry();
        let tmp = builder
            .tempdir_in(&parent)
            .map_err(|e| IoError::os(path, "create a temporary directory for", e))?
            .keep();
        live.push(tmp.clone());
        let registered = Registered(tmp.clone());
        drop(live);
        Ok(AtomicDir {
            tmp,
            path: path.to_path_buf(),
            parent,
            replaceable,
            committed: false,
            _registered: registered,
        })
    }

    /// The temporary directory, to write the contents in.
    pub fn dir(&self) -> &Path {
        &self.tmp
    }

    /// The path the directory will have.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Runs `write` (a write into the temporary directory) under the
    /// registry's lock: a signal's [`remove_unfinished_files`] waits for
    /// it to finish, and once that has begun `write` never starts (it
    /// waits for the exit), so nothing is written into the directory
    /// after it is deleted. `write` must not create or commit another
    /// [`AtomicFile`] or [`AtomicDir`] (it would wait for itself).
    pub fn while_live<R>(&self, write: impl FnOnce(&Path) -> R) -> R {
        let _live = registry();
        write(&self.tmp)
    }

    /// Syncs every file to disk and renames the temporary directory to the
    /// destination, replacing an existing directory there (checked again
    /// with `replaceable`).
    pub fn commit(mut self) -> Result<(), IoError> {
        sync_tree(&self.tmp).map_err(|e| IoError::os(&self.path, "sync", e))?;
        let mut live = registry();
        let mut aside = None;
        if std::fs::symlink_metadata(&self.path).is_ok() {
            if let Err(e) = check_replaceable(&self.path, self.replaceable) {
                drop(live);
                return Err(e);
            }
            // An empty directory to rename the old one over.
            let old = tempfile::Builder::new()
                .prefix(&format!(
                    ".{}.",
                    self.path.file_name().unwrap_or_default().to_string_lossy()
                ))
                .suffix(".old")
                .tempdir_in(&self.parent)
                .map_err(|e| IoError::os(&self.path, "create a temporary directory for", e))?
                .keep();
            if let Err(e) = std::fs::rename(&self.path, &old) {
                let _ = std::fs::remove_dir(&old);
                drop(live);
                return Err(IoError::os(&self.path, "replace", e));
            }
            aside = Some(old);
        }
        if let Err(e) = std::fs::rename(&self.tmp, &self.path) {
            if let Some(old) = &aside {
                let _ = std::fs::rename(old, &self.path);
            }
            drop(live);
            return Err(IoError::os(&self.path, "replace", e));
        }
        self.committed = true;
        // The old directory is listed until it is deleted, so that a
        // signal meanwhile deletes the rest of it.
        let old = aside.map(|old| {
            live.push(old.clone());
            Registered(old)
        });
        drop(live);
        if let Some(old) = &old {
            let _ = std::fs::remove_dir_all(&old.0);
        }
        drop(old);
        sync_dir(&self.parent);
        Ok(())
    }
}

impl Drop for AtomicDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

/// Refuses an existing `path` that `replaceable` does not accept.
fn check_replaceable(
    path: &Path,
    replaceable: fn(&Path) -> Result<(), String>,
) -> Result<(), IoError> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(());
    }
    replaceable(path).map_err(|reason| IoError::BadDestination {
        path: path.to_path_buf(),
        reason,
    })
}

/// Syncs every file and directory under `root` (and `root`) to disk.
fn sync_tree(root: &Path) -> io::Result<()> {
    let mut pending = vec![root.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d)? {
            let entry = entry?;
            let kind = entry.file_type()?;
            if kind.is_dir() {
                pending.push(entry.path());
            } else if kind.is_file() {
                std::fs::File::open(entry.path())?.sync_all()?;
            }
        }
        sync_dir(&d);
    }
    Ok(())
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
        // An [`AtomicDir`]'s temporary directory, or a file.
        let gone = if path.is_dir() {
            std::fs::remove_dir_all(path)
        } else {
            std::fs::remove_file(path)
        };
        if gone.is_ok() {
            removed += 1;
        }
    }
    std::mem::forget(live);
    removed
}

/// The directory `path` will be created in, checked to exist, with `path`
/// checked not to be a directory itself.
fn destination_dir(path: &Path) -> Result<PathBuf, IoError> {
    if path.is_dir() && !path.as_os_str().is_empty() {
        return Err(IoError::BadDestination {
            path: path.to_path_buf(),
            reason: "it is a directory".to_string(),
        });
    }
    destination_parent(path)
}

/// The directory `path` will be created in, checked to exist.
fn destination_parent(path: &Path) -> Result<PathBuf, IoError> {
    let bad = |reason: &str| IoError::BadDestination {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    if path.as_os_str().is_empty() {
        return Err(bad("empty file name"));
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
    fn zarr_only(path: &Path) -> Result<(), String> {
        if path.join("zarr.json").is_file() {
            Ok(())
        } else {
            Err("not a store".to_string())
        }
    }

    #[test]
    fn a_directory_appears_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.zarr");
        // Dropped before commit: nothing left, and unlisted.
        let dropped = AtomicDir::create(&p, zarr_only).unwrap();
        fs::write(dropped.dir().join("zarr.json"), b"{}").unwrap();
        let tmp = dropped.dir().to_path_buf();
        assert!(listed(&tmp));
        drop(dropped);
        assert!(!tmp.exists() && !listed(&tmp));
        assert!(entries(dir.path()).is_empty());

        let first = AtomicDir::create(&p, zarr_only).unwrap();
        fs::create_dir(first.dir().join("0")).unwrap();
        fs::write(first.dir().join("0/a"), b"first").unwrap();
        fs::write(first.dir().join("zarr.json"), b"{}").unwrap();
        assert!(!p.exists());
        first.commit().unwrap();
        assert_eq!(fs::read(p.join("0/a")).unwrap(), b"first");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // An ordinary new directory's, not a temporary one's 0o700.
            let probe = dir.path().join("probe");
            fs::create_dir(&probe).unwrap();
            let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode();
            assert_eq!(mode(&p), mode(&probe));
            fs::remove_dir(&probe).unwrap();
        }

        // A second replaces it whole: no file of the first is left.
        let second = AtomicDir::create(&p, zarr_only).unwrap();
        fs::write(second.dir().join("zarr.json"), b"{\"v\": 2}").unwrap();
        second.commit().unwrap();
        assert_eq!(fs::read(p.join("zarr.json")).unwrap(), b"{\"v\": 2}");
        assert!(!p.join("0").exists());
        assert_eq!(entries(dir.path()), ["out.zarr"]);

        // What the check refuses is left alone, at create and at commit.
        let other = dir.path().join("other");
        fs::create_dir(&other).unwrap();
        fs::write(other.join("keep"), b"k").unwrap();
        let err = AtomicDir::create(&other, zarr_only).unwrap_err();
        assert!(
            err.to_string().ends_with("cannot write: not a store"),
            "{err}"
        );
        let late = dir.path().join("late");
        let pending = AtomicDir::create(&late, zarr_only).unwrap();
        fs::write(&late, b"appeared meanwhile").unwrap();
        assert!(pending.commit().is_err());
        assert_eq!(fs::read(&late).unwrap(), b"appeared meanwhile");
        assert_eq!(entries(dir.path()), ["late", "other", "out.zarr"]);
    }
}
