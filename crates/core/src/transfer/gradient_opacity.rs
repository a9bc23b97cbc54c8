//! Gradient-magnitude opacity: opacity scaled by how steeply the data
//! change, so that boundaries between materials show and the insides of
//! uniform regions fade.
//!
//! Levoy 1988 (eq. 5) makes the opacity of region boundaries proportional
//! to `|∇f|`; VTK's volume property multiplies the scalar opacity by a
//! gradient-opacity function of `|∇f|`. Here that function is a clamped
//! linear ramp of the relative magnitude `m = |∇f| / max|∇f|` (the
//! maximum over the volume's voxels): 0 for `m <= lo`, 1 for `m >= hi`,
//! `(m − lo)/(hi − lo)` between. Relative magnitudes keep the same `LO,HI`
//! meaningful across data in any units.

use crate::error::SettingError;

/// The ramp of one volume: `factor(|∇f|)` in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradientOpacity {
    lo: f32,
    /// `1/(hi − lo)`.
    inv_width: f32,
    /// `1/max|∇f|`, or 0 for a volume with no gradient anywhere (every
    /// `m` is then 0).
    inv_max: f32,
}

impl GradientOpacity {
    /// The ramp from `lo` to `hi` (fractions of `max_gradient`, the
    /// largest world gradient magnitude in the volume).
    pub fn new((lo, hi): (f32, f32), max_gradient: f32) -> Self {
        GradientOpacity {
            lo,
            inv_width: 1.0 / (hi - lo),
            inv_max: if max_gradient > 0.0 {
                1.0 / max_gradient
            } else {
                0.0
            },
        }
    }

    /// Checks `0 <= lo < hi <= 1`.
    pub fn validate((lo, hi): (f32, f32)) -> Result<(), SettingError> {
        if !(0.0 <= lo && lo < hi && hi <= 1.0) {
            return Err(SettingError::GradientOpacity { lo, hi });
        }
        Ok(())
    }

    /// The factor opacity is multiplied by where the world gradient has
    /// magnitude `gradient` (see [`crate::kernels::gradient::magnitude`]).
    #[inline]
    pub fn factor(&self, gradient: f32) -> f32 {
        ((gradient * self.inv_max - self.lo) * self.inv_width).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_runs_from_lo_to_hi_of_the_largest_magnitude() {
        let g = GradientOpacity::new((0.2, 0.6), 50.0);
        // m = 0.1, 0.2, 0.4, 0.6, 1.
        assert_eq!(g.factor(5.0), 0.0);
        assert_eq!(g.factor(10.0), 0.0);
        assert!((g.factor(20.0) - 0.5).abs() < 1e-6);
        assert!((g.factor(30.0) - 1.0).abs() < 1e-6);
        assert_eq!(g.factor(50.0), 1.0);
        assert_eq!(g.factor(0.0), 0.0);
        // A constant volume has no gradient: nothing shows.
        let flat = GradientOpacity::new((0.0, 0.5), 0.0);
        assert_eq!(flat.factor(0.0), 0.0);
    }

    #[test]
    fn bad_ramps_are_refused() {
        assert!(GradientOpacity::validate((0.0, 1.0)).is_ok());
        for range in [
            (0.5, 0.5),
            (0.6, 0.2),
            (-0.1, 0.5),
            (0.2, 1.5),
            (f32::NAN, 0.5),
        ] {
            assert!(GradientOpacity::validate(range).is_err(), "{range:?}");
        }
    }
}
