//! The channels of INPUT as volumes of one picture (`--channels`): which
//! are asked for and in which colours (each is then read along its axis,
//! `layer.rs`' `ChannelAxis`, under what the others leave of
//! `--max-memory`, `Budget`), and a channel's colour as a transfer
//! function's, which the Python module's `color=` and channels take too.

use super::Refused;
use volray_core::PiecewiseLinear;
use volray_options::LookOptions;

/// Refuses the look flags that do not apply to `--channels`, whose
/// colours are `--channel-colors`' (render's and view's).
pub fn refuse_channel_look(look: &LookOptions) -> Result<(), Refused> {
    for (given, other) in [
        (look.labels, "--labels"),
        (look.preset.is_some(), "--preset"),
        (look.colormap.is_some(), "--colormap"),
    ] {
        if given {
            return Err(Refused(format!(
                "--channels colours each channel (--channel-colors): {other} does not apply to channels (give it to an --overlay instead)"
            )));
        }
    }
    Ok(())
}

/// The channels `which` (`None`: all) of the `count` that `spec` holds,
/// and their colours (`--channel-colors`, else the palette): refused in
/// one line where there are none to render together, one is out of
/// range, or the colours do not match them.
pub fn picked_channels(
    channel_colors: Option<&[[f32; 3]]>,
    which: Option<&[usize]>,
    spec: &str,
    count: usize,
) -> Result<(Vec<usize>, Vec<[f32; 3]>), Refused> {
    if count < 2 {
        return Err(Refused(format!(
            "--channels: {spec} holds one volume, no channels to render together (volray info {spec} says what it holds)"
        )));
    }
    let indices: Vec<usize> = match which {
        None => (0..count).collect(),
        Some(list) => list.to_vec(),
    };
    if let Some(bad) = indices.iter().find(|&&i| i >= count) {
        return Err(Refused(format!(
            "--channels {bad}: {spec} holds {count} channels, numbered from 0"
        )));
    }
    let colors = match channel_colors {
        Some(given) if given.len() != indices.len() => {
            return Err(Refused(format!(
                "--channel-colors: {} colour(s) for {} channels: give one per channel",
                given.len(),
                indices.len()
            )));
        }
        Some(given) => given.to_vec(),
        None => (0..indices.len())
            .map(volray_options::colors::channel_colour)
            .collect(),
    };
    Ok((indices, colors))
}

/// A channel's colour transfer function (and the Python module's
/// `color=`): its colour at every value where samples are composited (the
/// opacity says how much of it), from black to it over the window where
/// the projections show the value through the colour map (a constant
/// would paint the projection flat).
pub fn channel_color(rgb: [f32; 3], projection: bool) -> PiecewiseLinear<3> {
    if projection {
        PiecewiseLinear::new("color", vec![(0.0, [0.0; 3]), (1.0, rgb)]).expect("colours in [0, 1]")
    } else {
        PiecewiseLinear::constant(rgb)
    }
}
