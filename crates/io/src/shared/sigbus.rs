//! A file truncated while it is mapped would kill the process: reading a
//! page of the mapping that lies past the file's new end raises SIGBUS.
//! This module turns that into an error instead.
//!
//! Each mapping registers its address range in a fixed table ([`Guard`]).
//! A SIGBUS handler, installed once, looks up the faulting address: inside
//! a registered range, it maps one anonymous zero page over the faulting
//! page (`mmap` with `MAP_FIXED`, which replaces that page of the mapping
//! in place), marks the range as faulted and returns, so the read that
//! faulted is retried and reads zeros. The renderer then asks the mapping
//! whether its bytes were the file's ([`Guard::faulted`] through
//! `MappedFile::verify`) and fails the frame with an error naming the file.
//! A SIGBUS anywhere else goes to the disposition that was there before
//! (the default one ends the process, as it would have).
//!
//! What the handler does is async-signal-safe: atomic loads and stores on
//! a static table, and the `mmap` and `sigaction` system calls (Linux's
//! `mmap` is a system call without locks in user space; POSIX does not
//! list it as async-signal-safe, which is why the handler does nothing
//! else).

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Mappings registered at once, at most: a render maps one file.
const SLOTS: usize = 32;

/// One registered range `[start, end)`; `start == 0` is a free slot.
struct Slot {
    start: AtomicUsize,
    end: AtomicUsize,
    faulted: AtomicBool,
}

#[allow(clippy::declare_interior_mutable_const)]
const FREE: Slot = Slot {
    start: AtomicUsize::new(0),
    end: AtomicUsize::new(0),
    faulted: AtomicBool::new(false),
};

static TABLE: [Slot; SLOTS] = [FREE; SLOTS];

/// The page size, and the disposition SIGBUS had before ours.
struct Installed {
    page: usize,
    previous: libc::sigaction,
}

// SAFETY: `libc::sigaction` is plain data (a handler address, a signal
// mask, flags); it is written once, before the handler can run, and only
// read afterwards.
unsafe impl Sync for Installed {}
unsafe impl Send for Installed {}

static INSTALLED: OnceLock<Result<Installed, String>> = OnceLock::new();

/// A registered range: while it lives, a SIGBUS inside it reads zeros and
/// is remembered instead of ending the process.
#[derive(Debug)]
pub(crate) struct Guard {
    slot: usize,
}

impl Guard {
    /// Registers `[start, start + len)`; installs the handler on first
    /// use. Fails if the handler cannot be installed or every slot is
    /// taken.
    pub(crate) fn new(start: usize, len: usize) -> Result<Guard, String> {
        install()?;
        let end = start
            .checked_add(len)
            .ok_or("mapping wraps the address space")?;
        for (slot, s) in TABLE.iter().enumerate() {
            if s.start.load(Ordering::Acquire) != 0 {
                continue;
            }
            // Claim the slot with a placeholder start, then publish the
            // range: the handler acts only on a slot whose start is real.
            if s.start
                .compare_exchange(0, usize::MAX, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
            {
                s.faulted.store(false, Ordering::Release);
                s.end.store(end, Ordering::Release);
                s.start.store(start, Ordering::Release);
                return Ok(Guard { slot });
            }
        }
        Err(format!("more than {SLOTS} files mapped at once"))
    }

    /// Whether a read of the range faulted (the file was shorter than
    /// its mapping: truncated after it was mapped).
    pub(crate) fn faulted(&self) -> bool {
        TABLE[self.slot].faulted.load(Ordering::Acquire)
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        let s = &TABLE[self.slot];
        // Unregistered before the mapping is unmapped (the guard is
        // dropped first): the handler never touches a range being reused.
        s.start.store(usize::MAX, Ordering::Release);
        s.end.store(0, Ordering::Release);
        s.start.store(0, Ordering::Release);
    }
}

fn install() -> Result<(), String> {
    INSTALLED
        .get_or_init(|| {
            // SAFETY: sysconf has no preconditions.
            let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
            if page <= 0 || (page as usize).count_ones() != 1 {
                return Err("cannot read the page size".into());
            }
            // SAFETY: a zeroed sigaction is a valid value (no handler, no
            // flags, empty mask), and both structures outlive the call.
            let mut action: libc::sigaction = unsafe { std::mem::zeroed() };
            let mut previous: libc::sigaction = unsafe { std::mem::zeroed() };
            action.sa_sigaction = on_sigbus as *const () as usize;
            action.sa_flags = libc::SA_SIGINFO | libc::SA_ONSTACK;
            // SAFETY: the mask is a valid sigset_t owned here; the handler
            // has the signature SA_SIGINFO requires; `previous` receives
            // the old disposition. The table and page size it reads are
            // statics initialised before it is installed: the OnceLock's
            // value is stored before another thread can map a file (they
            // wait on this initialisation), and this thread maps nothing
            // until it returns.
            let installed = unsafe {
                libc::sigemptyset(&mut action.sa_mask);
                libc::sigaction(libc::SIGBUS, &action, &mut previous)
            };
            if installed != 0 {
                return Err(format!(
                    "cannot install a SIGBUS handler: {}",
                    std::io::Error::last_os_error()
                ));
            }
            Ok(Installed {
                page: page as usize,
                previous,
            })
        })
        .as_ref()
        .map(|_| ())
        .map_err(Clone::clone)
}

/// The SIGBUS handler: see the module documentation.
extern "C" fn on_sigbus(
    signal: libc::c_int,
    info: *mut libc::siginfo_t,
    context: *mut libc::c_void,
) {
    // SAFETY: the kernel passes a valid siginfo_t for a handler installed
    // with SA_SIGINFO; si_addr is the faulting address for SIGBUS.
    let addr = unsafe { (*info).si_addr() } as usize;
    let Some(Ok(installed)) = INSTALLED.get() else {
        return default_action(signal);
    };
    for s in &TABLE {
        let start = s.start.load(Ordering::Acquire);
        if start == 0 || start == usize::MAX {
            continue;
        }
        let end = s.end.load(Ordering::Acquire);
        if addr < start || addr >= end {
            continue;
        }
        let page = addr & !(installed.page - 1);
        // SAFETY: `page` lies in a registered mapping (`MappedFile`'s:
        // read-only and shared, `MAP_SHARED`) that is alive: the read
        // that faulted borrows it, so it cannot be unmapped during the
        // read, and its guard unregisters it before it is unmapped. A
        // private anonymous page replaces that one page of the shared
        // mapping in place (`MAP_FIXED`), readable and zero, so the
        // faulting read can be retried; the rest of the mapping stays the
        // file's, and unmapping the whole range later unmaps this page
        // too. Nothing else maps there: the range is the mapping's own.
        let mapped = unsafe {
            libc::mmap(
                page as *mut libc::c_void,
                installed.page,
                libc::PROT_READ,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS | libc::MAP_FIXED,
                -1,
                0,
            )
        };
        if mapped != libc::MAP_FAILED {
            s.faulted.store(true, Ordering::Release);
            return;
        }
        break;
    }
    // Not a guarded mapping: what would have happened without us.
    let previous = &installed.previous;
    let handler = previous.sa_sigaction;
    if handler == libc::SIG_DFL || handler == libc::SIG_IGN {
        return default_action(signal);
    }
    // SAFETY: a handler someone installed before us, called as it was
    // registered to be called (with SA_SIGINFO, the three-argument form).
    unsafe {
        if previous.sa_flags & libc::SA_SIGINFO != 0 {
            let f: extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void) =
                std::mem::transmute(handler);
            f(signal, info, context);
        } else {
            let f: extern "C" fn(libc::c_int) = std::mem::transmute(handler);
            f(signal);
        }
    }
}

/// Restores the default disposition and returns: the faulting access is
/// retried and the default action (ending the process) happens.
fn default_action(signal: libc::c_int) {
    // SAFETY: signal() with SIG_DFL is async-signal-safe on Linux.
    unsafe {
        libc::signal(signal, libc::SIG_DFL);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_are_claimed_and_given_back() {
        let a = Guard::new(0x1000, 0x2000).unwrap();
        let b = Guard::new(0x5000, 0x1000).unwrap();
        assert_ne!(a.slot, b.slot);
        assert!(!a.faulted() && !b.faulted());
        drop(a);
        let c = Guard::new(0x9000, 0x1000).unwrap();
        assert_eq!(TABLE[c.slot].end.load(Ordering::Acquire), 0xa000);
        assert!(Guard::new(usize::MAX, 2).is_err());
    }

    // What the handler does with a SIGBUS outside every guarded range can
    // only be seen in a process it may end, so each case below runs in a
    // child: the test binary itself, re-run with `CHILD` naming the case
    // and a filter selecting the same test. The child maps a file of three
    // pages, cuts the file to nothing, guards page 0 and reads it (zeros,
    // caught), then reads page 2 (unguarded): a real SIGBUS, with the
    // faulting address in `si_addr`, that the guard hands on. The parent
    // judges the child by how it ended.

    /// The environment variable that makes a test its own child.
    const CHILD: &str = "VOLRAY_SIGBUS_CHILD";

    /// Exit codes of the child: the earlier handler ran, for the read it
    /// should have seen (`si_addr` on page 2, after the guarded read of
    /// page 0 succeeded); and every way it can go wrong.
    const CHAINED: i32 = 42;
    const WRONG_ADDRESS: i32 = 43;
    const BEFORE_GUARDED_READ: i32 = 44;
    const SURVIVED: i32 = 45;

    /// Where page 2 of the child's mapping starts, the page size, and
    /// whether the guarded read of page 0 is done: read by the earlier
    /// handlers.
    static PAGE_2: AtomicUsize = AtomicUsize::new(0);
    static PAGE: AtomicUsize = AtomicUsize::new(0);
    static GUARDED_READ_DONE: AtomicBool = AtomicBool::new(false);

    /// An earlier handler installed with `SA_SIGINFO`: ends the process
    /// with [`CHAINED`] if it is handed the fault it should see.
    extern "C" fn earlier_siginfo(
        _signal: libc::c_int,
        info: *mut libc::siginfo_t,
        _context: *mut libc::c_void,
    ) {
        // SAFETY: called as a SA_SIGINFO handler (by the kernel or by the
        // guard passing its own arguments on), so `info` is a valid
        // siginfo_t; `_exit` is async-signal-safe.
        unsafe {
            let addr = (*info).si_addr() as usize;
            let page = PAGE_2.load(Ordering::Acquire);
            let size = PAGE.load(Ordering::Acquire);
            libc::_exit(if !GUARDED_READ_DONE.load(Ordering::Acquire) {
                BEFORE_GUARDED_READ
            } else if addr >= page && addr < page + size {
                CHAINED
            } else {
                WRONG_ADDRESS
            });
        }
    }

    /// An earlier handler of the one-argument form (no `SA_SIGINFO`).
    extern "C" fn earlier_plain(_signal: libc::c_int) {
        // SAFETY: `_exit` is async-signal-safe.
        unsafe {
            libc::_exit(if GUARDED_READ_DONE.load(Ordering::Acquire) {
                CHAINED
            } else {
                BEFORE_GUARDED_READ
            });
        }
    }

    /// Sets SIGBUS's disposition before the guard is installed.
    fn set_earlier(handler: usize, flags: libc::c_int) {
        // SAFETY: a zeroed sigaction is valid (empty mask, no flags);
        // `handler` is SIG_DFL, SIG_IGN or one of the functions above,
        // whose signature matches `flags`; the structure outlives the call.
        let done = unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = handler;
            action.sa_flags = flags;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(libc::SIGBUS, &action, std::ptr::null_mut())
        };
        assert_eq!(done, 0, "sigaction: {}", std::io::Error::last_os_error());
    }

    /// The child's side: `case` says what SIGBUS's disposition is before
    /// the guard is installed ("std" leaves the one Rust's runtime
    /// installs at start-up, for stack overflows).
    fn child(case: &str) -> ! {
        // A core dump of the child killed on purpose is noise.
        let no_core = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: a valid rlimit, read by the call only.
        unsafe { libc::setrlimit(libc::RLIMIT_CORE, &no_core) };
        match case {
            "siginfo" => set_earlier(earlier_siginfo as *const () as usize, libc::SA_SIGINFO),
            "plain" => set_earlier(earlier_plain as *const () as usize, 0),
            "default" => set_earlier(libc::SIG_DFL, 0),
            "ignored" => set_earlier(libc::SIG_IGN, 0),
            "std" => {}
            other => panic!("unknown case {other}"),
        }
        // SAFETY: sysconf has no preconditions.
        let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) } as usize;
        PAGE.store(page, Ordering::Release);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cut.raw");
        std::fs::write(&path, vec![7u8; 3 * page]).unwrap();
        let file = std::fs::File::open(&path).unwrap();
        // SAFETY: nobody else knows of this file; it is cut below on
        // purpose, and reads past its end are what is tested.
        let map = unsafe { memmap2::Mmap::map(&file) }.unwrap();
        let base = map.as_ptr() as usize;
        PAGE_2.store(base + 2 * page, Ordering::Release);
        std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .unwrap()
            .set_len(0)
            .unwrap();
        let guard = Guard::new(base, page).unwrap();
        // SAFETY: inside the live mapping; page 0 is guarded.
        let first = unsafe { std::ptr::read_volatile(map.as_ptr()) };
        assert_eq!((first, guard.faulted()), (0, true));
        GUARDED_READ_DONE.store(true, Ordering::Release);
        // SAFETY: inside the live mapping, past the file's end and outside
        // the guarded range: SIGBUS, which is what this child is for.
        let _ = unsafe { std::ptr::read_volatile(map.as_ptr().add(2 * page)) };
        std::process::exit(SURVIVED);
    }

    /// Runs `case` in a child (this test binary, filtered to the test
    /// `test`), giving how it ended.
    fn run_child(test: &str, case: &str) -> std::process::Output {
        let module = module_path!().split_once("::").unwrap().1;
        let output = std::process::Command::new(std::env::current_exe().unwrap())
            .args([&format!("{module}::{test}"), "--exact", "--nocapture"])
            .env(CHILD, case)
            .output()
            .unwrap();
        // The child must have run the case, not filtered it away.
        assert!(
            !String::from_utf8_lossy(&output.stdout).contains("running 0 tests"),
            "{test} not found"
        );
        output
    }

    fn describe(output: &std::process::Output) -> String {
        format!(
            "{:?}\n{}{}",
            output.status,
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        )
    }

    #[test]
    fn a_sigbus_outside_every_guard_goes_to_the_handler_installed_before() {
        if let Ok(case) = std::env::var(CHILD) {
            child(&case);
        }
        let test = "a_sigbus_outside_every_guard_goes_to_the_handler_installed_before";
        for case in ["siginfo", "plain"] {
            let output = run_child(test, case);
            assert_eq!(
                output.status.code(),
                Some(CHAINED),
                "{case}: {}",
                describe(&output)
            );
        }
    }

    #[test]
    fn a_sigbus_outside_every_guard_without_a_handler_before_ends_the_process() {
        use std::os::unix::process::ExitStatusExt;
        if let Ok(case) = std::env::var(CHILD) {
            child(&case);
        }
        let test = "a_sigbus_outside_every_guard_without_a_handler_before_ends_the_process";
        // SIG_IGN cannot ignore a fault: the kernel delivers it with the
        // default action, and so does the guard.
        for case in ["default", "ignored", "std"] {
            let output = run_child(test, case);
            assert_eq!(
                output.status.signal(),
                Some(libc::SIGBUS),
                "{case}: {}",
                describe(&output)
            );
        }
    }
}
