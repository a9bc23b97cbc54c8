//! The fast path's ambient volume: every voxel's ambient occlusion
//! ([`super::ambient`]'s `A`), computed slice by slice.
//!
//! **How.** From a voxel, the rays' samples are voxels (the directions are
//! the lattice's), so `A` needs no interpolation: the product along each
//! ray is of the voxels' own `1 − α_d`. The slices within the rays' reach
//! `r` along z of the slice being computed, `k − r … k + r`, are kept in a
//! ring, each as one plane of `1 − α_d` per distinct step length. A row's
//! 26 products are taken a whole row at a time: for ray `d` and sample
//! `m`, row `j + m·d_y` of slice `k + m·d_z`, shifted by `m·d_x`,
//! multiplies the row's running product (a loop the compiler vectorises),
//! and a sample past the grid's end ends the ray there, as the reference's
//! does. The products are summed with each voxel's weights (the cosines
//! with its way out of the material, [`super::ambient::outward`], from
//! the opacities of the slices beside it). Only the voxels a sample can see
//! (with something opaque among the 27 around them) are computed, in runs
//! along each row; the others get 1, as the reference gives them, and
//! rows with nothing opaque within reach get 1 without a look.
//!
//! **Cost.** Per voxel the classifier once, one `powf` per distinct step
//! length (3 for equal spacings), and `Σ n_d` multiplies (160 at the
//! default radius of 8). `A` is kept as a `u16` per voxel
//! ([`BYTES_PER_VOXEL`]); the ring holds `(2r + 1)` planes per step length
//! in `f32` ([`AmbientVolume::ring_bytes`]). Rows of each slice are done in
//! parallel, each voxel's sum in one fixed order: the same at any thread
//! count.

use super::ambient::{AmbientRays, outward};
use crate::transfer::classifier::correct_opacity;
use glam::Vec3;
use rayon::prelude::*;

/// Bytes per voxel of an [`AmbientVolume`].
pub const BYTES_PER_VOXEL: usize = size_of::<u16>();

/// `A` is stored in units of `1/UNIT`.
const UNIT: f32 = u16::MAX as f32;

/// The ambient light reaching every voxel of a grid, for one radius and
/// one classification.
#[derive(Debug, Clone, PartialEq)]
pub struct AmbientVolume {
    dims: [usize; 3],
    /// x fastest.
    values: Vec<u16>,
}

/// One slice of the ring: `1 − α_d` per row and step length, the opacity
/// of one voxel's length, and whether each row holds anything opaque.
struct Slice {
    /// Row `j`'s plane of step length `l` is at `(j·L + l)·nx`.
    clear: Vec<f32>,
    /// Row `j` is at `j·nx`.
    alpha: Vec<f32>,
    opaque: Vec<bool>,
}

/// One ray as the rows are walked: its step, its samples, its plane among
/// a slice's step lengths, and its unit direction in world space.
struct Walk {
    step: [isize; 3],
    steps: usize,
    plane: usize,
    world: Vec3,
}

/// One thread's buffers for a row: the running product along a ray, the
/// weighted sum of the products and of the weights, and each voxel's way
/// out of the material (unit, by component; zero where there is none) and
/// whether there is none (1: every ray weighs 1; else 0), so that a ray's
/// weights are `all + max(0, d̂·N̂)` with no branch.
struct Row {
    product: Vec<f32>,
    sum: Vec<f32>,
    weights: Vec<f32>,
    normal: [Vec<f32>; 3],
    all: Vec<f32>,
    /// Whether a sample can see each voxel's colour.
    seen: Vec<bool>,
}

/// The slices in reach of the slice being computed.
struct Reach<'a> {
    ring: &'a [Slice],
    /// How many step lengths a slice has planes for.
    lengths: usize,
    dims: [usize; 3],
}

impl Reach<'_> {
    /// Row `y` of slice `z`'s plane `plane` of `1 − α_d`, if in the grid.
    #[inline]
    fn clear(&self, z: isize, y: isize, plane: usize) -> Option<&[f32]> {
        let [nx, ny, nz] = self.dims;
        if !(0..nz as isize).contains(&z) || !(0..ny as isize).contains(&y) {
            return None;
        }
        let slice = &self.ring[z as usize % self.ring.len()];
        let at = (y as usize * self.lengths + plane) * nx;
        Some(&slice.clear[at..at + nx])
    }
}

impl Row {
    fn new(nx: usize) -> Self {
        Row {
            product: vec![0.0; nx],
            sum: vec![0.0; nx],
            weights: vec![0.0; nx],
            normal: std::array::from_fn(|_| vec![0.0; nx]),
            all: vec![0.0; nx],
            seen: vec![false; nx],
        }
    }

    /// `A` of voxels `xs` of row `j` of slice `k` into `out`, from the
    /// rays `walks` through the slices in `reach`, each voxel's way out of
    /// the material `outward(i)`.
    fn occlude(
        &mut self,
        xs: std::ops::Range<usize>,
        walks: &[Walk],
        reach: &Reach,
        [j, k]: [usize; 2],
        out: &mut [u16],
        outward: impl Fn(usize) -> [f32; 3],
    ) {
        let nx = reach.dims[0];
        let (a, b) = (xs.start, xs.end);
        for i in xs.clone() {
            let n = Vec3::from(outward(i)).normalize_or_zero();
            (0..3).for_each(|c| self.normal[c][i] = n[c]);
            self.all[i] = f32::from(u8::from(n == Vec3::ZERO));
        }
        self.sum[a..b].fill(0.0);
        self.weights[a..b].fill(0.0);
        for walk in walks {
            let product = &mut self.product[a..b];
            product.fill(1.0);
            for m in 1..=walk.steps as isize {
                let step = walk.step;
                let (z, y) = (k as isize + m * step[2], j as isize + m * step[1]);
                let Some(clear) = reach.clear(z, y, walk.plane) else {
                    break;
                };
                // Voxels whose sample `m` is past the row's ends have
                // left the grid: their rays end there.
                let dx = m * step[0];
                let lo = (a as isize).max(-dx);
                let hi = (b as isize).min(nx as isize - dx);
                if lo >= hi {
                    break;
                }
                let to = &mut product[(lo as usize - a)..(hi as usize - a)];
                let from = &clear[(lo + dx) as usize..(hi + dx) as usize];
                for (p, c) in to.iter_mut().zip(from) {
                    *p *= c;
                }
            }
            let [cx, cy, cz] = &self.normal;
            let d = walk.world;
            let terms = (self.sum[a..b].iter_mut().zip(&mut self.weights[a..b]))
                .zip(self.product[a..b].iter().zip(&self.all[a..b]))
                .zip(cx[a..b].iter().zip(&cy[a..b]).zip(&cz[a..b]));
            for (((s, w), (p, all)), ((x, y), z)) in terms {
                let weight = all + (d.x * x + d.y * y + d.z * z).max(0.0);
                *s += weight * p;
                *w += weight;
            }
        }
        let done = self.sum[a..b].iter().zip(&self.weights[a..b]);
        for (o, (s, w)) in out.iter_mut().zip(done) {
            *o = ((s / w).min(1.0) * UNIT).round() as u16;
        }
    }
}

impl AmbientVolume {
    /// The ambient occlusion of `rays` in a grid of `dims` voxels (the
    /// rays' spacing apart) whose voxel `(i, j, k)` has the opacity of one
    /// voxel's length `unit(i, j, k)`.
    pub fn compute(
        dims: [usize; 3],
        rays: &AmbientRays,
        unit: impl Fn(usize, usize, usize) -> f32 + Sync,
    ) -> Self {
        let [nx, ny, nz] = dims;
        let lengths = rays.lengths();
        let ls = lengths.len();
        let [_, ry, rz] = rays.reach();
        let ring_size = 2 * rz + 1;
        let mut ring: Vec<Slice> = (0..ring_size)
            .map(|_| Slice {
                clear: vec![1.0; ny * ls * nx],
                alpha: vec![0.0; ny * nx],
                opaque: vec![false; ny],
            })
            .collect();
        let fill = |slice: &mut Slice, k: usize| {
            (slice.clear.par_chunks_mut(ls * nx))
                .zip(slice.alpha.par_chunks_mut(nx))
                .zip(slice.opaque.par_iter_mut())
                .enumerate()
                .for_each(|(j, ((rows, alphas), opaque))| {
                    *opaque = false;
                    for i in 0..nx {
                        let alpha = unit(i, j, k);
                        alphas[i] = alpha;
                        *opaque |= alpha > 0.0;
                        for (l, &length) in lengths.iter().enumerate() {
                            rows[l * nx + i] = if alpha > 0.0 {
                                1.0 - correct_opacity(alpha, length)
                            } else {
                                1.0
                            };
                        }
                    }
                });
        };
        let walks: Vec<Walk> = (rays.directions().iter())
            .map(|d| Walk {
                step: d.step,
                steps: d.steps,
                plane: lengths
                    .iter()
                    .position(|&x| x == d.length)
                    .expect("a length"),
                world: d.world.as_vec3(),
            })
            .collect();
        let spacing = rays.spacing().as_vec3().to_array();
        let mut values = vec![0u16; nx * ny * nz];
        for s in 0..rz.min(nz) {
            fill(&mut ring[s % ring_size], s);
        }
        for (k, out) in values.chunks_mut(nx * ny).enumerate() {
            if k + rz < nz {
                fill(&mut ring[(k + rz) % ring_size], k + rz);
            }
            let ring = &ring;
            let slices = k.saturating_sub(rz)..=(k + rz).min(nz - 1);
            let alpha = |i: usize, y: usize, z: usize| ring[z % ring_size].alpha[y * nx + i];
            let reach = Reach {
                ring,
                lengths: ls,
                dims,
            };
            out.par_chunks_mut(nx).enumerate().for_each_init(
                || Row::new(nx),
                |row, (j, out)| {
                    out.fill(u16::MAX);
                    let rows = j.saturating_sub(ry)..=(j + ry).min(ny - 1);
                    let near = slices.clone().any(|s| {
                        let opaque = &ring[s % ring_size].opaque;
                        rows.clone().any(|y| opaque[y])
                    });
                    if !near {
                        return;
                    }
                    // The voxels a sample can see: those with something
                    // opaque among the 27 around them (the reference
                    // marches only those, and gives the others 1).
                    row.seen.fill(false);
                    for z in k.saturating_sub(1)..=(k + 1).min(nz - 1) {
                        for y in j.saturating_sub(1)..=(j + 1).min(ny - 1) {
                            let alphas = &ring[z % ring_size].alpha[y * nx..(y + 1) * nx];
                            for (i, &a) in alphas.iter().enumerate() {
                                if a > 0.0 {
                                    let near = i.saturating_sub(1)..=(i + 1).min(nx - 1);
                                    row.seen[near].fill(true);
                                }
                            }
                        }
                    }
                    let mut a = 0;
                    while a < nx {
                        if !row.seen[a] {
                            a += 1;
                            continue;
                        }
                        let b = (a..nx).find(|&i| !row.seen[i]).unwrap_or(nx);
                        let outward = |i| outward([i, j, k], dims, spacing, alpha);
                        row.occlude(a..b, &walks, &reach, [j, k], &mut out[a..b], outward);
                        a = b;
                    }
                },
            );
        }
        AmbientVolume { dims, values }
    }

    /// The bytes a computation for `rays` in a grid of `dims` holds
    /// besides the volume: its ring of slices.
    pub fn ring_bytes(dims: [usize; 3], rays: &AmbientRays) -> usize {
        let [nx, ny, _] = dims;
        let slices = 2 * rays.reach()[2] + 1;
        slices * ny * ((rays.lengths().len() + 1) * nx * size_of::<f32>() + 1)
    }

    /// The grid's size.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The bytes kept.
    pub fn bytes(&self) -> usize {
        self.values.len() * BYTES_PER_VOXEL
    }

    /// The ambient light reaching voxel `(i, j, k)`, in `[0, 1]`.
    #[inline]
    pub fn at(&self, [i, j, k]: [usize; 3]) -> f32 {
        let [nx, ny, _] = self.dims;
        f32::from(self.values[i + nx * (j + ny * k)]) * (1.0 / UNIT)
    }

    /// The ambient light reaching index-space point `p` (in `[0, n − 1]³`),
    /// interpolated trilinearly between the voxels'.
    #[inline]
    pub fn sample(&self, p: Vec3) -> f32 {
        super::sample_voxels(self.dims, p, |v| self.at(v))
    }
}
