//! The frames of `volray render`'s animations, planned: a **turntable**'s
//! views ([`turntable_frame`]: frame `i` of `n` at azimuth
//! `azimuth + 360·i/n`, framed to the bounding sphere ([`Fit::Sphere`]) so
//! that the object keeps its scale as it turns), and the one transfer
//! function and framing every frame of a **series** (several volumes, or a
//! file's time points) shares ([`Extent`], read from every volume by
//! [`series_settings`]). The front end renders and writes the frames.

use crate::AppError;
use crate::input::{self, Request};
use volray_core::glam::DVec3;
use volray_core::{Camera, Fit, NonFinite, RenderSettings};
use volray_options::LookOptions;

/// The views of an animation of one picture: how many frames, and the
/// settings of each from the settings the options describe. The front
/// end renders and writes frame after frame; the level (and whether the
/// volume is rendered in pieces) is chosen for the first. A turntable is
/// one ([`Turntable`]). A camera and look path through keyframes is
/// [`crate::movie`]'s: it moves the options, not only the settings.
pub trait Views {
    /// The number of frames.
    fn frames(&self) -> usize;
    /// The settings of frame `i` (of [`Views::frames`]) of `base`.
    fn frame(&self, base: &RenderSettings, i: usize) -> RenderSettings;
}

/// A turntable of so many frames: [`turntable_frame`]'s views.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Turntable(pub usize);

impl Views for Turntable {
    fn frames(&self) -> usize {
        self.0
    }

    fn frame(&self, base: &RenderSettings, i: usize) -> RenderSettings {
        turntable_frame(base, i, self.0)
    }
}

/// The settings of frame `i` of an `n`-frame turntable of `base`.
pub fn turntable_frame(base: &RenderSettings, i: usize, n: usize) -> RenderSettings {
    RenderSettings {
        camera: Camera {
            azimuth: base.camera.azimuth + 360.0 * i as f64 / n as f64,
            fit: Fit::Sphere,
            ..base.camera
        },
        ..base.clone()
    }
}

/// The value range, the bounds and (for gradient opacity) the largest
/// gradient magnitude of the volumes seen so far.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct Extent {
    pub range: Option<(f32, f32)>,
    pub bounds: Option<(DVec3, DVec3)>,
    pub max_gradient: f32,
}

impl Extent {
    /// Adds a volume of values `lo..=hi` within the box `min..max`.
    pub fn add(&mut self, (lo, hi): (f32, f32), (min, max): (DVec3, DVec3)) {
        self.range = Some(match self.range {
            Some((a, b)) => (a.min(lo), b.max(hi)),
            None => (lo, hi),
        });
        self.bounds = Some(match self.bounds {
            Some((a, b)) => (a.min(min), b.max(max)),
            None => (min, max),
        });
    }

    /// `base` with one value window and one framed box for every volume:
    /// the window is the union of the ranges unless the transfer function
    /// fixes one (`--range`, `--tf`, a CT preset); the box is the union of
    /// the bounds; gradient opacity is relative to the largest gradient.
    /// Volumes that are all the same constant keep no window
    /// (each one's own range is then that constant).
    pub fn fix(&self, base: &RenderSettings) -> RenderSettings {
        let mut settings = base.clone();
        if settings.transfer_function.domain.is_none()
            && let Some((lo, hi)) = self.range
            && lo < hi
        {
            settings.transfer_function.domain = Some((lo as f64, hi as f64));
        }
        if settings.camera.bounds.is_none() {
            settings.camera.bounds = self.bounds;
        }
        // Gradient opacity relative to the steepest volume of all, so that
        // one gradient magnitude gets one opacity in every frame.
        if settings.gradient_opacity.is_some() && self.max_gradient > 0.0 {
            settings.gradient_opacity_max = Some(self.max_gradient);
        }
        settings
    }
}

/// The settings every frame of a series shares, from a first pass over
/// its volumes (`inputs`, each read in turn and dropped, so that a long
/// series never has to fit in memory; the frames read them again): one
/// value window and one framed box for all ([`Extent::fix`]); with
/// `labels`, the labels of every volume, so that a label has one colour;
/// with `tf auto`, the transfer function chosen from the first volume's
/// histogram over the window of them all. `base` is the settings the
/// options describe; `look` the options, `non_finite` how non-finite
/// values are rendered.
pub fn series_settings(
    inputs: &[Request],
    base: &RenderSettings,
    look: &LookOptions,
    non_finite: NonFinite,
    pool: &rayon::ThreadPool,
) -> Result<RenderSettings, AppError> {
    let mut extent = Extent::default();
    let mut first = None;
    let mut labels = std::collections::BTreeSet::new();
    for one in inputs {
        let input = input::load_log(one, look.log)?;
        if first.is_none() && look.auto_tf() {
            first = volray_core::transfer::auto::robust_histogram_of(&input.volume);
        }
        if look.labels {
            let found = volray_options::volume_labels(&input.volume, &input.name);
            labels.extend(found.map_err(AppError::Option)?);
        }
        let renderer = crate::renderer::renderer_for(&input, base, non_finite)?;
        extent.add(renderer.value_range(), input.volume.bounds());
        if base.gradient_opacity.is_some() {
            let max = pool.install(|| renderer.max_gradient());
            extent.max_gradient = extent.max_gradient.max(max);
        }
    }
    let mut settings = extent.fix(base);
    // Where the first volume's histogram was refined past outliers, its
    // window is the series' (a window given still wins), as for one
    // volume: over the union of the ranges the bulk would be squeezed.
    if let Some((lo, hi)) = first.as_ref().and_then(|r| r.window)
        && base.transfer_function.domain.is_none()
    {
        settings.transfer_function.domain = Some((f64::from(lo), f64::from(hi)));
    }
    let tf = &mut settings.transfer_function;
    if look.labels {
        let found: Vec<i64> = labels.into_iter().collect();
        let names = format!("{} volumes", inputs.len());
        volray_options::label_transfer_function(look, tf, &found, &names)
            .map_err(AppError::Option)?;
    }
    if let Some(histogram) = &first {
        // Chosen from the first volume, over the window of them all.
        volray_options::apply_auto(look, tf, histogram);
    }
    Ok(settings)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turntable_frames_turn_by_equal_steps_from_the_given_azimuth() {
        let base = RenderSettings {
            camera: Camera {
                azimuth: 10.0,
                elevation: 20.0,
                ..Camera::default()
            },
            ..RenderSettings::default()
        };
        let azimuths: Vec<f64> = (0..4)
            .map(|i| turntable_frame(&base, i, 4).camera.azimuth)
            .collect();
        assert_eq!(azimuths, [10.0, 100.0, 190.0, 280.0]);
        let frame = turntable_frame(&base, 3, 4);
        assert_eq!(Turntable(4).frames(), 4);
        assert_eq!(Turntable(4).frame(&base, 3), frame);
        assert_eq!(frame.camera.fit, Fit::Sphere);
        assert_eq!(frame.camera.elevation, 20.0);
        assert_eq!(
            RenderSettings {
                camera: base.camera,
                ..frame.clone()
            },
            base
        );
    }

    #[test]
    fn a_series_shares_the_union_of_ranges_and_bounds() {
        let mut extent = Extent::default();
        extent.add((0.0, 2.0), (DVec3::ZERO, DVec3::ONE));
        extent.add(
            (-1.0, 1.5),
            (DVec3::new(0.5, -1.0, 0.0), DVec3::new(3.0, 0.5, 1.0)),
        );
        let fixed = extent.fix(&RenderSettings::default());
        assert_eq!(fixed.transfer_function.domain, Some((-1.0, 2.0)));
        assert_eq!(
            fixed.camera.bounds,
            Some((DVec3::new(0.0, -1.0, 0.0), DVec3::new(3.0, 1.0, 1.0)))
        );
        // A window the user gave stays.
        let mut given = RenderSettings::default();
        given.transfer_function.domain = Some((0.0, 10.0));
        assert_eq!(
            extent.fix(&given).transfer_function.domain,
            Some((0.0, 10.0))
        );
        // Constant volumes all alike keep no window.
        let mut flat = Extent::default();
        flat.add((3.0, 3.0), (DVec3::ZERO, DVec3::ONE));
        flat.add((3.0, 3.0), (DVec3::ZERO, DVec3::ONE));
        assert_eq!(
            flat.fix(&RenderSettings::default())
                .transfer_function
                .domain,
            None
        );
    }
}
