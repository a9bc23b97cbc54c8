//! Transfer-function presets for common data (`--preset`).
//!
//! CT presets work in Hounsfield units (air −1000, water 0, soft tissue
//! about 20 to 80, cancellous bone from about 200, cortical bone above
//! 1000), so they fix the value domain; the others are relative to the
//! volume's own value range (or `--range`). Opacities are per voxel of
//! length, as everywhere in volray. The shapes follow the usual
//! ParaView/3D Slicer presets ("CT-Bone", "CT-Muscle", "MR-Default")
//! without copying their exact numbers.

use crate::transfer::colormap::colormap;
use crate::transfer::function::{PiecewiseLinear, TransferFunction};

/// The names `--preset` accepts.
pub const NAMES: [&str; 4] = ["ct-bone", "ct-soft-tissue", "mr", "electron-density"];

/// The CT domain, in Hounsfield units: air to dense cortical bone.
const CT_DOMAIN: (f64, f64) = (-1000.0, 2000.0);

/// `t` of a Hounsfield value in [`CT_DOMAIN`].
fn hu(v: f64) -> f32 {
    ((v - CT_DOMAIN.0) / (CT_DOMAIN.1 - CT_DOMAIN.0)) as f32
}

fn table<const N: usize>(points: Vec<(f32, [f32; N])>) -> PiecewiseLinear<N> {
    PiecewiseLinear::new("preset", points).expect("presets are sorted and in [0, 1]")
}

/// The preset called `name`, or `None`.
pub fn preset(name: &str) -> Option<TransferFunction> {
    let tf = match name {
        // Bone only: transparent below 150 HU, rising through cancellous to
        // cortical bone; ivory to white.
        "ct-bone" => TransferFunction {
            domain: Some(CT_DOMAIN),
            opacity: Some(table(vec![
                (hu(150.0), [0.0]),
                (hu(400.0), [0.3]),
                (hu(1000.0), [0.8]),
                (hu(2000.0), [0.95]),
            ])),
            color: Some(table(vec![
                (hu(150.0), [0.85, 0.72, 0.55]),
                (hu(700.0), [0.95, 0.9, 0.8]),
                (hu(2000.0), [1.0, 1.0, 1.0]),
            ])),
        },
        // Skin and muscle faint and red, fat hidden, bone opaque and white.
        "ct-soft-tissue" => TransferFunction {
            domain: Some(CT_DOMAIN),
            opacity: Some(table(vec![
                (hu(-500.0), [0.0]),
                (hu(-100.0), [0.0]),
                (hu(40.0), [0.08]),
                (hu(150.0), [0.12]),
                (hu(400.0), [0.6]),
                (hu(2000.0), [0.9]),
            ])),
            color: Some(table(vec![
                (hu(-100.0), [0.55, 0.25, 0.15]),
                (hu(40.0), [0.8, 0.35, 0.25]),
                (hu(150.0), [0.9, 0.6, 0.45]),
                (hu(400.0), [0.95, 0.9, 0.8]),
                (hu(2000.0), [1.0, 1.0, 1.0]),
            ])),
        },
        // Relative: the darkest tenth (background, air) transparent, then a
        // ramp; grey.
        "mr" => TransferFunction {
            domain: None,
            opacity: Some(table(vec![(0.1, [0.0]), (0.5, [0.3]), (1.0, [0.7])])),
            color: colormap("grey"),
        },
        // Relative: a density that falls off over decades, so even the low
        // tail is faintly visible while the peaks stay see-through; magma.
        "electron-density" => TransferFunction {
            domain: None,
            opacity: Some(table(vec![
                (0.0, [0.0]),
                (0.02, [0.02]),
                (0.2, [0.15]),
                (1.0, [0.6]),
            ])),
            color: colormap("magma"),
        },
        _ => return None,
    };
    Some(tf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::classifier::Classifier;

    #[test]
    fn every_preset_exists() {
        for name in NAMES {
            let tf = preset(name).unwrap();
            assert!(tf.opacity.is_some() && tf.color.is_some(), "{name}");
        }
        assert!(preset("ct-lung").is_none());
    }

    #[test]
    fn ct_bone_hides_air_and_tissue_and_shows_bone() {
        let tf = preset("ct-bone").unwrap();
        // The volume's own range must not matter: CT presets fix the domain.
        let c = Classifier::from_transfer_function(&tf, (-3000.0, 5000.0), (0.0, 0.5), 1.0);
        for air_or_tissue in [-1000.0, -100.0, 0.0, 60.0, 150.0] {
            assert_eq!(c.unit_opacity(air_or_tissue), 0.0, "{air_or_tissue} HU");
        }
        let cancellous = c.unit_opacity(400.0);
        let (colour, cortical) = (c.material(1000.0), c.unit_opacity(1000.0));
        assert!((cancellous - 0.3).abs() < 1e-5 && (cortical - 0.8).abs() < 1e-5);
        assert!(colour.iter().all(|&v| v > 0.8), "{colour:?}");
    }
}
