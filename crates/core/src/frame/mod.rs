//! A frame made ready: the settings checked, the camera framed on the
//! volume, and where every pixel's ray takes its samples.

pub mod image;
pub mod partial;
pub mod progress;
pub mod request;

use crate::camera::View;
use crate::error::{RenderError, SettingError};
use crate::sampling::clipping::{ClipPlane, Clipping};
use crate::sampling::grid::GridFrame;
use crate::sampling::{PixelSamples, Sampling};
use crate::settings::{MAX_SAMPLES_PER_RAY, RenderSettings};
use crate::volume::Volume;
use crate::volume::piece::Piece;

/// A validated, framed view of a volume.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub view: View,
    /// Where each pixel's ray takes its samples (the grid, the step in
    /// world units, the crop box and clip planes, jitter).
    pub sampling: Sampling,
}

impl Frame {
    /// Checks `settings` and frames their camera and samples on `volume`.
    pub fn new(settings: &RenderSettings, volume: &Volume) -> Result<Self, RenderError> {
        settings.validate()?;
        let grid = GridFrame::of(volume);
        // A piece is framed, and sampled, as the whole volume it is part of.
        let whole = match &settings.piece {
            Some(piece) => {
                piece.validate(volume.dims(), volume.spacing())?;
                piece.whole
            }
            None => grid,
        };
        let view = View::frame(
            &settings.camera,
            whole.bounds(),
            settings.width,
            settings.height,
        )?;
        let step = settings.step * volume.spacing().min_element();
        let samples = whole.extent().length() / step;
        if samples > MAX_SAMPLES_PER_RAY {
            return Err(SettingError::StepTooSmall {
                step: settings.step,
                samples,
                limit: MAX_SAMPLES_PER_RAY,
            }
            .into());
        }
        let clipping = Clipping {
            crop: settings.crop,
            // Unit normals: the planes' arithmetic stays in range.
            planes: (settings.clip_planes.iter())
                .map(|p| ClipPlane {
                    point: p.point,
                    normal: p.normal.normalize(),
                })
                .collect(),
        };
        let sampling = Sampling {
            grid,
            step,
            clipping,
            jitter: settings.jitter,
            from_eye: matches!(view, View::Perspective(_)),
            ownership: settings.piece.as_ref().map(Piece::ownership),
        };
        Ok(Frame { view, sampling })
    }

    /// The samples of pixel (`col`, `row`), or `None` if its ray takes none.
    pub fn samples(&self, col: usize, row: usize) -> Option<PixelSamples> {
        self.sampling.pixel(&self.view, col, row)
    }

    /// Samples all rays take together, before skipping and early
    /// termination (a measure of a frame's work).
    pub fn nominal_samples(&self) -> usize {
        (0..self.view.height())
            .flat_map(|row| (0..self.view.width()).map(move |col| (col, row)))
            .filter_map(|(col, row)| self.samples(col, row))
            .map(|s| s.count())
            .sum()
    }
}
