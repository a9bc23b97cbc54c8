//! Animations: frames written one at a time as an animated PNG, a GIF or a
//! numbered PNG sequence, so a turntable of a thousand frames never has to
//! fit in memory.
//!
//! The kind comes from the output path: a name with a printf-style frame
//! number (`turn_%03d.png`, `f%d.png`) is a PNG sequence, `.png` an
//! animated PNG (APNG, which browsers play and plain PNG readers show as
//! its first frame), `.gif` a looping GIF (256 colours per frame, chosen
//! by NeuQuant). Nothing appears at the output until
//! [`Animation::finish`]: a failed or abandoned animation leaves no file
//! (a sequence keeps its frames as temporary files and renames them all
//! at the end, so an interrupted run leaves none of them).

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use volray_core::Image;

use crate::atomic::{AtomicFile, PendingFile, publish_all};
use crate::error::IoError;
use crate::images::png::{BitDepth, quantize_8, write_png_pending};

/// How an animation is stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AnimationKind {
    /// One animated PNG file.
    Apng,
    /// One looping GIF file.
    Gif,
    /// One PNG per frame; the pattern holds a printf-style `%d` / `%0Nd`.
    PngSequence,
}

impl AnimationKind {
    /// The kind `path` names, or `None` for an extension that is not an
    /// animation format.
    pub fn from_path(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_str()?;
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "png" if frame_pattern(name).is_some() => Some(AnimationKind::PngSequence),
            "png" | "apng" => Some(AnimationKind::Apng),
            "gif" => Some(AnimationKind::Gif),
            _ => None,
        }
    }
}

/// The printf-style frame number in a file name: (prefix, width, suffix).
fn frame_pattern(name: &str) -> Option<(String, usize, String)> {
    let at = name.find('%')?;
    let rest = &name[at + 1..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    let after = &rest[digits.len()..];
    let suffix = after.strip_prefix('d')?;
    let width = if digits.is_empty() {
        0
    } else {
        digits.parse().ok()?
    };
    Some((name[..at].to_string(), width, suffix.to_string()))
}

/// The file of frame `index` of a PNG sequence `pattern`.
pub fn sequence_path(pattern: &Path, index: usize) -> Option<PathBuf> {
    let name = pattern.file_name()?.to_str()?;
    let (prefix, width, suffix) = frame_pattern(name)?;
    Some(pattern.with_file_name(format!("{prefix}{index:0width$}{suffix}")))
}

enum Sink {
    Apng(Box<png::Writer<BufWriter<File>>>, AtomicFile),
    Gif(Box<gif::Encoder<BufWriter<File>>>, AtomicFile),
    /// The frames written so far, published together by `finish`.
    Sequence(Vec<PendingFile>),
}

/// An animation being written.
pub struct Animation {
    path: PathBuf,
    width: usize,
    height: usize,
    frames: usize,
    written: usize,
    delay_centis: u16,
    sink: Sink,
}

impl Animation {
    /// Starts an animation of `frames` frames of `width` × `height` at
    /// `fps` frames per second, stored as `path` names (see the module
    /// docs).
    pub fn create(
        path: &Path,
        width: usize,
        height: usize,
        frames: usize,
        fps: f64,
    ) -> Result<Self, IoError> {
        let kind = AnimationKind::from_path(path).ok_or_else(|| {
            IoError::invalid(
                path,
                "an animation is written as .png (animated PNG), .gif, or a PNG sequence named with %d (e.g. turn_%03d.png)",
            )
        })?;
        if !(fps.is_finite() && fps > 0.0 && fps <= 100.0) {
            return Err(IoError::invalid(
                path,
                format!("frame rate {fps} must be in (0, 100] frames per second"),
            ));
        }
        let side = |n: usize| (1..=u16::MAX as usize).contains(&n);
        if frames == 0 || !side(width) || !side(height) {
            return Err(IoError::ImageSize {
                path: path.to_path_buf(),
                width,
                height,
            });
        }
        let to_io = |e: std::io::Error| IoError::os(path, "write", e);
        let delay_centis = (100.0 / fps).round().clamp(1.0, 65535.0) as u16;
        let sink = match kind {
            AnimationKind::Apng => {
                let mut file = AtomicFile::create(path)?;
                let out = BufWriter::new(file.file().try_clone().map_err(to_io)?);
                let mut encoder = png::Encoder::new(out, width as u32, height as u32);
                encoder.set_color(png::ColorType::Rgb);
                encoder.set_depth(png::BitDepth::Eight);
                let png_err = |e: png::EncodingError| {
                    IoError::invalid(path, format!("cannot encode APNG: {e}"))
                };
                encoder.set_animated(frames as u32, 0).map_err(png_err)?;
                encoder
                    .set_frame_delay(delay_centis, 100)
                    .map_err(png_err)?;
                let writer = encoder.write_header().map_err(png_err)?;
                Sink::Apng(Box::new(writer), file)
            }
            AnimationKind::Gif => {
                let mut file = AtomicFile::create(path)?;
                let out = BufWriter::new(file.file().try_clone().map_err(to_io)?);
                let gif_err = |e: gif::EncodingError| {
                    IoError::invalid(path, format!("cannot encode GIF: {e}"))
                };
                let mut encoder =
                    gif::Encoder::new(out, width as u16, height as u16, &[]).map_err(gif_err)?;
                encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
                Sink::Gif(Box::new(encoder), file)
            }
            AnimationKind::PngSequence => Sink::Sequence(Vec::with_capacity(frames)),
        };
        Ok(Animation {
            path: path.to_path_buf(),
            width,
            height,
            frames,
            written: 0,
            delay_centis,
            sink,
        })
    }

    /// Adds the next frame.
    pub fn push(&mut self, image: &Image) -> Result<(), IoError> {
        let path = self.path.clone();
        if (image.width(), image.height()) != (self.width, self.height) {
            return Err(IoError::invalid(
                &path,
                format!(
                    "frame {} is {}x{}, the animation is {}x{}",
                    self.written,
                    image.width(),
                    image.height(),
                    self.width,
                    self.height
                ),
            ));
        }
        if self.written == self.frames {
            return Err(IoError::invalid(
                &path,
                format!("more than the {} frames announced", self.frames),
            ));
        }
        let rgb = || -> Vec<u8> {
            image
                .pixels()
                .iter()
                .flat_map(|px| [quantize_8(px[0]), quantize_8(px[1]), quantize_8(px[2])])
                .collect()
        };
        match &mut self.sink {
            Sink::Apng(writer, _) => writer
                .write_image_data(&rgb())
                .map_err(|e| IoError::invalid(&path, format!("cannot encode APNG frame: {e}")))?,
            Sink::Gif(encoder, _) => {
                let mut frame =
                    gif::Frame::from_rgb_speed(self.width as u16, self.height as u16, &rgb(), 10);
                frame.delay = self.delay_centis;
                encoder.write_frame(&frame).map_err(|e| {
                    IoError::invalid(&path, format!("cannot encode GIF frame: {e}"))
                })?;
            }
            Sink::Sequence(written) => {
                let file =
                    sequence_path(&path, self.written).expect("the kind checked the pattern");
                written.push(write_png_pending(&file, image, BitDepth::Eight)?);
            }
        }
        self.written += 1;
        Ok(())
    }

    /// Completes the animation once every announced frame was pushed, and
    /// returns the files written.
    pub fn finish(mut self) -> Result<Vec<PathBuf>, IoError> {
        if self.written != self.frames {
            return Err(IoError::invalid(
                &self.path,
                format!(
                    "only {} of {} frames were rendered",
                    self.written, self.frames
                ),
            ));
        }
        let path = self.path.clone();
        let to_io = |e: std::io::Error| IoError::os(&path, "write", e);
        // Taking the sink out leaves an empty sequence for Drop to clean.
        match std::mem::replace(&mut self.sink, Sink::Sequence(Vec::new())) {
            Sink::Apng(writer, file) => {
                let out = writer
                    .finish()
                    .map_err(|e| IoError::invalid(&path, format!("cannot finish APNG: {e}")));
                out?;
                file.commit()?;
                Ok(vec![path.clone()])
            }
            Sink::Gif(encoder, file) => {
                let mut out = encoder
                    .into_inner()
                    .map_err(|e| IoError::invalid(&path, format!("cannot finish GIF: {e}")))?;
                std::io::Write::flush(&mut out).map_err(to_io)?;
                drop(out);
                file.commit()?;
                Ok(vec![path.clone()])
            }
            Sink::Sequence(written) => publish_all(written),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(v: f32) -> Image {
        let mut img = Image::new(4, 3, [v, 0.0, 1.0 - v, 1.0]);
        img.set(0, 0, [1.0, 1.0, 1.0, 1.0]);
        img
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    }

    #[test]
    fn kinds_and_sequence_names() {
        assert_eq!(
            AnimationKind::from_path(Path::new("a/t.png")),
            Some(AnimationKind::Apng)
        );
        assert_eq!(
            AnimationKind::from_path(Path::new("t.GIF")),
            Some(AnimationKind::Gif)
        );
        assert_eq!(
            AnimationKind::from_path(Path::new("f/turn_%03d.png")),
            Some(AnimationKind::PngSequence)
        );
        assert_eq!(AnimationKind::from_path(Path::new("t.mp4")), None);
        assert_eq!(
            sequence_path(Path::new("f/turn_%03d.png"), 7),
            Some(PathBuf::from("f/turn_007.png"))
        );
        assert_eq!(
            sequence_path(Path::new("x%d.png"), 12),
            Some(PathBuf::from("x12.png"))
        );
        assert_eq!(sequence_path(Path::new("x.png"), 1), None);
    }

    #[test]
    fn apng_has_every_frame_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.png");
        let mut a = Animation::create(&p, 4, 3, 3, 10.0).unwrap();
        for i in 0..3 {
            a.push(&frame(i as f32 / 2.0)).unwrap();
        }
        assert_eq!(a.finish().unwrap(), vec![p.clone()]);
        let mut decoder = png::Decoder::new(std::io::BufReader::new(File::open(&p).unwrap()));
        decoder.set_transformations(png::Transformations::IDENTITY);
        let mut reader = decoder.read_info().unwrap();
        let ctl = reader.info().animation_control.unwrap();
        assert_eq!(ctl.num_frames, 3);
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let mut reds = Vec::new();
        for _ in 0..3 {
            reader.next_frame(&mut buf).unwrap();
            assert_eq!(&buf[..3], &[255, 255, 255]);
            reds.push(buf[3]);
            let fc = reader.info().frame_control.unwrap();
            assert_eq!((fc.delay_num, fc.delay_den), (10, 100));
        }
        assert_eq!(reds, [0, 128, 255]);
        assert_eq!(names(dir.path()), ["t.png"]);
    }

    #[test]
    fn gif_loops_with_every_frame() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.gif");
        let mut a = Animation::create(&p, 4, 3, 2, 25.0).unwrap();
        a.push(&frame(0.0)).unwrap();
        a.push(&frame(1.0)).unwrap();
        a.finish().unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut d = opts.read_info(File::open(&p).unwrap()).unwrap();
        let mut n = 0;
        while let Some(f) = d.read_next_frame().unwrap() {
            assert_eq!(f.delay, 4);
            // Pixel 1 is pure blue in frame 0 and pure red in frame 1.
            let px = &f.buffer[4..8];
            let expect: [u8; 3] = if n == 0 { [0, 0, 255] } else { [255, 0, 0] };
            for c in 0..3 {
                assert!(
                    (i32::from(px[c]) - i32::from(expect[c])).abs() <= 8,
                    "{px:?}"
                );
            }
            n += 1;
        }
        assert_eq!(n, 2);
    }

    #[test]
    fn unfinished_animations_leave_nothing() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["t.png", "t.gif", "s_%02d.png"] {
            let p = dir.path().join(name);
            let mut a = Animation::create(&p, 4, 3, 3, 10.0).unwrap();
            a.push(&frame(0.5)).unwrap();
            a.push(&frame(0.5)).unwrap();
            let err = a.finish().unwrap_err();
            assert!(err.to_string().contains("only 2 of 3 frames"), "{err}");
            assert!(
                names(dir.path()).is_empty(),
                "{name}: {:?}",
                names(dir.path())
            );
        }
        // A finished sequence keeps its frames.
        let p = dir.path().join("s_%02d.png");
        let mut a = Animation::create(&p, 4, 3, 2, 10.0).unwrap();
        a.push(&frame(0.5)).unwrap();
        a.push(&frame(0.5)).unwrap();
        assert_eq!(a.finish().unwrap().len(), 2);
        assert_eq!(names(dir.path()), ["s_00.png", "s_01.png"]);
        // Wrong frame sizes and bad names are refused.
        let mut a = Animation::create(&dir.path().join("u.gif"), 4, 3, 1, 10.0).unwrap();
        assert!(a.push(&Image::new(3, 3, [0.0; 4])).is_err());
        assert!(Animation::create(&dir.path().join("u.mp4"), 4, 3, 1, 10.0).is_err());
        assert!(Animation::create(&dir.path().join("u.gif"), 4, 3, 1, 0.0).is_err());
    }

    #[test]
    fn a_sequence_appears_all_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s_%d.png");
        // An earlier run's frame 0 stays as it was until the new sequence
        // is complete: a run stopped half way (Ctrl-C) must not leave a mix.
        let old = dir.path().join("s_0.png");
        std::fs::write(&old, b"earlier frame").unwrap();
        let mut a = Animation::create(&p, 4, 3, 3, 10.0).unwrap();
        a.push(&frame(0.0)).unwrap();
        a.push(&frame(1.0)).unwrap();
        let during = names(dir.path());
        assert_eq!(std::fs::read(&old).unwrap(), b"earlier frame");
        assert!(!during.contains(&"s_1.png".to_string()), "{during:?}");
        // The frames wait as listed temporary files, which a signal
        // handler would delete.
        let temps: Vec<&String> = during.iter().filter(|n| n.ends_with(".tmp")).collect();
        assert_eq!(temps.len(), 2, "{during:?}");
        a.push(&frame(0.5)).unwrap();
        assert_eq!(a.finish().unwrap().len(), 3);
        assert_eq!(names(dir.path()), ["s_0.png", "s_1.png", "s_2.png"]);
        assert_ne!(std::fs::read(&old).unwrap(), b"earlier frame");
    }
}
