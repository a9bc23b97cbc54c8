//! A movie encoded by ffmpeg (Debian's `ffmpeg`) as its frames come: raw
//! RGB frames piped to its standard input (`-f rawvideo -pix_fmt rgb24
//! -s WxH -r FPS -i -`), so no frame is held longer than it takes to
//! encode and nothing is written to disk twice (the napari-animation
//! lesson: its #115, three days for frames that ffmpeg, fed directly,
//! wrote in ten minutes).
//!
//! - `.mp4`: H.264 (libx264), `yuv420p` so that every player shows it,
//!   at a constant rate factor (`crf`, default 16: every frame of the check in scripts/movie-check.sh at ≥ 40 dB PSNR against its still); `.webm`: VP9 (libvpx),
//!   the same. 4:2:0 chroma halves each side, so the frame's sides must
//!   be even: an odd size is refused (not padded: a padded frame
//!   would not be the frame a still render gives).
//! - The movie is written to a temporary file beside the output, listed
//!   in the registry of unfinished files (so Ctrl-C deletes it), and renamed into
//!   place only once ffmpeg has finished well: a failed or interrupted
//!   run leaves nothing. ffmpeg writes through its standard output's
//!   file (`/dev/stdout`: the temporary file's own inode,
//!   so a ffmpeg still running after volray was stopped cannot create
//!   the file again under its name).
//! - ffmpeg's messages are kept (`-loglevel error`, read by a thread so
//!   the pipe never fills) and shown in one line if it fails; if it dies,
//!   the next frame's write fails and rendering stops.

use crate::AtomicFile;
use crate::error::IoError;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::thread::JoinHandle;

/// The container and codec an output name asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Codec {
    /// `.mp4`: H.264.
    Mp4,
    /// `.webm`: VP9.
    Webm,
}

impl Codec {
    /// The codec of an output name, if it is a movie ffmpeg writes.
    pub fn of(path: &Path) -> Option<Codec> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "mp4" => Some(Codec::Mp4),
            "webm" => Some(Codec::Webm),
            _ => None,
        }
    }

    /// ffmpeg's words for the codec at `crf`, and the container.
    fn args(self, crf: u8) -> Vec<String> {
        let crf = crf.to_string();
        let words: Vec<&str> = match self {
            Codec::Mp4 => vec![
                "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", &crf, "-f", "mp4",
            ],
            Codec::Webm => vec![
                "-c:v",
                "libvpx-vp9",
                "-pix_fmt",
                "yuv420p",
                "-crf",
                &crf,
                "-b:v",
                "0",
                "-f",
                "webm",
            ],
        };
        words.into_iter().map(String::from).collect()
    }
}

/// The `--crf` when none is given.
pub const DEFAULT_CRF: u8 = 16;

/// Where ffmpeg writes: its standard output's file, opened again by
/// name (seekable, as MP4's index needs; `pipe:1` is not).
const OWN_OUTPUT: &str = "/dev/stdout";

/// The program run: `ffmpeg`, found on `PATH`.
const FFMPEG: &str = "ffmpeg";

/// A movie being encoded.
pub struct Encoder {
    path: PathBuf,
    child: Child,
    stdin: Option<ChildStdin>,
    stderr: Option<JoinHandle<String>>,
    file: Option<AtomicFile>,
    frame_bytes: usize,
}

impl Encoder {
    /// Starts ffmpeg encoding `width` × `height` frames at `fps` into
    /// `path`, or says why it cannot (ffmpeg missing; an odd size).
    pub fn start(
        path: &Path,
        codec: Codec,
        (width, height): (usize, usize),
        fps: f64,
        crf: u8,
    ) -> Result<Self, IoError> {
        check_size(path, width, height)?;
        let mut file = AtomicFile::create(path)?;
        let out = file
            .file()
            .try_clone()
            .map_err(|e| IoError::os(path, "write", e))?;
        let mut command = Command::new(FFMPEG);
        command
            .args(["-hide_banner", "-loglevel", "error", "-f", "rawvideo"])
            .args(["-pix_fmt", "rgb24", "-s", &format!("{width}x{height}")])
            .args(["-r", &format!("{fps}"), "-i", "-", "-an"])
            .args(codec.args(crf))
            .arg("-y")
            .arg(OWN_OUTPUT)
            .stdin(Stdio::piped())
            .stdout(Stdio::from(out))
            .stderr(Stdio::piped());
        let mut child = command.spawn().map_err(|e| not_started(path, e))?;
        let stdin = child.stdin.take();
        let stderr = child.stderr.take().map(|mut err| {
            std::thread::spawn(move || {
                let mut text = String::new();
                // Read to the end whatever it says; bounded by what
                // ffmpeg writes at -loglevel error.
                let _ = err.read_to_string(&mut text);
                text
            })
        });
        Ok(Encoder {
            path: path.to_path_buf(),
            child,
            stdin,
            stderr,
            file: Some(file),
            frame_bytes: width * height * 3,
        })
    }

    /// Sends the next frame, `rgb` 8-bit RGB rows top to bottom.
    pub fn push(&mut self, rgb: &[u8]) -> Result<(), IoError> {
        assert_eq!(rgb.len(), self.frame_bytes, "a frame of the movie's size");
        let stdin = self.stdin.as_mut().expect("open until finish");
        if stdin.write_all(rgb).is_err() {
            // ffmpeg is gone: its exit and messages say why.
            self.stdin = None;
            let _ = self.child.wait();
            return Err(self.failure("stopped before the last frame"));
        }
        Ok(())
    }

    /// Ends the input, waits for ffmpeg and publishes the movie.
    pub fn finish(mut self) -> Result<(), IoError> {
        drop(self.stdin.take());
        let status = self
            .child
            .wait()
            .map_err(|e| failed(&self.path, format!("ffmpeg: {e}")))?;
        if !status.success() {
            return Err(self.failure(&format!("failed ({status})")));
        }
        let file = self.file.take().expect("committed once");
        file.commit()?;
        Ok(())
    }

    /// ffmpeg's failure in one line: what happened and what it said.
    fn failure(&mut self, what: &str) -> IoError {
        let said = self
            .stderr
            .take()
            .and_then(|t| t.join().ok())
            .unwrap_or_default();
        let said: Vec<&str> = said
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        let said = if said.is_empty() {
            String::new()
        } else {
            format!(": {}", said.join("; "))
        };
        failed(&self.path, format!("ffmpeg {what}{said}"))
    }
}

impl Drop for Encoder {
    /// An unfinished movie: ffmpeg stopped, the temporary file deleted
    /// (by the `AtomicFile`).
    fn drop(&mut self) {
        if self.file.is_some() {
            drop(self.stdin.take());
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// An encoding that failed, in one line naming the movie: an I/O failure.
fn failed(path: &Path, message: String) -> IoError {
    IoError::os(path, "write", std::io::Error::other(message))
}

/// Why ffmpeg did not start, in one line.
fn not_started(path: &Path, e: std::io::Error) -> IoError {
    match e.kind() {
        std::io::ErrorKind::NotFound => failed(
            path,
            "writing a movie needs ffmpeg, which is not on PATH (Debian: apt-get install ffmpeg); or write .gif, .png (animated) or numbered PNGs (frame_%05d.png)".into(),
        ),
        _ => failed(path, format!("cannot start ffmpeg: {e}")),
    }
}

/// Refuses, before any frame is rendered, a movie ffmpeg cannot write
/// because it is not there (a resumable movie starts ffmpeg only once
/// every frame is kept).
pub fn check_available(path: &Path) -> Result<(), IoError> {
    Command::new(FFMPEG)
        .arg("-version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map(|_| ())
        .map_err(|e| not_started(path, e))
}

/// 4:2:0 chroma needs even sides.
pub fn check_size(path: &Path, width: usize, height: usize) -> Result<(), IoError> {
    if width % 2 == 1 || height % 2 == 1 {
        return Err(IoError::invalid(
            path,
            format!(
                "frames of {width}x{height}: a movie's frames have even sides (H.264 and VP9 at 4:2:0 halve the colour's resolution); e.g. {}x{}",
                width + width % 2,
                height + height % 2
            ),
        ));
    }
    Ok(())
}
