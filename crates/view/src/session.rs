//! One tab's renderer: a thread of its own that owns a
//! [`Renderer`] of the volume (so that the bricks classified for this
//! tab's transfer function are kept from frame to frame, whatever other
//! tabs do), takes the latest request from a single-slot [`Mailbox`],
//! renders it, encodes it, and hands the message to the tab's socket
//! through a channel of one, so that a slow page slows the renderer
//! instead of queueing frames.
//!
//! When the tab goes away the mailbox closes, the thread ends and the
//! renderer with its caches is freed.

use crate::encode::{self, DRAFT_QUALITY};
use crate::mailbox::Mailbox;
use crate::protocol::{Basis, FrameHeader, Quality, Request, ServerMessage, frame_message};
use crate::reproduce::{Refusal, Reproduce};
use crate::stats::Stats;
use std::sync::Arc;
use std::time::Instant;
use tokio::sync::mpsc;
use volray_core::camera::View;
use volray_core::{Image, NonFinite, RenderError, RenderSettings, Renderer, Volume};

/// What the renderer thread sends to the tab's socket.
#[derive(Debug)]
pub enum Outgoing {
    /// A frame: header and image.
    Frame(Vec<u8>),
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
    /// The most tabs rendering at once (each renderer holds its caches).
    pub max_sessions: usize,
}

/// A tab that could not be given a renderer.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("{0} tabs are open, the most this server renders at once: close one and reload")]
    TooMany(usize),
    #[error("cannot start a renderer thread: {0}")]
    Thread(#[from] std::io::Error),
}

/// A frame that could not be made.
#[derive(Debug, thiserror::Error)]
enum FrameError {
    #[error("{0}")]
    Refused(#[from] Refusal),
    #[error("{0}")]
    Render(#[from] RenderError),
    #[error("{0}")]
    Encode(#[from] encode::EncodeError),
}

/// Starts a tab's renderer thread, which serves `mailbox` until it closes
/// or the socket's end of `out` goes away; refused when
/// [`Shared::max_sessions`] are running.
pub fn spawn(
    shared: &Shared,
    mailbox: Arc<Mailbox<Request>>,
    out: mpsc::Sender<Outgoing>,
) -> Result<(), SpawnError> {
    let open =
        (shared.stats.open(shared.max_sessions)).ok_or(SpawnError::TooMany(shared.max_sessions))?;
    let volume = Arc::clone(&shared.volume);
    let reproduce = Arc::clone(&shared.reproduce);
    let pool = Arc::clone(&shared.pool);
    let stats = Arc::clone(&shared.stats);
    let non_finite = shared.non_finite;
    let cache_budget = shared.cache_budget;
    std::thread::Builder::new()
        .name("view-render".into())
        .spawn(move || {
            let _open = open;
            let renderer = match Renderer::with_non_finite(&volume, non_finite) {
                Ok(r) => r.with_cache_budget(cache_budget),
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
                renderer,
                reproduce: &*reproduce,
                pool: &pool,
                image: Image::new(0, 0, [0.0; 4]),
                rgb: Vec::new(),
            };
            while let Some(request) = mailbox.take() {
                let outgoing = match tab.frame(&request) {
                    Ok(message) => {
                        stats.frame_rendered();
                        Outgoing::Frame(message)
                    }
                    Err(e) => Outgoing::Text(
                        ServerMessage::Error {
                            seq: Some(request.seq),
                            message: e.to_string(),
                        }
                        .to_json(),
                    ),
                };
                if out.blocking_send(outgoing).is_err() {
                    break;
                }
            }
            stats.add_dropped(mailbox.dropped());
        })?;
    Ok(())
}

/// A tab's renderer and its buffers, reused from frame to frame.
struct Tab<'a> {
    renderer: Renderer<'a>,
    reproduce: &'a dyn Reproduce,
    pool: &'a rayon::ThreadPool,
    image: Image,
    rgb: Vec<u8>,
}

impl Tab<'_> {
    /// The frame `request` asks for, as a binary message.
    fn frame(&mut self, request: &Request) -> Result<Vec<u8>, FrameError> {
        let reproduction = self.reproduce.reproduce(&request.state)?;
        let basis = basis(&self.renderer, &reproduction.settings)?;
        let settings = match request.quality {
            Quality::Draft => RenderSettings {
                width: draft_side(reproduction.settings.width),
                height: draft_side(reproduction.settings.height),
                ..reproduction.settings
            },
            Quality::Full | Quality::Save => reproduction.settings,
        };
        let start = Instant::now();
        let (renderer, image) = (&self.renderer, &mut self.image);
        self.pool
            .install(|| renderer.render_into(&settings, image))?;
        let rendered = Instant::now();
        let (mime, bytes) = match request.quality {
            Quality::Draft => (
                "image/jpeg",
                encode::jpeg(&self.image, DRAFT_QUALITY, &mut self.rgb)?,
            ),
            Quality::Full | Quality::Save => {
                ("image/png", encode::png(&self.image, &mut self.rgb)?)
            }
        };
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
            basis,
        };
        Ok(frame_message(&header, &bytes))
    }
}

/// A draft frame's side: half the full frame's, at least one pixel.
pub fn draft_side(full: usize) -> usize {
    full.div_ceil(2)
}

/// The screen axes of the full-size view of `settings`, for panning.
fn basis(renderer: &Renderer, settings: &RenderSettings) -> Result<Basis, RenderError> {
    let frame = renderer.prepare(settings)?;
    let (reference, right, up, units_per_pixel) = match frame.view {
        View::Orthographic(v) => (v.centre, v.right, v.up, v.pixel_size),
        View::Perspective(v) => (
            v.reference,
            v.right,
            v.up,
            v.pixel_size * (v.reference - v.eye).length(),
        ),
    };
    Ok(Basis {
        reference: reference.to_array(),
        right: right.to_array(),
        up: up.to_array(),
        pixels_per_unit: 1.0 / units_per_pixel,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mailbox::Slot;
    use crate::protocol::Quality;
    use crate::reproduce::Reproduction;
    use crate::state::ViewState;
    use crate::state::tests::sample;
    use volray_core::glam::DVec3;

    /// Renders states with the library's defaults and their camera.
    struct Plain;

    impl Reproduce for Plain {
        fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal> {
            if state.zoom > 100.0 {
                return Err(Refusal("too close".into()));
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
            })
        }
    }

    fn shared() -> Shared {
        let n = 17;
        let h = 2.0 / (n - 1) as f64;
        let volume = Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
            (1.0 - p.length()).max(0.0) as f32
        })
        .unwrap();
        Shared {
            volume: Arc::new(volume),
            non_finite: NonFinite::Refuse,
            cache_budget: volray_core::DEFAULT_CACHE_BUDGET,
            reproduce: Arc::new(Plain),
            pool: Arc::new(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(1)
                    .build()
                    .unwrap(),
            ),
            stats: Arc::new(Stats::default()),
            max_sessions: 1,
        }
    }

    fn header(message: &[u8]) -> serde_json::Value {
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
                },
            );
        }
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        // One renderer at most: a second tab is refused.
        let refused = spawn(&shared, Arc::new(Mailbox::default()), mpsc::channel(1).0);
        assert!(matches!(refused, Err(SpawnError::TooMany(1))));
        let Some(Outgoing::Frame(message)) = rx.blocking_recv() else {
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
            },
        );
        let Some(Outgoing::Frame(message)) = rx.blocking_recv() else {
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
}
