//! Figure 1c: surface renderings of the angular parts of the 21 states of
//! Figure 1, the polar surfaces `r(θ, φ) = |Y_lm(θ, φ)|²` (errata 6), seen
//! from (150, 150, 500) towards the origin, z up, with the paper's Phong
//! model and hidden surfaces removed by a z-buffer (`volray-surface`).
//!
//! - **Mesh**: `|Y_lm|²` from `volray-data`'s spherical harmonics on a
//!   (θ, φ) grid of [`THETA_STEPS`] × 2·[`THETA_STEPS`] = 96 × 192 cells
//!   at full size (an l = 5 lobe spans about 30° of θ, 16 cells), 24 × 48
//!   for reduced runs.
//! - **Scale**: each panel is framed on its own surface, the window
//!   [`MARGIN`] times the surface's bounding sphere, as the volume panels
//!   are each normalised to their own density (the surfaces' sizes differ
//!   by a factor of 11: `max |Y_lm|²` runs from 1/4π = 0.080 for `(0,0)`
//!   to `|Y_50(0)|²` = 11/4π = 0.88 for `(5,0)`).
//! - **Light and colour**: a headlight, `k_a = 0.15`, `k_d = 0.7`,
//!   `k_s = 0.3`, `n = 20`, on a pale warm material; 3 × 3 samples per
//!   pixel smooth the silhouettes.

use volray_core::{Image, Phong};
use volray_data::hydrogen::SphericalHarmonic;
use volray_surface::{PolarSurface, SurfaceSettings};

use crate::PaperError;
use crate::montage::{Panel, TriangleLayout};
use crate::orbitals::{N, OrbitalView, states};

/// θ cells of a surface at full size (φ has twice as many).
pub const THETA_STEPS: usize = 96;

/// The window's half-size over the smallest one that holds the surface's
/// projection: each panel is framed on its own surface as seen, so that
/// the `m = 0` surfaces, whose long lobes point nearly at the viewer, are
/// not drawn small.
pub const MARGIN: f64 = 1.08;

/// The surfaces' material colour.
pub const COLOR: [f32; 3] = [1.0, 0.88, 0.7];

/// The polar surface `r = |Y_lm(θ, φ)|²` on `theta_steps` × `2·theta_steps`
/// cells.
pub fn angular_surface(l: u32, m: u32, theta_steps: usize) -> Result<PolarSurface, PaperError> {
    let harmonic = SphericalHarmonic::new(l, m as i32)
        .map_err(volray_data::DataError::invalid(format!("Y_{l}{m}")))?;
    PolarSurface::new(
        |theta, _phi| harmonic.norm_sqr(theta),
        theta_steps,
        2 * theta_steps,
    )
    .map_err(|e| PaperError::Surface {
        what: format!("|Y_{l}{m}|²"),
        source: e,
    })
}

/// The settings of one `size × size` panel for `surface`.
pub fn panel_settings(surface: &PolarSurface, size: usize) -> Result<SurfaceSettings, PaperError> {
    let mut settings = SurfaceSettings {
        width: size,
        height: size,
        camera: OrbitalView::Oblique.camera(),
        phong: Phong {
            ambient: [0.15; 3],
            diffuse: [0.7; 3],
            specular: [0.3; 3],
            shininess: 20.0,
            light_color: [1.0; 3],
        },
        light_direction: None,
        color: COLOR,
        background: crate::BACKGROUND,
        half_window: None,
        supersampling: 3,
    };
    let fitted = volray_surface::fitted_half_window(surface, &settings).map_err(|e| {
        PaperError::Surface {
            what: "a panel's window".into(),
            source: e,
        }
    })?;
    settings.half_window = Some(MARGIN * fitted);
    Ok(settings)
}

/// Renders `|Y_lm|²` at `size × size` pixels.
pub fn render_panel(l: u32, m: u32, size: usize, theta_steps: usize) -> Result<Image, PaperError> {
    let surface = angular_surface(l, m, theta_steps)?;
    volray_surface::render(&surface, &panel_settings(&surface, size)?).map_err(|e| {
        PaperError::Surface {
            what: format!("|Y_{l}{m}|²"),
            source: e,
        }
    })
}

/// Figure 1c: the montage of the 21 surfaces, `size × size` pixels each,
/// meshes of `theta_steps` × `2·theta_steps` cells.
pub fn figure(size: usize, theta_steps: usize) -> Result<Image, PaperError> {
    let panels = states(N)
        .map(|(l, m)| {
            Ok(Panel {
                row: l as usize,
                col: m as usize,
                image: render_panel(l, m, size, theta_steps)?,
                label: format!("({l},{m})"),
            })
        })
        .collect::<Result<Vec<_>, PaperError>>()?;
    let layout = TriangleLayout::new(N as usize, size, true);
    Ok(crate::montage::compose(
        &layout,
        &panels,
        crate::BACKGROUND,
        crate::LABEL_COLOR,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn surfaces_are_the_squared_harmonics() {
        // |Y_00|² = 1/4π everywhere: a sphere.
        let s = angular_surface(0, 0, 8).unwrap();
        assert!((s.max_radius() - 1.0 / (4.0 * PI)).abs() < 1e-15);
        // |Y_10|² = 3 cos²θ/4π peaks at the poles, which the grid samples.
        let s = angular_surface(1, 0, 8).unwrap();
        assert!((s.max_radius() - 3.0 / (4.0 * PI)).abs() < 1e-12);
        // |Y_11|² = 3 sin²θ/8π peaks at the equator (θ = π/2, sampled for
        // an even number of θ steps).
        let s = angular_surface(1, 1, 8).unwrap();
        assert!((s.max_radius() - 3.0 / (8.0 * PI)).abs() < 1e-12);
        // |Y_l0(θ = 0)|² = (2l + 1)/4π: the largest of Figure 1c's surfaces.
        let s = angular_surface(5, 0, 8).unwrap();
        assert!((s.max_radius() - 11.0 / (4.0 * PI)).abs() < 1e-12);
    }

    #[test]
    fn panels_frame_the_surface_with_a_margin() {
        let s = angular_surface(2, 1, 8).unwrap();
        let settings = panel_settings(&s, 40).unwrap();
        let fitted = volray_surface::fitted_half_window(&s, &settings).unwrap();
        assert_eq!(settings.half_window, Some(MARGIN * fitted));
        // Seen from (150, 150, 500), |Y_21|²'s outline is narrower than its
        // bounding sphere.
        assert!(fitted < s.max_radius());
        assert_eq!((settings.width, settings.height), (40, 40));
        let image = render_panel(0, 0, 40, 16).unwrap();
        // The sphere covers the centre and misses the corners.
        assert_eq!(image.get(20, 20)[3], 1.0);
        assert_eq!(image.get(0, 0), [0.0, 0.0, 0.0, 0.0]);
    }
}
