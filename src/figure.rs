//! `--colorbar`, `--scale-bar`, `--axes`, `--outline`, `--title`,
//! `--label`: what a frame was rendered with (the renderer's view and
//! classifier, the labels, the units, the names of the world's axes)
//! handed to volray-annotate, which draws them into the image: a still,
//! or each frame of a turntable or series (`animate.rs`).

use crate::error::CliError;
use crate::flags::{ColorBarSide, FigureArgs, RenderArgs, ScaleLength};
use crate::input::Input;
use crate::render::OutputKind;
use volray_annotate::colorbar::Side;
use volray_annotate::figure::{Annotations, Subject, annotate};
use volray_core::glam::DVec3;
use volray_core::transfer::classifier::Classifier;
use volray_core::transfer::labels::{MAX_LABELS, labels_of};
use volray_core::{Blend, Image, RenderSettings, Renderer};
use volray_io::VolumeFormat;

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
    }
}

/// The names of the world's +x, +y, +z where the file says what they
/// are: a NIfTI, Analyze, MGH or MINC world is RAS+ (x towards the
/// subject's right, y anterior, z superior), DICOM's LPS+, NRRD's its
/// `space`; x, y, z otherwise, and for a grid rendered in its own axes
/// because they are rotated away from the world's.
pub fn axis_names(input: &Input) -> [&'static str; 3] {
    const XYZ: [&str; 3] = ["x", "y", "z"];
    let Some((format, info)) = &input.file else {
        return XYZ;
    };
    if (info.notes.iter()).any(|n| n.contains("own axes")) {
        return XYZ;
    }
    match format {
        VolumeFormat::Nifti | VolumeFormat::Analyze | VolumeFormat::Mgh | VolumeFormat::Minc => {
            ["R", "A", "S"]
        }
        VolumeFormat::Dicom => ["L", "P", "S"],
        VolumeFormat::Nrrd => {
            let space = (info.header.iter())
                .find(|(k, _)| k == "space")
                .map(|(_, v)| v.trim().to_ascii_lowercase());
            match space.as_deref() {
                Some("right-anterior-superior" | "ras") => ["R", "A", "S"],
                Some("left-anterior-superior" | "las") => ["L", "A", "S"],
                Some("left-posterior-superior" | "lps") => ["L", "P", "S"],
                _ => XYZ,
            }
        }
        _ => XYZ,
    }
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
    let volume = renderer.volume();
    let frame = (renderer.prepare(settings)).map_err(|e| CliError::input(e.to_string()))?;
    let classifier = Classifier::for_frame(
        settings,
        renderer.value_range(),
        volume.spacing().min_element() as f32,
        || renderer.max_gradient(),
    );
    let (lo, inv) = classifier.normalisation();
    let (lo, hi) = (
        f64::from(lo),
        f64::from(lo) + if inv > 0.0 { 1.0 / f64::from(inv) } else { 0.0 },
    );
    // The data were rendered as log10 of themselves (--log): the bar's
    // values are the data's own.
    let log = args.view.look.log;
    let value = |v: f64| if log { v.log10() as f32 } else { v as f32 };
    let window = if log {
        (10f64.powf(lo), 10f64.powf(hi))
    } else {
        (lo, hi)
    };
    let projection = settings.blend != Blend::Composite;
    let colour = |v: f64| {
        if projection {
            classifier.projection_colour(value(v))
        } else {
            classifier.material(value(v))
        }
    };
    let opacity = |v: f64| classifier.unit_opacity(value(v));
    let labels = if volume.is_labels() {
        let found = labels_of(volume, MAX_LABELS)
            .ok()
            .flatten()
            .unwrap_or_default();
        Some(
            (found.into_iter())
                .filter(|&l| classifier.unit_opacity(l as f32) > 0.0)
                .map(|l| (l.to_string(), classifier.material(l as f32)))
                .collect(),
        )
    } else {
        None
    };
    let length_unit = input
        .file
        .as_ref()
        .and_then(|(_, info)| info.length_unit.clone());
    let hounsfield = (args.view.look.preset.as_deref()).is_some_and(|p| p.starts_with("ct-"));
    let subject = Subject {
        view: &frame.view,
        bounds: scale_box,
        window,
        log,
        colour: &colour,
        opacity: &opacity,
        labels,
        blend: settings.blend,
        value_unit: hounsfield.then_some("HU"),
        length_unit: length_unit.as_deref(),
        background: settings.background,
        axis_names: axis_names(input),
        boxes,
    };
    annotate(image, &annotations(&args.figure), &subject);
    Ok(())
}
