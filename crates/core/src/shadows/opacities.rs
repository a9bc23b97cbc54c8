//! Every voxel's opacity for the shadow rays' step, quantised: what the
//! light volume's sweeps read (`light_volume`).
//!
//! The light follows the camera unless it is fixed in the world (the
//! camera's key light), so an orbit sweeps a new light volume every
//! frame while the transfer function stays: classifying every voxel
//! again for each sweep was 56 of its 225 ms on the peers' 257³ cloud.
//! The opacities are kept instead, per classifier and step, as a `u16`
//! per voxel in units of `1/65535` (a sample's opacity off by at most
//! 7.6·10⁻⁶), which a sweep reads with one multiplication: 6.6 ms of the
//! 257³ cloud's sweep, where kept for a voxel's length and corrected for
//! the step through a table they took 12 to 21.
//!
//! A sweep reads them slice by slice across the axis the light is
//! closest to, a row at a time, so they are kept in that order
//! ([`VoxelOpacities::arrange`]): read from x-fastest storage, a light
//! closest to x would read a cache line for each voxel.

use rayon::prelude::*;

/// Bytes per voxel of [`VoxelOpacities`].
pub const BYTES_PER_VOXEL: usize = size_of::<u16>();

/// Opacities are stored in units of `1/UNIT`.
const UNIT: f64 = u16::MAX as f64;

/// The two axes across axis `a`, the lower first: a slice across `a`
/// is stored in rows along the first (see [`VoxelOpacities::arrange`]).
pub(crate) fn across(a: usize) -> (usize, usize) {
    match a {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Every voxel's opacity for a sample every `unit_world` world units.
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelOpacities {
    dims: [usize; 3],
    unit_world: f64,
    /// The axes from fastest to slowest in `values`.
    order: [usize; 3],
    values: Vec<u16>,
}

impl VoxelOpacities {
    /// The opacities `alpha(i, j, k)` of a grid of `dims` voxels, each for
    /// a sample every `unit_world` world units (slices in parallel).
    pub fn from_fn(
        dims: [usize; 3],
        unit_world: f64,
        alpha: impl Fn(usize, usize, usize) -> f32 + Sync,
    ) -> Self {
        let [nx, ny, _] = dims;
        let mut values = vec![0u16; dims.iter().product()];
        (values.par_chunks_mut(nx * ny).enumerate()).for_each(|(k, slice)| {
            for (n, value) in slice.iter_mut().enumerate() {
                let a = f64::from(alpha(n % nx, n / nx, k)).clamp(0.0, 1.0);
                *value = (a * UNIT).round() as u16;
            }
        });
        VoxelOpacities {
            dims,
            unit_world,
            order: [0, 1, 2],
            values,
        }
    }

    /// Stores the opacities slice by slice across axis `a`, each slice's
    /// rows along the lower of the other two axes (the sweep's order), if
    /// they are not so already: one pass over the grid, holding a second
    /// copy while it runs.
    pub fn arrange(&mut self, a: usize) {
        let (b, c) = across(a);
        let order = [b, c, a];
        if order == self.order {
            return;
        }
        let from = self.strides();
        let (nb, nc) = (self.dims[b], self.dims[c]);
        let mut values = vec![0u16; self.values.len()];
        if nb * nc > 0 {
            let old = &self.values;
            (values.par_chunks_mut(nb * nc).enumerate()).for_each(|(s, slice)| {
                for (ic, row) in slice.chunks_mut(nb).enumerate() {
                    let first = s * from[a] + ic * from[c];
                    let source = old[first..].iter().step_by(from[b]);
                    row.iter_mut().zip(source).for_each(|(v, &q)| *v = q);
                }
            });
        }
        self.order = order;
        self.values = values;
    }

    /// The grid's size, in voxels.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The length a voxel's opacity is for, in world units: the shadow
    /// rays' step.
    pub fn unit_world(&self) -> f64 {
        self.unit_world
    }

    /// Voxel `(i, j, k)`'s opacity, in [0, 1].
    pub fn at(&self, [i, j, k]: [usize; 3]) -> f32 {
        let [si, sj, sk] = self.strides();
        (f64::from(self.values[i * si + j * sj + k * sk]) / UNIT) as f32
    }

    /// Every voxel's opacity in units of `1/65535`, voxel `(i, j, k)` at
    /// `i·s₀ + j·s₁ + k·s₂` ([`Self::strides`]): x fastest, or as last
    /// [arranged](Self::arrange).
    pub(crate) fn values(&self) -> &[u16] {
        &self.values
    }

    /// Where voxel `(i, j, k)` is in [`Self::values`]: `i·s₀ + j·s₁ + k·s₂`.
    pub(crate) fn strides(&self) -> [usize; 3] {
        let [fast, middle, slow] = self.order;
        let mut strides = [0; 3];
        strides[fast] = 1;
        strides[middle] = self.dims[fast];
        strides[slow] = self.dims[fast] * self.dims[middle];
        strides
    }
}
