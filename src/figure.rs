//! `--colorbar`, `--scale-bar`, `--axes`, `--outline`, `--title`,
//! `--label`: what a frame was rendered with (the renderer's view and
//! classifier, the labels, the units, the names of the world's axes)
//! handed to volray-annotate, which draws them into the image: a still,
//! or each frame of a turntable or series (`animate.rs`).

use crate::error::CliError;
use crate::outfile::OutputKind;
use volray_annotate::colorbar::Side;
use volray_annotate::figure::{Annotations, Rendered, annotate_frame};
use volray_app::input::Input;
use volray_core::glam::DVec3;
use volray_core::{Image, RenderSettings, Renderer};
use volray_flags::{ColorBarSide, FigureArgs, RenderArgs, ScaleLength};

/// The annotations the flags ask for.
pub fn annotations(args: &FigureArgs) -> Annotations {
    Annotations {
        colorbar: args.colorbar.map(|side| match side {
            ColorBarSide::Right => Side::Right,
            ColorBarSide::Left => Side::Left,
        }),
        scale_bar: args.scale_bar.map(|l| match l {
            ScaleLength::Auto => None,
            ScaleLength::Given(l) => Some(l),
        }),
        title: args.title.clone(),
        label: args.label.clone(),
        axes: args.axes,
        outline: args.outline,
        units: args.units.clone(),
    }
}

/// The names of the world's +x, +y, +z for the triad: the file's
/// ([`volray_io::world_axis_names`]), else x, y, z.
pub fn axis_names(input: &Input) -> [&'static str; 3] {
    (input.file.as_ref())
        .and_then(|(format, info)| volray_io::world_axis_names(*format, info))
        .unwrap_or(["x", "y", "z"])
}

/// Refuses annotations where they are not drawn yet: volumes rendered
/// piece by piece from their chunks (`what`).
pub fn refuse(args: &FigureArgs, what: &str) -> Result<(), CliError> {
    if args.any() {
        return Err(CliError::input(format!(
            "{}: annotations are drawn into frames of a volume read whole; not into {what} yet",
            args.first_flag()
        )));
    }
    Ok(())
}

/// Draws the flags' annotations into `image`, a frame `renderer` rendered
/// with `settings`, of `input` (for its units); an OpenEXR output keeps the
/// bare frame, and says so.
pub fn draw(
    args: &RenderArgs,
    kind: OutputKind,
    settings: &RenderSettings,
    renderer: &Renderer,
    input: &Input,
    image: &mut Image,
) -> Result<(), CliError> {
    let bounds = renderer.volume().bounds();
    draw_framed(
        args,
        kind,
        settings,
        renderer,
        input,
        &[bounds],
        bounds,
        image,
    )
}

/// [`draw`] into a movie's frame, with the frame's own `--title` and
/// `--label` (a keyframe may change them) in place of the flags'.
pub fn draw_titled(
    args: &RenderArgs,
    settings: &RenderSettings,
    renderer: &Renderer,
    input: &Input,
    (title, label): (Option<String>, Option<String>),
    image: &mut Image,
) -> Result<(), CliError> {
    let annotations = Annotations {
        title,
        label,
        ..annotations(&args.figure)
    };
    let a = &annotations;
    let any = a.colorbar.is_some()
        || a.scale_bar.is_some()
        || a.title.is_some()
        || a.label.is_some()
        || a.axes
        || a.outline;
    if !any {
        return Ok(());
    }
    let bounds = renderer.volume().bounds();
    annotate(
        args,
        settings,
        renderer,
        input,
        &annotations,
        (&[bounds], bounds),
        image,
    )
}

/// [`draw`], the outline drawing `boxes`, a perspective scale bar holding
/// at the centre of `scale_box` (a series: the box framing every frame,
/// so that the bar is the same in each).
#[allow(clippy::too_many_arguments)]
pub fn draw_framed(
    args: &RenderArgs,
    kind: OutputKind,
    settings: &RenderSettings,
    renderer: &Renderer,
    input: &Input,
    boxes: &[(DVec3, DVec3)],
    scale_box: (DVec3, DVec3),
    image: &mut Image,
) -> Result<(), CliError> {
    if !args.figure.any() {
        return Ok(());
    }
    if kind == OutputKind::Exr {
        eprintln!(
            "{}: {} keeps the bare frame (annotations are drawn into PNG and GIF output)",
            args.figure.first_flag(),
            args.out.output.display()
        );
        return Ok(());
    }
    let boxes = (boxes, scale_box);
    annotate(
        args,
        settings,
        renderer,
        input,
        &annotations(&args.figure),
        boxes,
        image,
    )
}

/// Draws `annotations` (if any) into `image`, the outline drawing
/// `boxes.0`, a perspective scale bar holding at the centre of `boxes.1`.
fn annotate(
    args: &RenderArgs,
    settings: &RenderSettings,
    renderer: &Renderer,
    input: &Input,
    annotations: &Annotations,
    (boxes, scale_box): (&[(DVec3, DVec3)], (DVec3, DVec3)),
    image: &mut Image,
) -> Result<(), CliError> {
    let length_unit = input
        .file
        .as_ref()
        .and_then(|(_, info)| info.length_unit.clone());
    let rendered = Rendered {
        log: args.view.look.log || input.auto_log,
        value_unit: volray_annotate::figure::preset_unit(args.view.look.preset.as_deref()),
        length_unit: length_unit.as_deref(),
        axis_names: axis_names(input),
        boxes,
        scale_box,
    };
    annotate_frame(image, annotations, renderer, settings, &rendered)
        .map_err(|e| CliError::input(e.to_string()))
}
