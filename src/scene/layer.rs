//! What a volume of one picture is ([`Layer`]) and where it came from
//! ([`LayerSource`]: INPUT, a channel of it along a [`ChannelAxis`], an
//! overlay), and the `--max-memory` the volumes share ([`Budget`]).

use super::OverlaySpec;
use crate::error::CliError;
use crate::flags::InputArgs;
use volray_app::input::Input;
use volray_core::RenderSettings;
use volray_core::scene::Look;
use volray_io::FileInfo;

/// One volume of the picture: what was read, its settings alone (whose
/// look becomes its [`Look`]), and where it came from.
pub struct Layer {
    pub input: Input,
    pub settings: RenderSettings,
    pub source: LayerSource,
}

impl Layer {
    /// Its look in the picture: shown unless an overlay's `hidden`.
    pub fn look(&self) -> Look {
        Look {
            visible: !matches!(&self.source, LayerSource::Overlay(o) if o.hidden),
            ..Look::of(&self.settings)
        }
    }
}

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

    /// `input` reading volume `index` along this axis.
    pub fn pick(self, input: &InputArgs, index: usize) -> InputArgs {
        let mut one = input.clone();
        match self {
            ChannelAxis::Channel => one.channel = Some(index),
            ChannelAxis::Time => one.frame = Some(index),
        }
        one
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
pub struct Budget {
    pub(crate) limit: u64,
    held: u64,
}

impl Budget {
    pub(crate) fn new(max_memory: Option<u64>) -> Self {
        Budget {
            limit: max_memory.unwrap_or_else(volray_io::default_max_memory),
            held: 0,
        }
    }

    /// The bytes `volume` holds in memory (none for one mapped from its
    /// file).
    pub(crate) fn held_by(volume: &volray_core::Volume) -> u64 {
        if volume.samples().is_external() {
            return 0;
        }
        let [x, y, z] = volume.dims();
        (x * y * z * volume.sample_type().bytes()) as u64
    }

    pub(crate) fn add(&mut self, volume: &volray_core::Volume) {
        self.held = self.held.saturating_add(Self::held_by(volume));
    }

    /// `volume`, added before, dropped.
    pub(crate) fn remove(&mut self, volume: &volray_core::Volume) {
        self.held = self.held.saturating_sub(Self::held_by(volume));
    }

    /// The limit the next volume is read under.
    pub(crate) fn left(&self) -> Option<u64> {
        Some(self.limit.saturating_sub(self.held))
    }

    /// A refusal of the next volume, saying what the others hold.
    pub(crate) fn explain(&self, e: CliError) -> CliError {
        if self.held == 0 {
            return e;
        }
        CliError {
            message: format!(
                "{} (the volumes read before it hold {} of --max-memory {})",
                e.message,
                volray_io::format_bytes(u128::from(self.held)),
                volray_io::format_bytes(u128::from(self.limit))
            ),
            ..e
        }
    }
}
