//! The fast path of a scene's composite mix: the reference's samples
//! (`reference.rs`), in `f32`, front to back, with early ray termination,
//! skipping what is transparent in each volume.
//!
//! **Where a ray looks.** Each volume's bricks that may add something
//! (pre-classified: its occupied bricks; post-classified: those whose value
//! range is not transparent) are binned into the image's 16² tiles, front
//! to back, as for the single-volume caster ([`TileBins`]). A tile no
//! volume lists is empty. Each ray of a tile reads each volume's list in
//! order, finding its range of samples in each listed brick (the order in
//! which the ray meets them), and takes the nearest range of any volume
//! joined with every range that overlaps it: samples outside these ranges
//! are transparent in every volume, so empty space is skipped only where
//! every volume is empty. A ray stopped by a surface reads no further.
//!
//! **Chunks.** Within a range the ray takes its samples in chunks, from
//! [`FIRST_CHUNK`] samples, doubling to [`CHUNK`] (a ray that meets an
//! opaque surface stops within a few samples, and wastes at most the rest
//! of its chunk). For a chunk, each volume with a brick in the range fills
//! its samples (colour and opacity; zero outside its box and where it is
//! transparent), brick by brick of its own grid, so its inner loop runs
//! over one brick at a time as on the single-volume paths; then the
//! chunk's samples are mixed ([`Mixer`]) and composited, and the ray stops
//! once less than 1/1024 of the light gets through. A tile holds each
//! pre-classified brick it reads, lit, until its rays are done ([`Held`]).
//!
//! **A volume's samples** are those of its single-volume fast path:
//! - pre-classified (the paper's): its occupied bricks, classified once
//!   per transfer function and kept by its [`Renderer`], lit for the frame
//!   when a ray first reaches them ([`crate::cpu::lit_bricks`]), their
//!   voxels' colours and opacities interpolated trilinearly; a brick that
//!   is not occupied, or a cell of one whose eight corners are
//!   transparent, adds exactly nothing and is not read;
//! - post-classified: the scalar and the gradient interpolated from its
//!   packed voxels, classified and shaded (`cpu/post/`), stepping over the
//!   bricks whose value range is transparent.
//!
//! Positions are `f32`, counted from the ray's first sample in each
//! volume's index space, so a far eye costs no precision. Each pixel is
//! computed from its own ray alone, whatever thread runs it (tiles in
//! parallel): the image is bit-identical for any thread count.

use super::SceneFrame;
use crate::bricks::cache::CacheRef;
use crate::bricks::occupied::{ClassifiedBricks, Source};
use crate::bricks::{BRICK, BrickGrid, SIDE, SLOTS, cell, slot};
use crate::cpu::lit_bricks::{Lighting, LitBricks};
use crate::cpu::post::skipping::{TransparentValues, transparent_bricks};
use crate::cpu::tiles::{TILE, TileBins};
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::frame::progress::Progress;
use crate::kernels::composite::{EMPTY, FrontToBack, PartialPixel};
use crate::kernels::mix::Mixer;
use crate::kernels::phong::{LightGeometry, Phong, lit_colour};
use crate::kernels::trilinear::{cell_of, corners, interpolate};
use crate::renderer::{FastState, Renderer};
use crate::sampling::grid::GridFrame;
use crate::sampling::{PixelSamples, Sampling};
use crate::settings::{Classification, RenderSettings};
use crate::transfer::classifier::Classifier;
use crate::volume::non_finite::NonFiniteMask;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::MutexGuard;
use wide::f32x4;

/// The most samples a ray takes at a time: each volume fills a chunk,
/// then the chunk is mixed and composited.
pub(crate) const CHUNK: usize = 32;

/// The first chunk of a ray's range in some volume's bricks.
const FIRST_CHUNK: usize = 4;

/// A pre-classified volume's lit-brick buffer, when its cache is full.
type Scratch = Option<Box<[[f32; 4]; SLOTS]>>;

/// What one volume's samples are made of in this frame.
enum Kind<'a> {
    Pre {
        bricks: &'a ClassifiedBricks,
        lit: &'a LitBricks,
        /// Boxed: the variants then take alike.
        lighting: Box<Lighting<'a>>,
        /// Per brick of the grid: its occupied brick's number plus 1, or 0.
        occupied: Vec<u32>,
    },
    Post {
        voxels: &'a [f32x4],
        /// Per brick of the grid: whether every sample in it is transparent.
        transparent: Vec<bool>,
        values: TransparentValues,
        classifier: &'a Classifier,
        lighting: Option<(&'a Phong, LightGeometry)>,
        mask: Option<&'a NonFiniteMask>,
    },
}

/// One volume of the frame.
struct Layer<'a> {
    frame: GridFrame,
    grid: BrickGrid,
    kind: Kind<'a>,
    /// The bricks that may add something (pre-classified: the occupied
    /// ones, numbered as [`ClassifiedBricks`] does; post-classified: those
    /// not transparent), binned into the image's tiles.
    bins: TileBins,
    /// Per brick of the lists: the index-space box its samples lie in.
    boxes: Vec<([usize; 3], [usize; 3])>,
}

/// Slack, in samples, around each box's range of samples (as the
/// bricked caster's): a sample on a face is found whatever the rounding.
const SAMPLE_SLACK: f64 = 1e-3;
/// Slack, in voxels, for rays parallel to a box face.
const PARALLEL_SLACK: f64 = 1e-4;

/// One ray through one volume: sample `k` is at index-space
/// `start + (k − first)·delta`, and samples `range` are in its box.
struct Walk {
    start: Vec3,
    delta: Vec3,
    /// The same in `f64`, for the non-finite mask's test.
    start64: DVec3,
    delta64: DVec3,
    /// `1/delta64` per axis (infinite along an axis the ray is parallel to).
    inv64: DVec3,
    first: i64,
    range: Range<i64>,
}

impl Walk {
    #[inline(always)]
    fn position(&self, k: i64, max: Vec3) -> Vec3 {
        (self.start + self.delta * (k - self.first) as f32).clamp(Vec3::ZERO, max)
    }
}

impl Layer<'_> {
    /// The last voxel's index-space position.
    fn max(&self) -> Vec3 {
        let d = self.frame.dims;
        Vec3::new((d[0] - 1) as f32, (d[1] - 1) as f32, (d[2] - 1) as f32)
    }

    /// The brick holding index-space point `p` (in the grid).
    #[inline(always)]
    fn brick_of(&self, p: Vec3) -> [usize; 3] {
        let b = self.grid.bricks;
        [
            ((p.x as usize) / BRICK).min(b[0] - 1),
            ((p.y as usize) / BRICK).min(b[1] - 1),
            ((p.z as usize) / BRICK).min(b[2] - 1),
        ]
    }

    /// Whether every sample in brick `b` is transparent.
    #[inline(always)]
    fn transparent(&self, b: [usize; 3]) -> bool {
        let i = self.grid.index(b);
        match &self.kind {
            Kind::Pre { occupied, .. } => occupied[i] == 0,
            Kind::Post { transparent, .. } => transparent[i],
        }
    }

    /// The first sample of `walk` past brick `b` (which holds sample
    /// `k`): where the ray leaves the brick's box, by the slab test in
    /// `f64`. A sample on the exit face counts as past it (a face's voxels
    /// belong to both bricks); rounding moves the exit by a hair at most,
    /// so it never passes over a sample inside the next brick.
    #[inline]
    fn exit(&self, walk: &Walk, b: [usize; 3], k: i64) -> i64 {
        let (lo, hi) = self.grid.bounds(b);
        let mut n = f64::INFINITY;
        for a in 0..3 {
            let d = walk.delta64[a];
            let face = if d > 0.0 {
                hi[a]
            } else if d < 0.0 {
                lo[a]
            } else {
                continue;
            };
            n = n.min((face as f64 - walk.start64[a]) * walk.inv64[a]);
        }
        let exit = walk
            .first
            .saturating_add(n.ceil().min(i64::MAX as f64 / 2.0) as i64);
        exit.max(k + 1)
    }

    /// The samples of `walk` in list entry `n`'s box (its bricks'
    /// samples lie in it), within the volume's box; `None` if it misses.
    fn interval(&self, walk: &Walk, n: u32) -> Option<(i64, i64)> {
        let (lo, hi) = self.boxes[n as usize];
        let (mut enter, mut leave) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            let (d, s) = (walk.delta64[a], walk.start64[a]);
            let (l, h) = (lo[a] as f64, hi[a] as f64);
            if d == 0.0 {
                if s < l - PARALLEL_SLACK || s > h + PARALLEL_SLACK {
                    return None;
                }
                continue;
            }
            let inv = walk.inv64[a];
            let (n0, n1) = ((l - s) * inv, (h - s) * inv);
            enter = enter.max(n0.min(n1));
            leave = leave.min(n0.max(n1));
        }
        if enter > leave {
            return None;
        }
        let first = walk.first + (enter - SAMPLE_SLACK).ceil() as i64;
        let last = walk.first + (leave + SAMPLE_SLACK).floor() as i64;
        let (first, last) = (first.max(walk.range.start), last.min(walk.range.end - 1));
        (first <= last).then_some((first, last))
    }

    /// Fills `out` with this volume's samples `ks` of the ray `walk`
    /// (`(r, g, b, α)`, zero where it adds nothing); says whether any has
    /// an opacity above zero.
    fn fill(&self, walk: &Walk, ks: Range<i64>, out: &mut [f32x4], held: &mut Held) -> bool {
        out.fill(f32x4::ZERO);
        let (from, to) = (ks.start.max(walk.range.start), ks.end.min(walk.range.end));
        let max = self.max();
        let mut any = false;
        let mut k = from;
        while k < to {
            // The run of samples in one brick.
            let b = self.brick_of(walk.position(k, max));
            let end = self.exit(walk, b, k).min(to);
            if !self.transparent(b) {
                let out = &mut out[(k - ks.start) as usize..(end - ks.start) as usize];
                any |= match &self.kind {
                    Kind::Pre { .. } => self.pre(b, walk, k..end, out, held),
                    Kind::Post { .. } => self.post(b, walk, k..end, out),
                };
            }
            k = end;
        }
        any
    }

    /// Pre-classified samples `ks`, all in brick `b`, into `out`.
    fn pre(
        &self,
        b: [usize; 3],
        walk: &Walk,
        ks: Range<i64>,
        out: &mut [f32x4],
        held: &mut Held,
    ) -> bool {
        let Kind::Pre {
            bricks,
            lit,
            lighting,
            occupied,
        } = &self.kind
        else {
            unreachable!("a pre-classified volume")
        };
        let n = occupied[self.grid.index(b)] as usize - 1;
        // The tile's lit brick; a brick its list lacks (rounding at the
        // edge of a brick's projection) straight from the cache.
        let mut scratch = None;
        let slots = match held.get(n) {
            Some(slots) => CacheOr::Held(slots),
            None => CacheOr::Cache(lit.get(n, lighting, &mut scratch)),
        };
        let cells = &bricks.cells[n];
        let (lo, hi) = self.grid.bounds(b);
        let origin = Vec3::new(lo[0] as f32, lo[1] as f32, lo[2] as f32);
        let last = std::array::from_fn(|a| hi[a] - 1 - lo[a]);
        let max = self.max();
        let mut any = false;
        for (k, o) in ks.zip(out) {
            let p = (walk.position(k, max) - origin).max(Vec3::ZERO);
            let (c, f) = cell_of(p, last);
            let i = cell(c[0], c[1], c[2]);
            if cells[i / 64] & (1 << (i % 64)) == 0 {
                continue;
            }
            let base = slot(c[0], c[1], c[2]);
            let s = interpolate(
                corners(|i| f32x4::new(slots.at(i)), base, SIDE, SIDE * SIDE),
                f,
            );
            any |= s.as_array()[3] > 0.0;
            *o = s;
        }
        any
    }

    /// Post-classified samples `ks`, all in brick `b`, into `out`.
    fn post(&self, b: [usize; 3], walk: &Walk, ks: Range<i64>, out: &mut [f32x4]) -> bool {
        let Kind::Post {
            voxels,
            values,
            classifier,
            lighting,
            mask,
            ..
        } = &self.kind
        else {
            unreachable!("a post-classified volume")
        };
        let mask = mask.filter(|m| m.near(b));
        let [nx, ny, _] = self.frame.dims;
        let (lo, hi) = self.grid.bounds(b);
        let as_vec = |v: [usize; 3]| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
        let (box_lo, box_hi) = (as_vec(lo), as_vec(hi));
        let last = hi.map(|h| h - 1);
        let max = self.max();
        let lighting = lighting.as_ref().map(|(phong, light)| (*phong, light));
        let mut any = false;
        for (k, o) in ks.zip(out) {
            if let Some(m) = mask {
                let p = walk.start64 + walk.delta64 * (k - walk.first) as f64;
                if m.skips(p) {
                    continue;
                }
            }
            let p = walk.position(k, max).clamp(box_lo, box_hi);
            let (c, offsets) = cell_of(p, last);
            let base = c[0] + nx * (c[1] + ny * c[2]);
            let [gx, gy, gz, f] =
                interpolate(corners(|i| voxels[i], base, nx, nx * ny), offsets).to_array();
            if values.contains(f) {
                continue;
            }
            let g = [gx, gy, gz];
            let alpha = if classifier.uses_gradient() {
                classifier.opacity_at(f, g)
            } else {
                classifier.sample_opacity(f)
            };
            if alpha == 0.0 {
                continue;
            }
            let [r, g, b] = lit_colour(lighting, Vec3::from(g), classifier.material(f));
            *o = f32x4::new([r, g, b, alpha]);
            any = true;
        }
        any
    }
}

/// A pre-classified volume's lit bricks held for one tile: each brick of
/// the tile's list lit (or found lit) when a ray of the tile first needs
/// it, then read by every ray of the tile under one lock, as the bricked
/// caster reads each brick once per tile (asking the cache per ray and
/// brick costs a lock and an atomic update each, which two threads then
/// contend for).
struct Held<'t> {
    source: Option<(&'t LitBricks, &'t Lighting<'t>)>,
    /// The list's bricks `(n, position in the list)`, by `n`.
    order: Vec<(u32, u32)>,
    /// Per position in the list: the brick, once needed.
    refs: Vec<Option<CacheRef<'t, [[f32; 4]; SLOTS]>>>,
    /// Per position in the list: the buffer it is lit into when the cache
    /// has no room.
    slots: Vec<Option<&'t mut Scratch>>,
}

impl<'t> Held<'t> {
    /// The bricks of `list` of a volume whose lit bricks are `source`
    /// (`None`: post-classified, nothing to hold), lit into `store` when
    /// the cache is full.
    fn new(
        source: Option<(&'t LitBricks, &'t Lighting<'t>)>,
        list: &[u32],
        store: &'t mut [Scratch],
    ) -> Self {
        let mut order: Vec<(u32, u32)> = (list.iter().enumerate())
            .map(|(j, &n)| (n, j as u32))
            .collect();
        order.sort_unstable();
        Held {
            source,
            order,
            refs: list.iter().map(|_| None).collect(),
            slots: store.iter_mut().map(Some).collect(),
        }
    }

    /// Occupied brick `n`'s lit voxels, if the tile's list holds it.
    fn get(&mut self, n: usize) -> Option<&[[f32; 4]; SLOTS]> {
        let (lit, lighting) = self.source?;
        let at = (self.order)
            .binary_search_by_key(&(n as u32), |&(m, _)| m)
            .ok()?;
        let j = self.order[at].1 as usize;
        if self.refs[j].is_none() {
            let scratch = self.slots[j].take().expect("each brick is lit once a tile");
            self.refs[j] = Some(lit.get(n, lighting, scratch));
        }
        self.refs[j].as_deref()
    }
}

/// Lit voxels held for the tile, or read from the cache for one run.
enum CacheOr<'a, 'c> {
    Held(&'a [[f32; 4]; SLOTS]),
    Cache(CacheRef<'c, [[f32; 4]; SLOTS]>),
}

impl CacheOr<'_, '_> {
    #[inline(always)]
    fn at(&self, i: usize) -> [f32; 4] {
        match self {
            CacheOr::Held(slots) => slots[i],
            CacheOr::Cache(slots) => slots[i],
        }
    }
}

/// One tile's rays: the volumes, their tile lists, and the buffers the
/// rays reuse.
struct Rays<'a, 'l, 't> {
    layers: &'a [Layer<'l>],
    /// Per volume: the tile's list of bricks.
    lists: Vec<&'a [u32]>,
    /// Per volume: its lit bricks held for the tile.
    held: Vec<Held<'t>>,
    /// Per volume: its samples of the chunk being mixed.
    chunks: Vec<[f32x4; CHUNK]>,
    walks: Vec<Walk>,
    /// Per volume: where the ray is in its tile list, and the next range
    /// of samples it has in a listed brick.
    cursors: Vec<usize>,
    heads: Vec<Option<(i64, i64)>>,
}

impl Rays<'_, '_, '_> {
    /// The ray's next range of samples in a brick of volume `i`'s list.
    #[inline]
    fn next_hit(&mut self, i: usize) -> Option<(i64, i64)> {
        let list = self.lists[i];
        while let Some(&n) = list.get(self.cursors[i]) {
            self.cursors[i] += 1;
            if let Some(hit) = self.layers[i].interval(&self.walks[i], n) {
                return Some(hit);
            }
        }
        None
    }

    /// Composites the samples of `ray` (whose world ray is `origin +
    /// t·direction`): the ranges in the listed bricks of any volume, a
    /// chunk at a time, each volume filling its samples, mixed.
    fn cast(&mut self, ray: &PixelSamples, origin: DVec3, direction: DVec3) -> FrontToBack {
        let first_point = origin + ray.t(ray.first) * direction;
        let tolerance = 1e-6 * ray.step;
        self.walks.clear();
        self.walks.extend(self.layers.iter().map(|layer| {
            let g = &layer.frame;
            let start64 = (first_point - g.origin) / g.spacing;
            let delta64 = ray.step * direction / g.spacing;
            // The samples in the volume's box.
            let range = g.span(origin, direction).map_or(0..0, |(t0, t1)| {
                let a = ((t0 - tolerance) / ray.step - ray.offset).ceil() as i64;
                let b = ((t1 + tolerance) / ray.step - ray.offset).floor() as i64;
                a.max(ray.first)..b.min(ray.last) + 1
            });
            Walk {
                start: start64.as_vec3(),
                delta: delta64.as_vec3(),
                start64,
                delta64,
                inv64: delta64.recip(),
                first: ray.first,
                range,
            }
        }));
        // Each volume's listed bricks in the order the ray meets them
        // (the lists are front to back, see `cpu/tiles.rs`), read only as
        // far as the ray goes: a ray stopped by the first surface tests no
        // brick behind it.
        self.heads.clear();
        self.cursors.clear();
        for i in 0..self.layers.len() {
            self.cursors.push(0);
            let head = self.next_hit(i);
            self.heads.push(head);
        }
        let mut acc = FrontToBack::NEW;
        let mut done = ray.first;
        // The nearest range of any volume, joined with every range that
        // overlaps or adjoins it.
        while let Some(i) = (0..self.heads.len())
            .filter(|&i| self.heads[i].is_some())
            .min_by_key(|&i| self.heads[i].map(|(a, _)| a))
        {
            let (a, mut b) = self.heads[i].expect("a head");
            let mut mask = 1u64 << i;
            self.heads[i] = self.next_hit(i);
            loop {
                let join =
                    (0..self.heads.len()).find(|&i| self.heads[i].is_some_and(|(a, _)| a <= b + 1));
                let Some(i) = join else { break };
                b = b.max(self.heads[i].expect("a head").1);
                mask |= 1 << i;
                self.heads[i] = self.next_hit(i);
            }
            let a = a.max(done);
            if a > b {
                continue;
            }
            done = b + 1;
            let mut k = a;
            // Chunks from FIRST_CHUNK samples, doubling to CHUNK: a ray
            // that meets an opaque surface stops after a few samples, and
            // a chunk's samples past that point are wasted work.
            let mut length = FIRST_CHUNK;
            while k <= b {
                let end = (k + length as i64).min(b + 1);
                length = (2 * length).min(CHUNK);
                let mut any = 0u64;
                for (i, layer) in self.layers.iter().enumerate() {
                    if mask & (1 << i) != 0
                        && layer.fill(
                            &self.walks[i],
                            k..end,
                            &mut self.chunks[i],
                            &mut self.held[i],
                        )
                    {
                        any |= 1 << i;
                    }
                }
                if any != 0 {
                    for s in 0..(end - k) as usize {
                        let mut mixer = Mixer::NEW;
                        for (i, chunk) in self.chunks.iter().enumerate() {
                            if any & (1 << i) != 0 {
                                mixer.add(chunk[s]);
                            }
                        }
                        if let Some(sample) = mixer.sample() {
                            acc.add(sample);
                            if acc.is_opaque() {
                                return acc;
                            }
                        }
                    }
                }
                k = end;
            }
        }
        acc
    }
}

/// Renders `layers` (each volume shown, with its settings) mixed, as the
/// frame's settings `shared` say, into a partial image.
pub(super) fn render(
    layers: &[(&Renderer, &RenderSettings)],
    frame: &SceneFrame,
    shared: &RenderSettings,
    progress: &Progress,
) -> PartialImage {
    let view = &frame.view;
    let pre = shared.classification == Classification::Pre;
    let classifiers: Vec<Classifier> = layers.iter().map(|(r, s)| r.classifier(s)).collect();
    let lights: Vec<LightGeometry> = (layers.iter())
        .map(|(_, s)| Renderer::light(s, view))
        .collect();
    // Pre-classified: each volume's kept bricks, locked for the frame.
    let mut states: Vec<Option<MutexGuard<Option<FastState>>>> = (layers.iter())
        .zip(&classifiers)
        .map(|((r, _), c)| pre.then(|| r.fast_state(c.clone())))
        .collect();
    let numbers: Vec<u64> = (states.iter_mut())
        .map(|s| s.as_mut().map_or(0, |g| state_mut(g).lit.next_frame(&[])))
        .collect();
    let masks: Vec<_> = layers.iter().map(|(r, _)| r.masked()).collect();
    let sampling = &frame.sampling;
    let built: Vec<Layer> = (0..layers.len())
        .map(|i| {
            let (renderer, settings) = layers[i];
            let volume = renderer.volume();
            let grid = BrickGrid::new(volume.dims());
            let layer_frame = GridFrame::of(volume);
            // The frame's samples, in this volume's grid, for binning.
            let own = Sampling {
                grid: layer_frame,
                ..sampling.clone()
            };
            let lighting = settings.shading.then_some((&settings.phong, lights[i]));
            let (kind, bins, boxes) = match &states[i] {
                Some(guard) => {
                    let state = guard.as_ref().expect("the state was made");
                    let bricks = &state.bricks;
                    let source = Source {
                        volume,
                        classifier: &state.classifier,
                        masked: &masks[i],
                    };
                    let mut occupied = vec![0u32; grid.len()];
                    for (n, b) in bricks.bricks().enumerate() {
                        occupied[grid.index(b)] = n as u32 + 1;
                    }
                    let kind = Kind::Pre {
                        bricks,
                        lit: &state.lit,
                        lighting: Box::new(Lighting::new(
                            source,
                            bricks,
                            numbers[i],
                            lighting.as_ref().map(|(p, l)| (*p, l)),
                            None,
                        )),
                        occupied,
                    };
                    let bins = TileBins::new(bricks, &own, view);
                    let boxes = (0..bricks.len()).map(|n| bricks.occupied_box(n)).collect();
                    (kind, bins, boxes)
                }
                None => {
                    let macrocells = renderer.macrocells();
                    let classifier = &classifiers[i];
                    let transparent = transparent_bricks(macrocells, classifier);
                    let visible: Vec<[usize; 3]> = (0..grid.len())
                        .filter(|&b| !transparent[b])
                        .map(|b| grid.coords(b))
                        .collect();
                    let bins = TileBins::of_boxes(
                        visible.len(),
                        |n| visible[n],
                        |n| grid.bounds(visible[n]),
                        &own,
                        view,
                    );
                    let boxes = visible.iter().map(|&b| grid.bounds(b)).collect();
                    let kind = Kind::Post {
                        voxels: renderer.packed_voxels(),
                        transparent,
                        values: TransparentValues::new(classifier, renderer.value_range()),
                        classifier,
                        lighting,
                        mask: renderer.non_finite(),
                    };
                    (kind, bins, boxes)
                }
            };
            Layer {
                frame: layer_frame,
                grid,
                kind,
                bins,
                boxes,
            }
        })
        .collect();
    assert!(built.len() <= 64, "a layer mask holds 64 volumes");

    let (width, height) = (view.width(), view.height());
    let mut image = PartialImage::composite(width, height);
    let PartialPixels::Composite(pixels) = image.pixels_mut() else {
        unreachable!("a composite image")
    };
    // Each tile's rows, as slices of the image rows (as the bricked
    // caster's): independent pieces of work.
    let (tiles_x, tiles_y) = (width.div_ceil(TILE), height.div_ceil(TILE));
    let mut tiles: Vec<Vec<&mut [PartialPixel]>> = (0..tiles_x * tiles_y)
        .map(|_| Vec::with_capacity(TILE))
        .collect();
    for (row, pixels) in pixels.chunks_mut(width).enumerate() {
        for (tx, segment) in pixels.chunks_mut(TILE).enumerate() {
            tiles[(row / TILE) * tiles_x + tx].push(segment);
        }
    }
    tiles.into_par_iter().enumerate().for_each(|(t, mut rows)| {
        if progress.stopped() {
            return;
        }
        let (tx, ty) = (t % tiles_x, t / tiles_x);
        let lists: Vec<&[u32]> = built.iter().map(|l| l.bins.list(tx, ty)).collect();
        let done = rows.iter().map(|r| r.len()).sum();
        if lists.iter().all(|l| l.is_empty()) {
            // No volume has anything here.
            for row in rows.iter_mut() {
                row.fill(EMPTY);
            }
            progress.done(done);
            return;
        }
        let mut store: Vec<Vec<Scratch>> = (lists.iter())
            .map(|l| l.iter().map(|_| None).collect())
            .collect();
        let held = (built.iter().zip(&lists).zip(store.iter_mut()))
            .map(|((layer, list), store)| {
                let source = match &layer.kind {
                    Kind::Pre { lit, lighting, .. } => Some((*lit, &**lighting)),
                    Kind::Post { .. } => None,
                };
                Held::new(source, list, store)
            })
            .collect();
        let mut rays = Rays {
            layers: &built,
            lists,
            held,
            chunks: vec![[f32x4::ZERO; CHUNK]; built.len()],
            walks: Vec::with_capacity(built.len()),
            cursors: Vec::with_capacity(built.len()),
            heads: Vec::with_capacity(built.len()),
        };
        for (r, row) in rows.iter_mut().enumerate() {
            for (c, pixel) in row.iter_mut().enumerate() {
                let (col, row) = (tx * TILE + c, ty * TILE + r);
                let (origin, direction) = view.pixel_ray(col, row);
                *pixel = match sampling.ray(col, row, origin, direction) {
                    Some(ray) => rays.cast(&ray, origin, direction).partial(),
                    None => EMPTY,
                };
            }
        }
        progress.done(done);
    });

    let lit: Vec<usize> = (built.iter())
        .map(|l| match &l.kind {
            Kind::Pre { lighting, .. } => lighting.count(),
            Kind::Post { .. } => 0,
        })
        .collect();
    drop(built);
    for (state, lit) in states.iter_mut().zip(lit) {
        if let Some(guard) = state {
            state_mut(guard).lit.end_frame(lit);
        }
    }
    image
}

/// The fast state a guard holds (made by [`Renderer::fast_state`]).
fn state_mut<'a>(guard: &'a mut MutexGuard<Option<FastState>>) -> &'a mut FastState {
    guard.as_mut().expect("the state was made")
}
