//! Casting the frame's rays: each ray walks the bricks it crosses in order
//! (Amanatides and Woo's traversal), steps over the transparent ones, and
//! interpolates, classifies, shades and composites the samples of the
//! others front to back.

use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;
use wide::f32x4;

use super::scene::{PostWork, Scene};
use super::skipping::{TransparentValues, transparent_bricks, value_range};
use crate::bricks::{BRICK, BrickGrid};
use crate::camera::View;
use crate::frame::progress::Progress;
use crate::kernels::composite::{EMPTY, Finish, FrontToBack, PartialPixel};
use crate::kernels::phong::{Reaching, lit_colour_reached};
use crate::kernels::trilinear::{cell_of, corners, interpolate};
use crate::sampling::grid::clamp_to_grid;
use crate::sampling::{PixelSamples, Sampling};

/// Renders `scene` through `view`, sampling as `sampling` says, into
/// `pixels` (the view's, row-major), each ray's partial pixel or the
/// finished one as `finish` says. `progress` is called with the number of
/// pixels finished, a row at a time.
pub fn render(
    scene: &Scene,
    view: &View,
    sampling: &Sampling,
    pixels: &mut [PartialPixel],
    finish: Finish,
    progress: &Progress,
) -> PostWork {
    let dims = scene.macrocells.grid.dims;
    assert_eq!(scene.voxels.len(), dims.iter().product::<usize>());
    assert_eq!(pixels.len(), view.width() * view.height());
    let rays = Rays {
        scene,
        grid: scene.macrocells.grid,
        transparent: transparent_bricks(scene.macrocells, scene.classifier),
        values: TransparentValues::new(scene.classifier, value_range(scene.macrocells)),
    };
    let width = view.width();
    pixels
        .par_chunks_mut(width)
        .enumerate()
        .map(|(row, pixels)| {
            let mut work = PostWork::default();
            if progress.stopped() {
                return work;
            }
            for (col, pixel) in pixels.iter_mut().enumerate() {
                *pixel = finish.apply(match sampling.pixel(view, col, row) {
                    Some(ray) => rays.cast(&ray, &mut work).partial(),
                    None => EMPTY,
                });
            }
            progress.done(pixels.len());
            work
        })
        .reduce(PostWork::default, |mut a, b| {
            a += b;
            a
        })
}

/// The frame's rays.
struct Rays<'a> {
    scene: &'a Scene<'a>,
    grid: BrickGrid,
    /// [`transparent_bricks`], by brick index.
    transparent: Vec<bool>,
    values: TransparentValues,
}

/// One ray's samples as `f32` index-space positions: sample `k` is at
/// `start + (k − first)·delta` (before clamping).
struct Positions {
    start: Vec3,
    delta: Vec3,
    first: i64,
}

impl Rays<'_> {
    /// Composites the samples of `ray` (it has at least one), brick by
    /// brick in the order the ray crosses them.
    fn cast(&self, ray: &PixelSamples, work: &mut PostWork) -> FrontToBack {
        let dims = self.grid.dims;
        let mut acc = FrontToBack::NEW;
        // Positions count from the first sample (near the volume, even for
        // a far perspective eye), so `f32` loses nothing to a far origin.
        let start = ray.origin + ray.t(ray.first) * ray.direction;
        let positions = Positions {
            start: start.as_vec3(),
            delta: (ray.step * ray.direction).as_vec3(),
            first: ray.first,
        };
        // Amanatides & Woo: the brick of the first sample; per axis, the
        // `t` of the next brick face the ray crosses, the `t` a brick's
        // width takes, and the direction of the step.
        let p = clamp_to_grid(start, dims);
        let mut brick: [i64; 3] =
            std::array::from_fn(|a| ((p[a] as usize).min(dims[a] - 2) / BRICK) as i64);
        let mut next_face = [f64::INFINITY; 3];
        let mut across = [f64::INFINITY; 3];
        let mut step = [0i64; 3];
        for a in 0..3 {
            let d = ray.direction[a];
            let width = BRICK as f64;
            if d > 0.0 {
                step[a] = 1;
                next_face[a] = ((brick[a] + 1) as f64 * width - ray.origin[a]) / d;
                across[a] = width / d;
            } else if d < 0.0 {
                step[a] = -1;
                next_face[a] = (brick[a] as f64 * width - ray.origin[a]) / d;
                across[a] = -width / d;
            }
        }
        let mut k = ray.first;
        loop {
            // The face the ray leaves this brick by (the first axis on a tie).
            let mut a = 0;
            for b in 1..3 {
                if next_face[b] < next_face[a] {
                    a = b;
                }
            }
            let beyond = brick[a] + step[a];
            let leaving = step[a] == 0 || beyond < 0 || beyond >= self.grid.bricks[a] as i64;
            // The samples before the exit; the last brick takes all the
            // rest (those rounding put a hair beyond the grid, clamped).
            let end = if leaving {
                ray.last + 1
            } else {
                let exit = (next_face[a] / ray.step - ray.offset).ceil();
                (exit.max(k as f64) as i64).min(ray.last + 1)
            };
            if end > k {
                let b = brick.map(|c| c as usize);
                if self.transparent[self.grid.index(b)] {
                    work.bricks_skipped += 1;
                } else {
                    // Near a masked voxel, the samples the reference skips;
                    // elsewhere none (a loop with no test, as without a mask).
                    let terminated = match self.scene.mask.filter(|m| m.near(b)) {
                        None => self.march(b, k..end, &positions, &mut acc, work, |_| false),
                        Some(m) => self.march(b, k..end, &positions, &mut acc, work, |k| {
                            m.skips(ray.position(k, dims))
                        }),
                    };
                    if terminated {
                        break;
                    }
                }
            }
            k = end;
            if leaving || k > ray.last {
                break;
            }
            brick[a] = beyond;
            next_face[a] += across[a];
        }
        acc
    }

    /// Composites the samples `ks` in brick `b` into `acc`, but those
    /// `skipped` says to pass over. Returns whether the ray has terminated.
    fn march(
        &self,
        b: [usize; 3],
        ks: Range<i64>,
        positions: &Positions,
        acc: &mut FrontToBack,
        work: &mut PostWork,
        skipped: impl Fn(i64) -> bool,
    ) -> bool {
        let scene = self.scene;
        let classifier = scene.classifier;
        let voxels = scene.voxels;
        let [nx, ny, _] = self.grid.dims;
        let (lo, hi) = self.grid.bounds(b);
        let (box_lo, box_hi) = (
            Vec3::new(lo[0] as f32, lo[1] as f32, lo[2] as f32),
            Vec3::new(hi[0] as f32, hi[1] as f32, hi[2] as f32),
        );
        // The cells of the brick: the last one along each axis holds its
        // far face, so every corner is one of the brick's voxels.
        let last_cell = hi.map(|h| h - 1);
        let uses_gradient = classifier.uses_gradient();
        let (sy, sz) = (nx, nx * ny);
        for k in ks {
            if skipped(k) {
                continue;
            }
            work.samples += 1;
            let n = (k - positions.first) as f32;
            let p = (positions.start + positions.delta * n).clamp(box_lo, box_hi);
            let (c, offsets) = cell_of(p, last_cell);
            let base = c[0] + sy * c[1] + sz * c[2];
            // Gradient and value interpolate together: (gx, gy, gz, f).
            let [x, y, z, f] =
                interpolate(corners(|i| voxels[i], base, sy, sz), offsets).to_array();
            let g = [x, y, z];
            // A sample of zero opacity adds exactly nothing: not shaded.
            if self.values.contains(f) {
                continue;
            }
            let alpha = if uses_gradient {
                classifier.opacity_at(f, g)
            } else {
                classifier.sample_opacity(f)
            };
            if alpha == 0.0 {
                continue;
            }
            let lighting = scene
                .lighting
                .as_ref()
                .map(|(phong, light)| (*phong, light));
            let reaching = Reaching {
                light: scene.light.map_or(1.0, |light| light.sample(p)),
                ambient: scene.ambient.map_or(1.0, |ambient| ambient.sample(p)),
            };
            let [r, g, b] =
                lit_colour_reached(lighting, Vec3::from(g), classifier.material(f), reaching);
            acc.add(f32x4::new([r, g, b, alpha]));
            if acc.is_opaque() {
                return true;
            }
        }
        false
    }
}
