//! From a file's grid geometry to the [`Volume`]'s axis-aligned one.
//!
//! Formats describe a grid by an origin and one world-space step vector
//! per index axis (NRRD `space directions`, NIfTI `sform`, DICOM image
//! orientation and slice positions, MetaImage `TransformMatrix`, cube
//! voxel vectors). volray's [`Volume`] is axis-aligned with positive
//! spacing, so [`grid_to_volume`] maps one onto the other:
//!
//! - steps along ± world axes (any order): the samples are reordered and
//!   flipped so that index x, y, z run along world +x, +y, +z; nothing is
//!   resampled and world positions are kept exactly;
//! - orthogonal steps rotated away from the world axes: the grid is kept in
//!   its own index axes with spacing |step| (what VTK before 9.0 and many
//!   viewers do), and a note says the rotation was not applied;
//! - non-orthogonal (skewed) steps: refused; a reader that can resample
//!   (Gaussian cube, CHGCAR) does so before calling this;
//! - a grid one sample thick along an axis (a slice, a 2-D image): no
//!   volume, but an [`IoError::FlatImage`] carrying what was read.

use std::path::Path;

use volray_core::glam::DVec3;
use volray_core::{Samples, Volume, with_samples};

use crate::FileInfo;
use crate::error::IoError;

/// What a grid one sample thick holds, as an [`IoError::FlatImage`]: the
/// samples in the file's index order, the spacing |step| along each axis
/// (1 where the step is not a length, as along a single slice).
fn flat_image(
    path: &Path,
    dims: [usize; 3],
    data: Vec<f32>,
    steps: [DVec3; 3],
    origin: DVec3,
    info: &FileInfo,
) -> IoError {
    let spacing = steps.map(|s| {
        let len = s.length();
        if len.is_finite() && len > 0.0 {
            len
        } else {
            1.0
        }
    });
    let shown: Vec<String> = dims
        .iter()
        .filter(|&&n| n > 1)
        .map(|n| n.to_string())
        .collect();
    let reason = format!(
        "a {}-D image ({} samples), not a volume: volray renders volumes of at least 2 points along each axis",
        shown.len(),
        if shown.is_empty() {
            "1".to_string()
        } else {
            shown.join(" x ")
        }
    );
    IoError::FlatImage {
        path: path.to_path_buf(),
        image: Box::new(crate::FlatImage {
            format: crate::VolumeFormat::Raw,
            dims,
            spacing: DVec3::from(spacing),
            origin: if origin.is_finite() {
                origin
            } else {
                DVec3::ZERO
            },
            values: data,
            info: info.clone(),
            reason,
        }),
    }
}

/// Cosine tolerance for "parallel" and "orthogonal": headers written with
/// single precision carry direction cosines good to about 1e-7.
const COS_TOLERANCE: f64 = 1e-4;

/// Builds the volume for `data` (index axis 0 fastest, `dims` points)
/// whose index axis `a` steps by `steps[a]` in world space from `origin`
/// (the world position of sample (0, 0, 0)). What was done to fit the
/// grid to volray's axis-aligned volume is added to `info.notes`.
pub fn grid_to_volume(
    path: &Path,
    dims: [usize; 3],
    data: impl Into<Samples>,
    steps: [DVec3; 3],
    origin: DVec3,
    info: &mut FileInfo,
) -> Result<Volume, IoError> {
    let data = data.into();
    if dims.contains(&1) && !dims.contains(&0) {
        return Err(flat_image(
            path,
            dims,
            data.to_f32_vec(),
            steps,
            origin,
            info,
        ));
    }
    if !origin.is_finite() {
        return Err(IoError::invalid(
            path,
            format!(
                "origin ({}, {}, {}) is not finite",
                origin.x, origin.y, origin.z
            ),
        ));
    }
    let mut units = [DVec3::ZERO; 3];
    let mut lengths = [0.0; 3];
    for a in 0..3 {
        let len = steps[a].length();
        if !(len.is_finite() && len > 0.0) {
            let s = steps[a];
            return Err(IoError::invalid(
                path,
                format!(
                    "grid step along index axis {a} is ({}, {}, {}): it must be finite and non-zero",
                    s.x, s.y, s.z
                ),
            ));
        }
        lengths[a] = len;
        units[a] = steps[a] / len;
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let cos = units[a].dot(units[b]);
        if cos.abs() > COS_TOLERANCE {
            let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
            return Err(IoError::invalid(
                path,
                format!(
                    "grid axes {a} and {b} meet at {angle:.3} degrees, not 90: volray renders orthogonal grids only"
                ),
            ));
        }
    }

    // Which world axis each index axis runs along, and in which sense.
    let mut world_axis = [usize::MAX; 3];
    let mut flipped = [false; 3];
    for (a, unit) in units.iter().enumerate() {
        for w in 0..3 {
            if unit[w].abs() > 1.0 - COS_TOLERANCE {
                world_axis[a] = w;
                flipped[a] = unit[w] < 0.0;
            }
        }
    }
    if world_axis.contains(&usize::MAX) {
        info.notes.push(format!(
            "the grid axes are rotated away from world x, y, z (directions ({:.4}, {:.4}, {:.4}), ({:.4}, {:.4}, {:.4}), ({:.4}, {:.4}, {:.4})): rendered in the grid's own axes with spacing {}, {}, {}; the rotation is not applied",
            units[0].x, units[0].y, units[0].z,
            units[1].x, units[1].y, units[1].z,
            units[2].x, units[2].y, units[2].z,
            lengths[0], lengths[1], lengths[2],
        ));
        return Volume::from_samples(dims, data)
            .and_then(|v| v.with_spacing(DVec3::from(lengths)))
            .and_then(|v| v.with_origin(origin))
            .map_err(|e| IoError::volume(path, e));
    }

    let identity = world_axis == [0, 1, 2] && flipped == [false; 3];
    let mut new_dims = [0; 3];
    let mut spacing = DVec3::ZERO;
    let mut new_origin = origin;
    for a in 0..3 {
        new_dims[world_axis[a]] = dims[a];
        spacing[world_axis[a]] = lengths[a];
        if flipped[a] {
            new_origin += steps[a] * (dims[a].saturating_sub(1)) as f64;
        }
    }
    if !identity && data.is_external() {
        // A mapping cannot be reordered in place: the volume stays in the
        // file's axes, and whoever reads it by boxes reorders each box
        // (`read` refuses it unless asked for, by
        // `MapPolicy::AlwaysInFileOrder`).
        let reorientation = Reorientation {
            file_dims: dims,
            world_axis,
            flipped,
            spacing,
            origin: new_origin,
        };
        info.notes.push(format!(
            "mapped in the file's own axis order; each box read is reordered so that x, y, z run along world +x, +y, +z ({})",
            reorientation.describe()
        ));
        info.reorientation = Some(reorientation);
        return Volume::from_samples(dims, data)
            .and_then(|v| v.with_spacing(DVec3::from(lengths)))
            .and_then(|v| v.with_origin(origin))
            .map_err(|e| IoError::volume(path, e));
    }
    let data = if identity {
        data
    } else {
        let map = Reorientation {
            file_dims: dims,
            world_axis,
            flipped,
            spacing,
            origin: new_origin,
        }
        .describe();
        info.notes.push(format!(
            "samples reordered so that x, y, z run along world +x, +y, +z ({map})"
        ));
        with_samples!(&data, |values| Samples::from(reorder(
            values, dims, world_axis, flipped
        )))
    };
    Volume::from_samples(new_dims, data)
        .and_then(|v| v.with_spacing(spacing))
        .and_then(|v| v.with_origin(new_origin))
        .map_err(|e| IoError::volume(path, e))
}

/// How a grid stored along other axes, or along them backwards, maps onto
/// the world-aligned volume, for a volume kept in the file's own axis
/// order (mapped: see [`MapPolicy::AlwaysInFileOrder`](crate::MapPolicy)).
/// [`Reorientation::sub_box`] reads a box of the world-aligned volume
/// from the file's grid: only the file's pages holding that box are read,
/// and only the box is reordered.
#[derive(Debug, Clone, PartialEq)]
pub struct Reorientation {
    /// Samples along each of the file's index axes.
    pub file_dims: [usize; 3],
    /// The world axis each file index axis runs along.
    pub world_axis: [usize; 3],
    /// Whether it runs along it backwards.
    pub flipped: [bool; 3],
    /// The world-aligned volume's spacing and the world position of its
    /// sample (0, 0, 0).
    pub spacing: DVec3,
    pub origin: DVec3,
}

impl Reorientation {
    /// The world-aligned volume's samples along x, y, z.
    pub fn dims(&self) -> [usize; 3] {
        let mut dims = [0; 3];
        for a in 0..3 {
            dims[self.world_axis[a]] = self.file_dims[a];
        }
        dims
    }

    /// The box of the file's grid (in its index axes) holding the box
    /// `lo..hi` (half-open) of the world-aligned volume.
    pub fn file_box(&self, lo: [usize; 3], hi: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let mut file_lo = [0; 3];
        let mut file_hi = [0; 3];
        for a in 0..3 {
            let w = self.world_axis[a];
            if self.flipped[a] {
                // World index i is file index n - 1 - i.
                file_lo[a] = self.file_dims[a] - hi[w];
                file_hi[a] = self.file_dims[a] - lo[w];
            } else {
                file_lo[a] = lo[w];
                file_hi[a] = hi[w];
            }
        }
        (file_lo, file_hi)
    }

    /// The box `lo..hi` (half-open, at least 2 samples along each axis) of
    /// the world-aligned volume, from `file`, the file's grid as read in
    /// its own axes: the file's box copied out, then reordered. Keeps the
    /// sample type and the label mark.
    pub fn sub_box(
        &self,
        file: &Volume,
        lo: [usize; 3],
        hi: [usize; 3],
    ) -> Result<Volume, volray_core::VolumeError> {
        let (file_lo, file_hi) = self.file_box(lo, hi);
        let piece = file.sub_box(file_lo, file_hi);
        let piece_dims = piece.dims();
        let samples = with_samples!(piece.samples(), |values| Samples::from(reorder(
            values,
            piece_dims,
            self.world_axis,
            self.flipped
        )));
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let origin =
            self.origin + DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64) * self.spacing;
        let mut v = Volume::from_samples(dims, samples)
            .and_then(|v| v.with_spacing(self.spacing))
            .and_then(|v| v.with_origin(origin))?;
        v.set_labels(file.is_labels());
        Ok(v)
    }

    /// Each file index axis and the world axis it runs along, e.g.
    /// `index axis 0 -> -x, index axis 1 -> +y, index axis 2 -> +z`.
    fn describe(&self) -> String {
        let names = ["x", "y", "z"];
        let map: Vec<String> = (0..3)
            .map(|a| {
                format!(
                    "index axis {a} -> {}{}",
                    if self.flipped[a] { "-" } else { "+" },
                    names[self.world_axis[a]]
                )
            })
            .collect();
        map.join(", ")
    }
}

/// Permutes (and flips) the axes of `data`: old index axis `a` becomes new
/// axis `world_axis[a]`, reversed where `flipped[a]`.
fn reorder<T: Copy>(
    data: &[T],
    dims: [usize; 3],
    world_axis: [usize; 3],
    flipped: [bool; 3],
) -> Vec<T> {
    let old_strides = [1, dims[0], dims[0] * dims[1]];
    let mut new_dims = [0; 3];
    // Per new axis: the old stride and whether it runs backwards.
    let mut stride = [0isize; 3];
    let mut start = 0isize;
    for a in 0..3 {
        let w = world_axis[a];
        new_dims[w] = dims[a];
        let s = old_strides[a] as isize;
        if flipped[a] {
            stride[w] = -s;
            start += s * (dims[a] as isize - 1);
        } else {
            stride[w] = s;
        }
    }
    let mut out = Vec::with_capacity(data.len());
    for k in 0..new_dims[2] as isize {
        for j in 0..new_dims[1] as isize {
            let row = start + j * stride[1] + k * stride[2];
            out.extend((0..new_dims[0] as isize).map(|i| data[(row + i * stride[0]) as usize]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(dims: [usize; 3]) -> Vec<f32> {
        (0..dims[0] * dims[1] * dims[2]).map(|i| i as f32).collect()
    }

    /// World position of every sample, computed from the file's geometry,
    /// must equal the position of the same value in the volume.
    fn check_positions(dims: [usize; 3], steps: [DVec3; 3], origin: DVec3) -> FileInfo {
        let mut info = FileInfo::default();
        let data = ramp(dims);
        let v =
            grid_to_volume(Path::new("f"), dims, data.clone(), steps, origin, &mut info).unwrap();
        let [nx, ny, _] = v.dims();
        for (n, &value) in v.values().iter().enumerate() {
            let (i, j, k) = (n % nx, (n / nx) % ny, n / (nx * ny));
            let old = value as usize;
            let (a, b, c) = (
                old % dims[0],
                (old / dims[0]) % dims[1],
                old / (dims[0] * dims[1]),
            );
            let expect = origin + steps[0] * a as f64 + steps[1] * b as f64 + steps[2] * c as f64;
            let got = v.world_position(i, j, k);
            assert!((got - expect).length() < 1e-9, "{got} vs {expect}");
        }
        info
    }

    #[test]
    fn identity_keeps_everything() {
        let info = check_positions(
            [3, 4, 5],
            [DVec3::X * 0.5, DVec3::Y * 2.0, DVec3::Z],
            DVec3::new(1.0, -2.0, 3.0),
        );
        assert!(info.notes.is_empty());
    }

    #[test]
    fn flips_and_permutations_keep_world_positions() {
        let info = check_positions(
            [3, 4, 5],
            [DVec3::Z * -0.5, DVec3::X * 2.0, DVec3::Y * -1.5],
            DVec3::new(1.0, -2.0, 3.0),
        );
        assert_eq!(info.notes.len(), 1);
        assert!(
            info.notes[0].contains("index axis 0 -> -z"),
            "{:?}",
            info.notes
        );
    }

    #[test]
    fn rotated_grid_keeps_index_axes_and_says_so() {
        let c = std::f64::consts::FRAC_1_SQRT_2;
        let mut info = FileInfo::default();
        let steps = [
            DVec3::new(c, c, 0.0) * 2.0,
            DVec3::new(-c, c, 0.0),
            DVec3::Z,
        ];
        let v = grid_to_volume(
            Path::new("f"),
            [2, 3, 4],
            ramp([2, 3, 4]),
            steps,
            DVec3::ZERO,
            &mut info,
        )
        .unwrap();
        assert_eq!(v.dims(), [2, 3, 4]);
        assert!((v.spacing() - DVec3::new(2.0, 1.0, 1.0)).length() < 1e-12);
        assert!(info.notes[0].contains("not applied"));
    }

    #[test]
    fn skewed_and_degenerate_grids_are_refused() {
        let mut info = FileInfo::default();
        let skew = [DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::Z];
        let err = grid_to_volume(
            Path::new("f.cube"),
            [2, 2, 2],
            ramp([2, 2, 2]),
            skew,
            DVec3::ZERO,
            &mut info,
        )
        .unwrap_err();
        assert!(err.to_string().contains("63.435 degrees"), "{err}");
        let zero = [DVec3::X, DVec3::ZERO, DVec3::Z];
        let err = grid_to_volume(
            Path::new("f"),
            [2, 2, 2],
            ramp([2, 2, 2]),
            zero,
            DVec3::ZERO,
            &mut info,
        )
        .unwrap_err();
        assert!(err.to_string().contains("index axis 1"), "{err}");
        let err = grid_to_volume(
            Path::new("f"),
            [2, 2, 2],
            ramp([2, 2, 2]),
            [DVec3::X, DVec3::Y, DVec3::Z],
            DVec3::new(f64::NAN, 0.0, 0.0),
            &mut info,
        )
        .unwrap_err();
        assert!(err.to_string().contains("origin"), "{err}");
    }
}
