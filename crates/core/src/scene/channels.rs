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
//! cache), lit when the first ray that needs them crosses the brick; a
//! sample takes, from each volume whose cell is occupied, its
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
use crate::cpu::bricked::{self, Accumulator, BrickSource, CellBox, Segment, render_source};
use crate::cpu::lit_bricks::{Lighting, LitBricks};
use crate::cpu::tiles::TileBins;
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::frame::progress::Progress;
use crate::kernels::composite::{EMPTY, Finish, FrontToBack, PartialPixel};
use crate::kernels::mix::Mixer;
use crate::kernels::trilinear::{corners, interpolate};
use crate::renderer::{FastState, Renderer};
use crate::sampling::Sampling;
use crate::sampling::grid::GridFrame;
use crate::settings::RenderSettings;
use std::cell::{Cell, OnceCell};
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

/// Where one volume's brick is lit when the lit-brick cache has no room.
type Scratch = Option<Box<[[f32; 4]; SLOTS]>>;

/// A volume occupied in a brick: its number `k` in the scene and its
/// occupied cells, and its voxels, lit when a ray first needs them (see
/// [`Self::voxels`]).
struct LitVolume<'l> {
    k: usize,
    /// Its number among the volume's occupied bricks.
    n: usize,
    channel: &'l Channel<'l>,
    cells: &'l [u64; CELLS / 64],
    /// Where it is lit if the lit-brick cache has no room (taken then).
    scratch: Cell<Option<&'l mut Scratch>>,
    voxels: OnceCell<CacheRef<'l, [[f32; 4]; SLOTS]>>,
}

impl LitVolume<'_> {
    /// The brick's voxels of this volume, lit for the frame now unless
    /// they are.
    #[inline]
    fn voxels(&self) -> &[[f32; 4]; SLOTS] {
        self.voxels.get_or_init(|| {
            let scratch = self.scratch.take().expect("a brick's volume is lit once");
            self.channel
                .lit
                .get(self.n, &self.channel.lighting, scratch)
        })
    }

    /// The voxels, lit now unless they are, and the occupied cells.
    #[inline]
    fn lit(&self) -> (&[[f32; 4]; SLOTS], &[u64; CELLS / 64]) {
        (self.voxels(), self.cells)
    }
}

/// The volumes occupied in a brick: the first [`DIRECT`] in an array, any
/// more in a vector (a vector for every brick a tile crosses cost an
/// allocation each).
struct LitVolumes<'l> {
    few: [Option<LitVolume<'l>>; DIRECT],
    more: Vec<LitVolume<'l>>,
    len: usize,
}

impl<'l> LitVolumes<'l> {
    fn push(&mut self, volume: LitVolume<'l>) {
        match self.few.get_mut(self.len) {
            Some(slot) => *slot = Some(volume),
            None => self.more.push(volume),
        }
        self.len += 1;
    }

    fn iter(&self) -> impl Iterator<Item = &LitVolume<'l>> {
        self.few.iter().flatten().chain(&self.more)
    }

    /// Volume `v` (`v` < [`DIRECT`]).
    #[inline]
    fn direct(&self, v: usize) -> &LitVolume<'l> {
        self.few[v].as_ref().expect("a volume occupied here")
    }
}

impl Channels<'_> {
    fn cell_box(&self, u: usize) -> CellBox {
        CellBox::new(&self.grid, self.union.bricks[u], self.union.boxes[u])
    }

    fn light<'l>(&'l self, u: usize, scratch: &'l mut Vec<Scratch>) -> LitVolumes<'l> {
        scratch.resize_with(self.channels.len(), || None);
        let mut lit = LitVolumes {
            few: [const { None }; DIRECT],
            more: Vec::new(),
            len: 0,
        };
        // Each volume is lit when the first ray that uses it crosses the
        // brick: in the composite mix, the first ray with samples here; in
        // the additive mix, the first whose compositor of that volume is
        // not opaque.
        for (k, (channel, scratch)) in self.channels.iter().zip(scratch.iter_mut()).enumerate() {
            let n = self.number(u, k) as usize;
            if n != NONE as usize {
                lit.push(LitVolume {
                    k,
                    n,
                    channel,
                    cells: &channel.bricks.cells[n],
                    scratch: Cell::new(Some(scratch)),
                    voxels: OnceCell::new(),
                });
            }
        }
        lit
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

impl BrickSource for Channels<'_> {
    type Acc = FrontToBack;
    /// The volumes occupied in the brick: their lit voxels and occupied
    /// cells.
    type Lit<'l>
        = LitVolumes<'l>
    where
        Self: 'l;
    type Scratch = Vec<Scratch>;

    fn cell_box(&self, u: usize) -> CellBox {
        Channels::cell_box(self, u)
    }

    fn light<'l>(&'l self, u: usize, scratch: &'l mut Self::Scratch) -> Self::Lit<'l> {
        Channels::light(self, u, scratch)
    }

    fn march<'l>(
        &'l self,
        acc: &mut FrontToBack,
        lit: &Self::Lit<'l>,
        _: usize,
        segment: &Segment,
    ) -> bool {
        // The voxels read straight, not through each lock's guard.
        match lit.len {
            // One volume occupied here: the single-volume caster's march.
            1 => {
                let volume = lit.direct(0);
                bricked::march(acc, volume.voxels(), volume.cells, segment)
            }
            2 => march_n(acc, &[0, 1].map(|v| lit.direct(v).lit()), segment),
            3 => march_n(acc, &[0, 1, 2].map(|v| lit.direct(v).lit()), segment),
            n if n <= DIRECT => {
                static NOTHING: ([[f32; 4]; SLOTS], [u64; CELLS / 64]) =
                    ([[0.0; 4]; SLOTS], [0; CELLS / 64]);
                let mut direct = [(&NOTHING.0, &NOTHING.1); DIRECT];
                for (d, volume) in direct[..n].iter_mut().zip(lit.iter()) {
                    *d = (volume.voxels(), volume.cells);
                }
                march(acc, &direct[..n], segment)
            }
            _ => {
                let volumes: Vec<_> = lit.iter().map(|v| (v.voxels(), v.cells)).collect();
                march(acc, &volumes, segment)
            }
        }
    }

    fn done(&self, u: usize) {
        Channels::done(self, u)
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

/// [`march`] for exactly `N` volumes, the loop over them unrolled. Which
/// volumes are occupied in the sample's cell is one bit mask: none, one
/// (interpolated and composited as it is, no mixer) or several (mixed).
/// Against the loop that counted the occupied volumes as it went (one
/// sample kept aside until a second came), with the other changes of the
/// same commit in both (`examples/scene_bench.rs`, processor time, three
/// alternated runs on 2026-11-27, load average 5.7 to 6.0): two channels
/// took 1.65, 1.78 and 1.69 times one channel against 1.80, 1.95 and
/// 1.84; three 2.24, 2.15 and 2.18 against 2.34, 2.40 and 2.45.
///
/// Tried before (2026-11-27, `examples/scene_bench.rs`, processor time,
/// same binary switched at run time, two runs each): two volumes occupied
/// at a sample interpolated in one 8-lane AVX vector (`vinsertf128` of the
/// two corners, seven 8-lane lerps; the same sums lane by lane) took 1.80
/// and 2.05 times one channel for two channels against 1.84 and 1.86
/// without, and 2.44 and 2.60 against 2.19 and 2.35 for three: no gain,
/// so not kept. Neither was a loop that first gathered the occupied
/// volumes into a list (1.89 and 1.89 against 1.85 and 1.81).
#[inline(never)]
fn march_n<const N: usize>(
    acc: &mut FrontToBack,
    volumes: &[(&[[f32; 4]; SLOTS], &[u64; CELLS / 64]); N],
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
        let (word, shift) = (bit / 64, bit % 64);
        // Bit k: volume k is occupied in the sample's cell.
        let mut occupied = 0u32;
        for (k, (_, cells)) in volumes.iter().enumerate() {
            occupied |= ((cells[word] >> shift & 1) as u32) << k;
        }
        if occupied == 0 {
            continue;
        }
        let [fx, fy, fz, _] = (here - f32x4::from_i32x4(c)).to_array();
        let base = slot(i, j, l);
        let at = |k: usize| {
            let lit = volumes[k].0;
            let voxels = corners(|s| f32x4::new(lit[s]), base, SIDE, SIDE * SIDE);
            interpolate(voxels, [fx, fy, fz])
        };
        // One volume's sample is composited as it is; several are mixed.
        let sample = if occupied & (occupied - 1) == 0 {
            at(occupied.trailing_zeros() as usize)
        } else {
            let mut mixer = Mixer::NEW;
            for k in 0..N {
                if occupied >> k & 1 != 0 {
                    mixer.add(at(k));
                }
            }
            match mixer.sample() {
                Some(sample) => sample,
                None => continue,
            }
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

/// Up to this many volumes are composited side by side in one march of
/// the additive mix; more are marched in groups of this many, the groups'
/// partial pixels summed.
const GROUP: usize = 4;

/// The additive mix's ray: one front-to-back compositor per volume, each
/// taking its volume's samples exactly as that volume's own renderer
/// takes them (and stopping where that one stops); the partial pixel is
/// theirs summed as [`super::add`] sums the volumes' frames, in order
/// from [`EMPTY`], so the result is what rendering each apart and
/// summing gives (up to the rounding of samples on the faces of boxes
/// that differ: the union's and each volume's own).
#[derive(Clone, Copy)]
struct Sums<const N: usize>([FrontToBack; N]);

impl<const N: usize> Accumulator for Sums<N> {
    const NEW: Self = Sums([FrontToBack::NEW; N]);

    #[inline]
    fn partial(&self) -> PartialPixel {
        (self.0.iter()).fold(EMPTY, |sum, acc| super::add(sum, acc.partial()))
    }
}

/// `N` volumes on one grid in the additive mix: the same bricks, lists
/// and lit voxels as the composite mix ([`Channels`]), a compositor per
/// volume along each ray. A ray ends when every volume's compositor is
/// opaque; a brick is skipped where every volume is empty (the union's
/// lists), and a volume empty in a brick takes no sample there. A brick
/// is lit for a volume only when a ray whose compositor of that volume is
/// not opaque crosses it (one bench frame of two channels lit 5497
/// bricks, against 5856 when every volume occupied in a brick was lit
/// with the first ray; one channel alone lights 2559).
struct Additive<'c, 'a, const N: usize>(&'c Channels<'a>);

impl<const N: usize> BrickSource for Additive<'_, '_, N> {
    type Acc = Sums<N>;
    type Lit<'l>
        = LitVolumes<'l>
    where
        Self: 'l;
    type Scratch = Vec<Scratch>;

    fn cell_box(&self, u: usize) -> CellBox {
        self.0.cell_box(u)
    }

    fn light<'l>(&'l self, u: usize, scratch: &'l mut Self::Scratch) -> Self::Lit<'l> {
        self.0.light(u, scratch)
    }

    fn march<'l>(
        &'l self,
        acc: &mut Sums<N>,
        lit: &Self::Lit<'l>,
        _: usize,
        segment: &Segment,
    ) -> bool {
        static NOTHING: ([[f32; 4]; SLOTS], [u64; CELLS / 64]) =
            ([[0.0; 4]; SLOTS], [0; CELLS / 64]);
        // The volumes occupied here whose rays still take light: a volume
        // whose ray is opaque has stopped, as its own renderer's has.
        let mut live: [Numbered; N] = [(0, &NOTHING.0, &NOTHING.1); N];
        let mut m = 0;
        for volume in lit.iter() {
            if !acc.0[volume.k].is_opaque() {
                live[m] = (volume.k, volume.voxels(), volume.cells);
                m += 1;
            }
        }
        match m {
            0 => {}
            // One volume: the single-volume caster's march.
            1 => {
                let (k, voxels, cells) = live[0];
                bricked::march(&mut acc.0[k], voxels, cells, segment);
            }
            2 => march_apart::<N, 2>(&mut acc.0, &live, segment),
            3 => march_apart::<N, 3>(&mut acc.0, &live, segment),
            _ => march_apart::<N, GROUP>(&mut acc.0, &live, segment),
        }
        acc.0.iter().all(FrontToBack::is_opaque)
    }

    fn done(&self, u: usize) {
        self.0.done(u)
    }
}

/// A volume occupied in a brick: its number in the scene, its lit voxels
/// and its occupied cells.
type Numbered<'l> = (usize, &'l [[f32; 4]; SLOTS], &'l [u64; CELLS / 64]);

/// Composites the samples of `segment` into the compositors `rays` of the
/// first `M` of `volumes` (each its number `k`, lit voxels and occupied
/// cells; each not yet opaque), each volume's samples into its own ray as
/// [`bricked::march`] composites one volume's, until every one of them is
/// opaque.
#[inline(never)]
fn march_apart<const N: usize, const M: usize>(
    rays: &mut [FrontToBack; N],
    volumes: &[Numbered; N],
    segment: &Segment,
) {
    let volumes: [_; M] = std::array::from_fn(|v| volumes[v]);
    let last_cell = f32x4::splat((BRICK - 1) as f32);
    // The volumes' rays, in registers for the loop.
    let mut acc: [FrontToBack; M] = std::array::from_fn(|v| rays[volumes[v].0]);
    let mut p = segment.origin + segment.delta * f32x4::splat(segment.first as f32);
    let mut live = M;
    let mut left = segment.last - segment.first + 1;
    while left > 0 {
        left -= 1;
        let here = p.fast_max(segment.lo).fast_min(segment.hi);
        p += segment.delta;
        let c = here.fast_min(last_cell).fast_trunc_int();
        let [i, j, l, _] = c.to_array().map(|x| x as usize & (BRICK - 1));
        let bit = cell(i, j, l);
        let [fx, fy, fz, _] = (here - f32x4::from_i32x4(c)).to_array();
        for (ray, (_, lit, cells)) in acc.iter_mut().zip(&volumes) {
            if ray.is_opaque() || cells[bit / 64] >> (bit % 64) & 1 == 0 {
                continue;
            }
            let voxels = corners(|s| f32x4::new(lit[s]), slot(i, j, l), SIDE, SIDE * SIDE);
            ray.add(interpolate(voxels, [fx, fy, fz]));
            live -= usize::from(ray.is_opaque());
        }
        if live == 0 {
            break;
        }
    }
    for (v, (k, _, _)) in volumes.iter().enumerate() {
        rays[*k] = acc[v];
    }
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
/// settings) in the composite mix, as `frame` says, into a partial image.
pub(super) fn render(
    layers: &[(&Renderer, &RenderSettings)],
    frame: &SceneFrame,
    progress: &Progress,
) -> PartialImage {
    with_channels(layers, frame, |channels, bins, sampling| {
        cast_with(channels, (bins, sampling, frame, progress))
    })
}

/// Renders `layers` (pre-classified volumes on one grid) in the additive
/// mix, as `frame` says: each volume composited on its own along the
/// rays of one march, the colours summed and the transmittances
/// multiplied, into a partial image (the background and the clamp are
/// the caller's, as for volumes rendered apart).
pub(super) fn render_additive(
    layers: &[(&Renderer, &RenderSettings)],
    frame: &SceneFrame,
    progress: &Progress,
) -> PartialImage {
    let mut groups = layers.chunks(GROUP).map(|group| {
        with_channels(group, frame, |channels, bins, sampling| {
            let args = (bins, sampling, frame, progress);
            match group.len() {
                1 => cast_with(&Additive::<1>(channels), args),
                2 => cast_with(&Additive::<2>(channels), args),
                3 => cast_with(&Additive::<3>(channels), args),
                _ => cast_with(&Additive::<GROUP>(channels), args),
            }
        })
    });
    let mut image = groups.next().expect("a volume shown");
    for group in groups {
        let (PartialPixels::Composite(sum), PartialPixels::Composite(more)) =
            (image.pixels_mut(), group.pixels())
        else {
            unreachable!("composited frames")
        };
        for (s, p) in sum.iter_mut().zip(more) {
            *s = super::add(*s, *p);
        }
    }
    image
}

/// Casts `source`'s rays, binned into `bins` and sampled as `sampling`
/// says, through `frame`'s view into a partial image.
fn cast_with<S: BrickSource>(
    source: &S,
    (bins, sampling, frame, progress): (&TileBins, &Sampling, &SceneFrame, &Progress),
) -> PartialImage {
    let view = &frame.view;
    let mut image = PartialImage::composite(view.width(), view.height());
    let PartialPixels::Composite(pixels) = image.pixels_mut() else {
        unreachable!("a composite image")
    };
    render_source(
        source,
        bins,
        sampling,
        view,
        pixels,
        Finish::Partial,
        progress,
    );
    image
}

/// Calls `cast` with the lit bricks of `layers` (pre-classified volumes on
/// one grid, each with its settings) in a frame as `frame` says, the
/// union of their occupied bricks binned into the image's tiles, and the
/// frame's samples in their grid; then ends the frame of each volume's
/// lit bricks.
fn with_channels<R>(
    layers: &[(&Renderer, &RenderSettings)],
    frame: &SceneFrame,
    cast: impl FnOnce(&Channels, &TileBins, &Sampling) -> R,
) -> R {
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
                    lighting: Lighting::new(source, &state.bricks, numbers[k], lighting, None),
                }
            })
            .collect(),
    };
    let result = cast(&channels, &bins, &sampling);
    let lit: Vec<usize> = channels
        .channels
        .iter()
        .map(|c| c.lighting.count())
        .collect();
    drop(channels);
    for (guard, lit) in states.iter_mut().zip(lit) {
        state_mut(guard).lit.end_frame(lit);
    }
    result
}

fn state<'g>(guard: &'g MutexGuard<Option<FastState>>) -> &'g FastState {
    guard.as_ref().expect("the state was made")
}

fn state_mut<'g>(guard: &'g mut MutexGuard<Option<FastState>>) -> &'g mut FastState {
    guard.as_mut().expect("the state was made")
}
