//! Opening the page in a browser, when there is a display to show it on:
//! `open` on macOS, `xdg-open` where X11 or Wayland runs. Never an error:
//! the URL is printed anyway, and a login node without a display is the
//! usual case (the page is then opened through an SSH tunnel).

use std::process::{Command, Stdio};

/// Tries to open `url`; says nothing whether it worked or not.
pub fn open(url: &str) {
    let Some(opener) = opener() else {
        return;
    };
    // Detached: the child is never waited for and its output is dropped.
    let _ = Command::new(opener)
        .arg(url)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn();
}

/// The program that opens URLs here, if there is a display.
fn opener() -> Option<&'static str> {
    if cfg!(target_os = "macos") {
        return Some("open");
    }
    let display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|var| std::env::var_os(var).is_some_and(|v| !v.is_empty()));
    (cfg!(unix) && display).then_some("xdg-open")
}
