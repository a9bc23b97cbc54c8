//! Figures 2a and 2b: whole-volume renderings of two fractal clouds, the
//! paper's "stellar clouds": D = 3.7, σ = 1, mean 0, seeds 1 and 2, 129³
//! grids at 480 × 480 (errata 7; the field is `volray-data`'s midpoint
//! displacement, `docs/fractal.md`).
//!
//! # The paper's recipe, and the choices it leaves open
//!
//! "A suitable threshold value was subtracted uniformly from the values at
//! every point and among the resulting values the negative ones were
//! replaced by zeros. To ward off some undesirable boundary effects, the
//! data were modulated by a decreasing ramp before thresholding."
//!
//! - **Ramp**: `volray-data`'s, flat out to 70% of the half width and
//!   falling linearly to 0 at the inscribed sphere ([`CloudStyle::ramp`]
//!   0.3), applied to the field scaled to [0, 1].
//! - **Threshold**: chosen per cloud, as the paper's "suitable" suggests:
//!   the value that leaves [`CloudStyle::filled`] = 8% of the voxels the
//!   ramp leaves non-zero (those inside the sphere) above it: enough
//!   empty space for holes, dark lanes and a ragged outline, where 25%
//!   fills the sphere into a ball. A fixed threshold would not do: the
//!   coarsest levels of the field decide how much of it lies above any one
//!   level, so the same threshold leaves 3–22% of the grid non-empty
//!   depending on the seed (`docs/fractal.md`). The cloud is then exactly the `volray-data`
//!   source `fractal:129,seed=S,ramp=0.3,threshold=T` with the chosen `T`
//!   ([`Cloud::spec`]), so `volray render` reproduces it.
//! - **Opacity**: the paper's `α = p + t (q − p)`, `p = 0` (empty space
//!   stays empty), `q = 0.2` per voxel, with `t = f / f_top`, clamped, and
//!   `f_top` the level whose denser voxels hold 20% of the cloud's sum
//!   ([`crate::orbitals::density_level`]): the densest knots saturate, the
//!   thin outskirts stay translucent.
//! - **Colour**: a glow from dark red through orange to a pale yellow
//!   white ([`stellar_colors`]) over the same `t`, like an emission nebula;
//!   lit by the paper's Phong model mostly ambient (`k_a = 0.6`,
//!   `k_d = 0.4`, `k_s = 0`): the rough field's normals change from voxel
//!   to voxel, and a strong diffuse or specular term turns into speckle.
//! - **View**: from [`VIEW_POINT`] = (500, 150, 100) towards the cloud's
//!   centre, z up, off the grid's axes. Seen along an axis, every ray
//!   passes the voxel columns at the same offset, and since trilinear
//!   interpolation of a rough field varies less between grid points than
//!   at them, the image shows the grid's lattice, 3.7 pixels apart at
//!   129³ → 480². The window is the diameter of the ramp's sphere, where
//!   the cloud ends ([`crate::orbitals::inscribed_ball_camera`]).

use volray_core::PiecewiseLinear;
use volray_core::glam::DVec3;
use volray_core::{FrameRequest, Render, Rendered};
use volray_core::{Image, Method, Phong, RenderSettings, Renderer, TransferFunction, Volume};
use volray_data::fractal::{FractalParams, generate};

use crate::PaperError;
use crate::orbitals::{inscribed_ball_camera, top_window};

/// The seeds of Figures 2a and 2b (and of Table 1's fractal sets I and II).
pub const SEEDS: [u64; 2] = [1, 2];

/// Where the clouds are seen from (module docs); the view reference is
/// the centre of the grid, the origin.
pub const VIEW_POINT: DVec3 = DVec3::new(500.0, 150.0, 100.0);

/// How a fractal cloud is made and rendered (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct CloudStyle {
    /// Width of the boundary ramp, a fraction of the half width.
    pub ramp: f64,
    /// Share of the voxels inside the ramp's sphere left non-empty by the
    /// threshold.
    pub filled: f64,
    /// Share of the cloud's sum held by the voxels that saturate at `t = 1`.
    pub top_share: f64,
    /// The paper's `[p, q]`.
    pub opacity: (f32, f32),
    pub phong: Phong,
}

impl Default for CloudStyle {
    fn default() -> Self {
        CloudStyle {
            ramp: 0.3,
            filled: 0.08,
            top_share: 0.2,
            opacity: (0.0, 0.2),
            phong: Phong {
                ambient: [0.6; 3],
                diffuse: [0.4; 3],
                specular: [0.0; 3],
                ..Phong::default()
            },
        }
    }
}

/// A generated cloud and the parameters that make it.
#[derive(Debug, Clone)]
pub struct Cloud {
    pub volume: Volume,
    /// With the threshold chosen for this cloud.
    pub params: FractalParams,
}

impl Cloud {
    /// The `volray-data` source spec that generates the same volume.
    pub fn spec(&self) -> String {
        self.params.to_string()
    }
}

/// The paper's field (D = 3.7, σ = 1) on `size³` points with `seed`,
/// ramped, before any threshold.
pub fn unthresholded(size: usize, seed: u64, style: &CloudStyle) -> FractalParams {
    FractalParams {
        size,
        seed,
        dimension: 3.7,
        sigma: 1.0,
        ramp: style.ramp,
        threshold: 0.0,
        ..FractalParams::default()
    }
}

/// The threshold that leaves the share `filled` of the non-zero values of
/// `values` strictly above it: the `(1 − filled)` quantile of the non-zero
/// values (0 when there are none). Subtracting it and setting negatives to
/// 0 is the paper's thresholding.
pub fn threshold_for(values: &[f32], filled: f64) -> f64 {
    let mut inside: Vec<f32> = values.iter().copied().filter(|&v| v > 0.0).collect();
    if inside.is_empty() {
        return 0.0;
    }
    let keep = ((filled.clamp(0.0, 1.0) * inside.len() as f64).round() as usize).min(inside.len());
    if keep == inside.len() {
        return 0.0;
    }
    // The largest value that must become empty: exactly `keep` values lie
    // above it (ties aside).
    let index = inside.len() - keep - 1;
    let (_, v, _) = inside.select_nth_unstable_by(index, f32::total_cmp);
    f64::from(*v)
}

/// Cloud `seed` on `size³` points with its threshold chosen (module docs).
pub fn cloud(size: usize, seed: u64, style: &CloudStyle) -> Result<Cloud, PaperError> {
    let base = unthresholded(size, seed, style);
    let field = generate(&base)?;
    // The ramped field lies in [0, 1]; a threshold of 1 or more would empty
    // it, which `volray-data` refuses, and no share > 0 asks for it.
    let threshold = threshold_for(&field.values(), style.filled).min(0.999);
    drop(field);
    let params = FractalParams { threshold, ..base };
    Ok(Cloud {
        volume: generate(&params)?,
        params,
    })
}

/// The colours of the clouds over `t`: dark red, orange, pale yellow,
/// near white.
pub fn stellar_colors() -> PiecewiseLinear<3> {
    PiecewiseLinear::new(
        "color",
        vec![
            (0.0, [0.35, 0.02, 0.05]),
            (0.35, [0.85, 0.25, 0.08]),
            (0.7, [1.0, 0.75, 0.35]),
            (1.0, [1.0, 1.0, 0.9]),
        ],
    )
    .expect("sorted points with values in [0, 1]")
}

/// The render settings of a cloud at `size × size` pixels, seen from
/// [`VIEW_POINT`], z up.
pub fn settings(
    volume: &Volume,
    style: &CloudStyle,
    size: usize,
    method: Method,
) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        camera: inscribed_ball_camera(VIEW_POINT),
        opacity_ramp: style.opacity,
        transfer_function: TransferFunction {
            domain: top_window(volume, style.top_share),
            opacity: None,
            color: Some(stellar_colors()),
        },
        phong: style.phong,
        method,
        ..RenderSettings::default()
    }
}

/// Renders `cloud` at `size × size` pixels.
pub fn render(cloud: &Cloud, style: &CloudStyle, size: usize) -> Result<Image, PaperError> {
    let what = cloud.spec();
    let renderer = Renderer::new(&cloud.volume).map_err(PaperError::render(&what))?;
    renderer
        .render(FrameRequest::new(&settings(
            &cloud.volume,
            style,
            size,
            Method::Fast,
        )))
        .map(Rendered::image)
        .map_err(PaperError::render(&what))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threshold_keeps_the_asked_share_of_the_inside() {
        // 0 marks outside; 1..=8 inside. Keeping 25% = 2 of 8 leaves 7 and
        // 8 above the threshold 6.
        let values = [0.0, 5.0, 1.0, 0.0, 8.0, 3.0, 7.0, 2.0, 6.0, 4.0, 0.0];
        assert_eq!(threshold_for(&values, 0.25), 6.0);
        assert_eq!(threshold_for(&values, 0.5), 4.0);
        assert_eq!(threshold_for(&values, 1.0), 0.0);
        assert_eq!(threshold_for(&values, 0.0), 8.0);
        assert_eq!(threshold_for(&[0.0; 4], 0.25), 0.0);
    }

    #[test]
    fn a_cloud_keeps_its_share_and_its_spec_regenerates_it() {
        let style = CloudStyle::default();
        let c = cloud(33, 1, &style).unwrap();
        let inside = generate(&unthresholded(33, 1, &style))
            .unwrap()
            .values()
            .iter()
            .filter(|&&v| v > 0.0)
            .count();
        let filled = c.volume.values().iter().filter(|&&v| v > 0.0).count();
        let share = filled as f64 / inside as f64;
        assert!((share - style.filled).abs() < 0.01, "{share}");
        let again = volray_data::generate(&c.spec()).unwrap();
        assert_eq!(again, c.volume);
        assert!(
            c.spec()
                .starts_with("fractal:33,seed=1,dim=3.7,sigma=1,ramp=0.3,threshold=0.")
        );
        // The other seed makes another cloud.
        let other = cloud(33, 2, &style).unwrap();
        assert_ne!(other.volume, c.volume);
    }

    #[test]
    fn colours_glow_from_red_to_white() {
        let c = stellar_colors();
        let dark = c.eval(0.0);
        let bright = c.eval(1.0);
        assert!(dark[0] > dark[1] && dark[0] > dark[2]);
        assert!(bright.iter().all(|&v| v >= 0.9));
        // Brightness rises with t.
        let luma = |t: f32| c.eval(t).iter().sum::<f32>();
        assert!((1..=10).all(|i| luma(i as f32 / 10.0) > luma((i - 1) as f32 / 10.0)));
    }
}
