//! What lies under a pixel: the viewer's probe.
//!
//! The pixel's ray takes the frame's own samples ([`crate::sampling`]: the
//! same points, crop box and clip planes as the picture), and the probe
//! answers with the sample the pixel shows most:
//!
//! - **composite** (and an isosurface): the first sample at which the ray
//!   has become half opaque, `Π(1 − αᵢ) ≤ ½`, its opacities as the
//!   frame classifies them ([`crate::transfer::classifier`]): the surface
//!   the eye sees there;
//! - **MIP** and **MinIP**: the sample of the largest (smallest) value;
//! - **average**: no one sample: none.
//!
//! The value is the volume's, trilinear at the sample (as the casters
//! interpolate it), and the position its world point. A ray that takes no
//! sample, or never becomes half opaque, has nothing under it.

use crate::kernels::blend::Blend;
use crate::renderer::Renderer;
use crate::settings::RenderSettings;
use crate::{RenderError, Volume};
use glam::DVec3;

/// What a pixel shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// The sample's world point.
    pub position: DVec3,
    /// Its point in voxel indices (fractional).
    pub index: DVec3,
    /// The volume's value there.
    pub value: f32,
}

impl Renderer<'_> {
    /// What pixel (`col`, `row`) of the frame `settings` describe shows,
    /// or `None` where it shows no one sample (see [`crate::probe`]).
    pub fn probe(
        &self,
        settings: &RenderSettings,
        col: usize,
        row: usize,
    ) -> Result<Option<Probe>, RenderError> {
        let frame = self.prepare(settings)?;
        if col >= settings.width || row >= settings.height {
            return Ok(None);
        }
        let Some(ray) = frame.sampling.pixel(&frame.view, col, row) else {
            return Ok(None);
        };
        let volume = self.volume();
        let dims = volume.dims();
        let at = |k: i64| {
            let p = ray.position(k, dims);
            (p, trilinear(volume, p))
        };
        let found = match settings.blend {
            Blend::Composite => {
                let classifier = self.classifier(settings);
                let mut transmittance = 1.0f32;
                (ray.first..=ray.last).map(at).find(|&(p, f)| {
                    if !f.is_finite() {
                        return false;
                    }
                    let alpha = if classifier.uses_gradient() {
                        classifier.opacity_at(f, gradient(volume, p))
                    } else {
                        classifier.sample_opacity(f)
                    };
                    transmittance *= 1.0 - alpha;
                    transmittance <= 0.5
                })
            }
            Blend::Maximum => extreme(ray.first..=ray.last, at, |a, b| a > b),
            Blend::Minimum => extreme(ray.first..=ray.last, at, |a, b| a < b),
            Blend::Average => None,
        };
        Ok(found.map(|(index, value)| Probe {
            position: volume.origin() + index * volume.spacing(),
            index,
            value,
        }))
    }
}

/// The first sample whose value beats every other's by `better`.
fn extreme(
    samples: impl Iterator<Item = i64>,
    at: impl Fn(i64) -> (DVec3, f32),
    better: impl Fn(f32, f32) -> bool,
) -> Option<(DVec3, f32)> {
    samples
        .map(at)
        .filter(|(_, f)| f.is_finite())
        .fold(None, |best, (p, f)| match best {
            Some((_, b)) if !better(f, b) => best,
            _ => Some((p, f)),
        })
}

/// The value at index-space point `p` (inside the grid), trilinear.
fn trilinear(volume: &Volume, p: DVec3) -> f32 {
    let [nx, ny, nz] = volume.dims();
    let lo = |x: f64, n: usize| (x.floor() as usize).min(n.saturating_sub(2));
    let (i, j, k) = (lo(p.x, nx), lo(p.y, ny), lo(p.z, nz));
    let (u, v, w) = (p.x - i as f64, p.y - j as f64, p.z - k as f64);
    let g = |di, dj, dk| f64::from(volume.get(i + di, j + dj, k + dk));
    let x00 = g(0, 0, 0) * (1.0 - u) + g(1, 0, 0) * u;
    let x10 = g(0, 1, 0) * (1.0 - u) + g(1, 1, 0) * u;
    let x01 = g(0, 0, 1) * (1.0 - u) + g(1, 0, 1) * u;
    let x11 = g(0, 1, 1) * (1.0 - u) + g(1, 1, 1) * u;
    let y0 = x00 * (1.0 - v) + x10 * v;
    let y1 = x01 * (1.0 - v) + x11 * v;
    (y0 * (1.0 - w) + y1 * w) as f32
}

/// The world gradient at index-space point `p`: central differences of
/// the trilinear value half a voxel either side, over the spacing.
fn gradient(volume: &Volume, p: DVec3) -> [f32; 3] {
    let top = grid_top(volume.dims());
    let spacing = volume.spacing();
    let mut g = [0.0f32; 3];
    for (axis, out) in g.iter_mut().enumerate() {
        let mut e = DVec3::ZERO;
        e[axis] = 0.5;
        let a = (p - e).clamp(DVec3::ZERO, top);
        let b = (p + e).clamp(DVec3::ZERO, top);
        let run = (b[axis] - a[axis]) * spacing[axis];
        if run > 0.0 {
            let rise = f64::from(trilinear(volume, b)) - f64::from(trilinear(volume, a));
            *out = (rise / run) as f32;
        }
    }
    g
}

/// The largest index-space point of a grid of `dims`.
fn grid_top(dims: [usize; 3]) -> DVec3 {
    DVec3::new(
        (dims[0] - 1) as f64,
        (dims[1] - 1) as f64,
        (dims[2] - 1) as f64,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TransferFunction;

    /// A solid ball of radius 0.5 about the origin in a 33³ grid over
    /// [−1, 1]³: 1 inside, 0 outside.
    fn ball() -> Volume {
        let h = 2.0 / 32.0;
        Volume::from_fn([33; 3], DVec3::splat(h), DVec3::splat(-1.0), |p| {
            if p.length() <= 0.5 { 1.0 } else { 0.0 }
        })
        .unwrap()
    }

    /// Opaque from the value 0.5 up.
    fn step_tf() -> RenderSettings {
        RenderSettings {
            width: 33,
            height: 33,
            transfer_function: TransferFunction::from_json(
                r#"{"opacity": [[0, 0], [0.49, 0], [0.5, 1], [1, 1]]}"#,
            )
            .unwrap(),
            ..RenderSettings::default()
        }
    }

    #[test]
    fn the_centre_pixel_shows_the_balls_near_surface_and_mip_its_inside() {
        let volume = ball();
        let renderer = Renderer::new(&volume).unwrap();
        let settings = step_tf();
        // From +x (the default view), the centre ray meets the ball at x = 0.5.
        let hit = renderer.probe(&settings, 16, 16).unwrap().unwrap();
        let step = settings.step * 2.0 / 32.0;
        assert!(
            (hit.position.x - 0.5).abs() <= step + 2.0 / 32.0,
            "{:?}",
            hit.position
        );
        assert!(hit.position.y.abs() < 1e-9 && hit.position.z.abs() < 1e-9);
        assert!(hit.value >= 0.5, "{}", hit.value);
        // A corner pixel's ray misses the ball: nothing half opaque.
        assert_eq!(renderer.probe(&settings, 0, 0).unwrap(), None);
        // Outside the frame: nothing.
        assert_eq!(renderer.probe(&settings, 33, 0).unwrap(), None);
        // MIP: the largest value, 1, first met at the ball's surface.
        let mip = RenderSettings {
            blend: Blend::Maximum,
            ..settings.clone()
        };
        let top = renderer.probe(&mip, 16, 16).unwrap().unwrap();
        assert_eq!(top.value, 1.0);
        assert!(top.position.x <= 0.5 && top.position.x > 0.0);
        // MinIP: 0, at the ray's first sample (the box's +x face).
        let low = RenderSettings {
            blend: Blend::Minimum,
            ..settings.clone()
        };
        let bottom = renderer.probe(&low, 16, 16).unwrap().unwrap();
        assert_eq!(bottom.value, 0.0);
        assert!(
            (bottom.position.x - 1.0).abs() < 1e-9,
            "{:?}",
            bottom.position
        );
        let average = RenderSettings {
            blend: Blend::Average,
            ..settings
        };
        assert_eq!(renderer.probe(&average, 16, 16).unwrap(), None);
    }

    #[test]
    fn a_crop_box_moves_the_probe_behind_what_it_cuts() {
        let volume = ball();
        let renderer = Renderer::new(&volume).unwrap();
        let mut settings = step_tf();
        settings.crop = Some((DVec3::splat(-1.0), DVec3::new(0.0, 1.0, 1.0)));
        let hit = renderer.probe(&settings, 16, 16).unwrap().unwrap();
        // The near half is cut away: the ray enters at x = 0, inside.
        assert!(
            hit.position.x <= 1e-9 && hit.position.x > -0.1,
            "{:?}",
            hit.position
        );
        assert_eq!(hit.value, 1.0);
    }
}
