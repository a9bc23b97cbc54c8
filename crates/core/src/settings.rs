//! Everything that decides a frame besides the volume: [`RenderSettings`],
//! with the choices of path ([`Method`]), blend mode ([`Blend`]) and
//! classification ([`Classification`]), and the checks that name the
//! setting that is out of range ([`SettingError`]).

use crate::camera::Camera;
use crate::error::{ImageSide, Reflection, SettingError};
pub use crate::kernels::blend::Blend;
use crate::kernels::phong::Phong;
use crate::sampling::clipping::ClipPlane;
use crate::transfer::function::TransferFunction;
use crate::transfer::gradient_opacity::GradientOpacity;
use crate::transfer::iso::IsoSurface;
use crate::volume::piece::Piece;
use glam::DVec3;

/// Largest image side, in pixels.
pub const MAX_IMAGE_SIDE: usize = 16384;
/// Largest image, in pixels (8192², a 1 GiB frame buffer).
pub const MAX_IMAGE_PIXELS: usize = 1 << 26;
/// Largest number of samples one ray may take: a smaller step is refused
/// rather than left to run for hours.
pub const MAX_SAMPLES_PER_RAY: f64 = 1.0e6;

/// Where classification happens.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Classification {
    /// Classify and shade voxels, interpolate colours (the paper's).
    #[default]
    Pre,
    /// Interpolate the scalar and the gradient, classify and shade samples.
    Post,
}

/// Which stage 2 to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Front to back, early ray termination, empty-space skipping, in
    /// parallel; every option has a fast path (see the module docs).
    #[default]
    Fast,
    /// The paper's back-to-front compositing in `f64`, and every other
    /// option: the oracle.
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
    /// How the samples make the pixel: composite (the paper's) or a
    /// projection of the scalar.
    pub blend: Blend,
    /// Classify voxels (the paper's) or samples.
    pub classification: Classification,
    /// Offset each pixel's samples by a per-pixel fraction of a step.
    pub jitter: bool,
    /// Render only what every plane keeps.
    pub clip_planes: Vec<ClipPlane>,
    /// Render only what lies in this world box `(lo, hi)`.
    pub crop: Option<(DVec3, DVec3)>,
    /// Levoy's isovalue contour instead of the value's opacity (`None`: off).
    pub iso: Option<IsoSurface>,
    /// Opacity times a ramp of `|∇f|` from 0 at `LO` to 1 at `HI`,
    /// fractions of the volume's largest gradient magnitude (`None`: off).
    pub gradient_opacity: Option<(f32, f32)>,
    /// The gradient magnitude (world units) the `gradient_opacity`
    /// fractions are fractions of; `None`: the volume's own largest. A
    /// series of volumes shares the largest of them all, as it shares one
    /// value window.
    pub gradient_opacity_max: Option<f32>,
    /// Render only this piece of a larger volume, as one rank of a
    /// distributed render does (see [`crate::volume::piece`]); `None` renders the
    /// renderer's volume as the whole.
    pub piece: Option<Piece>,
    /// Shade with the light that reaches each point through the volume
    /// ([`crate::shadows`]). Without a `light_direction` the light is the
    /// camera's key light ([`key_light`]) rather than the headlight, whose
    /// shadows would hide behind what casts them.
    pub shadows: bool,
    /// Scale the ambient light by the mean transmittance over short rays
    /// of this many voxels around each point (ambient occlusion,
    /// [`crate::shadows::ambient`]); `None`: off.
    pub ambient_occlusion: Option<f64>,
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
            blend: Blend::Composite,
            classification: Classification::Pre,
            jitter: false,
            clip_planes: Vec::new(),
            crop: None,
            iso: None,
            gradient_opacity: None,
            gradient_opacity_max: None,
            piece: None,
            shadows: false,
            ambient_occlusion: None,
        }
    }
}

impl RenderSettings {
    /// Checks every setting, naming the one that is wrong.
    pub fn validate(&self) -> Result<(), SettingError> {
        use SettingError as E;
        for (side, value) in [
            (ImageSide::Width, self.width),
            (ImageSide::Height, self.height),
        ] {
            if value == 0 || value > MAX_IMAGE_SIDE {
                return Err(E::ImageSide {
                    side,
                    value,
                    max: MAX_IMAGE_SIDE,
                });
            }
        }
        if self.width * self.height > MAX_IMAGE_PIXELS {
            return Err(E::ImagePixels {
                width: self.width,
                height: self.height,
                max: MAX_IMAGE_PIXELS,
            });
        }
        if !(self.step.is_finite() && self.step > 0.0) {
            return Err(E::Step(self.step));
        }
        let (p, q) = self.opacity_ramp;
        if !(0.0 <= p && p < q && q <= 1.0) {
            return Err(E::OpacityRamp { p, q });
        }
        let ph = &self.phong;
        for (term, value) in [
            (Reflection::Ambient, ph.ambient),
            (Reflection::Diffuse, ph.diffuse),
            (Reflection::Specular, ph.specular),
            (Reflection::LightColor, ph.light_color),
        ] {
            if value.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(E::Reflection { term, value });
            }
        }
        if !(ph.shininess.is_finite() && ph.shininess >= 0.0) {
            return Err(E::Shininess(ph.shininess));
        }
        if self.background.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return Err(E::Background(self.background));
        }
        if let Some(l) = self.light_direction
            && !(l.is_finite() && l.length() > 0.0)
        {
            return Err(E::LightDirection(l));
        }
        if let Some((lo, hi)) = self.crop
            && !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all())
        {
            return Err(E::Crop { lo, hi });
        }
        for plane in &self.clip_planes {
            if !plane.point.is_finite() {
                return Err(E::ClipPoint(plane.point));
            }
            let length = plane.normal.length();
            if !(length.is_finite() && length > 0.0) {
                return Err(E::ClipNormal(plane.normal));
            }
        }
        if let Some(iso) = &self.iso {
            iso.validate()?;
        }
        if let Some(range) = self.gradient_opacity {
            GradientOpacity::validate(range)?;
        }
        if let Some(max) = self.gradient_opacity_max
            && !(max.is_finite() && max > 0.0)
        {
            return Err(E::GradientOpacityMax(max));
        }
        if self.shadows {
            if self.blend != Blend::Composite {
                return Err(E::Shadows("a projection has no light to shadow"));
            }
            if !self.shading {
                return Err(E::Shadows("the lighting is off"));
            }
            if self.piece.is_some() {
                return Err(E::Shadows(
                    "a piece of a volume cannot see the pieces that shadow it",
                ));
            }
        }
        if let Some(radius) = self.ambient_occlusion {
            if !crate::shadows::ambient::RADII.contains(&radius) {
                return Err(E::AmbientOcclusionRadius(radius));
            }
            if self.blend != Blend::Composite {
                return Err(E::AmbientOcclusion("a projection has no light to occlude"));
            }
            if self.piece.is_some() {
                return Err(E::AmbientOcclusion(
                    "a piece of a volume cannot see the pieces around it",
                ));
            }
        }
        Ok(())
    }
}

/// The light of a frame with shadows and no light direction: a key light
/// 45° above the viewer and 30° to the left, as photographers and VTK's
/// light kit place theirs, so that shadows fall down and to the right of
/// what casts them. `to_viewer` and `up` are the camera's (world, unit
/// and not parallel); the light turns with the camera.
pub fn key_light(to_viewer: DVec3, up: DVec3) -> DVec3 {
    let right = up.cross(to_viewer).normalize_or_zero();
    let up = to_viewer.cross(right).normalize_or_zero();
    let (elevation, azimuth) = (45f64.to_radians(), 30f64.to_radians());
    (to_viewer * elevation.cos() * azimuth.cos() + up * elevation.sin()
        - right * elevation.cos() * azimuth.sin())
    .normalize()
}
