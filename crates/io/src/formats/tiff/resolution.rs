//! The spacing of a TIFF stack with neither ImageJ nor OME metadata, from
//! its resolution tags (TIFF 6.0, section 8: `XResolution`, `YResolution`
//! in pixels per `ResolutionUnit`: 1 none, 2 inch, the default, 3
//! centimetre), as CT and microscopy exporters write the pixel size and
//! as Fiji reads it.
//!
//! The tags were made to say how large a page prints, so not every value
//! is a pixel size. The rule:
//! - **centimetre**: always a physical size: x = 10 / `XResolution` mm,
//!   y = 10 / `YResolution` mm;
//! - **inch**, written in the file: x = 25.4 / `XResolution` mm, unless
//!   both are one of the print and screen defaults that writers put there
//!   whatever the image (72, 96, 150, 300, 600 or 1200 pixels per inch),
//!   which mean nothing about the voxels and are ignored with a note;
//! - **none**, or no `ResolutionUnit` tag (whose default, inch, nobody
//!   chose): only an aspect ratio, ignored with a note, spacing 1.
//!
//! A TIFF stores no slice spacing: where x and y come from the tags, z is
//! taken equal to x (cubic voxels, as a stack exported slice by slice at
//! its pixel size usually is) and the note says so and names `--spacing`
//! for the real one. Fiji keeps z at 1 in the same unit instead, which
//! stretches a CT exported at 0.5 mm twofold.
//!
//! ImageJ and OME metadata, where present, are read instead
//! (`imagej.rs`, `ome.rs`): both say the unit themselves.

use volray_core::glam::DVec3;

use crate::FileInfo;

/// The resolutions (pixels per inch) that writers store by default: print
/// and screen sizes, not voxel sizes.
const DEFAULT_DPI: [f64; 6] = [72.0, 96.0, 150.0, 300.0, 600.0, 1200.0];

/// The stack's spacing in mm from `XResolution`, `YResolution` and
/// `ResolutionUnit` (each `None` where the tag is absent), or `None` with
/// a note in `info` where they give none (see the module docs). Sets
/// `info.length_unit` to mm where they give one.
pub(super) fn spacing_from_tags(
    resolution: [Option<f64>; 2],
    unit: Option<u16>,
    info: &mut FileInfo,
) -> Option<DVec3> {
    let [Some(x), Some(y)] = resolution else {
        if resolution.iter().any(Option::is_some) {
            info.notes
                .push("only one of XResolution and YResolution: spacing 1, 1, 1 (pixels)".into());
        }
        return None;
    };
    let mm_per_unit = match unit {
        Some(3) => 10.0,
        Some(2) if DEFAULT_DPI.contains(&x) && DEFAULT_DPI.contains(&y) => {
            info.notes.push(format!(
                "XResolution {x}, YResolution {y} pixels per inch are a print default, not a voxel size: spacing 1, 1, 1 (pixels); give --spacing for the real one"
            ));
            return None;
        }
        Some(2) => 25.4,
        Some(1) | None => {
            info.notes.push(
                "no ImageJ or OME metadata, and the resolution tags name no unit: spacing 1, 1, 1 (pixels)"
                    .into(),
            );
            return None;
        }
        Some(other) => {
            info.notes.push(format!(
                "ResolutionUnit {other} is not one TIFF defines (1 none, 2 inch, 3 centimetre): spacing 1, 1, 1 (pixels)"
            ));
            return None;
        }
    };
    let valid = |r: f64| r.is_finite() && r > 0.0;
    if !valid(x) || !valid(y) {
        info.notes.push(format!(
            "XResolution {x}, YResolution {y} are not positive numbers of pixels: spacing 1, 1, 1 (pixels)"
        ));
        return None;
    }
    let unit_name = if unit == Some(3) {
        "centimetre"
    } else {
        "inch"
    };
    let (sx, sy) = (mm_per_unit / x, mm_per_unit / y);
    info.notes.push(format!(
        "spacing {sx}, {sy}, {sx} mm from the resolution tags ({x}, {y} pixels per {unit_name}); a TIFF stores no slice spacing: z taken equal to x, give --spacing for the real one"
    ));
    info.length_unit = Some("mm".into());
    Some(DVec3::new(sx, sy, sx))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spacing(res: [Option<f64>; 2], unit: Option<u16>) -> (Option<DVec3>, FileInfo) {
        let mut info = FileInfo::new("");
        (spacing_from_tags(res, unit, &mut info), info)
    }

    #[test]
    fn pixels_per_centimetre_are_tenths_of_a_millimetre() {
        let (s, info) = spacing([Some(20.0), Some(40.0)], Some(3));
        assert_eq!(s, Some(DVec3::new(0.5, 0.25, 0.5)));
        assert_eq!(info.length_unit.as_deref(), Some("mm"));
        assert!(
            info.notes[0].contains("z taken equal to x"),
            "{:?}",
            info.notes
        );
    }

    #[test]
    fn pixels_per_inch_are_read_unless_a_print_default() {
        let (s, _) = spacing([Some(50.8), Some(50.8)], Some(2));
        assert_eq!(s, Some(DVec3::splat(0.5)));
        let (s, info) = spacing([Some(72.0), Some(72.0)], Some(2));
        assert_eq!(s, None);
        assert_eq!(info.length_unit, None);
        assert!(info.notes[0].contains("print default"), "{:?}", info.notes);
    }

    #[test]
    fn no_unit_or_a_bad_value_keeps_pixels() {
        for (res, unit) in [
            ([Some(20.0), Some(20.0)], None),
            ([Some(20.0), Some(20.0)], Some(1)),
            ([Some(20.0), Some(20.0)], Some(7)),
            ([Some(0.0), Some(20.0)], Some(3)),
            ([Some(f64::NAN), Some(20.0)], Some(3)),
            ([Some(20.0), None], Some(3)),
        ] {
            let (s, info) = spacing(res, unit);
            assert_eq!(s, None, "{res:?} {unit:?}");
            assert_eq!(info.length_unit, None);
            assert_eq!(info.notes.len(), 1, "{:?}", info.notes);
        }
        let (s, info) = spacing([None, None], Some(3));
        assert_eq!((s, info.notes.len()), (None, 0));
    }
}
