//! The composite mix of pre-classified volumes on one grid (the channels
//! of a stack, a segmentation on its scan's grid), cast brick by brick as
//! one volume is ([`crate::cpu::bricked`]): the same samples as
//! `fast.rs`, much faster where the grids agree.
//!
//! The volumes' bricks coincide, so the bricks occupied in any of them
//! are binned into the image's tiles once, and each tile's rays cross
//! each such brick together before the next (the brick's voxels stay in
//! the cache for all 256 rays). In a brick, each volume occupied there
//! has its lit voxels ([`crate::cpu::lit_bricks`], each volume's own
//! cache); a sample takes, from each volume whose cell is occupied, its
//! trilinear colour and opacity, mixes them ([`Mixer`]) and composites
//! the mix (the sample of a volume alone there as it is: the mix of one
//! sample is itself, up to rounding). A volume transparent in a cell adds exactly nothing there
//! (its eight corners have opacity 0), as on the single-volume path.
//!
//! The geometry of the rays (parallel or from the eye, crops, clip
//! planes, jitter, the exact ranges at the volume's faces) is the
//! single-volume caster's, shared through [`BrickSource`].

use super::SceneFrame;
use crate::bricks::cache::CacheRef;
use crate::bricks::occupied::{ClassifiedBricks, Source};
use crate::bricks::{BRICK, BrickGrid, CELLS, SIDE, SLOTS, cell, slot};
use crate::cpu::bricked::{self, BrickSource, CellBox, Segment, render_source};
use crate::cpu::lit_bricks::{Lighting, LitBricks};
use crate::cpu::tiles::TileBins;
use crate::kernels::composite::{Finish, FrontToBack};
use crate::kernels::mix::Mixer;
use crate::kernels::trilinear::{corners, interpolate};
use crate::partial::{PartialImage, PartialPixels};
use crate::progress::Progress;
use crate::renderer::{FastState, Renderer};
use crate::sampling::Sampling;
use crate::sampling::grid::GridFrame;
use crate::settings::RenderSettings;
use std::ops::Deref;
use std::sync::MutexGuard;
use wide::f32x4;

/// No occupied brick of a volume here.
const NONE: u32 = u32::MAX;
/// Up to this many volumes occupied in one brick, a ray's march reads
/// their voxels by plain references (more: through their guards).
const DIRECT: usize = 8;

/// One volume's lit bricks in the frame.
struct Channel<'a> {
    bricks: &'a ClassifiedBricks,
    lit: &'a LitBricks,
    lighting: Lighting<'a>,
}

/// The bricks occupied in any of the volumes, as the caster's list
/// entries: entry `u` is brick `bricks[u]`, whose samples lie in
/// `boxes[u]` (the box of every volume's occupied cells there), and is
/// volume `k`'s occupied brick `numbers[u·K + k]` (or [`NONE`]).
struct Union {
    bricks: Vec<[usize; 3]>,
    boxes: Vec<([usize; 3], [usize; 3])>,
    numbers: Vec<u32>,
}

impl Union {
    fn new(grid: &BrickGrid, volumes: &[&ClassifiedBricks]) -> Self {
        let k_count = volumes.len();
        let mut entry = vec![NONE; grid.len()];
        let mut union = Union {
            bricks: Vec::new(),
            boxes: Vec::new(),
            numbers: Vec::new(),
        };
        for (k, bricks) in volumes.iter().enumerate() {
            for (n, b) in bricks.bricks().enumerate() {
                let i = grid.index(b);
                let (lo, hi) = bricks.occupied_box(n);
                let u = if entry[i] == NONE {
                    entry[i] = union.bricks.len() as u32;
                    union.bricks.push(b);
                    union.boxes.push((lo, hi));
                    union.numbers.extend(std::iter::repeat_n(NONE, k_count));
                    entry[i] as usize
                } else {
                    let u = entry[i] as usize;
                    let (ulo, uhi) = &mut union.boxes[u];
                    for a in 0..3 {
                        ulo[a] = ulo[a].min(lo[a]);
                        uhi[a] = uhi[a].max(hi[a]);
                    }
                    u
                };
                union.numbers[u * k_count + k] = n as u32;
            }
        }
        union
    }
}

/// Several volumes' lit bricks on one grid, for the brick-by-brick caster.
struct Channels<'a> {
    grid: BrickGrid,
    union: Union,
    channels: Vec<Channel<'a>>,
}

impl Channels<'_> {
    #[inline]
    fn number(&self, u: usize, k: usize) -> u32 {
        self.union.numbers[u * self.channels.len() + k]
    }
}

impl BrickSource for Channels<'_> {
    /// The volumes occupied in the brick: their lit voxels and occupied
    /// cells.
    type Lit<'l>
        = Vec<(CacheRef<'l, [[f32; 4]; SLOTS]>, &'l [u64; CELLS / 64])>
    where
        Self: 'l;
    type Scratch = Vec<Option<Box<[[f32; 4]; SLOTS]>>>;

    fn cell_box(&self, u: usize) -> CellBox {
        CellBox::new(&self.grid, self.union.bricks[u], self.union.boxes[u])
    }

    fn light<'l>(&'l self, u: usize, scratch: &'l mut Self::Scratch) -> Self::Lit<'l> {
        scratch.resize_with(self.channels.len(), || None);
        (self.channels.iter().zip(scratch.iter_mut()).enumerate())
            .filter_map(|(k, (channel, scratch))| {
                let n = self.number(u, k) as usize;
                (n != NONE as usize).then(|| {
                    let lit = channel.lit.get(n, &channel.lighting, scratch);
                    (lit, &channel.bricks.cells[n])
                })
            })
            .collect()
    }

    fn march<'l>(
        &'l self,
        acc: &mut FrontToBack,
        lit: &Self::Lit<'l>,
        _: usize,
        segment: &Segment,
    ) -> bool {
        // The voxels read straight, not through each lock's guard.
        static NOTHING: ([[f32; 4]; SLOTS], [u64; CELLS / 64]) =
            ([[0.0; 4]; SLOTS], [0; CELLS / 64]);
        match lit.len() {
            // One volume occupied here: the single-volume caster's march.
            1 => return bricked::march(acc, &lit[0].0, lit[0].1, segment),
            n if n > DIRECT => return march(acc, lit, segment),
            _ => {}
        }
        let mut direct = [(&NOTHING.0, &NOTHING.1); DIRECT];
        for (d, (voxels, cells)) in direct.iter_mut().zip(lit) {
            *d = (&**voxels, *cells);
        }
        match lit.len() {
            2 => march_n(acc, &[direct[0], direct[1]], segment),
            3 => march_n(acc, &[direct[0], direct[1], direct[2]], segment),
            n => march(acc, &direct[..n], segment),
        }
    }

    fn done(&self, u: usize) {
        for (k, channel) in self.channels.iter().enumerate() {
            let n = self.number(u, k);
            if n != NONE {
                channel.lit.done(n as usize);
            }
        }
    }
}

/// Composites the samples of `segment` into `acc`, each the mix of the
/// `volumes` (lit voxels, occupied cells) whose cell is occupied there, as
/// the single-volume caster's `march` composites one volume's. Returns
/// whether the ray has terminated.
#[inline(never)]
fn march<L: Deref<Target = [[f32; 4]; SLOTS]>>(
    acc: &mut FrontToBack,
    volumes: &[(L, &[u64; CELLS / 64])],
    segment: &Segment,
) -> bool {
    march_body(acc, volumes, segment)
}

/// [`march`] for exactly `N` volumes, the loop over them unrolled: two
/// channels of the bench's 256³ specimen took 1.79 times one channel's
/// frame, against 1.86 through the slice (`examples/scene_bench.rs`,
/// one run each).
#[inline(never)]
fn march_n<const N: usize>(
    acc: &mut FrontToBack,
    volumes: &[(&[[f32; 4]; SLOTS], &[u64; CELLS / 64]); N],
    segment: &Segment,
) -> bool {
    march_body(acc, volumes, segment)
}

#[inline(always)]
fn march_body<L: Deref<Target = [[f32; 4]; SLOTS]>>(
    acc: &mut FrontToBack,
    volumes: &[(L, &[u64; CELLS / 64])],
    segment: &Segment,
) -> bool {
    let last_cell = f32x4::splat((BRICK - 1) as f32);
    let mut ray = *acc;
    let mut p = segment.origin + segment.delta * f32x4::splat(segment.first as f32);
    let mut terminated = false;
    let mut left = segment.last - segment.first + 1;
    while left > 0 {
        left -= 1;
        let here = p.fast_max(segment.lo).fast_min(segment.hi);
        p += segment.delta;
        let c = here.fast_min(last_cell).fast_trunc_int();
        let [i, j, l, _] = c.to_array().map(|x| x as usize & (BRICK - 1));
        let bit = cell(i, j, l);
        let [fx, fy, fz, _] = (here - f32x4::from_i32x4(c)).to_array();
        // One volume's sample is composited as it is; several are mixed.
        let (mut mixer, mut only, mut count) = (Mixer::NEW, f32x4::ZERO, 0);
        for (lit, cells) in volumes {
            if cells[bit / 64] >> (bit % 64) & 1 == 0 {
                continue;
            }
            let voxels = corners(|s| f32x4::new(lit[s]), slot(i, j, l), SIDE, SIDE * SIDE);
            let sample = interpolate(voxels, [fx, fy, fz]);
            count += 1;
            if count == 1 {
                only = sample;
            } else {
                if count == 2 {
                    mixer.add(only);
                }
                mixer.add(sample);
            }
        }
        let sample = match count {
            0 => continue,
            1 => only,
            _ => match mixer.sample() {
                Some(sample) => sample,
                None => continue,
            },
        };
        ray.add(sample);
        if ray.is_opaque() {
            terminated = true;
            break;
        }
    }
    *acc = ray;
    terminated
}

/// Whether every volume of `layers` is on one grid: the same points,
/// origin and spacing (so that their bricks coincide).
pub(super) fn one_grid(layers: &[(&Renderer, &RenderSettings)]) -> bool {
    let grid = |r: &Renderer| {
        let v = r.volume();
        (v.dims(), v.origin(), v.spacing())
    };
    (layers.windows(2)).all(|w| grid(w[0].0) == grid(w[1].0))
}

/// Renders `layers` (pre-classified volumes on one grid, each with its
/// settings) mixed, as `frame` says, into a partial image.
pub(super) fn render(
    layers: &[(&Renderer, &RenderSettings)],
    frame: &SceneFrame,
    progress: &Progress,
) -> PartialImage {
    let view = &frame.view;
    let volume = layers[0].0.volume();
    let grid = BrickGrid::new(volume.dims());
    // The frame's samples in the volumes' grid (the box is the same).
    let sampling = Sampling {
        grid: GridFrame::of(volume),
        ..frame.sampling.clone()
    };
    let mut states: Vec<MutexGuard<Option<FastState>>> = (layers.iter())
        .map(|(r, s)| r.fast_state(r.classifier(s)))
        .collect();
    let union = {
        let volumes: Vec<&ClassifiedBricks> = states.iter().map(|g| &state(g).bricks).collect();
        Union::new(&grid, &volumes)
    };
    let bins = TileBins::of_boxes(
        union.bricks.len(),
        |u| union.bricks[u],
        |u| union.boxes[u],
        &sampling,
        view,
    );
    // Each volume's lit bricks start the frame with the tiles' uses of
    // its own bricks.
    let k_count = layers.len();
    let numbers: Vec<u64> = (states.iter_mut().enumerate())
        .map(|(k, guard)| {
            let listed: Vec<u32> = (bins.entries().iter())
                .map(|&u| union.numbers[u as usize * k_count + k])
                .filter(|&n| n != NONE)
                .collect();
            state_mut(guard).lit.next_frame(&listed)
        })
        .collect();
    let masks: Vec<_> = layers.iter().map(|(r, _)| r.masked()).collect();
    let lights: Vec<_> = (layers.iter())
        .map(|(_, s)| Renderer::light(s, view))
        .collect();
    let channels = Channels {
        grid,
        union,
        channels: (0..k_count)
            .map(|k| {
                let (renderer, settings) = layers[k];
                let state = state(&states[k]);
                let source = Source {
                    volume: renderer.volume(),
                    classifier: &state.classifier,
                    masked: &masks[k],
                };
                let lighting = settings.shading.then_some((&settings.phong, &lights[k]));
                Channel {
                    bricks: &state.bricks,
                    lit: &state.lit,
                    lighting: Lighting::new(source, &state.bricks, numbers[k], lighting),
                }
            })
            .collect(),
    };
    let (width, height) = (view.width(), view.height());
    let mut image = PartialImage::composite(width, height);
    let PartialPixels::Composite(pixels) = image.pixels_mut() else {
        unreachable!("a composite image")
    };
    render_source(
        &channels,
        &bins,
        &sampling,
        view,
        pixels,
        Finish::Partial,
        progress,
    );
    let lit: Vec<usize> = channels
        .channels
        .iter()
        .map(|c| c.lighting.count())
        .collect();
    drop(channels);
    for (guard, lit) in states.iter_mut().zip(lit) {
        state_mut(guard).lit.end_frame(lit);
    }
    image
}

fn state<'g>(guard: &'g MutexGuard<Option<FastState>>) -> &'g FastState {
    guard.as_ref().expect("the state was made")
}

fn state_mut<'g>(guard: &'g mut MutexGuard<Option<FastState>>) -> &'g mut FastState {
    guard.as_mut().expect("the state was made")
}
