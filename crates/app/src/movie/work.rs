//! The finished frames of a resumable movie (`--resume`, `--movie-frames`):
//! a work folder beside the output, `OUTPUT.frames/`, holding each frame
//! as a lossless 8-bit RGB PNG (`000012.png`, written atomically, so a
//! frame there is whole) and `run.json`, what the run was (its command
//! words, the keyframes file's text, the frame count and size), so that
//! a run resumes only its own frames. A PNG-sequence output keeps its
//! frames as its own files (written once, never again); the folder then
//! holds a marker per finished frame (`000012.done`), so that files an
//! earlier, different run left are not taken for finished frames.
//! The folder is deleted once the movie is complete.

use crate::AppError;
use std::path::{Path, PathBuf};
use volray_core::Image;

/// The work folder of a movie.
pub struct Work {
    dir: PathBuf,
    /// A PNG sequence's pattern: its frames are its own files.
    sequence: Option<PathBuf>,
    size: (usize, usize),
}

impl Work {
    /// Opens (or starts) the work folder of `output`, which `identity`
    /// describes; refuses one another run left.
    pub fn open(
        output: &Path,
        identity: &str,
        sequence: bool,
        size: (usize, usize),
    ) -> Result<Work, AppError> {
        let mut name = output.file_name().unwrap_or_default().to_os_string();
        name.push(".frames");
        let dir = output.with_file_name(name);
        let io = |e: std::io::Error| failed(format!("{}: {e}", dir.display()));
        let run = dir.join("run.json");
        if dir.is_dir() && run.exists() {
            let earlier = std::fs::read_to_string(&run).unwrap_or_default();
            if earlier != identity {
                return Err(AppError::Refused {
                    message: format!(
                        "{}: holds the frames of another command (another input, keyframes file, size or options): delete it to start this movie over",
                        dir.display()
                    ),
                    bad_input: true,
                });
            }
        } else {
            // A folder without its run.json was stopped as it was made.
            if !dir.is_dir() {
                std::fs::create_dir(&dir).map_err(io)?;
            }
            volray_io::write_atomically(&run, |w| w.write_all(identity.as_bytes()))?;
        }
        Ok(Work {
            dir,
            sequence: sequence.then(|| output.to_path_buf()),
            size,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn frame_file(&self, k: usize) -> PathBuf {
        self.dir.join(format!("{k:06}.png"))
    }

    fn marker(&self, k: usize) -> PathBuf {
        self.dir.join(format!("{k:06}.done"))
    }

    /// Whether frame `k` is finished.
    pub fn has(&self, k: usize) -> bool {
        match &self.sequence {
            Some(_) => self.marker(k).is_file(),
            None => self.frame_file(k).is_file(),
        }
    }

    /// Keeps frame `k`: a sequence's file (as the sequence writes it),
    /// then its marker; else the lossless frame in the folder.
    pub fn save(&self, k: usize, image: &Image, rgb: &[u8]) -> Result<(), AppError> {
        match &self.sequence {
            Some(pattern) => {
                let file = volray_io::sequence_path(pattern, k).expect("a sequence's pattern");
                volray_io::write_png(&file, image, volray_io::BitDepth::Eight)?;
                volray_io::write_atomically(&self.marker(k), |_| Ok(()))?;
            }
            None => {
                let (w, h) = self.size;
                volray_io::write_atomically(&self.frame_file(k), |out| {
                    let mut encoder = png::Encoder::new(out, w as u32, h as u32);
                    encoder.set_color(png::ColorType::Rgb);
                    encoder.set_depth(png::BitDepth::Eight);
                    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
                    writer
                        .write_image_data(rgb)
                        .map_err(std::io::Error::other)?;
                    writer.finish().map_err(std::io::Error::other)
                })?;
            }
        }
        Ok(())
    }

    /// Frame `k` as 8-bit RGB, read back (not for a sequence, whose
    /// frames are the output already).
    pub fn load(&self, k: usize) -> Result<Vec<u8>, AppError> {
        let path = self.frame_file(k);
        let bad = |why: String| failed(format!("{}: {why}", path.display()));
        let file = std::fs::File::open(&path).map_err(|e| bad(e.to_string()))?;
        let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
        decoder.set_transformations(png::Transformations::IDENTITY);
        let mut reader = decoder.read_info().map_err(|e| bad(e.to_string()))?;
        let info = reader.info();
        let (w, h) = self.size;
        if (info.width as usize, info.height as usize) != (w, h)
            || info.color_type != png::ColorType::Rgb
            || info.bit_depth != png::BitDepth::Eight
        {
            return Err(bad(format!(
                "not a {w}x{h} 8-bit RGB frame of this movie: delete the folder to start over"
            )));
        }
        let mut rgb = vec![0; w * h * 3];
        reader
            .next_frame(&mut rgb)
            .map_err(|e| bad(e.to_string()))?;
        Ok(rgb)
    }

    /// Deletes the folder: the movie is complete.
    pub fn remove(self) -> Result<(), AppError> {
        std::fs::remove_dir_all(&self.dir)
            .map_err(|e| failed(format!("{}: {e}", self.dir.display())))
    }
}

/// A failure of the work folder's files: an I/O failure.
fn failed(message: String) -> AppError {
    AppError::Refused {
        message,
        bad_input: false,
    }
}

/// What a run is, for its work folder: the command's words `words`
/// (less those that choose which frames or how many threads, which change
/// no pixel), the keyframes file's text, the frame count and size.
pub fn identity_of(words: &[String], keys: &str, frames: usize, size: (usize, usize)) -> String {
    let mut kept = Vec::new();
    let mut skip = false;
    for word in words {
        if std::mem::take(&mut skip) {
            continue;
        }
        match word.as_str() {
            "--resume" => {}
            "--movie-frames" | "--threads" => skip = true,
            w if w.starts_with("--movie-frames=") || w.starts_with("--threads=") => {}
            _ => kept.push(word),
        }
    }
    serde_json::json!({
        "version": 1,
        "command": kept,
        "keyframes": keys,
        "frames": frames,
        "size": [size.0, size.1],
    })
    .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(text: &str) -> Vec<String> {
        text.split(' ').map(String::from).collect()
    }

    #[test]
    fn a_run_is_its_words_less_those_that_change_no_pixel() {
        let id = |text: &str| identity_of(&words(text), "{}", 24, (64, 48));
        let plain = id("render a.nii --keyframes k.json -o m.mp4");
        assert_eq!(
            id("render a.nii --resume --keyframes k.json -o m.mp4 --threads 2"),
            plain
        );
        assert_eq!(
            id("render a.nii --movie-frames 0:12 --keyframes k.json -o m.mp4"),
            plain
        );
        assert_eq!(
            id("render a.nii --movie-frames=3: --threads=1 --keyframes k.json -o m.mp4"),
            plain
        );
        assert_ne!(
            id("render a.nii --zoom 2 --keyframes k.json -o m.mp4"),
            plain
        );
        assert_ne!(
            identity_of(
                &words("render a.nii --keyframes k.json -o m.mp4"),
                "{}",
                25,
                (64, 48)
            ),
            plain
        );
    }
}
