//! Resampling a periodic grid on a skewed (non-orthogonal) cell onto an
//! axis-aligned grid, for crystal data: VASP CHGCAR on hexagonal or fcc
//! lattices, cube files from periodic codes, whole-cell CCP4 maps.
//!
//! volray's [`Volume`] is axis-aligned, and [`grid_to_volume`] refuses
//! skewed grids. A crystal's density is periodic, though, so its value is
//! known everywhere in space: the grid of `n_a` points along cell vector
//! `a` (point `i` at `i/n_a` of `a`, point `n_a` repeating point 0) is
//! interpolated trilinearly in its own index space, wrapping each index
//! modulo `n_a`, at the points of an orthogonal grid that covers the
//! cell's bounding box. Samples of the box outside the cell are periodic
//! images, exactly what the crystal holds there.
//!
//! A grid that is not one whole cell (a CCP4 map of part of a cell, or of
//! more than one) is not periodic: [`resample_box`] resamples its own box
//! (the parallelepiped from its first point to its last) the same way,
//! without wrapping, and marks the samples outside the box NaN.
//!
//! [`grid_to_volume`]: crate::grid_to_volume

use std::path::Path;

use volray_core::Volume;
use volray_core::glam::{DMat3, DVec3};

use crate::error::IoError;
use crate::shared::limits::format_bytes;

/// Cosine tolerance for "orthogonal", the same as `grid_to_volume`'s:
/// headers written in single precision carry cosines good to about 1e-7.
const COS_TOLERANCE: f64 = 1e-4;

/// The resampled grid holds at most this many times the file's points
/// (the bounding box of a very skewed cell is much larger than the cell;
/// beyond this the spacing grows instead).
const MAX_GROWTH: f64 = 8.0;

/// Why a grid cannot be resampled.
#[derive(Debug)]
pub(crate) enum ResampleError {
    /// The cell's geometry does not allow it; the reason says why.
    Cell(String),
    /// The resampled grid beside the file's points would take more than
    /// `limit` bytes; `need` says how much, up to the limit (as
    /// [`IoError::OverMemoryLimit`] has it).
    Memory { need: String, limit: u64 },
}

impl ResampleError {
    /// The error about the file `path`, led by the header `field` that
    /// gave the cell.
    pub(crate) fn at(self, path: &Path, field: &str) -> IoError {
        match self {
            ResampleError::Cell(reason) => IoError::invalid(path, format!("{field}: {reason}")),
            ResampleError::Memory { need, limit } => {
                IoError::over_memory_limit(path, format!("{field}: {need}"), limit)
            }
        }
    }
}

/// True if two of the step vectors are not orthogonal.
pub(crate) fn is_skewed(steps: [DVec3; 3]) -> bool {
    [(0, 1), (0, 2), (1, 2)].iter().any(|&(a, b)| {
        let (u, v) = (steps[a], steps[b]);
        let norms = u.length() * v.length();
        norms > 0.0 && (u.dot(v) / norms).abs() > COS_TOLERANCE
    })
}

/// The angles between the step vectors (between 1 and 2, 0 and 2, 0 and
/// 1, as crystallography's α, β, γ), in degrees.
pub(crate) fn angles(steps: [DVec3; 3]) -> [f64; 3] {
    let angle = |u: DVec3, v: DVec3| {
        (u.dot(v) / (u.length() * v.length()))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    };
    [
        angle(steps[1], steps[2]),
        angle(steps[0], steps[2]),
        angle(steps[0], steps[1]),
    ]
}

/// Resamples `data` (index axis 0 fastest, `dims` points, one period per
/// axis: point `dims[a]` would repeat point 0) whose index axis `a` steps
/// by `steps[a]` from `origin`, onto an axis-aligned grid covering the
/// cell's bounding box. Returns the volume and a note saying what was
/// done, naming the index axes `names` (as the file does) and lengths in
/// `unit`. The steps must be linearly independent and `data` must hold
/// `dims[0]·dims[1]·dims[2]` values. The resampled grid and `data`
/// together must fit `max_memory` bytes.
pub(crate) fn resample(
    dims: [usize; 3],
    data: &[f32],
    steps: [DVec3; 3],
    origin: DVec3,
    names: [&str; 3],
    unit: &str,
    max_memory: u64,
) -> Result<(Volume, String), ResampleError> {
    let grid = Grid::new(dims, data, steps, origin);
    let (volume, described) = grid.resample(Extent::Periodic, max_memory)?;
    let [a, b, c] = names;
    let note = format!(
        "{}: the grid was treated as one periodic cell of {} x {} x {} points ({a} x {b} x {c}) and resampled trilinearly onto {} covering the cell's bounding box; samples outside the cell are its periodic images",
        not_orthogonal(steps, names),
        dims[0],
        dims[1],
        dims[2],
        described.in_unit(unit),
    );
    Ok((volume, note))
}

/// Resamples a skewed grid that is not one periodic cell (a part of a
/// crystal's cell, or more than one) as [`resample`] does, but over the
/// grid's own box only, the parallelepiped from its first point to its
/// last: samples of the bounding box outside it are NaN, space the file
/// does not cover (to be rendered as empty).
pub(crate) fn resample_box(
    dims: [usize; 3],
    data: &[f32],
    steps: [DVec3; 3],
    origin: DVec3,
    names: [&str; 3],
    unit: &str,
    max_memory: u64,
) -> Result<(Volume, String), ResampleError> {
    if dims.iter().any(|&n| n < 2) {
        return Err(ResampleError::Cell(format!(
            "{} x {} x {} points span no box: every axis needs at least 2",
            dims[0], dims[1], dims[2]
        )));
    }
    let grid = Grid::new(dims, data, steps, origin);
    let (volume, described) = grid.resample(Extent::Box, max_memory)?;
    let [a, b, c] = names;
    let note = format!(
        "{} and the grid is not one whole periodic cell: its box of {} x {} x {} points ({a} x {b} x {c}), a parallelepiped, was resampled trilinearly onto {} covering the box; the {} samples outside the box are NaN (empty space, no data)",
        not_orthogonal(steps, names),
        dims[0],
        dims[1],
        dims[2],
        described.in_unit(unit),
        volume.len() - described.inside,
    );
    Ok((volume, note))
}

/// Resamples a sheared grid that is no crystal (a NIfTI sform that is
/// not a rotation times a scale) over its own box, as [`resample_box`]
/// does: NaN outside the parallelepiped from its first point to its last.
pub(crate) fn resample_sheared(
    dims: [usize; 3],
    data: &[f32],
    steps: [DVec3; 3],
    origin: DVec3,
    names: [&str; 3],
    unit: &str,
    max_memory: u64,
) -> Result<(Volume, String), ResampleError> {
    if dims.iter().any(|&n| n < 2) {
        return Err(ResampleError::Cell(format!(
            "{} x {} x {} points span no box: every axis needs at least 2",
            dims[0], dims[1], dims[2]
        )));
    }
    let grid = Grid::new(dims, data, steps, origin);
    let (volume, described) = grid.resample(Extent::Box, max_memory)?;
    let [a, b, c] = names;
    let note = format!(
        "{}: the grid's box of {} x {} x {} points ({a} x {b} x {c}), a parallelepiped, was resampled trilinearly onto {} covering the box; the {} samples outside the box are NaN (empty space, no data)",
        not_orthogonal(steps, names),
        dims[0],
        dims[1],
        dims[2],
        described.in_unit(unit),
        volume.len() - described.inside,
    );
    Ok((volume, note))
}

/// "the grid axes are not orthogonal (angle(b, c) ..., ... degrees)", the
/// axes named `names`.
fn not_orthogonal(steps: [DVec3; 3], names: [&str; 3]) -> String {
    let [alpha, beta, gamma] = angles(steps);
    let [a, b, c] = names;
    format!(
        "the grid axes are not orthogonal (angle({b}, {c}) {alpha:.3}, angle({a}, {c}) {beta:.3}, angle({a}, {b}) {gamma:.3} degrees)"
    )
}

/// A file's grid: `dims` points, index axis 0 fastest, axis `a` stepping
/// by `steps[a]` from `origin`.
struct Grid<'d> {
    dims: [usize; 3],
    data: &'d [f32],
    steps: [DVec3; 3],
    origin: DVec3,
}

/// What part of space a grid's values cover.
#[derive(Clone, Copy, PartialEq)]
enum Extent {
    /// All of it: the grid is one period of a crystal, `dims[a]` steps long.
    Periodic,
    /// Its own box only, `dims[a] - 1` steps long.
    Box,
}

/// The axis-aligned grid a cell was resampled onto, for notes.
struct Described {
    dims: [usize; 3],
    spacing: DVec3,
    lo: DVec3,
    /// Samples inside the cell or box (the others are periodic images or NaN).
    inside: usize,
}

impl Described {
    fn in_unit(&self, unit: &str) -> String {
        let ([nx, ny, nz], s, lo) = (self.dims, self.spacing, self.lo);
        format!(
            "an orthogonal {nx}x{ny}x{nz} grid with spacing {:.6}, {:.6}, {:.6} {unit} from ({:.6}, {:.6}, {:.6})",
            s.x, s.y, s.z, lo.x, lo.y, lo.z
        )
    }
}

impl<'d> Grid<'d> {
    fn new(dims: [usize; 3], data: &'d [f32], steps: [DVec3; 3], origin: DVec3) -> Self {
        Grid {
            dims,
            data,
            steps,
            origin,
        }
    }

    fn resample(
        &self,
        extent_kind: Extent,
        max_memory: u64,
    ) -> Result<(Volume, Described), ResampleError> {
        let Grid {
            dims,
            data,
            steps,
            origin,
        } = *self;
        // The steps each cell vector spans.
        let spans = dims.map(|n| match extent_kind {
            Extent::Periodic => n as f64,
            Extent::Box => (n - 1) as f64,
        });
        let cell = DMat3::from_cols(
            steps[0] * spans[0],
            steps[1] * spans[1],
            steps[2] * spans[2],
        );
        let volume = cell.determinant().abs();
        let to_grid = DMat3::from_cols(steps[0], steps[1], steps[2]);
        if !(volume.is_finite() && volume > 0.0) || to_grid.determinant() == 0.0 {
            return Err(ResampleError::Cell(
                "the cell vectors are linearly dependent (the cell has no volume)".into(),
            ));
        }
        let to_grid = to_grid.inverse();

        // The bounding box of the cell: each world axis spans the sum of the
        // negative and of the positive components of the cell vectors.
        let mut lo = origin;
        let mut extent = DVec3::ZERO;
        for a in 0..3 {
            let v = cell.col(a);
            lo += v.min(DVec3::ZERO);
            extent += v.abs();
        }
        // Isotropic spacing: the file's finest step, so no detail is lost,
        // grown if the box would hold more than MAX_GROWTH times the file's
        // points.
        let points = (dims[0] * dims[1] * dims[2]) as f64;
        let mut h = steps[0]
            .length()
            .min(steps[1].length())
            .min(steps[2].length());
        let box_points = extent.x * extent.y * extent.z / (h * h * h);
        if box_points > MAX_GROWTH * points {
            h *= (box_points / (MAX_GROWTH * points)).cbrt();
        }
        if !(extent.is_finite() && h.is_finite() && h > 0.0) {
            return Err(ResampleError::Cell(format!(
                "the cell's bounding box ({}, {}, {}) cannot be sampled",
                extent.x, extent.y, extent.z
            )));
        }
        let mut out_dims = [0usize; 3];
        let mut spacing = DVec3::ZERO;
        for w in 0..3 {
            // Each axis holds at most the capped total (plus rounding).
            let steps = (extent[w] / h)
                .round()
                .clamp(1.0, 2.0 * MAX_GROWTH * points);
            let n = steps as usize + 1;
            out_dims[w] = n;
            spacing[w] = extent[w] / (n - 1) as f64;
        }
        let [nx, ny, nz] = out_dims;
        // After the cap, rounding each axis up by at most 1.5 samples can
        // multiply the count by at most 2.5^3 < 16: a safety net only.
        let total = nx as f64 * ny as f64 * nz as f64;
        if total > 16.0 * MAX_GROWTH * points + 4096.0 {
            return Err(ResampleError::Cell(format!(
                "the cell's bounding box would need {nx}x{ny}x{nz} samples, far more than the file's {points} points"
            )));
        }
        let held = (total + data.len() as f64) * 4.0;
        if held > max_memory as f64 {
            return Err(ResampleError::Memory {
                need: format!(
                    "resampling onto {nx}x{ny}x{nz} points beside the file's {points} takes {} as f32, more than",
                    format_bytes(held as u128)
                ),
                limit: max_memory,
            });
        }
        let mut out = Vec::with_capacity(nx * ny * nz);
        let mut inside = 0;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let p = lo + DVec3::new(i as f64, j as f64, k as f64) * spacing;
                    let g = to_grid * (p - origin);
                    let value = match extent_kind {
                        Extent::Periodic => {
                            if (0..3).all(|a| g[a] >= 0.0 && g[a] < spans[a]) {
                                inside += 1;
                            }
                            self.periodic(g)
                        }
                        Extent::Box => match self.bounded(g) {
                            Some(v) => {
                                inside += 1;
                                v
                            }
                            None => f32::NAN,
                        },
                    };
                    out.push(value);
                }
            }
        }
        let volume = Volume::new(out_dims, out)
            .and_then(|v| v.with_spacing(spacing))
            .and_then(|v| v.with_origin(lo))
            .map_err(|e| ResampleError::Cell(e.to_string()))?;
        let described = Described {
            dims: out_dims,
            spacing,
            lo,
            inside,
        };
        Ok((volume, described))
    }

    /// The value at grid coordinates `g`, each index wrapped into the
    /// period.
    fn periodic(&self, g: DVec3) -> f32 {
        let dims = self.dims;
        let mut base = [0usize; 3];
        let mut next = [0usize; 3];
        let mut t = [0.0f64; 3];
        for a in 0..3 {
            let n = dims[a] as f64;
            let f = g[a].floor();
            t[a] = g[a] - f;
            // rem_euclid keeps negative and far-away cells in [0, n).
            let i = f.rem_euclid(n) as usize % dims[a];
            base[a] = i;
            next[a] = (i + 1) % dims[a];
        }
        self.trilinear(base, next, t)
    }

    /// The value at grid coordinates `g` within the box (each coordinate
    /// 0 to `dims[a] - 1`, up to rounding), or `None` outside it.
    fn bounded(&self, g: DVec3) -> Option<f32> {
        let dims = self.dims;
        let mut base = [0usize; 3];
        let mut next = [0usize; 3];
        let mut t = [0.0f64; 3];
        for a in 0..3 {
            let last = (dims[a] - 1) as f64;
            let tol = 1e-9 * last.max(1.0);
            if !(g[a] >= -tol && g[a] <= last + tol) {
                return None;
            }
            let x = g[a].clamp(0.0, last);
            let i = (x.floor() as usize).min(dims[a] - 2);
            base[a] = i;
            next[a] = i + 1;
            t[a] = x - i as f64;
        }
        Some(self.trilinear(base, next, t))
    }

    /// Trilinear interpolation between the corners `base` and `next`.
    fn trilinear(&self, base: [usize; 3], next: [usize; 3], t: [f64; 3]) -> f32 {
        let dims = self.dims;
        let at =
            |i: usize, j: usize, k: usize| f64::from(self.data[i + dims[0] * (j + dims[1] * k)]);
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let c00 = lerp(
            at(base[0], base[1], base[2]),
            at(next[0], base[1], base[2]),
            t[0],
        );
        let c10 = lerp(
            at(base[0], next[1], base[2]),
            at(next[0], next[1], base[2]),
            t[0],
        );
        let c01 = lerp(
            at(base[0], base[1], next[2]),
            at(next[0], base[1], next[2]),
            t[0],
        );
        let c11 = lerp(
            at(base[0], next[1], next[2]),
            at(next[0], next[1], next[2]),
            t[0],
        );
        let c0 = lerp(c00, c10, t[1]);
        let c1 = lerp(c01, c11, t[1]);
        lerp(c0, c1, t[2]) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(dims: [usize; 3]) -> Vec<f32> {
        let mut v = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    v.push((i + 10 * j + 100 * k) as f32);
                }
            }
        }
        v
    }

    /// A hexagonal cell (γ = 120°) tilted c axis.
    fn hexagonal() -> ([usize; 3], [DVec3; 3]) {
        let dims = [6, 6, 5];
        let a = DVec3::new(3.0, 0.0, 0.0);
        let b = DVec3::new(-1.5, 1.5 * 3f64.sqrt(), 0.0);
        let c = DVec3::new(0.5, 0.25, 4.0);
        (
            dims,
            [a / dims[0] as f64, b / dims[1] as f64, c / dims[2] as f64],
        )
    }

    #[test]
    fn skew_and_angles() {
        let (_, steps) = hexagonal();
        assert!(is_skewed(steps));
        assert!(!is_skewed([DVec3::X, DVec3::Y * 2.0, DVec3::Z]));
        let angles = angles([DVec3::X, DVec3::new(-0.5, 0.75f64.sqrt(), 0.0), DVec3::Z]);
        assert!((angles[2] - 120.0).abs() < 1e-9, "{angles:?}");
        assert!((angles[0] - 90.0).abs() < 1e-9);
    }

    /// Every output sample must equal the trilinear interpolation of the
    /// file's grid at its position: inside one grid cell that does not
    /// wrap, the ramp i + 10j + 100k is reproduced exactly from the
    /// point's fractional grid coordinates.
    #[test]
    fn interior_samples_reproduce_a_trilinear_ramp() {
        let (dims, steps) = hexagonal();
        let origin = DVec3::new(1.0, -2.0, 0.5);
        let (v, note) = resample(
            dims,
            &ramp(dims),
            steps,
            origin,
            ["a", "b", "c"],
            "angstrom",
            u64::MAX,
        )
        .unwrap();
        assert!(note.contains("angle(a, b) 120.000"), "{note}");
        let to_grid = DMat3::from_cols(steps[0], steps[1], steps[2]).inverse();
        let [nx, ny, nz] = v.dims();
        let mut checked = 0;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let g = to_grid * (v.world_position(i, j, k) - origin);
                    let inside = (0..3).all(|a| g[a] >= 0.0 && g[a] <= (dims[a] - 1) as f64);
                    if inside {
                        let expect = g.x + 10.0 * g.y + 100.0 * g.z;
                        assert!(
                            (f64::from(v.get(i, j, k)) - expect).abs() < 1e-3,
                            "({i}, {j}, {k}): {} vs {expect}",
                            v.get(i, j, k)
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 50, "only {checked} samples inside the cell");
    }

    /// Samples outside the cell equal those one lattice vector away, and
    /// the box covers the whole cell.
    #[test]
    fn outside_samples_are_periodic_images() {
        let (dims, steps) = hexagonal();
        let data: Vec<f32> = ramp(dims).iter().map(|v| (v * 0.37).sin()).collect();
        let (v, _) = resample(
            dims,
            &data,
            steps,
            DVec3::ZERO,
            ["a", "b", "c"],
            "bohr",
            u64::MAX,
        )
        .unwrap();
        let (lo, hi) = v.bounds();
        let cell = [
            steps[0] * dims[0] as f64,
            steps[1] * dims[1] as f64,
            steps[2] * dims[2] as f64,
        ];
        for corner in 0..8 {
            let mut p = DVec3::ZERO;
            for (a, vec) in cell.iter().enumerate() {
                if corner & (1 << a) != 0 {
                    p += *vec;
                }
            }
            assert!(p.cmpge(lo - 1e-9).all() && p.cmple(hi + 1e-9).all(), "{p}");
        }
        // Interpolate the resampled volume's own samples against an
        // independent periodic evaluation at a shifted position.
        let to_grid = DMat3::from_cols(steps[0], steps[1], steps[2]).inverse();
        let direct = |p: DVec3| -> f64 {
            let g = to_grid * p;
            let mut acc = 0.0;
            for corner in 0..8 {
                let mut w = 1.0;
                let mut idx = [0usize; 3];
                for a in 0..3 {
                    let f = g[a].floor();
                    let t = g[a] - f;
                    let up = corner & (1 << a) != 0;
                    w *= if up { t } else { 1.0 - t };
                    let n = dims[a] as i64;
                    idx[a] = ((f as i64 + i64::from(up)).rem_euclid(n)) as usize;
                }
                acc += w * f64::from(data[idx[0] + dims[0] * (idx[1] + dims[1] * idx[2])]);
            }
            acc
        };
        let [nx, ny, nz] = v.dims();
        for (i, j, k) in [(0, 0, 0), (nx - 1, ny - 1, nz - 1), (nx / 2, 1, nz - 1)] {
            let p = v.world_position(i, j, k);
            let got = f64::from(v.get(i, j, k));
            assert!((got - direct(p)).abs() < 1e-5, "{got} vs {}", direct(p));
            assert!((got - direct(p + cell[0] - cell[2])).abs() < 1e-5);
        }
    }

    #[test]
    fn very_skewed_cells_are_capped() {
        let dims = [4, 4, 4];
        let t = 5f64.to_radians();
        let steps = [
            DVec3::X,
            DVec3::new(t.cos(), t.sin(), 0.0),
            DVec3::new(t.cos(), 0.0, t.sin()),
        ];
        let (v, _) = resample(
            dims,
            &ramp(dims),
            steps,
            DVec3::ZERO,
            ["a", "b", "c"],
            "angstrom",
            u64::MAX,
        )
        .unwrap();
        assert!(v.len() as f64 <= MAX_GROWTH * 64.0 * 1.5, "{}", v.len());
        let flat = [DVec3::X, DVec3::Y, DVec3::X + DVec3::Y];
        assert!(
            resample(
                dims,
                &ramp(dims),
                flat,
                DVec3::ZERO,
                ["a", "b", "c"],
                "bohr",
                u64::MAX
            )
            .is_err()
        );
    }
}
