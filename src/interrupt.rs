//! Ctrl-C (SIGINT), SIGTERM and SIGHUP: the process deletes the temporary
//! files of the outputs it is still writing, then exits with 128 + the
//! signal's number (130 for Ctrl-C), as shells report a process a signal
//! stopped. Without this the default action kills the process at once and
//! leaves `.out.png.XXXX.tmp` files behind, since destructors never run.
//!
//! The signals are caught by `signal-hook`, which turns them into messages
//! to a thread of ours: the deleting happens there, outside the signal
//! handler, where taking a lock and calling the file system are allowed.

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
            if let Some(signal) = signals.forever().next() {
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
