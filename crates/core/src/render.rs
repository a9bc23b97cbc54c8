//! The whole pipeline for one frame: validate the settings, run stage 1
//! (shade and classify every voxel), frame the camera, run stage 2 (cast
//! the rays) on the fast or the reference path.

use crate::camera::{Camera, CameraError, OrthographicView};
use crate::classify::Classifier;
use crate::gradient::gradients;
use crate::image::Image;
use crate::ray::GridFrame;
use crate::shading::{LightGeometry, Phong};
use crate::stage1::{ShadedVolume, shade_and_classify};
use crate::transfer_function::TransferFunction;
use crate::volume::Volume;
use crate::{raycast, reference};
use glam::DVec3;
use thiserror::Error;

/// Largest image side, in pixels.
pub const MAX_IMAGE_SIDE: usize = 16384;
/// Largest image, in pixels (8192², a 1 GiB frame buffer).
pub const MAX_IMAGE_PIXELS: usize = 1 << 26;
/// Largest number of samples one ray may take: a smaller step is refused
/// rather than left to run for hours.
pub const MAX_SAMPLES_PER_RAY: f64 = 1.0e6;

/// Why a frame could not be rendered.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RenderError {
    #[error("{count} of {total} values are not finite (NaN or infinite)")]
    NonFinite { count: usize, total: usize },
    #[error("{0}")]
    Setting(String),
    #[error(transparent)]
    Camera(#[from] CameraError),
}

/// Which stage 2 to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Front to back, early ray termination, parallel tiles.
    #[default]
    Fast,
    /// The paper's back-to-front compositing in `f64`: the oracle.
    Reference,
}

/// Everything that decides a frame, besides the volume.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    pub width: usize,
    pub height: usize,
    pub camera: Camera,
    /// Distance between samples along a ray, in voxels: units of the
    /// smallest grid spacing (the paper's step is 1, errata 8).
    pub step: f64,
    /// The paper's opacity sub-interval `[p, q]`, used when the transfer
    /// function has no opacity.
    pub opacity_ramp: (f32, f32),
    pub transfer_function: TransferFunction,
    pub phong: Phong,
    /// `false`: no lighting, voxels take their material colour.
    pub shading: bool,
    /// Direction *towards* the light at infinity; `None`: a headlight (`L = V`).
    pub light_direction: Option<DVec3>,
    /// The opaque background, the last sample of every ray.
    pub background: [f32; 3],
    pub method: Method,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 480,
            height: 480,
            camera: Camera::default(),
            step: 1.0,
            opacity_ramp: (0.0, 0.5),
            transfer_function: TransferFunction::default(),
            phong: Phong::default(),
            shading: true,
            light_direction: None,
            background: [0.0; 3],
            method: Method::Fast,
        }
    }
}

fn setting(message: String) -> RenderError {
    RenderError::Setting(message)
}

impl RenderSettings {
    /// Checks every setting, naming the one that is wrong.
    pub fn validate(&self) -> Result<(), RenderError> {
        for (name, n) in [("width", self.width), ("height", self.height)] {
            if n == 0 || n > MAX_IMAGE_SIDE {
                return Err(setting(format!(
                    "image {name} {n} must be between 1 and {MAX_IMAGE_SIDE} pixels"
                )));
            }
        }
        if self.width * self.height > MAX_IMAGE_PIXELS {
            return Err(setting(format!(
                "image {}x{} has more than {MAX_IMAGE_PIXELS} pixels",
                self.width, self.height
            )));
        }
        if !(self.step.is_finite() && self.step > 0.0) {
            return Err(setting(format!(
                "step {} must be a positive number of voxels",
                self.step
            )));
        }
        let (p, q) = self.opacity_ramp;
        if !(0.0 <= p && p < q && q <= 1.0) {
            return Err(setting(format!(
                "opacity ramp p,q = {p},{q} needs 0 <= p < q <= 1"
            )));
        }
        let ph = &self.phong;
        for (name, c) in [
            ("ambient", ph.ambient),
            ("diffuse", ph.diffuse),
            ("specular", ph.specular),
            ("light colour", ph.light_color),
        ] {
            if c.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(setting(format!(
                    "{name} {c:?} must be finite and non-negative"
                )));
            }
        }
        if !(ph.shininess.is_finite() && ph.shininess >= 0.0) {
            return Err(setting(format!(
                "shininess {} must be finite and non-negative",
                ph.shininess
            )));
        }
        if self.background.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return Err(setting(format!(
                "background {:?} must be in [0, 1]",
                self.background
            )));
        }
        if let Some(l) = self.light_direction
            && !(l.is_finite() && l.length() > 0.0)
        {
            return Err(setting(format!(
                "light direction {l} must be a finite, non-zero vector"
            )));
        }
        Ok(())
    }
}

/// A volume ready to render: its value range and gradients are computed
/// once and kept for every frame.
pub struct Renderer<'v> {
    volume: &'v Volume,
    value_range: (f32, f32),
    gradients: Vec<[f32; 3]>,
}

impl<'v> Renderer<'v> {
    /// Prepares `volume`; refuses one with non-finite values.
    pub fn new(volume: &'v Volume) -> Result<Self, RenderError> {
        let count = volume.count_non_finite();
        if count > 0 {
            return Err(RenderError::NonFinite {
                count,
                total: volume.len(),
            });
        }
        let value_range = volume.value_range().expect("a volume has finite values");
        Ok(Renderer {
            volume,
            value_range,
            gradients: gradients(volume),
        })
    }

    pub fn volume(&self) -> &Volume {
        self.volume
    }

    /// `(fmin, fmax)` of the volume.
    pub fn value_range(&self) -> (f32, f32) {
        self.value_range
    }

    /// Renders one frame.
    pub fn render(&self, settings: &RenderSettings) -> Result<Image, RenderError> {
        self.render_with_progress(settings, &|_| {})
    }

    /// Renders one frame, calling `progress` with the number of pixels
    /// finished as the work proceeds (`width·height` in all).
    pub fn render_with_progress(
        &self,
        settings: &RenderSettings,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<Image, RenderError> {
        let frame = self.prepare(settings)?;
        let shaded = self.stage1(settings, &frame.view);
        Ok(self.stage2(settings, &frame, &shaded, progress))
    }

    /// Validates `settings` and frames the view.
    pub fn prepare(&self, settings: &RenderSettings) -> Result<Frame, RenderError> {
        settings.validate()?;
        let view = OrthographicView::frame(
            &settings.camera,
            self.volume.bounds(),
            settings.width,
            settings.height,
        )?;
        let step = settings.step * self.volume.spacing().min_element();
        let samples = self.volume.extent().length() / step;
        if samples > MAX_SAMPLES_PER_RAY {
            return Err(setting(format!(
                "step {} voxels is too small for this volume: a ray would take up to {samples:.0} samples (limit {MAX_SAMPLES_PER_RAY:.0})",
                settings.step
            )));
        }
        let grid = GridFrame {
            dims: self.volume.dims(),
            origin: self.volume.origin(),
            spacing: self.volume.spacing(),
        };
        Ok(Frame { view, grid, step })
    }

    /// Stage 1: per-voxel colour and opacity for this frame's light and view.
    pub fn stage1(&self, settings: &RenderSettings, view: &OrthographicView) -> ShadedVolume {
        let classifier = Classifier::from_transfer_function(
            &settings.transfer_function,
            self.value_range,
            settings.opacity_ramp,
            settings.step as f32,
        );
        let to_viewer = (-view.direction).as_vec3();
        let light = match settings.light_direction {
            Some(l) => LightGeometry::new(l.as_vec3(), to_viewer),
            None => LightGeometry::headlight(to_viewer),
        };
        let lighting = settings.shading.then_some((&settings.phong, &light));
        shade_and_classify(self.volume, &self.gradients, &classifier, lighting)
    }

    /// Stage 2: cast the rays through the shaded voxels.
    pub fn stage2(
        &self,
        settings: &RenderSettings,
        frame: &Frame,
        shaded: &ShadedVolume,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Image {
        let cast = match settings.method {
            Method::Fast => raycast::render,
            Method::Reference => reference::render,
        };
        cast(
            shaded,
            &frame.grid,
            &frame.view,
            frame.step,
            settings.background,
            progress,
        )
    }
}

/// A validated, framed view of a volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub view: OrthographicView,
    pub grid: GridFrame,
    /// Sample spacing along the rays, in world units.
    pub step: f64,
}
