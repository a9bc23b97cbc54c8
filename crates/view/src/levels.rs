//! A pyramid's levels read whole, shared by every tab: the last
//! [`CACHED_LEVELS`] used, each behind an `Arc` (its samples as outside
//! bytes, so that each tab's renderer of it shares them) together with
//! its reservation in the server's ledger: the bytes are given back when
//! the last renderer of the level and the cache have let go of it.
//!
//! The cache's lock is held only to look a level up, mark it loading,
//! and put it in: never while a level is read from its file (seconds for
//! a large level), so that a tab drafting from a level held already is
//! not kept waiting by another tab's read. A level being read is marked
//! *loading*: a second tab that needs it waits for that read (on a
//! condition variable) instead of reading it too; one that needs another
//! level reads it at the same time.

use crate::ledger::{Ledger, Overdrawn, Reservation};
use crate::pyramid::{CACHED_LEVELS, Pyramid};
use bytemuck::cast_slice;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use volray_core::{External, ExternalBytes, Sample, Samples, Store, Volume};

/// Why a level could not be read whole.
#[derive(Debug, thiserror::Error)]
pub enum LevelError {
    #[error("{0}")]
    Memory(#[from] Overdrawn),
    /// The source's one-line message, and its kind.
    #[error("{0}")]
    Read(volray_core::SourceError),
}

/// The levels read whole, shared by every tab.
pub struct Levels {
    pub pyramid: Pyramid,
    cache: Mutex<Cache>,
    /// Notified whenever a level stops loading (read, or failed).
    loaded: Condvar,
}

#[derive(Default)]
struct Cache {
    /// Level and volume, the most recently used last.
    held: Vec<(usize, Volume)>,
    /// The levels being read now, each by one tab.
    loading: Vec<usize>,
    /// The tabs waiting for another's read.
    waiting: usize,
}

impl Cache {
    /// Keeps `volume` as level `level`, the most recently used, letting
    /// go of the least recently used beyond [`CACHED_LEVELS`].
    fn put(&mut self, level: usize, volume: Volume) {
        self.held.retain(|(l, _)| *l != level);
        self.held.push((level, volume));
        let over = self.held.len().saturating_sub(CACHED_LEVELS);
        self.held.drain(..over);
    }
}

/// A level marked loading: the mark taken off when dropped (the read
/// done, failed, or unwound by a panic), and the waiting tabs woken.
struct Loading<'a> {
    levels: &'a Levels,
    level: usize,
}

impl Drop for Loading<'_> {
    fn drop(&mut self) {
        self.levels.lock().loading.retain(|l| *l != self.level);
        self.levels.loaded.notify_all();
    }
}

impl Levels {
    pub fn new(pyramid: Pyramid) -> Levels {
        Levels {
            pyramid,
            cache: Mutex::new(Cache::default()),
            loaded: Condvar::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Cache> {
        self.cache.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Whether level `level` is held whole now.
    pub fn is_held(&self, level: usize) -> bool {
        self.lock().held.iter().any(|(l, _)| *l == level)
    }

    /// How many tabs wait for a level another tab is reading.
    #[cfg(test)]
    pub fn waiting(&self) -> usize {
        self.lock().waiting
    }

    /// Keeps `volume` as level `level`, its bytes held by `reserved`.
    pub fn keep(&self, level: usize, volume: Volume, reserved: Reservation) -> Volume {
        let volume = shared(volume, reserved);
        self.lock().put(level, volume.clone());
        volume
    }

    /// Level `level` whole: from the cache, or read (its bytes reserved
    /// from `ledger` first, the least recently used levels let go of
    /// where they do not fit). The cache is not locked while the level
    /// is read; a tab needing a level another tab is reading waits for
    /// that read.
    pub fn whole(&self, level: usize, ledger: &Arc<Ledger>) -> Result<Volume, LevelError> {
        let mut cache = self.lock();
        loop {
            if let Some(i) = cache.held.iter().position(|(l, _)| *l == level) {
                let entry = cache.held.remove(i);
                let volume = entry.1.clone();
                cache.held.push(entry);
                return Ok(volume);
            }
            if !cache.loading.contains(&level) {
                break;
            }
            // Read by another tab: held once it is done (or, if its read
            // failed, read here next).
            cache.waiting += 1;
            cache = self.loaded.wait(cache).unwrap_or_else(|e| e.into_inner());
            cache.waiting -= 1;
        }
        let pyramid = &self.pyramid;
        let dims = pyramid.grid(level).dims;
        let [x, y, z] = dims;
        let what = format!("level {level} ({x}x{y}x{z}) read whole");
        let bytes = pyramid.volume_bytes(level);
        let reserved = loop {
            match ledger.reserve(&what, bytes) {
                Ok(r) => break r,
                // Let go of the least recently used level, and try again
                // (its bytes come back once no tab renders it either).
                Err(e) if cache.held.is_empty() => return Err(e.into()),
                Err(_) => {
                    cache.held.remove(0);
                }
            }
        };
        cache.loading.push(level);
        drop(cache);
        let loading = Loading {
            levels: self,
            level,
        };
        let mut volume = pyramid
            .source(level)
            .read_box([0; 3], dims)
            .map_err(LevelError::Read)?;
        volume.set_labels(pyramid.labels());
        let volume = shared(volume, reserved);
        // Held before the mark is taken off, so that a waiting tab finds it.
        self.lock().put(level, volume.clone());
        drop(loading);
        Ok(volume)
    }
}

/// Samples read whole, and their bytes' reservation: given back when the
/// last volume sharing them is dropped.
#[derive(Debug)]
struct Held {
    samples: Owned,
    _reserved: Reservation,
}

#[derive(Debug)]
enum Owned {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    F32(Vec<f32>),
}

impl ExternalBytes for Held {
    fn bytes(&self) -> &[u8] {
        match &self.samples {
            Owned::U8(v) => v,
            Owned::I8(v) => cast_slice(v),
            Owned::U16(v) => cast_slice(v),
            Owned::I16(v) => cast_slice(v),
            Owned::F32(v) => cast_slice(v),
        }
    }

    fn verify(&self) -> Result<(), String> {
        // Memory of our own: nothing can change it underneath.
        Ok(())
    }
}

/// `volume` with its samples behind an `Arc`, held with `reserved`:
/// clones share them. A volume whose samples are already outside bytes
/// is returned as it is (and `reserved` given back).
pub fn shared(volume: Volume, reserved: Reservation) -> Volume {
    let (dims, spacing, origin, labels) = (
        volume.dims(),
        volume.spacing(),
        volume.origin(),
        volume.is_labels(),
    );
    let samples = match volume.into_samples() {
        Samples::U8(Store::Owned(v)) => Samples::U8(held(v, Owned::U8, reserved)),
        Samples::I8(Store::Owned(v)) => Samples::I8(held(v, Owned::I8, reserved)),
        Samples::U16(Store::Owned(v)) => Samples::U16(held(v, Owned::U16, reserved)),
        Samples::I16(Store::Owned(v)) => Samples::I16(held(v, Owned::I16, reserved)),
        Samples::F32(Store::Owned(v)) => Samples::F32(held(v, Owned::F32, reserved)),
        external => external,
    };
    let mut volume = Volume::from_samples(dims, samples)
        .and_then(|v| v.with_spacing(spacing))
        .and_then(|v| v.with_origin(origin))
        .expect("the grid of a volume that was valid");
    volume.set_labels(labels);
    volume
}

/// The samples `v` behind an `Arc` with `reserved`, as outside bytes.
fn held<T: Sample>(v: Vec<T>, wrap: fn(Vec<T>) -> Owned, reserved: Reservation) -> Store<T> {
    let len = v.len();
    let held: Arc<dyn ExternalBytes> = Arc::new(Held {
        samples: wrap(v),
        _reserved: reserved,
    });
    // A vector of the samples' own type: aligned, and `len` of them.
    Store::External(External::new(held, 0, len).expect("a vector's own samples"))
}
