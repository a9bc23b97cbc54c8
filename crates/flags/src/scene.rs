//! Several volumes in one picture, and a file's time points as an
//! animation: `--channels`, `--channel-colors`, `--mix`, `--overlay` and
//! `--frames`. `scene.rs` (beside `main.rs`) renders the first four,
//! `animate.rs` the last.

use clap::Args;

/// The volumes rendered with INPUT, and how they mix.
#[derive(Debug, Default, Args)]
pub struct SceneArgs {
    /// Render channels of INPUT together, each in its colour: `all`, or
    /// their numbers from 0, as --channel counts them (a hyperstack's or
    /// OME-TIFF's channels, an HDF5 dataset's or OME-Zarr image's `c`
    /// axis, a 5-D NIfTI's components), at the time point --frame picks;
    /// a file of one channel and several time points (a 4-D NIfTI) has
    /// its time points rendered together. Each has its own value window
    /// (unless --range) and the opacity of the look flags (by default
    /// chosen from its own histogram).
    #[arg(long, value_name = "all|I,J,...", value_parser = parse_channels, help_heading = "Several volumes")]
    pub channels: Option<Channels>,

    /// The channels' colours, one per channel: names (magenta, green,
    /// cyan, yellow, red, blue, orange, white, grey, purple, pink) or
    /// #rrggbb [default: magenta, green, cyan, yellow, red, blue, orange,
    /// white, in this order, then again].
    #[arg(long, value_name = "C1,C2,...", value_parser = parse_colors, help_heading = "Several volumes")]
    pub channel_colors: Option<ChannelColors>,

    /// How the volumes' samples mix: composite (the opacity of all of
    /// them, the opacity-weighted colour: correct occlusion) or additive
    /// (each composited alone, the colours summed: fluorescence)
    /// [default: additive with --channels, else composite].
    #[arg(
        long,
        value_enum,
        value_name = "composite|additive",
        help_heading = "Several volumes"
    )]
    pub mix: Option<MixMode>,

    /// Another volume in the picture, placed by its world coordinates,
    /// with its own look after a ':' (comma-separated): labels,
    /// colormap=NAME, preset=NAME, range=LO,HI, opacity=P,Q, tf=FILE.json,
    /// frame=N; e.g. `seg.nii.gz:labels`. Repeatable.
    #[arg(long, value_name = "FILE[:OPTIONS]", help_heading = "Several volumes")]
    pub overlay: Vec<String>,

    /// Render the time points of INPUT as an animation (`all`, or `A:B`:
    /// A up to B−1, as a Python slice; either may be left out), with one
    /// transfer function and one framing for all, as a series of inputs:
    /// a 4-D NIfTI's volumes, a hyperstack's or OME-Zarr image's `t`,
    /// NetCDF time (as --frame counts them), of the channel --channel
    /// picks. Read one at a time.
    #[arg(long, value_name = "all|A:B", value_parser = parse_frames, help_heading = "Animations")]
    pub frames: Option<Frames>,
}

impl SceneArgs {
    /// Whether several volumes are rendered in one picture.
    pub fn is_scene(&self) -> bool {
        self.channels.is_some() || !self.overlay.is_empty()
    }
}

/// `--channels`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Channels {
    All,
    Some(Vec<usize>),
}

/// `--channel-colors`: RGB in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelColors(pub Vec<[f32; 3]>);

/// `--mix`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MixMode {
    Composite,
    Additive,
}

/// `--frames`: a range of frames, `end` exclusive (`None`: to the last).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frames {
    pub start: usize,
    pub end: Option<usize>,
}

fn parse_channels(s: &str) -> Result<Channels, String> {
    let s = s.trim();
    if s == "all" {
        return Ok(Channels::All);
    }
    let numbers = s
        .split(',')
        .map(|n| {
            n.trim().parse::<usize>().map_err(|_| {
                format!(
                    "'{}' is not a channel number (all, or numbers from 0)",
                    n.trim()
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    for (i, n) in numbers.iter().enumerate() {
        if numbers[..i].contains(n) {
            return Err(format!("channel {n} is named twice"));
        }
    }
    Ok(Channels::Some(numbers))
}

/// One colour: a name or `#rrggbb`.
pub fn parse_color(s: &str) -> Result<[f32; 3], String> {
    let s = s.trim();
    if let Some(hex) = s.strip_prefix('#') {
        return (volray_app::scene::hex_colour(hex))
            .filter(|_| hex.len() == 6)
            .ok_or_else(|| format!("'{s}' is not a colour #rrggbb"));
    }
    volray_options::colors::named(s).ok_or_else(|| {
        let names = volray_options::colors::names();
        format!("unknown colour '{s}' ({}, or #rrggbb)", names.join(", "))
    })
}

fn parse_colors(s: &str) -> Result<ChannelColors, String> {
    s.split(',')
        .map(parse_color)
        .collect::<Result<Vec<_>, _>>()
        .map(ChannelColors)
}

pub(crate) fn parse_frames(s: &str) -> Result<Frames, String> {
    let s = s.trim();
    if s == "all" {
        return Ok(Frames {
            start: 0,
            end: None,
        });
    }
    let Some((a, b)) = s.split_once(':') else {
        return Err(format!("'{s}' is not all or A:B (time points A up to B-1)"));
    };
    let number = |t: &str| -> Result<Option<usize>, String> {
        let t = t.trim();
        if t.is_empty() {
            return Ok(None);
        }
        t.parse::<usize>()
            .map(Some)
            .map_err(|_| format!("'{t}' is not a time point number (from 0)"))
    };
    let (start, end) = (number(a)?.unwrap_or(0), number(b)?);
    if end.is_some_and(|e| e <= start) {
        return Err(format!("{s} holds no time point: A:B needs A < B"));
    }
    Ok(Frames { start, end })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_colours_and_frames_parse() {
        assert_eq!(parse_channels("all"), Ok(Channels::All));
        assert_eq!(parse_channels("0, 2"), Ok(Channels::Some(vec![0, 2])));
        assert!(parse_channels("0,0").is_err());
        assert!(parse_channels("x").is_err());
        assert_eq!(parse_color("Magenta"), Ok([1.0, 0.0, 1.0]));
        assert_eq!(parse_color("#ff8000"), Ok([1.0, 128.0 / 255.0, 0.0]));
        assert!(parse_color("#ff80").is_err());
        assert!(parse_color("teal").unwrap_err().contains("magenta"));
        let f = |s| parse_frames(s);
        assert_eq!(
            f("all"),
            Ok(Frames {
                start: 0,
                end: None
            })
        );
        assert_eq!(
            f("2:5"),
            Ok(Frames {
                start: 2,
                end: Some(5)
            })
        );
        assert_eq!(
            f(":3"),
            Ok(Frames {
                start: 0,
                end: Some(3)
            })
        );
        assert_eq!(
            f("1:"),
            Ok(Frames {
                start: 1,
                end: None
            })
        );
        assert!(f("3:3").is_err() && f("3").is_err());
    }
}
