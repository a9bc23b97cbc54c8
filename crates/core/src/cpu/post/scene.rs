//! What a frame's rays read ([`Scene`]): the voxels' scalars and
//! gradients packed together ([`packed_voxels`]), the bricks, the
//! classifier and the light; and what the rays did ([`PostWork`]).

use rayon::prelude::*;
use wide::f32x4;

use crate::bricks::macrocells::Macrocells;
use crate::kernels::phong::{LightGeometry, Phong};
use crate::shadows::ambient_volume::AmbientVolume;
use crate::shadows::light_volume::LightVolume;
use crate::transfer::classifier::Classifier;
use crate::volume::non_finite::NonFiniteMask;
use crate::volume::{Sample, Volume};

/// Bytes per voxel of the packed values and gradients ([`packed_voxels`]).
pub(crate) const BYTES_PER_VOXEL: usize = size_of::<f32x4>();

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
    /// With shadows, the light reaching each voxel ([`crate::shadows`]).
    pub light: Option<&'a LightVolume>,
    /// With ambient occlusion, the ambient light reaching each voxel
    /// ([`crate::shadows::ambient`]).
    pub ambient: Option<&'a AmbientVolume>,
}

/// Every voxel's world gradient (from `gradients`, see
/// [`crate::kernels::gradient::gradients`]) and scalar as the lanes
/// `(gx, gy, gz, f)`, x fastest: what [`render`](super::render) reads.
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
