//! The channels of INPUT as volumes of one picture (`--channels`): along
//! which are asked for and in which colours, each read along its axis
//! (`layer.rs`' `ChannelAxis`) under what the others leave of
//! `--max-memory` (`Budget`) with its look.

use super::layer::{Budget, ChannelAxis, Layer, LayerSource, channel_axis};
use crate::error::CliError;
use crate::flags::{ChannelColors, Channels, InputArgs, LookArgs, SceneArgs, ViewArgs};
use crate::session::load;
use volray_app::input;
use volray_core::{PiecewiseLinear, RenderSettings};

/// Refuses the look flags that do not apply to `--channels`, whose
/// colours are `--channel-colors`' (render's and view's).
pub fn refuse_channel_look(look: &LookArgs) -> Result<(), CliError> {
    for (given, other) in [
        (look.labels, "--labels"),
        (look.preset.is_some(), "--preset"),
        (look.colormap.is_some(), "--colormap"),
    ] {
        if given {
            return Err(CliError::input(format!(
                "--channels colours each channel (--channel-colors): {other} does not apply to channels (give it to an --overlay instead)"
            )));
        }
    }
    Ok(())
}

/// The channels `which` of INPUT (read as `input_args` say: at the time
/// point `--frame` picks), each with its look.
pub(super) fn read_channels(
    input_args: &InputArgs,
    view: &ViewArgs,
    scene: &SceneArgs,
    which: &Channels,
    settings: &RenderSettings,
    budget: &mut Budget,
) -> Result<Vec<Layer>, CliError> {
    let spec = input_args.input.as_deref().unwrap_or(input::DEMO);
    if volray_data::is_source_spec(spec) {
        return Err(CliError::input(format!(
            "--channels: {spec} is a built-in source, one volume: give a file holding several channels"
        )));
    }
    let log = view.look.log;
    if input_args.channel.is_some() {
        return Err(CliError::input(format!(
            "--channels picks the channels of {spec}; --channel picks one: give one of them"
        )));
    }
    // Channel 0 (at the time point --frame picks) tells how many the file
    // holds; kept if asked for, else dropped before the others are read,
    // and no longer counted against --max-memory.
    let first = load(input_args, log)?;
    budget.add(&first.volume);
    let Some((_, info)) = &first.file else {
        return Err(CliError::input(format!(
            "--channels: {spec} is not a file holding several channels"
        )));
    };
    let (count, axis) = channel_axis(info);
    if axis == ChannelAxis::Time && input_args.frame.is_some() {
        return Err(CliError::input(format!(
            "--channels renders the {count} volumes of {spec} (one channel, {count} time points) together; --frame picks one: give one of them"
        )));
    }
    let (indices, colors) = picked_channels(scene.channel_colors.as_ref(), which, spec, count)?;
    let mut first = Some(first);
    if !indices.contains(&0) {
        budget.remove(&first.take().expect("channel 0 read").volume);
    }
    let mut layers = Vec::with_capacity(indices.len());
    for (&index, &rgb) in indices.iter().zip(&colors) {
        let kept = if index == 0 { first.take() } else { None };
        let mut input = match kept {
            Some(input) => input,
            None => {
                let mut one = axis.pick(input_args, index);
                one.max_memory = budget.left();
                let mut input = load(&one, log).map_err(|e| budget.explain(e))?;
                budget.add(&input.volume);
                input.max_memory = budget.limit;
                input
            }
        };
        input.name = format!("{spec} (channel {index})");
        let mut settings = settings.clone();
        let tf = &mut settings.transfer_function;
        tf.color = Some(channel_color(rgb, settings.blend.is_projection()));
        crate::settings::file_window(
            &view.look,
            tf,
            input.file.as_ref().and_then(|(_, i)| i.display_window()),
        );
        crate::settings::from_volume(&view.look, tf, &mut input.volume, &input.name)?;
        layers.push(Layer {
            input,
            settings,
            source: LayerSource::Channel { index, axis },
        });
    }
    Ok(layers)
}

/// The channels `which` of the `count` that `spec` holds, and their
/// colours (`--channel-colors`, else the palette): refused in one line
/// where there are none to render together, one is out of range, or the
/// colours do not match them.
pub fn picked_channels(
    channel_colors: Option<&ChannelColors>,
    which: &Channels,
    spec: &str,
    count: usize,
) -> Result<(Vec<usize>, Vec<[f32; 3]>), CliError> {
    if count < 2 {
        return Err(CliError::input(format!(
            "--channels: {spec} holds one volume, no channels to render together (volray info {spec} says what it holds)"
        )));
    }
    let indices: Vec<usize> = match which {
        Channels::All => (0..count).collect(),
        Channels::Some(list) => list.clone(),
    };
    if let Some(bad) = indices.iter().find(|&&i| i >= count) {
        return Err(CliError::input(format!(
            "--channels {bad}: {spec} holds {count} channels, numbered from 0"
        )));
    }
    let colors = match channel_colors {
        Some(given) if given.0.len() != indices.len() => {
            return Err(CliError::input(format!(
                "--channel-colors: {} colour(s) for {} channels: give one per channel",
                given.0.len(),
                indices.len()
            )));
        }
        Some(given) => given.0.clone(),
        None => (0..indices.len())
            .map(volray_options::colors::channel_colour)
            .collect(),
    };
    Ok((indices, colors))
}

/// A channel's colour transfer function: its colour at every value where
/// samples are composited (the opacity says how much of it), from black
/// to it over the window where the projections show the value through
/// the colour map.
fn channel_color(rgb: [f32; 3], projection: bool) -> PiecewiseLinear<3> {
    if projection {
        PiecewiseLinear::new("color", vec![(0.0, [0.0; 3]), (1.0, rgb)]).expect("colours in [0, 1]")
    } else {
        PiecewiseLinear::constant(rgb)
    }
}
