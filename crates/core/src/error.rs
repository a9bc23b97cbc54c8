//! What can go wrong rendering a frame, as values a caller can match on:
//! which setting is out of range, its value and the bound, rather than a
//! message to parse. Messages speak of the library's settings
//! ([`RenderSettings`](crate::RenderSettings) fields), never of a command
//! line's flags: a front end names its own flag by matching the variant.

use crate::camera::CameraError;
use glam::DVec3;
use std::fmt;
use thiserror::Error;

/// Why a frame could not be rendered.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RenderError {
    /// The volume holds NaN or infinite values and they are refused
    /// ([`NonFinite::Refuse`](crate::NonFinite::Refuse)).
    #[error("{count} of {total} values are not finite (NaN or infinite)")]
    NonFinite { count: usize, total: usize },
    /// A setting is out of its range.
    #[error(transparent)]
    Setting(#[from] SettingError),
    /// The camera cannot frame a picture.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// The volume's samples, in bytes owned elsewhere (a mapped file),
    /// changed while they were read: the frame is not the file's.
    #[error("the volume changed while it was rendered: {0}")]
    SamplesChanged(String),
    /// The frame was stopped by its caller
    /// ([`FrameRequest::stopped_by`](crate::FrameRequest::stopped_by)).
    #[error("the frame was stopped before it was finished")]
    Stopped,
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// Why several volumes cannot be rendered together (`scene`).
/// Layers are counted from 0, the first volume being layer 0.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SceneError {
    #[error("a scene needs at least one volume")]
    Empty,
    #[error(
        "volume {layer} (box {} .. {}) does not meet the first volume's box ({} .. {}): check its origin and spacing",
        boxes[0].0, boxes[0].1, boxes[1].0, boxes[1].1
    )]
    Disjoint {
        layer: usize,
        /// Its box and the first volume's (boxed: errors stay small).
        boxes: Box<[(DVec3, DVec3); 2]>,
    },
    #[error("{looks} looks for {layers} volumes: give one per volume")]
    Looks { layers: usize, looks: usize },
    #[error("volume {layer}: opacity {value} must be in [0, 1]")]
    Opacity { layer: usize, value: f32 },
    #[error("volume {layer}: {error}")]
    Layer {
        layer: usize,
        error: Box<RenderError>,
    },
    #[error("a scene of pieces: {0}")]
    Piece(&'static str),
    /// Shadows are cast by one volume on itself; several volumes' light
    /// volumes would have to be swept together.
    #[error("shadows are cast within one volume: a scene of several volumes cannot show them yet")]
    Shadows,
    /// Ambient occlusion, likewise.
    #[error(
        "ambient occlusion is found within one volume: a scene of several volumes cannot show it yet"
    )]
    AmbientOcclusion,
}

/// A render setting out of its range: which one, its value and the bound.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SettingError {
    #[error("image {side} {value} must be between 1 and {max} pixels")]
    ImageSide {
        side: ImageSide,
        value: usize,
        max: usize,
    },
    #[error("image {width}x{height} has more than {max} pixels")]
    ImagePixels {
        width: usize,
        height: usize,
        max: usize,
    },
    #[error("step {0} must be a positive number of voxels")]
    Step(f64),
    /// A step so small that a ray would take more than `limit` samples.
    #[error(
        "step {step} voxels is too small for this volume: a ray would take up to {samples:.0} samples (limit {limit:.0})"
    )]
    StepTooSmall { step: f64, samples: f64, limit: f64 },
    #[error("opacity ramp p,q = {p},{q} needs 0 <= p < q <= 1")]
    OpacityRamp { p: f32, q: f32 },
    #[error("{term} {value:?} must be finite and non-negative")]
    Reflection { term: Reflection, value: [f32; 3] },
    #[error("shininess {0} must be finite and non-negative")]
    Shininess(f32),
    #[error("background {0:?} must be in [0, 1]")]
    Background([f32; 3]),
    #[error("light direction {0} must be a finite, non-zero vector")]
    LightDirection(DVec3),
    #[error("crop box {lo} .. {hi} must be finite with low < high on every axis")]
    Crop { lo: DVec3, hi: DVec3 },
    #[error("{0}")]
    Piece(Box<Misfit>),
    #[error("clip plane point {0} must be finite")]
    ClipPoint(DVec3),
    #[error("clip plane normal {0} must be a finite, non-zero vector")]
    ClipNormal(DVec3),
    #[error("iso value {0} must be finite")]
    IsoValue(f32),
    #[error("iso thickness {0} must be a positive number of voxels")]
    IsoThickness(f32),
    #[error(
        "gradient opacity LO,HI = {lo},{hi} needs 0 <= LO < HI <= 1 (fractions of the largest gradient magnitude)"
    )]
    GradientOpacity { lo: f32, hi: f32 },
    #[error("gradient opacity maximum {0} must be a finite gradient magnitude above 0")]
    GradientOpacityMax(f32),
    /// Shadows asked for where nothing is lit.
    #[error("shadows need lit, composited samples: {0}")]
    Shadows(&'static str),
    /// Ambient occlusion asked for where nothing is composited.
    #[error("ambient occlusion needs composited samples: {0}")]
    AmbientOcclusion(&'static str),
    #[error("ambient occlusion radius {0} must be 1 to 32 voxels")]
    AmbientOcclusionRadius(f64),
}

/// Which side of the image [`SettingError::ImageSide`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageSide {
    Width,
    Height,
}

impl fmt::Display for ImageSide {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ImageSide::Width => "width",
            ImageSide::Height => "height",
        })
    }
}

/// Which Phong coefficient [`SettingError::Reflection`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reflection {
    Ambient,
    Diffuse,
    Specular,
    LightColor,
}

impl fmt::Display for Reflection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Reflection::Ambient => "ambient",
            Reflection::Diffuse => "diffuse",
            Reflection::Specular => "specular",
            Reflection::LightColor => "light colour",
        })
    }
}

/// A volume that is not the piece it is said to be (see
/// `Piece::validate`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Misfit {
    pub whole: [usize; 3],
    pub offset: [usize; 3],
    pub dims: [usize; 3],
    pub owned: ([usize; 3], [usize; 3]),
}

impl std::fmt::Display for Misfit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a piece of {:?} voxels at {:?} of a {:?} grid, owning {:?}..{:?}, must lie in the grid with the cells it samples, at the grid's spacing",
            self.dims, self.offset, self.whole, self.owned.0, self.owned.1
        )
    }
}
