//! # volray-view: explore a volume in the browser, rendered where it lives
//!
//! `volray view` serves one volume to a browser: the page orbits, zooms
//! and pans the camera, edits the transfer function over the volume's
//! histogram and switches blend modes, and the server renders each view
//! on its CPU cores and streams the frames back. Nothing is installed on
//! the viewing side but a browser, which may sit at the other end of an
//! SSH tunnel.
//!
//! ```text
//!  page (assets/) ──WebSocket: the whole ViewState, JSON──► server.rs ─► mailbox.rs (one slot:
//!    ▲  drag: "draft"; mouse-up: "full"                                  │  the latest request)
//!    │                                                                  ▼
//!    └──── binary: FrameHeader + JPEG (draft) or PNG (full) ◄── session/: the tab's thread,
//!          (protocol.rs)                               encode.rs     its own Renderer;
//!                                                                  Reproduce: state → settings
//!                                                                  and the `volray render` line
//! ```
//!
//! | file | what |
//! |---|---|
//! | `server.rs` | the routes (page, assets, `/ws`, `/api/status`), the token guard, a tab's socket loop |
//! | `token.rs` | the 128-bit access token and its constant-time check |
//! | `state.rs` | [`ViewState`]: what the page's controls set, and its bounds |
//! | `protocol.rs` | the messages both ways, parsed and checked |
//! | `mailbox.rs` | the single-slot mailbox: stale requests dropped, never queued; the stop flag of the frame a newer request supersedes |
//! | `session/` | a tab's renderer thread: reserve, render (stoppable), encode, send; `mod.rs` its life in order, then one file per concern (`frame.rs`, `render.rs`, `drafts.rs`, `levels.rs`, `pieces.rs`, `time.rs`, `figure.rs`, `probe.rs`) |
//! | `ledger.rs` | the memory limit shared by every tab: the volume, each tab's renderer, each frame in flight |
//! | `launch.rs` | [`launch::Launch`]: a viewer started from the volumes its front end read: the starting state checked and reproduced, the first message, the [`Viewer`] |
//! | `open.rs` | a chunked file opened level by level: its [`Pyramid`], the level read first |
//! | `pyramid.rs`, `levels.rs` | a multiscale volume served level by level; the levels read whole, shared by the tabs, read outside the cache's lock |
//! | `reproduce.rs` | [`Reproduce`]: the caller turns a state into settings and a command |
//! | `hello.rs` | the page's first message: histogram, colours, the start |
//! | `link.rs` | [`Host`]: the viewer without a server, its tabs' messages carried by the caller (the Jupyter widget), the frames a page has not acknowledged bounded |
//! | `watch.rs` | [`Watch`]: a volume its owner changes between frames (a numpy array), asked for before each frame |
//! | `options.rs` | a state as volray-options' [`volray_options::Options`], for front ends that render from options (Python) |
//! | `encode.rs` | JPEG and PNG, quantised as `volray render` writes PNGs |
//! | `stats.rs` | counters for `/api/status` |
//! | `page.rs`, `assets/` | the page, embedded; `assets/embed.js` carries its messages in an iframe of a notebook |
//!
//! The crate knows nothing of command-line flags: the caller's
//! [`Reproduce`] writes the state as a command and builds the settings
//! from that command, so that the still frame and the command agree.

mod coarse;
mod encode;
mod hello;
pub mod launch;
mod ledger;
mod levels;
mod link;
mod mailbox;
pub mod open;
mod page;
mod protocol;
mod pyramid;
mod server;
mod session;
mod stats;
mod token;
mod watch;

// The page's state and its reproduction live in volray-app (the viewer,
// the CLI and Python share them); named here as they were.
use volray_app::reproduce::{options, state, viewer as reproduce};

pub use hello::Start;
pub use ledger::{ENCODE_BYTES_PER_PIXEL, Overdrawn};
pub use link::{Host, MAX_IN_FLIGHT, Message, Tab};
pub use options::{OptionsStart, start_state, state_options};
pub use page::embedded_html;
pub use protocol::{
    Basis, FrameHeader, Hello, LevelShown, Quality, ServerMessage, VolumeHello, draft_side,
};
pub use pyramid::{CACHED_LEVELS, DRAFT_SHARE, Pyramid, PyramidError};
pub use reproduce::{Refusal, Reproduce, Reproduction, SceneLooks};
pub use server::{ServeError, Server, Stopper};
pub use session::{FigureContext, ReadTimePoint, SpawnError, TimePoints};
pub use state::{
    BlendMode, ColorBarSide, Figure, LayerState, Lighting, MAX_SIDE, START_COLOURS, STEP_RANGE,
    StateError, ViewState, WHITE, ZOOM_RANGE, solid_colour,
};
pub use stats::Snapshot;
pub use token::{NoRandomness, Token};
pub use watch::Watch;

use std::net::SocketAddr;
use std::sync::Arc;
use volray_core::{NonFinite, Volume};

/// Everything a viewer serves.
pub struct Viewer {
    /// The volume as rendered (log10 of the data's when the page is told
    /// so by [`Start::log`]).
    pub volume: Arc<Volume>,
    pub non_finite: NonFinite,
    /// The bytes each tab's renderer may keep in brick caches
    /// (`Renderer::with_cache_budget`); less where the limit needs it for
    /// the starting view's frame.
    pub cache_budget: usize,
    /// The memory limit of the whole server: the volume, every tab's
    /// renderer and every frame in flight, together.
    pub max_memory: u128,
    /// The page's first message ([`Start::hello`]).
    pub hello: Hello,
    pub reproduce: Arc<dyn Reproduce>,
    /// The workers every tab's frames are rendered on.
    pub pool: Arc<rayon::ThreadPool>,
    /// The most tabs rendering at once (each has a thread), whatever the
    /// memory allows.
    pub max_sessions: usize,
    /// A multiscale volume served level by level (`pyramid.rs`), and the
    /// level `volume` is: read whole by the caller for [`Start::hello`],
    /// it is the first level the server holds, and the tabs render the
    /// pyramid's levels instead of it.
    pub levels: Option<(Pyramid, usize)>,
    /// A scene's other volumes (`volray view --channels`, `--overlay`),
    /// rendered with `volume` in one picture, each as the state's
    /// `layers` and the caller's [`Reproduce`] say; not with `levels`.
    pub others: Vec<Arc<Volume>>,
    /// A time axis served one time point at a time (`volume` is the
    /// starting one); not with `levels`.
    pub time: Option<TimePoints>,
    /// What the frames' annotations need of the volume.
    pub figure: FigureContext,
}

/// A viewer that could not start.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("{0}")]
    Token(#[from] NoRandomness),
    #[error("{0}")]
    Serve(#[from] ServeError),
    #[error("the starting view: {0}")]
    Start(#[from] Refusal),
    #[error("{0}")]
    Memory(#[from] Overdrawn),
}

impl Viewer {
    /// Binds `addr` with a new access token; [`Server::run`] serves.
    pub fn bind(self, addr: SocketAddr) -> Result<Server, ViewError> {
        let token = Token::generate()?;
        Ok(Server::bind(addr, token, self.host()?)?)
    }

    /// The viewer without a server: its tabs' messages carried by the
    /// caller ([`Host::open`]), as the Python module's Jupyter widget
    /// carries them over the notebook's connection.
    pub fn host(self) -> Result<Host, ViewError> {
        if self.levels.is_some() && (!self.others.is_empty() || self.time.is_some()) {
            return Err(ViewError::Start(Refusal(
                "a multiscale volume is served alone, without other volumes or a time axis".into(),
            )));
        }
        let start = self.reproduce.reproduce(&self.hello.start)?.settings;
        let (mut costs, cache_budget) = ledger::Costs::fitting(
            &self.volume,
            &start,
            self.non_finite,
            self.cache_budget,
            self.max_memory,
        );
        // A scene's tab holds a renderer of each volume.
        for other in &self.others {
            let more = ledger::Costs::new(other, &start, self.non_finite, cache_budget);
            costs.volume += more.volume;
            costs.tab += more.tab;
        }
        let ledger = ledger::Ledger::new(self.max_memory);
        let (held, levels, volume) = match self.levels {
            None => (
                ledger.reserve("the volume", costs.volume)?,
                None,
                self.volume,
            ),
            Some((pyramid, level)) => {
                // The level read for the page's first message is the
                // first the server holds, its bytes reserved while held.
                let [x, y, z] = self.volume.dims();
                let what = format!("level {level} ({x}x{y}x{z}) read whole");
                let held = ledger.reserve(&what, costs.volume)?;
                let levels = levels::Levels::new(pyramid);
                let kept = levels.keep(level, Arc::unwrap_or_clone(self.volume), held);
                let nothing = ledger.reserve("nothing", 0)?;
                (nothing, Some(Arc::new(levels)), Arc::new(kept))
            }
        };
        let hello = ServerMessage::Hello(Box::new(self.hello)).to_json();
        let shared = session::Shared {
            volume,
            non_finite: self.non_finite,
            cache_budget,
            reproduce: self.reproduce,
            pool: self.pool,
            stats: Arc::new(stats::Stats::default()),
            max_sessions: self.max_sessions,
            ledger,
            costs,
            levels,
            others: self.others,
            time: self.time.map(Arc::new),
            figure: Arc::new(self.figure),
            copy_above: coarse::COARSE_ABOVE,
            watch: None,
        };
        Ok(Host {
            hello,
            shared,
            volume: held,
        })
    }
}
