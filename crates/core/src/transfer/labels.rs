//! Label volumes (segmentations: integer labels, one per region): a
//! categorical colour and an opacity per label, classified by label.
//!
//! The values of a label volume name regions, so they must never be
//! blended: the transfer function built here is constant over each label
//! and jumps half way between two labels present, and the volume is
//! rendered pre-classified (each voxel classified by its own label, then
//! colours and opacities interpolated between voxels), so a sample between
//! a voxel of label 1 and one of label 5 is a mix of their colours, never
//! the colour of 3. Label 0 is the background: transparent. Shading uses
//! the gradient of each voxel's smoothed label indicator
//! ([`Volume::as_labels`], [`crate::kernels::gradient`]), so that surfaces
//! are smooth rather than staircased.
//!
//! This is what VTK does with nearest-neighbour interpolation and a label
//! colour table, and 3D Slicer with its segment colours, with the
//! difference that the boundary between two labels is interpolated (half
//! way between their voxels) rather than a staircase of voxel faces.
//!
//! ```
//! use volray_core::transfer::labels::{LabelStyle, PALETTE, transfer_function};
//!
//! let tf = transfer_function(&[0, 2, 7], &LabelStyle::default()).unwrap();
//! let (lo, hi) = tf.domain.unwrap();
//! let t = |v: f64| ((v - lo) / (hi - lo)) as f32;
//! let (opacity, color) = (tf.opacity.unwrap(), tf.color.unwrap());
//! assert_eq!(opacity.eval(t(0.0)), [0.0]); // the background
//! assert_eq!(opacity.eval(t(2.0)), [1.0]);
//! assert_eq!(color.eval(t(7.0)), PALETTE[7]);
//! // Half way between 2 and 7: 4.4 is still 2, 4.6 is 7.
//! assert_eq!(color.eval(t(4.4)), PALETTE[2]);
//! assert_eq!(color.eval(t(4.6)), PALETTE[7]);
//! ```

use std::collections::BTreeSet;

use crate::transfer::function::{PiecewiseLinear, TransferFunction};
use crate::volume::{Sample, Volume};
use thiserror::Error;

/// The most distinct labels a label volume may hold: the colour lookup
/// costs a few operations per label and voxel.
pub const MAX_LABELS: usize = 4096;

/// The opacity (per unit voxel distance) of a label no option names:
/// opaque surfaces, as 3D Slicer shows segments.
pub const DEFAULT_OPACITY: f32 = 1.0;

/// Label `L`'s colour is `PALETTE[L mod 20]`, so a label keeps its colour
/// from file to file: Tableau's 20 categorical colours (matplotlib's
/// `tab20`), the darker of each pair first, then the lighter ones.
pub const PALETTE: [[f32; 3]; 20] = [
    [0.122, 0.467, 0.706],
    [1.000, 0.498, 0.055],
    [0.173, 0.627, 0.173],
    [0.839, 0.153, 0.157],
    [0.580, 0.404, 0.741],
    [0.549, 0.337, 0.294],
    [0.890, 0.467, 0.761],
    [0.498, 0.498, 0.498],
    [0.737, 0.741, 0.133],
    [0.090, 0.745, 0.812],
    [0.682, 0.780, 0.910],
    [1.000, 0.733, 0.471],
    [0.596, 0.875, 0.541],
    [1.000, 0.596, 0.588],
    [0.773, 0.690, 0.835],
    [0.769, 0.612, 0.580],
    [0.969, 0.714, 0.824],
    [0.780, 0.780, 0.780],
    [0.859, 0.859, 0.553],
    [0.620, 0.855, 0.898],
];

/// Why a volume cannot be read as labels.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LabelError {
    #[error("value {0} is not an integer: labels must be integers")]
    NotInteger(f32),
    #[error("more than {MAX_LABELS} distinct labels")]
    TooMany,
    #[error("label {0} is not in the volume (it holds {1})")]
    Absent(i64, String),
}

/// How the labels look: opacities other than [`DEFAULT_OPACITY`], which
/// labels are shown, and colours other than [`PALETTE`]'s.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LabelStyle {
    /// `(label, opacity)` pairs (the CLI's `--label-opacity L:A,...`).
    pub opacity: Vec<(i64, f32)>,
    /// Only these labels are shown (`--show-labels 1,3,5`); `None`: all
    /// but 0.
    pub shown: Option<Vec<i64>>,
    /// `(label, colour)` pairs the file gives (a DICOM Segmentation's
    /// segment colours); other labels take [`colour_of`]'s.
    pub colours: Vec<(i64, [f32; 3])>,
}

impl LabelStyle {
    /// The opacity of `label`.
    pub fn opacity_of(&self, label: i64) -> f32 {
        let hidden = match &self.shown {
            Some(shown) => !shown.contains(&label),
            None => label == 0,
        };
        if hidden {
            return 0.0;
        }
        (self.opacity.iter().rev())
            .find(|(l, _)| *l == label)
            .map_or(DEFAULT_OPACITY, |(_, a)| *a)
    }

    /// The colour of `label`: the one given, else [`colour_of`]'s.
    pub fn colour(&self, label: i64) -> [f32; 3] {
        (self.colours.iter())
            .find(|(l, _)| *l == label)
            .map_or_else(|| colour_of(label), |(_, c)| *c)
    }

    /// Refuses a style that names a label `labels` does not hold.
    pub fn check(&self, labels: &[i64]) -> Result<(), LabelError> {
        let named = (self.opacity.iter().map(|(l, _)| l)).chain(self.shown.iter().flatten());
        for &label in named {
            if labels.binary_search(&label).is_err() {
                return Err(LabelError::Absent(label, list(labels)));
            }
        }
        Ok(())
    }
}

/// `labels` as a short list for messages.
fn list(labels: &[i64]) -> String {
    let shown: Vec<String> = labels.iter().take(12).map(i64::to_string).collect();
    let more = if labels.len() > 12 { ", ..." } else { "" };
    format!("{}{more}", shown.join(", "))
}

/// The colour of `label`.
pub fn colour_of(label: i64) -> [f32; 3] {
    PALETTE[label.rem_euclid(PALETTE.len() as i64) as usize]
}

/// The value whose colour voxel (`i`, `j`, `k`) of a label volume (values
/// `data`, x fastest, on a grid of `dims`) takes: its own when `shown` (its
/// label is not transparent), else that of the nearest shown label among
/// its 26 neighbours (faces, then edges, then corners, each in a fixed
/// order), else its own. A hidden label is transparent, but the renderer
/// interpolates colours and opacities apart (pre-classification): without
/// this, a label's surface would take half its colour from the hidden
/// label beside it (label 0's, say) where it meets it. Every path calls
/// this for every voxel of a label volume.
#[inline]
pub fn colour_value<T: Sample>(
    data: &[T],
    dims: [usize; 3],
    [i, j, k]: [usize; 3],
    shown: impl Fn(f32) -> bool,
) -> f32 {
    let [nx, ny, nz] = dims;
    let own = data[i + nx * (j + ny * k)].to_f32();
    if shown(own) {
        return own;
    }
    let step = |c: usize, d: i32, n: usize| {
        let c = c as i64 + i64::from(d);
        (0..n as i64).contains(&c).then_some(c as usize)
    };
    for nonzero in 1..=3 {
        for dk in -1..=1i32 {
            for dj in -1..=1i32 {
                for di in -1..=1i32 {
                    if (di != 0) as i32 + (dj != 0) as i32 + (dk != 0) as i32 != nonzero {
                        continue;
                    }
                    let (Some(x), Some(y), Some(z)) =
                        (step(i, di, nx), step(j, dj, ny), step(k, dk, nz))
                    else {
                        continue;
                    };
                    let v = data[x + nx * (y + ny * z)].to_f32();
                    if shown(v) {
                        return v;
                    }
                }
            }
        }
    }
    own
}

/// The distinct labels of `volume`, sorted, or why its values are not
/// labels: a value that is not an integer, or more than `max` distinct
/// values (`Ok(None)`).
pub fn labels_of(volume: &Volume, max: usize) -> Result<Option<Vec<i64>>, LabelError> {
    fn collect<T: Sample>(data: &[T], max: usize) -> Result<Option<Vec<i64>>, LabelError> {
        let mut seen = BTreeSet::new();
        let mut last = None;
        for v in data.iter().map(|v| v.to_f32()) {
            // Runs of one label are the common case: one lookup per run.
            if last == Some(v.to_bits()) {
                continue;
            }
            last = Some(v.to_bits());
            if !(v.is_finite() && v.fract() == 0.0) {
                return Err(LabelError::NotInteger(v));
            }
            if seen.insert(v as i64) && seen.len() > max {
                return Ok(None);
            }
        }
        Ok(Some(seen.into_iter().collect()))
    }
    crate::with_samples!(volume.samples(), |data| collect(data, max))
}

/// The transfer function of a label volume holding `labels` (sorted,
/// distinct, at least one) under `style`: over the window from half a
/// label below the first to half above the last, each label's colour and
/// opacity constant up to half way to the next, where both jump.
pub fn transfer_function(
    labels: &[i64],
    style: &LabelStyle,
) -> Result<TransferFunction, LabelError> {
    if labels.len() > MAX_LABELS {
        return Err(LabelError::TooMany);
    }
    style.check(labels)?;
    let (first, last) = (labels[0] as f64, labels[labels.len() - 1] as f64);
    let (lo, hi) = (first - 0.5, last + 0.5);
    let t = |v: f64| ((v - lo) / (hi - lo)) as f32;
    let mut opacity = Vec::with_capacity(2 * labels.len());
    let mut colour = Vec::with_capacity(2 * labels.len());
    for (n, &label) in labels.iter().enumerate() {
        let from = if n == 0 {
            0.0
        } else {
            t((labels[n - 1] as f64 + label as f64) / 2.0)
        };
        let to = match labels.get(n + 1) {
            Some(&next) => t((label as f64 + next as f64) / 2.0),
            None => 1.0,
        };
        let a = style.opacity_of(label);
        opacity.extend([(from, [a]), (to, [a])]);
        let c = style.colour(label);
        colour.extend([(from, c), (to, c)]);
    }
    Ok(TransferFunction {
        domain: Some((lo, hi)),
        opacity: Some(PiecewiseLinear::new("opacity", opacity).expect("sorted points in [0, 1]")),
        color: Some(PiecewiseLinear::new("color", colour).expect("sorted points in [0, 1]")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn at(tf: &TransferFunction, v: f64) -> (f32, [f32; 3]) {
        let (lo, hi) = tf.domain.unwrap();
        let t = ((v - lo) / (hi - lo)) as f32;
        (
            tf.opacity.as_ref().unwrap().eval(t)[0],
            tf.color.as_ref().unwrap().eval(t),
        )
    }

    #[test]
    fn each_label_has_its_colour_up_to_half_way_to_the_next() {
        let tf = transfer_function(&[0, 1, 3, 10], &LabelStyle::default()).unwrap();
        assert_eq!(at(&tf, 0.0), (0.0, PALETTE[0]));
        assert_eq!(at(&tf, 1.0), (1.0, PALETTE[1]));
        assert_eq!(at(&tf, 1.9), (1.0, PALETTE[1]));
        assert_eq!(at(&tf, 2.1), (1.0, PALETTE[3]));
        assert_eq!(at(&tf, 6.4), (1.0, PALETTE[3]));
        assert_eq!(at(&tf, 6.6), (1.0, PALETTE[10]));
        assert_eq!(at(&tf, 10.0), (1.0, PALETTE[10]));
        // Labels beyond the palette wrap around; negative labels too.
        assert_eq!(colour_of(23), PALETTE[3]);
        assert_eq!(colour_of(-1), PALETTE[19]);
    }

    #[test]
    fn colours_a_file_gives_replace_the_palettes_for_those_labels_only() {
        let style = LabelStyle {
            colours: vec![(2, [0.0, 0.0, 1.0])],
            ..LabelStyle::default()
        };
        let tf = transfer_function(&[0, 1, 2], &style).unwrap();
        assert_eq!(at(&tf, 2.0).1, [0.0, 0.0, 1.0]);
        assert_eq!(at(&tf, 1.0).1, PALETTE[1]);
    }

    #[test]
    fn shown_labels_and_opacities_are_as_the_style_says() {
        let style = LabelStyle {
            opacity: vec![(3, 0.25)],
            shown: Some(vec![0, 3]),
            ..LabelStyle::default()
        };
        let tf = transfer_function(&[0, 1, 3], &style).unwrap();
        // Shown explicitly, 0 is opaque; 1 is hidden; 3 has its own.
        assert_eq!(at(&tf, 0.0).0, 1.0);
        assert_eq!(at(&tf, 1.0).0, 0.0);
        assert_eq!(at(&tf, 3.0).0, 0.25);
        let absent = LabelStyle {
            opacity: vec![(4, 0.5)],
            shown: None,
            ..LabelStyle::default()
        };
        assert_eq!(
            transfer_function(&[0, 1, 3], &absent),
            Err(LabelError::Absent(4, "0, 1, 3".into()))
        );
    }

    #[test]
    fn a_hidden_voxel_takes_the_colour_of_the_nearest_shown_label() {
        // 3³: label 2 at the centre's +x face neighbour, label 7 at a
        // corner, 0 elsewhere; 0 is hidden.
        let mut v = vec![0.0f32; 27];
        v[2 + 3 * (1 + 3)] = 2.0;
        v[0] = 7.0;
        let shown = |f: f32| f != 0.0;
        // The centre: a face neighbour (2) before a corner (7).
        assert_eq!(colour_value(&v, [3; 3], [1, 1, 1], shown), 2.0);
        // Shown voxels keep their own.
        assert_eq!(colour_value(&v, [3; 3], [0, 0, 0], shown), 7.0);
        // (0, 1, 0): 7 is a face neighbour, 2 an edge one.
        assert_eq!(colour_value(&v, [3; 3], [0, 1, 0], shown), 7.0);
        // Nothing shown nearby: its own.
        assert_eq!(colour_value(&v, [3; 3], [0, 2, 2], |_| false), 0.0);
    }

    #[test]
    fn a_single_label_spans_the_window() {
        let tf = transfer_function(&[5], &LabelStyle::default()).unwrap();
        assert_eq!(tf.domain, Some((4.5, 5.5)));
        assert_eq!(at(&tf, 5.0), (1.0, PALETTE[5]));
    }

    #[test]
    fn labels_are_the_distinct_integers_and_nothing_else() {
        let v = Volume::new([2, 2, 2], vec![0.0, 3.0, 3.0, 1.0, 0.0, 3.0, -2.0, 1.0]).unwrap();
        assert_eq!(labels_of(&v, 10), Ok(Some(vec![-2, 0, 1, 3])));
        assert_eq!(labels_of(&v, 3), Ok(None));
        let f =
            Volume::from_fn([2, 2, 2], DVec3::ONE, DVec3::ZERO, |p| (p.x * 0.5) as f32).unwrap();
        assert_eq!(labels_of(&f, 10), Err(LabelError::NotInteger(0.5)));
        let u8s = Volume::from_samples([2, 2, 2], vec![7u8; 8]).unwrap();
        assert_eq!(labels_of(&u8s, 10), Ok(Some(vec![7])));
    }
}
