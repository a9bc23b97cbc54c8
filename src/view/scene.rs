//! `volray view` of several volumes in one picture (`--channels`,
//! `--overlay`) or of a file's time points (`--frames`).
//!
//! The volumes are read as `volray render` reads them (`crate::scene`),
//! each whole; the page shows a panel per volume (shown or hidden, its
//! colours, window and opacity) and the server renders them as one
//! `volray_core::Scene`. The command each frame prints writes every
//! volume after the first as an `--overlay` with its look in full
//! (`range=`, `tf=view-tf-N.json`, `hidden`), the channels of INPUT
//! included (`channel=K` and the `frame=T` of `--frame`, or `frame=K`
//! for a file whose time points are rendered as channels), with `--mix`: the frame the page
//! shows is that command's.
//!
//! A time axis (`--frames A:B`) is served one time point at a time: the
//! first is read before the server starts (its histogram and transfer
//! function serve every time point, as a series' do), and each tab reads
//! the one its slider asks for, as `--frame T`.

use super::{launch, serve};
use crate::error::CliError;
use crate::scene::{overlay_specs, read_layers, whole_input};
use crate::session::{load, renderer_for};
use crate::settings::{read_tf_file, settings_with_tf_text};
use volray_app::input;
use volray_flags::ViewerArgs;
use volray_flags::reproduce::{CliReproduce, SceneWords};
use volray_view::{LayerState, START_COLOURS, TimePoints, WHITE};

pub fn run(args: &ViewerArgs) -> Result<(), CliError> {
    refuse_unsupported(args)?;
    let look = &args.view.look;
    let tf_text = look.tf_file().map(read_tf_file).transpose()?;
    let settings = settings_with_tf_text(&args.view, tf_text.as_deref())?;
    let spec = args.input.input.as_deref().unwrap_or(input::DEMO);
    let input_args = whole_input(
        &args.input,
        &args.view,
        &settings,
        "the viewer's --channels, --overlay and --frames",
    )?;
    let overlays = overlay_specs(&args.scene)?;

    // A time axis: its first time point read now, the others as asked.
    let mut time = None;
    let mut first_args = input_args.clone();
    if let Some(frames) = args.scene.frames {
        first_args.frame = Some(frames.start);
        let first = load(&first_args, look.log)?;
        let count = first.file.as_ref().map_or(1, |(_, info)| info.time_points);
        let end = volray_app::scene::time_range(frames.start, frames.end, count, spec)
            .map_err(|e| CliError::input(e.0))?;
        drop(first);
        let (read_args, log, labels) = (input_args.clone(), look.log, look.labels);
        time = Some(TimePoints {
            range: [frames.start, end],
            start: frames.start,
            read: Box::new(move |t| {
                let one = volray_flags::InputArgs {
                    frame: Some(t),
                    ..read_args.clone()
                };
                let mut input = load(&one, log).map_err(|e| e.message)?;
                input.volume.set_labels(labels);
                Ok(input.volume)
            }),
        });
    }
    let layers = read_layers(&first_args, &args.view, &args.scene, &overlays, &settings)?;
    for layer in &layers {
        // The checks `render` makes: memory, non-finite values, the view.
        let renderer = renderer_for(&args.view, &layer.settings, &layer.input)?;
        renderer
            .prepare(&layer.settings)
            .map_err(|e| crate::session::render_failure(&args.view, &layer.input.name, e))?;
    }
    let first = &layers[0];
    let settings = first.settings.clone();
    let non_finite = first.input.non_finite(args.view.sampling.nonfinite.into());
    let volume = &first.input.volume;
    let grid = (volume.dims(), volume.spacing(), volume.sample_type());
    // The first volume's transfer function, as its command names it.
    let named = settings.transfer_function.clone();
    let mut reproduce = CliReproduce::new(
        args,
        named,
        grid,
        non_finite,
        (first.input.max_memory, false),
    );
    if time.is_some() {
        reproduce = reproduce.with_time();
    }
    if args.scene.is_scene() {
        let mix = crate::scene::mix(&args.scene);
        let words = SceneWords::of(spec, args.input.frame, &layers, mix);
        reproduce = reproduce.with_scene(words);
    }
    let mut layers = layers.into_iter();
    let first = layers.next().expect("the first volume");
    let mut launch = launch(args, first.input, settings, reproduce)?;
    launch.state.time = time.as_ref().map(|t| t.start);
    launch.state.layers = (layers.as_slice().iter())
        .map(|l| LayerState {
            visible: l.look().visible,
            window: None,
            opacity: None,
            colormap: if l.settings.transfer_function.color.is_some() {
                START_COLOURS.to_string()
            } else {
                WHITE.to_string()
            },
        })
        .collect();
    launch.others = layers
        .map(|l| (l.input.name, l.input.volume, l.settings))
        .collect();
    launch.time = time;
    serve(args, launch)
}

/// What `render` refuses of several volumes in one picture, and what
/// the viewer does not serve with them.
fn refuse_unsupported(args: &ViewerArgs) -> Result<(), CliError> {
    let scene = &args.scene;
    let look = &args.view.look;
    let flag = match (&scene.channels, scene.overlay.is_empty()) {
        (Some(_), _) => "--channels",
        (None, false) => "--overlay",
        (None, true) => "--frames",
    };
    if scene.is_scene() && scene.frames.is_some() {
        return Err(CliError::input(format!(
            "{flag} and --frames cannot be combined: give one of them"
        )));
    }
    if scene.frames.is_some() && args.input.frame.is_some() {
        return Err(CliError::input(
            "--frames serves a range of time points; --frame picks one: give one of them",
        ));
    }
    if scene.channels.is_some() {
        crate::scene::refuse_channel_look(look)?;
    }
    if scene.is_scene() && look.log {
        return Err(CliError::input(format!(
            "{flag} with --log: the viewer writes each volume as an --overlay, which is not taken to log10: render the picture with volray render instead"
        )));
    }
    if scene.is_scene() && (args.input.dims.is_some() || args.input.dtype.is_some()) {
        return Err(CliError::input(format!(
            "{flag}: a raw file (--dims, --dtype) holds one volume, and an overlay names a file with a header"
        )));
    }
    Ok(())
}
