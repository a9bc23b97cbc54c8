//! Volumes larger than the memory they may take (`--max-memory`), mapped
//! from their file instead of read into memory.
//!
//! A file whose samples are stored uncompressed, contiguous, x fastest, in
//! a type a volume keeps (`u8`, `i8`, `u16`, `i16`, `f32`) and in this
//! machine's byte order is the volume's memory already: mapped, its pages
//! are read by the operating system as the renderer touches them and
//! dropped again under memory pressure (they are the page cache's, not the
//! process's anonymous memory, so `--max-memory` bounds what the renderer
//! adds, not the file). Each reader says whether its data can be mapped
//! and, when it cannot, why ([`plan`] puts that into the refusal).
//!
//! A mapped file changed under the renderer is detected, never a crash:
//! reads past the end of a file truncated meanwhile are caught
//! ([`super::sigbus`]) and, like a change of length or modification time,
//! make [`MappedFile::verify`] fail, which fails the frame
//! ([`volray_core::RenderError::SamplesChanged`]).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use memmap2::{Mmap, MmapOptions};
use volray_core::{External, ExternalBytes, Sample, Samples, Store};

use super::sigbus::Guard;
use crate::dtype::{DType, Endian};
use crate::error::IoError;
use crate::shared::input::open_input;

/// When a reader maps its file rather than reading it
/// ([`ReadOptions::map`](crate::ReadOptions::map)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MapPolicy {
    /// Only a volume larger than the memory limit, where its format and
    /// layout allow; read into memory otherwise.
    #[default]
    IfLarger,
    /// Whenever the format and layout allow (for tests and benchmarks);
    /// read into memory otherwise.
    Always,
    /// As [`Always`](MapPolicy::Always), and a file whose axes are not x,
    /// y, z in that order and sense is mapped all the same, in its own
    /// axis order: the volume read is the file's grid, and
    /// [`FileInfo::reorientation`](crate::FileInfo::reorientation) says
    /// how to take the world-aligned volume's boxes from it (for a reader
    /// of boxes, such as an MPI rank, which reorders only its own box).
    /// Under the other policies such a file is read into memory and
    /// reordered, or, mapped because it is over the limit, refused.
    AlwaysInFileOrder,
    /// Never: a volume over the limit is refused.
    Never,
}

impl MapPolicy {
    /// Whether every volume that can be mapped is.
    pub fn always(self) -> bool {
        matches!(self, MapPolicy::Always | MapPolicy::AlwaysInFileOrder)
    }
}

/// What a reader does with its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Plan {
    Read,
    Map,
}

/// Decides between reading and mapping: `within_limit` is the reader's own
/// check of the volume against the memory limit, `mappable` whether its
/// data could be mapped (or why not). Over the limit, a mappable volume is
/// mapped (unless `policy` says never) and any other is refused with the
/// reason it could not be mapped added to the refusal.
pub(crate) fn plan(
    policy: MapPolicy,
    mappable: Result<(), String>,
    within_limit: Result<usize, IoError>,
) -> Result<Plan, IoError> {
    match within_limit {
        Ok(_) if policy.always() && mappable.is_ok() => Ok(Plan::Map),
        Ok(_) => Ok(Plan::Read),
        Err(IoError::OverMemoryLimit { path, need, limit }) if policy != MapPolicy::Never => {
            match mappable {
                Ok(()) => Ok(Plan::Map),
                Err(why) => {
                    let head = need.strip_suffix(" exceed").unwrap_or(&need);
                    Err(IoError::OverMemoryLimit {
                        path,
                        need: format!(
                            "{head}, which cannot be mapped from the file instead ({why}), exceed"
                        ),
                        limit,
                    })
                }
            }
        }
        Err(e) => Err(e),
    }
}

/// The note a reader adds to a volume it mapped.
pub(crate) fn mapped_note(volume: &volray_core::Volume) -> String {
    let bytes = volume.len() * volume.sample_type().bytes();
    format!(
        "mapped from the file rather than read into memory ({} of {} samples): its pages are read as the renderer needs them",
        crate::format_bytes(bytes as u128),
        volume.sample_type().name()
    )
}

/// Whether samples of `dtype` stored in `endian` order from byte `offset`
/// of a file can be used as they are in the file, or why not. A mapping
/// starts at a page boundary, so samples of 2 or 4 bytes must start at a
/// multiple of their size to be read in place; a header of another length
/// before them (an attached NRRD or MetaImage header) prevents it.
pub(crate) fn mappable(dtype: DType, endian: Endian, offset: u64) -> Result<(), String> {
    if !matches!(
        dtype,
        DType::U8 | DType::I8 | DType::U16 | DType::I16 | DType::F32
    ) {
        return Err(format!(
            "{dtype} samples are converted to f32 as they are read: store them as u8, i8, u16, i16 or f32"
        ));
    }
    if dtype.size() > 1 && endian != Endian::NATIVE {
        return Err(format!(
            "{endian}-endian samples on a {}-endian machine: store them {}-endian",
            Endian::NATIVE,
            Endian::NATIVE
        ));
    }
    let size = dtype.size() as u64;
    if !offset.is_multiple_of(size) {
        return Err(format!(
            "the samples start at byte {offset}, not a multiple of their {size} bytes: store them in a file of their own (a detached header)"
        ));
    }
    Ok(())
}

/// `count` samples of `dtype` (as [`mappable`] allows) from byte `offset`
/// of the file at `path`, mapped.
pub(crate) fn map_samples(
    path: &Path,
    offset: u64,
    dtype: DType,
    count: usize,
) -> Result<Samples, IoError> {
    let file = MappedFile::open(path)?;
    let offset = usize::try_from(offset)
        .map_err(|_| IoError::invalid(path, "data offset beyond this machine's addresses"))?;
    fn external<T: Sample>(
        path: &Path,
        file: Arc<MappedFile>,
        offset: usize,
        count: usize,
    ) -> Result<Store<T>, IoError> {
        External::new(file, offset, count)
            .map(Store::External)
            .map_err(|e| IoError::invalid(path, format!("cannot map the samples: {e}")))
    }
    Ok(match dtype {
        DType::U8 => Samples::U8(external(path, file, offset, count)?),
        DType::I8 => Samples::I8(external(path, file, offset, count)?),
        DType::U16 => Samples::U16(external(path, file, offset, count)?),
        DType::I16 => Samples::I16(external(path, file, offset, count)?),
        DType::F32 => Samples::F32(external(path, file, offset, count)?),
        other => {
            return Err(IoError::invalid(
                path,
                format!("{other} samples cannot be mapped"),
            ));
        }
    })
}

/// A file mapped read-only, guarded against truncation.
#[derive(Debug)]
pub struct MappedFile {
    // Dropped in this order: the range is unregistered, then unmapped.
    guard: Guard,
    map: Mmap,
    file: File,
    path: PathBuf,
    len: u64,
    modified: Option<SystemTime>,
}

impl MappedFile {
    /// Maps the whole file at `path` read-only.
    pub(crate) fn open(path: &Path) -> Result<Arc<MappedFile>, IoError> {
        let (file, len) = open_input(path)?;
        let meta = file
            .metadata()
            .map_err(|e| IoError::os(path, "read metadata of", e))?;
        if len == 0 {
            return Err(IoError::invalid(path, "the file is empty: nothing to map"));
        }
        // SAFETY: `MmapOptions::map` maps the file read-only and *shared*
        // (memmap2's `MmapInner::map`: `PROT_READ`, `MAP_SHARED`): the
        // pages are the page cache's, so a write to the file by another
        // process shows through them at once. A private mapping would not
        // prevent that either: Linux shows a file's changes through the
        // pages of a `MAP_PRIVATE` mapping not yet copied, and a read-only
        // one is never copied (POSIX leaves it unspecified, mmap(2)). So
        // the `&[u8]` this hands out is sound only under the assumption
        // every mapped-file reader makes, that nobody writes or truncates
        // the file while it is mapped; no lock can enforce that (advisory
        // locks bind only those who take them). What this crate does
        // instead is keep a breach of it from crashing the process or
        // passing unnoticed: reads past a truncated end are caught (the
        // guard below, registered before any read of the map; the zero
        // page it maps over the faulting page is in place of the shared
        // one, see `sigbus`) and read zeros, which `verify` reports, as it
        // does a change of length or modification time. The samples are
        // plain numbers (every bit pattern is a value of `u8`, `i8`,
        // `u16`, `i16` or `f32`), so bytes changed under a read give wrong
        // values, never invalid ones.
        let map =
            unsafe { MmapOptions::new().map(&file) }.map_err(|e| IoError::os(path, "map", e))?;
        let guard = Guard::new(map.as_ptr() as usize, map.len())
            .map_err(|why| IoError::invalid(path, format!("cannot guard the mapping: {why}")))?;
        Ok(Arc::new(MappedFile {
            guard,
            map,
            file,
            path: path.to_path_buf(),
            len,
            modified: meta.modified().ok(),
        }))
    }
}

impl ExternalBytes for MappedFile {
    fn bytes(&self) -> &[u8] {
        &self.map
    }

    fn verify(&self) -> Result<(), String> {
        let path = self.path.display();
        if self.guard.faulted() {
            return Err(format!(
                "{path}: the file was truncated while it was mapped: reads past its new end gave zeros"
            ));
        }
        let meta = self
            .file
            .metadata()
            .map_err(|e| format!("{path}: cannot read metadata of the mapped file: {e}"))?;
        if meta.len() != self.len {
            return Err(format!(
                "{path}: the file changed from {} to {} bytes while it was mapped",
                self.len,
                meta.len()
            ));
        }
        if meta.modified().ok() != self.modified {
            return Err(format!("{path}: the file was modified while it was mapped"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn over(need: &str) -> Result<usize, IoError> {
        Err(IoError::OverMemoryLimit {
            path: "v.nrrd".into(),
            need: need.into(),
            limit: 100,
        })
    }

    #[test]
    fn a_volume_over_the_limit_is_mapped_where_it_can_be() {
        use MapPolicy::*;
        let yes = || Ok(());
        let no = || Err("gzip-compressed data".to_string());
        assert_eq!(plan(IfLarger, yes(), Ok(10)).unwrap(), Plan::Read);
        assert_eq!(plan(Always, yes(), Ok(10)).unwrap(), Plan::Map);
        assert_eq!(plan(Always, no(), Ok(10)).unwrap(), Plan::Read);
        assert_eq!(plan(AlwaysInFileOrder, yes(), Ok(10)).unwrap(), Plan::Map);
        assert_eq!(plan(AlwaysInFileOrder, no(), Ok(10)).unwrap(), Plan::Read);
        assert_eq!(plan(IfLarger, yes(), over("x exceed")).unwrap(), Plan::Map);
        let err = plan(IfLarger, no(), over("sizes 9 9 9 (729 values) exceed")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "v.nrrd: sizes 9 9 9 (729 values), which cannot be mapped from the file instead (gzip-compressed data), exceed the memory limit of 100 bytes"
        );
        let err = plan(Never, yes(), over("x exceed")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "v.nrrd: x exceed the memory limit of 100 bytes"
        );
        let other = Err(IoError::invalid(Path::new("v"), "bad"));
        assert!(plan(IfLarger, yes(), other).is_err());
    }

    #[test]
    fn only_native_types_in_native_order_map() {
        assert!(mappable(DType::U16, Endian::NATIVE, 352).is_ok());
        assert!(mappable(DType::U8, Endian::Big, 3).is_ok());
        let err = mappable(DType::F32, Endian::NATIVE, 366).unwrap_err();
        assert!(
            err.contains("start at byte 366, not a multiple of their 4 bytes"),
            "{err}"
        );
        let err = mappable(DType::F64, Endian::NATIVE, 0).unwrap_err();
        assert!(err.contains("converted to f32"), "{err}");
        let other = match Endian::NATIVE {
            Endian::Little => Endian::Big,
            Endian::Big => Endian::Little,
        };
        let err = mappable(DType::I16, other, 0).unwrap_err();
        assert!(err.contains("-endian machine"), "{err}");
    }

    #[test]
    fn mapped_samples_are_the_file_and_a_change_is_noticed() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.raw");
        let values: Vec<u16> = (0..64).map(|i| i * 1000).collect();
        let mut bytes = vec![0u8; 8];
        bytes.extend(values.iter().flat_map(|v| v.to_ne_bytes()));
        std::fs::write(&p, &bytes).unwrap();
        let samples = map_samples(&p, 8, DType::U16, 64).unwrap();
        assert!(samples.is_external());
        assert_eq!(samples, Samples::from(values.clone()));
        assert_eq!(samples.verify(), Ok(()));
        // Longer now: noticed.
        let mut longer = bytes.clone();
        longer.push(0);
        std::fs::write(&p, &longer).unwrap();
        let err = samples.verify().unwrap_err();
        assert!(err.contains("changed from 136 to 137 bytes"), "{err}");
        assert!(map_samples(&p, 1, DType::U16, 4).is_err());
        assert!(map_samples(&p, 8, DType::U16, 65).is_err());
    }

    /// Reading a mapped page past the end of a file truncated meanwhile
    /// raises SIGBUS; the guard turns it into zeros and an error from
    /// `verify`, and the process goes on.
    #[test]
    fn a_file_truncated_under_its_mapping_reads_zeros_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.raw");
        let n = 3 * 65536 / 4;
        let values: Vec<f32> = (0..n).map(|i| 1.0 + i as f32).collect();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_ne_bytes()).collect();
        std::fs::write(&p, &bytes).unwrap();
        let samples = map_samples(&p, 0, DType::F32, n).unwrap();
        assert_eq!(samples.get(n - 1), n as f32);
        std::fs::OpenOptions::new()
            .write(true)
            .open(&p)
            .unwrap()
            .set_len(100)
            .unwrap();
        // Within the file still: the value; past its end: 0, not a crash.
        assert_eq!(samples.get(3), 4.0);
        assert_eq!(samples.get(n - 1), 0.0);
        assert_eq!(samples.get(n / 2), 0.0);
        let err = samples.verify().unwrap_err();
        assert!(err.contains("truncated while it was mapped"), "{err}");
    }
}
