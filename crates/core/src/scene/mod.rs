//! Several volumes in one picture: the channels of a fluorescence stack, a
//! segmentation over its scan, a PET scan over its MRI, density and
//! temperature of one simulation. A [`Scene`] holds one [`Renderer`] per
//! volume (its layers, each keeping its own per-volume work across
//! frames); [`SceneSettings`] say how each looks ([`Look`]: its transfer
//! function, value window, label mode, opacity scale) and how they mix
//! ([`Mix`]).
//!
//! **One ray march.** Volumes drawn one after the other occlude each
//! other wrongly: whichever is drawn last covers the other, whatever lies
//! in front (pyvista #1356, napari #4618). Here every ray takes its samples
//! at `t = (k + u)·step` (the step in world units: `settings.step` times
//! the smallest spacing of all the volumes), and at each sample every
//! volume whose box holds it is classified and shaded (by its own transfer
//! function and its own gradient) and the samples are mixed
//! ([`mix`](crate::kernels::mix)), then composited front to back as one.
//! So an opaque ball of one volume in front of another's hides it, from
//! either side.
//!
//! **Mixes.** [`Mix::Composite`]: at each step the opacity-weighted colour
//! of the volumes' samples, with the opacity `1 − Π(1 − αᵢ)` of all of
//! them (the union of independent absorbers: Cai and Sakas, "Data
//! intermixing and multi-volume rendering", *Computer Graphics Forum*
//! 18(3), 1999), composited front to back: a correct mix and correct
//! occlusion. [`Mix::Additive`]: each volume composited along the ray on
//! its own and the colours summed (napari's additive blending, for
//! fluorescence: each stain emits its own light), the transmittance the
//! product. The projection blend modes (maximum, minimum, average) project
//! each volume on its own, through its own colour map, and sum the colours
//! (a per-channel MIP, as ImageJ's composite and napari show channels).
//!
//! **Placement.** Volumes on different grids and spacings are placed by
//! their world coordinates (origin and spacing): the camera frames the box
//! holding them all, and a volume adds nothing outside its own box.
//!
//! **Paths.** The reference path ([`Method::Reference`]) mixes every
//! sample of every volume in `f64` (`reference.rs`): the oracle. The fast
//! path (`fast.rs`) takes the same samples in `f32`, in chunks along each
//! ray, each volume walking its own bricks: its occupied bricks lit as on
//! the single-volume path (pre-classified) or its transparent bricks
//! stepped over (post-classified), and stops the ray when less than
//! 1/1024 of the light gets through. A brick of one volume costs nothing
//! where it is transparent, so empty space is skipped only where every
//! volume is transparent. The additive mix of pre-classified volumes on
//! one grid is one march too (`channels.rs`): a compositor per volume
//! along each ray, the colours summed at its end. Other additive mixes and
//! the projections render each volume with its own [`Renderer`], whose
//! paths are the single-volume ones. A scene of one volume renders exactly as that volume's
//! [`Renderer`] does.
//!
//! ```
//! use volray_core::glam::DVec3;
//! use volray_core::scene::{Look, Mix, Scene, SceneSettings};
//! use volray_core::{FrameRequest, Render};
//! use volray_core::{PiecewiseLinear, RenderSettings, Renderer, TransferFunction, Volume};
//!
//! // Two channels of one 24³ grid: a ball left, a ball right.
//! let ball = |c: DVec3| {
//!     Volume::from_fn([24; 3], DVec3::ONE, DVec3::ZERO, move |p| {
//!         (1.0 - (p - c).length() / 6.0).max(0.0) as f32
//!     })
//!     .unwrap()
//! };
//! let (a, b) = (ball(DVec3::new(12.0, 6.0, 12.0)), ball(DVec3::new(12.0, 17.0, 12.0)));
//! let scene = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()]).unwrap();
//! let settings = RenderSettings { width: 48, height: 48, ..Default::default() };
//! let coloured = |rgb| Look {
//!     transfer_function: TransferFunction {
//!         color: Some(PiecewiseLinear::constant(rgb)),
//!         ..Default::default()
//!     },
//!     ..Look::of(&settings)
//! };
//! let looks = vec![coloured([1.0, 0.0, 1.0]), coloured([0.0, 1.0, 0.0])];
//! let request = SceneSettings { settings, looks, mix: Mix::Composite };
//! let image = scene.render(FrameRequest::new(&request)).unwrap().image();
//! // Seen along −x, +y is to the right: the first ball magenta, the second green.
//! let (left, right) = (image.get(11, 24), image.get(36, 24));
//! assert!(left[0] > 0.3 && left[1] < 0.05, "{left:?}");
//! assert!(right[1] > 0.3 && right[0] < 0.05, "{right:?}");
//! ```

mod channels;
mod fast;
mod reference;
#[cfg(test)]
mod tests;

use crate::camera::View;
use crate::error::{RenderError, SceneError};
use crate::frame::image::Image;
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::frame::progress::Progress;
use crate::frame::request::{FrameRequest, FrameTimes, Picture, Render, Rendered};
use crate::kernels::composite::{EMPTY, PartialPixel, over_background};
use crate::renderer::Renderer;
use crate::sampling::Sampling;
use crate::sampling::clipping::{ClipPlane, Clipping};
use crate::sampling::grid::GridFrame;
use crate::settings::{Classification, MAX_SAMPLES_PER_RAY, Method, RenderSettings};
use crate::transfer::function::{PiecewiseLinear, TransferFunction};
use crate::transfer::iso::IsoSurface;
use crate::volume::piece::Piece;
use crate::{SettingError, Volume};
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;

/// How the samples of several volumes at one step make one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mix {
    /// The opacity-weighted colour of the volumes' samples and the
    /// opacity of all of them, composited front to back: correct
    /// occlusion between volumes (see the module docs).
    #[default]
    Composite,
    /// Each volume composited on its own, the colours summed (napari's
    /// additive blending, for fluorescence channels).
    Additive,
}

/// How one volume of a scene looks: the per-volume part of
/// [`RenderSettings`].
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// Its transfer function: colours, opacity, and value window (the
    /// domain; `None`: its own value range).
    pub transfer_function: TransferFunction,
    /// The paper's opacity ramp, where the transfer function has no opacity.
    pub opacity_ramp: (f32, f32),
    /// Levoy's contour of this volume.
    pub iso: Option<IsoSurface>,
    /// Gradient-magnitude opacity of this volume (fractions of its largest).
    pub gradient_opacity: Option<(f32, f32)>,
    pub gradient_opacity_max: Option<f32>,
    /// Its opacity times this, in [0, 1] (1: as the transfer function says).
    pub opacity: f32,
    /// `false`: not drawn (a hidden layer keeps its caches).
    pub visible: bool,
    /// The volume is this piece of a larger one, as one rank of a
    /// distributed frame holds it ([`crate::volume::piece`]): its whole volume's
    /// grid, the box it owns, the whole volume's value range. The volumes
    /// of a scene of pieces are pieces of one grid, split alike (the
    /// channels of one stack); their partial images
    /// (a [partial](FrameRequest::partial) frame) combine front to back into the whole
    /// scene's frame.
    pub piece: Option<Piece>,
}

impl Look {
    /// The look `settings` give a volume rendered alone, fully opaque as
    /// its transfer function says and visible.
    pub fn of(settings: &RenderSettings) -> Self {
        Look {
            transfer_function: settings.transfer_function.clone(),
            opacity_ramp: settings.opacity_ramp,
            iso: settings.iso,
            gradient_opacity: settings.gradient_opacity,
            gradient_opacity_max: settings.gradient_opacity_max,
            opacity: 1.0,
            visible: true,
            piece: settings.piece.clone(),
        }
    }

    /// Whether it draws anything.
    fn shown(&self) -> bool {
        self.visible && self.opacity > 0.0
    }

    /// The settings of this volume in a frame of `shared`, its samples
    /// `step` of its own voxels apart, the camera framing `bounds`.
    fn apply(&self, shared: &RenderSettings, step: f64, bounds: (DVec3, DVec3)) -> RenderSettings {
        let mut transfer_function = self.transfer_function.clone();
        let mut opacity_ramp = self.opacity_ramp;
        if self.opacity < 1.0 {
            let s = self.opacity;
            match &mut transfer_function.opacity {
                Some(table) => {
                    let points = table.points().iter().map(|&(t, [a])| (t, [a * s]));
                    *table = PiecewiseLinear::new("opacity", points.collect())
                        .expect("scaling keeps the points ordered");
                }
                None => opacity_ramp = (opacity_ramp.0 * s, opacity_ramp.1 * s),
            }
        }
        let mut camera = shared.camera;
        camera.bounds = Some(camera.framed_bounds(bounds));
        RenderSettings {
            camera,
            step,
            transfer_function,
            opacity_ramp,
            iso: self.iso,
            gradient_opacity: self.gradient_opacity,
            gradient_opacity_max: self.gradient_opacity_max,
            piece: self.piece.clone(),
            ..shared.clone()
        }
    }
}

/// Everything that decides a frame of a scene: the frame's settings (the
/// camera, the image, the step, lighting, background, path, blend mode,
/// classification, crop and clip planes: shared by every volume; their
/// transfer function and opacity are ignored), each volume's [`Look`],
/// and how they [`Mix`].
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSettings {
    pub settings: RenderSettings,
    /// One per layer, in the scene's order.
    pub looks: Vec<Look>,
    pub mix: Mix,
}

/// Several volumes rendered together, each a [`Renderer`] keeping its
/// per-volume work across frames. The first frames the scene's order:
/// its layers are listed in the order given.
pub struct Scene<'v> {
    layers: Vec<Renderer<'v>>,
    /// The box holding every volume.
    bounds: (DVec3, DVec3),
}

impl<'v> Scene<'v> {
    /// A scene of `layers`, the first one first. Refuses none, and a
    /// volume whose box does not meet the first one's (an overlay placed
    /// elsewhere in the world is, almost always, an overlay of another
    /// scan or in another unit).
    pub fn new(layers: Vec<Renderer<'v>>) -> Result<Self, SceneError> {
        let first = layers.first().ok_or(SceneError::Empty)?.volume();
        for (i, layer) in layers.iter().enumerate().skip(1) {
            if !overlaps(layer.volume(), first) {
                return Err(SceneError::Disjoint {
                    layer: i,
                    boxes: Box::new([layer.volume().bounds(), first.bounds()]),
                });
            }
        }
        let first = first.bounds();
        let bounds = (layers.iter().map(|l| l.volume().bounds()))
            .fold(first, |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
        Ok(Scene { layers, bounds })
    }

    /// The layers, in order.
    pub fn layers(&self) -> &[Renderer<'v>] {
        &self.layers
    }

    /// The world box holding every volume (what the camera frames).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.bounds
    }

    /// The smallest grid spacing of any volume: the step's unit.
    fn voxel_size(&self) -> f64 {
        (self.layers.iter())
            .map(|l| l.volume().spacing().min_element())
            .fold(f64::INFINITY, f64::min)
    }

    /// The box the camera frames in a frame of `request`: every volume's,
    /// or the whole grid's of a scene of pieces, whose pieces are checked
    /// to split one grid alike (the volumes' pieces: `shared.piece` is
    /// for one volume, refused here).
    fn framed(&self, request: &SceneSettings) -> Result<(DVec3, DVec3), SceneError> {
        let pieces: Vec<Option<&Piece>> = request.looks.iter().map(|l| l.piece.as_ref()).collect();
        if request.settings.piece.is_some() {
            return Err(SceneError::Piece(
                "a scene's pieces are given per volume (Look::piece), not in the shared settings",
            ));
        }
        if pieces.iter().any(Option::is_some) && pieces.iter().any(Option::is_none) {
            return Err(SceneError::Piece("either every volume is a piece, or none"));
        }
        let Some(first) = pieces[0] else {
            return Ok(self.bounds);
        };
        let alike = |p: &Option<&Piece>| {
            p.is_some_and(|p| {
                p.whole == first.whole && p.offset == first.offset && p.owned == first.owned
            })
        };
        if !pieces.iter().all(alike) {
            return Err(SceneError::Piece(
                "the volumes' pieces must be the same box of one grid",
            ));
        }
        if request.mix == Mix::Additive || request.settings.blend.is_projection() {
            return Err(SceneError::Piece(
                "pieces of a scene combine front to back only in the composite mix",
            ));
        }
        Ok(first.whole.bounds())
    }

    /// One frame of the composite mix as a partial image: premultiplied
    /// colour and transmittance, without the background. With every
    /// volume a piece of its whole ([`Look::piece`]), the partial images
    /// of the pieces, combined front to back
    /// ([`PartialImage::combine`]) and finished over the background
    /// ([`PartialImage::finish`]), give the whole scene's frame, as for
    /// one volume (see [`crate::volume::piece`]). The additive mix and the
    /// projections, which do not combine front to back, are refused.
    fn partial_frame(
        &self,
        request: &SceneSettings,
        progress: &Progress,
    ) -> Result<PartialImage, RenderError> {
        if request.mix == Mix::Additive || request.settings.blend.is_projection() {
            return Err(
                SceneError::Piece("a scene's partial image is of the composite mix only").into(),
            );
        }
        let settings = self.layer_settings(request)?;
        if self.layers.len() == 1 {
            return Ok(self.layers[0].partial_frame(&settings[0], progress)?.0);
        }
        let shown: Vec<usize> = (0..self.layers.len())
            .filter(|&i| request.looks[i].shown())
            .collect();
        self.composite(&settings, &shown, request, progress)
    }

    /// Each layer's settings in a frame of `request`, checked.
    fn layer_settings(&self, request: &SceneSettings) -> Result<Vec<RenderSettings>, RenderError> {
        let shared = &request.settings;
        shared.validate()?;
        if shared.shadows {
            return Err(SceneError::Shadows.into());
        }
        if shared.ambient_occlusion.is_some() {
            return Err(SceneError::AmbientOcclusion.into());
        }
        if request.looks.len() != self.layers.len() {
            return Err(SceneError::Looks {
                layers: self.layers.len(),
                looks: request.looks.len(),
            }
            .into());
        }
        let bounds = self.framed(request)?;
        let world_step = shared.step * self.voxel_size();
        let samples = (self.bounds.1 - self.bounds.0).length() / world_step;
        if samples > MAX_SAMPLES_PER_RAY {
            return Err(SettingError::StepTooSmall {
                step: shared.step,
                samples,
                limit: MAX_SAMPLES_PER_RAY,
            }
            .into());
        }
        (self.layers.iter().zip(&request.looks).enumerate())
            .map(|(i, (layer, look))| {
                if !(look.opacity.is_finite() && (0.0..=1.0).contains(&look.opacity)) {
                    return Err(SceneError::Opacity {
                        layer: i,
                        value: look.opacity,
                    }
                    .into());
                }
                let step = world_step / layer.volume().spacing().min_element();
                let settings = look.apply(shared, step, bounds);
                let volume = layer.volume();
                (settings.validate())
                    .and_then(|()| match &settings.piece {
                        Some(piece) => piece.validate(volume.dims(), volume.spacing()),
                        None => Ok(()),
                    })
                    .map_err(|e| SceneError::Layer {
                        layer: i,
                        error: Box::new(e.into()),
                    })?;
                Ok(settings)
            })
            .collect()
    }

    fn render_frame(
        &self,
        request: &SceneSettings,
        progress: &Progress,
    ) -> Result<Image, RenderError> {
        let settings = self.layer_settings(request)?;
        if self.layers.len() == 1 {
            // One volume: exactly its renderer's frame.
            let renderer = &self.layers[0];
            let mut image = Image::new(0, 0, [0.0; 4]);
            renderer.frame_into(&settings[0], &mut image, progress)?;
            return Ok(image);
        }
        let shown: Vec<usize> = (0..self.layers.len())
            .filter(|&i| request.looks[i].shown())
            .collect();
        let shared = &request.settings;
        let (width, height) = (shared.width, shared.height);
        let background = shared.background;
        if shared.blend.is_projection() {
            return self.projections(&settings, &shown, shared, progress);
        }
        if request.mix == Mix::Additive && shown.len() > 1 {
            let layers: Vec<(&Renderer, &RenderSettings)> = shown
                .iter()
                .map(|&i| (&self.layers[i], &settings[i]))
                .collect();
            if shared.method == Method::Fast
                && shared.classification == Classification::Pre
                && channels::one_grid(&layers)
            {
                // One march, a compositor per volume along each ray.
                let frame = self.frame(shared, &settings[shown[0]], layers[0].0.volume())?;
                let partial = channels::render_additive(&layers, &frame, progress);
                for (layer, _) in &layers {
                    layer.verify()?;
                }
                let PartialPixels::Composite(sum) = partial.pixels() else {
                    unreachable!("a composited frame")
                };
                let pixels = (sum.par_iter())
                    .map(|p| clamp_colour(over_background(*p, background)))
                    .collect();
                return Ok(Image::from_pixels(width, height, pixels).expect("the frame's size"));
            }
        }
        if request.mix == Mix::Additive || shown.len() <= 1 {
            // Each volume on its own, the colours summed.
            let mut sum = vec![EMPTY; width * height];
            for &i in &shown {
                let layer = &self.layers[i];
                let (partial, _) = layer.partial_frame(&settings[i], progress)?;
                let PartialPixels::Composite(pixels) = partial.pixels() else {
                    unreachable!("a composited frame")
                };
                (sum.par_iter_mut().zip(pixels)).for_each(|(s, p)| *s = add(*s, *p));
            }
            let pixels = (sum.into_par_iter())
                .map(|p| clamp_colour(over_background(p, background)))
                .collect();
            return Ok(Image::from_pixels(width, height, pixels).expect("the frame's size"));
        }
        // One march through every volume shown.
        let partial = self.composite(&settings, &shown, request, progress)?;
        Ok(partial.finish(background, |_| unreachable!("a composited frame")))
    }

    /// The volumes `shown` (their settings `settings`) marched as one, in
    /// the composite mix: a partial image.
    fn composite(
        &self,
        settings: &[RenderSettings],
        shown: &[usize],
        request: &SceneSettings,
        progress: &Progress,
    ) -> Result<PartialImage, RenderError> {
        let shared = &request.settings;
        let (width, height) = (shared.width, shared.height);
        if shown.is_empty() {
            return Ok(PartialImage::composite(width, height));
        }
        let frame = self.frame(shared, &settings[shown[0]], self.layers[shown[0]].volume())?;
        let layers: Vec<(&Renderer, &RenderSettings)> = shown
            .iter()
            .map(|&i| (&self.layers[i], &settings[i]))
            .collect();
        let partial = match shared.method {
            Method::Reference => reference::render(&layers, &frame, shared, progress),
            Method::Fast
                if shared.classification == Classification::Pre && channels::one_grid(&layers) =>
            {
                channels::render(&layers, &frame, progress)
            }
            Method::Fast => fast::render(&layers, &frame, shared, progress),
        };
        for (layer, _) in &layers {
            layer.verify()?;
        }
        Ok(partial)
    }

    /// The frame's view and samples: the camera framing every volume (or
    /// the whole grid of a scene of pieces), rays through their box (the
    /// whole grid's, taking the samples the pieces own), samples `step`
    /// times the smallest spacing apart. `first` and its settings
    /// `layer`: a volume shown, whose piece, if it is one, stands for
    /// every volume's.
    fn frame(
        &self,
        shared: &RenderSettings,
        layer: &RenderSettings,
        first: &Volume,
    ) -> Result<SceneFrame, RenderError> {
        let view = View::frame(
            &shared.camera,
            layer.camera.framed_bounds(self.bounds),
            shared.width,
            shared.height,
        )?;
        let (lo, hi) = self.bounds;
        let clipping = Clipping {
            crop: shared.crop,
            planes: (shared.clip_planes.iter())
                .map(|p| ClipPlane {
                    point: p.point,
                    normal: p.normal.normalize(),
                })
                .collect(),
        };
        let (grid, ownership) = match &layer.piece {
            // The piece's own grid, its rays bounded by the whole's.
            Some(piece) => (GridFrame::of(first), Some(piece.ownership())),
            // The box of every volume as a grid of 2³ points: rays are
            // sampled in it, each volume mapping the world to its own grid.
            None => (
                GridFrame {
                    dims: [2; 3],
                    origin: lo,
                    spacing: hi - lo,
                },
                None,
            ),
        };
        let sampling = Sampling {
            grid,
            step: shared.step * self.voxel_size(),
            clipping,
            jitter: shared.jitter,
            from_eye: matches!(view, View::Perspective(_)),
            ownership,
        };
        Ok(SceneFrame { view, sampling })
    }

    /// Each volume projected on its own through its colour map, the
    /// colours summed; a pixel no volume's ray sampled is the background.
    fn projections(
        &self,
        settings: &[RenderSettings],
        shown: &[usize],
        shared: &RenderSettings,
        progress: &Progress,
    ) -> Result<Image, RenderError> {
        let (width, height) = (shared.width, shared.height);
        let mut sum: Vec<Option<[f32; 3]>> = vec![None; width * height];
        for &i in shown {
            let layer = &self.layers[i];
            let (partial, _) = layer.partial_frame(&settings[i], progress)?;
            let classifier = layer.classifier(&settings[i]);
            let PartialPixels::Projection { blend, pixels } = partial.pixels() else {
                unreachable!("a projection")
            };
            (sum.par_iter_mut().zip(pixels)).for_each(|(s, p)| {
                if let Some(f) = p.value(*blend) {
                    let c = classifier.projection_colour(f as f32);
                    let old = s.unwrap_or([0.0; 3]);
                    *s = Some(std::array::from_fn(|k| old[k] + c[k]));
                }
            });
        }
        let bg = shared.background;
        let pixels = (sum.into_par_iter())
            .map(|s| match s {
                Some([r, g, b]) => [r.min(1.0), g.min(1.0), b.min(1.0), 1.0],
                None => [bg[0], bg[1], bg[2], 0.0],
            })
            .collect();
        Ok(Image::from_pixels(width, height, pixels).expect("the frame's size"))
    }
}

impl Render for Scene<'_> {
    type Settings = SceneSettings;
    type Times = FrameTimes;
    type Error = RenderError;

    /// One frame of the scene, its time all counted as `cast`. A partial
    /// frame is of the composite mix only (the additive mix and the
    /// projections do not combine front to back): with every volume a
    /// piece of its whole ([`Look::piece`]), the partial images of the
    /// pieces, combined front to back ([`PartialImage::combine`]) and
    /// finished over the background ([`PartialImage::finish`]), give the
    /// whole scene's frame, as for one volume (see [`crate::volume::piece`]).
    /// Progress counts `width·height` pixels per march: once for one
    /// march, once per volume rendered apart.
    fn render(&self, request: FrameRequest<'_, SceneSettings>) -> Result<Rendered, RenderError> {
        let start = Instant::now();
        let (settings, progress) = (request.settings(), request.progress());
        let picture = match request.wants_partial() {
            true => Picture::Partial(self.partial_frame(settings, &progress)?),
            false => Picture::Image(self.render_frame(settings, &progress)?),
        };
        let times = FrameTimes::cast(start.elapsed());
        request.answer(Rendered { picture, times })
    }
}

/// A scene's frame: the view framing every volume, and where each ray
/// takes its samples (in the box of every volume).
pub(crate) struct SceneFrame {
    pub view: View,
    pub sampling: Sampling,
}

/// The partial pixel of two volumes composited apart, their colours
/// summed: the additive mix.
#[inline]
fn add(a: PartialPixel, b: PartialPixel) -> PartialPixel {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] * b[3]]
}

/// A finished pixel's colour clamped to 1 (summed colours may exceed it).
#[inline]
fn clamp_colour([r, g, b, a]: [f32; 4]) -> [f32; 4] {
    [r.min(1.0), g.min(1.0), b.min(1.0), a]
}

/// Whether `volume`'s box meets `first`'s: what [`Scene::new`] asks of
/// every layer after the first (a front end may ask it before reading a
/// whole volume).
pub fn overlaps(volume: &Volume, first: &Volume) -> bool {
    let (lo, hi) = volume.bounds();
    let (flo, fhi) = first.bounds();
    !(lo.cmpgt(fhi).any() || hi.cmplt(flo).any())
}
