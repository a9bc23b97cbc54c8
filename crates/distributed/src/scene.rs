//! Several volumes of one grid (the channels of a stack, a segmentation
//! on its scan's grid) rendered together across the ranks: the same k-d
//! split for every volume, each rank holding its box of each, rendering
//! them as one scene of pieces (`volray_core::scene`: one ray march,
//! the composite mix) into a partial image, composited as one volume's
//! are ([`crate::compose`]).
//!
//! Each volume keeps its own statistics (value range, largest gradient),
//! agreed across the ranks as for one volume ([`Distributed`]). Volumes on
//! different grids would need one split for several grids, and the
//! additive mix and the projections do not combine front to back: those
//! are refused ([`SceneFrameError`]).

use crate::compose::composite;
use crate::frame::{Distributed, FrameError, RankTimes, Source, agree};
use crate::kd::Viewpoint;
use crate::transport::Transport;
use std::time::Instant;
use thiserror::Error;
use volray_core::camera::View;
use volray_core::scene::{Mix, Scene, SceneSettings};
use volray_core::{
    FrameRequest, Image, NonFinite, PartialImage, Render, RenderError, Rendered, Renderer,
};

/// Why several volumes cannot be rendered together across the ranks.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SceneFrameError {
    #[error(
        "volume {layer} is on another grid ({dims:?} points) than the first ({first:?}): across ranks, the volumes of a scene must share one grid"
    )]
    Grids {
        layer: usize,
        dims: [usize; 3],
        first: [usize; 3],
    },
    #[error(
        "across ranks, several volumes render in the composite mix only (the additive mix and the projections do not combine front to back)"
    )]
    Mix,
}

/// Refuses volumes on different grids, before anything is read.
fn check_grids<T: Transport + ?Sized>(
    transport: &T,
    grids: &[volray_core::sampling::grid::GridFrame],
) -> Result<(), FrameError> {
    for (layer, grid) in grids.iter().enumerate() {
        if *grid != grids[0] {
            return Err(FrameError::Rank {
                rank: transport.rank(),
                message: SceneFrameError::Grids {
                    layer,
                    dims: grid.dims,
                    first: grids[0].dims,
                }
                .to_string(),
                bad_input: true,
            });
        }
    }
    Ok(())
}

/// One rank's part of a distributed scene: its piece of each volume.
pub struct DistributedScene<'t, T: Transport + ?Sized> {
    volumes: Vec<Distributed<'t, T>>,
    /// This rank's pieces as one scene (none where its box is empty).
    scene: Option<Scene<'static>>,
}

impl<'t, T: Transport + ?Sized> DistributedScene<'t, T> {
    /// Splits the grid of `sources` (one grid for all, else an error
    /// before anything is read) among the ranks and reads this rank's
    /// piece of each, agreeing on each volume's value range.
    pub fn read(
        transport: &'t T,
        sources: &[&dyn Source],
        non_finite: NonFinite,
    ) -> Result<Self, FrameError> {
        let grids: Vec<_> = sources.iter().map(|s| s.grid()).collect();
        check_grids(transport, &grids)?;
        let volumes: Vec<Distributed<T>> = (sources.iter())
            .map(|s| Distributed::read(transport, *s, non_finite))
            .collect::<Result<_, _>>()?;
        Self::of(volumes)
    }

    /// The scene of `volumes`, each read by [`Distributed::read`] (and
    /// asked what it needs of the ranks, a histogram, say, before it is
    /// handed here: its renderer then belongs to the scene).
    pub fn of(mut volumes: Vec<Distributed<'t, T>>) -> Result<Self, FrameError> {
        let first = volumes.first().expect("a volume");
        let grids: Vec<_> = volumes.iter().map(Distributed::grid).collect();
        check_grids(first.plan().0, &grids)?;
        let renderers: Vec<Renderer<'static>> = volumes
            .iter_mut()
            .filter_map(|d| d.take_renderer())
            .collect();
        // Every volume has the same boxes: all or none held.
        let scene = if renderers.len() == volumes.len() && !renderers.is_empty() {
            Some(Scene::new(renderers).map_err(RenderError::from)?)
        } else {
            None
        };
        Ok(DistributedScene { volumes, scene })
    }

    /// Each volume's agreed value range.
    pub fn value_ranges(&self) -> Vec<(f32, f32)> {
        self.volumes.iter().map(Distributed::value_range).collect()
    }

    /// Renders one frame of `request` (its looks without pieces: each
    /// rank sets its own) across the ranks: the finished frame on rank 0,
    /// `None` on the others; and this rank's times.
    pub fn render(
        &mut self,
        request: &SceneSettings,
    ) -> Result<(Option<Image>, RankTimes), FrameError> {
        let settings = &request.settings;
        if request.mix == Mix::Additive || settings.blend.is_projection() {
            return Err(FrameError::Rank {
                rank: 0,
                message: SceneFrameError::Mix.to_string(),
                bad_input: true,
            });
        }
        let mut looks = request.looks.clone();
        for (k, (look, volume)) in looks.iter_mut().zip(&mut self.volumes).enumerate() {
            let needs_gradient = look.iso.is_some() || look.gradient_opacity.is_some();
            let held = self.scene.as_ref().map(|s| s.layers()[k].volume());
            look.piece = Some(volume.piece_of(needs_gradient, held)?);
        }
        let grid = self.volumes[0].grid();
        let view = View::frame(
            &settings.camera,
            grid.bounds(),
            settings.width,
            settings.height,
        )
        .map_err(RenderError::from)?;
        let viewpoint = Viewpoint::of(&view);
        let start = Instant::now();
        let rendered = match &self.scene {
            Some(scene) => {
                let request = SceneSettings {
                    looks,
                    ..request.clone()
                };
                (scene.render(FrameRequest::new(&request).partial())).map(Rendered::partial)
            }
            None => (settings.validate())
                .map(|()| PartialImage::composite(settings.width, settings.height))
                .map_err(RenderError::from),
        };
        let cast = start.elapsed();
        // Every rank refuses the same settings alike; anything else must
        // not leave the others waiting.
        let status = (rendered.as_ref())
            .map(|_| Vec::new())
            .map_err(|e| e.to_string());
        let (transport, plan) = self.volumes[0].plan();
        if let Err(e @ FrameError::Rank { .. }) = agree(transport, status) {
            return Err(match rendered {
                Err(e) => FrameError::Render(e),
                Ok(_) => e,
            });
        }
        let mut times = self.volumes[0].read_times();
        times.cast = cast;
        let partial = rendered.expect("agreed");
        let (image, stats) = composite(transport, plan, &viewpoint, &grid, partial)?;
        times.compose = stats;
        let image = image.map(|p| p.finish(settings.background, |_| settings.background));
        Ok((image, times))
    }
}
