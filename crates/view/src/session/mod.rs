//! One tab's renderer: a thread of its own that owns a
//! [`Renderer`] of the volume (so that the bricks classified for this
//! tab's transfer function are kept from frame to frame, whatever other
//! tabs do), takes the latest request from a single-slot [`Mailbox`],
//! renders it, encodes it, and hands the message to the tab's socket
//! through a channel of one, so that a slow page slows the renderer
//! instead of queueing frames.
//!
//! A frame is rendered with the mailbox's stop flag
//! (`Renderer::render_stoppable`): a newer request for the tab, or the
//! tab closing, stops it within a tile's work (a brick's, on the bricked
//! path; a frame stopped before it starts is not started), and the
//! thread goes on to
//! the newer request or ends. Before a frame is rendered its bytes are
//! reserved from the server's [`Ledger`]; a frame that does not fit
//! beside what the other tabs hold is answered with the reason, not
//! queued.
//!
//! A large volume's drafts are drawn from a coarse copy of it
//! (`coarse.rs`), made after the tab's first still is sent (or on its
//! first draft) and kept with the tab's renderer, its bytes reserved from the ledger; the stills are always
//! the volume's own frames.
//!
//! When the tab goes away the mailbox closes, the thread ends and the
//! renderer with its caches is freed, and its reservation given back.
//!
//! The tab's life, file by file: [`spawn`] (here) starts its thread and
//! builds what it renders ([`Source`]: the volume, a scene, or a
//! pyramid's levels), then serves the mailbox until it closes: a probe is
//! answered (`probe.rs`); a still slow to render is preceded by a quick
//! draft (`drafts.rs`); each frame (`frame.rs`) is reproduced from the
//! page's state, drawn (`render.rs`: reserved, rendered stoppable on the
//! pool) from the volume or its time point (`time.rs`), the drafts'
//! coarse copy (`drafts.rs`), a level held whole (`levels.rs`) or a level
//! in pieces (`pieces.rs`), annotated (`figure.rs`), encoded and sent;
//! after a still is sent the drafts' copy is made. When the mailbox
//! closes the thread ends and everything the tab held is given back.

mod drafts;
mod figure;
mod frame;
mod levels;
mod pieces;
mod probe;
mod render;
mod time;

pub use figure::FigureContext;
pub use time::{ReadTimePoint, TimePoints};

use crate::encode;
use crate::ledger::{Costs, Ledger, Overdrawn, Reservation};
use crate::levels::{LevelError, Levels};
use crate::mailbox::Mailbox;
use crate::protocol::{Quality, Request, ServerMessage};
use crate::reproduce::{Refusal, Reproduce};
use crate::stats::Stats;
use crate::watch::Watch;
use drafts::DraftCopy;
use levels::LevelTab;
use pieces::Pieces;
use std::sync::Arc;
use tokio::sync::mpsc;
use volray_core::scene::Scene;
use volray_core::{NonFinite, RenderError, Renderer, Volume};

/// What the renderer thread sends to the tab's socket.
#[derive(Debug)]
pub enum Outgoing {
    /// A frame: header and image, and the bytes reserved for the message
    /// until it is sent.
    Frame(Vec<u8>, Reservation),
    /// A JSON message (an error).
    Text(String),
}

/// What every tab's renderer shares.
pub struct Shared {
    pub volume: Arc<Volume>,
    pub non_finite: NonFinite,
    /// The bytes each tab's renderer may keep in brick caches.
    pub cache_budget: usize,
    pub reproduce: Arc<dyn Reproduce>,
    pub pool: Arc<rayon::ThreadPool>,
    pub stats: Arc<Stats>,
    /// The most tabs rendering at once (each has a thread).
    pub max_sessions: usize,
    /// The memory limit, and what the tabs and frames reserve from it.
    pub ledger: Arc<Ledger>,
    pub costs: Costs,
    /// A multiscale volume served level by level (`pyramid.rs`): then
    /// the tabs render its levels, not `volume`.
    pub levels: Option<Arc<Levels>>,
    /// A scene's other volumes, rendered with `volume` in one picture
    /// (`volray_core::scene`); their renderers are counted in
    /// `costs.tab`.
    pub others: Vec<Arc<Volume>>,
    /// A time axis served one time point at a time.
    pub time: Option<Arc<TimePoints>>,
    /// What the annotations need of the volume beyond its renderer.
    pub figure: Arc<FigureContext>,
    /// A volume of more voxels than this, served whole without a time
    /// axis, is drafted from a coarse copy (`coarse.rs`,
    /// [`coarse::COARSE_ABOVE`]).
    pub copy_above: usize,
    /// Where the volume may change between frames: asked for it before
    /// each frame (`watch.rs`; a whole volume without a time axis).
    pub watch: Option<Arc<dyn Watch>>,
}

/// A tab that could not be given a renderer.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("{0} tabs are open, the most this server renders at once: close one and reload")]
    TooMany(usize),
    #[error("{0}")]
    Memory(#[from] Overdrawn),
    #[error("cannot start a renderer thread: {0}")]
    Thread(#[from] std::io::Error),
}

/// A frame that could not be made.
#[derive(Debug, thiserror::Error)]
enum FrameError {
    #[error("{0}")]
    Refused(#[from] Refusal),
    #[error("{0}")]
    Memory(#[from] Overdrawn),
    #[error("{0}")]
    Render(#[from] RenderError),
    #[error("{0}")]
    Encode(#[from] encode::EncodeError),
    #[error("{0}")]
    Level(#[from] LevelError),
    /// A level too large for any piece to fit what the limit has left.
    #[error("{0}")]
    Pieces(String),
    /// A time point that could not be read, or is not served.
    #[error("{0}")]
    Time(String),
    /// The volume as its owner has it now could not be read.
    #[error("{0}")]
    Watch(String),
}

impl From<volray_core::camera::CameraError> for FrameError {
    fn from(e: volray_core::camera::CameraError) -> Self {
        FrameError::Render(e.into())
    }
}

/// Starts a tab's renderer thread, which serves `mailbox` until it closes
/// or the socket's end of `out` goes away; refused when
/// [`Shared::max_sessions`] are running or the tab's renderer does not
/// fit the memory limit beside the others.
pub fn spawn(
    shared: &Shared,
    mailbox: Arc<Mailbox<Request>>,
    out: mpsc::Sender<Outgoing>,
) -> Result<(), SpawnError> {
    let open =
        (shared.stats.open(shared.max_sessions)).ok_or(SpawnError::TooMany(shared.max_sessions))?;
    // A pyramid's tabs reserve a renderer for each level they hold.
    let tab_bytes = match shared.levels {
        Some(_) => 0,
        None => shared.costs.tab,
    };
    let held = shared.ledger.reserve("another tab's renderer", tab_bytes)?;
    let levels = shared.levels.clone();
    let others = shared.others.clone();
    let time = shared.time.clone();
    let figure = Arc::clone(&shared.figure);
    let volume = Arc::clone(&shared.volume);
    let reproduce = Arc::clone(&shared.reproduce);
    let pool = Arc::clone(&shared.pool);
    let stats = Arc::clone(&shared.stats);
    let ledger = Arc::clone(&shared.ledger);
    let costs = shared.costs;
    let non_finite = shared.non_finite;
    let cache_budget = shared.cache_budget;
    let copy_above = shared.copy_above;
    let watch = shared.watch.clone();
    std::thread::Builder::new()
        .name("view-render".into())
        .spawn(move || {
            // Given back when the renderer is freed, after it.
            let (_open, _held) = (open, held);
            let renderer = |volume| {
                Renderer::with_non_finite(volume, non_finite)
                    .map(|r| r.with_cache_budget(cache_budget))
            };
            let source = match levels {
                Some(levels) => Ok(Source::Levels(LevelTab {
                    levels,
                    renderers: Vec::new(),
                    streamed: Pieces::default(),
                })),
                None if others.is_empty() => renderer(&volume).map(|r| Source::Whole {
                    renderer: r,
                    time: None,
                    copy: DraftCopy::NotYet,
                }),
                None => (std::iter::once(&volume).chain(&others))
                    .map(|v| renderer(v))
                    .collect::<Result<Vec<_>, _>>()
                    .and_then(|layers| Scene::new(layers).map_err(RenderError::Scene))
                    .map(Source::Scene),
            };
            let source = match source {
                Ok(source) => source,
                Err(e) => {
                    let message = ServerMessage::Error {
                        seq: None,
                        message: e.to_string(),
                    };
                    let _ = out.blocking_send(Outgoing::Text(message.to_json()));
                    return;
                }
            };
            let mut tab = Tab {
                source,
                reproduce: &*reproduce,
                pool: &pool,
                stats: &stats,
                ledger: &ledger,
                costs,
                time: time.as_deref(),
                volume: &volume,
                last_still_ms: None,
                figure: &figure,
                copy_above,
                watch: watch.as_deref(),
                generation: 0,
            };
            while let Some(request) = mailbox.take() {
                if request.probe.is_some() {
                    let answer = tab.probe(&request);
                    mailbox.finished();
                    if out.blocking_send(Outgoing::Text(answer.to_json())).is_err() {
                        break;
                    }
                    continue;
                }
                // A still slow to render: a quick frame of it first. A
                // quick frame stopped stops its still too (the stop flag
                // stays set: the still would be stopped at its first
                // check, after classifying its bricks for nothing).
                let frame = match tab
                    .quick(&request)
                    .map(|q| tab.frame(&q, mailbox.stop_flag()))
                {
                    Some(Ok((message, reservation))) => {
                        stats.frame_rendered();
                        if out
                            .blocking_send(Outgoing::Frame(message, reservation))
                            .is_err()
                        {
                            break;
                        }
                        tab.frame(&request, mailbox.stop_flag())
                    }
                    Some(Err(FrameError::Render(RenderError::Stopped))) => {
                        Err(FrameError::Render(RenderError::Stopped))
                    }
                    _ => tab.frame(&request, mailbox.stop_flag()),
                };
                mailbox.finished();
                let outgoing = match frame {
                    Ok((message, reservation)) => {
                        stats.frame_rendered();
                        Outgoing::Frame(message, reservation)
                    }
                    // Superseded (the newer request is taken next) or
                    // closed (`take` says so): nothing to send.
                    Err(FrameError::Render(RenderError::Stopped)) => {
                        stats.frame_stopped();
                        continue;
                    }
                    Err(e) => {
                        if matches!(e, FrameError::Memory(_)) {
                            stats.frame_refused();
                        }
                        Outgoing::Text(
                            ServerMessage::Error {
                                seq: Some(request.seq),
                                message: e.to_string(),
                            }
                            .to_json(),
                        )
                    }
                };
                let sent_still =
                    request.quality == Quality::Full && matches!(outgoing, Outgoing::Frame(..));
                if out.blocking_send(outgoing).is_err() {
                    break;
                }
                if sent_still {
                    tab.prepare_drafts(&request);
                }
            }
            stats.add_dropped(mailbox.dropped());
        })?;
    Ok(())
}

/// What a tab renders: the volume (or a time point of it, read for the
/// tab and held with its bytes reserved), a scene of it and others, or a
/// pyramid's levels.
// One per tab, on its thread's stack: the sizes do not matter.
#[allow(clippy::large_enum_variant)]
enum Source<'a> {
    Whole {
        renderer: Renderer<'a>,
        time: Option<(usize, Reservation)>,
        /// The drafts' coarse copy of the volume.
        copy: DraftCopy,
    },
    Scene(Scene<'a>),
    Levels(LevelTab),
}

/// A tab's renderer and what it reports to.
struct Tab<'a> {
    source: Source<'a>,
    reproduce: &'a dyn Reproduce,
    pool: &'a rayon::ThreadPool,
    stats: &'a Stats,
    ledger: &'a Arc<Ledger>,
    costs: Costs,
    time: Option<&'a TimePoints>,
    /// The starting time point's volume.
    volume: &'a Volume,
    /// Milliseconds the last full-size frame took to render.
    last_still_ms: Option<f64>,
    figure: &'a FigureContext,
    /// See [`Shared::copy_above`].
    copy_above: usize,
    /// See [`Shared::watch`], and the generation of the volume this tab
    /// renders.
    watch: Option<&'a dyn Watch>,
    generation: u64,
}

impl Tab<'_> {
    /// The volume as its owner has it now, where it is watched: a new
    /// renderer (and no drafts' copy yet) where it changed since the last
    /// frame.
    fn watched(&mut self) -> Result<(), FrameError> {
        let (Some(watch), None, Source::Whole { renderer, copy, .. }) =
            (self.watch, self.time, &mut self.source)
        else {
            return Ok(());
        };
        let Some((generation, volume)) =
            watch.current(self.generation).map_err(FrameError::Watch)?
        else {
            return Ok(());
        };
        let budget = renderer.cache_budget();
        *renderer = Renderer::owning(volume, self.costs.non_finite())?.with_cache_budget(budget);
        *copy = DraftCopy::NotYet;
        self.generation = generation;
        Ok(())
    }
}

#[cfg(test)]
mod level_tests;

#[cfg(test)]
mod link_tests;

#[cfg(test)]
mod tests;
