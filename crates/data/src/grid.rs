//! The grid shared by the analytic sources: `n` points per side spanning the
//! cube `[−h, h]³` (h = 1 for the built-in sources), point `i` at
//! `h·(−1 + 2i/(n − 1))`.

use rayon::prelude::*;
use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::DataError;

/// Fewest points per side: a volume needs extent along every axis.
pub const MIN_POINTS: usize = 2;

/// Most points per side: 1025³ f32 voxels are 4.3 GB.
pub const MAX_POINTS: usize = 1025;

/// Checks a points-per-side count against [`MIN_POINTS`]..=[`MAX_POINTS`],
/// returning the message for [`DataError::Invalid`].
pub fn check_points(n: usize) -> Result<(), String> {
    if n < MIN_POINTS {
        Err(format!(
            "grid must have at least {MIN_POINTS} points per side, got {n}"
        ))
    } else if n > MAX_POINTS {
        Err(format!(
            "grid must have at most {MAX_POINTS} points per side, got {n}"
        ))
    } else {
        Ok(())
    }
}

/// Coordinate of point `i` of `n` on `[−1, 1]`: `−1 + 2i/(n − 1)`.
///
/// Computed as `(2i − (n − 1))/(n − 1)`, one correctly rounded division, so
/// the ends are exactly ±1, the middle of an odd grid is exactly 0 and the
/// grid is exactly mirror symmetric: `coordinate(n − 1 − i, n) ==
/// −coordinate(i, n)`.
pub fn coordinate(i: usize, n: usize) -> f64 {
    debug_assert!(n >= 2 && i < n);
    let last = (n - 1) as f64;
    (2.0 * i as f64 - last) / last
}

/// A volume of `n³` points on `[−h, h]³` (h = `half_width`) whose value at
/// each point is `f(position)`, computed in `f64` and stored as `f32`.
///
/// The volume's origin is `(−h, −h, −h)` and its spacing `2h/(n − 1)`; `f`
/// is evaluated at `h ·` [`coordinate`] on each axis (equal to
/// `origin + i·spacing` up to rounding, but exactly symmetric). Slices are
/// computed in parallel. `spec` names the source in errors.
pub fn cube_volume(
    spec: &str,
    n: usize,
    half_width: f64,
    f: impl Fn(DVec3) -> f64 + Sync,
) -> Result<Volume, DataError> {
    check_points(n).map_err(DataError::invalid(spec))?;
    if !(half_width.is_finite() && half_width > 0.0) {
        return Err(DataError::Invalid {
            spec: spec.to_string(),
            message: format!("grid half width must be positive and finite, got {half_width}"),
        });
    }
    // The whole grid, or the box `generate_box` asked for.
    let (lo, hi) = WINDOW.get().unwrap_or(([0; 3], [n; 3]));
    if (0..3).any(|a| lo[a] + 2 > hi[a] || hi[a] > n) {
        return Err(DataError::Invalid {
            spec: spec.to_string(),
            message: format!("box {lo:?}..{hi:?} is not inside the {n}³ grid"),
        });
    }
    let coords = |a: usize| -> Vec<f64> {
        (lo[a]..hi[a])
            .map(|i| half_width * coordinate(i, n))
            .collect()
    };
    let (xs, ys, zs) = (coords(0), coords(1), coords(2));
    let (nx, ny) = (xs.len(), ys.len());
    let mut data = vec![0.0f32; nx * ny * zs.len()];
    data.par_chunks_mut(nx * ny)
        .zip(zs.par_iter())
        .for_each(|(slice, &z)| {
            for (row, &y) in slice.chunks_mut(nx).zip(&ys) {
                for (v, &x) in row.iter_mut().zip(&xs) {
                    *v = f(DVec3::new(x, y, z)) as f32;
                }
            }
        });
    let volume_error = |error| DataError::Volume {
        spec: spec.to_string(),
        error,
    };
    let spacing = DVec3::splat(2.0 * half_width / (n - 1) as f64);
    // The box's first voxel where `Volume::sub_box` of the whole puts it.
    let first = DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
    Volume::new([nx, ny, zs.len()], data)
        .and_then(|v| v.with_spacing(spacing))
        .and_then(|v| v.with_origin(DVec3::splat(-half_width) + first * spacing))
        .map_err(volume_error)
}

thread_local! {
    /// The box of voxels [`cube_volume`] samples on this thread, if not
    /// the whole grid: set by [`generate_box`] around one generation.
    static WINDOW: std::cell::Cell<Option<([usize; 3], [usize; 3])>> =
        const { std::cell::Cell::new(None) };
}

/// The voxels `lo..hi` (half-open) of the volume `spec` generates, as
/// `generate(spec)?.sub_box(lo, hi)` would give them, bit for bit, with
/// their world placement. The sources sampled point by point on a cube
/// grid (all but the fractal) compute only those voxels; the fractal
/// (midpoint displacement, a whole-grid process) is generated whole and
/// cut. A rank of a distributed render generates its box so.
pub fn generate_box(spec: &str, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, DataError> {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            WINDOW.set(None);
        }
    }
    let volume = {
        WINDOW.set(Some((lo, hi)));
        let _reset = Reset;
        crate::generate(spec)?
    };
    let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
    if volume.dims() == dims {
        return Ok(volume);
    }
    let whole = volume.dims();
    if (0..3).any(|a| lo[a] + 2 > hi[a] || hi[a] > whole[a]) {
        return Err(DataError::Invalid {
            spec: spec.to_string(),
            message: format!("box {lo:?}..{hi:?} is not inside the {whole:?} grid"),
        });
    }
    Ok(volume.sub_box(lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_follow_the_convention() {
        for n in [2, 3, 9, 40, 41, 64, 1025] {
            assert_eq!(coordinate(0, n), -1.0);
            assert_eq!(coordinate(n - 1, n), 1.0);
            for i in 0..n {
                let expected = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
                assert!((coordinate(i, n) - expected).abs() <= 2.0 * f64::EPSILON);
                assert_eq!(coordinate(n - 1 - i, n), -coordinate(i, n));
            }
            if n % 2 == 1 {
                assert_eq!(coordinate(n / 2, n), 0.0);
            }
        }
        assert_eq!(coordinate(1, 3), 0.0);
        assert_eq!(coordinate(1, 5), -0.5);
        assert_eq!(coordinate(10, 41), -0.5);
    }

    #[test]
    fn cube_volume_geometry_and_layout() {
        let n = 5;
        let v = cube_volume("t", n, 1.0, |p| p.x + 10.0 * p.y + 100.0 * p.z).unwrap();
        assert_eq!(v.dims(), [5, 5, 5]);
        assert_eq!(v.origin(), DVec3::splat(-1.0));
        assert_eq!(v.spacing(), DVec3::splat(0.5));
        assert_eq!(v.bounds(), (DVec3::splat(-1.0), DVec3::splat(1.0)));
        // x fastest: value at (i, j, k) encodes its own position.
        for (i, j, k) in [
            (0, 0, 0),
            (4, 0, 0),
            (0, 4, 0),
            (0, 0, 4),
            (1, 2, 3),
            (4, 4, 4),
        ] {
            let p = v.world_position(i, j, k);
            assert_eq!(v.get(i, j, k), (p.x + 10.0 * p.y + 100.0 * p.z) as f32);
        }
        assert_eq!(v.get(4, 0, 0), 1.0 - 10.0 - 100.0);

        let v = cube_volume("t", 3, 2.5, |p| p.x).unwrap();
        assert_eq!(v.origin(), DVec3::splat(-2.5));
        assert_eq!(v.spacing(), DVec3::splat(2.5));
        assert_eq!(v.values()[..3], [-2.5, 0.0, 2.5]);
    }

    #[test]
    fn cube_volume_rejects_bad_grids() {
        let e = cube_volume("src:1", 1, 1.0, |_| 0.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "src:1: grid must have at least 2 points per side, got 1"
        );
        let e = cube_volume("src:1026", 1026, 1.0, |_| 0.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "src:1026: grid must have at most 1025 points per side, got 1026"
        );
        assert!(cube_volume("s", 2, 0.0, |_| 0.0).is_err());
        assert!(cube_volume("s", 2, f64::NAN, |_| 0.0).is_err());
        assert!(check_points(2).is_ok() && check_points(1025).is_ok());
        assert!(check_points(0).is_err());
    }

    #[test]
    fn a_box_of_a_source_is_the_same_box_of_the_whole_volume() {
        for spec in [
            "marschner-lobb:17",
            "blobs:12",
            "hydrogen:3,2,1,grid=15",
            "sphere:11",
            "torus:11",
            "fractal:17",
        ] {
            let whole = crate::generate(spec).unwrap();
            let (lo, hi) = ([1, 0, 3], [6, 9, 11.min(whole.dims()[2])]);
            let part = generate_box(spec, lo, hi).unwrap();
            assert_eq!(part, whole.sub_box(lo, hi), "{spec}");
        }
        // The window is gone afterwards: the whole grid again.
        assert_eq!(crate::generate("blobs:12").unwrap().dims(), [12; 3]);
        assert!(generate_box("blobs:12", [0; 3], [13, 2, 2]).is_err());
    }
}
