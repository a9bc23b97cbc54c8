//! Figures 1a and 1b: whole-volume renderings of the 21 hydrogen densities
//! `|ψ_6lm|²`, `l = 0..5`, `m = 0..=l` (errata 6), each on a grid of the
//! paper's 50³ points rendered at 120 × 120.
//!
//! # What is rendered
//!
//! - **Grid**: every state on the same cube `[−R, R]³` with `R` the largest
//!   over `l` of the radius holding 99.5% of the radial probability
//!   ([`common_extent`], 92.4 a₀ for `n = 6`, reached at `l = 0`), so the
//!   panels share one length scale as a table of orbitals should (the
//!   paper found its scale factor "by trial and error, so that a
//!   substantial part of the density function would be enclosed").
//! - **Views**: Figure 1a from a view point on the +x axis, the origin
//!   (the nucleus, the cube's centre) as view reference, z up; Figure 1b
//!   from (150, 150, 500) towards the origin, z up. Orthographic, so only
//!   the direction of the view point matters. Both windows are the
//!   diameter `2R` of the cube's inscribed ball (the renderer's sphere
//!   fit, zoomed by √3 from the cube's circumscribed sphere), so the two
//!   figures share one scale; the box fit would shrink Figure 1b's
//!   orbitals by 30% to take in the cube's corners, where the densities
//!   have all but vanished.
//! - **Opacity**: the paper's `α = p + t (q − p)` with
//!   `t = (f − f_min)/(f_top − f_min)`, clamped to [0, 1]. The paper takes
//!   `f_top = f_max` per panel; that shows only the few densest voxels,
//!   because these densities span orders of magnitude (the 6s density at
//!   the nucleus is 22 times the level that bounds its densest 10%). Here
//!   each panel is normalised to its own `f_top` =
//!   [`density_level`]`(volume, 0.1)`: the density above which the panel's
//!   densest voxels hold 10% of its probability (a "highest-density
//!   region" level); denser voxels saturate at `t = 1`. `p = 0`: the
//!   density vanishes towards the cube's faces, and any `p > 0` would
//!   fill the cube with a uniform fog (`p = 0.01` over 50 samples veils
//!   40% of the light) — the paper's reason for `p > 0`, keeping the
//!   weakest voxels visible, is served by the window instead. `q = 0.2`
//!   per voxel: dense enough to read the shells, thin enough to see the
//!   inner nodes through the outer ones.
//! - **Colour**: the `magma` map over the same `t`, lit by the paper's
//!   Phong model with a headlight, `k_a = 0.4`, `k_d = 0.6`, `k_s = 0.3`,
//!   `n = 10` (more ambient than the renderer's default, because the
//!   smooth densities' normals turn away from the viewer over most of
//!   each shell).

use volray_core::glam::DVec3;
use volray_core::{
    Camera, Fit, Image, Method, Phong, RenderSettings, Renderer, TransferFunction, Volume,
};
use volray_core::{FrameRequest, Render, Rendered};
use volray_data::hydrogen::HydrogenParams;

use crate::PaperError;
use crate::montage::{Panel, TriangleLayout};

/// The principal quantum number of Figure 1.
pub const N: u32 = 6;

/// The share of a panel's probability held by the voxels denser than its
/// `f_top`.
pub const TOP_SHARE: f64 = 0.1;

/// The paper's `[p, q]` opacity sub-interval for Figures 1a and 1b.
pub const OPACITY: (f32, f32) = (0.0, 0.2);

/// The colour map of Figures 1a and 1b.
pub const COLORMAP: &str = "magma";

/// Phong coefficients of Figures 1a and 1b (module docs).
pub fn phong() -> Phong {
    Phong {
        ambient: [0.4; 3],
        diffuse: [0.6; 3],
        specular: [0.3; 3],
        shininess: 10.0,
        light_color: [1.0; 3],
    }
}

/// The two views of the hydrogen densities.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrbitalView {
    /// Figure 1a: from the +x axis, z up.
    XAxis,
    /// Figures 1b and 1c: from (150, 150, 500), z up.
    Oblique,
}

impl OrbitalView {
    /// The view point; the view reference is the origin.
    pub fn view_point(self) -> DVec3 {
        match self {
            OrbitalView::XAxis => DVec3::new(500.0, 0.0, 0.0),
            OrbitalView::Oblique => DVec3::new(150.0, 150.0, 500.0),
        }
    }

    /// The camera: this view point, looking at the origin, z up, the
    /// window the diameter of the inscribed ball of a cube centred there.
    pub fn camera(self) -> Camera {
        inscribed_ball_camera(self.view_point())
    }
}

/// A camera at `view_point` looking at the origin, z up, whose window is
/// the diameter of the ball inscribed in a volume cube centred there: the
/// sphere fit frames the cube's circumscribed sphere, √3 times larger.
pub fn inscribed_ball_camera(view_point: DVec3) -> Camera {
    Camera {
        view_point: Some(view_point),
        look_at: Some(DVec3::ZERO),
        up: DVec3::Z,
        fit: Fit::Sphere,
        zoom: 3f64.sqrt(),
        ..Camera::default()
    }
}

/// The states of Figure 1 in montage order: `(l, m)` for `l = 0..n`,
/// `m = 0..=l`.
pub fn states(n: u32) -> impl Iterator<Item = (u32, u32)> {
    (0..n).flat_map(|l| (0..=l).map(move |m| (l, m)))
}

/// The share of each state's radial probability the common cube's
/// inscribed ball holds at least.
pub const ENCLOSED: f64 = 0.9;

/// The radius inside which a state has a given share of its radial
/// probability (`volray-data`'s bisection, as for its default extent).
pub use volray_data::hydrogen::extent::enclosing_radius;

/// The half width shared by all panels: the largest over `l` of the
/// radius enclosing [`ENCLOSED`] of the radial probability, for principal
/// quantum number `n` (1 ≤ n ≤ 12).
pub fn common_extent(n: u32) -> f64 {
    (0..n)
        .map(|l| enclosing_radius(n, l, ENCLOSED))
        .fold(0.0, f64::max)
}

/// One state's density on `grid³` points over the common cube.
pub fn density(l: u32, m: u32, grid: usize) -> Result<Volume, PaperError> {
    let params = HydrogenParams {
        n: N,
        l,
        m: m as i32,
        grid,
        extent: Some(common_extent(N)),
        real: false,
    };
    Ok(volray_data::hydrogen::generate(&params)?)
}

/// The density level `f*` whose denser voxels hold `share` (0 < share ≤ 1)
/// of the volume's total: the smallest value `v` with
/// `Σ_{f ≥ v} f ≥ share · Σ f`, summed over the voxels. Values are taken as
/// they are (the densities are non-negative); a volume whose sum is not
/// positive gives its maximum.
pub fn density_level(volume: &Volume, share: f64) -> f32 {
    let mut values: Vec<f32> = volume.values().to_vec();
    values.sort_unstable_by(|a, b| b.total_cmp(a));
    let total: f64 = values.iter().map(|&v| f64::from(v)).sum();
    if total <= 0.0 {
        return values.first().copied().unwrap_or(0.0);
    }
    let target = share * total;
    let mut sum = 0.0;
    for &v in &values {
        sum += f64::from(v);
        if sum >= target {
            return v;
        }
    }
    values[values.len() - 1]
}

/// The value window `[f_min, f_top]` with `f_top` the [`density_level`] of
/// `share`; `None` (the volume's whole range) when that window would be
/// empty, as for a constant volume.
pub fn top_window(volume: &Volume, share: f64) -> Option<(f64, f64)> {
    let (lo, _) = volume.value_range()?;
    let top = density_level(volume, share);
    (top > lo).then(|| (f64::from(lo), f64::from(top)))
}

/// The render settings of one panel: `size × size` pixels, `view`, the
/// window `[f_min, f_top]` of this volume (module docs).
pub fn panel_settings(
    volume: &Volume,
    view: OrbitalView,
    size: usize,
    method: Method,
) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        camera: view.camera(),
        opacity_ramp: OPACITY,
        transfer_function: TransferFunction {
            domain: top_window(volume, TOP_SHARE),
            opacity: None,
            color: volray_core::transfer::colormap::colormap(COLORMAP),
        },
        phong: phong(),
        method,
        ..RenderSettings::default()
    }
}

/// Renders the panel of `state`.
pub fn render_panel(
    state: &StateDensity,
    view: OrbitalView,
    size: usize,
) -> Result<Image, PaperError> {
    let what = format!("|psi_{N}{}{}|^2", state.l, state.m);
    let settings = panel_settings(&state.volume, view, size, Method::Fast);
    let renderer = Renderer::new(&state.volume).map_err(PaperError::render(&what))?;
    renderer
        .render(FrameRequest::new(&settings))
        .map(Rendered::image)
        .map_err(PaperError::render(&what))
}

/// One state's density, for a panel.
#[derive(Debug, Clone)]
pub struct StateDensity {
    pub l: u32,
    pub m: u32,
    pub volume: Volume,
}

/// The 21 densities of Figure 1 on `grid³` points, in [`states`] order.
pub fn densities(grid: usize) -> Result<Vec<StateDensity>, PaperError> {
    states(N)
        .map(|(l, m)| {
            Ok(StateDensity {
                l,
                m,
                volume: density(l, m, grid)?,
            })
        })
        .collect()
}

/// Figure 1a or 1b: the montage of `densities` rendered from `view` at
/// `size × size` pixels per panel.
pub fn figure(
    densities: &[StateDensity],
    view: OrbitalView,
    size: usize,
) -> Result<Image, PaperError> {
    let panels = densities
        .iter()
        .map(|d| {
            Ok(Panel {
                row: d.l as usize,
                col: d.m as usize,
                image: render_panel(d, view, size)?,
                label: format!("({},{})", d.l, d.m),
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

    #[test]
    fn twenty_one_states_in_montage_order() {
        let all: Vec<_> = states(6).collect();
        assert_eq!(all.len(), 21);
        assert_eq!(all[..4], [(0, 0), (1, 0), (1, 1), (2, 0)]);
        assert_eq!(all[20], (5, 5));
    }

    #[test]
    fn density_level_bounds_the_densest_share() {
        // Values 1..=10 and ten zeros: total 55. The densest voxel, 10,
        // holds 10 ≥ 5.5 = 0.1·55 by itself.
        let data: Vec<f32> = [3.0, 10.0, 1.0, 7.0, 2.0, 9.0, 4.0, 8.0, 5.0, 6.0]
            .into_iter()
            .chain([0.0; 10])
            .collect();
        let v = Volume::new([2, 5, 2], data).unwrap();
        assert_eq!(density_level(&v, 0.1), 10.0);
        // 10 + 9 + 8 = 27 < 27.5 = 0.5·55 ≤ 34 = 27 + 7.
        assert_eq!(density_level(&v, 0.5), 7.0);
        // Everything: the smallest non-zero value completes the sum.
        assert_eq!(density_level(&v, 1.0), 1.0);
        let zero = Volume::new([2, 2, 2], vec![0.0; 8]).unwrap();
        assert_eq!(density_level(&zero, 0.1), 0.0);
        // The window runs from the minimum to the level; none for a
        // constant volume.
        assert_eq!(top_window(&v, 0.5), Some((0.0, 7.0)));
        assert_eq!(top_window(&zero, 0.1), None);
    }

    #[test]
    fn the_common_cube_holds_every_state() {
        use volray_data::hydrogen::default_extent;
        // At 99.5% the bisection is volray-data's default extent.
        for l in [0, 3, 5] {
            let r = enclosing_radius(6, l, 0.995);
            assert!((r - default_extent(6, l)).abs() < 1e-9 * r, "{l}");
        }
        // The ground state: P(r < R) = 1 − e^(−2R)(1 + 2R + 2R²).
        let r = enclosing_radius(1, 0, 0.9);
        let inside = 1.0 - (-2.0 * r).exp() * (1.0 + 2.0 * r + 2.0 * r * r);
        assert!((inside - 0.9).abs() < 1e-12, "{inside}");
        let common = common_extent(6);
        for l in 0..6 {
            assert!(enclosing_radius(6, l, ENCLOSED) <= common);
        }
        assert_eq!(common, enclosing_radius(6, 0, ENCLOSED));
    }

    #[test]
    fn views_look_at_the_origin_with_z_up() {
        let a = OrbitalView::XAxis.camera();
        assert_eq!(a.look_at, Some(DVec3::ZERO));
        assert_eq!(a.up, DVec3::Z);
        let d = a.view_point.unwrap().normalize();
        assert_eq!(d, DVec3::X);
        let b = OrbitalView::Oblique.camera();
        assert_eq!(b.view_point, Some(DVec3::new(150.0, 150.0, 500.0)));
    }
}
