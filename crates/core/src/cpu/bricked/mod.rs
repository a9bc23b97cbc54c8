//! The fast path's stage 2: the reference's samples, composited front to
//! back, visiting only the occupied cells, in parallel over image tiles,
//! for orthographic and perspective views.
//!
//! For each pixel the ray walks its tile's list of occupied bricks (see
//! [`crate::cpu::tiles`]) front to back. In each brick it finds the samples `k`
//! (the same as the reference's, see [`crate::sampling`]: `t = k·step`
//! from the image plane for parallel rays, from the eye in perspective)
//! whose positions lie in the box of the brick's occupied cells, and for
//! each sample in an occupied cell it interpolates the brick's lit voxels
//! (see [`crate::cpu::lit_bricks`]) trilinearly and composites. Everything
//! else contributes exactly nothing: a sample outside these boxes, or in a
//! cell whose eight corners are transparent, has opacity 0. A sample on a
//! face shared by two bricks is taken once, by the first.
//!
//! **Rays.** Parallel rays share one index-space step between samples and
//! start on the image plane. Perspective rays each have their own step
//! (along the pixel's direction from the eye, as [`View::pixel_ray`] gives
//! it) and take only the samples ahead of the eye (`t ≥ 0`, as the
//! reference). Positions are `f32`; so that an eye far from the volume
//! costs no precision, a perspective ray counts its samples from a base
//! sample near the volume's centre (its `t = 0` point is moved there).
//! The parallel rays' code is the same code with the shared step
//! (monomorphised: it pays nothing for the per-ray case).
//!
//! With a crop box or clip planes, or jitter, the samples are still the
//! reference's ([`crate::sampling`]): each ray's exact range of samples
//! `k` (inside the grid, the crop box and the clip planes) bounds what it
//! takes in every brick, and a jittered ray's `t = 0` point is moved by
//! its offset, so that its `k`-th sample is at `t = (k + u)·step`. The
//! exact range is found once per ray, when first needed: in a brick on
//! the volume's boundary, or in any brick when something is cut away.
//!
//! The ray stops once its transmittance is below
//! [`TERMINATION_TRANSMITTANCE`](crate::kernels::composite::TERMINATION_TRANSMITTANCE): colours are in [0, 1], so what lies
//! behind could change the pixel by at most that much, well under 1/255.
//! Each pixel is computed from its own ray alone, by the same arithmetic
//! whatever thread runs it, so the image is bit-identical for any thread
//! count.
//!
//! SIMD: positions and colours are `f32x4` (x, y, z or r, g, b, α in the
//! lanes); the eight corners of a cell are eight 16-byte loads.

use crate::bricks::cache::CacheRef;
use crate::bricks::occupied::ClassifiedBricks;
use crate::bricks::{BRICK, BrickGrid, SIDE, SLOTS, cell, slot};
use crate::camera::View;
use crate::cpu::lit_bricks::{Lighting, LitBricks};
use crate::cpu::tiles::{TILE, TileBins};
use crate::frame::progress::Progress;
use crate::kernels::composite::{Finish, FrontToBack, PartialPixel};
use crate::kernels::trilinear::{corners, interpolate};
use crate::sampling::Sampling;
use crate::sampling::jitter;
use glam::{DVec3, Vec4};
use rayon::prelude::*;
use wide::f32x4;

/// Bytes one tile takes while a frame is cast (its rows of pixels).
pub(crate) const FRAME_BYTES_PER_TILE: usize =
    size_of::<Vec<&mut [PartialPixel]>>() + TILE * size_of::<&mut [PartialPixel]>();

/// Slack, in samples, around each box's range of samples: a sample on a
/// box face is found whatever the rounding (it is clamped into the box, so
/// at most this far from where it belongs).
const SAMPLE_SLACK: f32 = 1e-3;
/// Slack, in voxels, for rays parallel to a box face.
const PARALLEL_SLACK: f32 = 1e-4;

/// The box of an occupied brick's occupied cells, in index space.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CellBox {
    /// The brick's first voxel.
    origin: f32x4,
    /// The box relative to `origin`.
    lo: f32x4,
    hi: f32x4,
    /// Whether a face of the brick is on the volume's boundary, where the
    /// samples must also be inside the ray's exact range.
    boundary: bool,
}

/// One frame's rays, in the index space of the grid.
struct Rays<'a> {
    sampling: &'a Sampling,
    view: &'a View,
    /// Whether every brick, not just the boundary ones, needs the rays'
    /// exact ranges (something is cut away).
    clipped: bool,
    geometry: Geometry,
}

/// Where the rays start and which way they run.
enum Geometry {
    /// Orthographic: parallel rays from the image plane.
    Parallel {
        /// Index-space point on the image plane (`t = 0`) of pixel (0, 0),
        /// and its change per column and per row.
        corner: DVec3,
        per_col: DVec3,
        per_row: DVec3,
        /// Every ray's step from one sample to the next.
        stepping: Stepping,
        /// The same in `f64`, for the jitter.
        delta: DVec3,
    },
    /// Perspective: rays from the eye, each with its own step.
    FromEye {
        /// The centre of the grid, in world units: each ray counts its
        /// samples from the one nearest to where it passes the centre.
        centre: DVec3,
    },
}

/// How one ray steps from sample to sample, in index space.
#[derive(Debug, Clone, Copy)]
struct Stepping {
    /// Index-space displacement from one sample to the next.
    delta: f32x4,
    /// `1/delta` per axis, 0 where `delta` is 0 (lane 3: 0).
    inv_delta: f32x4,
    /// All bits set in the lanes of the axes the ray is parallel to, and
    /// in lane 3.
    parallel: f32x4,
    /// The reference's number of this ray's sample 0: sample numbers here
    /// are counted from it.
    base: i64,
}

impl Stepping {
    const EMPTY: Stepping = Stepping {
        delta: f32x4::ZERO,
        inv_delta: f32x4::ZERO,
        parallel: f32x4::ZERO,
        base: 0,
    };

    fn new(delta: DVec3, base: i64) -> Self {
        let delta = delta.as_vec3();
        let inv = |d: f32| if d == 0.0 { 0.0 } else { 1.0 / d };
        let mask = |d: f32| if d == 0.0 { f32::from_bits(!0) } else { 0.0 };
        Stepping {
            delta: f32x4::new([delta.x, delta.y, delta.z, 0.0]),
            inv_delta: f32x4::new([inv(delta.x), inv(delta.y), inv(delta.z), 0.0]),
            parallel: f32x4::new([mask(delta.x), mask(delta.y), mask(delta.z), mask(0.0)]),
            base,
        }
    }

    /// The samples `k` whose positions `local + k·delta` (relative to the
    /// brick's origin) lie in box `b` (with [`SAMPLE_SLACK`]), or `None`.
    #[inline]
    fn samples_in(&self, b: &CellBox, local: f32x4) -> Option<(i32, i32)> {
        let to_lo = b.lo - local;
        let to_hi = b.hi - local;
        let (near, far) = (to_lo * self.inv_delta, to_hi * self.inv_delta);
        // Along a parallel axis the ray is inside the slab everywhere or
        // nowhere.
        let slack = f32x4::splat(PARALLEL_SLACK);
        let inside = to_lo.simd_le(slack) & to_hi.simd_ge(-slack);
        let inf = f32x4::splat(f32::INFINITY);
        let enter = self
            .parallel
            .select(inside.select(-inf, inf), near.fast_min(far));
        let leave = self.parallel.select(inf, near.fast_max(far));
        // Lane 3 is neutral (−∞, +∞): the box is the three slabs' overlap.
        let lo = Vec4::from_array(enter.to_array()).max_element();
        let hi = Vec4::from_array(leave.to_array()).min_element();
        // A miss along a parallel axis enters at +∞; rays are not parallel
        // to all three axes, so a hit is finite.
        if lo > hi {
            return None;
        }
        let first = ceil_i32(lo - SAMPLE_SLACK);
        let last = floor_i32(hi + SAMPLE_SLACK);
        (first <= last).then_some((first, last))
    }
}

/// The steppings of a tile's rays: one for all (parallel rays) or one per
/// ray (perspective), ray `i` in row-major order within the tile.
trait Steppings {
    fn of(&self, i: usize) -> &Stepping;
}

/// One stepping for every ray.
struct Shared(Stepping);

impl Steppings for Shared {
    #[inline]
    fn of(&self, _: usize) -> &Stepping {
        &self.0
    }
}

impl Steppings for [Stepping] {
    #[inline]
    fn of(&self, i: usize) -> &Stepping {
        &self[i]
    }
}

/// What a tile's rays read in the bricks of its list: one volume's lit
/// bricks ([`One`]), or several volumes' on one grid
/// ([`crate::scene`]'s channels, `Channels` in `scene/channels.rs`). The
/// caster is the same code for both (monomorphised), so one volume's
/// frames are exactly what they were before there were several.
pub(crate) trait BrickSource: Sync {
    /// What a ray accumulates: one compositor ([`FrontToBack`]), or one
    /// per volume (the additive mix).
    type Acc: Accumulator;
    /// A brick's voxels, lit for the frame, as [`Self::march`] reads them.
    type Lit<'l>
    where
        Self: 'l;
    /// Where bricks are lit when the lit-brick caches have no room.
    type Scratch: Default;
    /// The box of list entry `n`'s occupied cells.
    fn cell_box(&self, n: usize) -> CellBox;
    /// List entry `n`'s voxels, lit now unless they are.
    fn light<'l>(&'l self, n: usize, scratch: &'l mut Self::Scratch) -> Self::Lit<'l>;
    /// Composites `segment`'s samples in list entry `n` into `acc`;
    /// returns whether the ray has terminated.
    fn march<'l>(
        &'l self,
        acc: &mut Self::Acc,
        lit: &Self::Lit<'l>,
        n: usize,
        segment: &Segment,
    ) -> bool;
    /// A tile is done with list entry `n`.
    fn done(&self, n: usize);
}

/// What a ray carries from brick to brick: its compositing so far.
pub(crate) trait Accumulator: Copy + Send {
    /// Nothing composited yet.
    const NEW: Self;
    /// The ray's partial pixel.
    fn partial(&self) -> PartialPixel;
}

impl Accumulator for FrontToBack {
    const NEW: Self = FrontToBack::NEW;

    #[inline]
    fn partial(&self) -> PartialPixel {
        FrontToBack::partial(self)
    }
}

/// One volume's occupied bricks, lit into `lit` by `lighting`.
struct One<'a> {
    bricks: &'a ClassifiedBricks,
    lit: &'a LitBricks,
    lighting: &'a Lighting<'a>,
}

impl BrickSource for One<'_> {
    type Acc = FrontToBack;
    type Lit<'l>
        = CacheRef<'l, [[f32; 4]; SLOTS]>
    where
        Self: 'l;
    type Scratch = Option<Box<[[f32; 4]; SLOTS]>>;

    #[inline]
    fn cell_box(&self, n: usize) -> CellBox {
        cell_box(self.bricks, n)
    }

    #[inline]
    fn light<'l>(&'l self, n: usize, scratch: &'l mut Self::Scratch) -> Self::Lit<'l> {
        self.lit.get(n, self.lighting, scratch)
    }

    #[inline]
    fn march<'l>(
        &'l self,
        acc: &mut FrontToBack,
        lit: &Self::Lit<'l>,
        n: usize,
        segment: &Segment,
    ) -> bool {
        march(acc, lit, &self.bricks.cells[n], segment)
    }

    #[inline]
    fn done(&self, n: usize) {
        self.lit.done(n)
    }
}

/// Renders the occupied bricks of `bricks`, lit into `lit` by `lighting`
/// as the rays reach them (see [`crate::cpu::lit_bricks`]), binned into
/// `bins`, through `view` (either projection) with samples where
/// `sampling` says, into `pixels` (the view's, row-major), each ray's
/// partial pixel or the finished one as `finish` says. `progress` is
/// called with the number of pixels finished, a tile at a time.
#[allow(clippy::too_many_arguments)]
pub fn render(
    bricks: &ClassifiedBricks,
    lit: &LitBricks,
    lighting: &Lighting,
    bins: &TileBins,
    sampling: &Sampling,
    view: &View,
    pixels: &mut [PartialPixel],
    finish: Finish,
    progress: &Progress,
) {
    let one = One {
        bricks,
        lit,
        lighting,
    };
    render_source(&one, bins, sampling, view, pixels, finish, progress);
}

/// Renders the bricks of `source`, binned into `bins` (whose lists hold
/// the source's entries), through `view` with samples where `sampling`
/// says, into `pixels`, as [`render`] does.
pub(crate) fn render_source<S: BrickSource>(
    source: &S,
    bins: &TileBins,
    sampling: &Sampling,
    view: &View,
    pixels: &mut [PartialPixel],
    finish: Finish,
    progress: &Progress,
) {
    let width = view.width();
    assert_eq!(pixels.len(), width * view.height());
    let rays = Rays::new(sampling, view);
    // Each tile's rows, as slices of the image rows: the tiles are then
    // independent pieces of work, small enough to balance the threads.
    let mut tiles: Vec<Vec<&mut [PartialPixel]>> = (0..bins.tiles_x * bins.tiles_y)
        .map(|_| Vec::with_capacity(TILE))
        .collect();
    for (row, pixels) in pixels.chunks_mut(width).enumerate() {
        for (tx, segment) in pixels.chunks_mut(TILE).enumerate() {
            tiles[(row / TILE) * bins.tiles_x + tx].push(segment);
        }
    }
    tiles.into_par_iter().enumerate().for_each(|(t, mut rows)| {
        if progress.stopped() {
            return;
        }
        let (tx, ty) = (t % bins.tiles_x, t / bins.tiles_x);
        rays.tile(
            source,
            bins.list(tx, ty),
            (tx, ty),
            finish,
            &mut rows,
            progress,
        );
        progress.done(rows.iter().map(|r| r.len()).sum());
    });
}

/// Index-space coordinates as SIMD lanes (the last one 0).
fn lanes(v: [usize; 3]) -> f32x4 {
    f32x4::new([v[0] as f32, v[1] as f32, v[2] as f32, 0.0])
}

fn to_lanes(v: DVec3) -> f32x4 {
    f32x4::new([v.x as f32, v.y as f32, v.z as f32, 0.0])
}

fn cell_box(bricks: &ClassifiedBricks, n: usize) -> CellBox {
    CellBox::new(&bricks.grid, bricks.brick(n), bricks.occupied_box(n))
}

impl CellBox {
    /// The index-space box `cells` of occupied cells in brick `b` of `grid`.
    pub(crate) fn new(grid: &BrickGrid, b: [usize; 3], (lo, hi): ([usize; 3], [usize; 3])) -> Self {
        let origin = lanes(grid.origin(b));
        CellBox {
            origin,
            lo: lanes(lo) - origin,
            hi: lanes(hi) - origin,
            boundary: grid.touches_boundary(b),
        }
    }
}

/// A sample number counted from a ray's base, as the `i32` the ray caster
/// counts in (a ray has at most `renderer::MAX_SAMPLES_PER_RAY`
/// samples in the grid, and its base is near them).
fn relative(k: i64, base: i64) -> i32 {
    (k.saturating_sub(base)).clamp(i32::MIN as i64, i32::MAX as i64) as i32
}

impl<'a> Rays<'a> {
    fn new(sampling: &'a Sampling, view: &'a View) -> Self {
        let grid = &sampling.grid;
        let geometry = match view {
            View::Orthographic(v) => {
                let to_index = |world: DVec3| (world - grid.origin) / grid.spacing;
                let delta = v.direction * sampling.step / grid.spacing;
                Geometry::Parallel {
                    corner: to_index(v.pixel_centre(0, 0)),
                    per_col: v.right * v.pixel_size / grid.spacing,
                    per_row: -v.up * v.pixel_size / grid.spacing,
                    stepping: Stepping::new(delta, 0),
                    delta,
                }
            }
            View::Perspective(_) => {
                let extent = DVec3::new(
                    (grid.dims[0] - 1) as f64,
                    (grid.dims[1] - 1) as f64,
                    (grid.dims[2] - 1) as f64,
                ) * grid.spacing;
                Geometry::FromEye {
                    centre: grid.origin + 0.5 * extent,
                }
            }
        };
        Rays {
            sampling,
            view,
            // A piece's rays are cut to what it owns: every brick takes
            // each ray's exact range.
            clipped: sampling.clipping.is_active() || sampling.ownership.is_some(),
            geometry,
        }
    }

    /// Renders tile (`tx`, `ty`), whose bricks are `list`, into `rows`
    /// (its rows of pixels, top to bottom), as `finish` says.
    fn tile<B: BrickSource>(
        &self,
        scene: &B,
        list: &[u32],
        (tx, ty): (usize, usize),
        finish: Finish,
        rows: &mut [&mut [PartialPixel]],
        progress: &Progress,
    ) {
        let cols = tx * TILE..tx * TILE + rows[0].len();
        let count = cols.len() * rows.len();
        let pixel = |i: usize| (cols.start + i % cols.len(), ty * TILE + i / cols.len());
        let mut states = [RayState::<B::Acc>::EMPTY; TILE * TILE];
        let states = &mut states[..count];
        match self.geometry {
            Geometry::Parallel {
                corner,
                per_col,
                per_row,
                stepping,
                delta,
            } => {
                if !list.is_empty() {
                    for (i, state) in states.iter_mut().enumerate() {
                        let (col, row) = pixel(i);
                        let mut o = corner + per_col * col as f64 + per_row * row as f64;
                        if self.sampling.jitter {
                            // Sample k at t = (k + u)·step: move the t = 0 point.
                            o += jitter::offset(col, row) * delta;
                        }
                        state.origin = to_lanes(o);
                    }
                }
                self.cast(scene, list, &pixel, states, &Shared(stepping), progress);
            }
            Geometry::FromEye { centre } => {
                let mut steppings = [Stepping::EMPTY; TILE * TILE];
                let steppings = &mut steppings[..count];
                if !list.is_empty() {
                    for (i, (state, stepping)) in
                        states.iter_mut().zip(steppings.iter_mut()).enumerate()
                    {
                        let (col, row) = pixel(i);
                        (*state, *stepping) = self.ray_from_eye(col, row, centre);
                    }
                }
                self.cast(scene, list, &pixel, states, &*steppings, progress);
            }
        }
        for (i, state) in states.iter().enumerate() {
            let (c, r) = (i % cols.len(), i / cols.len());
            rows[r][c] = finish.apply(state.acc.partial());
        }
    }

    /// The start and the stepping of pixel (`col`, `row`)'s perspective ray:
    /// the reference's ray ([`View::pixel_ray`]), its samples counted from
    /// the one nearest to where the ray passes `centre`, and none behind
    /// the eye.
    fn ray_from_eye<A: Accumulator>(
        &self,
        col: usize,
        row: usize,
        centre: DVec3,
    ) -> (RayState<A>, Stepping) {
        let (grid, step) = (&self.sampling.grid, self.sampling.step);
        let (eye, direction) = self.view.pixel_ray(col, row);
        let offset = if self.sampling.jitter {
            jitter::offset(col, row)
        } else {
            0.0
        };
        let base = ((centre - eye).dot(direction).max(0.0) / step).floor() as i64;
        let delta = direction * step / grid.spacing;
        let origin = (eye - grid.origin) / grid.spacing + (base as f64 + offset) * delta;
        // The first sample at t ≥ 0, exactly as `Sampling::ray` finds it
        // for a ray whose interval starts at the eye.
        let tolerance = 1e-6 * step;
        let first = ((0.0 - tolerance) / step - offset).ceil() as i64;
        let state = RayState {
            origin: to_lanes(origin),
            next: relative(first, base),
            ..RayState::EMPTY
        };
        (state, Stepping::new(delta, base))
    }

    /// Casts the rays of one tile, whose bricks are `list`, from their
    /// `states` (ray `i` is pixel `pixel(i)`, stepping `steppings.of(i)`).
    ///
    /// Brick by brick, every ray of the tile crosses the brick before the
    /// next brick is touched: the brick's voxels are loaded into the cache
    /// once for all the tile's rays. Each ray still takes its bricks front
    /// to back, so its arithmetic is that of a ray cast on its own.
    ///
    /// A stopped frame ends its tiles between bricks: at a small step a
    /// tile is long work (at step 0.01 a ray of a 512³ volume has some
    /// 50,000 samples, a 16² tile 13 million), and checking only between
    /// tiles let a newer frame wait for it. Between bricks a tile's rays
    /// have crossed one brick each (at most 9·√3/0.01 ≈ 1,600 samples a
    /// ray there); the check is one relaxed load a brick. The stopped
    /// tile's pixels are partial, and the frame is answered `Stopped`,
    /// never shown.
    fn cast<B: BrickSource, S: Steppings + ?Sized>(
        &self,
        scene: &B,
        list: &[u32],
        pixel: &impl Fn(usize) -> (usize, usize),
        states: &mut [RayState<B::Acc>],
        steppings: &S,
        progress: &Progress,
    ) {
        // Where a brick the lit-brick cache has no room for is lit.
        let mut scratch = B::Scratch::default();
        let mut live = states.iter().filter(|s| !s.done).count();
        let mut reached = 0;
        for &n in list {
            // Once every ray of the tile has terminated, the bricks behind
            // are hidden: neither lit nor classified. (A dense CT seen at
            // 1024² hides most of its bricks behind the skin: lighting
            // every brick of the list took 2.8 s of a 512³ frame.)
            if live == 0 || progress.stopped() {
                break;
            }
            reached += 1;
            // The brick's box, computed per tile rather than kept per
            // frame (64 bytes an occupied brick): a few operations for the
            // tile's 256 rays.
            let b = &scene.cell_box(n as usize);
            live -= self.cross(b, scene, n as usize, &mut scratch, pixel, states, steppings);
        }
        // The tile is done with the bricks it reached: the lit-brick cache
        // gives a brick's buffer back after its last tile (see
        // `LitBricks`: the bricks behind are not counted down).
        for &n in &list[..reached] {
            scene.done(n as usize);
        }
    }

    /// Takes the samples of every ray of a tile (`states`, as in
    /// [`Self::cast`]) in one brick: its box `b`, its occupied `cells` and
    /// its voxels, which `light` lights when the first ray has samples in
    /// the brick (a brick that no live ray samples is never lit). Returns
    /// how many rays ended here.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn cross<'l, B: BrickSource, S: Steppings + ?Sized>(
        &self,
        b: &CellBox,
        scene: &'l B,
        n: usize,
        scratch: &'l mut B::Scratch,
        pixel: &impl Fn(usize) -> (usize, usize),
        states: &mut [RayState<B::Acc>],
        steppings: &S,
    ) -> usize {
        let mut scratch = Some(scratch);
        let mut lit: Option<B::Lit<'l>> = None;
        let mut ended = 0;
        for (i, state) in states.iter_mut().enumerate() {
            if state.done {
                continue;
            }
            let stepping = steppings.of(i);
            let local = state.origin - b.origin;
            let Some((first, mut last)) = stepping.samples_in(b, local) else {
                continue;
            };
            let mut first = first.max(state.next);
            if b.boundary || self.clipped {
                let range = *state.exact.get_or_insert_with(|| {
                    let (col, row) = pixel(i);
                    let base = stepping.base;
                    (self.sampling.pixel(self.view, col, row))
                        .map(|r| (relative(r.first, base), relative(r.last, base)))
                });
                let Some((f, l)) = range else {
                    // The ray misses the volume: it has no samples.
                    state.done = true;
                    ended += 1;
                    continue;
                };
                (first, last) = (first.max(f), last.min(l));
            }
            if first > last {
                continue;
            }
            state.next = last + 1;
            let segment = Segment {
                origin: local,
                delta: stepping.delta,
                lo: b.lo,
                hi: b.hi,
                first,
                last,
            };
            let lit = lit.get_or_insert_with(|| {
                scene.light(n, scratch.take().expect("a brick is lit once a tile"))
            });
            state.done = scene.march(&mut state.acc, lit, n, &segment);
            ended += usize::from(state.done);
        }
        ended
    }
}

/// Where one ray crosses one brick's box of occupied cells.
pub(crate) struct Segment {
    /// The ray's `t = 0` point and its step, relative to the brick's first
    /// voxel (lane 3 unused).
    pub origin: f32x4,
    pub delta: f32x4,
    /// The box, relative to the brick's first voxel.
    pub lo: f32x4,
    pub hi: f32x4,
    /// Its samples.
    pub first: i32,
    pub last: i32,
}

/// Composites the samples of `segment` into `acc` from the brick's `lit`
/// voxels and occupied `cells`. Returns whether the ray has terminated.
// Out of line: a function of its own, the sample loop compiles the same
// whatever its callers become (inlined, the compiler's choices around it
// moved its cost by several per cent from one change to the next).
#[inline(never)]
pub(crate) fn march(
    acc: &mut FrontToBack,
    lit: &[[f32; 4]; SLOTS],
    cells: &[u64; 8],
    segment: &Segment,
) -> bool {
    let last_cell = f32x4::splat((BRICK - 1) as f32);
    // A copy in registers for the loop.
    let mut ray = *acc;
    let mut p = segment.origin + segment.delta * f32x4::splat(segment.first as f32);
    let mut terminated = false;
    // A count down: an inclusive range costs a flag test per sample.
    let mut left = segment.last - segment.first + 1;
    while left > 0 {
        left -= 1;
        let here = p.fast_max(segment.lo).fast_min(segment.hi);
        p += segment.delta;
        // `here` ≥ 0, so truncation is the floor; the masks only tell the
        // compiler what the clamp already ensures.
        let c = here.fast_min(last_cell).fast_trunc_int();
        let [i, j, l, _] = c.to_array().map(|x| x as usize & (BRICK - 1));
        let bit = cell(i, j, l);
        if cells[bit / 64] >> (bit % 64) & 1 == 0 {
            continue;
        }
        let [fx, fy, fz, _] = (here - f32x4::from_i32x4(c)).to_array();
        let voxels = corners(|s| f32x4::new(lit[s]), slot(i, j, l), SIDE, SIDE * SIDE);
        ray.add(interpolate(voxels, [fx, fy, fz]));
        if ray.is_opaque() {
            terminated = true;
            break;
        }
    }
    *acc = ray;
    terminated
}

/// A ray of a tile, between bricks.
#[derive(Clone, Copy)]
struct RayState<A> {
    /// Index-space position of the ray's sample 0 (for parallel rays on
    /// the image plane, `t = 0`; see [`Stepping::base`]).
    origin: f32x4,
    acc: A,
    /// The first sample not yet taken (a perspective ray's first is the
    /// first ahead of the eye).
    next: i32,
    /// The ray's exact samples (as the reference finds them), found when
    /// first needed, in a brick on the volume's boundary (or in any brick
    /// when something is cut away).
    exact: Option<Option<(i32, i32)>>,
    /// Terminated, or off the volume.
    done: bool,
}

impl<A: Accumulator> RayState<A> {
    const EMPTY: RayState<A> = RayState {
        origin: f32x4::ZERO,
        acc: A::NEW,
        next: i32::MIN,
        exact: None,
        done: false,
    };
}

/// `⌈x⌉` and `⌊x⌋` for `|x| < 2³¹` without a library call (SSE2 has no
/// rounding instruction). Sample numbers are far smaller: a ray has at most
/// `renderer::MAX_SAMPLES_PER_RAY` samples on either side of the
/// image plane (of its base sample, in perspective, which lies level with
/// the grid's centre).
#[inline]
fn ceil_i32(x: f32) -> i32 {
    let t = x as i32;
    t + ((t as f32) < x) as i32
}

#[inline]
fn floor_i32(x: f32) -> i32 {
    let t = x as i32;
    t - ((t as f32) > x) as i32
}

#[cfg(test)]
mod tests;
