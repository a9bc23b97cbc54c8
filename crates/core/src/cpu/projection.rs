//! The fast path of the intensity projections (maximum, minimum, average;
//! see [`crate::kernels::projection`]): the reference's samples, in `f32`, skipping what
//! cannot change the result.
//!
//! Each ray takes the samples [`crate::sampling`] gives it (any view,
//! crop, clip planes, jitter), interpolates the scalar trilinearly in
//! `f32` and keeps the running maximum, minimum or sum (in `f64`). Two
//! exact shortcuts serve the maximum (and, mirrored, the minimum):
//!
//! - **Macro-cell skipping.** A trilinear sample lies between the smallest
//!   and the largest of its cell's eight voxels, so no sample in a brick
//!   whose largest voxel ([`crate::bricks::macrocells`]) is at most the running
//!   maximum can raise it: the ray jumps to the first sample past the
//!   brick (Parker et al., "Interactive ray tracing for volume
//!   visualization", IEEE TVCG 1999, use the same min/max bound for
//!   maximum intensity projection).
//! - **Early termination.** Once the running maximum is the volume's
//!   largest value, nothing can raise it.
//!
//! The average visits every sample. Each pixel is computed from its own
//! ray alone, so the image is the same for any thread count.
//!
//! Non-finite voxels rendered as empty space ([`NonFinite`](crate::NonFinite)): in a
//! brick near one, each sample is tested by the reference's rule, on the
//! reference's `f64` position, and not counted if skipped; a ray that
//! counts no sample shows the background. The bricks' ranges, of the
//! cleaned volume, still bound every counted sample.

use crate::bricks::BRICK;
use crate::bricks::macrocells::Macrocells;
use crate::camera::View;
use crate::frame::progress::Progress;
use crate::kernels::projection::Projected;
use crate::kernels::trilinear::sample_scalar;
use crate::sampling::{PixelSamples, Sampling};
use crate::settings::Blend;
use crate::volume::non_finite::NonFiniteMask;
use crate::volume::{Sample, Volume};
use glam::Vec3;
use rayon::prelude::*;

/// Samples within this fraction of a step before a brick's exit count as
/// past it: rounding cannot carry a sample counted in the brick out of it.
const EXIT_SLACK: f64 = 1e-4;

/// What the rays read: the samples, of type `T`.
struct Scene<'a, T> {
    data: &'a [T],
    dims: [usize; 3],
    /// The samples not to count, if the volume had non-finite values.
    mask: Option<&'a NonFiniteMask>,
    macrocells: &'a Macrocells,
    blend: Blend,
    /// The volume's `(min, max)`.
    range: (f32, f32),
}

/// Renders the projection `blend` (not [`Blend::Composite`]) of `volume`
/// through `view`, sampling as `sampling` says, into `pixels` (the view's
/// projections, row-major).
/// `macrocells` are the volume's and `range` its `(min, max)`. `progress`
/// is called with the number of pixels finished, a row at a time. With a
/// `mask`, `volume` is the cleaned copy and the samples the mask skips are
/// not counted.
#[allow(clippy::too_many_arguments)]
pub fn render(
    volume: &Volume,
    mask: Option<&NonFiniteMask>,
    macrocells: &Macrocells,
    range: (f32, f32),
    view: &View,
    sampling: &Sampling,
    blend: Blend,
    pixels: &mut [Projected],
    progress: &Progress,
) {
    assert_eq!(pixels.len(), view.width() * view.height());
    crate::with_samples!(volume.samples(), |data| {
        let scene = Scene {
            data,
            dims: volume.dims(),
            mask,
            macrocells,
            blend,
            range,
        };
        cast(&scene, view, sampling, pixels, progress)
    })
}

/// Casts every ray of `view` through `scene` into `pixels`.
fn cast<T: Sample>(
    scene: &Scene<T>,
    view: &View,
    sampling: &Sampling,
    pixels: &mut [Projected],
    progress: &Progress,
) {
    let (width, blend) = (view.width(), scene.blend);
    pixels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, pixels)| {
            if progress.stopped() {
                return;
            }
            for (col, pixel) in pixels.iter_mut().enumerate() {
                *pixel = match sampling.pixel(view, col, row) {
                    Some(ray) => scene.project(&ray),
                    None => Projected::empty(blend),
                };
            }
            progress.done(pixels.len());
        });
}

impl<T: Sample> Scene<'_, T> {
    /// The projection of one ray's samples (it has at least one; the mask
    /// may skip them all).
    fn project(&self, ray: &PixelSamples) -> Projected {
        let (dims, data) = (self.dims, self.data);
        let top = Vec3::new(
            (dims[0] - 1) as f32,
            (dims[1] - 1) as f32,
            (dims[2] - 1) as f32,
        );
        let start = (ray.origin + ray.t(ray.first) * ray.direction).as_vec3();
        let delta = (ray.step * ray.direction).as_vec3();
        let at = |k: i64| (start + delta * (k - ray.first) as f32).clamp(Vec3::ZERO, top);
        // Whether sample `k`, at `p`, is skipped: tested only near a masked
        // voxel, on the reference's position.
        let skipped = |k: i64, p: Vec3| {
            self.mask
                .is_some_and(|m| m.near_point(p) && m.skips(ray.position(k, dims)))
        };
        // Maximum and minimum are one search: for the minimum, the largest −f.
        let sign = match self.blend {
            Blend::Maximum => 1.0,
            Blend::Minimum => -1.0,
            Blend::Average | Blend::Composite => {
                let (sum, count) = match self.mask {
                    None => {
                        let sum: f64 = (ray.first..=ray.last)
                            .map(|k| sample_scalar(data, dims, at(k)) as f64)
                            .sum();
                        (sum, ray.count())
                    }
                    Some(_) => (ray.first..=ray.last)
                        .filter_map(|k| Some(at(k)).filter(|&p| !skipped(k, p)))
                        .fold((0.0f64, 0usize), |(sum, count), p| {
                            (sum + sample_scalar(data, dims, p) as f64, count + 1)
                        }),
                };
                return Projected {
                    value: sum,
                    count: count as u64,
                };
            }
        };
        let largest = if sign > 0.0 {
            self.range.1
        } else {
            -self.range.0
        };
        let grid = &self.macrocells.grid;
        let mut best = f32::NEG_INFINITY;
        let mut counted = false;
        let mut k = ray.first;
        // Brick by brick: the samples from k up to the brick's exit lie in
        // the brick (its box is convex), so its range bounds them all.
        while k <= ray.last {
            let p = at(k);
            // The brick of the sample's cell (the last cell holds the far faces).
            let b = std::array::from_fn(|a| (p[a] as usize).min(dims[a] - 2) / BRICK);
            let (lo, hi) = self.macrocells.ranges[grid.index(b)];
            // At least sample k, even if rounding puts it on the exit face.
            let next = exit(ray, grid.bounds(b)).max(k + 1);
            let bound = if sign > 0.0 { hi } else { -lo };
            if bound > best {
                let samples = k..next.min(ray.last + 1);
                if self.mask.is_some_and(|m| m.near(b)) {
                    for j in samples {
                        let p = at(j);
                        if !skipped(j, p) {
                            best = best.max(sign * sample_scalar(data, dims, p));
                            counted = true;
                        }
                    }
                } else {
                    // At least sample k (next > k, k <= last).
                    for j in samples {
                        best = best.max(sign * sample_scalar(data, dims, at(j)));
                    }
                    counted = true;
                }
                if best >= largest {
                    break;
                }
            }
            k = next;
        }
        // Without a mask every ray counts a sample (no brick's bound is
        // below −∞, the best before the first); with one, every sample may
        // have been skipped, and the ray shows the background.
        if counted {
            Projected {
                value: f64::from(sign * best),
                count: 1,
            }
        } else {
            Projected::empty(self.blend)
        }
    }
}

/// The first sample of `ray` past the index-space box `(lo, hi)` that the
/// ray is inside of (counting those [`EXIT_SLACK`] before the exit as past).
fn exit(ray: &PixelSamples, (lo, hi): ([usize; 3], [usize; 3])) -> i64 {
    let mut t_exit = f64::INFINITY;
    for a in 0..3 {
        let d = ray.direction[a];
        let face = if d > 0.0 { hi[a] } else { lo[a] } as f64;
        if d != 0.0 {
            t_exit = t_exit.min((face - ray.origin[a]) / d);
        }
    }
    (t_exit / ray.step - ray.offset - EXIT_SLACK).ceil() as i64
}
