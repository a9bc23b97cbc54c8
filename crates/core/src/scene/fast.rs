//! The fast path of a scene's composite mix: the reference's samples
//! (`reference.rs`), in `f32`, front to back, with early ray termination,
//! skipping what is transparent in each volume.
//!
//! **Chunks.** Each ray takes its samples [`CHUNK`] at a time. For a
//! chunk, each volume fills its samples of it (colour and opacity, zero
//! outside its box and where it is transparent), walking the bricks the
//! chunk crosses in its own grid; then the chunk's samples are mixed
//! ([`Mixer`]) and composited, and the ray stops once less than 1/1024 of
//! the light gets through. A chunk in which no volume has an opaque sample
//! is passed over whole. So each volume's inner loop runs over one brick
//! of its own at a time, as on the single-volume paths, and a ray that
//! terminates wastes at most one chunk's samples.
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
//! computed from its own ray alone, whatever thread runs it (rows in
//! parallel): the image is bit-identical for any thread count.

use super::SceneFrame;
use crate::bricks::occupied::{ClassifiedBricks, Source};
use crate::bricks::{BRICK, BrickGrid, SIDE, SLOTS, cell, slot};
use crate::cpu::lit_bricks::{Lighting, LitBricks};
use crate::cpu::post::skipping::{TransparentValues, transparent_bricks};
use crate::kernels::composite::{EMPTY, FrontToBack};
use crate::kernels::mix::Mixer;
use crate::kernels::phong::{LightGeometry, Phong, lit_colour};
use crate::kernels::trilinear::{cell_of, corners, interpolate};
use crate::non_finite::NonFiniteMask;
use crate::partial::{PartialImage, PartialPixels};
use crate::progress::Progress;
use crate::renderer::{FastState, Renderer};
use crate::sampling::grid::GridFrame;
use crate::settings::{Classification, RenderSettings};
use crate::transfer::classifier::Classifier;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::MutexGuard;
use wide::f32x4;

/// Samples a ray takes at a time: each volume fills a chunk, then the
/// chunk is mixed and composited. A terminated ray has wasted at most
/// this many samples of each volume.
pub(crate) const CHUNK: usize = 32;

/// A pre-classified volume's lit-brick buffer, when its cache is full.
type Scratch = Option<Box<[[f32; 4]; SLOTS]>>;

/// What one volume's samples are made of in this frame.
enum Kind<'a> {
    Pre {
        bricks: &'a ClassifiedBricks,
        lit: &'a LitBricks,
        lighting: Lighting<'a>,
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
}

/// One ray through one volume: sample `k` is at index-space
/// `start + (k − first)·delta`, and samples `range` are in its box.
struct Walk {
    start: Vec3,
    delta: Vec3,
    /// The same in `f64`, for the non-finite mask's test.
    start64: DVec3,
    delta64: DVec3,
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

    /// Fills `out` with this volume's samples `ks` of the ray `walk`
    /// (`(r, g, b, α)`, zero where it adds nothing); says whether any has
    /// an opacity above zero.
    fn fill(&self, walk: &Walk, ks: Range<i64>, out: &mut [f32x4], scratch: &mut Scratch) -> bool {
        out.fill(f32x4::ZERO);
        let (from, to) = (ks.start.max(walk.range.start), ks.end.min(walk.range.end));
        let max = self.max();
        let mut any = false;
        let mut k = from;
        while k < to {
            // The run of samples in one brick.
            let b = self.brick_of(walk.position(k, max));
            let mut end = k + 1;
            while end < to && self.brick_of(walk.position(end, max)) == b {
                end += 1;
            }
            let out = &mut out[(k - ks.start) as usize..(end - ks.start) as usize];
            any |= match &self.kind {
                Kind::Pre { .. } => self.pre(b, walk, k..end, out, scratch),
                Kind::Post { .. } => self.post(b, walk, k..end, out),
            };
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
        scratch: &mut Scratch,
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
        let n = occupied[self.grid.index(b)];
        if n == 0 {
            return false;
        }
        let n = n as usize - 1;
        let slots = lit.get(n, lighting, scratch);
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
                corners(|i| f32x4::new(slots[i]), base, SIDE, SIDE * SIDE),
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
            transparent,
            values,
            classifier,
            lighting,
            mask,
        } = &self.kind
        else {
            unreachable!("a post-classified volume")
        };
        if transparent[self.grid.index(b)] {
            return false;
        }
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
    let built: Vec<Layer> = (0..layers.len())
        .map(|i| {
            let (renderer, settings) = layers[i];
            let volume = renderer.volume();
            let grid = BrickGrid::new(volume.dims());
            let lighting = settings.shading.then_some((&settings.phong, lights[i]));
            let kind = match &states[i] {
                Some(guard) => {
                    let state = guard.as_ref().expect("the state was made");
                    let source = Source {
                        volume,
                        classifier: &state.classifier,
                        masked: &masks[i],
                    };
                    let mut occupied = vec![0u32; grid.len()];
                    for (n, b) in state.bricks.bricks().enumerate() {
                        occupied[grid.index(b)] = n as u32 + 1;
                    }
                    Kind::Pre {
                        bricks: &state.bricks,
                        lit: &state.lit,
                        lighting: Lighting::new(
                            source,
                            &state.bricks,
                            numbers[i],
                            lighting.as_ref().map(|(p, l)| (*p, l)),
                        ),
                        occupied,
                    }
                }
                None => {
                    let macrocells = renderer.macrocells();
                    let classifier = &classifiers[i];
                    Kind::Post {
                        voxels: renderer.packed_voxels(),
                        transparent: transparent_bricks(macrocells, classifier),
                        values: TransparentValues::new(classifier, renderer.value_range()),
                        classifier,
                        lighting,
                        mask: renderer.non_finite(),
                    }
                }
            };
            Layer {
                frame: GridFrame {
                    dims: volume.dims(),
                    origin: volume.origin(),
                    spacing: volume.spacing(),
                },
                grid,
                kind,
            }
        })
        .collect();

    let (width, height) = (view.width(), view.height());
    let mut image = PartialImage::composite(width, height);
    let PartialPixels::Composite(pixels) = image.pixels_mut() else {
        unreachable!("a composite image")
    };
    let sampling = &frame.sampling;
    pixels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, out)| {
            if progress.stopped() {
                return;
            }
            let mut scratch: Vec<Scratch> = built.iter().map(|_| None).collect();
            let mut chunks = vec![[f32x4::ZERO; CHUNK]; built.len()];
            let mut walks: Vec<Walk> = Vec::with_capacity(built.len());
            for (col, pixel) in out.iter_mut().enumerate() {
                let (origin, direction) = view.pixel_ray(col, row);
                let Some(ray) = sampling.ray(col, row, origin, direction) else {
                    *pixel = EMPTY;
                    continue;
                };
                let first_point = origin + ray.t(ray.first) * direction;
                let tolerance = 1e-6 * ray.step;
                walks.clear();
                walks.extend(built.iter().map(|layer| {
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
                        first: ray.first,
                        range,
                    }
                }));
                let mut acc = FrontToBack::NEW;
                let mut k = ray.first;
                'ray: while k <= ray.last {
                    let end = (k + CHUNK as i64).min(ray.last + 1);
                    let mut any = false;
                    for (i, layer) in built.iter().enumerate() {
                        any |= layer.fill(&walks[i], k..end, &mut chunks[i], &mut scratch[i]);
                    }
                    if any {
                        for j in 0..(end - k) as usize {
                            let mut mixer = Mixer::NEW;
                            for chunk in &chunks {
                                mixer.add(chunk[j]);
                            }
                            if let Some(sample) = mixer.sample() {
                                acc.add(sample);
                                if acc.is_opaque() {
                                    break 'ray;
                                }
                            }
                        }
                    }
                    k = end;
                }
                *pixel = acc.partial();
            }
            progress.done(out.len());
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
