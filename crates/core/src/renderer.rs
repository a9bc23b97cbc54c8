//! The whole pipeline for one frame: validate the settings, frame the
//! camera, then run the fast or the reference path. The reference shades
//! and classifies every voxel (stage 1) and composites every sample (stage
//! 2). The fast path keeps its view-independent work across frames (the
//! min/max macro-cells, and the occupied bricks classified for the last
//! transfer function), then per frame bins the bricks into tiles and casts
//! the rays, lighting each brick as the rays first reach it.
//!
//! **Routing.** [`Method::Fast`] asks for the fast paths: the bricked ray
//! caster ([`crate::cpu::bricked`]) renders views composited from
//! pre-classified voxels (the paper's method), and [`crate::cpu::projection`]
//! renders the projection blend modes (maximum, minimum, average), and
//! [`crate::cpu::post`] views composited from post-classified samples
//! (interpolate the scalar and the gradient, then classify and shade,
//! skipping transparent bricks); all take either projection and any crop
//! box, clip planes and jitter. [`Method::Reference`] runs the reference
//! path ([`crate::reference`]), which renders every option too, as the
//! oracle.
//!
//! **Non-finite values.** [`Renderer::new`] refuses a volume with NaN or
//! infinite values; [`Renderer::with_non_finite`] with
//! [`NonFinite::Transparent`] renders them as empty space, from a cleaned
//! copy and a mask (see [`NonFinite`](crate::NonFinite) for the exact rules).

mod depth_cues;

use crate::bricks::cache::Budget;
use crate::bricks::macrocells::Macrocells;
use crate::bricks::occupied::{Classified, ClassifiedBricks, Source};
use crate::camera::View;
use crate::cpu::lit_bricks::{Lighting, LitBricks};
use crate::cpu::projection as intensity;
use crate::cpu::tiles::TileBins;
use crate::cpu::{bricked, post as post_cast};
use crate::error::RenderError;
use crate::frame::Frame;
use crate::frame::image::Image;
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::frame::progress::Progress;
use crate::frame::request::{FrameRequest, FrameTimes, Picture, Render, Rendered};
use crate::kernels::composite::{Finish, PartialPixel};
use crate::kernels::gradient::{gradients, max_magnitude};
use crate::kernels::phong::LightGeometry;
use crate::reference;
use crate::reference::Shader;
use crate::reference::post::PostClassifier;
use crate::reference::stage1::{Reached, ShadedVolume, shade_and_classify};
use crate::settings::{Blend, Classification, Method, RenderSettings, key_light};
use crate::transfer::classifier::Classifier;
use crate::volume::Volume;
use crate::volume::non_finite::{NonFinite, NonFiniteMask};
use depth_cues::{KeptAmbient, KeptLight};
use std::borrow::Cow;
use std::sync::{Mutex, MutexGuard, OnceLock};
use std::time::Instant;

/// A volume ready to render. Its value range is found once; the fast
/// path's view-independent work (the min/max macro-cells, and the occupied
/// bricks with their normals and classification for the last transfer
/// function used; for post-classification, every voxel's gradient packed
/// with its value, 16 bytes per voxel) is done on the first frame that
/// needs it and kept.
///
/// Frames of one `Renderer` are rendered one at a time: a frame holds the
/// fast path's buffers while it runs.
pub struct Renderer<'v> {
    /// The volume as rendered: the caller's, or its cleaned copy where it
    /// has non-finite values rendered as empty space.
    volume: Cow<'v, Volume>,
    /// The non-finite voxels, when they are rendered as empty space.
    non_finite: Option<NonFiniteMask>,
    value_range: (f32, f32),
    macrocells: OnceLock<Macrocells>,
    /// The largest gradient magnitude, found on the first frame that needs it.
    max_gradient: OnceLock<f32>,
    /// Every voxel's gradient and value ([`post_cast::packed_voxels`]), for
    /// the post-classified fast path: computed on its first frame and kept
    /// (16 bytes per voxel).
    packed_voxels: OnceLock<Vec<wide::f32x4>>,
    fast: Mutex<Option<FastState>>,
    /// The last light volume the fast paths swept, for shadows.
    light: Mutex<Option<KeptLight>>,
    /// The last ambient volume the fast paths computed, for ambient
    /// occlusion.
    ambient: Mutex<Option<KeptAmbient>>,
    /// The most bytes the bricked fast path keeps of classified and lit
    /// bricks ([`Renderer::with_cache_budget`]).
    cache_budget: usize,
}

/// Whether `volume`'s samples were what they are meant to be while they
/// were read: a mapped file truncated or rewritten meanwhile is an error,
/// not a picture of whatever the pages held.
fn verify(volume: &Volume) -> Result<(), RenderError> {
    volume
        .samples()
        .verify()
        .map_err(RenderError::SamplesChanged)
}

/// The default budget of the bricked fast path's caches of classified and
/// lit bricks: 1 GiB, which holds every brick of the peers' volumes (257³:
/// 100 MiB) and keeps a 1024³ CT's frames within a few GiB.
pub const DEFAULT_CACHE_BUDGET: usize = 1 << 30;

/// The fast path's state kept between frames.
pub(crate) struct FastState {
    /// What `bricks` were classified with.
    pub classifier: Classifier,
    pub bricks: ClassifiedBricks,
    /// The frame's lit bricks, buffers reused from frame to frame.
    pub lit: LitBricks,
}

impl<'v> Renderer<'v> {
    /// Prepares `volume`; refuses one with non-finite values.
    pub fn new(volume: &'v Volume) -> Result<Self, RenderError> {
        Self::with_non_finite(volume, NonFinite::Refuse)
    }

    /// Prepares `volume`, whose non-finite values are refused
    /// ([`RenderError::NonFinite`]) or rendered as empty space, as `mode`
    /// says. Rendered as empty space, they cost a cleaned copy of the
    /// volume and a bit per voxel (see [`NonFinite`](crate::NonFinite)); a volume
    /// without them is used as it is, whatever `mode`.
    pub fn with_non_finite(volume: &'v Volume, mode: NonFinite) -> Result<Self, RenderError> {
        Self::prepare_volume(Cow::Borrowed(volume), mode)
    }

    /// [`Renderer::with_non_finite`] for a volume the renderer keeps: a
    /// renderer that outlives its caller's scope (one held by a Python
    /// object across frames, say). A volume whose samples are outside
    /// bytes (a mapped file, a numpy array) is cheap to move here.
    pub fn owning(volume: Volume, mode: NonFinite) -> Result<Renderer<'static>, RenderError> {
        Renderer::prepare_volume(Cow::Owned(volume), mode)
    }

    fn prepare_volume(volume: Cow<'v, Volume>, mode: NonFinite) -> Result<Self, RenderError> {
        let count = volume.count_non_finite();
        if count > 0 && mode == NonFinite::Refuse {
            return Err(RenderError::NonFinite {
                count,
                total: volume.len(),
            });
        }
        let (volume, non_finite) = match NonFiniteMask::clean(&volume) {
            None => (volume, None),
            Some((mask, cleaned)) => {
                // Every sample was read: were they the file's, if mapped?
                verify(&volume)?;
                (Cow::Owned(cleaned), Some(mask))
            }
        };
        // Finite values only; none at all: an empty window at the fill value.
        let value_range = volume.value_range().unwrap_or((0.0, 0.0));
        verify(&volume)?;
        Ok(Renderer {
            volume,
            non_finite,
            value_range,
            macrocells: OnceLock::new(),
            max_gradient: OnceLock::new(),
            packed_voxels: OnceLock::new(),
            fast: Mutex::new(None),
            light: Mutex::new(None),
            ambient: Mutex::new(None),
            cache_budget: DEFAULT_CACHE_BUDGET,
        })
    }

    /// The same renderer keeping at most `bytes` of classified and lit
    /// bricks on the bricked fast path ([`DEFAULT_CACHE_BUDGET`] unless
    /// set): beyond it, bricks are classified and lit again when a frame
    /// needs them, so frames of a volume whose occupied bricks do not fit
    /// take longer but the memory stays bounded. The images do not depend
    /// on it.
    pub fn with_cache_budget(mut self, bytes: usize) -> Self {
        self.cache_budget = bytes;
        self
    }

    /// The budget of the bricked fast path's caches, in bytes.
    pub fn cache_budget(&self) -> usize {
        self.cache_budget
    }

    /// The volume as rendered: the one given, or, where its non-finite
    /// values are rendered as empty space, its cleaned copy (those voxels
    /// hold [`NonFiniteMask::fill`]).
    pub fn volume(&self) -> &Volume {
        &self.volume
    }

    /// The non-finite voxels rendered as empty space, if there are any.
    pub fn non_finite(&self) -> Option<&NonFiniteMask> {
        self.non_finite.as_ref()
    }

    /// `(fmin, fmax)` of the volume.
    pub fn value_range(&self) -> (f32, f32) {
        self.value_range
    }

    /// One frame as a partial image (a scene's layers rendered apart share
    /// their caller's `progress`), its samples verified.
    pub(crate) fn partial_frame(
        &self,
        settings: &RenderSettings,
        progress: &Progress,
    ) -> Result<(PartialImage, FrameTimes), RenderError> {
        let frame = self.prepare(settings)?;
        let rendered = self.partial_unverified(settings, &frame, progress);
        verify(&self.volume)?;
        Ok(rendered)
    }

    /// The partial image of `frame` on the path `settings` take.
    fn partial_unverified(
        &self,
        settings: &RenderSettings,
        frame: &Frame,
        progress: &Progress,
    ) -> (PartialImage, FrameTimes) {
        let start = Instant::now();
        match settings.method {
            Method::Fast => {
                let mut partial = self.blank(settings, Vec::new());
                let times =
                    self.render_fast(settings, frame, &mut partial, Finish::Partial, progress);
                (partial, times)
            }
            Method::Reference => {
                let partial = self.render_reference(settings, frame, progress);
                (partial, FrameTimes::cast(start.elapsed()))
            }
        }
    }

    /// Whether the volume's samples were what they are meant to be while
    /// they were read (see [`verify`]).
    pub(crate) fn verify(&self) -> Result<(), RenderError> {
        verify(&self.volume)
    }

    /// The finished frame of `partial` (rendered with `settings`): over the
    /// background, projected values through the colour map.
    pub fn finish(&self, settings: &RenderSettings, partial: PartialImage) -> Image {
        let classifier = self.classifier(settings);
        partial.finish(settings.background, |f| classifier.projection_colour(f))
    }

    /// A whole frame into `image`'s buffer, its samples verified. A
    /// composited frame on a fast path is finished by the casters, each
    /// ray over the background as its last step ([`Finish::Over`]), with
    /// no second pass over the pixels, in `image`'s buffer when it is
    /// large enough; the others are finished from their partial image.
    pub(crate) fn frame_into(
        &self,
        settings: &RenderSettings,
        image: &mut Image,
        progress: &Progress,
    ) -> Result<FrameTimes, RenderError> {
        let frame = self.prepare(settings)?;
        let times = match (settings.method, settings.blend) {
            (Method::Fast, Blend::Composite) => {
                let buffer = std::mem::replace(image, Image::new(0, 0, [0.0; 4])).into_pixels();
                let mut partial = self.blank(settings, buffer);
                let finish = Finish::Over(settings.background);
                let times = self.render_fast(settings, &frame, &mut partial, finish, progress);
                let pixels = partial.into_composite().expect("a composited frame");
                *image = Image::from_pixels(settings.width, settings.height, pixels)
                    .expect("the frame's size");
                times
            }
            _ => {
                let start = Instant::now();
                let (partial, times) = self.partial_unverified(settings, &frame, progress);
                *image = self.finish(settings, partial);
                match settings.method {
                    // All of it, the finish included.
                    Method::Reference => FrameTimes::cast(start.elapsed()),
                    Method::Fast => times,
                }
            }
        };
        verify(&self.volume)?;
        Ok(times)
    }

    /// The partial image a fast frame of `settings` is rendered into:
    /// composited in `buffer`'s allocation (its old pixels are left, as the
    /// fast casters write every pixel), or no sample projected.
    fn blank(&self, settings: &RenderSettings, buffer: Vec<[f32; 4]>) -> PartialImage {
        let (width, height) = (settings.width, settings.height);
        match settings.blend {
            Blend::Composite => PartialImage::reusing(width, height, buffer),
            blend => PartialImage::projection(width, height, blend),
        }
    }

    /// Validates `settings` and frames the view.
    pub fn prepare(&self, settings: &RenderSettings) -> Result<Frame, RenderError> {
        Frame::new(settings, &self.volume)
    }

    /// The classifier `settings` describe for this volume.
    pub(crate) fn classifier(&self, settings: &RenderSettings) -> Classifier {
        Classifier::for_frame(
            settings,
            self.value_range_of(settings),
            self.volume.spacing().min_element() as f32,
            || self.max_gradient_of(settings),
        )
    }

    /// The volume's min/max bricks, found on the first frame that needs them.
    pub(crate) fn macrocells(&self) -> &Macrocells {
        self.macrocells
            .get_or_init(|| Macrocells::new(&self.volume))
    }

    /// The value range a frame of `settings` classifies by: the whole
    /// volume's, for a piece of one.
    fn value_range_of(&self, settings: &RenderSettings) -> (f32, f32) {
        settings
            .piece
            .as_ref()
            .map_or(self.value_range, |p| p.value_range)
    }

    /// The largest gradient magnitude a frame of `settings` scales by: the
    /// whole volume's, for a piece of one.
    fn max_gradient_of(&self, settings: &RenderSettings) -> f32 {
        match &settings.piece {
            Some(piece) => piece.max_gradient,
            None => self.max_gradient(),
        }
    }

    /// The volume's largest gradient magnitude (world units), found once.
    pub fn max_gradient(&self) -> f32 {
        *self
            .max_gradient
            .get_or_init(|| max_magnitude(&self.volume))
    }

    /// This frame's light: towards the light and towards the viewer. The
    /// viewer is at infinity along the central view direction, for
    /// perspective views too (as a headlight at infinity): one light
    /// geometry for the whole frame, so that pre-classification can light
    /// the voxels once.
    /// With shadows and no light direction, the light is the camera's key
    /// light ([`key_light`]).
    pub(crate) fn light(settings: &RenderSettings, view: &View) -> LightGeometry {
        let to_viewer = -view.direction();
        match (settings.light_direction, settings.shadows) {
            (Some(l), _) => LightGeometry::new(l.as_vec3(), to_viewer.as_vec3()),
            (None, true) => LightGeometry::new(
                key_light(to_viewer, settings.camera.up).as_vec3(),
                to_viewer.as_vec3(),
            ),
            (None, false) => LightGeometry::headlight(to_viewer.as_vec3()),
        }
    }

    /// The reference path's stage 1: colour and opacity of every voxel for
    /// this frame's light and view, from gradients computed afresh. Masked
    /// non-finite voxels get zero opacity.
    pub fn stage1(&self, settings: &RenderSettings, view: &View) -> ShadedVolume {
        let light = Self::light(settings, view);
        let lighting = settings.shading.then_some((&settings.phong, &light));
        let gradients = gradients(&self.volume);
        let classifier = self.classifier(settings);
        let light_reaching = (settings.shadows)
            .then(|| self.reference_light(settings, &light, &classifier, &gradients));
        let ambient_reaching = self.reference_ambient(settings, &classifier, &gradients);
        let mut shaded = shade_and_classify(
            &self.volume,
            &gradients,
            &classifier,
            lighting,
            Reached {
                light: light_reaching.as_deref(),
                ambient: ambient_reaching.as_deref(),
            },
        );
        if let Some(mask) = &self.non_finite {
            for (i, voxel) in shaded.voxels.iter_mut().enumerate() {
                if mask.contains(i) {
                    voxel.w = 0.0;
                }
            }
        }
        shaded
    }

    /// The reference path, with every option: the paper's stage 1 and
    /// back-to-front compositing, post-classified samples, or a projection
    /// of the scalar.
    fn render_reference(
        &self,
        settings: &RenderSettings,
        frame: &Frame,
        progress: &Progress,
    ) -> PartialImage {
        let render =
            |shader: &Shader| reference::render(shader, &frame.view, &frame.sampling, progress);
        match (settings.blend, settings.classification) {
            (Blend::Composite, Classification::Pre) => {
                render(&Shader::Pre(&self.stage1(settings, &frame.view)))
            }
            (Blend::Composite, Classification::Post) => {
                let classifier = self.classifier(settings);
                let light = Self::light(settings, &frame.view);
                let lighting = settings.shading.then_some((&settings.phong, light));
                // The depth cues' opacities from the gradients the samples
                // interpolate: computed once.
                let gradients = gradients(&self.volume);
                let shadows = (settings.shadows).then(|| {
                    let (ray, shadow) = self.shadow_ray(settings, &light, &classifier);
                    (self.opacities(&shadow, &gradients), ray)
                });
                let ambient = self.reference_ambient(settings, &classifier, &gradients);
                let mut post =
                    PostClassifier::with_gradients(&self.volume, gradients, &classifier, lighting)
                        .with_mask(self.non_finite.as_ref());
                if let Some((alpha, ray)) = &shadows {
                    post = post.with_shadows(alpha, *ray);
                }
                if let Some(ambient) = &ambient {
                    post = post.with_ambient_occlusion(ambient);
                }
                render(&Shader::Post(&post))
            }
            (blend, _) => render(&Shader::Projection {
                volume: &self.volume,
                blend,
                mask: self.non_finite.as_ref(),
            }),
        }
    }

    /// The fast paths into `partial` (as [`Self::blank`] made it): the
    /// projections' ([`crate::cpu::projection`]), post-classified
    /// compositing's ([`Self::render_post`]), or the bricked ray caster's
    /// ([`Self::render_bricks`]).
    fn render_fast(
        &self,
        settings: &RenderSettings,
        frame: &Frame,
        partial: &mut PartialImage,
        finish: Finish,
        progress: &Progress,
    ) -> FrameTimes {
        let pixels = match partial.pixels_mut() {
            PartialPixels::Composite(pixels) => pixels,
            PartialPixels::Projection { blend, pixels } => {
                let start = Instant::now();
                let macrocells = self.macrocells();
                intensity::render(
                    &self.volume,
                    self.non_finite.as_ref(),
                    macrocells,
                    self.value_range_of(settings),
                    &frame.view,
                    &frame.sampling,
                    *blend,
                    pixels,
                    progress,
                );
                return FrameTimes {
                    cast: start.elapsed(),
                    ..FrameTimes::default()
                };
            }
        };
        match settings.classification {
            Classification::Post => self.render_post(settings, frame, pixels, finish, progress),
            Classification::Pre => self.render_bricks(settings, frame, pixels, finish, progress),
        }
    }

    /// Post-classified compositing ([`crate::cpu::post`]), from the
    /// volume's packed gradients and values and its min/max bricks (both
    /// computed on the first frame that needs them, and kept); all its time
    /// counts as `cast`.
    fn render_post(
        &self,
        settings: &RenderSettings,
        frame: &Frame,
        pixels: &mut [PartialPixel],
        finish: Finish,
        progress: &Progress,
    ) -> FrameTimes {
        let start = Instant::now();
        let classifier = self.classifier(settings);
        let voxels = self.packed_voxels();
        let light = Self::light(settings, &frame.view);
        let mut kept = self.kept_light(settings.shadows);
        let light_volume = (settings.shadows)
            .then(|| self.light_volume(settings.step, &classifier, &light, &mut kept));
        let mut kept_ambient = self.kept_ambient(settings.ambient_occlusion.is_some());
        let ambient_volume = self.ambient_volume(settings, &classifier, &mut kept_ambient);
        let scene = post_cast::Scene {
            voxels,
            macrocells: self.macrocells(),
            classifier: &classifier,
            lighting: (settings.shading).then_some((&settings.phong, light)),
            mask: self.non_finite.as_ref(),
            light: light_volume,
            ambient: ambient_volume,
        };
        let (view, sampling) = (&frame.view, &frame.sampling);
        post_cast::render(&scene, view, sampling, pixels, finish, progress);
        FrameTimes {
            cast: start.elapsed(),
            ..FrameTimes::default()
        }
    }

    /// The bricked fast path's state for `classifier`, locked for a frame:
    /// the occupied bricks classified by it (classified again only when
    /// it differs from the last frame's) and the lit bricks' buffers.
    pub(crate) fn fast_state(&self, classifier: Classifier) -> MutexGuard<'_, Option<FastState>> {
        self.fast_state_until(classifier, &|| false)
            .expect("never stopped")
    }

    /// [`Self::fast_state`], `None` if `stopped` says so while the bricks
    /// are classified (the state is then left empty).
    pub(crate) fn fast_state_until(
        &self,
        classifier: Classifier,
        stopped: &(dyn Fn() -> bool + Sync),
    ) -> Option<MutexGuard<'_, Option<FastState>>> {
        let mut guard = self.fast.lock().unwrap_or_else(|e| e.into_inner());
        if guard.as_ref().is_none_or(|s| s.classifier != classifier) {
            // Drop the old bricks before building the new ones.
            *guard = None;
            let masked = self.masked();
            let source = Source {
                volume: &self.volume,
                classifier: &classifier,
                masked: &masked,
            };
            // One budget for both caches: the lit bricks in use first,
            // the classified ones in what they leave (see `LitBricks`).
            let budget = Budget::new(self.cache_budget);
            let bricks =
                ClassifiedBricks::sharing(&source, self.macrocells(), budget.clone(), stopped)?;
            let lit = LitBricks::sharing(bricks.len(), budget, size_of::<Classified>());
            *guard = Some(FastState {
                classifier,
                bricks,
                lit,
            });
        }
        Some(guard)
    }

    /// Whether voxel `v` is a non-finite one rendered as empty space.
    pub(crate) fn masked(&self) -> impl Fn(usize) -> bool + Sync + '_ {
        let mask = self.non_finite.as_ref();
        move |v: usize| mask.is_some_and(|m| m.contains(v))
    }

    /// Every voxel's gradient and value packed ([`post_cast::packed_voxels`]),
    /// made on the first frame that needs them and kept.
    pub(crate) fn packed_voxels(&self) -> &[wide::f32x4] {
        (self.packed_voxels)
            .get_or_init(|| post_cast::packed_voxels(&self.volume, &gradients(&self.volume)))
    }

    /// The bricked ray caster: classify (only when the classifier changed),
    /// light the occupied bricks, bin them into tiles, cast the rays.
    fn render_bricks(
        &self,
        settings: &RenderSettings,
        frame: &Frame,
        pixels: &mut [PartialPixel],
        finish: Finish,
        progress: &Progress,
    ) -> FrameTimes {
        let mut times = FrameTimes::default();
        let classifier = self.classifier(settings);
        let t0 = Instant::now();
        // Stopped while classifying: nothing drawn (the caller answers
        // `Stopped`).
        let Some(mut guard) = self.fast_state_until(classifier, &|| progress.stopped()) else {
            return times;
        };
        let masked = self.masked();
        let state = guard.as_mut().expect("the state was just made");
        let t1 = Instant::now();
        let bins = TileBins::new(&state.bricks, &frame.sampling, &frame.view);
        let t2 = Instant::now();
        let light = Self::light(settings, &frame.view);
        let mut kept = self.kept_light(settings.shadows);
        let light_volume = (settings.shadows)
            .then(|| self.light_volume(settings.step, &state.classifier, &light, &mut kept));
        let mut kept_ambient = self.kept_ambient(settings.ambient_occlusion.is_some());
        let ambient_volume = self.ambient_volume(settings, &state.classifier, &mut kept_ambient);
        let number = state.lit.next_frame(bins.entries());
        let classified_before = state.bricks.classified_count();
        let source = Source {
            volume: &self.volume,
            classifier: &state.classifier,
            masked: &masked,
        };
        let lighting = Lighting::new(
            source,
            &state.bricks,
            number,
            settings.shading.then_some((&settings.phong, &light)),
            light_volume,
        )
        .with_ambient(ambient_volume);
        bricked::render(
            &state.bricks,
            &state.lit,
            &lighting,
            &bins,
            &frame.sampling,
            &frame.view,
            pixels,
            finish,
            progress,
        );
        let t3 = Instant::now();
        times.classify = t1 - t0;
        times.bin = t2 - t1;
        times.cast = t3 - t2;
        times.bricks = state.bricks.len();
        times.lit = lighting.count();
        state.lit.end_frame(times.lit);
        times.classified = state.bricks.classified_count() - classified_before;
        times.cached_bytes = state.bricks.slot_bytes() + state.lit.bytes();
        times
    }
}

impl Render for Renderer<'_> {
    type Settings = RenderSettings;
    type Times = FrameTimes;
    type Error = RenderError;

    /// One frame of this volume: finished (in the request's image buffer
    /// where the path can reuse it) or partial, timed, stoppable.
    fn render(&self, mut request: FrameRequest<'_>) -> Result<Rendered, RenderError> {
        let settings = request.settings();
        let progress = request.progress();
        let rendered = if request.wants_partial() {
            let (partial, times) = self.partial_frame(settings, &progress)?;
            Rendered {
                picture: Picture::Partial(partial),
                times,
            }
        } else {
            let mut image = request.take_buffer();
            let times = self.frame_into(settings, &mut image, &progress)?;
            Rendered {
                picture: Picture::Image(image),
                times,
            }
        };
        request.answer(rendered)
    }
}
