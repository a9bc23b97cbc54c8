//! Where a volume of one picture came from ([`LayerSource`]: INPUT, a
//! channel of it along a [`ChannelAxis`], an overlay), and the
//! `--max-memory` the volumes share ([`Budget`]).

use super::OverlaySpec;
use volray_io::FileInfo;

/// Where a volume of the picture came from.
#[derive(Debug, Clone, PartialEq)]
pub enum LayerSource {
    /// INPUT, alone.
    Input,
    /// A channel of INPUT: its number, and the axis it is counted along.
    Channel { index: usize, axis: ChannelAxis },
    /// An `--overlay`.
    Overlay(OverlaySpec),
}

impl LayerSource {
    /// Whether it is drawn: unless an overlay's `hidden` (placed and
    /// framed all the same, `Look::visible`).
    pub fn visible(&self) -> bool {
        !matches!(self, LayerSource::Overlay(o) if o.hidden)
    }
}

/// The axis of INPUT whose volumes `--channels` renders together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelAxis {
    /// Its channels (`--channel`; volray-io's `Volumes`), at the time
    /// point `--frame` picks.
    Channel,
    /// Its time points (`--frame`), for a file of one channel and several
    /// time points: a 4-D NIfTI, NRRD or MetaImage whose 4th axis holds
    /// stains, as stacks of channels are often saved.
    Time,
}

impl ChannelAxis {
    /// The reader option that picks a volume along it: `channel` or
    /// `frame` (as an overlay's option; `--channel`, `--frame` as a flag).
    pub fn option(self) -> &'static str {
        match self {
            ChannelAxis::Channel => "channel",
            ChannelAxis::Time => "frame",
        }
    }

    /// The reader options `channel` and `frame` of an input set to read
    /// volume `index` along this axis.
    pub fn pick(self, channel: &mut Option<usize>, frame: &mut Option<usize>, index: usize) {
        match self {
            ChannelAxis::Channel => *channel = Some(index),
            ChannelAxis::Time => *frame = Some(index),
        }
    }
}

/// How many volumes `--channels` renders together in a file that `info`
/// describes, and along which axis: its channels where it holds several
/// (or one volume), else its time points.
pub fn channel_axis(info: &FileInfo) -> (usize, ChannelAxis) {
    let volumes = info.volumes();
    if volumes.channels > 1 || volumes.time_points < 2 {
        (volumes.channels.max(1), ChannelAxis::Channel)
    } else {
        (volumes.time_points, ChannelAxis::Time)
    }
}

/// `--max-memory` shared by the volumes of one picture: each is read
/// under what the ones read before it left (a mapped volume's pages are
/// the system's to drop, and hold nothing). Each volume's renderer is
/// then checked against the whole limit on its own (`renderer_for`), not
/// against what the others' hold: a gap, for volumes whose renderers'
/// structures (brick caches, a cleaned copy) are large beside them.
#[derive(Debug, Clone)]
pub struct Budget {
    pub limit: u64,
    held: u64,
}

impl Budget {
    pub fn new(max_memory: Option<u64>) -> Self {
        Budget {
            limit: max_memory.unwrap_or_else(volray_io::default_max_memory),
            held: 0,
        }
    }

    /// The bytes `volume` holds in memory (none for one mapped from its
    /// file).
    pub fn held_by(volume: &volray_core::Volume) -> u64 {
        if volume.samples().is_external() {
            return 0;
        }
        let [x, y, z] = volume.dims();
        (x * y * z * volume.sample_type().bytes()) as u64
    }

    pub fn add(&mut self, volume: &volray_core::Volume) {
        self.held = self.held.saturating_add(Self::held_by(volume));
    }

    /// `volume`, added before, dropped.
    pub fn remove(&mut self, volume: &volray_core::Volume) {
        self.held = self.held.saturating_sub(Self::held_by(volume));
    }

    /// The limit the next volume is read under.
    pub fn left(&self) -> Option<u64> {
        Some(self.limit.saturating_sub(self.held))
    }

    /// The message of a refusal of the next volume, saying what the
    /// others hold.
    pub fn explain(&self, message: &str) -> String {
        if self.held == 0 {
            return message.to_string();
        }
        format!(
            "{message} (the volumes read before it hold {} of --max-memory {})",
            volray_io::format_bytes(u128::from(self.held)),
            volray_io::format_bytes(u128::from(self.limit))
        )
    }
}
