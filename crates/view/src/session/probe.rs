//! A probe: what the pixel the page points at shows, in the frame of its
//! state (volray-core's `probe`), answered without rendering a frame.

use super::render::framed;
use super::{FrameError, Source, Tab};
use crate::protocol::{Request, ServerMessage};

impl Tab<'_> {
    /// What the pixel `request` probes shows, in the frame of its state
    /// (at the time point this tab shows; the first volume of a scene;
    /// nothing yet for a pyramid's levels).
    pub(super) fn probe(&mut self, request: &Request) -> ServerMessage {
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
}

#[cfg(test)]
mod tests {
    use crate::mailbox::{Mailbox, Slot};
    use crate::protocol::Quality;
    use crate::session::tests::{request, shared};
    use crate::session::{Outgoing, spawn};
    use std::sync::Arc;
    use tokio::sync::mpsc;

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
