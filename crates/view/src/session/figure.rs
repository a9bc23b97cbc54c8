//! A frame's annotations (`ViewState::figure`): what they need of the
//! volume beyond its renderer ([`FigureContext`]), and their drawing into
//! a tab's frame as `volray render` draws them (volray-annotate).

use super::render::framed;
use super::{FrameError, Source, Tab};
use crate::state::Figure;
use volray_annotate::figure::{Rendered, annotate_frame};
use volray_core::{Image, RenderSettings};

/// What a frame's annotations (`ViewState::figure`) need to know of the
/// volume beyond its renderer, as `volray render` takes it from the file
/// and the flags: whether it was rendered as log10, its units, the names
/// of its axes.
#[derive(Debug, Clone)]
pub struct FigureContext {
    pub log: bool,
    /// `HU` for a CT preset.
    pub value_unit: Option<String>,
    /// The file's length unit (`mm`).
    pub length_unit: Option<String>,
    /// The names of the world's +x, +y, +z (`R`, `A`, `S` for NIfTI).
    pub axis_names: [String; 3],
}

impl Default for FigureContext {
    fn default() -> Self {
        FigureContext {
            log: false,
            value_unit: None,
            length_unit: None,
            axis_names: ["x", "y", "z"].map(String::from),
        }
    }
}

impl Tab<'_> {
    /// Draws `figure` into `image`, a frame of `settings`, as `volray
    /// render` draws it: the first volume's colour bar and scale bar in
    /// the view framing every volume, the box of each for the outline.
    pub(super) fn annotate(
        &self,
        image: &mut Image,
        figure: &Figure,
        settings: &RenderSettings,
    ) -> Result<(), FrameError> {
        // The unit is the context's value_unit (the start's).
        let what = figure.annotations();
        let (first, framed, boxes) = match &self.source {
            Source::Whole { renderer, .. } => {
                (renderer, settings.clone(), vec![renderer.volume().bounds()])
            }
            Source::Scene(scene) => {
                let boxes = scene.layers().iter().map(|r| r.volume().bounds()).collect();
                (&scene.layers()[0], framed(scene, settings), boxes)
            }
            Source::Levels(_) => return Ok(()),
        };
        let cx = self.figure;
        let [x, y, z] = &cx.axis_names;
        let rendered = Rendered {
            log: cx.log,
            value_unit: cx.value_unit.as_deref(),
            length_unit: cx.length_unit.as_deref(),
            axis_names: [x.as_str(), y.as_str(), z.as_str()],
            boxes: &boxes,
            scale_box: first.volume().bounds(),
        };
        annotate_frame(image, &what, first, &framed, &rendered)?;
        Ok(())
    }
}
