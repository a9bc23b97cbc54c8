//! The fast path's per-frame stage 1: the paper's Phong colour of every
//! voxel slot of the occupied bricks, for this frame's light and viewer.
//!
//! The light follows the camera (a headlight by default), so this cannot
//! be kept across frames; everything it reads can (see
//! [`crate::bricks::occupied`]). It is the model of [`crate::kernels::phong`] and
//! `reference::stage1` on the stored normals: two-sided (the normal turned to
//! face the viewer), `C = Cs·(ka + kd·max(N·L, 0) + ks·max(N·H, 0)^n)` times
//! the material colour, clamped to [0, 1], with ambient light only where
//! the gradient is zero (a zero normal makes every dot product zero). Every
//! slot is lit, transparent ones included: colours and opacities are
//! interpolated separately (pre-classification), so a transparent voxel's
//! colour still tints the samples next to it.
//!
//! The work is SIMD across four voxels at a time (one voxel per lane), and
//! the result is `f32` RGBA per slot, ready for the ray caster to load
//! without conversion.

use crate::bricks::cache::{BrickCache, Budget, CacheRef};
use crate::bricks::occupied::{ClassifiedBricks, NORMAL_UNIT, Source, UNIT, Voxel};
use crate::bricks::{BrickGrid, SIDE, SLOTS, slot_coords};
use crate::kernels::phong::{Exponent, LightGeometry, Phong, reflect, two_sided};
use crate::shadows::ambient_volume::AmbientVolume;
use crate::shadows::light_volume::LightVolume;
use crate::transfer::classifier::Classifier;
use crate::transfer::function::PiecewiseLinear;
use crate::transfer::labels::colour_value;
use crate::volume::Sample;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use wide::bytemuck::cast;
use wide::{f32x4, i16x8, i32x4, i32x8};

/// Bytes one occupied brick's entry takes in [`LitBricks`], beside its
/// lit voxels.
pub(crate) const BYTES_PER_OCCUPIED_BRICK: usize =
    BrickCache::<[[f32; 4]; SLOTS]>::BYTES_PER_ENTRY + size_of::<AtomicU32>();
/// Bytes of one occupied brick's lit voxels.
pub(crate) const SLOT_BYTES_PER_OCCUPIED_BRICK: usize = size_of::<[[f32; 4]; SLOTS]>();

/// The frame's lit bricks, each lit the first time a ray needs it, under a
/// budget of bytes (see [`BrickCache`]).
///
/// Lighting a brick just before its rays cross it keeps its voxels in the
/// cache for them, lets the lighting's memory traffic overlap the ray
/// casting's arithmetic, and skips the bricks no tile lists (off screen),
/// which then need no buffer either. The buffers are kept from frame to
/// frame; a brick lit in an earlier frame is lit again, because the light
/// moves with the camera.
///
/// **Bricks in use.** A brick is needed only by the tiles whose lists
/// hold it, and those are neighbours, cast close together in time (tiles
/// go in row order; a brick's tiles are two or three rows at most). So
/// each brick counts the tiles that have yet to finish with it
/// ([`Self::next_frame`] from the tile lists, [`Self::done`] as each tile
/// ends), and the last one gives its buffer back to the cache's pool for
/// the next brick. A tile counts down only the bricks it reached: the
/// bricks of its list behind the point where all its rays terminated keep
/// a count, and a buffer if another tile lit them, to the end of the
/// frame: at most the bricks a frame lights, and counting them costs a
/// pass over whole lists where tiles stop after a few of their bricks (the
/// dense CT under the peers' ramp: 85 a list on average). The
/// budget then has to hold the bricks of the tiles in flight, not every
/// brick of the frame: a faint transfer function over a dense 512³ CT at
/// 1024² lights 244 000 bricks a frame (2.8 GB of lit voxels), of which
/// the tiles in flight on two threads hold about 11 000 (128 MiB) at a
/// time. Before, the first bricks a frame lit kept their buffers to its
/// end and every brick after them was lit again for each tile that listed
/// it (677 000 bricks lit a frame there), as it still is when even the
/// bricks in use do not fit.
///
/// **One budget.** The lit bricks share their budget with the classified
/// ones ([`ClassifiedBricks`]): a lit brick that finds no room drops a
/// classified brick to make it ([`ClassifiedBricks::shed`]), since a
/// brick classified again costs once a frame at most, and a brick lit
/// again costs once per tile. The classified bricks keep what the bricks
/// in use leave (there, 896 MiB of the default 1 GiB rather than the third
/// they had when the budget was split).
pub struct LitBricks {
    cache: BrickCache<[[f32; 4]; SLOTS]>,
    /// The frame being rendered: bricks lit for another are stale.
    frame: u64,
    /// Per occupied brick: the tiles of this frame that list it and have
    /// not finished. Kept only when the budget cannot hold every brick
    /// (`None` otherwise: nothing would be given back).
    uses: Option<Vec<AtomicU32>>,
    /// Whether this frame counts `uses`: when the last frame's lit bricks,
    /// classified and lit, did not fit the budget (and in the first
    /// frame). Counting costs a pass over the tile lists; under the peers'
    /// ramp the dense 512³ CT lights 12 091 of its 87 499 bricks a frame,
    /// which fit, and counting cost it 3 to 6 % of a frame (alternated
    /// runs, 0.186 against 0.178 s).
    counting: bool,
    /// Bytes a brick takes, classified and lit, and the budget's.
    per_brick: usize,
    limit: usize,
    /// Bricks the last frame lit ([`Self::end_frame`]).
    last_lit: Option<usize>,
}

impl LitBricks {
    /// The lit bricks of `bricks` occupied bricks, their lit voxels
    /// drawing on `budget`, which a cache of `beside` bytes a brick shares
    /// (the classified bricks).
    pub(crate) fn sharing(bricks: usize, budget: Arc<Budget>, beside: usize) -> Self {
        let per_brick = SLOT_BYTES_PER_OCCUPIED_BRICK + beside;
        let limit = budget.limit();
        let fits = bricks.saturating_mul(per_brick) <= limit;
        LitBricks {
            cache: BrickCache::new(bricks, budget, |f, now| f == now, |f, now| f < now),
            frame: 0,
            uses: (!fits).then(|| (0..bricks).map(|_| AtomicU32::new(0)).collect()),
            counting: false,
            per_brick,
            limit,
            last_lit: None,
        }
    }

    /// Ends a frame that lit `lit` bricks: whether the next one counts
    /// the bricks' uses depends on it.
    pub fn end_frame(&mut self, lit: usize) {
        self.last_lit = Some(lit);
    }

    /// Starts a new frame whose tile lists hold the bricks `listed` (each
    /// once per tile that lists it): every brick is stale. Returns its
    /// number (from 1).
    pub fn next_frame(&mut self, listed: &[u32]) -> u64 {
        self.frame += 1;
        self.counting = self.uses.is_some()
            && (self.last_lit).is_none_or(|lit| lit.saturating_mul(self.per_brick) > self.limit);
        if let Some(uses) = self.uses.as_mut().filter(|_| self.counting) {
            // Every buffer is stale: all of them back to the pool (a
            // stopped frame leaves some out).
            self.cache.release_all();
            for u in uses.iter_mut() {
                *u.get_mut() = 0;
            }
            for &n in listed {
                *uses[n as usize].get_mut() += 1;
            }
        }
        self.frame
    }

    /// A tile that listed brick `n` is done with it: after the last one,
    /// its buffer goes back to the pool. The caller must hold no lit
    /// brick.
    #[inline]
    pub fn done(&self, n: usize) {
        if self.counting
            && let Some(uses) = &self.uses
            && uses[n].fetch_sub(1, Ordering::AcqRel) == 1
        {
            self.cache.release(n);
        }
    }

    /// Occupied brick `n` lit by `lighting` for this frame (lit now,
    /// unless it already is): the cache's buffer, or, when it has no room,
    /// the one in `scratch` (see [`BrickCache::get`]).
    #[inline]
    pub fn get<'a>(
        &'a self,
        n: usize,
        lighting: &Lighting,
        scratch: &'a mut Option<Box<[[f32; 4]; SLOTS]>>,
    ) -> CacheRef<'a, [[f32; 4]; SLOTS]> {
        self.cache.get(
            n,
            self.frame,
            || Box::new([[0.0; 4]; SLOTS]),
            |out| lighting.shade(n, out),
            scratch,
            // The lit bricks in use come first: a classified brick is made
            // again from the volume once a frame at most, a lit brick that
            // finds no room would be lit once per tile.
            || lighting.bricks.shed(),
        )
    }

    /// Bytes of lit voxels held now.
    pub fn bytes(&self) -> usize {
        self.cache.bytes()
    }
}

/// Everything needed to light one brick of one frame.
pub struct Lighting<'a> {
    source: Source<'a>,
    bricks: &'a ClassifiedBricks,
    /// The frame, for the cache of classified bricks.
    frame: u64,
    material: Material,
    /// `None`: unlit, the colour is the material colour.
    light: Option<FrameLight>,
    /// With shadows, the light reaching each voxel ([`crate::shadows`]).
    light_reaching: Option<&'a LightVolume>,
    /// With ambient occlusion, the ambient light reaching each voxel
    /// ([`crate::shadows::ambient`]).
    ambient_reaching: Option<&'a AmbientVolume>,
    /// Bricks lit ([`Self::count`]).
    lit: AtomicUsize,
}

impl<'a> Lighting<'a> {
    /// The lighting of `bricks` (classified from `source`) under
    /// `lighting` (`None` for unlit rendering) in frame `frame`, shadowed
    /// by `light_reaching` (`None`: no shadows).
    pub fn new(
        source: Source<'a>,
        bricks: &'a ClassifiedBricks,
        frame: u64,
        lighting: Option<(&Phong, &LightGeometry)>,
        light_reaching: Option<&'a LightVolume>,
    ) -> Self {
        Lighting {
            source,
            bricks,
            frame,
            material: Material::new(source.classifier),
            light: lighting.map(|(phong, light)| FrameLight::new(phong, light)),
            light_reaching,
            ambient_reaching: None,
            lit: AtomicUsize::new(0),
        }
    }

    /// The same, the ambient term scaled by the ambient light reaching each
    /// voxel, `ambient_reaching` (`None`: all of it).
    pub fn with_ambient(self, ambient_reaching: Option<&'a AmbientVolume>) -> Self {
        Lighting {
            ambient_reaching,
            ..self
        }
    }

    /// How many bricks were lit so far (a brick lit twice, into the
    /// cache's buffer and then into a scratch one, counts twice).
    pub fn count(&self) -> usize {
        self.lit.load(Ordering::Relaxed)
    }

    /// Lights occupied brick `n` into `out`: `lit × material`, clamped, and
    /// the stored opacity.
    pub fn shade(&self, n: usize, out: &mut [[f32; 4]; SLOTS]) {
        self.lit.fetch_add(1, Ordering::Relaxed);
        let mut scratch = None;
        let classified = (self.bricks).classified(n, self.frame, &self.source, &mut scratch);
        let (bricks, b) = (self.bricks, self.bricks.brick(n));
        let voxels = &classified.voxels;
        let mut values = [0.0f32; SLOTS];
        let volume = self.source.volume;
        crate::with_samples!(volume.samples(), |data| {
            slot_values(data, &bricks.grid, b, &mut values);
            if volume.is_labels() {
                // The colour of a hidden label's voxel: its shown
                // neighbour's (see `colour_value`), as the reference's.
                let classifier = self.source.classifier;
                let shown = |f: f32| classifier.unit_opacity(f) > 0.0;
                let [nx, ny, _] = volume.dims();
                let needed = &classified.needed;
                for (n, s) in slot_coords().enumerate() {
                    // Slots no occupied cell uses are never sampled.
                    if needed[n / 64] >> (n % 64) & 1 != 0 && !shown(values[n]) {
                        let at = bricks.grid.voxel_of_slot(b, s);
                        let voxel = [at % nx, (at / nx) % ny, at / (nx * ny)];
                        values[n] = colour_value(data, volume.dims(), voxel, shown);
                    }
                }
            }
        });
        // The light reaching a slot's voxel (slots past the volume's end
        // repeat its last voxel, as their values do).
        let last = bricks.grid.dims.map(|n| n - 1);
        let origin = bricks.grid.origin(b);
        let voxel = |s: usize| {
            let local = [s % SIDE, (s / SIDE) % SIDE, s / (SIDE * SIDE)];
            std::array::from_fn(|a| (origin[a] + local[a]).min(last[a]))
        };
        let reaching = |s: usize| self.light_reaching.map_or(1.0, |light| light.at(voxel(s)));
        let ambient = |s: usize| (self.ambient_reaching).map_or(1.0, |a| a.at(voxel(s)));
        // Four slots at a time, one per SIMD lane.
        let mut group = |slots: [usize; 4], lanes: usize| {
            let colours = shade4(
                slots.map(|s| &voxels[s]),
                f32x4::new(slots.map(|s| values[s])),
                self.light.as_ref(),
                f32x4::new(slots.map(reaching)),
                f32x4::new(slots.map(ambient)),
                &self.material,
            );
            for (lane, colour) in colours.iter().take(lanes).enumerate() {
                out[slots[lane]] = colour.to_array();
            }
        };
        // Slots that are no occupied cell's corner are never sampled (64 is
        // a multiple of 4, so a group's bits are in one word).
        let needed = &classified.needed;
        for s in (0..SLOTS - 3).step_by(4) {
            if needed[s / 64] >> (s % 64) & 0xF != 0 {
                group([s, s + 1, s + 2, s + 3], 4);
            }
        }
        // The last slot (SLOTS = 4·182 + 1), in every lane.
        group([SLOTS - 1; 4], 1);
    }
}

/// The values of brick `b`'s slots, from the volume's samples `data`: rows
/// of slots along x are rows of the volume, the last voxel repeated past
/// its end.
fn slot_values<T: Sample>(data: &[T], grid: &BrickGrid, b: [usize; 3], values: &mut [f32; SLOTS]) {
    for s in slot_coords().step_by(SIDE) {
        let start = grid.voxel_of_slot(b, s);
        let end = grid.voxel_of_slot(b, [SIDE - 1, s[1], s[2]]);
        let row = &data[start..=end];
        let first = SIDE * (s[1] + SIDE * s[2]);
        for (i, v) in values[first..first + SIDE].iter_mut().enumerate() {
            *v = row[i.min(row.len() - 1)].to_f32();
        }
    }
}

/// The RGBA of four voxels with values `values`, reached by the fraction
/// `reaching` of the light and `ambient` of the ambient light (which is
/// all the light of an unlit frame).
#[inline]
fn shade4(
    voxels: [&Voxel; 4],
    values: f32x4,
    light: Option<&FrameLight>,
    reaching: f32x4,
    ambient: f32x4,
    material: &Material,
) -> [f32x4; 4] {
    let [x, y, z, alpha] = unpack4(voxels);
    let [mr, mg, mb] = material.at(values);
    let (r, g, b) = match light {
        Some(light) => {
            let [lr, lg, lb] = light.lit(x, y, z, reaching, ambient);
            (lr * mr, lg * mg, lb * mb)
        }
        None => (mr * ambient, mg * ambient, mb * ambient),
    };
    let unit = |c: f32x4| c.fast_max(f32x4::ZERO).fast_min(f32x4::ONE);
    f32x4::transpose([unit(r), unit(g), unit(b), alpha * f32x4::splat(1.0 / UNIT)])
}

/// Four voxels as SIMD lanes: their normals' x, y and z, and their
/// opacities, in the stored units. Each pair of voxels is one 16-byte
/// vector of `i16`, widened to `i32` and converted.
#[inline]
fn unpack4(v: [&Voxel; 4]) -> [f32x4; 4] {
    let pair = |a: &Voxel, b: &Voxel| {
        let words = i16x8::new([
            a.normal[0],
            a.normal[1],
            a.normal[2],
            a.alpha as i16,
            b.normal[0],
            b.normal[1],
            b.normal[2],
            b.alpha as i16,
        ]);
        let [lo, hi]: [i32x4; 2] = cast(i32x8::from_i16x8(words));
        [f32x4::from_i32x4(lo), f32x4::from_i32x4(hi)]
    };
    let [v0, v1] = pair(v[0], v[1]);
    let [v2, v3] = pair(v[2], v[3]);
    let [x, y, z, alpha] = f32x4::transpose([v0, v1, v2, v3]);
    // The opacity is a `u16`: undo the sign extension.
    let alpha = alpha
        .simd_lt(f32x4::ZERO)
        .select(alpha + f32x4::splat(65536.0), alpha);
    [x, y, z, alpha]
}

/// One frame's lighting, reduced to what each voxel needs.
#[derive(Debug, Clone, Copy)]
struct FrameLight {
    /// `Cs·ka`, `Cs·kd`, `Cs·ks` per channel (each in every lane).
    ambient: [f32x4; 3],
    diffuse: [f32x4; 3],
    specular: [f32x4; 3],
    shininess: Exponent,
    /// `V`, `L` and `H`, in units of the stored normals (1/32767), per
    /// component.
    to_viewer: [f32x4; 3],
    to_light: [f32x4; 3],
    half: [f32x4; 3],
}

impl FrameLight {
    fn new(phong: &Phong, light: &LightGeometry) -> Self {
        let cs = phong.light_color;
        let scaled = |v: glam::Vec3| (v / NORMAL_UNIT).to_array().map(f32x4::splat);
        let times_cs = |k: [f32; 3]| std::array::from_fn(|c| f32x4::splat(cs[c] * k[c]));
        FrameLight {
            ambient: times_cs(phong.ambient),
            diffuse: times_cs(phong.diffuse),
            specular: times_cs(phong.specular),
            shininess: Exponent::new(phong.shininess),
            to_viewer: scaled(light.to_viewer),
            to_light: scaled(light.to_light),
            half: scaled(light.half),
        }
    }

    /// The lit colour (before the material), per channel, of four voxels
    /// whose quantised unit normals have components `x`, `y` and `z`,
    /// reached by the fraction `reaching` of the light and `ambient` of the
    /// ambient light, as in [`Phong::shade_reached`].
    #[inline]
    fn lit(&self, x: f32x4, y: f32x4, z: f32x4, reaching: f32x4, ambient: f32x4) -> [f32x4; 3] {
        let dot = |d: [f32x4; 3]| x * d[0] + y * d[1] + z * d[2];
        let (diffuse, highlight) = two_sided(
            dot(self.to_viewer),
            dot(self.to_light),
            dot(self.half),
            self.shininess,
        );
        let (diffuse, highlight) = (diffuse * reaching, highlight * reaching);
        std::array::from_fn(|c| {
            reflect(
                self.ambient[c] * ambient,
                self.diffuse[c],
                self.specular[c],
                diffuse,
                highlight,
            )
        })
    }
}

/// The material colour function of one classifier, as a sum of clamped
/// ramps: `f(t) = v₀ + Σᵢ (vᵢ₊₁ − vᵢ)·clamp((t − tᵢ)/(tᵢ₊₁ − tᵢ), 0, 1)`,
/// a step where `tᵢ₊₁ = tᵢ` (the value after the jump, as
/// [`crate::transfer::function::PiecewiseLinear::eval`] takes it). It
/// equals the piecewise-linear function exactly, up to rounding, and needs
/// no search for the segment, so four voxels go through it at once.
struct Material {
    /// `(lo, 1/(hi − lo))` of the classifier's normalisation, in every lane.
    lo: f32x4,
    inv_range: f32x4,
    /// The value below the first point; white without a colour function.
    first: [f32x4; 3],
    /// Per segment: `tᵢ`, `1/(tᵢ₊₁ − tᵢ)` (`None` for a jump) and
    /// `vᵢ₊₁ − vᵢ`, in every lane.
    segments: Vec<(f32x4, Option<f32x4>, [f32x4; 3])>,
    /// A colour function of more than [`MAX_RAMPS`] segments (a colour
    /// map's 128, a label table's two per label), evaluated lane by lane
    /// by binary search instead, as the classifier does.
    many: Option<PiecewiseLinear<3>>,
}

/// The most segments the material is summed over as ramps: each costs
/// seven SIMD operations for four voxels, a binary search over 128 points
/// about as much as ten of them. A colour map's 128 ramps made lighting
/// take 47 % of a frame of a dense volume under a faint transfer function.
const MAX_RAMPS: usize = 16;

impl Material {
    fn new(classifier: &Classifier) -> Self {
        let points = classifier.color().map_or(&[][..], |c| c.points());
        let (lo, inv_range) = classifier.normalisation();
        let many = (points.len() > MAX_RAMPS + 1)
            .then(|| classifier.color().cloned())
            .flatten();
        Material {
            lo: f32x4::splat(lo),
            inv_range: f32x4::splat(inv_range),
            first: points.first().map_or([1.0; 3], |p| p.1).map(f32x4::splat),
            segments: (if many.is_some() { &[][..] } else { points })
                .windows(2)
                .map(|w| {
                    let ((t0, v0), (t1, v1)) = (w[0], w[1]);
                    let inv = (t1 > t0).then(|| f32x4::splat(1.0 / (t1 - t0)));
                    let step = std::array::from_fn(|c| f32x4::splat(v1[c] - v0[c]));
                    (f32x4::splat(t0), inv, step)
                })
                .collect(),
            many,
        }
    }

    /// The material colour, per channel, of four voxels of `values`.
    #[inline]
    fn at(&self, values: f32x4) -> [f32x4; 3] {
        let mut colour = self.first;
        // As `Classifier::normalise`, lane by lane.
        let t = (values - self.lo) * self.inv_range;
        if let Some(function) = &self.many {
            let lanes = t.to_array().map(|t| function.eval(t));
            return std::array::from_fn(|c| f32x4::new(lanes.map(|rgb| rgb[c])));
        }
        for (t0, inv, step) in &self.segments {
            let d = t - *t0;
            let ramp = match inv {
                Some(inv) => (d * *inv).fast_max(f32x4::ZERO).fast_min(f32x4::ONE),
                None => d.simd_ge(f32x4::ZERO).select(f32x4::ONE, f32x4::ZERO),
            };
            for c in 0..3 {
                colour[c] += step[c] * ramp;
            }
        }
        colour
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bricks::occupied::quantise_normal;
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::function::PiecewiseLinear;
    use glam::Vec3;

    #[test]
    fn quantised_shading_is_within_a_twentieth_of_a_level_of_phong() {
        // Normals all round the sphere and zero ones, several lights: the
        // stored normals cost well under 1/255.
        let phongs = [
            Phong::default(),
            Phong {
                ambient: [0.2, 0.1, 0.0],
                diffuse: [0.5, 0.9, 0.3],
                specular: [0.6, 0.2, 1.0],
                shininess: 7.5,
                light_color: [1.0, 0.8, 0.6],
            },
        ];
        let lights = [
            LightGeometry::headlight(Vec3::new(0.3, -0.8, 0.5).normalize()),
            LightGeometry::new(Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.0, 0.0, 1.0)),
        ];
        let mut worst = 0.0f32;
        for phong in &phongs {
            for light in &lights {
                let frame = FrameLight::new(phong, light);
                for i in (0..2000).step_by(4) {
                    // A Fibonacci sphere of gradient directions, varied
                    // lengths, and every 25th gradient zero.
                    let gradient = |i: usize| {
                        let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
                        let r = (1.0 - z * z).sqrt();
                        let phi = i as f32 * 2.399_963;
                        let length = if i.is_multiple_of(25) {
                            0.0
                        } else {
                            0.01 + i as f32
                        };
                        Vec3::new(r * phi.cos(), r * phi.sin(), z) * length
                    };
                    let g: [Vec3; 4] = std::array::from_fn(|k| gradient(i + k));
                    let voxels = g.map(|g| Voxel {
                        normal: quantise_normal(g.to_array()),
                        alpha: 0,
                    });
                    let [x, y, z, _] = unpack4(voxels.each_ref());
                    let lit = frame.lit(x, y, z, f32x4::ONE, f32x4::ONE);
                    for (k, g) in g.iter().enumerate() {
                        let exact = phong.shade(*g, light);
                        for c in 0..3 {
                            let got = lit[c].to_array()[k];
                            worst = worst.max((got - exact[c]).abs());
                        }
                    }
                }
            }
        }
        assert!(worst < 1.0 / 255.0 / 20.0, "{worst}");
        println!("largest quantised-shading error: {worst:e}");
    }

    #[test]
    fn materials_are_the_classifiers() {
        let color = PiecewiseLinear::new(
            "color",
            vec![
                (0.1, [0.2, 0.3, 0.4]),
                (0.5, [0.9, 0.1, 0.0]),
                (0.5, [0.0, 1.0, 0.5]),
                (0.8, [1.0, 1.0, 1.0]),
            ],
        )
        .unwrap();
        let c = Classifier::new(
            (-2.0, 3.0),
            OpacityMap::Ramp { p: 0.0, q: 1.0 },
            Some(color),
            1.0,
        );
        let m = Material::new(&c);
        for i in (0..=1000).step_by(4) {
            let f: [f32; 4] = std::array::from_fn(|k| -3.0 + 7.0 * (i + k) as f32 / 1000.0);
            let got = m.at(f32x4::new(f));
            for (k, f) in f.iter().enumerate() {
                let want = c.material(*f);
                for ch in 0..3 {
                    let g = got[ch].to_array()[k];
                    assert!((g - want[ch]).abs() < 1e-6, "{f}: {g} vs {want:?}");
                }
            }
        }
        // The jump at t = 0.5 (f = 0.5) takes the value after it.
        let at_jump = m.at(f32x4::splat(0.5)).map(|c| c.to_array()[0]);
        assert_eq!(c.material(0.5), [0.0, 1.0, 0.5]);
        for ch in 0..3 {
            assert!((at_jump[ch] - [0.0, 1.0, 0.5][ch]).abs() < 1e-6);
        }
        let white = Classifier::new((0.0, 1.0), OpacityMap::Ramp { p: 0.0, q: 1.0 }, None, 1.0);
        let w = Material::new(&white).at(f32x4::splat(0.3));
        assert!(w.iter().all(|c| *c == f32x4::ONE));
    }

    #[test]
    fn lit_and_unlit_voxels_take_their_material_and_opacity() {
        let color = PiecewiseLinear::constant([1.0, 0.5, 0.0]);
        let c = Classifier::new(
            (0.0, 1.0),
            OpacityMap::Ramp { p: 0.0, q: 1.0 },
            Some(color),
            1.0,
        );
        let material = Material::new(&c);
        let frame = FrameLight::new(&Phong::default(), &LightGeometry::headlight(Vec3::X));
        let flat = Voxel {
            normal: [0; 3],
            alpha: 65535,
        };
        let facing = Voxel {
            normal: [-32767, 0, 0],
            alpha: 32768,
        };
        let voxels = [&flat, &facing, &flat, &facing];
        let lit = shade4(
            voxels,
            f32x4::splat(0.5),
            Some(&frame),
            f32x4::ONE,
            f32x4::ONE,
            &material,
        );
        // Ambient only, then full light (ka + kd + ks = 1) on the back face.
        assert_eq!(lit[0].to_array(), [0.1, 0.05, 0.0, 1.0]);
        let full = lit[1].to_array();
        assert!((full[0] - 1.0).abs() < 1e-6 && (full[1] - 0.5).abs() < 1e-6);
        assert_eq!(full[3], 32768.0 / UNIT);
        let unlit = shade4(
            voxels,
            f32x4::splat(0.5),
            None,
            f32x4::ONE,
            f32x4::ONE,
            &material,
        );
        assert_eq!(unlit[1].to_array(), [1.0, 0.5, 0.0, 32768.0 / UNIT]);
        // Half the ambient light: half the ambient term, and half an unlit
        // voxel's colour; the light's terms unchanged.
        let half = f32x4::splat(0.5);
        let occluded = shade4(voxels, half, Some(&frame), f32x4::ONE, half, &material);
        assert_eq!(occluded[0].to_array(), [0.05, 0.025, 0.0, 1.0]);
        let full_occluded = occluded[1].to_array();
        assert!((full_occluded[0] - 0.95).abs() < 1e-6, "{full_occluded:?}");
        let unlit = shade4(voxels, half, None, f32x4::ONE, half, &material);
        assert_eq!(unlit[1].to_array(), [0.5, 0.25, 0.0, 32768.0 / UNIT]);
    }
}
