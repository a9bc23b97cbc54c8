//! Rendering a tab's frame: its bytes reserved from the ledger, then
//! rendered on the pool, counted as rendering and stopped by the
//! mailbox's stop flag ([`Context`]); and the screen axes of a view
//! ([`Basis`]), for panning.

use super::FrameError;
use crate::ledger::{Costs, Ledger, Reservation};
use crate::protocol::{Basis, LevelShown};
use crate::stats::Stats;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use volray_core::camera::View;
use volray_core::scene::{Scene, SceneSettings};
use volray_core::{FrameRequest, Image, Render, RenderError, RenderSettings, Renderer};

/// A frame rendered, before it is encoded.
pub(super) struct Drawn {
    pub(super) image: Image,
    pub(super) basis: Basis,
    pub(super) level: Option<LevelShown>,
    /// The frame's bytes, and the part the message keeps until sent.
    pub(super) reserved: Reservation,
    pub(super) message_bytes: u128,
}

/// What rendering a frame reports to and is stopped by.
pub(super) struct Context<'a> {
    pub(super) pool: &'a rayon::ThreadPool,
    pub(super) stats: &'a Stats,
    pub(super) ledger: &'a Arc<Ledger>,
    pub(super) costs: Costs,
    pub(super) stop: &'a AtomicBool,
    /// "a WxH frame", for a refusal.
    pub(super) what: &'a str,
}

impl Context<'_> {
    /// A frame of `settings` drawn by `drawing` (`renderer`, or its
    /// volume's coarse copy for a draft); its basis is that of `full`
    /// from `renderer`.
    pub(super) fn whole(
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
    pub(super) fn scene(
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

    pub(super) fn render(
        &self,
        renderer: &Renderer,
        settings: &RenderSettings,
    ) -> Result<Image, FrameError> {
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

/// `settings` for the scene's first volume alone, its camera framing
/// every volume's box as the scene's frames do (for its basis, probe and
/// annotations).
pub(super) fn framed(scene: &Scene, settings: &RenderSettings) -> RenderSettings {
    let mut framed = settings.clone();
    framed.camera.bounds = Some(framed.camera.framed_bounds(scene.bounds()));
    framed
}

/// The screen axes of the full-size view of `settings`, for panning.
pub(super) fn basis(renderer: &Renderer, settings: &RenderSettings) -> Result<Basis, RenderError> {
    let frame = renderer.prepare(settings)?;
    Ok(basis_of(&frame.view))
}

/// The screen axes of `view`.
pub(super) fn basis_of(view: &View) -> Basis {
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
mod tests {
    use super::*;
    use crate::session::tests::shared;
    use volray_core::glam::DVec3;

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
