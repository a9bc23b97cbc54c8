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
//! the opacities of the slices beside it). Rows with nothing opaque within
//! reach get 1 without work.
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
use glam::{DVec3, Vec3};
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
}

impl Row {
    fn new(nx: usize) -> Self {
        Row {
            product: vec![0.0; nx],
            sum: vec![0.0; nx],
            weights: vec![0.0; nx],
            normal: std::array::from_fn(|_| vec![0.0; nx]),
            all: vec![0.0; nx],
        }
    }
}

impl AmbientVolume {
    /// The ambient occlusion of `rays` in a grid of `dims` voxels
    /// `spacing` apart whose voxel `(i, j, k)` has the opacity of one
    /// voxel's length `unit(i, j, k)`.
    pub fn compute(
        dims: [usize; 3],
        spacing: DVec3,
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
            .zip(rays.world_directions(spacing))
            .map(|(d, world)| Walk {
                step: d.step,
                steps: d.steps,
                plane: lengths
                    .iter()
                    .position(|&x| x == d.length)
                    .expect("a length"),
                world: world.as_vec3(),
            })
            .collect();
        let spacing = spacing.as_vec3().to_array();
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
            out.par_chunks_mut(nx).enumerate().for_each_init(
                || Row::new(nx),
                |row, (j, out)| {
                    let rows = j.saturating_sub(ry)..=(j + ry).min(ny - 1);
                    let near = slices.clone().any(|s| {
                        let opaque = &ring[s % ring_size].opaque;
                        rows.clone().any(|y| opaque[y])
                    });
                    if !near {
                        out.fill(u16::MAX);
                        return;
                    }
                    // Each voxel's way out of the material, from the
                    // opacities beside it (slices k ± 1 are in the ring).
                    for i in 0..nx {
                        let n = Vec3::from(outward([i, j, k], dims, spacing, alpha))
                            .normalize_or_zero();
                        (0..3).for_each(|a| row.normal[a][i] = n[a]);
                        row.all[i] = f32::from(u8::from(n == Vec3::ZERO));
                    }
                    row.sum.fill(0.0);
                    row.weights.fill(0.0);
                    for walk in &walks {
                        let product = &mut row.product;
                        product.fill(1.0);
                        for m in 1..=walk.steps as isize {
                            let step = walk.step;
                            let (z, y) = (k as isize + m * step[2], j as isize + m * step[1]);
                            let dx = m * step[0];
                            if !(0..nz as isize).contains(&z)
                                || !(0..ny as isize).contains(&y)
                                || dx.unsigned_abs() >= nx
                            {
                                break;
                            }
                            let slice = &ring[z as usize % ring_size];
                            let at = (y as usize * ls + walk.plane) * nx;
                            let clear = &slice.clear[at..at + nx];
                            let shift = dx.unsigned_abs();
                            let (to, from) = if dx >= 0 {
                                (&mut product[..nx - shift], &clear[shift..])
                            } else {
                                (&mut product[shift..], &clear[..nx - shift])
                            };
                            for (p, c) in to.iter_mut().zip(from) {
                                *p *= c;
                            }
                        }
                        let [cx, cy, cz] = &row.normal;
                        let d = walk.world;
                        let terms = (row.sum.iter_mut().zip(row.weights.iter_mut()))
                            .zip(row.product.iter().zip(&row.all))
                            .zip(cx.iter().zip(cy).zip(cz));
                        for (((s, w), (p, all)), ((x, y), z)) in terms {
                            let weight = all + (d.x * x + d.y * y + d.z * z).max(0.0);
                            *s += weight * p;
                            *w += weight;
                        }
                    }
                    for (o, (s, w)) in out.iter_mut().zip(row.sum.iter().zip(&row.weights)) {
                        *o = ((s / w).min(1.0) * UNIT).round() as u16;
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
