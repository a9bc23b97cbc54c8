//! Opening the page in a browser, when there is a display to show it on:
//! `open` on macOS, `xdg-open` where X11 or Wayland runs. Never an error:
//! the URL is printed anyway, and a login node without a display is the
//! usual case (the page is then opened through an SSH tunnel).
//!
//! The page's URL carries its access token (`?token=…`), and a program's
//! arguments are readable by every user of the machine (`ps`, `/proc`): on
//! a shared login node, handing the URL to `xdg-open` (and so to the
//! browser's command line) would give the token away. So the opener is
//! given a file instead, as Jupyter does: a page that only redirects to
//! the URL, in a folder of this user's alone (0700), readable by this user
//! alone (0600), removed when the viewer stops.

use std::fs::{DirBuilder, OpenOptions};
use std::io::Write;
#[cfg(unix)]
use std::os::unix::fs::{DirBuilderExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The redirect page, removed (with its folder) when dropped.
pub struct Redirect {
    dir: PathBuf,
    file: PathBuf,
}

impl Redirect {
    /// Writes a page that sends the browser on to `url`, readable by this
    /// user alone, in a new folder under `parent`.
    pub fn write(parent: &Path, url: &str) -> std::io::Result<Self> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let dir = parent.join(format!("volray-view-{}-{nanos}", std::process::id()));
        // create, not create_all: a folder someone else made there (or a
        // link to one) is an error, never used.
        let mut builder = DirBuilder::new();
        #[cfg(unix)]
        builder.mode(0o700);
        builder.create(&dir)?;
        let file = dir.join("open.html");
        let redirect = Self { dir, file };
        let mut options = OpenOptions::new();
        options.write(true).create_new(true);
        #[cfg(unix)]
        options.mode(0o600);
        let mut out = options.open(&redirect.file)?;
        let url = html_escape(url);
        write!(
            out,
            "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">\n\
             <meta http-equiv=\"refresh\" content=\"0;url={url}\">\n\
             <title>volray view</title></head>\n\
             <body><p>Opening <a href=\"{url}\">the volray viewer</a>…</p></body></html>\n"
        )?;
        Ok(redirect)
    }

    /// The page's `file://` URL: what the opener is given.
    pub fn url(&self) -> String {
        format!("file://{}", self.file.display())
    }
}

impl Drop for Redirect {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.file);
        let _ = std::fs::remove_dir(&self.dir);
    }
}

/// Tries to open `url` (a token URL) through a redirect page; says nothing
/// whether it worked or not. The page lives as long as what this returns.
pub fn open(url: &str) -> Option<Redirect> {
    let opener = opener()?;
    // $XDG_RUNTIME_DIR is this user's alone where it is set; the folder
    // made in either place is 0700 anyway.
    let parent = std::env::var_os("XDG_RUNTIME_DIR")
        .map(PathBuf::from)
        .filter(|p| p.is_dir())
        .unwrap_or_else(std::env::temp_dir);
    let redirect = Redirect::write(&parent, url).ok()?;
    // Detached: the child is never waited for and its output is dropped.
    let _ = Command::new(opener)
        .arg(redirect.url())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn();
    Some(redirect)
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

/// `s` safe inside an HTML attribute.
fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    #[test]
    fn the_redirect_page_is_this_users_alone_and_goes_away_with_the_viewer() {
        let parent = std::env::temp_dir();
        let url = "http://127.0.0.1:8080/?token=abc&x=1";
        let redirect = Redirect::write(&parent, url).unwrap();
        let (dir, file) = (redirect.dir.clone(), redirect.file.clone());
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&dir), 0o700);
        assert_eq!(mode(&file), 0o600);
        let html = std::fs::read_to_string(&file).unwrap();
        assert!(html.contains("url=http://127.0.0.1:8080/?token=abc&amp;x=1\""));
        assert!(!redirect.url().contains("token"));
        drop(redirect);
        assert!(!file.exists() && !dir.exists());
    }
}
