//! The messages between the page and the server, over one WebSocket per
//! tab.
//!
//! The page sends text messages, each a JSON object:
//!
//! - `{"type": "view", "seq": N, "quality": "draft"|"full", "state": {...}}`:
//!   render this [`ViewState`]; `draft` while the user drags (JPEG, at
//!   `"draft_scale"` of the full size, half by default: the page picks it
//!   from the last drafts' times to hold its frame rate), `full` once the
//!   interaction stops (full size, PNG). Only the latest waiting request
//!   is rendered.
//! - `{"type": "save", "seq": N, "state": {...}}`: render the state at
//!   its size, as a PNG to download.
//! - `{"type": "probe", "seq": N, "x": X, "y": Y, "state": {...}}`: what
//!   the full-size frame's pixel at (X, Y) shows (`volray_core::probe`),
//!   answered with a [`ServerMessage::Probe`]. Only the latest waits.
//!
//! The server answers with text messages (the [`Hello`] first, then
//! [`ServerMessage::Error`] for a message it refused or a frame it could
//! not render, naming the message's `seq`) and binary messages, one per
//! frame: a 4-byte little-endian length, a JSON [`FrameHeader`] of that
//! length, then the image file.

use crate::mailbox::{Mailbox, Slot};
use crate::state::{Lighting, StateError, ViewState};
use serde::{Deserialize, Serialize};

/// The largest message a page may send: a state with the most opacity
/// points is a few kilobytes.
pub const MAX_MESSAGE_BYTES: usize = 64 << 10;

/// How good a frame must be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    /// Half size, JPEG: while the view moves.
    Draft,
    /// Full size, PNG: the still view.
    Full,
    /// The size asked for, PNG, to download.
    Save,
}

/// A request from the page.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum ClientMessage {
    View {
        seq: u64,
        quality: Quality,
        state: ViewState,
        #[serde(default)]
        draft_scale: Option<f64>,
    },
    Save {
        seq: u64,
        state: ViewState,
    },
    Probe {
        seq: u64,
        x: f64,
        y: f64,
        state: ViewState,
    },
}

/// A request the server can render: its sequence number, quality and
/// checked state.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    pub seq: u64,
    pub quality: Quality,
    pub state: ViewState,
    /// A draft's size over the full size's, per side, in
    /// [`DRAFT_SCALE_RANGE`].
    pub draft_scale: f64,
    /// A probe of the full-size frame's pixel (column, row), instead of
    /// a frame.
    pub probe: Option<[usize; 2]>,
}

impl crate::mailbox::Kind for Request {
    fn is_draft(&self) -> bool {
        self.quality == Quality::Draft && self.probe.is_none()
    }
}

/// The smallest and largest scale of a draft, per side.
pub const DRAFT_SCALE_RANGE: (f64, f64) = (1.0 / 16.0, 1.0);

/// A draft's scale when the page names none: half size.
pub const DRAFT_SCALE: f64 = 0.5;

/// A draft frame's side: half the full frame's, at least one pixel.
pub fn draft_side(full: usize) -> usize {
    full.div_ceil(2)
}

/// A message refused: not JSON of a known shape, or out of bounds.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MessageError {
    #[error("message of {0} bytes is too long (at most {MAX_MESSAGE_BYTES})")]
    TooLong(usize),
    #[error("malformed message: {0}")]
    Malformed(String),
    #[error("\"quality\": \"save\" is asked for with a save message")]
    SaveQuality,
    #[error("draft_scale {0} is outside 1/16 to 1")]
    DraftScale(f64),
    #[error("the probe's pixel ({x}, {y}) is outside the frame")]
    ProbeOutside { x: f64, y: f64 },
    #[error("{0}")]
    State(#[from] StateError),
}

impl MessageError {
    /// The `seq` of the refused message, when it could be read.
    pub fn seq_of(text: &str) -> Option<u64> {
        serde_json::from_str::<serde_json::Value>(text)
            .ok()?
            .get("seq")?
            .as_u64()
    }
}

/// Parses and checks a message from the page.
pub fn parse(text: &str) -> Result<Request, MessageError> {
    if text.len() > MAX_MESSAGE_BYTES {
        return Err(MessageError::TooLong(text.len()));
    }
    let message: ClientMessage =
        serde_json::from_str(text).map_err(|e| MessageError::Malformed(e.to_string()))?;
    let request = match message {
        ClientMessage::View {
            quality: Quality::Save,
            ..
        } => return Err(MessageError::SaveQuality),
        ClientMessage::View {
            seq,
            quality,
            state,
            draft_scale,
        } => {
            let draft_scale = draft_scale.unwrap_or(DRAFT_SCALE);
            let (lo, hi) = DRAFT_SCALE_RANGE;
            if !(lo..=hi).contains(&draft_scale) {
                return Err(MessageError::DraftScale(draft_scale));
            }
            Request {
                seq,
                quality,
                state,
                draft_scale,
                probe: None,
            }
        }
        ClientMessage::Save { seq, state } => Request {
            seq,
            quality: Quality::Save,
            state,
            draft_scale: DRAFT_SCALE,
            probe: None,
        },
        ClientMessage::Probe { seq, x, y, state } => {
            let inside = |v: f64, n: usize| v.is_finite() && v >= 0.0 && v < n as f64;
            if !inside(x, state.width) || !inside(y, state.height) {
                return Err(MessageError::ProbeOutside { x, y });
            }
            Request {
                seq,
                quality: Quality::Full,
                state,
                draft_scale: DRAFT_SCALE,
                probe: Some([x as usize, y as usize]),
            }
        }
    };
    request.state.check()?;
    Ok(request)
}

/// The screen axes of a rendered view, for panning: the page moves the
/// reference by `−dx·right + dy·up` world units per `pixels_per_unit`
/// pixels dragged (at full size).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Basis {
    /// The view reference, the image centre.
    pub reference: [f64; 3],
    pub right: [f64; 3],
    pub up: [f64; 3],
    /// Full-size pixels per world unit at the reference.
    pub pixels_per_unit: f64,
}

/// What comes before a frame's image in its binary message.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameHeader {
    /// The request's sequence number.
    pub seq: u64,
    pub quality: Quality,
    /// `image/jpeg` or `image/png`.
    pub mime: &'static str,
    pub width: usize,
    pub height: usize,
    /// Milliseconds spent rendering and encoding.
    pub render_ms: f64,
    pub encode_ms: f64,
    /// The command that renders the full-quality frame of this state.
    pub command: String,
    /// The transfer-function file it names: name and JSON.
    pub tf_file: Option<(String, String)>,
    /// The files a scene's other volumes' `tf=` options name.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub layer_tf_files: Vec<(String, String)>,
    pub basis: Basis,
    /// The level of a multiscale volume the frame shows (absent for a
    /// volume of one level read whole).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub level: Option<LevelShown>,
}

/// Which level of a multiscale volume a frame shows, and how it was read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct LevelShown {
    /// The level, 0 the finest.
    pub index: usize,
    /// The levels the volume has.
    pub count: usize,
    pub dims: [usize; 3],
    /// The pieces it was rendered in: 1 when held whole.
    pub pieces: usize,
    /// The pieces (or whole levels) read for this frame; the others were
    /// held already, transparent or hidden.
    pub read: usize,
}

/// `header` and `image` as one binary message.
pub fn frame_message(header: &FrameHeader, image: &[u8]) -> Vec<u8> {
    let json = serde_json::to_vec(header).expect("a frame header serialises");
    let mut out = Vec::with_capacity(4 + json.len() + image.len());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    out.extend_from_slice(image);
    out
}

/// The volume as the page is told it first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Hello {
    /// The input's name (its spec or path, as given).
    pub name: String,
    pub dims: [usize; 3],
    pub spacing: [f64; 3],
    /// `[min, max]` of the values rendered.
    pub range: [f32; 2],
    /// Whether the values rendered are log10 of the data's.
    pub log: bool,
    /// Counts of the values in equal bins over `range`.
    pub histogram: Vec<u64>,
    /// The starting view, and where a double click returns.
    pub start: ViewState,
    /// The starting opacity ramp `[p, q]` (used while the state's
    /// opacity is `None`).
    pub opacity_ramp: [f32; 2],
    /// The starting transfer function's opacity points, if it has some.
    pub start_opacity: Option<Vec<[f32; 2]>>,
    /// The starting window (the transfer function's domain, else the
    /// value range).
    pub start_window: [f64; 2],
    /// Each colour choice and its colours at evenly spaced `t`, to draw.
    pub colormaps: Vec<(String, Vec<[f32; 3]>)>,
    /// A multiscale volume's levels' dims, finest first (absent for a
    /// volume of one level read whole: then `dims` are its, else the
    /// finest level's, while `range` and `histogram` are those of the
    /// level the first drafts show).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub levels: Option<Vec<[usize; 3]>>,
    /// The box the view frames, world corners `[lo, hi]` (every volume's,
    /// for a scene): the crop and clip controls' ranges.
    pub bounds: [[f64; 3]; 2],
    /// The lighting the view starts with (each term the mean of its
    /// r, g, b), for the lighting controls.
    pub lighting: Lighting,
    /// Whether the page sizes the frame to its window (no size was given
    /// at the start): the state's width and height follow the viewport
    /// and its device pixel ratio.
    pub fit: bool,
    /// A scene's volumes after the first (whose are the fields above),
    /// in their order: each one's panel.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub volumes: Vec<VolumeHello>,
    /// The time points served, `[first, end)` as the file counts its
    /// frames (`volray view --frames`): the time slider's range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<[usize; 2]>,
}

/// A scene's volume after the first, as its panel is drawn: the fields
/// of [`Hello`] for the first volume.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VolumeHello {
    pub name: String,
    pub dims: [usize; 3],
    pub range: [f32; 2],
    pub histogram: Vec<u64>,
    pub opacity_ramp: [f32; 2],
    pub start_opacity: Option<Vec<[f32; 2]>>,
    pub start_window: [f64; 2],
    /// Its starting transfer function's colours at evenly spaced `t`
    /// (the page's "start" choice for this volume), if it has some.
    pub start_colours: Option<Vec<[f32; 3]>>,
    /// A label volume: its colours and opacities are its label table's,
    /// shown or hidden only.
    pub labels: bool,
}

/// A message from the server as text.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum ServerMessage {
    Hello(Box<Hello>),
    /// A refused message or a frame that could not be rendered.
    Error {
        seq: Option<u64>,
        message: String,
    },
    /// What a probed pixel shows: its world point and the first volume's
    /// value there, or nothing (`null`s).
    Probe {
        seq: u64,
        position: Option<[f64; 3]>,
        index: Option<[f64; 3]>,
        value: Option<f32>,
    },
}

impl ServerMessage {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("server messages serialise")
    }
}

/// Files a request from a page in its slot, giving back its state where
/// it asks for a view ("draft" or "full"); or says why it was refused.
pub(crate) fn file(
    mailbox: &Mailbox<Request>,
    text: &str,
) -> Result<Option<ViewState>, ServerMessage> {
    match parse(text) {
        Ok(request) => {
            let (slot, view) = match request.quality {
                _ if request.probe.is_some() => (Slot::Probe, None),
                Quality::Save => (Slot::Save, None),
                Quality::Draft | Quality::Full => (Slot::Latest, Some(request.state.clone())),
            };
            mailbox.put(slot, request);
            Ok(view)
        }
        Err(e) => Err(ServerMessage::Error {
            seq: MessageError::seq_of(text),
            message: e.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::ViewState;

    #[test]
    fn a_probe_is_filed_in_its_own_slot_and_the_waiting_view_is_kept() {
        let mailbox = Mailbox::default();
        let view = serde_json::json!({"type": "view", "seq": 1, "quality": "full", "state": ViewState::default()});
        let filed = file(&mailbox, &view.to_string()).unwrap();
        assert_eq!(
            filed,
            Some(ViewState::default()),
            "a view gives back its state"
        );
        let probe = serde_json::json!({"type": "probe", "seq": 2, "x": 3, "y": 4, "state": ViewState::default()});
        assert_eq!(file(&mailbox, &probe.to_string()).unwrap(), None);
        // The probe is answered first, then the view it did not replace.
        assert_eq!(mailbox.waiting(), 2);
        assert_eq!(mailbox.take().map(|r| r.seq), Some(2));
        assert_eq!(mailbox.take().map(|r| r.seq), Some(1));
    }

    fn view(quality: &str) -> String {
        serde_json::json!({
            "type": "view", "seq": 5, "quality": quality, "state": ViewState::default()
        })
        .to_string()
    }

    #[test]
    fn views_and_saves_parse() {
        let r = parse(&view("draft")).unwrap();
        assert_eq!(
            (r.seq, r.quality, r.state),
            (5, Quality::Draft, ViewState::default())
        );
        assert_eq!(parse(&view("full")).unwrap().quality, Quality::Full);
        let save = serde_json::json!({"type": "save", "seq": 9, "state": ViewState::default()});
        let r = parse(&save.to_string()).unwrap();
        assert_eq!((r.seq, r.quality), (9, Quality::Save));
        // A draft's scale: half by default, or as the page picks it.
        assert_eq!(parse(&view("draft")).unwrap().draft_scale, DRAFT_SCALE);
        let scaled = serde_json::json!({
            "type": "view", "seq": 5, "quality": "draft", "state": ViewState::default(), "draft_scale": 0.25
        });
        assert_eq!(parse(&scaled.to_string()).unwrap().draft_scale, 0.25);
        // A probe of a pixel of the full-size frame.
        let probe = serde_json::json!({"type": "probe", "seq": 6, "x": 12.5, "y": 479.9, "state": ViewState::default()});
        let r = parse(&probe.to_string()).unwrap();
        assert_eq!((r.seq, r.probe), (6, Some([12, 479])));
    }

    #[test]
    fn bad_messages_are_errors_not_panics() {
        let mut nan = serde_json::to_value(ViewState::default()).unwrap();
        nan["zoom"] = serde_json::Value::Null;
        let far = ViewState {
            zoom: 1e9,
            ..ViewState::default()
        };
        let cases = [
            ("{", "malformed"),
            ("", "malformed"),
            ("[1,2]", "malformed"),
            ("null", "malformed"),
            (r#"{"type": "view"}"#, "malformed"),
            (r#"{"type": "explode", "seq": 1}"#, "malformed"),
            (
                &serde_json::json!({"type": "view", "seq": 1, "quality": "full", "state": nan})
                    .to_string(),
                "malformed",
            ),
            (
                r#"{"type": "view", "seq": 1, "quality": "full", "state": {"zoom": NaN}}"#,
                "malformed",
            ),
            (&view("save"), "save message"),
            (&view("best"), "malformed"),
            (
                &serde_json::json!({"type": "view", "seq": -1, "quality": "full", "state": ViewState::default()})
                    .to_string(),
                "malformed",
            ),
            (
                &serde_json::json!({"type": "view", "seq": 1, "quality": "full", "state": far})
                    .to_string(),
                "zoom 1000000000 is outside",
            ),
            (
                &serde_json::json!({"type": "view", "seq": 1, "quality": "full", "state": ViewState::default(), "x": 1})
                    .to_string(),
                "malformed",
            ),
            (&"x".repeat(MAX_MESSAGE_BYTES + 1), "too long"),
            (
                &serde_json::json!({"type": "view", "seq": 1, "quality": "draft", "state": ViewState::default(), "draft_scale": 0.01})
                    .to_string(),
                "draft_scale 0.01 is outside 1/16 to 1",
            ),
            (
                &serde_json::json!({"type": "view", "seq": 1, "quality": "draft", "state": ViewState::default(), "draft_scale": 2})
                    .to_string(),
                "draft_scale 2 is outside",
            ),
            (
                &serde_json::json!({"type": "probe", "seq": 1, "x": 480, "y": 0, "state": ViewState::default()})
                    .to_string(),
                "the probe's pixel (480, 0) is outside the frame",
            ),
        ];
        for (text, expect) in cases {
            let err = parse(text).unwrap_err().to_string();
            assert!(err.contains(expect), "{text:.80}: {err}");
        }
        assert_eq!(MessageError::seq_of(&view("best")), Some(5));
        assert_eq!(MessageError::seq_of("{"), None);
    }

    #[test]
    fn a_frame_message_is_length_header_image() {
        let header = FrameHeader {
            seq: 3,
            quality: Quality::Full,
            mime: "image/png",
            width: 2,
            height: 1,
            render_ms: 1.5,
            encode_ms: 0.5,
            command: "volray render".into(),
            tf_file: None,
            layer_tf_files: Vec::new(),
            basis: Basis {
                reference: [0.0; 3],
                right: [0.0, 1.0, 0.0],
                up: [0.0, 0.0, 1.0],
                pixels_per_unit: 2.0,
            },
            level: None,
        };
        let message = frame_message(&header, b"IMAGE");
        let n = u32::from_le_bytes(message[..4].try_into().unwrap()) as usize;
        let json: serde_json::Value = serde_json::from_slice(&message[4..4 + n]).unwrap();
        assert_eq!(json["seq"], 3);
        assert_eq!(json["quality"], "full");
        assert_eq!(json["basis"]["pixels_per_unit"], 2.0);
        assert_eq!(&message[4 + n..], b"IMAGE");
        // A volume of one level says nothing of levels; a pyramid's does.
        assert!(json.get("level").is_none());
        let leveled = FrameHeader {
            level: Some(LevelShown {
                index: 2,
                count: 5,
                dims: [256; 3],
                pieces: 1,
                read: 0,
            }),
            ..header
        };
        let message = frame_message(&leveled, b"");
        let json: serde_json::Value = serde_json::from_slice(&message[4..]).unwrap();
        assert_eq!(json["level"]["index"], 2);
        assert_eq!(json["level"]["count"], 5);
        assert_eq!(json["level"]["dims"], serde_json::json!([256, 256, 256]));
        let error = ServerMessage::Error {
            seq: Some(4),
            message: "no".into(),
        };
        assert_eq!(
            error.to_json(),
            r#"{"type":"error","seq":4,"message":"no"}"#
        );
    }
}
