//! The fast path of post-classified compositing: the reference's samples
//! (see [`crate::reference::post`]), in `f32`, front to back, skipping
//! the bricks that are transparent whatever their samples.
//!
//! Each ray takes the samples [`crate::sampling`] gives it (orthographic or
//! perspective, cropped, clipped, jittered), walks the 8³-cell bricks of
//! [`crate::bricks`] it crosses in order, and in every brick that may be
//! visible takes each sample: it interpolates the scalar and the voxels'
//! central-difference gradients ([`crate::kernels::gradient`]) trilinearly, then
//! classifies and shades the sample with the formulas of
//! [`crate::reference::post`] (the classifier's opacity and material,
//! Phong lighting for the frame's one light geometry, the colour clamped
//! to [0, 1]) and composites it front to back ([`crate::kernels::composite`]). The
//! ray stops once its transmittance is below
//! [`TERMINATION_TRANSMITTANCE`](crate::kernels::composite::TERMINATION_TRANSMITTANCE), as on the bricked fast path.
//!
//! **Brick walk.** The ray visits the bricks in the order it crosses them,
//! by the 3-D digital differential analyser of J. Amanatides and A. Woo, "A
//! fast voxel traversal algorithm for ray tracing", *Eurographics* 1987:
//! for each axis the ray parameter `t` of the next brick face it crosses,
//! advanced by a brick's width in `t` as the ray steps into the next brick
//! along that axis. A brick takes the samples whose `t` lies before its
//! exit, each clamped into the brick's box (a sample on a shared face
//! belongs to either brick; clamping moves one only by rounding).
//!
//! **Skipping.** A trilinear sample lies between the smallest and the
//! largest of its cell's voxels, so every sample of a brick has a value in
//! the brick's range ([`crate::bricks::macrocells`]); if
//! [`Classifier::is_transparent_between`] says that range gets zero
//! opacity at every gradient (with Levoy's contour and gradient-magnitude
//! opacity too, see [`crate::transfer::classifier`]), no sample of the brick can add
//! anything and the ray steps over it. In `f32` the interpolated value may
//! stray past the range by rounding, by at most `7.5·ε·max(|lo|, |hi|)`
//! (three nested lerps, each off by at most `2u·|b − a| + u·|result|`,
//! `u = ε/2`); the test is made on the range widened by
//! [`RANGE_MARGIN`]`·ε·max(|lo|, |hi|)`, so skipping never drops a sample
//! that would have been visible. A brick of one value interpolates that
//! value exactly and is tested unwidened. Within a brick, a sample whose
//! value lies in a transparent stretch at either end of the volume's range
//! ([`TransparentValues`], found once per frame with the same exact test)
//! is passed over before it is classified, and a sample whose opacity is
//! zero before it is shaded: either would add exactly nothing. (The
//! gradient is interpolated with the value, in the other three lanes of
//! the same vector lerps, so it costs nothing apart.)
//!
//! **Arithmetic.** The reference's formulas, in `f32`: positions counted
//! from the ray's first sample, the scalar and the gradient interpolated by
//! lerps (a sample on a face between two bricks is interpolated in the
//! brick the walk is in), the classifier's [`Classifier::opacity_at`] and
//! [`Classifier::material`], [`Phong::shade`] with the frame's light (a
//! headlight at infinity along the central view direction, for perspective
//! views too, as on the reference), the colour clamped to [0, 1]. The
//! images agree with the reference's within 1/255, early termination
//! (at most 1/1024) being the largest part of the difference.
//!
//! **Gradients** are the reference's: each voxel's central difference,
//! interpolated trilinearly. The renderer computes them once per volume
//! and keeps them packed with the scalars ([`packed_voxels`]: each voxel
//! as `(gx, gy, gz, f)`, x fastest), so that one 16-byte load per corner
//! and one chain of vector lerps interpolate value and gradient together
//! (the same arithmetic, lane by lane, as separate scalar and vector
//! lerps, so the same values). It costs 16 bytes per voxel, four times the
//! volume itself. (A bricked copy, each brick's 9³ corner voxels together
//! as in [`crate::bricks::occupied`], 22.8 bytes per voxel, measured no faster:
//! the cost is in the arithmetic, not the cache.)
//!
//! **Non-finite voxels** rendered as empty space ([`NonFinite`](crate::NonFinite)):
//! the scene's voxels are the cleaned copy's, and in a brick near a masked
//! voxel each sample is first tested by the reference's rule on the
//! reference's `f64` position, and passed over if skipped. Other bricks,
//! and volumes without non-finite values, pay nothing.
//!
//! Each pixel is computed from its own ray alone, by the same arithmetic
//! whatever thread runs it (rows in parallel), so the image is
//! bit-identical for any thread count.

use crate::bricks::macrocells::Macrocells;
use crate::bricks::{BRICK, BrickGrid};
use crate::camera::View;
use crate::kernels::composite::{EMPTY, Finish, FrontToBack, PartialPixel};
use crate::kernels::phong::{LightGeometry, Phong, lit_colour};
use crate::kernels::trilinear::{cell_of, corners, interpolate};
use crate::non_finite::NonFiniteMask;
use crate::progress::Progress;
use crate::sampling::grid::clamp_to_grid;
use crate::sampling::{PixelSamples, Sampling};
use crate::transfer::classifier::Classifier;
use crate::volume::{Sample, Volume};
use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;
use wide::f32x4;

/// Bytes per voxel of the packed values and gradients ([`packed_voxels`]).
pub(crate) const BYTES_PER_VOXEL: usize = size_of::<f32x4>();
/// Bytes per brick of a frame's transparency flags ([`transparent_bricks`]).
pub(crate) const FRAME_BYTES_PER_BRICK: usize = size_of::<bool>();

/// A brick's value range is widened by this many `f32::EPSILON` of its
/// largest magnitude before the transparency test: twice the bound on how
/// far rounding can carry a trilinear sample past its voxels' range.
pub const RANGE_MARGIN: f32 = 16.0;

/// What one frame's rays read: the scalars and gradients packed
/// ([`packed_voxels`], made once per volume), and the frame's classifier
/// and light.
pub struct Scene<'a> {
    /// Every voxel's `(gx, gy, gz, f)`, x fastest.
    pub voxels: &'a [f32x4],
    /// The volume's min/max bricks.
    pub macrocells: &'a Macrocells,
    pub classifier: &'a Classifier,
    /// The Phong coefficients and the frame's light; `None`: unlit, each
    /// sample takes its material colour.
    pub lighting: Option<(&'a Phong, LightGeometry)>,
    /// The samples to pass over, where `voxels` are those of a cleaned
    /// volume ([`NonFinite`](crate::NonFinite)); `None`: every sample counts.
    pub mask: Option<&'a NonFiniteMask>,
}

/// Every voxel's world gradient (from `gradients`, see
/// [`crate::kernels::gradient::gradients`]) and scalar as the lanes
/// `(gx, gy, gz, f)`, x fastest: what [`render`] reads.
pub fn packed_voxels(volume: &Volume, gradients: &[[f32; 3]]) -> Vec<f32x4> {
    assert_eq!(gradients.len(), volume.len());
    crate::with_samples!(volume.samples(), |data| {
        (gradients.par_iter().zip(data))
            .map(|(&[x, y, z], f)| f32x4::new([x, y, z, f.to_f32()]))
            .collect()
    })
}

/// What a frame's rays did: a measure of the work skipping saved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PostWork {
    /// Samples interpolated (the rest were in skipped bricks or behind
    /// terminated rays).
    pub samples: u64,
    /// Bricks stepped over as transparent, counted once per ray.
    pub bricks_skipped: u64,
}

impl std::ops::AddAssign for PostWork {
    fn add_assign(&mut self, other: Self) {
        self.samples += other.samples;
        self.bricks_skipped += other.bricks_skipped;
    }
}

/// The values trilinear samples of voxels in `[lo, hi]` can take in `f32`:
/// the range widened by [`RANGE_MARGIN`]`·ε·max(|lo|, |hi|)`, unless all
/// the voxels are equal (see the module's notes on rounding).
pub fn sample_range((lo, hi): (f32, f32)) -> (f32, f32) {
    if lo < hi {
        let margin = RANGE_MARGIN * f32::EPSILON * lo.abs().max(hi.abs());
        (lo - margin, hi + margin)
    } else {
        (lo, hi)
    }
}

/// Whether each brick of `macrocells` is transparent under `classifier`
/// for every sample it can hold.
pub fn transparent_bricks(macrocells: &Macrocells, classifier: &Classifier) -> Vec<bool> {
    (macrocells.ranges.iter())
        .map(|&range| {
            let (lo, hi) = sample_range(range);
            classifier.is_transparent_between(lo, hi)
        })
        .collect()
}

/// The values that get zero opacity at every gradient at the bottom and
/// the top of the range samples can take: a sample whose value is among
/// them is passed over after its interpolation, before classifying it
/// (which costs a table search and, at steps other than 1, a power). Found
/// by bisection with [`Classifier::is_transparent_between`], which is
/// exact, so passing over them changes nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransparentValues {
    /// The range samples can take: the volume's, widened for rounding
    /// (see the module's notes).
    lowest: f32,
    highest: f32,
    /// `[lowest, below]` is transparent (`below = −∞`: no such values).
    below: f32,
    /// `[above, highest]` is transparent (`above = +∞`: none).
    above: f32,
}

impl TransparentValues {
    /// The transparent ends of the values samples of a volume whose values
    /// span `value_range` can take, under `classifier`.
    pub fn new(classifier: &Classifier, value_range: (f32, f32)) -> Self {
        let (lowest, highest) = sample_range(value_range);
        let transparent = |lo: f32, hi: f32| classifier.is_transparent_between(lo, hi);
        // The end of the transparent stretch from `from` towards `to`,
        // given that `from` itself is transparent and `to` is not: the
        // test is monotone (a part of a transparent interval is transparent).
        let bisect = |from: f32, to: f32, holds: &dyn Fn(f32) -> bool| {
            let (mut ok, mut bad) = (from, to);
            loop {
                let mid = ok / 2.0 + bad / 2.0;
                // Down to neighbouring floats.
                let between = if ok < bad {
                    ok < mid && mid < bad
                } else {
                    bad < mid && mid < ok
                };
                if !between {
                    return ok;
                }
                if holds(mid) {
                    ok = mid;
                } else {
                    bad = mid;
                }
            }
        };
        let (below, above) = if transparent(lowest, highest) {
            (highest, lowest)
        } else {
            let below = if transparent(lowest, lowest) {
                bisect(lowest, highest, &|x| transparent(lowest, x))
            } else {
                f32::NEG_INFINITY
            };
            let above = if transparent(highest, highest) {
                bisect(highest, lowest, &|x| transparent(x, highest))
            } else {
                f32::INFINITY
            };
            (below, above)
        };
        TransparentValues {
            lowest,
            highest,
            below,
            above,
        }
    }

    /// Whether a sample of value `f` has zero opacity whatever its gradient.
    #[inline]
    pub fn contains(&self, f: f32) -> bool {
        (self.lowest <= f && f <= self.below) || (self.above <= f && f <= self.highest)
    }
}

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

/// The volume's `(min, max)`, from its bricks' ranges.
fn value_range(macrocells: &Macrocells) -> (f32, f32) {
    (macrocells.ranges.iter()).fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), r| {
        (lo.min(r.0), hi.max(r.1))
    })
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
            let [r, g, b] = lit_colour(lighting, Vec3::from(g), classifier.material(f));
            acc.add(f32x4::new([r, g, b, alpha]));
            if acc.is_opaque() {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::function::PiecewiseLinear;
    use crate::transfer::iso::IsoSurface;

    #[test]
    fn packed_voxels_interpolate_to_the_scalar_and_the_gradient_of_the_reference() {
        use crate::kernels::gradient::gradients;
        use crate::kernels::trilinear::{reference, sample_scalar};
        use glam::DVec3;
        // Values from a hash of the index: nothing a layout bug could hide behind.
        let volume = Volume::from_fn([7, 5, 6], DVec3::new(1.0, 0.5, 2.0), DVec3::ZERO, |p| {
            let (i, j, k) = (p.x as u32, (p.y / 0.5) as u32, (p.z / 2.0) as u32);
            let h = (i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663))
                ^ k.wrapping_mul(83_492_791);
            (h % 1000) as f32 / 37.0 - 9.0
        })
        .unwrap();
        let dims = volume.dims();
        let grads = gradients(&volume);
        let voxels = packed_voxels(&volume, &grads);
        let [x, y, z, f] = voxels[3 + 7 * (2 + 5 * 4)].to_array();
        assert_eq!(
            ([x, y, z], f),
            (grads[3 + 7 * (2 + 5 * 4)], volume.get(3, 2, 4))
        );
        // The interpolation of `march`, on the packed lanes.
        let mut s = 0.618_034_f64;
        for _ in 0..500 {
            let p = Vec3::from(std::array::from_fn(|a| {
                s = (s * 9301.0 + 0.49297).fract();
                (s * (dims[a] - 1) as f64) as f32
            }));
            let (c, offsets) = cell_of(p, dims.map(|n| n - 2));
            let (sy, sz) = (dims[0], dims[0] * dims[1]);
            let base = c[0] + sy * c[1] + sz * c[2];
            let [x, y, z, f] =
                interpolate(corners(|i| voxels[i], base, sy, sz), offsets).to_array();
            // The value lane is the scalar lerps' value to the last bit.
            let scalar = sample_scalar(&volume.values(), dims, p);
            assert_eq!(f.to_bits(), scalar.to_bits(), "{p}");
            let want = reference([p.x, p.y, p.z].map(f64::from), dims, DVec3::ZERO, |i| {
                Vec3::from(grads[i]).as_dvec3()
            });
            let got = DVec3::new(x as f64, y as f64, z as f64);
            assert!(
                (got - want).abs().max_element() < 1e-4,
                "{p}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn the_transparency_test_allows_for_rounding_past_a_bricks_range() {
        // Voxels a < b, and a sample on b's face (weight 1): in f32,
        // a + (b − a)·1 rounds to just above b. Under the paper's ramp over
        // [b, b + 1], zero exactly up to b, that sample is (faintly)
        // opaque, so a brick of values in [a, b] must not be skipped,
        // though the unwidened test calls [a, b] transparent.
        let (a, b) = (f32::from_bits(1043137375), f32::from_bits(1055846055));
        let sample = a + (b - a) * 1.0;
        assert!(a < b && sample > b, "{a} {b} {sample}");
        let ramp = OpacityMap::Ramp { p: 0.0, q: 0.5 };
        let classifier = Classifier::new((b, b + 1.0), ramp, None, 1.0);
        assert!(classifier.sample_opacity(sample) > 0.0);
        assert!(classifier.is_transparent_between(a, b));
        let brick = |range: (f32, f32)| Macrocells {
            grid: BrickGrid::new([9, 9, 9]),
            ranges: vec![range],
        };
        assert_eq!(transparent_bricks(&brick((a, b)), &classifier), [false]);
        // A brick of the one value b interpolates b exactly: skipped.
        assert_eq!(b + (b - b) * 0.37, b);
        assert_eq!(transparent_bricks(&brick((b, b)), &classifier), [true]);
        // Well below the ramp's foot the margin changes nothing.
        let lower = (a - 1.0, b - 1.0);
        assert_eq!(transparent_bricks(&brick(lower), &classifier), [true]);
    }

    #[test]
    fn transparent_values_are_exactly_the_zero_opacity_ends_of_the_range() {
        // Over [0, 10]: opacity zero up to t = 0.25 and from t = 0.9 on.
        let table =
            PiecewiseLinear::new("opacity", vec![(0.25, [0.0]), (0.5, [0.7]), (0.9, [0.0])])
                .unwrap();
        let c = Classifier::new((0.0, 10.0), OpacityMap::Table(table), None, 0.5);
        let v = TransparentValues::new(&c, (-2.0, 12.0));
        assert_eq!((v.below, v.above), (2.5, 9.0));
        // Just inside the visible stretch, the opacity is not zero.
        let (up, down) = (f32::from_bits(2.5f32.to_bits() + 1), 9.0f32.next_down());
        assert!(!v.contains(up) && c.sample_opacity(up) > 0.0);
        assert!(!v.contains(down) && c.sample_opacity(down) > 0.0);
        for i in 0..=1400 {
            let f = -2.0 + i as f32 / 100.0;
            assert_eq!(v.contains(f), c.sample_opacity(f) == 0.0, "{f}");
        }
        // With an iso-surface at 5 (thickness 1 voxel of 1, |∇f| <= 2),
        // values within 2 of it may be opaque, whatever the table says.
        let iso = IsoSurface {
            value: 5.0,
            thickness: 1.0,
        };
        let c = c.with_iso(iso, 1.0, 2.0);
        let v = TransparentValues::new(&c, (-2.0, 12.0));
        assert!((v.below - 3.0).abs() < 0.01 && v.below < 3.0, "{}", v.below);
        assert!((v.above - 7.0).abs() < 0.01 && v.above > 7.0, "{}", v.above);
        for i in 0..=1400 {
            let f = -2.0 + i as f32 / 100.0;
            if v.contains(f) {
                for k in 0..=20 {
                    let g = [0.1 * k as f32, 0.0, 0.0];
                    assert_eq!(c.opacity_at(f, g), 0.0, "{f} {g:?}");
                }
            }
        }
        // Opaque everywhere: nothing; transparent everywhere: everything.
        let ramp = |p| Classifier::new((0.0, 1.0), OpacityMap::Ramp { p, q: 0.5 }, None, 1.0);
        let v = TransparentValues::new(&ramp(0.1), (0.0, 1.0));
        assert!(!v.contains(0.0) && !v.contains(1.0));
        // The paper's ramp from 0: only the bottom of the domain.
        let v = TransparentValues::new(&ramp(0.0), (0.0, 1.0));
        assert_eq!(v.below, 0.0);
        assert!(v.contains(0.0) && !v.contains(1e-30) && !v.contains(1.0));
        let none = Classifier::new(
            (0.0, 1.0),
            OpacityMap::Table(PiecewiseLinear::constant([0.0])),
            None,
            1.0,
        );
        let v = TransparentValues::new(&none, (0.0, 1.0));
        assert!(v.contains(0.0) && v.contains(0.5) && v.contains(1.0));
    }

    use crate::camera::View;
    use crate::camera::{Camera, Projection};
    use crate::image::Image;
    use crate::kernels::gradient::gradients;
    use crate::partial::{PartialImage, PartialPixels};
    use crate::renderer::Renderer;
    use crate::settings::{Classification, Method, RenderSettings};
    use glam::DVec3;

    fn on_the_reference(settings: &RenderSettings) -> RenderSettings {
        RenderSettings {
            method: Method::Reference,
            ..settings.clone()
        }
    }

    /// 48³ of nothing but three small dense features: a 3³ block deep behind
    /// empty bricks (seen along −x, the eye is on +x), a single voxel on a
    /// brick corner, and a 2-voxel rod lying in a brick face.
    fn sparse() -> Volume {
        let n = 48;
        Volume::from_fn([n, n, n], DVec3::ONE, DVec3::ZERO, |p| {
            let (x, y, z) = (p.x as usize, p.y as usize, p.z as usize);
            let block = (3..6).contains(&x) && (30..33).contains(&y) && (10..13).contains(&z);
            let corner = (x, y, z) == (16, 16, 24);
            let rod = x == 8 && y == 40 && (20..22).contains(&z);
            if block || corner || rod { 1.0 } else { 0.0 }
        })
        .unwrap()
    }

    /// Renders `settings` with [`render`] directly, to see its work.
    fn post_cast_work(renderer: &Renderer, settings: &RenderSettings) -> (Image, PostWork, usize) {
        let volume = renderer.volume();
        let frame = renderer.prepare(settings).unwrap();
        let classifier = renderer.classifier(settings);
        let voxels = packed_voxels(volume, &gradients(volume));
        let macrocells = Macrocells::new(volume);
        let light = LightGeometry::headlight((-frame.view.direction()).as_vec3());
        let scene = Scene {
            voxels: &voxels,
            macrocells: &macrocells,
            classifier: &classifier,
            lighting: Some((&settings.phong, light)),
            mask: None,
        };
        let mut partial = PartialImage::composite(settings.width, settings.height);
        let PartialPixels::Composite(pixels) = partial.pixels_mut() else {
            unreachable!()
        };
        let work = render(
            &scene,
            &frame.view,
            &frame.sampling,
            pixels,
            Finish::Partial,
            &Progress::new(&|_| {}),
        );
        let image = renderer.finish(settings, partial);
        (image, work, frame.nominal_samples())
    }

    #[test]
    fn empty_bricks_are_skipped_and_small_features_behind_them_are_found() {
        let volume = sparse();
        let renderer = Renderer::new(&volume).unwrap();
        let cameras = [
            Camera::default(),
            Camera {
                view_point: Some(DVec3::new(100.0, 30.0, 45.0)),
                ..Camera::default()
            },
            Camera {
                projection: Projection::Perspective { fov_degrees: 50.0 },
                azimuth: 20.0,
                elevation: -15.0,
                ..Camera::default()
            },
        ];
        for camera in cameras {
            // The paper's ramp from 0: the empty bricks (all 0, the minimum)
            // are transparent; a dense voxel's opacity is 0.9.
            let s = RenderSettings {
                width: 96,
                height: 96,
                camera,
                step: 0.5,
                opacity_ramp: (0.0, 0.9),
                classification: Classification::Post,
                ..RenderSettings::default()
            };
            let (image, work, nominal) = post_cast_work(&renderer, &s);
            // The renderer's fast path is this very function.
            assert!(image == renderer.render(&s).unwrap(), "{camera:?}");
            let slow = renderer.render(&on_the_reference(&s)).unwrap();
            assert!(
                image.max_abs_diff(&slow).unwrap() <= 1.0 / 255.0,
                "{camera:?}"
            );
            // Most samples lie in empty bricks and are never interpolated.
            println!("{camera:?}: {work:?} of {nominal} nominal samples");
            assert!(work.bricks_skipped > 10_000, "{work:?}");
            assert!(work.samples * 10 < nominal as u64, "{work:?} of {nominal}");
            // Each feature shows where its centre projects.
            let view = View::frame(&camera, volume.bounds(), 96, 96).unwrap();
            for centre in [
                DVec3::new(4.0, 31.0, 11.0),
                DVec3::new(16.0, 16.0, 24.0),
                DVec3::new(8.0, 40.0, 20.5),
            ] {
                let (c, r) = view.project(centre).unwrap();
                let alpha = image.get(c as usize, r as usize)[3];
                assert!(
                    alpha > 0.3,
                    "{camera:?}: feature at {centre} has alpha {alpha}"
                );
            }
        }
    }

    #[test]
    fn bricks_near_an_isovalue_are_visited_and_far_ones_skipped() {
        // With an iso-surface, a brick is skipped only if its values lie
        // farther from the isovalue than the contour can reach at the
        // volume's steepest gradient. The steepest is at the block's corners,
        // |∇f| = |(½, ½, ½)| = √3/2 per voxel, so a contour 0.5 voxels thick
        // reaches 0.43 from the isovalue 0.5: the empty bricks (all 0) are
        // skipped, and the features' bricks are not.
        let volume = sparse();
        let renderer = Renderer::new(&volume).unwrap();
        assert!((renderer.max_gradient() - 0.75f32.sqrt()).abs() < 1e-6);
        let s = RenderSettings {
            width: 64,
            height: 64,
            step: 0.5,
            classification: Classification::Post,
            iso: Some(IsoSurface {
                value: 0.5,
                thickness: 0.5,
            }),
            ..RenderSettings::default()
        };
        let (fast, work, nominal) = post_cast_work(&renderer, &s);
        assert!(fast == renderer.render(&s).unwrap());
        let slow = renderer.render(&on_the_reference(&s)).unwrap();
        assert!(fast.max_abs_diff(&slow).unwrap() <= 1.0 / 255.0);
        assert!(slow.pixels().iter().filter(|p| p[3] > 0.3).count() >= 4);
        println!("iso: {work:?} of {nominal} nominal samples");
        assert!(work.bricks_skipped > 1000, "{work:?}");
        assert!(work.samples * 10 < nominal as u64, "{work:?} of {nominal}");
        // A contour reaching every value (a thickness of 100 voxels) rules
        // out no brick.
        let thick = RenderSettings {
            iso: Some(IsoSurface {
                value: 0.5,
                thickness: 100.0,
            }),
            ..s
        };
        let (fast, work, _) = post_cast_work(&renderer, &thick);
        assert_eq!(work.bricks_skipped, 0);
        let slow = renderer.render(&on_the_reference(&thick)).unwrap();
        assert!(fast.max_abs_diff(&slow).unwrap() <= 1.0 / 255.0);
    }
}
