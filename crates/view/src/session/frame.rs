//! A request's frame, from the page's state to the message sent: its
//! settings reproduced (at the draft's scale), drawn from what the tab
//! renders, annotated, encoded (a JPEG draft, a PNG still) and headed
//! with the command that reproduces it.

use super::drafts::scaled;
use super::render::{Context, Drawn};
use super::time::at_time;
use super::{FrameError, Source, Tab};
use crate::coarse;
use crate::encode::{self, DRAFT_QUALITY};
use crate::ledger::Reservation;
use crate::protocol::{FrameHeader, Quality, Request, frame_message};
use crate::reproduce::Refusal;
use std::sync::atomic::AtomicBool;
use std::time::Instant;
use volray_core::RenderSettings;
use volray_core::scene::{Look, SceneSettings};

impl Tab<'_> {
    /// The frame `request` asks for, as a binary message, and the bytes
    /// reserved for the message until it is sent; stopped when `stop` is
    /// set.
    pub(super) fn frame(
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
