//! One tab's renderer: a thread of its own that owns a
//! [`Renderer`] of the volume (so that the bricks classified for this
//! tab's transfer function are kept from frame to frame, whatever other
//! tabs do), takes the latest request from a single-slot [`Mailbox`],
//! renders it, encodes it, and hands the message to the tab's socket
//! through a channel of one, so that a slow page slows the renderer
//! instead of queueing frames.
//!
//! A frame is rendered with the mailbox's stop flag
//! (`FrameRequest::stopped_by`): a newer request for the tab, or the
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

use crate::coarse;
use crate::encode::{self, DRAFT_QUALITY};
use crate::ledger::{Costs, Ledger, Overdrawn, Reservation};
use crate::levels::{LevelError, Levels};
use crate::mailbox::Mailbox;
use crate::protocol::{
    Basis, DRAFT_SCALE_RANGE, FrameHeader, LevelShown, Quality, Request, ServerMessage,
    frame_message,
};
use crate::reproduce::{Refusal, Reproduce};
use crate::state::Figure;
use crate::stats::Stats;
use crate::watch::Watch;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;
use tokio::sync::mpsc;
use volray_annotate::figure::{Rendered, annotate_frame};
use volray_core::camera::View;
use volray_core::scene::{Look, Scene, SceneSettings};
use volray_core::{
    FrameRequest, Image, MemoryBound, NonFinite, Render, RenderError, RenderSettings, Renderer,
    Volume,
};
use volray_distributed::streamed::{StreamError, Streamed};

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

/// What a frame's annotations (`ViewState::figure`) need to know of the
/// volume beyond its renderer, as `volray render` takes it from the file
/// and the flags: whether it was rendered as log10, its units, the names
/// of its axes.
#[derive(Debug, Clone)]
pub struct FigureContext {
    pub log: bool,
    /// `HU` for a CT preset.
    pub value_unit: Option<String>,
    /// The file's length unit (`mm`).
    pub length_unit: Option<String>,
    /// The names of the world's +x, +y, +z (`R`, `A`, `S` for NIfTI).
    pub axis_names: [String; 3],
}

impl Default for FigureContext {
    fn default() -> Self {
        FigureContext {
            log: false,
            value_unit: None,
            length_unit: None,
            axis_names: ["x", "y", "z"].map(String::from),
        }
    }
}

/// Reads one time point of a file as a volume, or says why not in one line.
pub type ReadTimePoint = dyn Fn(usize) -> Result<Volume, String> + Send + Sync;

/// The time points a viewer serves (`volray view --frames`): `volume` is
/// the starting one; a tab asked for another reads it, holding it (its
/// bytes reserved) until it is asked for the next.
pub struct TimePoints {
    /// `[first, end)`, as the file counts its frames.
    pub range: [usize; 2],
    /// The time point `volume` is.
    pub start: usize,
    pub read: Box<ReadTimePoint>,
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
                    streamed: None,
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

/// A tab's coarse copy of its volume for the drafts (`coarse.rs`), made
/// after the first still or on the first draft that takes it, and kept
/// with the tab's renderer.
// One per tab: the sizes do not matter.
#[allow(clippy::large_enum_variant)]
enum DraftCopy {
    NotYet,
    /// The copy's renderer, its smallest spacing over the volume's, and
    /// the bytes reserved for it (its samples and its renderer's
    /// structures, its brick caches at an eighth of the tab's budget).
    Made {
        renderer: Renderer<'static>,
        ratio: f64,
        _reserved: Reservation,
    },
    /// It did not fit what the memory limit has left: the drafts come
    /// from the volume, as for a small one.
    Refused,
}

impl DraftCopy {
    /// The copy's renderer and spacing ratio for a draft of `settings`
    /// of `renderer`'s volume, made now if it is the first; `None` where
    /// the drafts come from the volume itself.
    fn renderer(
        &mut self,
        cx: &Context,
        renderer: &Renderer,
        settings: &RenderSettings,
        above: usize,
    ) -> Option<(&Renderer<'static>, f64)> {
        let volume = renderer.volume();
        if volume.len() <= above || !coarse::drafts_from_copy(volume, settings) {
            return None;
        }
        if let DraftCopy::NotYet = self {
            *self = Self::make(cx, volume, settings).unwrap_or(DraftCopy::Refused);
        }
        match self {
            DraftCopy::Made {
                renderer, ratio, ..
            } => Some((renderer, *ratio)),
            _ => None,
        }
    }

    fn make(cx: &Context, volume: &Volume, settings: &RenderSettings) -> Option<DraftCopy> {
        let copy = cx.pool.install(|| coarse::halved(volume));
        let ratio = coarse::spacing_ratio(volume, &copy);
        let budget = cx.costs.cache_budget() / 8;
        let non_finite = cx.costs.non_finite();
        let bound = MemoryBound::for_volume(&copy, settings, non_finite, budget);
        let reserved = (cx.ledger)
            .reserve(
                "the drafts' coarse copy of the volume",
                bound.volume + bound.cleaned + bound.path,
            )
            .ok()?;
        let renderer = Renderer::owning(copy, non_finite).ok()?;
        Some(DraftCopy::Made {
            renderer: renderer.with_cache_budget(budget),
            ratio,
            _reserved: reserved,
        })
    }
}

/// A still that took longer than this to render is preceded by a quick
/// frame ([`Tab::quick`]) the next time.
pub const SLOW_STILL_MS: f64 = 300.0;

/// What a quick frame aims to take.
const QUICK_MS: f64 = 80.0;

/// A frame rendered, before it is encoded.
struct Drawn {
    image: Image,
    basis: Basis,
    level: Option<LevelShown>,
    /// The frame's bytes, and the part the message keeps until sent.
    reserved: Reservation,
    message_bytes: u128,
}

impl Tab<'_> {
    /// After the still `request` was sent: the drafts' coarse copy made
    /// now, while the page shows the still, rather than on the first
    /// draft of a drag, which would wait for it (0.08 s for 257³ voxels,
    /// 0.7 s for 512³ on two busy cores). A request that comes meanwhile
    /// waits as long.
    fn prepare_drafts(&mut self, request: &Request) {
        let Source::Whole { renderer, copy, .. } = &mut self.source else {
            return;
        };
        let small = renderer.volume().len() <= self.copy_above;
        if self.time.is_some() || small || !matches!(copy, DraftCopy::NotYet) {
            return;
        }
        let Ok(reproduction) = self.reproduce.reproduce(&request.state) else {
            return;
        };
        let never = AtomicBool::new(false);
        let cx = Context {
            pool: self.pool,
            stats: self.stats,
            ledger: self.ledger,
            costs: self.costs,
            stop: &never,
            what: "the drafts' copy",
        };
        copy.renderer(&cx, renderer, &reproduction.settings, self.copy_above);
    }

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

    /// A quick draft of the still `request` asks for, where the last still
    /// took longer than [`SLOW_STILL_MS`]: its scale aims at [`QUICK_MS`]
    /// (the time goes with the pixels, the square of the scale).
    fn quick(&self, request: &Request) -> Option<Request> {
        quick_request(self.last_still_ms, request)
    }

    /// Draws `figure` into `image`, a frame of `settings`, as `volray
    /// render` draws it: the first volume's colour bar and scale bar in
    /// the view framing every volume, the box of each for the outline.
    fn annotate(
        &self,
        image: &mut Image,
        figure: &Figure,
        settings: &RenderSettings,
    ) -> Result<(), FrameError> {
        // The unit is the context's value_unit (the start's).
        let what = figure.annotations();
        let (first, framed, boxes) = match &self.source {
            Source::Whole { renderer, .. } => {
                (renderer, settings.clone(), vec![renderer.volume().bounds()])
            }
            Source::Scene(scene) => {
                let boxes = scene.layers().iter().map(|r| r.volume().bounds()).collect();
                (&scene.layers()[0], framed(scene, settings), boxes)
            }
            Source::Levels(_) => return Ok(()),
        };
        let cx = self.figure;
        let [x, y, z] = &cx.axis_names;
        let rendered = Rendered {
            log: cx.log,
            value_unit: cx.value_unit.as_deref(),
            length_unit: cx.length_unit.as_deref(),
            axis_names: [x.as_str(), y.as_str(), z.as_str()],
            boxes: &boxes,
            scale_box: first.volume().bounds(),
        };
        annotate_frame(image, &what, first, &framed, &rendered)?;
        Ok(())
    }

    /// What the pixel `request` probes shows, in the frame of its state
    /// (at the time point this tab shows; the first volume of a scene;
    /// nothing yet for a pyramid's levels).
    fn probe(&mut self, request: &Request) -> ServerMessage {
        let [col, row] = request.probe.unwrap_or_default();
        let found = (|| -> Result<Option<volray_core::probe::Probe>, FrameError> {
            let settings = self.reproduce.reproduce(&request.state)?.settings;
            Ok(match &self.source {
                Source::Whole { renderer, .. } => renderer.probe(&settings, col, row)?,
                Source::Scene(scene) => {
                    scene.layers()[0].probe(&framed(scene, &settings), col, row)?
                }
                Source::Levels(_) => None,
            })
        })();
        match found {
            Ok(found) => ServerMessage::Probe {
                seq: request.seq,
                position: found.map(|p| p.position.to_array()),
                index: found.map(|p| p.index.to_array()),
                value: found.map(|p| p.value),
            },
            Err(e) => ServerMessage::Error {
                seq: Some(request.seq),
                message: e.to_string(),
            },
        }
    }

    /// The frame `request` asks for, as a binary message, and the bytes
    /// reserved for the message until it is sent; stopped when `stop` is
    /// set.
    fn frame(
        &mut self,
        request: &Request,
        stop: &AtomicBool,
    ) -> Result<(Vec<u8>, Reservation), FrameError> {
        let reproduction = self.reproduce.reproduce(&request.state)?;
        let full = &reproduction.settings;
        let settings = match request.quality {
            Quality::Draft => RenderSettings {
                width: scaled(full.width, request.draft_scale),
                height: scaled(full.height, request.draft_scale),
                ..full.clone()
            },
            Quality::Full | Quality::Save => full.clone(),
        };
        let what = format!("a {}x{} frame", settings.width, settings.height);
        let start = Instant::now();
        let cx = Context {
            pool: self.pool,
            stats: self.stats,
            ledger: self.ledger,
            costs: self.costs,
            stop,
            what: &what,
        };
        let figure = &request.state.figure;
        if !figure.is_bare() && matches!(self.source, Source::Levels(_)) {
            return Err(FrameError::Refused(Refusal(
                "the figure's annotations are not drawn on a multiscale volume's levels yet".into(),
            )));
        }
        self.watched()?;
        let mut drawn = match &mut self.source {
            Source::Whole {
                renderer,
                time,
                copy,
            } => {
                if let Some(points) = self.time {
                    at_time(points, self.volume, request.state.time, renderer, time, &cx)?;
                }
                let drafted = (request.quality == Quality::Draft && self.time.is_none())
                    .then(|| copy.renderer(&cx, renderer, &settings, self.copy_above))
                    .flatten();
                match drafted {
                    Some((coarse, ratio)) => {
                        let drawn = coarse::draft_settings(
                            &settings,
                            renderer.value_range(),
                            ratio,
                            || renderer.max_gradient(),
                        );
                        cx.whole(renderer, coarse, full, &drawn)?
                    }
                    None => cx.whole(renderer, renderer, full, &settings)?,
                }
            }
            Source::Scene(scene) => {
                let Some(looks) = &reproduction.scene else {
                    return Err(FrameError::Time(
                        "the state has no looks for the scene's other volumes".into(),
                    ));
                };
                let request = SceneSettings {
                    settings: settings.clone(),
                    looks: std::iter::once(Look::of(&settings))
                        .chain(looks.looks.iter().cloned())
                        .collect(),
                    mix: looks.mix,
                };
                cx.scene(scene, full, &request)?
            }
            Source::Levels(tab) => tab.draw(&cx, request.quality, full, &settings)?,
        };
        if !figure.is_bare() {
            self.annotate(&mut drawn.image, figure, &settings)?;
        }
        let Drawn {
            image,
            basis,
            level,
            mut reserved,
            message_bytes,
        } = drawn;
        let rendered = Instant::now();
        if request.quality == Quality::Full {
            self.last_still_ms = Some((rendered - start).as_secs_f64() * 1e3);
        }
        let mut rgb = Vec::new();
        let (mime, bytes) = match request.quality {
            Quality::Draft => ("image/jpeg", encode::jpeg(&image, DRAFT_QUALITY, &mut rgb)?),
            Quality::Full | Quality::Save => ("image/png", encode::png(&image, &mut rgb)?),
        };
        drop((image, rgb));
        let header = FrameHeader {
            seq: request.seq,
            quality: request.quality,
            mime,
            width: settings.width,
            height: settings.height,
            render_ms: (rendered - start).as_secs_f64() * 1e3,
            encode_ms: rendered.elapsed().as_secs_f64() * 1e3,
            command: reproduction.command,
            tf_file: reproduction.tf_file,
            layer_tf_files: reproduction.scene.map(|s| s.tf_files).unwrap_or_default(),
            basis,
            level,
        };
        // The pixels are given back here; the message's bytes when sent.
        Ok((
            frame_message(&header, &bytes),
            reserved.split_off(message_bytes),
        ))
    }
}

/// What rendering a frame reports to and is stopped by.
struct Context<'a> {
    pool: &'a rayon::ThreadPool,
    stats: &'a Stats,
    ledger: &'a Arc<Ledger>,
    costs: Costs,
    stop: &'a AtomicBool,
    /// "a WxH frame", for a refusal.
    what: &'a str,
}

impl Context<'_> {
    /// A frame of `settings` drawn by `drawing` (`renderer`, or its
    /// volume's coarse copy for a draft); its basis is that of `full`
    /// from `renderer`.
    fn whole(
        &self,
        renderer: &Renderer,
        drawing: &Renderer,
        full: &RenderSettings,
        settings: &RenderSettings,
    ) -> Result<Drawn, FrameError> {
        let basis = basis(renderer, full)?;
        let (bytes, message_bytes) = self.costs.frame(drawing.volume(), settings);
        let reserved = self.ledger.reserve(self.what, bytes)?;
        let image = self.render(drawing, settings)?;
        Ok(Drawn {
            image,
            basis,
            level: None,
            reserved,
            message_bytes,
        })
    }

    /// A frame of the scene `request` asks for; its basis is that of the
    /// full-size frame `full`, framing every volume.
    fn scene(
        &self,
        scene: &Scene,
        full: &RenderSettings,
        request: &SceneSettings,
    ) -> Result<Drawn, FrameError> {
        let basis = basis(&scene.layers()[0], &framed(scene, full))?;
        // Each volume's path and frame, as if each were rendered apart
        // (the additive mix and the projections are): an upper bound.
        let mut bytes = 0;
        let mut message_bytes = 0;
        for layer in scene.layers() {
            let (b, m) = self.costs.frame(layer.volume(), &request.settings);
            bytes += b;
            message_bytes = m;
        }
        let reserved = self.ledger.reserve(self.what, bytes)?;
        let image = self.rendering(|| {
            scene
                .render(FrameRequest::new(request).stopped_by(self.stop))
                .map(volray_core::Rendered::image)
        })?;
        Ok(Drawn {
            image,
            basis,
            level: None,
            reserved,
            message_bytes,
        })
    }

    fn render(&self, renderer: &Renderer, settings: &RenderSettings) -> Result<Image, FrameError> {
        // A fresh frame buffer each time (not one kept across frames):
        // what a tab holds between frames is then its caches alone.
        let request = FrameRequest::new(settings).stopped_by(self.stop);
        self.rendering(|| renderer.render(request).map(volray_core::Rendered::image))
    }

    /// `work` on the pool, counted as a frame rendering; not started
    /// when the frame is stopped already (a renderer would classify its
    /// bricks before its first check: 0.44 s for `fractal:257` at step
    /// 0.01, more for a 512³ volume).
    fn rendering(
        &self,
        work: impl FnOnce() -> Result<Image, RenderError> + Send,
    ) -> Result<Image, FrameError> {
        if self.stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(RenderError::Stopped.into());
        }
        let _rendering = self.stats.rendering();
        Ok(self.pool.install(work)?)
    }
}

/// A tab's part of a pyramid: its renderers of the levels held whole and
/// the still's level rendered piece by piece.
struct LevelTab {
    levels: Arc<Levels>,
    /// Renderers of levels held whole, the last used last, with the
    /// bytes reserved for their structures; at most two (the drafts' and
    /// the still's level).
    renderers: Vec<(usize, Renderer<'static>, Reservation)>,
    /// A level rendered piece by piece, with its budget: kept so that
    /// what it learnt of its pieces (their value ranges) serves the next
    /// still.
    streamed: Option<(usize, u64, Streamed)>,
}

impl LevelTab {
    /// A frame of `settings` (the full-size frame's `full`): a draft from
    /// a coarse level held whole, a still from the level it needs, whole
    /// if it fits what the memory limit has left, else in pieces; either
    /// framed on the still's level's box.
    fn draw(
        &mut self,
        cx: &Context,
        quality: Quality,
        full: &RenderSettings,
        settings: &RenderSettings,
    ) -> Result<Drawn, FrameError> {
        let levels = Arc::clone(&self.levels);
        let pyramid = &levels.pyramid;
        let non_finite = cx.costs.non_finite();
        settings.validate().map_err(RenderError::from)?;
        let still = pyramid.still_level(full)?;
        let grid = pyramid.grid(still);
        let basis = basis_of(&View::frame(
            &full.camera,
            grid.bounds(),
            full.width,
            full.height,
        )?);
        let limit = cx.ledger.limit();
        let (level, whole) = match quality {
            Quality::Draft => match pyramid.draft_level(settings, still, non_finite, limit)? {
                Some(level) => (level, true),
                // Even the coarsest level is too large to hold: in pieces.
                None => (pyramid.len() - 1, false),
            },
            Quality::Full | Quality::Save => {
                let (extra, _) = cx.costs.pieces_frame(settings);
                let held = if levels.is_held(still) {
                    pyramid.volume_bytes(still)
                } else {
                    0
                };
                let need =
                    (pyramid.whole_bytes(still, settings, non_finite) + extra).saturating_sub(held);
                let free = limit.saturating_sub(cx.ledger.held());
                (still, need <= free)
            }
        };
        // Whichever level it shows, the frame is framed as the still
        // (`Pyramid::framed`): no jump when the still replaces the drafts.
        let framed = pyramid.framed(settings, still);
        let (image, shown, reserved, message_bytes) = if whole {
            self.whole(cx, level, &framed)?
        } else {
            self.pieces(cx, level, &framed)?
        };
        Ok(Drawn {
            image,
            basis,
            level: Some(shown),
            reserved,
            message_bytes,
        })
    }

    /// A frame of level `level` held whole.
    fn whole(
        &mut self,
        cx: &Context,
        level: usize,
        settings: &RenderSettings,
    ) -> Result<(Image, LevelShown, Reservation, u128), FrameError> {
        let levels = &self.levels;
        let pyramid = &levels.pyramid;
        let non_finite = cx.costs.non_finite();
        let cache_budget = cx.costs.cache_budget();
        let read = usize::from(!levels.is_held(level));
        let index = match self.renderers.iter().position(|(l, ..)| *l == level) {
            Some(i) => i,
            None => {
                // This tab lets go of its renderers of other levels but
                // the last one used (the drafts' or the still's).
                let over = self.renderers.len().saturating_sub(1);
                self.renderers.drain(..over);
                let volume = levels.whole(level, cx.ledger)?;
                let bound = pyramid.bound(level, settings, non_finite, cache_budget);
                let what = format!("a renderer of level {level}");
                let structures = cx.ledger.reserve(&what, bound.cleaned + bound.path)?;
                let renderer =
                    Renderer::owning(volume, non_finite)?.with_cache_budget(cache_budget);
                self.renderers.push((level, renderer, structures));
                self.renderers.len() - 1
            }
        };
        let entry = self.renderers.remove(index);
        self.renderers.push(entry);
        let (_, renderer, structures) = self.renderers.last().expect("pushed above");
        let bound = pyramid.bound(level, settings, non_finite, cache_budget);
        let (bytes, message_bytes) = cx.costs.frame_of(&bound, settings, structures.bytes());
        let reserved = cx.ledger.reserve(cx.what, bytes)?;
        let image = cx.render(renderer, settings)?;
        let shown = LevelShown {
            index: level,
            count: pyramid.len(),
            dims: pyramid.grid(level).dims,
            pieces: 1,
            read,
        };
        Ok((image, shown, reserved, message_bytes))
    }

    /// A frame of level `level` rendered piece by piece, in pieces that
    /// fit what the memory limit has left (at most
    /// [`volray_lazy::PIECE_BUDGET`]).
    fn pieces(
        &mut self,
        cx: &Context,
        level: usize,
        settings: &RenderSettings,
    ) -> Result<(Image, LevelShown, Reservation, u128), FrameError> {
        let pyramid = &self.levels.pyramid;
        let non_finite = cx.costs.non_finite();
        let (extra, message_bytes) = cx.costs.pieces_frame(settings);
        let free = (cx.ledger.limit())
            .saturating_sub(cx.ledger.held())
            .saturating_sub(extra);
        let budget = u64::try_from(free)
            .unwrap_or(u64::MAX)
            .min(volray_lazy::PIECE_BUDGET);
        let keep = matches!(&self.streamed, Some((l, b, _)) if *l == level && *b <= budget);
        if !keep {
            let source = Arc::clone(pyramid.source(level));
            let streamed = Streamed::new(source, non_finite, budget).with_labels(pyramid.labels());
            self.streamed = Some((level, budget, streamed));
        }
        let (_, budget, streamed) = self.streamed.as_mut().expect("set above");
        let reserved = cx.ledger.reserve(cx.what, extra + u128::from(*budget))?;
        let rendered = {
            let _rendering = cx.stats.rendering();
            cx.pool
                .install(|| streamed.render(FrameRequest::new(settings).stopped_by(cx.stop)))
                .map(volray_core::Rendered::image_and_times)
        };
        let [x, y, z] = pyramid.grid(level).dims;
        let (image, times) = rendered.map_err(|e| match e {
            StreamError::Render(e) => FrameError::Render(e),
            StreamError::Read(m) => FrameError::Level(LevelError::Read(m)),
            StreamError::TooLarge(m) => FrameError::Pieces(format!(
                "level {level} ({x}x{y}x{z}) in pieces: {m}: wait for the other tabs' frames, or raise --max-memory"
            )),
        })?;
        let shown = LevelShown {
            index: level,
            count: pyramid.len(),
            dims: [x, y, z],
            pieces: times.pieces,
            read: times.read_pieces,
        };
        Ok((image, shown, reserved, message_bytes))
    }
}

/// Makes `renderer` render the time point `asked` (`None`: the starting
/// one): a time point other than the starting one is read for this tab
/// and held, its bytes reserved, until another is asked for.
fn at_time<'a>(
    points: &TimePoints,
    start: &'a Volume,
    asked: Option<usize>,
    renderer: &mut Renderer<'a>,
    held: &mut Option<(usize, Reservation)>,
    cx: &Context,
) -> Result<(), FrameError> {
    let asked = asked.unwrap_or(points.start);
    let [first, end] = points.range;
    if !(first..end).contains(&asked) {
        return Err(FrameError::Time(format!(
            "time point {asked} is not served: {first} to {}",
            end - 1
        )));
    }
    let now = held.as_ref().map_or(points.start, |(t, _)| *t);
    if now == asked {
        return Ok(());
    }
    // Back to the starting time point, letting go of the one held before
    // the next is read.
    let budget = renderer.cache_budget();
    let non_finite = cx.costs.non_finite();
    *renderer = Renderer::with_non_finite(start, non_finite)?.with_cache_budget(budget);
    *held = None;
    if asked == points.start {
        return Ok(());
    }
    let reserved = (cx.ledger).reserve(&format!("time point {asked}"), cx.costs.volume)?;
    let volume = (points.read)(asked).map_err(FrameError::Time)?;
    *renderer = Renderer::owning(volume, non_finite)?.with_cache_budget(budget);
    *held = Some((asked, reserved));
    Ok(())
}

/// [`Tab::quick`], for a tab whose last still took `last_still_ms`.
fn quick_request(last_still_ms: Option<f64>, request: &Request) -> Option<Request> {
    let last = last_still_ms?;
    if request.quality != Quality::Full || last <= SLOW_STILL_MS {
        return None;
    }
    let (lo, hi) = DRAFT_SCALE_RANGE;
    Some(Request {
        quality: Quality::Draft,
        draft_scale: (QUICK_MS / last).sqrt().clamp(lo, hi),
        ..request.clone()
    })
    .filter(|_| request.probe.is_none())
}

/// `settings` for the scene's first volume alone, its camera framing
/// every volume's box as the scene's frames do (for its basis, probe and
/// annotations).
fn framed(scene: &Scene, settings: &RenderSettings) -> RenderSettings {
    let mut framed = settings.clone();
    framed.camera.bounds = Some(framed.camera.framed_bounds(scene.bounds()));
    framed
}

/// A side of `full` pixels at `scale`, at least one pixel.
fn scaled(full: usize, scale: f64) -> usize {
    ((full as f64 * scale).round() as usize).max(1)
}

/// A draft frame's side: half the full frame's, at least one pixel.
pub fn draft_side(full: usize) -> usize {
    full.div_ceil(2)
}

/// The screen axes of the full-size view of `settings`, for panning.
fn basis(renderer: &Renderer, settings: &RenderSettings) -> Result<Basis, RenderError> {
    let frame = renderer.prepare(settings)?;
    Ok(basis_of(&frame.view))
}

/// The screen axes of `view`.
fn basis_of(view: &View) -> Basis {
    let (reference, right, up, units_per_pixel) = match *view {
        View::Orthographic(v) => (v.centre, v.right, v.up, v.pixel_size),
        View::Perspective(v) => (
            v.reference,
            v.right,
            v.up,
            v.pixel_size * (v.reference - v.eye).length(),
        ),
    };
    Basis {
        reference: reference.to_array(),
        right: right.to_array(),
        up: up.to_array(),
        pixels_per_unit: 1.0 / units_per_pixel,
    }
}

#[cfg(test)]
mod level_tests;

#[cfg(test)]
mod link_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mailbox::Slot;
    use crate::protocol::Quality;
    use crate::reproduce::Reproduction;
    use crate::state::ViewState;
    use crate::state::tests::sample;
    use volray_core::glam::DVec3;

    /// Something done on the renderer's thread between taking a request
    /// and rendering it.
    type Meanwhile = Box<dyn FnOnce() + Send>;

    /// Renders states with the library's defaults and their camera; the
    /// first state whose azimuth is `meanwhile`'s runs its closure while
    /// being reproduced, after its request was taken and before its
    /// frame is rendered: what a page does during a frame, without a race.
    #[derive(Default)]
    pub(super) struct Plain {
        meanwhile: std::sync::Mutex<Option<(f64, Meanwhile)>>,
    }

    impl Reproduce for Plain {
        fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal> {
            if state.zoom > 100.0 {
                return Err(Refusal("too close".into()));
            }
            let mut meanwhile = self.meanwhile.lock().unwrap();
            if meanwhile.as_ref().is_some_and(|(a, _)| *a == state.azimuth) {
                let (_, act) = meanwhile.take().unwrap();
                act();
            }
            let mut settings = RenderSettings {
                width: state.width,
                height: state.height,
                ..RenderSettings::default()
            };
            settings.camera.azimuth = state.azimuth;
            Ok(Reproduction {
                settings,
                command: format!("render --azimuth {}", state.azimuth),
                tf_file: None,
                scene: None,
            })
        }
    }

    fn shared() -> Shared {
        shared_with(Arc::new(Plain::default()), u128::MAX, 1)
    }

    /// A view of 17³ voxels with `reproduce`, a memory limit and a most
    /// tabs.
    pub(super) fn shared_with(reproduce: Arc<Plain>, limit: u128, max_sessions: usize) -> Shared {
        let n = 17;
        let h = 2.0 / (n - 1) as f64;
        let volume = Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
            (1.0 - p.length()).max(0.0) as f32
        })
        .unwrap();
        let start = RenderSettings::default();
        let cache_budget = 1 << 20;
        let costs = Costs::new(&volume, &start, NonFinite::Refuse, cache_budget);
        Shared {
            volume: Arc::new(volume),
            non_finite: NonFinite::Refuse,
            cache_budget,
            reproduce,
            pool: Arc::new(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(1)
                    .build()
                    .unwrap(),
            ),
            stats: Arc::new(Stats::default()),
            max_sessions,
            ledger: Ledger::new(limit),
            costs,
            levels: None,
            others: Vec::new(),
            time: None,
            figure: Arc::new(FigureContext::default()),
            copy_above: usize::MAX,
            watch: None,
        }
    }

    /// A view request for a `side`² frame at `azimuth`.
    pub(super) fn request(seq: u64, quality: Quality, side: usize, azimuth: f64) -> Request {
        let mut state = sample();
        (state.width, state.height, state.azimuth) = (side, side, azimuth);
        Request {
            seq,
            quality,
            state,
            draft_scale: crate::protocol::DRAFT_SCALE,
            probe: None,
        }
    }

    pub(super) fn header(message: &[u8]) -> serde_json::Value {
        let n = u32::from_le_bytes(message[..4].try_into().unwrap()) as usize;
        serde_json::from_slice(&message[4..4 + n]).unwrap()
    }

    #[test]
    fn the_latest_request_is_rendered_and_stale_ones_are_dropped() {
        let shared = shared();
        let mailbox = Arc::new(Mailbox::default());
        let (tx, mut rx) = mpsc::channel(1);
        // A burst before the renderer starts: only the last is rendered.
        for seq in 0..1000 {
            let mut state = sample();
            state.width = 32;
            state.height = 32;
            state.azimuth = seq as f64;
            let quality = if seq == 999 {
                Quality::Full
            } else {
                Quality::Draft
            };
            mailbox.put(
                Slot::Latest,
                Request {
                    seq,
                    quality,
                    state,
                    draft_scale: crate::protocol::DRAFT_SCALE,
                    probe: None,
                },
            );
        }
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        // One renderer at most: a second tab is refused.
        let refused = spawn(&shared, Arc::new(Mailbox::default()), mpsc::channel(1).0);
        assert!(matches!(refused, Err(SpawnError::TooMany(1))));
        let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
            panic!("no frame")
        };
        let h = header(&message);
        assert_eq!(h["seq"], 999);
        assert_eq!(h["quality"], "full");
        assert_eq!(h["mime"], "image/png");
        assert_eq!(
            (h["width"].as_u64(), h["height"].as_u64()),
            (Some(32), Some(32))
        );
        assert_eq!(h["command"], "render --azimuth 999");
        assert_eq!(shared.stats.sessions(), 1);

        // A draft is half size, a JPEG; a refusal is an error naming the seq.
        let mut state = sample();
        state.width = 33;
        mailbox.put(
            Slot::Latest,
            Request {
                seq: 1000,
                quality: Quality::Draft,
                state: state.clone(),
                draft_scale: crate::protocol::DRAFT_SCALE,
                probe: None,
            },
        );
        let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
            panic!("no frame")
        };
        let h = header(&message);
        assert_eq!(
            (h["width"].as_u64(), h["mime"].as_str()),
            (Some(17), Some("image/jpeg"))
        );
        state.zoom = 200.0;
        mailbox.put(
            Slot::Latest,
            Request {
                seq: 1001,
                quality: Quality::Full,
                state,
                draft_scale: crate::protocol::DRAFT_SCALE,
                probe: None,
            },
        );
        let Some(Outgoing::Text(text)) = rx.blocking_recv() else {
            panic!("no error")
        };
        assert_eq!(text, r#"{"type":"error","seq":1001,"message":"too close"}"#);

        // Closing the mailbox ends the thread and frees the tab.
        mailbox.close();
        assert!(rx.blocking_recv().is_none());
        assert_eq!(shared.stats.sessions(), 0);
        assert_eq!(shared.stats.frames(), 2);
        assert_eq!(shared.stats.dropped(), 999);
        assert_eq!(shared.ledger.held(), 0);
    }

    #[test]
    fn a_frame_superseded_while_it_renders_is_stopped_and_the_newer_one_sent() {
        let plain = Arc::new(Plain::default());
        let shared = shared_with(Arc::clone(&plain), u128::MAX, 1);
        let mailbox = Arc::new(Mailbox::default());
        // While the first frame is about to render, the page asks for
        // another view.
        let page = Arc::clone(&mailbox);
        *plain.meanwhile.lock().unwrap() = Some((
            1.0,
            Box::new(move || page.put(Slot::Latest, request(2, Quality::Full, 48, 2.0))),
        ));
        mailbox.put(Slot::Latest, request(1, Quality::Full, 48, 1.0));
        let (tx, mut rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
            panic!("no frame")
        };
        // The first frame was stopped, not sent: the next is the newer.
        assert_eq!(header(&message)["seq"], 2);
        assert_eq!(shared.stats.stopped(), 1);
        assert_eq!(shared.stats.frames(), 1);
        mailbox.close();
        assert!(rx.blocking_recv().is_none());
        let status = shared.stats.snapshot(&shared.ledger);
        assert_eq!((status.sessions, status.rendering), (0, 0));
    }

    #[test]
    fn closing_the_tab_stops_its_frame_and_frees_its_renderer() {
        let plain = Arc::new(Plain::default());
        let shared = shared_with(Arc::clone(&plain), u128::MAX, 1);
        let mailbox = Arc::new(Mailbox::default());
        let page = Arc::clone(&mailbox);
        *plain.meanwhile.lock().unwrap() = Some((1.0, Box::new(move || page.close())));
        mailbox.put(Slot::Latest, request(1, Quality::Full, 48, 1.0));
        let (tx, mut rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        // The frame is stopped, nothing is sent, and the thread ends.
        assert!(rx.blocking_recv().is_none());
        let status = shared.stats.snapshot(&shared.ledger);
        assert_eq!(
            (
                status.sessions,
                status.rendering,
                status.frames,
                status.stopped
            ),
            (0, 0, 0, 1)
        );
        assert_eq!(shared.ledger.held(), 0);
    }

    #[test]
    fn a_frame_that_does_not_fit_beside_the_other_tabs_is_refused_with_the_reason() {
        let probe = shared();
        let big = RenderSettings {
            width: 200,
            height: 200,
            ..RenderSettings::default()
        };
        let (frame, message) = probe.costs.frame(&probe.volume, &big);
        // Two renderers and one frame fit, but not a second frame beside
        // the first one's message, not yet sent.
        let limit = 2 * probe.costs.tab + frame + message - 1;
        let shared = shared_with(Arc::new(Plain::default()), limit, 2);
        let (a, b) = (Arc::new(Mailbox::default()), Arc::new(Mailbox::default()));
        let (a_tx, mut a_rx) = mpsc::channel(1);
        let (b_tx, mut b_rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&a), a_tx).unwrap();
        spawn(&shared, Arc::clone(&b), b_tx).unwrap();
        a.put(Slot::Latest, request(1, Quality::Full, 200, 0.0));
        let Some(in_flight @ Outgoing::Frame(..)) = a_rx.blocking_recv() else {
            panic!("no frame")
        };
        assert_eq!(shared.ledger.held(), 2 * probe.costs.tab + message);
        b.put(Slot::Latest, request(7, Quality::Full, 200, 0.0));
        let Some(Outgoing::Text(text)) = b_rx.blocking_recv() else {
            panic!("not refused")
        };
        let error: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(error["seq"], 7);
        let reason = error["message"].as_str().unwrap();
        assert!(
            reason.starts_with("a 200x200 frame needs up to ")
                && reason.contains("but the open tabs hold"),
            "{reason}"
        );
        assert_eq!(shared.stats.snapshot(&shared.ledger).refused, 1);
        // Once the first frame is sent, the second fits.
        drop(in_flight);
        b.put(Slot::Latest, request(8, Quality::Full, 200, 0.0));
        assert!(matches!(b_rx.blocking_recv(), Some(Outgoing::Frame(..))));
        // A third tab's renderer does not fit beside two.
        let third = spawn(&shared, Arc::new(Mailbox::default()), mpsc::channel(1).0);
        assert!(matches!(third, Err(SpawnError::TooMany(2))));
        a.close();
        b.close();
        assert!(a_rx.blocking_recv().is_none() && b_rx.blocking_recv().is_none());
        assert_eq!(shared.ledger.held(), 0);
    }

    /// Every box read from a pyramid's levels: (level, lo, hi).
    pub(super) type Reads = Arc<std::sync::Mutex<Vec<(usize, [usize; 3], [usize; 3])>>>;

    /// A level that records every box read from it.
    struct Counted {
        level: usize,
        source: Arc<dyn volray_core::VolumeSource>,
        reads: Reads,
    }

    impl volray_core::VolumeSource for Counted {
        fn grid(&self) -> volray_core::sampling::grid::GridFrame {
            self.source.grid()
        }
        fn sample_type(&self) -> volray_core::SampleType {
            self.source.sample_type()
        }
        fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
            self.reads.lock().unwrap().push((self.level, lo, hi));
            self.source.read_box(lo, hi)
        }
    }

    /// A 64³ OME-Zarr pyramid of 16³ chunks (levels 64³, 32³, 16³): its
    /// directory and path.
    fn pyramid_file() -> (tempfile::TempDir, std::path::PathBuf) {
        use volray_io::{OmeZarrOptions, write_ome_zarr};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("blob.ome.zarr");
        let volume = Volume::from_fn([64; 3], DVec3::ONE, DVec3::ZERO, |p| {
            let d = (p - DVec3::new(30.0, 34.0, 28.0)).length();
            ((1.0 - d / 26.0).max(0.0) * (1.0 + 0.3 * (p.x * 0.4).sin())) as f32
        })
        .unwrap();
        let options = OmeZarrOptions {
            chunk: 16,
            shard: 32,
            ..OmeZarrOptions::default()
        };
        write_ome_zarr(&path, &volume, &options).unwrap();
        (dir, path)
    }

    /// Level `level` of `path` read whole, as `volray render --level N`
    /// reads it.
    fn read_level(path: &std::path::Path, level: usize) -> Volume {
        let opts = volray_io::ReadOptions {
            level: Some(level),
            ..volray_io::ReadOptions::default()
        };
        volray_io::read(path, &opts).unwrap().volume
    }

    /// A server of the pyramid at `path` under `limit` bytes, its stills
    /// at `still` (`None`: auto), and the log of what its levels read.
    fn pyramid_shared(
        path: &std::path::Path,
        limit: u128,
        still: Option<usize>,
    ) -> (Shared, Reads) {
        let reads = Reads::default();
        let sources = (0..3)
            .map(|level| {
                let opts = volray_io::ReadOptions {
                    level: Some(level),
                    ..volray_io::ReadOptions::default()
                };
                let lazy = volray_io::open_lazy(path, &opts).unwrap().unwrap();
                Arc::new(Counted {
                    level,
                    source: lazy.source,
                    reads: Arc::clone(&reads),
                }) as Arc<dyn volray_core::VolumeSource>
            })
            .collect();
        let pyramid = crate::pyramid::Pyramid::new(sources, still).unwrap();
        let mut shared = shared_with(Arc::new(Plain::default()), limit, 1);
        // No brick caches: what a level's renderer holds is its frame's.
        shared.cache_budget = 0;
        let start = RenderSettings::default();
        shared.costs = Costs::new(&shared.volume, &start, NonFinite::Refuse, 0);
        shared.levels = Some(Arc::new(Levels::new(pyramid)));
        (shared, reads)
    }

    /// The frame of `request` from a tab of `shared`: its header and image.
    fn one_frame(
        mailbox: &Mailbox<Request>,
        rx: &mut mpsc::Receiver<Outgoing>,
        request: Request,
    ) -> (serde_json::Value, Vec<u8>) {
        mailbox.put(Slot::Latest, request);
        match rx.blocking_recv() {
            Some(Outgoing::Frame(message, _)) => {
                let n = u32::from_le_bytes(message[..4].try_into().unwrap()) as usize;
                (header(&message), message[4 + n..].to_vec())
            }
            Some(Outgoing::Text(text)) => panic!("{text}"),
            None => panic!("no frame"),
        }
    }

    /// 8-bit RGB pixels of a PNG.
    fn pixels(png: &[u8]) -> Vec<u8> {
        let mut reader = png::Decoder::new(std::io::Cursor::new(png))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        buf
    }

    #[test]
    fn a_large_volumes_drafts_come_from_its_coarse_copy_and_its_still_from_the_volume() {
        for large in [false, true] {
            let mut shared = shared();
            // The 17³ volume counts as large, or not.
            shared.copy_above = if large { 0 } else { usize::MAX };
            let mailbox = Arc::new(Mailbox::default());
            let (tx, mut rx) = mpsc::channel(1);
            spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
            let tab = shared.ledger.held();
            let (h, _) = one_frame(&mailbox, &mut rx, request(1, Quality::Draft, 64, 30.0));
            assert_eq!(
                (h["quality"].as_str(), h["width"].as_u64()),
                (Some("draft"), Some(32))
            );
            // The copy (9³ voxels and its renderer) is held with the tab.
            let copy = shared.ledger.held() - tab;
            assert_eq!(
                copy > 9 * 9 * 9 * 4,
                large,
                "{copy} bytes held beside the tab"
            );
            // The still after it is the volume's own frame, pixel for
            // pixel, as the Command box reproduces it.
            let still = request(2, Quality::Full, 64, 30.0);
            let settings = Plain::default().reproduce(&still.state).unwrap().settings;
            let want = Renderer::new(&shared.volume)
                .unwrap()
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let (h, png) = one_frame(&mailbox, &mut rx, still);
            assert_eq!(h["quality"], "full");
            let want = encode::png(&want, &mut Vec::new()).unwrap();
            assert!(pixels(&png) == pixels(&want), "large: {large}");
            // A second draft uses the copy made for the first.
            one_frame(&mailbox, &mut rx, request(3, Quality::Draft, 64, 40.0));
            assert_eq!(shared.ledger.held(), tab + copy);
            mailbox.close();
            assert!(rx.blocking_recv().is_none());
            assert_eq!(shared.ledger.held(), 0, "given back with the tab");

            // A tab whose first frame is a still makes the copy after
            // sending it, before any draft: once a probe that follows is
            // answered, it is held.
            let mailbox = Arc::new(Mailbox::default());
            let (tx, mut rx) = mpsc::channel(1);
            spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
            one_frame(&mailbox, &mut rx, request(4, Quality::Full, 64, 30.0));
            let mut probe = request(5, Quality::Full, 64, 30.0);
            probe.probe = Some([32, 32]);
            mailbox.put(Slot::Probe, probe);
            assert!(matches!(rx.blocking_recv(), Some(Outgoing::Text(_))));
            // (Its renderer's bound is the still's here, the draft's above.)
            let held = shared.ledger.held() - tab;
            assert_eq!(
                held > 9 * 9 * 9 * 4,
                large,
                "{held} bytes held beside the tab"
            );
            mailbox.close();
            assert!(rx.blocking_recv().is_none());
            assert_eq!(shared.ledger.held(), 0);
        }
    }

    #[test]
    fn a_pyramids_drafts_show_a_coarser_level_held_whole_and_its_still_the_level_auto_chooses() {
        let (_dir, path) = pyramid_file();
        let (shared, reads) = pyramid_shared(&path, 1 << 30, None);
        let pyramid = &shared.levels.as_ref().unwrap().pyramid;
        let full = RenderSettings {
            width: 64,
            height: 64,
            ..RenderSettings::default()
        };
        let draft = RenderSettings {
            width: 32,
            height: 32,
            ..full.clone()
        };
        let still = pyramid.auto_level(&full).unwrap();
        let coarse = pyramid.auto_level(&draft).unwrap();
        assert!(coarse > still, "draft {coarse}, still {still}");
        let mailbox = Arc::new(Mailbox::default());
        let (tx, mut rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();

        // A drag: the coarse level, read whole once, then held.
        let (h, _) = one_frame(&mailbox, &mut rx, request(1, Quality::Draft, 64, 30.0));
        assert_eq!(h["level"]["index"], coarse);
        assert_eq!(h["level"]["count"], 3);
        assert_eq!(
            (h["level"]["pieces"].as_u64(), h["level"]["read"].as_u64()),
            (Some(1), Some(1))
        );
        let dims = pyramid.grid(coarse).dims;
        assert_eq!(*reads.lock().unwrap(), [(coarse, [0; 3], dims)]);
        let (h, _) = one_frame(&mailbox, &mut rx, request(2, Quality::Draft, 64, 40.0));
        assert_eq!(
            (h["level"]["index"].as_u64(), h["level"]["read"].as_u64()),
            (Some(coarse as u64), Some(0))
        );
        assert_eq!(reads.lock().unwrap().len(), 1, "a drag reads nothing more");

        // Still: the level auto chooses, whole: the frame `volray render
        // --level N` renders of it, byte for byte.
        let (h, png) = one_frame(&mailbox, &mut rx, request(3, Quality::Full, 64, 40.0));
        assert_eq!(h["level"]["index"], still);
        assert_eq!(h["level"]["pieces"], 1);
        let dims = pyramid.grid(still).dims;
        assert_eq!(reads.lock().unwrap()[1..], [(still, [0; 3], dims)]);
        let volume = read_level(&path, still);
        let mut settings = full.clone();
        settings.camera.azimuth = 40.0;
        let reference = Renderer::new(&volume)
            .unwrap()
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        assert_eq!(png, encode::png(&reference, &mut Vec::new()).unwrap());
        mailbox.close();
        assert!(rx.blocking_recv().is_none());
        drop(shared.levels);
        assert_eq!(shared.ledger.held(), 0, "every level's bytes given back");
    }

    #[test]
    fn a_still_beyond_the_memory_left_is_rendered_in_pieces_never_read_whole_within_a_level() {
        let (_dir, path) = pyramid_file();
        let full = RenderSettings {
            width: 64,
            height: 64,
            ..RenderSettings::default()
        };
        // Level 0's still does not fit: what reading it whole takes, less
        // a byte; the drafts' level fits a quarter of that.
        let (probe, _) = pyramid_shared(&path, u128::MAX, Some(0));
        let pyramid = &probe.levels.as_ref().unwrap().pyramid;
        let nf = NonFinite::Refuse;
        let whole = pyramid.whole_bytes(0, &full, nf) + probe.costs.pieces_frame(&full).0;
        let limit = whole - 1;
        let draft = RenderSettings {
            width: 32,
            height: 32,
            ..full.clone()
        };
        let coarse = pyramid.draft_level(&draft, 0, nf, limit).unwrap().unwrap();
        assert!(coarse > 0);
        let (shared, reads) = pyramid_shared(&path, limit, Some(0));
        let mailbox = Arc::new(Mailbox::default());
        let (tx, mut rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        let (h, _) = one_frame(&mailbox, &mut rx, request(1, Quality::Draft, 64, 20.0));
        assert_eq!(h["level"]["index"], coarse);
        let (h, png) = one_frame(&mailbox, &mut rx, request(2, Quality::Full, 64, 20.0));
        assert_eq!(h["level"]["index"], 0);
        let pieces = h["level"]["pieces"].as_u64().unwrap();
        assert!(pieces > 1, "{h}");
        // Level 0 was never read whole; no level read whole was larger
        // than the limit allows.
        let log = reads.lock().unwrap().clone();
        assert!(log.iter().any(|(l, ..)| *l == 0));
        for (level, lo, hi) in log {
            let dims = pyramid.grid(level).dims;
            assert!(
                level != 0 || (lo, hi) != ([0; 3], dims),
                "level 0 read whole"
            );
            if (lo, hi) == ([0; 3], dims) {
                assert!(pyramid.volume_bytes(level) <= limit / crate::pyramid::DRAFT_SHARE);
            }
        }
        // Within a level (1/255) of level 0 rendered whole.
        let volume = read_level(&path, 0);
        let mut settings = full.clone();
        settings.camera.azimuth = 20.0;
        let reference = Renderer::new(&volume)
            .unwrap()
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        let expected = pixels(&encode::png(&reference, &mut Vec::new()).unwrap());
        let got = pixels(&png);
        assert_eq!(got.len(), expected.len());
        let worst = got
            .iter()
            .zip(&expected)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap();
        assert!(worst <= 1, "{worst}/255");
        mailbox.close();
        assert!(rx.blocking_recv().is_none());
        assert!(shared.ledger.held() <= limit);
    }

    #[test]
    fn a_still_in_pieces_superseded_before_it_starts_reads_nothing_and_the_newer_frame_is_sent() {
        let (_dir, path) = pyramid_file();
        let (probe, _) = pyramid_shared(&path, u128::MAX, Some(0));
        let full = RenderSettings {
            width: 64,
            height: 64,
            ..RenderSettings::default()
        };
        let pyramid = &probe.levels.as_ref().unwrap().pyramid;
        let limit = pyramid.whole_bytes(0, &full, NonFinite::Refuse) - 1;
        let plain = Arc::new(Plain::default());
        let (mut shared, reads) = pyramid_shared(&path, limit, Some(0));
        shared.reproduce = Arc::clone(&plain) as Arc<dyn Reproduce>;
        let mailbox = Arc::new(Mailbox::default());
        let page = Arc::clone(&mailbox);
        *plain.meanwhile.lock().unwrap() = Some((
            1.0,
            Box::new(move || page.put(Slot::Latest, request(2, Quality::Draft, 64, 2.0))),
        ));
        mailbox.put(Slot::Latest, request(1, Quality::Full, 64, 1.0));
        let (tx, mut rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
            panic!("no frame")
        };
        let h = header(&message);
        assert_eq!(h["seq"], 2);
        assert!(h["level"]["index"].as_u64().unwrap() > 0);
        assert_eq!(shared.stats.stopped(), 1);
        // Only the draft's level was read: the still stopped before its
        // first piece.
        let log = reads.lock().unwrap().clone();
        assert!(log.iter().all(|(l, ..)| *l > 0), "{log:?}");
        mailbox.close();
        assert!(rx.blocking_recv().is_none());
    }

    #[test]
    fn the_basis_spans_the_screen() {
        let shared = shared();
        let renderer = Renderer::new(&shared.volume).unwrap();
        let settings = RenderSettings {
            width: 100,
            height: 100,
            ..RenderSettings::default()
        };
        let b = basis(&renderer, &settings).unwrap();
        // The default view looks along −x: right is +y, up +z; the 2-unit
        // face spans 100 pixels.
        assert_eq!(b.right, [0.0, 1.0, 0.0]);
        assert_eq!(b.up, [0.0, 0.0, 1.0]);
        assert!((b.pixels_per_unit - 50.0).abs() < 1e-9);
        assert!(DVec3::from(b.reference).length() < 1e-12);
    }

    #[test]
    fn a_slow_still_is_preceded_by_a_quick_draft_scaled_to_its_time() {
        let full = request(7, Quality::Full, 480, 0.0);
        assert_eq!(quick_request(None, &full), None, "no still yet");
        assert_eq!(quick_request(Some(SLOW_STILL_MS), &full), None, "not slow");
        let draft = request(7, Quality::Draft, 480, 0.0);
        assert_eq!(
            quick_request(Some(2000.0), &draft),
            None,
            "drafts are quick"
        );
        // 4x QUICK_MS: half the side, a quarter of the pixels and time.
        let quick = quick_request(Some(4.0 * QUICK_MS), &full).unwrap();
        assert_eq!((quick.seq, quick.quality), (7, Quality::Draft));
        assert!((quick.draft_scale - 0.5).abs() < 1e-12);
        assert_eq!(quick.state, full.state);
        // Never below 1/16 a side.
        let slowest = quick_request(Some(1e9), &full).unwrap();
        assert_eq!(slowest.draft_scale, DRAFT_SCALE_RANGE.0);
        assert_eq!((scaled(480, 1.0 / 16.0), scaled(1, 1.0 / 16.0)), (30, 1));
    }

    #[test]
    fn a_probe_is_answered_with_what_the_pixel_shows_and_a_frame_is_not_rendered() {
        let shared = shared();
        let mailbox = Arc::new(Mailbox::default());
        let (tx, mut rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        let probe = |seq, col, row| {
            let mut r = request(seq, Quality::Full, 33, 0.0);
            r.probe = Some([col, row]);
            r
        };
        mailbox.put(Slot::Probe, probe(1, 16, 16));
        let Some(Outgoing::Text(text)) = rx.blocking_recv() else {
            panic!("no answer")
        };
        let answer: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(
            (answer["type"].as_str(), answer["seq"].as_u64()),
            (Some("probe"), Some(1))
        );
        // The centre ray from +x meets the cone's values on the x axis.
        let position = answer["position"].as_array().unwrap();
        let x = position[0].as_f64().unwrap();
        assert!(x > 0.0 && x < 1.0, "{answer}");
        assert!(position[1].as_f64().unwrap().abs() < 1e-9, "{answer}");
        let value = answer["value"].as_f64().unwrap();
        assert!(
            (value - (1.0 - x)).abs() < 0.05,
            "the cone's value 1 - |p|: {answer}"
        );
        // The corner's ray meets only zeros: nothing.
        mailbox.put(Slot::Probe, probe(2, 0, 0));
        let Some(Outgoing::Text(text)) = rx.blocking_recv() else {
            panic!("no answer")
        };
        let answer: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(answer["position"], serde_json::Value::Null, "{answer}");
        assert_eq!(shared.stats.snapshot(&shared.ledger).frames, 0, "no frame");
    }
}
