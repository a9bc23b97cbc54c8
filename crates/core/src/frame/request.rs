//! One frame asked for, and its answer: the one entry every renderer of
//! volray has ([`Render::render`]): one volume's `Renderer`, a `Scene` of
//! several, and a volume rendered piece by piece (volray-distributed's
//! `Streamed`).
//!
//! A [`FrameRequest`] carries the frame's settings and, as options, where
//! progress goes ([`FrameRequest::reporting`]), a flag that stops the
//! frame ([`FrameRequest::stopped_by`]: the casters check it per tile, one
//! brick at a time on the bricked path, and a streamed frame per piece as
//! well), whether the partial image before the background is wanted
//! rather than the finished frame ([`FrameRequest::partial`]), and an
//! image whose buffer the frame may reuse ([`FrameRequest::reusing`]). The
//! answer, [`Rendered`], carries the image or the partial image and where
//! the time went: every frame is timed, as the clock is read a handful of
//! times a frame and the counts beside the times (bricks lit, pieces read)
//! are what the front ends report.
//!
//! The name: a *frame request*, because [`Frame`](super::Frame) is already
//! the frame made ready (settings checked, camera framed), and a scene's
//! settings are already a "request" to some callers; this asks for one
//! frame, of any renderer.

use crate::error::RenderError;
use crate::frame::image::Image;
use crate::frame::partial::PartialImage;
use crate::frame::progress::Progress;
use crate::settings::RenderSettings;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// Something that renders frames: the one entry of every renderer.
pub trait Render {
    /// What decides a frame: [`RenderSettings`] for one volume, a scene's
    /// settings for several.
    type Settings;
    /// Where a frame's time went.
    type Times;
    /// Why a frame failed; [`RenderError::Stopped`] when it was stopped.
    type Error: From<RenderError>;

    /// Renders the frame `request` asks for: finished over the background,
    /// or partial ([`FrameRequest::partial`]); [`RenderError::Stopped`]
    /// when its stop flag was set during the frame. Frames of one renderer
    /// are rendered one at a time.
    fn render(
        &self,
        request: FrameRequest<'_, Self::Settings>,
    ) -> Result<Rendered<Self::Times>, Self::Error>;
}

/// Nothing to report to.
const UNHEARD: &(dyn Fn(usize) + Sync) = &|_| {};

/// One frame asked of a [`Render`]er (see the module documentation).
pub struct FrameRequest<'a, S = RenderSettings> {
    settings: &'a S,
    report: &'a (dyn Fn(usize) + Sync),
    stop: Option<&'a AtomicBool>,
    partial: bool,
    buffer: Option<Image>,
}

impl<'a, S> FrameRequest<'a, S> {
    /// The finished frame of `settings`: no progress reported, never
    /// stopped, a fresh image.
    pub fn new(settings: &'a S) -> Self {
        FrameRequest {
            settings,
            report: UNHEARD,
            stop: None,
            partial: false,
            buffer: None,
        }
    }

    /// The same, telling `report` of the pixels finished as the work
    /// proceeds (`width·height` in all per pass over the image: once for
    /// one volume, once per volume rendered apart in a scene, once per
    /// piece rendered of a streamed volume).
    pub fn reporting(self, report: &'a (dyn Fn(usize) + Sync)) -> Self {
        FrameRequest { report, ..self }
    }

    /// The same, stopped once `stop` is set (by another thread): the work
    /// left is skipped, within about one tile's time (one brick's on the
    /// bricked path), and the answer is [`RenderError::Stopped`].
    pub fn stopped_by(self, stop: &'a AtomicBool) -> Self {
        FrameRequest {
            stop: Some(stop),
            ..self
        }
    }

    /// The same, answered with the partial image: premultiplied colour and
    /// transmittance, or projected values, without the background (see
    /// [`PartialImage`]); partial images of pieces of a volume
    /// [`combine`](PartialImage::combine) front to back.
    pub fn partial(self) -> Self {
        FrameRequest {
            partial: true,
            ..self
        }
    }

    /// The same, rendered into `image`'s buffer where the path can (the
    /// composited fast path, when it is the frame's size or larger), so
    /// that a sequence of frames does not allocate one each.
    pub fn reusing(self, image: Image) -> Self {
        FrameRequest {
            buffer: Some(image),
            ..self
        }
    }

    /// The frame's settings.
    pub fn settings(&self) -> &'a S {
        self.settings
    }

    /// Whether the partial image is asked for.
    pub fn wants_partial(&self) -> bool {
        self.partial
    }

    /// What the frame reports to and asks of its caller.
    pub fn progress(&self) -> Progress<'a> {
        let progress = Progress::new(self.report);
        match self.stop {
            Some(stop) => progress.stopping(stop),
            None => progress,
        }
    }

    /// The image to render into: the one given to reuse, or an empty one.
    pub fn take_buffer(&mut self) -> Image {
        self.buffer
            .take()
            .unwrap_or_else(|| Image::new(0, 0, [0.0; 4]))
    }

    /// A request for a part of this frame (a piece, a layer) with
    /// `settings`: the same progress report and stop flag, the finished
    /// frame and a fresh image unless asked otherwise.
    pub fn for_part<'b, T>(&self, settings: &'b T) -> FrameRequest<'b, T>
    where
        'a: 'b,
    {
        FrameRequest {
            settings,
            report: self.report,
            stop: self.stop,
            partial: false,
            buffer: None,
        }
    }

    /// `rendered`, or [`RenderError::Stopped`] if the frame was stopped
    /// meanwhile (whatever it holds is then unfinished).
    pub fn answer<T>(&self, rendered: Rendered<T>) -> Result<Rendered<T>, RenderError> {
        if self.progress().stopped() {
            return Err(RenderError::Stopped);
        }
        Ok(rendered)
    }
}

/// A frame rendered, as its [`FrameRequest`] asked: the image or the
/// partial image, and where the time went.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered<T = FrameTimes> {
    pub picture: Picture,
    pub times: T,
}

/// A frame's pixels: finished, or partial.
#[derive(Debug, Clone, PartialEq)]
pub enum Picture {
    /// Over the background.
    Image(Image),
    /// Before the background ([`FrameRequest::partial`]).
    Partial(PartialImage),
}

impl<T> Rendered<T> {
    /// The finished frame.
    ///
    /// # Panics
    /// If the request asked for the partial image.
    pub fn image(self) -> Image {
        self.image_and_times().0
    }

    /// The partial image.
    ///
    /// # Panics
    /// If the request asked for the finished frame.
    pub fn partial(self) -> PartialImage {
        self.partial_and_times().0
    }

    /// The finished frame and its times.
    ///
    /// # Panics
    /// If the request asked for the partial image.
    pub fn image_and_times(self) -> (Image, T) {
        match self.picture {
            Picture::Image(image) => (image, self.times),
            Picture::Partial(_) => panic!("the partial image was asked for"),
        }
    }

    /// The partial image and its times.
    ///
    /// # Panics
    /// If the request asked for the finished frame.
    pub fn partial_and_times(self) -> (PartialImage, T) {
        match self.picture {
            Picture::Partial(partial) => (partial, self.times),
            Picture::Image(_) => panic!("the finished frame was asked for"),
        }
    }
}

/// Where a frame's time went. On the bricked fast path the parts are
/// timed; a projection, a post-classified frame, a frame on the reference
/// path or of a scene counts all its time as `cast`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameTimes {
    /// Classifying the volume into bricks: zero unless the transfer
    /// function (or the step) changed since the last frame.
    pub classify: Duration,
    /// Binning the occupied bricks into image tiles.
    pub bin: Duration,
    /// Stage 1 per frame, lighting the occupied bricks' voxels (done as the
    /// rays first reach each brick), and stage 2, casting the rays.
    pub cast: Duration,
    /// Occupied bricks.
    pub bricks: usize,
    /// Bricks lit for the frame: those a ray sampled before it
    /// terminated (hidden and off-screen bricks are not lit). A brick lit
    /// more than once (for several tiles, when the cache budget does not
    /// hold the bricks in use) counts each time.
    pub lit: usize,
    /// Bricks classified during the frame because the cache of classified
    /// bricks did not hold them (counted each time, as `lit`).
    pub classified: usize,
    /// Bytes of classified and lit bricks the caches hold after the frame
    /// (at most the renderer's cache budget).
    pub cached_bytes: usize,
}

impl FrameTimes {
    /// The whole frame.
    pub fn total(&self) -> Duration {
        self.classify + self.bin + self.cast
    }

    /// A frame whose time all went into `cast`.
    pub(crate) fn cast(cast: Duration) -> Self {
        FrameTimes {
            cast,
            ..FrameTimes::default()
        }
    }
}
