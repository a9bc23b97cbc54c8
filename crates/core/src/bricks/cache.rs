//! A cache of per-brick buffers under a byte budget, aged by frame: the
//! fast path's classified and lit bricks live here, so that its memory is
//! bounded whatever the number of occupied bricks.
//!
//! Each occupied brick has an entry: a buffer, once filled, and the frame
//! that last used it. A request for a brick's buffer
//! ([`BrickCache::get`]) uses the entry if it holds a valid buffer; else
//! the buffer is (re)filled, into the entry's own buffer if it has one,
//! else into a new one while the budget allows, else into one taken from
//! a brick that no recent frame used (a clock hand sweeps the entries for
//! one), else into the caller's scratch buffer (on its stack), used once.
//! So the cache never exceeds its budget, a volume whose bricks all fit
//! behaves as if there were no budget, and a larger one keeps what the
//! last frames used and recomputes the rest.
//!
//! A caller that knows a brick's buffer will not be asked for again (the
//! lit bricks: once the last tile that lists a brick is done with it, see
//! `cpu::lit_bricks`) gives it back ([`BrickCache::release`]) to a
//! pool, from which the next brick takes it before any is allocated or
//! taken from another entry. The buffers then hold the bricks in use, not
//! the first ones a frame asked for, and a budget smaller than all the
//! bricks still fills each brick once a frame when the bricks in use fit.
//!
//! Several caches may draw on one [`Budget`] (the classified and the lit
//! bricks do). A cache whose `get` is given a way to make room (`shed`:
//! the lit bricks drop classified ones, which can be made again) frees
//! bytes that way before it falls back on a scratch buffer, so it has the
//! first claim on the budget and the other cache keeps what is left.
//!
//! The policy is by frame rather than least-recently-used because a frame
//! visits bricks in an order (tiles, front to back) that repeats from
//! frame to frame: LRU would evict every brick just before its next use
//! when they do not all fit, whereas keeping what the last frames used,
//! and passing the rest through the stack, keeps a fixed share of them.
//!
//! Concurrency: each entry has its own lock. A thread fills an entry under
//! its write lock and takes a buffer from another entry only with
//! `try_write` (never waiting), so two threads stealing from each other
//! cannot deadlock; readers share an entry's read lock.

use std::ops::Deref;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, RwLock, RwLockReadGuard, RwLockWriteGuard};

/// How many entries the clock hand looks at for a buffer to take before
/// giving up and filling a temporary one.
const SWEEP: usize = 64;

/// A brick's buffer, as [`BrickCache::get`] gives it.
pub(crate) enum CacheRef<'a, T> {
    /// The cache's buffer, under the entry's read lock.
    Cached(RwLockReadGuard<'a, Option<Box<T>>>),
    /// The caller's scratch buffer, filled for this use.
    Scratch(&'a T),
}

impl<T> Deref for CacheRef<'_, T> {
    type Target = T;

    #[inline]
    fn deref(&self) -> &T {
        match self {
            CacheRef::Cached(buffer) => buffer.as_deref().expect("a cached buffer is filled"),
            CacheRef::Scratch(buffer) => buffer,
        }
    }
}

/// Bytes that one or more caches allocate their buffers from.
#[derive(Debug)]
pub(crate) struct Budget {
    limit: usize,
    /// Bytes of the buffers allocated, by every cache drawing on it.
    used: AtomicUsize,
}

impl Budget {
    /// At most `limit` bytes.
    pub fn new(limit: usize) -> Arc<Self> {
        Arc::new(Budget {
            limit,
            used: AtomicUsize::new(0),
        })
    }

    /// The most bytes.
    pub fn limit(&self) -> usize {
        self.limit
    }

    /// Counts `size` more bytes if there is room for them.
    fn take(&self, size: usize) -> bool {
        self.used
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |b| {
                (b.checked_add(size)? <= self.limit).then_some(b + size)
            })
            .is_ok()
    }

    /// Gives back `size` bytes.
    fn give(&self, size: usize) {
        self.used.fetch_sub(size, Ordering::AcqRel);
    }
}

/// Per-brick buffers of type `T` under a budget of bytes.
pub(crate) struct BrickCache<T> {
    entries: Vec<Entry<T>>,
    /// Bytes of this cache's buffers (each `size_of::<T>()`).
    bytes: AtomicUsize,
    budget: Arc<Budget>,
    /// Where the next sweep for a buffer to take starts.
    hand: AtomicUsize,
    /// Whether a buffer filled for frame `f` is still valid in frame `now`.
    valid: fn(f: u64, now: u64) -> bool,
    /// Whether a buffer last used in frame `f` may be taken in frame `now`.
    evictable: fn(f: u64, now: u64) -> bool,
    /// Buffers given back ([`Self::release`]), reused first. Made with room
    /// for every buffer the budget allows (at most one per entry: a buffer
    /// is allocated only while the pool is empty), so it never grows.
    pool: Mutex<Vec<Box<T>>>,
    /// Buffers filled, into the cache or a scratch buffer ([`Self::fills`]).
    fills: AtomicUsize,
}

struct Entry<T> {
    buffer: RwLock<Option<Box<T>>>,
    /// The frame that last filled or used the buffer (0: never).
    frame: AtomicU64,
}

impl<T> BrickCache<T> {
    /// Bytes an entry takes beside its buffer: the entry, and its
    /// buffer's place in the pool.
    pub const BYTES_PER_ENTRY: usize = size_of::<Entry<T>>() + size_of::<Box<T>>();

    /// A cache of `count` entries whose buffers take at most what `budget`
    /// has room for. `valid` and `evictable` give the policy (see the
    /// module docs); frames are numbered from 1.
    pub fn new(
        count: usize,
        budget: Arc<Budget>,
        valid: fn(u64, u64) -> bool,
        evictable: fn(u64, u64) -> bool,
    ) -> Self {
        BrickCache {
            entries: (0..count)
                .map(|_| Entry {
                    buffer: RwLock::new(None),
                    frame: AtomicU64::new(0),
                })
                .collect(),
            bytes: AtomicUsize::new(0),
            hand: AtomicUsize::new(0),
            valid,
            evictable,
            pool: Mutex::new(Vec::with_capacity(
                count.min(budget.limit / size_of::<T>().max(1)),
            )),
            budget,
            fills: AtomicUsize::new(0),
        }
    }

    /// Gives entry `n`'s buffer back to the pool, if it has one: the
    /// caller knows that no one will ask for brick `n` again until it is
    /// refilled. The caller must hold no reference into this cache (it
    /// waits for the entry's lock).
    pub fn release(&self, n: usize) {
        let entry = &self.entries[n];
        let taken = {
            let mut buffer = entry.buffer.write().unwrap_or_else(|e| e.into_inner());
            entry.frame.store(0, Ordering::Release);
            buffer.take()
        };
        if let Some(buffer) = taken {
            self.pool
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(buffer);
        }
    }

    /// Gives every buffer back to the pool (between frames, when every
    /// buffer is stale).
    pub fn release_all(&mut self) {
        let pool = self.pool.get_mut().unwrap_or_else(|e| e.into_inner());
        for entry in &mut self.entries {
            *entry.frame.get_mut() = 0;
            let buffer = entry.buffer.get_mut().unwrap_or_else(|e| e.into_inner());
            pool.extend(buffer.take());
        }
    }

    /// How many times a buffer was filled, into the cache or a scratch
    /// buffer, since the cache was made.
    pub fn fills(&self) -> usize {
        self.fills.load(Ordering::Relaxed)
    }

    /// Puts `buffer` into entry `n`, which has none, if the budget has
    /// room for it; says whether it did.
    pub fn put(&self, n: usize, buffer: Box<T>) -> bool {
        if !self.reserve_bytes() {
            return false;
        }
        let mut entry = (self.entries[n].buffer.write()).unwrap_or_else(|e| e.into_inner());
        debug_assert!(entry.is_none());
        *entry = Some(buffer);
        true
    }

    /// Counts one more buffer if the budget has room for it.
    fn reserve_bytes(&self) -> bool {
        let size = size_of::<T>();
        let room = self.budget.take(size);
        if room {
            self.bytes.fetch_add(size, Ordering::AcqRel);
        }
        room
    }

    /// Drops one buffer that no one is reading (one given back, else any
    /// entry's), its bytes back to the budget for another cache drawing
    /// on it; says whether it found one. The hand goes round the entries
    /// once at most: a cache that holds a buffer gives one up unless every
    /// holder is being read.
    pub fn shed(&self) -> bool {
        if self.bytes() == 0 {
            return false;
        }
        let pooled = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop();
        let dropped = pooled.is_some() || {
            let count = self.entries.len();
            (0..count).any(|_| {
                let m = self.hand.fetch_add(1, Ordering::Relaxed) % count;
                let entry = &self.entries[m];
                entry.buffer.try_write().is_ok_and(|mut buffer| {
                    let taken = buffer.take();
                    if taken.is_some() {
                        entry.frame.store(0, Ordering::Release);
                    }
                    taken.is_some()
                })
            })
        };
        if dropped {
            let size = size_of::<T>();
            self.bytes.fetch_sub(size, Ordering::AcqRel);
            self.budget.give(size);
        }
        dropped
    }

    /// Bytes of buffer memory allocated.
    pub fn bytes(&self) -> usize {
        self.bytes.load(Ordering::Relaxed)
    }

    /// Brick `n`'s buffer in frame `now`, filled by `fill` first unless
    /// the entry holds one still valid (see the module docs for where the
    /// buffer comes from): the entry's own, under its read lock, or, when
    /// the budget has no room for it, the buffer in `scratch` (made there
    /// the first time: a caller reuses one for many bricks), filled for
    /// this use only. `blank` makes a buffer to fill (its contents are
    /// overwritten); `shed` makes room in the budget when it has none
    /// (another cache's [`Self::shed`]), saying whether it did.
    pub fn get<'a>(
        &'a self,
        n: usize,
        now: u64,
        blank: impl Fn() -> Box<T>,
        mut fill: impl FnMut(&mut T),
        scratch: &'a mut Option<Box<T>>,
        shed: impl Fn() -> bool,
    ) -> CacheRef<'a, T> {
        let entry = &self.entries[n];
        // Rarely more than once: see the end of the loop.
        loop {
            {
                let buffer = entry.buffer.read().unwrap_or_else(|e| e.into_inner());
                if buffer.is_some() && (self.valid)(entry.frame.load(Ordering::Acquire), now) {
                    entry.frame.fetch_max(now, Ordering::AcqRel);
                    return CacheRef::Cached(buffer);
                }
            }
            let mut buffer = entry.buffer.write().unwrap_or_else(|e| e.into_inner());
            // Another thread may have filled it meanwhile.
            let valid = buffer.is_some() && (self.valid)(entry.frame.load(Ordering::Acquire), now);
            if !valid {
                self.fills.fetch_add(1, Ordering::Relaxed);
                if buffer.is_none() {
                    *buffer = self.reserve(n, now, &blank, &shed);
                }
                match buffer.as_deref_mut() {
                    Some(b) => fill(b),
                    None => {
                        // No room: the scratch buffer, used once.
                        drop(buffer);
                        let scratch = scratch.get_or_insert_with(&blank);
                        fill(scratch);
                        return CacheRef::Scratch(scratch);
                    }
                }
            }
            entry.frame.fetch_max(now, Ordering::AcqRel);
            // Read under a shared lock, so that other threads can read it
            // too: a buffer used in frame `now` is not taken for another
            // brick in it.
            drop(buffer);
            let buffer = entry.buffer.read().unwrap_or_else(|e| e.into_inner());
            if buffer.is_some() {
                return CacheRef::Cached(buffer);
            }
            // Between the two locks another cache drawing on the budget
            // shed this buffer to make room (`shed` takes any buffer no
            // one holds a lock on; std's RwLock cannot turn a write lock
            // into a read lock): fill the brick again.
        }
    }

    /// A buffer for entry `n`: one given back, else a new one if the
    /// budget allows (after `shed` made room, while it can), else one
    /// taken from an evictable entry, else `None`.
    fn reserve(
        &self,
        n: usize,
        now: u64,
        blank: &impl Fn() -> Box<T>,
        shed: impl Fn() -> bool,
    ) -> Option<Box<T>> {
        if let Some(buffer) = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop() {
            return Some(buffer);
        }
        loop {
            if self.reserve_bytes() {
                return Some(blank());
            }
            if !shed() {
                break;
            }
        }
        let count = self.entries.len();
        for _ in 0..SWEEP.min(count) {
            let m = self.hand.fetch_add(1, Ordering::Relaxed) % count;
            if m == n {
                continue;
            }
            let victim = &self.entries[m];
            if !(self.evictable)(victim.frame.load(Ordering::Acquire), now) {
                continue;
            }
            if let Ok(mut guard) = victim.buffer.try_write()
                && let Some(taken) = Self::take_if(&mut guard, victim, now, self.evictable)
            {
                return Some(taken);
            }
        }
        None
    }

    /// The buffer of `victim` (whose write lock is `guard`), if it is still
    /// evictable.
    fn take_if(
        guard: &mut RwLockWriteGuard<'_, Option<Box<T>>>,
        victim: &Entry<T>,
        now: u64,
        evictable: fn(u64, u64) -> bool,
    ) -> Option<Box<T>> {
        if evictable(victim.frame.load(Ordering::Acquire), now) {
            let taken = guard.take();
            if taken.is_some() {
                victim.frame.store(0, Ordering::Release);
            }
            taken
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;

    /// Buffers valid in the frame that filled them only; taken once a
    /// later frame runs.
    fn per_frame(count: usize, buffers: usize) -> BrickCache<[u64; 16]> {
        BrickCache::new(
            count,
            Budget::new(buffers * size_of::<[u64; 16]>()),
            |f, now| f == now,
            |f, now| f < now,
        )
    }

    #[test]
    fn a_cache_that_holds_everything_fills_each_buffer_once_per_validity() {
        let cache = per_frame(10, 10);
        let fills = AtomicUsize::new(0);
        for now in 1..=3 {
            for _ in 0..2 {
                for n in 0..10 {
                    let mut scratch = None;
                    let v = cache.get(
                        n,
                        now,
                        || Box::new([0; 16]),
                        |b| {
                            fills.fetch_add(1, Ordering::Relaxed);
                            b.fill(100 * now + n as u64)
                        },
                        &mut scratch,
                        || false,
                    )[7];
                    assert_eq!(v, 100 * now + n as u64);
                }
            }
        }
        // Once per brick per frame, the second pass reading what the first
        // filled; ten buffers allocated in all.
        assert_eq!(fills.load(Ordering::Relaxed), 30);
        assert_eq!(cache.bytes(), 10 * size_of::<[u64; 16]>());
    }

    #[test]
    fn a_small_budget_is_never_exceeded_and_every_read_sees_its_fill() {
        // Four buffers for ten bricks, bricks asked for from two threads.
        let cache = per_frame(10, 4);
        let fills = AtomicUsize::new(0);
        for now in 1..=5 {
            std::thread::scope(|s| {
                for t in 0..2 {
                    let (cache, fills) = (&cache, &fills);
                    s.spawn(move || {
                        for i in 0..50 {
                            let n = (i * 7 + t * 3) % 10;
                            let mut scratch = None;
                            let v = cache.get(
                                n,
                                now,
                                || Box::new([0; 16]),
                                |b| {
                                    fills.fetch_add(1, Ordering::Relaxed);
                                    b.fill(1000 * now + n as u64)
                                },
                                &mut scratch,
                                || false,
                            )[15];
                            assert_eq!(v, 1000 * now + n as u64);
                        }
                    });
                }
            });
            assert!(cache.bytes() <= 4 * size_of::<[u64; 16]>());
        }
        // Bricks without a buffer are filled on every request.
        assert!(fills.load(Ordering::Relaxed) > 5 * 10);
    }

    #[test]
    fn a_buffer_shed_while_its_brick_is_filled_is_filled_again_not_read_empty() {
        // The lit bricks shed classified ones from another thread at any
        // moment, even between a fill's write lock and its read lock: the
        // reader must see its brick's values, never a missing buffer.
        let cache = per_frame(4, 4);
        let stop = std::sync::atomic::AtomicBool::new(false);
        // Stops the shedding thread however the reads end (a failed
        // assertion too, or the scope would wait for it forever).
        struct Stop<'a>(&'a std::sync::atomic::AtomicBool);
        impl Drop for Stop<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Relaxed);
            }
        }
        std::thread::scope(|s| {
            s.spawn(|| {
                while !stop.load(Ordering::Relaxed) {
                    cache.shed();
                }
            });
            let _stop = Stop(&stop);
            for now in 1..=20_000u64 {
                let n = (now % 4) as usize;
                let mut scratch = None;
                let v = cache.get(
                    n,
                    now,
                    || Box::new([0; 16]),
                    |b| b.fill(10 * now + n as u64),
                    &mut scratch,
                    || false,
                )[3];
                assert_eq!(v, 10 * now + n as u64);
            }
        });
    }

    #[test]
    fn buffers_of_bricks_a_frame_used_are_kept_and_the_others_taken() {
        // Buffers stay valid; taken only from bricks unused in the last
        // frame and this one, as the classified bricks are.
        let cache: BrickCache<[u64; 16]> = BrickCache::new(
            6,
            Budget::new(2 * size_of::<[u64; 16]>()),
            |_, _| true,
            |f, now| f + 1 < now,
        );
        let fill = |cache: &BrickCache<[u64; 16]>, n: usize, now: u64| {
            let mut filled = false;
            let mut scratch = None;
            let b = cache.get(
                n,
                now,
                || Box::new([0; 16]),
                |b| {
                    filled = true;
                    b.fill(n as u64)
                },
                &mut scratch,
                || false,
            );
            assert_eq!(b[0], n as u64);
            drop(b);
            filled
        };
        assert!(fill(&cache, 0, 1) && fill(&cache, 1, 1));
        // Frame 2: bricks 0 and 1 were used in frame 1, so brick 2 goes
        // through a temporary buffer (each time), and 0 is still cached.
        assert!(fill(&cache, 2, 2));
        assert!(!fill(&cache, 0, 2));
        assert!(fill(&cache, 2, 2));
        // Frame 3 uses brick 0 again.
        assert!(!fill(&cache, 0, 3));
        // Frame 4: brick 1 was last used in frame 1: its buffer goes to
        // brick 3; brick 0, used in frame 3, keeps its own.
        assert!(fill(&cache, 3, 4));
        assert!(!fill(&cache, 3, 4));
        assert!(!fill(&cache, 0, 4));
        assert!(fill(&cache, 1, 4));
        assert_eq!(cache.bytes(), 2 * size_of::<[u64; 16]>());
    }
}
