//! The `Volume`: a regular grid of scalar samples with physical geometry.
//!
//! Voxels are grid *points* (the paper's `g_ijk`, VTK's point data): voxel
//! `(i, j, k)` sits at `origin + (i·dx, j·dy, k·dz)`, so the volume spans
//! `(n − 1)·spacing` along each axis and a cell is bounded by eight voxels.
//! Values are stored with x varying fastest, `index = x + nx·(y + ny·z)`,
//! in the type they came in ([`Samples`]: `u8`, `i8`, `u16`, `i16` or
//! `f32`), and read as `f32`. [`Volume::to_log10`] puts values that span
//! decades on a log scale.

pub mod histogram;
pub mod non_finite;
pub mod piece;
mod sample;
mod samples;
mod source;
mod store;

pub use sample::{Sample, SampleType};
pub use samples::Samples;
pub use source::{SourceError, SourceErrorKind, VolumeSource, check_box};
pub use store::{External, ExternalBytes, ExternalError, Store};

use glam::DVec3;
use std::borrow::Cow;
use thiserror::Error;

/// Why a grid could not be made into a [`Volume`].
#[derive(Debug, Error, Clone, PartialEq)]
pub enum VolumeError {
    #[error("dimensions {0}x{1}x{2}: every axis needs at least 2 points to span a volume")]
    TooThin(usize, usize, usize),
    #[error("dimensions {0}x{1}x{2} overflow the address space")]
    DimsOverflow(usize, usize, usize),
    #[error("dimensions {dims:?} need {expected} values but {actual} were given")]
    LengthMismatch {
        dims: [usize; 3],
        expected: usize,
        actual: usize,
    },
    #[error("spacing ({0}, {1}, {2}) must be finite and positive on every axis")]
    BadSpacing(f64, f64, f64),
    #[error("origin ({0}, {1}, {2}) must be finite")]
    BadOrigin(f64, f64, f64),
    #[error("a log scale needs a positive value, but the largest value is {0}")]
    NoPositiveValue(f32),
}

/// A regular grid of scalars with per-axis spacing and an origin.
#[derive(Debug, Clone, PartialEq)]
pub struct Volume {
    dims: [usize; 3],
    spacing: DVec3,
    origin: DVec3,
    samples: Samples,
    /// Whether the values are labels ([`Volume::as_labels`]).
    labels: bool,
}

/// Number of points of a grid of `dims`, or `None` if it overflows `usize`.
pub fn checked_point_count(dims: [usize; 3]) -> Option<usize> {
    dims[0].checked_mul(dims[1])?.checked_mul(dims[2])
}

impl Volume {
    /// A volume with unit spacing and its first voxel at the world origin.
    ///
    /// `data` holds `nx·ny·nz` values, x fastest. Every axis needs at least
    /// two points: a volume with no extent along an axis cannot be ray cast.
    pub fn new(dims: [usize; 3], data: Vec<f32>) -> Result<Self, VolumeError> {
        Self::from_samples(dims, data)
    }

    /// [`Volume::new`] with samples of any [`SampleType`], kept in it.
    pub fn from_samples(
        dims: [usize; 3],
        samples: impl Into<Samples>,
    ) -> Result<Self, VolumeError> {
        let samples = samples.into();
        let [nx, ny, nz] = dims;
        if nx < 2 || ny < 2 || nz < 2 {
            return Err(VolumeError::TooThin(nx, ny, nz));
        }
        let expected = checked_point_count(dims).ok_or(VolumeError::DimsOverflow(nx, ny, nz))?;
        if samples.len() != expected {
            return Err(VolumeError::LengthMismatch {
                dims,
                expected,
                actual: samples.len(),
            });
        }
        Ok(Volume {
            dims,
            spacing: DVec3::ONE,
            origin: DVec3::ZERO,
            samples,
            labels: false,
        })
    }

    /// A volume whose value at each voxel is `f(world position)`.
    pub fn from_fn(
        dims: [usize; 3],
        spacing: DVec3,
        origin: DVec3,
        f: impl Fn(DVec3) -> f32,
    ) -> Result<Self, VolumeError> {
        let [nx, ny, nz] = dims;
        let count = checked_point_count(dims).ok_or(VolumeError::DimsOverflow(nx, ny, nz))?;
        let mut data = Vec::with_capacity(count.min(1 << 31));
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let p = origin + DVec3::new(i as f64, j as f64, k as f64) * spacing;
                    data.push(f(p));
                }
            }
        }
        Volume::new(dims, data)?
            .with_spacing(spacing)?
            .with_origin(origin)
    }

    /// The same grid with another voxel spacing (world units per voxel step).
    pub fn with_spacing(mut self, spacing: DVec3) -> Result<Self, VolumeError> {
        if !(spacing.is_finite() && spacing.min_element() > 0.0) {
            return Err(VolumeError::BadSpacing(spacing.x, spacing.y, spacing.z));
        }
        self.spacing = spacing;
        Ok(self)
    }

    /// The same grid with its first voxel at another world position.
    pub fn with_origin(mut self, origin: DVec3) -> Result<Self, VolumeError> {
        if !origin.is_finite() {
            return Err(VolumeError::BadOrigin(origin.x, origin.y, origin.z));
        }
        self.origin = origin;
        Ok(self)
    }

    /// The same grid read as labels (a segmentation): each value names a
    /// region rather than measuring something. Every path then shades with
    /// the gradient of the smoothed indicator of each voxel's own label
    /// (`kernels::gradient`) instead of the values' gradient,
    /// which between labels 1 and 5 would point at the larger number; a
    /// transfer function that is constant over each label
    /// (`transfer::labels`) classifies by label, pre-classified, so
    /// that no two labels' values are ever blended.
    pub fn as_labels(mut self) -> Self {
        self.labels = true;
        self
    }

    /// Marks the values as labels, or not ([`Self::as_labels`], in place).
    pub fn set_labels(&mut self, labels: bool) {
        self.labels = labels;
    }

    /// Whether the values are labels ([`Self::as_labels`]).
    pub fn is_labels(&self) -> bool {
        self.labels
    }

    /// Points along x, y and z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// World distance between neighbouring voxels along x, y and z.
    pub fn spacing(&self) -> DVec3 {
        self.spacing
    }

    /// World position of voxel (0, 0, 0).
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// The samples, x fastest, in their stored type.
    pub fn samples(&self) -> &Samples {
        &self.samples
    }

    /// The samples, the volume given up (to hand them to another owner,
    /// such as a numpy array, without a copy).
    pub fn into_samples(self) -> Samples {
        self.samples
    }

    /// The type the samples are kept in.
    pub fn sample_type(&self) -> SampleType {
        self.samples.sample_type()
    }

    /// The values as `f32`, x fastest: the samples themselves for an `f32`
    /// volume, a converted copy for another type.
    pub fn values(&self) -> Cow<'_, [f32]> {
        match &self.samples {
            Samples::F32(data) => Cow::Borrowed(data),
            other => Cow::Owned(other.to_f32_vec()),
        }
    }

    /// The same volume with its samples converted to `f32`.
    pub fn to_f32(&self) -> Volume {
        self.with_samples(Samples::from(self.values().into_owned()))
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false: a volume has at least 2×2×2 voxels.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Linear index of voxel (i, j, k): `i + nx·(j + ny·k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Value at voxel (i, j, k).
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        self.samples.get(self.index(i, j, k))
    }

    /// The voxels `lo[a] ≤ i < hi[a]` as a volume of their own: the same
    /// sample type, spacing and labels, placed where they are in the world
    /// (its origin is voxel `lo`'s position). Reads only those voxels, so
    /// a box of a mapped volume touches only its own pages.
    ///
    /// # Panics
    /// If the box is not inside the grid or is thinner than two voxels on
    /// an axis (callers make it from the grid's dimensions).
    pub fn sub_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Volume {
        assert!(
            (0..3).all(|a| lo[a] + 2 <= hi[a] && hi[a] <= self.dims[a]),
            "box {lo:?}..{hi:?} of a {:?} grid",
            self.dims
        );
        let [nx, ny, _] = self.dims;
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let samples: Samples = crate::with_samples!(&self.samples, |data| {
            let mut out = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    let row = (z * ny + y) * nx;
                    out.extend_from_slice(&data[row + lo[0]..row + hi[0]]);
                }
            }
            Samples::from(out)
        });
        Volume {
            dims,
            spacing: self.spacing,
            origin: self.world_position(lo[0], lo[1], lo[2]),
            samples,
            labels: self.labels,
        }
    }

    /// World position of voxel (i, j, k).
    pub fn world_position(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.spacing
    }

    /// World size of the volume: `(n − 1)·spacing` per axis.
    pub fn extent(&self) -> DVec3 {
        let n = DVec3::new(
            (self.dims[0] - 1) as f64,
            (self.dims[1] - 1) as f64,
            (self.dims[2] - 1) as f64,
        );
        n * self.spacing
    }

    /// The world-space bounding box `(min corner, max corner)`.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.origin, self.origin + self.extent())
    }

    /// World position of the centre of the bounding box.
    pub fn centre(&self) -> DVec3 {
        self.origin + 0.5 * self.extent()
    }

    /// Number of NaN or infinite values.
    pub fn count_non_finite(&self) -> usize {
        match &self.samples {
            Samples::F32(data) => data.iter().filter(|v| !v.is_finite()).count(),
            _ => 0,
        }
    }

    /// `(fmin, fmax)` over the finite values, or `None` if there are none.
    pub fn value_range(&self) -> Option<(f32, f32)> {
        fn range<T: Sample>(data: &[T]) -> Option<(f32, f32)> {
            let mut range: Option<(f32, f32)> = None;
            for v in data.iter().filter(|v| v.is_finite()) {
                let v = v.to_f32();
                range = Some(match range {
                    None => (v, v),
                    Some((lo, hi)) => (lo.min(v), hi.max(v)),
                });
            }
            range
        }
        crate::with_samples!(&self.samples, |data| range(data))
    }

    /// The same grid with every value `f` replaced by `log10 f`, for data
    /// that span decades (densities), as yt's `take_log`. Values `<= 0`
    /// have no logarithm: they become the log of the smallest positive
    /// finite value in the volume, the bottom of the scale, so that they
    /// show as the lowest value (yt leaves them `−inf` or NaN and masks
    /// them). NaN stays NaN and `+∞` stays `+∞` (the renderer refuses
    /// both, or renders them as empty space: [`NonFinite`](crate::NonFinite)). A volume with no positive finite value is refused.
    pub fn to_log10(&self) -> Result<Volume, VolumeError> {
        match self.smallest_positive() {
            Some(smallest) => Ok(self.to_log10_above(smallest)),
            None => {
                let largest = self
                    .values()
                    .iter()
                    .copied()
                    .fold(f32::NEG_INFINITY, f32::max);
                Err(VolumeError::NoPositiveValue(largest))
            }
        }
    }

    /// The smallest positive finite value, if any: the bottom of
    /// [`Self::to_log10`]'s scale.
    pub fn smallest_positive(&self) -> Option<f32> {
        let smallest = (self.values().iter().copied())
            .filter(|v| *v > 0.0 && v.is_finite())
            .fold(f32::INFINITY, f32::min);
        (smallest < f32::INFINITY).then_some(smallest)
    }

    /// [`Self::to_log10`] with values `<= 0` at `log10 smallest`: a piece
    /// of a larger volume takes the whole volume's smallest positive value,
    /// so that its scale is the whole's.
    pub fn to_log10_above(&self, smallest: f32) -> Volume {
        // In f64, so that exact powers of ten give exact exponents.
        let log = |v: f32| (v as f64).log10() as f32;
        let floor = log(smallest);
        let data = (self.values().iter())
            .map(|&v| if v <= 0.0 { floor } else { log(v) })
            .collect::<Vec<f32>>();
        self.with_samples(Samples::from(data))
    }

    /// This volume's grid with other samples (as many, x fastest).
    fn with_samples(&self, samples: Samples) -> Volume {
        debug_assert_eq!(samples.len(), self.len());
        Volume {
            dims: self.dims,
            spacing: self.spacing,
            origin: self.origin,
            samples,
            labels: self.labels,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_is_x_fastest() {
        let v = Volume::new([2, 3, 4], (0..24).map(|i| i as f32).collect()).unwrap();
        assert_eq!(v.index(1, 0, 0), 1);
        assert_eq!(v.index(0, 1, 0), 2);
        assert_eq!(v.index(0, 0, 1), 6);
        assert_eq!(v.get(1, 2, 3), (1 + 2 * (2 + 3 * 3)) as f32);
    }

    #[test]
    fn geometry_follows_point_convention() {
        let v = Volume::new([3, 5, 9], vec![0.0; 135])
            .unwrap()
            .with_spacing(DVec3::new(1.0, 0.5, 2.0))
            .unwrap()
            .with_origin(DVec3::new(-1.0, 2.0, 3.0))
            .unwrap();
        assert_eq!(v.extent(), DVec3::new(2.0, 2.0, 16.0));
        assert_eq!(v.world_position(2, 4, 8), DVec3::new(1.0, 4.0, 19.0));
        assert_eq!(v.centre(), DVec3::new(0.0, 3.0, 11.0));
    }

    #[test]
    fn rejects_bad_grids() {
        assert_eq!(
            Volume::new([1, 4, 4], vec![0.0; 16]),
            Err(VolumeError::TooThin(1, 4, 4))
        );
        assert!(matches!(
            Volume::new([2, 2, 2], vec![0.0; 7]),
            Err(VolumeError::LengthMismatch { expected: 8, .. })
        ));
        assert!(matches!(
            Volume::new([usize::MAX, 2, 2], vec![]),
            Err(VolumeError::DimsOverflow(..))
        ));
        let v = Volume::new([2, 2, 2], vec![0.0; 8]).unwrap();
        assert!(v.clone().with_spacing(DVec3::new(1.0, 0.0, 1.0)).is_err());
        assert!(
            v.clone()
                .with_spacing(DVec3::new(1.0, f64::NAN, 1.0))
                .is_err()
        );
        assert!(v.with_origin(DVec3::new(f64::INFINITY, 0.0, 0.0)).is_err());
    }

    #[test]
    fn value_range_skips_non_finite() {
        let v = Volume::new(
            [2, 2, 2],
            vec![1.0, f32::NAN, -2.0, 3.0, 0.0, f32::INFINITY, 0.5, 0.0],
        )
        .unwrap();
        assert_eq!(v.value_range(), Some((-2.0, 3.0)));
        assert_eq!(v.count_non_finite(), 2);
    }

    #[test]
    fn log_scale_gives_the_exponent_and_floors_non_positive_values() {
        // 10^k for k = −6..=9 at the first 16 voxels, then 0, a negative
        // value, NaN and +∞; spacing and origin kept.
        let mut data: Vec<f32> = (-6..=9).map(|k| 10f64.powi(k) as f32).collect();
        data.extend([0.0, -3.0, f32::NAN, f32::INFINITY]);
        data.resize(24, 1.0);
        let v = Volume::new([2, 3, 4], data)
            .unwrap()
            .with_spacing(DVec3::new(1.0, 2.0, 3.0))
            .unwrap()
            .with_origin(DVec3::new(-1.0, 0.5, 7.0))
            .unwrap();
        let log = v.to_log10().unwrap();
        assert_eq!(log.dims(), v.dims());
        assert_eq!(log.bounds(), v.bounds());
        for (i, k) in (-6..=9).enumerate() {
            let got = log.values()[i];
            assert!((got - k as f32).abs() <= 1e-6, "10^{k}: {got}");
        }
        // Exact powers of ten that f32 holds exactly give exact exponents.
        for (i, k) in (0..=9).enumerate() {
            assert_eq!(log.values()[6 + i], k as f32);
        }
        // 0 and −3 sit at the bottom of the scale, log10(1e−6).
        assert_eq!(log.values()[16], log.values()[0]);
        assert_eq!(log.values()[17], log.values()[0]);
        assert!(log.values()[18].is_nan());
        assert_eq!(log.values()[19], f32::INFINITY);
        assert_eq!(log.values()[20], 0.0);
    }

    #[test]
    fn log_scale_refuses_a_volume_with_no_positive_value() {
        let v = Volume::new([2, 2, 2], vec![0.0, -1.0, -2.5, 0.0, -0.1, 0.0, 0.0, -4.0]).unwrap();
        let err = v.to_log10().unwrap_err();
        assert_eq!(err, VolumeError::NoPositiveValue(0.0));
        assert_eq!(
            err.to_string(),
            "a log scale needs a positive value, but the largest value is 0"
        );
        // Only +∞ is positive: there is no finite bottom for the scale.
        let inf = Volume::new(
            [2, 2, 2],
            vec![f32::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        );
        assert!(inf.unwrap().to_log10().is_err());
    }
}
