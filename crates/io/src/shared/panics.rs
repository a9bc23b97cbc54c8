//! Panics inside third-party decoders, turned into errors without a word
//! of panic text, and every other panic still loud.
//!
//! The readers run code that may panic on corrupt input (jpeg-decoder,
//! openjp2, dicom-pixeldata's RLE, the DICOM parser): [`guarded`] runs it
//! under `catch_unwind` and the reader turns a panic into its one-line
//! error. But a panic hook runs *before* unwinding, where it cannot know
//! whether a `catch_unwind` will catch: Rust's default hook prints
//! `thread 'main' panicked at …` and a backtrace note for a panic that is
//! then caught and recovered from, and a hook that ends an MPI job
//! (`MPI_Abort`) would end it for a panic the reader recovers from.
//!
//! So [`guarded`] marks the thread while its closure runs, and installs,
//! once, a hook that keeps quiet for a panic on a marked thread and hands
//! every other panic to the hook it replaced (Rust's default message, or
//! a front end's own). Every front end (the command line, the Python
//! module, the viewer) gets this without doing anything. A front end that
//! must end something on a bug (`mpirun`: every rank) does so after the
//! panic has unwound to its top (volray-app's `distributed::ranked`), never in a hook.
//!
//! volray's own decoders (`dicom/jpegls.rs`) are not run through it: a
//! panic there is volray's bug, and shows. A decoder that hands work to
//! threads of its own would panic on those threads, which are not marked,
//! and loudly (none of the decoders used here does).

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;

thread_local! {
    /// How many [`guarded`] calls this thread is inside (they may nest).
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

/// Runs `f`, returning `Err` with the panic's payload if it panics, with
/// no panic text printed for it.
pub fn guarded<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
    /// Unmarks the thread however `f` ends.
    struct Unmark;
    impl Drop for Unmark {
        fn drop(&mut self) {
            DEPTH.with(|d| d.set(d.get().saturating_sub(1)));
        }
    }
    install_quiet_hook();
    DEPTH.with(|d| d.set(d.get() + 1));
    let _unmark = Unmark;
    catch_unwind(AssertUnwindSafe(f))
}

/// Whether this thread is inside [`guarded`], where a panic is caught
/// and becomes an error.
pub fn is_guarded() -> bool {
    DEPTH.with(|d| d.get() > 0)
}

/// Sets, once, the hook that is silent inside [`guarded`] and otherwise
/// runs the hook it replaced.
fn install_quiet_hook() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let before = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !is_guarded() {
                before(info);
            }
        }));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_guarded_panic_is_returned_and_the_mark_ends_with_the_call() {
        let caught = guarded(|| -> u32 { panic!("corrupt stream") });
        let payload = caught.expect_err("the panic is returned");
        assert_eq!(payload.downcast_ref::<&str>(), Some(&"corrupt stream"));
        assert!(!is_guarded(), "the mark ends with the call");

        // Nested: the inner panic is caught, the outer call goes on,
        // still marked until it ends.
        let nested = guarded(|| (guarded(|| panic!("inner")).is_err(), is_guarded()));
        assert!(matches!(nested, Ok((true, true))));
        assert!(!is_guarded());
        assert_eq!(guarded(|| 7).ok(), Some(7));
    }

    #[test]
    fn marks_are_per_thread() {
        let other = guarded(|| std::thread::spawn(is_guarded).join().unwrap());
        assert!(matches!(other, Ok(false)), "another thread is not marked");
    }
}
