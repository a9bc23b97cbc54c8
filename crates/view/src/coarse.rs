//! Drafts from a coarser copy of a volume served without levels: what a
//! multiscale volume's drafts get from its pyramid (`pyramid.rs`), made
//! here once, in memory, for a large volume read whole.
//!
//! **Why.** A pre-classified frame lights every brick its rays touch for
//! each new view (the headlight turns with the camera), a cost that does
//! not shrink with the frame: `volray bench fractal:257 --threads 2` took
//! 52 ms at 57×48 pixels and 158 ms at 916×765, so a drag at a 1280×800
//! window stayed near 14 frames/s however small its drafts were. The copy
//! has an eighth of the voxels, so an eighth of the bricks to light (and
//! to classify again when the transfer function changes), and its drafts
//! take half the samples a ray. ParaView's level-of-detail rendering and
//! neuroglancer's multiscale drafts trade the same way: while the view
//! moves the picture is coarser; the still after it is the full volume's
//! frame, exactly the one the Command box reproduces.
//!
//! **The copy** ([`halved`]): about half the voxels along each axis (`n`
//! voxels become `⌈(n − 1)/2⌉ + 1`), spanning the same box (the spacing
//! grows by `r = (n − 1)/(m − 1)`, 2 for odd `n`), each value the
//! tent-filtered average of the voxels within `r` of its position
//! (weights `1 − |d|/r`: ¼, ½, ¼ for odd `n`), separable, non-finite
//! values left out (a value with none finite around it stays NaN).
//!
//! **Its frames look like the volume's** ([`draft_settings`]): the
//! transfer function's domain is the volume's value range (the copy's
//! averages span less), and its opacity, given per unit of one voxel, is
//! made per unit of the copy's larger voxel, `α' = 1 − (1 − α)^r`, at
//! enough points that the piecewise-linear function follows the curve.
//! The step stays `settings.step` in the copy's voxels: half the samples
//! a ray, each as opaque as the distance it stands for.

use rayon::prelude::*;
use volray_core::transfer::function::{PiecewiseLinear, TransferFunction};
use volray_core::{Blend, Method, RenderSettings, Sample, Volume};

/// A volume of more voxels than this (256³) is drafted from its copy.
/// Smaller ones render drafts fast enough from themselves (`fractal:129`,
/// 2.1 M voxels: 30 frames/s at 480², docs/viewer.md), and would lose
/// too much of their detail.
pub const COARSE_ABOVE: usize = 1 << 24;

/// Whether drafts of `volume` (when large) with `settings` can be
/// rendered from its coarse copy: a volume of values (labels are not
/// averaged), composited (projections light nothing, and their colour
/// map spans the volume's own range) on the fast path.
pub fn drafts_from_copy(volume: &Volume, settings: &RenderSettings) -> bool {
    !volume.is_labels()
        && volume.dims().iter().all(|&n| n >= 3)
        && settings.blend == Blend::Composite
        && settings.method == Method::Fast
        && settings.piece.is_none()
}

/// Voxels along an axis of `n` in the copy.
fn halved_side(n: usize) -> usize {
    if n < 3 { n } else { (n - 1).div_ceil(2) + 1 }
}

/// For each of the `m` voxels of an axis of `n` resampled to `m`: the
/// first voxel it averages and the weights of the voxels from there.
///
/// Voxel `j` lies at `p = j·r` (`r = (n − 1)/(m − 1)`); its value is
/// ¼ L(p − 1) + ½ L(p) + ¼ L(p + 1), `L` the linear interpolation of the
/// axis's voxels: the ¼, ½, ¼ tent where `p` is a voxel (odd `n`), and a
/// linear function kept exactly wherever it is not (even `n`). At the
/// ends, the points past the axis are left out.
fn tent(n: usize, m: usize) -> Vec<(usize, Vec<f32>)> {
    if m == n {
        return (0..n).map(|i| (i, vec![1.0])).collect();
    }
    let r = (n - 1) as f64 / (m - 1) as f64;
    (0..m)
        .map(|j| {
            let p = j as f64 * r;
            let mut weights = [0.0f64; 4];
            let lo = (p.floor() as usize).saturating_sub(1);
            for (k, c) in [(-1.0, 0.25), (0.0, 0.5), (1.0, 0.25)] {
                let q = p + k;
                if q < -1e-9 || q > (n - 1) as f64 + 1e-9 {
                    continue;
                }
                let q = q.clamp(0.0, (n - 1) as f64);
                let i = (q.floor() as usize).min(n - 2);
                let f = q - i as f64;
                weights[i - lo] += c * (1.0 - f);
                weights[i + 1 - lo] += c * f;
            }
            let last = (0..4).rev().find(|&k| weights[k] > 0.0).unwrap_or(0);
            let hi = last.min(n - 1 - lo);
            (lo, weights[..=hi].iter().map(|&w| w as f32).collect())
        })
        .collect()
}

/// The weighted average of the finite values `at(lo + k)`, NaN if none.
#[inline]
fn average(lo: usize, weights: &[f32], at: impl Fn(usize) -> f32) -> f32 {
    let (mut sum, mut total) = (0.0f32, 0.0f32);
    for (k, &w) in weights.iter().enumerate() {
        let v = at(lo + k);
        if v.is_finite() {
            sum += w * v;
            total += w;
        }
    }
    if total > 0.0 { sum / total } else { f32::NAN }
}

/// `volume` at about half its resolution along each axis, over the same
/// box (see the module documentation), as `f32`. Runs on the current
/// rayon pool.
pub fn halved(volume: &Volume) -> Volume {
    let [nx, ny, nz] = volume.dims();
    let [mx, my, mz] = volume.dims().map(halved_side);
    let (tx, ty, tz) = (tent(nx, mx), tent(ny, my), tent(nz, mz));
    // Along x, from the samples in their own type: [mx, ny, nz].
    let mut along_x = vec![0.0f32; mx * ny * nz];
    volray_core::with_samples!(volume.samples(), |data| {
        along_x
            .par_chunks_mut(mx)
            .zip(data.par_chunks(nx))
            .for_each(|(out, row)| {
                for (o, (lo, w)) in out.iter_mut().zip(&tx) {
                    *o = average(*lo, w, |i| row[i].to_f32());
                }
            })
    });
    // Along y, plane by plane: [mx, my, nz].
    let mut along_y = vec![0.0f32; mx * my * nz];
    along_y
        .par_chunks_mut(mx * my)
        .zip(along_x.par_chunks(mx * ny))
        .for_each(|(out, plane)| {
            for (j, (lo, w)) in ty.iter().enumerate() {
                for i in 0..mx {
                    out[j * mx + i] = average(*lo, w, |y| plane[y * mx + i]);
                }
            }
        });
    drop(along_x);
    // Along z, each output plane from the planes it averages.
    let plane = mx * my;
    let mut along_z = vec![0.0f32; plane * mz];
    along_z
        .par_chunks_mut(plane)
        .zip(&tz)
        .for_each(|(out, (lo, w))| {
            for (v, o) in out.iter_mut().enumerate() {
                *o = average(*lo, w, |z| along_y[z * plane + v]);
            }
        });
    let ratio = |n: usize, m: usize| (n - 1) as f64 / (m - 1).max(1) as f64;
    let spacing = volume.spacing()
        * volray_core::glam::DVec3::new(ratio(nx, mx), ratio(ny, my), ratio(nz, mz));
    Volume::new([mx, my, mz], along_z)
        .and_then(|v| v.with_spacing(spacing))
        .and_then(|v| v.with_origin(volume.origin()))
        .expect("the copy of a valid volume is valid")
}

/// How much longer the copy's smallest spacing is than the volume's: the
/// power its opacities take.
pub fn spacing_ratio(volume: &Volume, copy: &Volume) -> f64 {
    copy.spacing().min_element() / volume.spacing().min_element()
}

/// The settings that draw `settings`' draft from the copy, whose
/// smallest spacing is `ratio` times the volume's, whose values span
/// `value_range` and whose largest gradient `max_gradient` gives (asked
/// only for gradient opacity without its own maximum; see the module
/// documentation).
pub fn draft_settings(
    settings: &RenderSettings,
    value_range: (f32, f32),
    ratio: f64,
    max_gradient: impl FnOnce() -> f32,
) -> RenderSettings {
    let tf = &settings.transfer_function;
    let opacity = match &tf.opacity {
        Some(f) => f.points().to_vec(),
        // The paper's ramp, as the classifier reads it.
        None => {
            let (p, q) = settings.opacity_ramp;
            vec![(0.0, [p]), (1.0, [q])]
        }
    };
    let function =
        PiecewiseLinear::new("opacity", opacity.clone()).expect("the points of a valid function");
    // Each segment cut in eight: the power bends it.
    const CUTS: usize = 8;
    let mut points = Vec::with_capacity(opacity.len() * CUTS + 1);
    for pair in opacity.windows(2) {
        let ((t0, [a0]), (t1, _)) = (pair[0], pair[1]);
        points.push((t0, [a0]));
        if t1 > t0 {
            for k in 1..CUTS {
                let t = t0 + (t1 - t0) * k as f32 / CUTS as f32;
                points.push((t, function.eval(t)));
            }
        }
    }
    points.push(*opacity.last().expect("at least one point"));
    let thicker = |a: f32| (1.0 - (1.0 - f64::from(a)).powf(ratio)).clamp(0.0, 1.0) as f32;
    let points = points
        .into_iter()
        .map(|(t, [a])| (t, [thicker(a)]))
        .collect();
    RenderSettings {
        transfer_function: TransferFunction {
            domain: tf
                .domain
                .or(Some((f64::from(value_range.0), f64::from(value_range.1)))),
            opacity: Some(
                PiecewiseLinear::new("opacity", points).expect("values in [0, 1], sorted"),
            ),
            color: tf.color.clone(),
        },
        gradient_opacity_max: match settings.gradient_opacity {
            Some(_) => settings
                .gradient_opacity_max
                .or_else(|| Some(max_gradient())),
            None => settings.gradient_opacity_max,
        },
        ..settings.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::glam::DVec3;
    use volray_core::{FrameRequest, Render};

    #[test]
    fn an_odd_axis_halves_with_the_quarter_half_quarter_tent() {
        assert_eq!(
            tent(5, 3),
            vec![
                (0, vec![0.5, 0.25]),
                (1, vec![0.25, 0.5, 0.25]),
                (3, vec![0.25, 0.5])
            ]
        );
        assert_eq!(halved_side(257), 129);
        assert_eq!(halved_side(512), 257);
        assert_eq!(halved_side(2), 2);
    }

    #[test]
    fn a_linear_field_is_kept_exactly_on_the_same_box() {
        // f = x + 2y − 3z is its own average inside, for odd and even
        // sides; at the faces the one-sided averages lean inwards.
        let f = |p: DVec3| (p.x + 2.0 * p.y - 3.0 * p.z) as f32;
        for dims in [[9, 7, 5], [10, 8, 6]] {
            let volume = Volume::from_fn(dims, DVec3::new(0.5, 1.0, 2.0), DVec3::splat(-1.0), f)
                .unwrap()
                .to_f32();
            let copy = halved(&volume);
            assert_eq!(copy.bounds(), volume.bounds(), "{dims:?}");
            let [mx, my, mz] = copy.dims();
            for k in 1..mz - 1 {
                for j in 1..my - 1 {
                    for i in 1..mx - 1 {
                        let p = copy.world_position(i, j, k);
                        let (got, want) = (copy.get(i, j, k), f(p));
                        assert!(
                            (got - want).abs() < 1e-4,
                            "{dims:?} ({i},{j},{k}): {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn non_finite_values_are_left_out_of_the_averages() {
        let mut data = vec![1.0f32; 27];
        data[13] = f32::NAN; // the centre
        data[0] = f32::INFINITY;
        let volume = Volume::new([3, 3, 3], data).unwrap();
        let copy = halved(&volume);
        assert_eq!(copy.dims(), [2, 2, 2]);
        assert!(
            copy.values().iter().all(|&v| v == 1.0),
            "{:?}",
            copy.values()
        );
    }

    /// The mean absolute difference of two frames' channels.
    fn difference(a: &volray_core::Image, b: &volray_core::Image) -> f64 {
        let (a, b) = (a.pixels(), b.pixels());
        assert_eq!(a.len(), b.len());
        let sum: f64 = (a.iter().zip(b))
            .flat_map(|(x, y)| (0..3).map(move |c| f64::from((x[c] - y[c]).abs())))
            .sum();
        sum / (3 * a.len()) as f64
    }

    #[test]
    fn a_draft_from_the_copy_looks_like_the_volumes_and_not_without_its_settings() {
        // A soft ball over a slope of values, seen from the default view:
        // what a draft shows, at a draft's size.
        let n = 65;
        let h = 2.0 / (n - 1) as f64;
        let volume = Volume::from_fn([n; 3], DVec3::splat(h), DVec3::splat(-1.0), |p| {
            ((1.0 - p.length()).max(0.0) + 0.2 * (p.x + 1.0)) as f32
        })
        .unwrap();
        let settings = RenderSettings {
            width: 48,
            height: 48,
            opacity_ramp: (0.0, 0.3),
            ..RenderSettings::default()
        };
        let copy = halved(&volume);
        let ratio = spacing_ratio(&volume, &copy);
        assert!((ratio - 2.0).abs() < 1e-12);
        let whole = volray_core::Renderer::new(&volume).unwrap();
        let coarse = volray_core::Renderer::new(&copy).unwrap();
        let want = whole.render(FrameRequest::new(&settings)).unwrap().image();
        let drafted = draft_settings(&settings, whole.value_range(), ratio, || 1.0);
        let got = coarse.render(FrameRequest::new(&drafted)).unwrap().image();
        let plain = coarse.render(FrameRequest::new(&settings)).unwrap().image();
        let (near, off) = (difference(&got, &want), difference(&plain, &want));
        // Measured: 0.015 with the draft settings, 0.16 without.
        assert!(
            near < 0.025,
            "the copy's draft differs by {near}, without its settings {off}"
        );
        assert!(
            off > 3.0 * near,
            "the copy without its settings: {off} vs {near}"
        );
    }

    #[test]
    fn the_copys_opacity_is_as_opaque_per_world_distance() {
        let settings = RenderSettings {
            opacity_ramp: (0.1, 0.9),
            ..RenderSettings::default()
        };
        let drafted = draft_settings(&settings, (-2.0, 6.0), 2.0, || 1.0);
        let tf = &drafted.transfer_function;
        assert_eq!(tf.domain, Some((-2.0, 6.0)));
        let opacity = tf.opacity.as_ref().unwrap();
        // Two voxels of the volume are one of the copy: the light left is
        // (1 − α)² at the points, and close to it between them.
        for t in [0.0f32, 0.25, 0.5, 0.8, 1.0] {
            let a = 0.1 + 0.8 * t;
            let want = 1.0 - (1.0 - a) * (1.0 - a);
            let got = opacity.eval(t)[0];
            assert!((got - want).abs() < 0.01, "t = {t}: {got} vs {want}");
        }
        // A domain given is kept.
        let mut named = settings.clone();
        named.transfer_function.domain = Some((1.0, 2.0));
        let drafted = draft_settings(&named, (-2.0, 6.0), 2.0, || 1.0);
        assert_eq!(drafted.transfer_function.domain, Some((1.0, 2.0)));
    }
}
