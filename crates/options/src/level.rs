//! `--level auto`: which level of a multiscale
//! image a view needs, so that a picture of a huge pyramid reads what it
//! can show and no more (neuroglancer's and BigDataViewer's rule, for one
//! frame).
//!
//! The rule: the coarsest level whose voxels are no larger than a pixel's
//! footprint (within [`SLACK`]) ([`View::pixel_footprint`]: an orthographic pixel's size;
//! in perspective, a pixel's size at the point of the volume nearest the
//! eye), a voxel measured by its largest spacing. A finer level would add
//! detail no pixel shows; a coarser one would blur what the picture can
//! resolve. The view is framed on the finest level's box (the levels'
//! boxes differ by half a coarse voxel), so every level is chosen for the
//! same picture. With no level that fine, the finest.
//!
//! ```
//! use volray_core::glam::DVec3;
//! use volray_core::RenderSettings;
//! use volray_options::level::auto_level;
//!
//! // A 2048³ pyramid of 1 µm voxels, halved six times, at 1024² pixels.
//! let spacings: Vec<DVec3> = (0..7).map(|k| DVec3::splat((1u32 << k) as f64)).collect();
//! let bounds = (DVec3::ZERO, DVec3::splat(2047.0));
//! let settings = RenderSettings { width: 1024, height: 1024, ..RenderSettings::default() };
//! // The default framing fits the face seen, 2047 µm over 1024 pixels:
//! // 2 µm a pixel (less 0.05 %), so level 1 (2 µm voxels).
//! assert_eq!(auto_level(&spacings, bounds, &settings).unwrap(), 1);
//! ```

use volray_core::RenderSettings;
use volray_core::camera::{CameraError, View};
use volray_core::glam::DVec3;

/// How much coarser than a pixel's footprint a level's voxels may be.
pub const SLACK: f64 = 1.0 / 32.0;

/// A level asked for: chosen for the view, or by number (0 the finest).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LevelChoice {
    Auto,
    Index(usize),
}

impl std::str::FromStr for LevelChoice {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        if text == "auto" {
            return Ok(LevelChoice::Auto);
        }
        text.parse::<usize>().map(LevelChoice::Index).map_err(|_| {
            format!("\"{text}\" is not a level: give auto or a level number, 0 the finest")
        })
    }
}

/// The level a frame of `settings` needs, among levels whose voxels are
/// `spacings` apart (finest first), the view framed on `bounds` (the
/// finest level's box). An error only where the camera cannot frame the
/// box, as rendering would say.
pub fn auto_level(
    spacings: &[DVec3],
    bounds: (DVec3, DVec3),
    settings: &RenderSettings,
) -> Result<usize, CameraError> {
    let view = View::frame(&settings.camera, bounds, settings.width, settings.height)?;
    let footprint = view.pixel_footprint(bounds);
    // A little slack: the framed box spans n − 1 voxel gaps of a grid of
    // n points, so a 2048³ box at 1024 pixels measures 2047/1024 units a
    // pixel, and the level of 2-unit voxels (which the picture cannot tell
    // from level 0) would miss by 0.05 %. 1/32 allows that gap for any
    // grid of 33 points or more, and never takes a level half as fine.
    let fits = |s: &DVec3| s.max_element() <= footprint * (1.0 + SLACK);
    Ok(spacings.iter().rposition(fits).unwrap_or(0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::camera::{Camera, Projection};

    fn pyramid(levels: u32) -> Vec<DVec3> {
        (0..levels)
            .map(|k| DVec3::new(1.0, 1.0, 2.0) * f64::from(1u32 << k))
            .collect()
    }

    #[test]
    fn an_orthographic_view_takes_the_coarsest_level_no_coarser_than_a_pixel() {
        // A 512 x 512 x 256 box (spacing 1, 1, 2) seen from +x, its
        // 511 x 510 face fitted: 511/width world units a pixel.
        let bounds = (DVec3::ZERO, DVec3::new(511.0, 511.0, 510.0));
        let at = |width: usize, zoom: f64| {
            let settings = RenderSettings {
                width,
                height: width,
                camera: Camera {
                    zoom,
                    ..Camera::default()
                },
                ..RenderSettings::default()
            };
            auto_level(&pyramid(6), bounds, &settings).unwrap()
        };
        let view = View::frame(&Camera::default(), bounds, 100, 100).unwrap();
        assert!((view.pixel_footprint(bounds) - 5.11).abs() < 1e-9);
        // Level k's largest spacing is 2^(k+1): 5.11 units a pixel take
        // level 1 (4), 2.555 level 0 (2).
        assert_eq!(at(100, 1.0), 1);
        assert_eq!(at(200, 1.0), 0);
        // A 2x zoom is twice the pixels.
        assert_eq!(at(100, 2.0), 0);
        assert_eq!(at(50, 1.0), 2);
        assert_eq!(at(25, 2.0), 2);
        // A huge image needs the finest level, and no level is finer.
        assert_eq!(at(8000, 1.0), 0);
        // A tiny one the coarsest there is.
        assert_eq!(at(2, 1.0), 5);
    }

    #[test]
    fn a_level_a_grid_gap_coarser_than_a_pixel_still_qualifies() {
        // 2048 points a side: 2047 units over 1024 pixels, 1.999 a pixel.
        let bounds = (DVec3::ZERO, DVec3::splat(2047.0));
        let spacings: Vec<DVec3> = (0..6).map(|k| DVec3::splat(f64::from(1u32 << k))).collect();
        let at = |pixels: usize| {
            let settings = RenderSettings {
                width: pixels,
                height: pixels,
                ..RenderSettings::default()
            };
            auto_level(&spacings, bounds, &settings).unwrap()
        };
        assert_eq!(at(1024), 1);
        assert_eq!(at(512), 2);
        // 1.93 units a pixel: 2-unit voxels are 3.5 % too coarse.
        assert_eq!(at(1060), 0);
    }

    #[test]
    fn a_perspective_view_is_measured_at_the_nearest_point_of_the_volume() {
        let bounds = (DVec3::ZERO, DVec3::splat(1023.0));
        let spacings: Vec<DVec3> = (0..8).map(|k| DVec3::splat(f64::from(1u32 << k))).collect();
        let settings = |eye: DVec3| RenderSettings {
            width: 256,
            height: 256,
            camera: Camera {
                projection: Projection::Perspective { fov_degrees: 30.0 },
                view_point: Some(eye),
                look_at: Some(DVec3::splat(511.5)),
                ..Camera::default()
            },
            ..RenderSettings::default()
        };
        // The eye 1000 units in front of the x = 1023 face: a pixel there is
        // 1000·2·tan(15°)/256 ≈ 2.09 units, so level 1 (2 units).
        let far = settings(DVec3::new(2023.0, 511.5, 511.5));
        assert_eq!(auto_level(&spacings, bounds, &far).unwrap(), 1);
        // 100 units away: 0.21 units, finer than any level: level 0.
        let near = settings(DVec3::new(1123.0, 511.5, 511.5));
        assert_eq!(auto_level(&spacings, bounds, &near).unwrap(), 0);
        // Inside the volume: the finest.
        let inside = settings(DVec3::new(900.0, 511.5, 511.5));
        assert_eq!(auto_level(&spacings, bounds, &inside).unwrap(), 0);
    }

    #[test]
    fn levels_are_named_auto_or_by_number() {
        assert_eq!("auto".parse::<LevelChoice>(), Ok(LevelChoice::Auto));
        assert_eq!("3".parse::<LevelChoice>(), Ok(LevelChoice::Index(3)));
        let e = "1.5".parse::<LevelChoice>().unwrap_err();
        assert!(e.contains("\"1.5\" is not a level"), "{e}");
    }
}
