//! Ctrl-C (SIGINT), SIGTERM and SIGHUP: the process deletes the temporary
//! files of the outputs it is still writing, then exits with 128 + the
//! signal's number (130 for Ctrl-C), as shells report a process a signal
//! stopped. Without this the default action kills the process at once and
//! leaves `.out.png.XXXX.tmp` files behind, since destructors never run.
//!
//! The signals are caught by `signal-hook`, which turns them into messages
//! to a thread of ours: the deleting happens there, outside the signal
//! handler, where taking a lock and calling the file system are allowed.
//!
//! A command that serves until it is stopped (`volray view`) registers a
//! stop with [`stop_instead`]: the first signal then runs it, and the
//! command ends as it finishes, with exit 0; a second signal exits as
//! above, in case stopping hangs.

use std::sync::Mutex;

/// What the next signal does instead of exiting.
type Stop = Box<dyn FnOnce() + Send>;
static STOP: Mutex<Option<Stop>> = Mutex::new(None);

/// Makes the next signal call `stop` instead of ending the process.
#[cfg_attr(not(unix), allow(dead_code))]
pub fn stop_instead(stop: impl FnOnce() + Send + 'static) {
    *STOP.lock().unwrap_or_else(|e| e.into_inner()) = Some(Box::new(stop));
}

/// The registered stop, taken (it runs once).
#[cfg_attr(not(unix), allow(dead_code))]
fn take_stop() -> Option<Stop> {
    STOP.lock().unwrap_or_else(|e| e.into_inner()).take()
}

/// Starts the thread that answers the signals. If it cannot be started the
/// signals keep their default action (the process dies at once, possibly
/// leaving a temporary file): worth a warning, not worth refusing to work.
#[cfg(unix)]
pub fn install() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    use signal_hook::iterator::Signals;

    let mut signals = match Signals::new([SIGINT, SIGTERM, SIGHUP]) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("volray: warning: cannot catch Ctrl-C: {e}");
            return;
        }
    };
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for signal in signals.forever() {
                if let Some(stop) = take_stop() {
                    stop();
                    continue;
                }
                // Holds the registry's lock until the exit, so no other
                // thread publishes or starts a file in between.
                volray_io::remove_unfinished_files();
                eprintln!("volray: interrupted");
                std::process::exit(128 + signal);
            }
        });
    if let Err(e) = spawned {
        eprintln!("volray: warning: cannot catch Ctrl-C: {e}");
    }
}

/// Elsewhere the signals keep their default action.
#[cfg(not(unix))]
pub fn install() {}
