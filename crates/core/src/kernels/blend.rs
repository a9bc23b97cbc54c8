//! Blend modes: how the samples along a ray make the pixel.
//!
//! [`Blend::Composite`] is the paper's: classified, shaded samples
//! composited with the transparency formula (see [`crate::kernels::composite`]).
//! The others are projections of the interpolated *scalar* along the ray,
//! as VTK's `vtkVolumeMapper` blend modes MAXIMUM_INTENSITY,
//! MINIMUM_INTENSITY and AVERAGE_INTENSITY: the maximum, the minimum or the
//! mean of the values at the ray's samples (inside the cropped and clipped
//! part of the volume). The value is then shown through the colour map:
//! the pixel is the classifier's colour of the value's normalised scalar
//! `t`, opaque, with no shading and no opacity. Without a colour function
//! the map is grey, `t` clamped to [0, 1] (a white map would show nothing
//! but the volume's silhouette), so with `--range 0,1` a maximum intensity
//! pixel's grey level is the ray's maximum. A ray with no sample shows the
//! background.

/// How a ray's samples combine into its pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Blend {
    /// Composite classified, shaded samples (the paper's).
    #[default]
    Composite,
    /// Maximum intensity projection (MIP).
    Maximum,
    /// Minimum intensity projection (MinIP).
    Minimum,
    /// The mean value along the ray.
    Average,
}

impl Blend {
    /// Whether this projects the scalar instead of compositing.
    pub fn is_projection(self) -> bool {
        self != Blend::Composite
    }
}
