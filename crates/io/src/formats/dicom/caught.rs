//! Third-party decoders run with their panics caught and kept quiet.
//!
//! `dicom-object`'s parser, `dicom-pixeldata` (RLE), `jpeg-decoder` and
//! `openjp2` can panic on some corrupt input (their own index arithmetic
//! on stream-controlled values). [`catch_unwind`] turns such a panic into
//! an error, but the default panic hook has printed `thread 'main'
//! panicked at ...` and a backtrace hint by then, before volray's one-line
//! error (issue 41). [`quietly`] installs, once, a hook that passes every
//! panic to the hook it replaces except those raised on a thread while it
//! is inside [`quietly`]. volray's own decoder (`jpegls.rs`) is not run
//! through it: a panic there is volray's bug, and should show.

use std::cell::Cell;
use std::panic::{self, AssertUnwindSafe, catch_unwind};
use std::sync::Once;

thread_local! {
    /// Whether this thread is inside [`quietly`].
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`; a panic inside it is `None`, with nothing printed.
pub(super) fn quietly<T>(f: impl FnOnce() -> T) -> Option<T> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    result.ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_is_none_and_the_flag_is_restored() {
        assert_eq!(quietly(|| 7), Some(7));
        let none: Option<()> = quietly(|| panic!("a corrupt stream"));
        assert_eq!(none, None);
        // Nested: the inner call leaves the outer one quiet.
        assert_eq!(
            quietly(|| quietly(|| 1).map(|v| v + QUIET.with(Cell::get) as i32)),
            Some(Some(2))
        );
        assert!(!QUIET.with(Cell::get));
    }
}
