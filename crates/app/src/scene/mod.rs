//! Several volumes in one picture (volray-core's `Scene`), assembled the
//! same way by every front end: the channels of an input
//! (`--channels`, their colours `--channel-colors`; the Python module's
//! `channel_axis`), overlays (`--overlay FILE[:OPTIONS]`), how they mix
//! (`--mix`, `mix=`), a file's time points (`--frames`), and the memory
//! limit the volumes share.
//!
//! Plain types and typed refusals ([`Refused`], [`LayerError`]) only:
//! the command line's volumes are read here (`read.rs`), the Python
//! module's come from arrays; each front end spells the refusals as its
//! own errors.
//!
//! - `layer.rs`: where a volume came from ([`LayerSource`], [`ChannelAxis`])
//!   and the shared `--max-memory` ([`Budget`]);
//! - `channels.rs`: which channels, in which colours;
//! - `overlay.rs`: an `--overlay`'s spec, look and settings;
//! - `read.rs`: the volumes read, each whole with its look ([`Layer`]),
//!   the refusals typed ([`LayerError`]) for each front end to word.

mod channels;
mod layer;
mod overlay;
mod read;

pub use channels::{channel_color, picked_channels, refuse_channel_look};
pub use layer::{Budget, ChannelAxis, LayerSource, channel_axis};
pub use overlay::{OVERLAY_OPTIONS, OverlayNaming, OverlaySpec};
pub use read::{
    ChannelPick, Failure, First, Layer, LayerError, Overlays, channels_at, pick, read_layers,
};

use volray_core::scene::Mix;

/// A scene refused: one line saying what is wrong, naming the flag or
/// the file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Refused(pub String);

/// The names of the mixes, as `--mix` and `mix=` take them.
pub const MIX_NAMES: [&str; 2] = ["composite", "additive"];

/// The mix `name` names (`composite` or `additive`).
pub fn mix_of_name(name: &str) -> Option<Mix> {
    match name {
        "composite" => Some(Mix::Composite),
        "additive" => Some(Mix::Additive),
        _ => None,
    }
}

/// The name of `mix`, as [`mix_of_name`] reads it.
pub fn mix_name(mix: Mix) -> &'static str {
    match mix {
        Mix::Composite => "composite",
        Mix::Additive => "additive",
    }
}

/// The mix of a picture that names none: channels add up (as napari and
/// fluorescence microscopy show them), other volumes composite (correct
/// occlusion).
pub fn default_mix(channels: bool) -> Mix {
    if channels {
        Mix::Additive
    } else {
        Mix::Composite
    }
}

/// The end (exclusive) of the time points `start..end` (`end`: `None`
/// for the last) of `spec`, which holds `count`: refused where there are
/// not two to walk or the range leaves them (`--frames A:B`).
pub fn time_range(
    start: usize,
    end: Option<usize>,
    count: usize,
    spec: &str,
) -> Result<usize, Refused> {
    let end = end.unwrap_or(count);
    if count < 2 || start >= count || end > count {
        return Err(Refused(format!(
            "--frames {start}:{end}: {spec} holds {count} time point(s), numbered from 0"
        )));
    }
    Ok(end)
}

/// A colour written in hexadecimal, `rrggbb` or `rgb` (after the `#`),
/// components in [0, 1].
pub fn hex_colour(digits: &str) -> Option<[f32; 3]> {
    if !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let channel = |s: &str| u8::from_str_radix(s, 16).ok().map(|v| f32::from(v) / 255.0);
    match digits.len() {
        6 => Some([
            channel(&digits[0..2])?,
            channel(&digits[2..4])?,
            channel(&digits[4..6])?,
        ]),
        3 => {
            let one = |i: usize| channel(&digits[i..=i].repeat(2));
            Some([one(0)?, one(1)?, one(2)?])
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_io::FileInfo;

    #[test]
    fn mixes_read_back_from_their_names_and_channels_add_up_by_default() {
        for mix in [Mix::Composite, Mix::Additive] {
            assert_eq!(mix_of_name(mix_name(mix)), Some(mix));
        }
        assert_eq!(
            MIX_NAMES.map(mix_of_name),
            [Some(Mix::Composite), Some(Mix::Additive)]
        );
        assert_eq!(mix_of_name("over"), None);
        assert_eq!(default_mix(true), Mix::Additive);
        assert_eq!(default_mix(false), Mix::Composite);
    }

    #[test]
    fn hexadecimal_colours_are_bytes_over_255() {
        assert_eq!(hex_colour("ff8000"), Some([1.0, 128.0 / 255.0, 0.0]));
        assert_eq!(hex_colour("f80"), hex_colour("ff8800"));
        for bad in ["ff80", "gg0000", "", "+f0000", "ff00001"] {
            assert_eq!(hex_colour(bad), None, "{bad}");
        }
    }

    #[test]
    fn a_time_range_must_lie_in_the_file() {
        assert_eq!(time_range(1, None, 4, "a.nii"), Ok(4));
        assert_eq!(time_range(0, Some(2), 4, "a.nii"), Ok(2));
        assert_eq!(
            time_range(2, Some(5), 4, "a.nii").unwrap_err().0,
            "--frames 2:5: a.nii holds 4 time point(s), numbered from 0"
        );
        assert!(time_range(4, None, 4, "a.nii").is_err());
        assert!(time_range(0, None, 1, "a.nii").is_err());
    }

    #[test]
    fn channels_are_picked_with_their_colours_or_the_palette() {
        let palette: Vec<[f32; 3]> = (0..3).map(volray_options::colors::channel_colour).collect();
        assert_eq!(
            picked_channels(None, None, "s.tif", 3),
            Ok((vec![0, 1, 2], palette.clone()))
        );
        let red = [[1.0, 0.0, 0.0]];
        assert_eq!(
            picked_channels(Some(&red), Some(&[2]), "s.tif", 3),
            Ok((vec![2], red.to_vec()))
        );
        let refused = |colors: Option<&[[f32; 3]]>, which: Option<&[usize]>, count| {
            picked_channels(colors, which, "s.tif", count)
                .unwrap_err()
                .0
        };
        assert_eq!(
            refused(None, Some(&[0, 3]), 3),
            "--channels 3: s.tif holds 3 channels, numbered from 0"
        );
        assert!(refused(None, None, 1).contains("holds one volume"));
        assert!(refused(Some(&red), Some(&[0, 1]), 3).contains("1 colour(s) for 2 channels"));
    }

    #[test]
    fn channel_colours_are_constant_but_ramp_from_black_under_a_projection() {
        let rgb = [0.25, 0.5, 1.0];
        let composited = channel_color(rgb, false);
        let projected = channel_color(rgb, true);
        for t in [0.0, 0.5, 1.0] {
            assert_eq!(composited.eval(t), rgb);
        }
        assert_eq!(projected.eval(0.0), [0.0; 3]);
        assert_eq!(projected.eval(0.5), [0.125, 0.25, 0.5]);
        assert_eq!(projected.eval(1.0), rgb);
    }

    #[test]
    fn channels_run_along_the_channel_axis_else_along_time() {
        let info = |channels, time_points| FileInfo {
            channels,
            time_points,
            ..FileInfo::default()
        };
        assert_eq!(channel_axis(&info(3, 5)), (3, ChannelAxis::Channel));
        assert_eq!(channel_axis(&info(1, 5)), (5, ChannelAxis::Time));
        assert_eq!(channel_axis(&info(1, 1)), (1, ChannelAxis::Channel));
        let (mut channel, mut frame) = (None, Some(1));
        ChannelAxis::Time.pick(&mut channel, &mut frame, 4);
        assert_eq!((channel, frame), (None, Some(4)));
        ChannelAxis::Channel.pick(&mut channel, &mut frame, 2);
        assert_eq!((channel, frame), (Some(2), Some(4)));
    }

    #[test]
    fn the_volumes_share_the_memory_limit_and_say_so() {
        let volume = volray_core::Volume::new([4, 4, 4], vec![0.0; 64]).unwrap();
        let mut budget = Budget::new(Some(1000));
        assert_eq!(budget.explain("too large"), "too large");
        budget.add(&volume);
        assert_eq!(budget.left(), Some(1000 - 256));
        assert!(budget.explain("too large").starts_with(
            "too large (the volumes read before it hold 256 bytes of --max-memory 1000 bytes)"
        ));
        budget.remove(&volume);
        assert_eq!(budget.left(), Some(1000));
    }
}
