//! Levoy's isovalue contour surfaces: opacity that draws one iso-surface
//! of a fixed thickness, whatever the steepness of the data.
//!
//! M. Levoy, "Display of surfaces from volume data", *IEEE CG&A* 8(3),
//! 1988, eq. 3: for the isovalue `f_v` with opacity `α_v` (see
//! `transfer::classifier::Classifier::iso_alpha`: an opacity table's value at
//! `f_v`, or the ramp's top `q`) and a transition region `r` voxels thick,
//!
//! ```text
//! α(x) = α_v                                 if |∇f(x)| = 0 and f(x) = f_v
//!        α_v·(1 − |f_v − f(x)| / (r·|∇f(x)|))  if |∇f(x)| > 0 and |f(x) − f_v| <= r·|∇f(x)|
//!        0                                   otherwise
//! ```
//!
//! Near the surface `|f − f_v| / |∇f|` is the distance to it, so the
//! opacity falls linearly from `α_v` on the surface to zero `r` voxels
//! away on either side: a shell of constant thickness, where a threshold
//! on the value alone would give thick shells where the data are flat and
//! holes where they are steep (the paper's reference 1).
//!
//! `|∇f|` is per voxel of the smallest grid spacing `h` (the unit of the
//! thickness `r`, as of the sampling step). The renderer's gradients are
//! in world units, and `r·|∇f|_voxel = (r·h)·|∇f|_world`, so the contour
//! keeps the world width `r·h` and takes world gradients.

use crate::error::SettingError;

/// An iso-surface as the user gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoSurface {
    /// The isovalue `f_v`, in the volume's units.
    pub value: f32,
    /// The thickness `r` of the transition region on either side of the
    /// surface, in voxels of the smallest spacing.
    pub thickness: f32,
}

impl IsoSurface {
    /// Checks that the value is finite and the thickness finite and positive.
    pub fn validate(&self) -> Result<(), SettingError> {
        if !self.value.is_finite() {
            return Err(SettingError::IsoValue(self.value));
        }
        if !(self.thickness.is_finite() && self.thickness > 0.0) {
            return Err(SettingError::IsoThickness(self.thickness));
        }
        Ok(())
    }
}

/// Eq. 3 ready to evaluate: an [`IsoSurface`] on one volume under one
/// transfer function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoContour {
    /// `f_v`.
    value: f32,
    /// `α_v`, the unit opacity (before the step correction) at `f_v`.
    alpha: f32,
    /// `r·h`: the thickness in world units.
    width: f32,
    /// An upper bound on `width·|∇f|` over the volume (and over gradients
    /// interpolated between its voxels): no value farther than this from
    /// `f_v` is ever opaque.
    reach: f32,
}

/// How much the bound on the gradient magnitude is widened: a gradient
/// interpolated between voxels (post-classification) is a convex
/// combination of theirs, so its magnitude is at most their largest, but
/// rounding may add a few units in the last place.
const REACH_MARGIN: f32 = 1.0 + 1.0 / 1024.0;

impl IsoContour {
    /// The contour of `iso` with opacity `alpha` on the surface, on a grid
    /// whose smallest spacing is `voxel_size` and whose gradients (world
    /// units) are at most `max_gradient` long.
    pub fn new(iso: IsoSurface, alpha: f32, voxel_size: f32, max_gradient: f32) -> Self {
        let width = iso.thickness * voxel_size;
        IsoContour {
            value: iso.value,
            alpha,
            width,
            reach: width * max_gradient * REACH_MARGIN,
        }
    }

    /// Eq. 3: the unit opacity of value `f` where the world gradient has
    /// magnitude `gradient` (see [`crate::kernels::gradient::magnitude`]).
    #[inline]
    pub fn opacity(&self, f: f32, gradient: f32) -> f32 {
        let distance = (f - self.value).abs();
        if distance == 0.0 {
            // On the surface, whatever the gradient (the first case, and the
            // limit of the second).
            return self.alpha;
        }
        // `distance > 0`, so this also rules out `|∇f| = 0` (and a product
        // that underflows), and the division below is by a positive number.
        let reach = self.width * gradient;
        if distance <= reach {
            self.alpha * (1.0 - distance / reach)
        } else {
            0.0
        }
    }

    /// Whether every value in `[lo, hi]` gets zero opacity at every
    /// gradient the volume has: `α_v = 0`, or `f_v` lies farther from the
    /// interval than the bound on `r·|∇f|`. Conservative and exact in
    /// `f32`: for `f` in `[lo, hi]` the computed `|f − f_v|` is at least
    /// the computed distance from the nearer end (rounding is monotone),
    /// and the computed `width·|∇f|` at most `reach`.
    pub fn is_transparent_between(&self, lo: f32, hi: f32) -> bool {
        let distance = if self.value < lo {
            lo - self.value
        } else if self.value > hi {
            self.value - hi
        } else {
            0.0
        };
        self.alpha == 0.0 || distance > self.reach
    }

    /// `f_v`.
    pub fn value(&self) -> f32 {
        self.value
    }

    /// `α_v`.
    pub fn alpha(&self) -> f32 {
        self.alpha
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contour() -> IsoContour {
        // r = 2 voxels of 0.5: 1 world unit either side; |∇f| <= 4.
        let iso = IsoSurface {
            value: 10.0,
            thickness: 2.0,
        };
        IsoContour::new(iso, 0.8, 0.5, 4.0)
    }

    #[test]
    fn opacity_falls_linearly_across_the_transition_region() {
        let c = contour();
        // |∇f| = 3 per world unit: the region is |f − 10| <= 3.
        assert_eq!(c.opacity(10.0, 3.0), 0.8);
        assert!((c.opacity(11.5, 3.0) - 0.4).abs() < 1e-7);
        assert!((c.opacity(8.5, 3.0) - 0.4).abs() < 1e-7);
        assert!((c.opacity(12.25, 3.0) - 0.2).abs() < 1e-6);
        assert_eq!(c.opacity(13.0, 3.0), 0.0);
        assert_eq!(c.opacity(13.01, 3.0), 0.0);
        assert_eq!(c.opacity(6.0, 3.0), 0.0);
        // A flat region is opaque only exactly at the isovalue.
        assert_eq!(c.opacity(10.0, 0.0), 0.8);
        assert_eq!(c.opacity(10.0001, 0.0), 0.0);
        // A gradient whose product with the width underflows: no NaN.
        assert_eq!(c.opacity(10.0001, 1e-45), 0.0);
    }

    #[test]
    fn transparency_is_decided_by_the_distance_to_the_isovalue() {
        let c = contour();
        // The reach is 1·4 (and a hair): values within 4 of 10 may be opaque.
        assert!(!c.is_transparent_between(13.9, 20.0));
        assert!(!c.is_transparent_between(0.0, 6.1));
        assert!(!c.is_transparent_between(9.0, 11.0));
        assert!(c.is_transparent_between(14.1, 20.0));
        assert!(c.is_transparent_between(-5.0, 5.9));
        // Sampling agrees: every value in a transparent interval, at every
        // gradient up to the maximum, has zero opacity.
        for (lo, hi) in [(14.1f32, 20.0f32), (-5.0, 5.9)] {
            for i in 0..=50 {
                let f = lo + (hi - lo) * i as f32 / 50.0;
                for g in 0..=40 {
                    assert_eq!(c.opacity(f, g as f32 / 10.0), 0.0, "{f} {g}");
                }
            }
        }
        let invisible = IsoContour::new(
            IsoSurface {
                value: 10.0,
                thickness: 2.0,
            },
            0.0,
            0.5,
            4.0,
        );
        assert!(invisible.is_transparent_between(9.0, 11.0));
        assert_eq!(invisible.opacity(10.0, 1.0), 0.0);
    }

    #[test]
    fn bad_surfaces_are_refused() {
        let ok = IsoSurface {
            value: 1.0,
            thickness: 0.5,
        };
        assert!(ok.validate().is_ok());
        let err = IsoSurface {
            value: f32::NAN,
            thickness: 1.0,
        }
        .validate()
        .unwrap_err();
        assert!(
            matches!(err, SettingError::IsoValue(v) if v.is_nan()),
            "{err}"
        );
        for thickness in [0.0, -1.0, f32::INFINITY] {
            let err = IsoSurface {
                value: 1.0,
                thickness,
            }
            .validate()
            .unwrap_err();
            assert_eq!(err, SettingError::IsoThickness(thickness));
            assert!(err.to_string().starts_with("iso thickness "), "{err}");
        }
    }
}
