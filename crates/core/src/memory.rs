//! How much memory rendering a frame takes: an upper bound from the sizes
//! of the structures each path allocates, known before anything is
//! allocated, so that a front end can refuse a volume that would not fit
//! (`volray --max-memory`).
//!
//! Each module states the bytes its own structures take per voxel, per
//! brick or per pixel (from `size_of` of the real types); this module adds
//! them up for the path a [`RenderSettings`] selects, assuming the worst
//! case: every brick occupied and lit (a dense volume under a permissive
//! transfer function). A sparse volume takes less. The parts:
//!
//! | path | kept by the renderer | per frame |
//! |---|---|---|
//! | fast, pre-classified (composite, iso) | min/max per brick; occupied bricks, classified (8 bytes a slot) and lit (16 bytes a slot), 9³ slots per brick of 8³ cells (1.42 a voxel) | tile lists, each brick's cell box |
//! | fast, post-classified | min/max per brick; each voxel's gradient and value (16 bytes) | the gradients (12 bytes a voxel) while the packed voxels are built, on the first frame |
//! | fast, projections (MIP, MinIP, average) | min/max per brick | — |
//! | reference, pre-classified | — | gradients (12) and shaded voxels (16 bytes a voxel) |
//! | reference, post-classified | — | gradients (12) |
//!
//! With shadows ([`crate::shadows`]) the fast paths keep a light volume
//! (2 bytes a voxel) and its running slices while it is swept; with
//! ambient occlusion ([`crate::shadows::ambient`]) an ambient volume (2
//! bytes a voxel) and its ring of slices while it is computed. The
//! reference adds the light reaching each voxel (4 bytes a voxel each)
//! and the opacities it is marched through (see `depth_cues`).
//!
//! plus the frame (16 bytes a pixel, partial and finished image sharing
//! one buffer; a projection 32) and, with non-finite values rendered as
//! empty space, the cleaned copy of the volume and its mask. A renderer
//! that renders frames of several paths keeps each path's caches.

use crate::bricks;
use crate::bricks::BrickGrid;
use crate::cpu::{bricked, lit_bricks, post, tiles};
use crate::frame::image::Image;
use crate::kernels::gradient;
use crate::kernels::projection::Projected;
use crate::reference::{self, stage1};
use crate::settings::{Blend, Classification, MAX_SAMPLES_PER_RAY, Method, RenderSettings};
use crate::shadows::ambient::AmbientRays;
use crate::shadows::ambient_volume::{self, AmbientVolume};
use crate::shadows::light_volume::{self, LightVolume};
use crate::shadows::opacities;
use crate::volume::non_finite::{self, NonFinite};
use crate::volume::{SampleType, Volume};
use glam::DVec3;

/// An upper bound, in bytes, on the memory one frame of a volume takes,
/// by part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MemoryBound {
    /// The volume's values (`f32`), held by the caller.
    pub volume: u128,
    /// A cleaned copy of the volume and its mask, when non-finite values
    /// are rendered as empty space.
    pub cleaned: u128,
    /// What the path keeps across frames and allocates for one.
    pub path: u128,
    /// The frame's pixels.
    pub frame: u128,
}

impl MemoryBound {
    /// The bound on the memory a frame of a volume of `dims` voxels
    /// `spacing` apart takes with `settings`, the volume included;
    /// `non_finite` is how its non-finite values are treated
    /// ([`NonFinite::Transparent`] counts the cleaned copy, as if the
    /// volume had some); `cache_budget` is the renderer's
    /// ([`Renderer::with_cache_budget`](crate::Renderer::with_cache_budget)).
    /// The volume's samples count in their own type.
    pub fn new(
        dims: [usize; 3],
        spacing: DVec3,
        sample: SampleType,
        settings: &RenderSettings,
        non_finite: NonFinite,
        cache_budget: usize,
    ) -> Self {
        let voxels: u128 = dims.iter().map(|&n| n as u128).product();
        let grid = BrickGrid::new(dims.map(|n| n.max(2)));
        let bricks = grid.len() as u128;
        let macrocells = bricks * bricks::macrocells::BYTES_PER_BRICK as u128;
        let gradients = voxels * gradient::BYTES_PER_VOXEL as u128;
        // The reference path reads a dense `f32` copy of other sample types.
        let reference_values = match sample {
            SampleType::F32 => 0,
            _ => voxels * size_of::<f32>() as u128,
        };
        let cues = depth_cues(dims, spacing, settings);
        let path = match (settings.method, settings.blend, settings.classification) {
            (Method::Fast, Blend::Composite, Classification::Pre) => {
                macrocells + bricked_path(grid, settings, cache_budget) + cues
            }
            // The gradients are held while the packed voxels are made, and
            // let go before the depth cues are computed.
            (Method::Fast, Blend::Composite, Classification::Post) => {
                macrocells
                    + voxels * post::BYTES_PER_VOXEL as u128
                    + gradients.max(cues)
                    + bricks * post::FRAME_BYTES_PER_BRICK as u128
            }
            (Method::Fast, _, _) => macrocells,
            (Method::Reference, Blend::Composite, Classification::Pre) => {
                reference_values
                    + gradients
                    + voxels * stage1::BYTES_PER_VOXEL as u128
                    + ray_samples(dims, spacing, settings)
                    + cues
            }
            (Method::Reference, Blend::Composite, Classification::Post) => {
                reference_values + gradients + ray_samples(dims, spacing, settings) + cues
            }
            (Method::Reference, _, _) => reference_values,
        };
        let pixels = settings.width as u128 * settings.height as u128;
        let image = size_of::<[f32; 4]>() as u128;
        let frame = match settings.blend {
            Blend::Composite => pixels * image,
            _ => pixels * (image + size_of::<Projected>() as u128),
        } + size_of::<Image>() as u128;
        // Only `f32` samples can be non-finite.
        let cleaned = match non_finite {
            NonFinite::Transparent if sample == SampleType::F32 => non_finite::bytes(dims),
            _ => 0,
        };
        MemoryBound {
            volume: voxels * sample.bytes() as u128,
            cleaned,
            path,
            frame,
        }
    }

    /// [`Self::new`] for `volume`.
    pub fn for_volume(
        volume: &Volume,
        settings: &RenderSettings,
        non_finite: NonFinite,
        cache_budget: usize,
    ) -> Self {
        Self::new(
            volume.dims(),
            volume.spacing(),
            volume.sample_type(),
            settings,
            non_finite,
            cache_budget,
        )
    }

    /// The whole bound.
    pub fn total(&self) -> u128 {
        self.volume + self.cleaned + self.path + self.frame
    }
}

/// The bytes shadows and ambient occlusion add to a frame of `settings`:
/// on the fast paths, the light and ambient volumes and the opacities the
/// light is swept through (kept) and what each holds while it is
/// computed, one after the other; on the reference, the light and ambient
/// light reaching each voxel (4 bytes each), the opacities they are
/// marched through (4 bytes, let go before the shaded voxels are made;
/// where samples are classified, the shadows' are held for the frame and
/// the ambient occlusion's until it is computed).
fn depth_cues(dims: [usize; 3], spacing: DVec3, settings: &RenderSettings) -> u128 {
    let voxels: u128 = dims.iter().map(|&n| n as u128).product();
    let cues = u128::from(settings.shadows) + u128::from(settings.ambient_occlusion.is_some());
    if cues == 0 {
        return 0;
    }
    let float = size_of::<f32>() as u128;
    if settings.method == Method::Reference {
        return match settings.classification {
            Classification::Pre => voxels * float * cues,
            Classification::Post => {
                let ambient = u128::from(settings.ambient_occlusion.is_some());
                voxels * float * (u128::from(settings.shadows) + 2 * ambient)
            }
        };
    }
    let shadows = match settings.shadows {
        false => (0, 0),
        true => {
            let bytes = light_volume::BYTES_PER_VOXEL + opacities::BYTES_PER_VOXEL;
            let kept = voxels * bytes as u128;
            let step = crate::shadows::shadow_step(settings.step);
            // The opacities' second copy while they are arranged for the
            // sweep, then its ring of slices.
            let arranging = voxels * opacities::BYTES_PER_VOXEL as u128;
            let ring = LightVolume::ring_bytes(dims, step) as u128;
            (kept, arranging.max(ring))
        }
    };
    let ambient = match settings.ambient_occlusion {
        None => (0, 0),
        Some(radius) => {
            let rays = AmbientRays::new(radius, spacing);
            let kept = voxels * ambient_volume::BYTES_PER_VOXEL as u128;
            (kept, AmbientVolume::ring_bytes(dims, &rays) as u128)
        }
    };
    shadows.0 + ambient.0 + shadows.1.max(ambient.1)
}

/// The reference path's samples of the rays being composited, one ray per
/// worker thread: a ray takes at most the grid's diagonal over the step.
fn ray_samples(dims: [usize; 3], spacing: DVec3, settings: &RenderSettings) -> u128 {
    let extent = DVec3::new(
        (dims[0].max(2) - 1) as f64,
        (dims[1].max(2) - 1) as f64,
        (dims[2].max(2) - 1) as f64,
    ) * spacing;
    let step = settings.step * spacing.min_element();
    // Collected into a vector, which grows by doubling.
    let samples =
        ((extent.length() / step).min(MAX_SAMPLES_PER_RAY).ceil() as u128 + 1).next_power_of_two();
    rayon::current_num_threads() as u128 * samples * reference::BYTES_PER_SAMPLE as u128
}

/// The bricked fast path with every brick occupied and lit: the classified
/// and lit bricks, and what a frame allocates for them.
fn bricked_path(grid: BrickGrid, settings: &RenderSettings, cache_budget: usize) -> u128 {
    let bricks = grid.len() as u128;
    let per_occupied = bricks::occupied::BYTES_PER_OCCUPIED_BRICK
        + lit_bricks::BYTES_PER_OCCUPIED_BRICK
        + tiles::BYTES_PER_OCCUPIED_BRICK;
    // The slots, classified and lit, as far as the budget they share goes.
    let slots = (bricks
        * (bricks::occupied::SLOT_BYTES_PER_OCCUPIED_BRICK
            + lit_bricks::SLOT_BYTES_PER_OCCUPIED_BRICK) as u128)
        .min(cache_budget as u128);
    let tiles_x = settings.width.div_ceil(tiles::TILE) as u128;
    let tiles_y = settings.height.div_ceil(tiles::TILE) as u128;
    let tile_count = tiles_x * tiles_y;
    // Each brick is listed in the tiles its projection touches: a brick
    // of the volume framed to fill the window spans about
    // `window / bricks across` pixels (zoomed), √3 times that along its
    // diagonal, and a box of `e` pixels touches at most `⌈e/16⌉ + 1`
    // tiles along an axis; never more than all of them.
    let across = grid.bricks.iter().copied().min().unwrap_or(1).max(1) as f64;
    let window = settings.width.max(settings.height) as f64;
    let zoom = settings.camera.zoom.max(1.0);
    let span = (window * zoom * 3f64.sqrt() / across / tiles::TILE as f64).ceil() + 1.0;
    let per_brick = (span * span).min(tile_count as f64) as u128;
    slots
        + bricks * (per_occupied as u128 + bricks::occupied::BYTES_PER_BRICK as u128)
        + bricks * per_brick * tiles::BYTES_PER_ENTRY as u128
        + tile_count * (tiles::BYTES_PER_TILE + bricked::FRAME_BYTES_PER_TILE) as u128
}
