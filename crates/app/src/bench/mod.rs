//! `volray bench`'s timing: whole frames of one volume ([`time_frames`]),
//! their medians, the `--json` rows, and the peer benchmark's workloads
//! (`--peers`, see [`peers`]) with VTK timed beside them ([`vtk`]). The
//! front end takes the flags and prints what this returns.
//!
//! A frame is everything after the volume is in memory: classification
//! (done on the first frame and kept while the transfer function stays the
//! same, as VTK keeps its normals), lighting the voxels for this view,
//! binning the bricks into tiles and casting the rays into the frame
//! buffer; PNG encoding is not timed. One warm-up view (rendered for at
//! least a quarter of a second, untimed, so that the CPU is awake), then
//! `frames` timed ones, each turned a further half degree about the up
//! axis so that no view-dependent work is reused.

pub mod peers;
pub mod vtk;

use crate::AppError;
use std::path::Path;
use std::time::{Duration, Instant};
use volray_core::{
    Camera, FrameRequest, FrameTimes, Image, Method, Render, RenderSettings, Renderer,
};

/// One timed frame.
#[derive(Debug, Clone, Copy)]
pub struct Timed {
    /// Wall time of the whole frame, seconds.
    pub wall: f64,
    /// The fast path's breakdown (`None` on the reference path).
    pub parts: Option<FrameTimes>,
}

/// The least time the warm-up view is rendered for, untimed. A CPU that
/// was idle (while the volume was read, or while VTK ran) comes back to
/// full speed only after some tens of milliseconds of work; VTK's harness
/// gets that while Python imports VTK.
pub const WARM_UP: Duration = Duration::from_millis(250);

/// Renders the warm-up view (`base`'s camera) until [`WARM_UP`] has passed,
/// then `frames` timed frames each turned half a degree further about the
/// up axis, calling `report` after the first warm-up frame (frame 0, which
/// includes the classification) and after each timed one. Returns the
/// warm-up image and the timed frames.
pub fn time_frames(
    renderer: &Renderer,
    base: &RenderSettings,
    frames: u32,
    mut report: impl FnMut(u32, &Timed),
) -> Result<(Image, Vec<Timed>), volray_core::RenderError> {
    let mut image = Image::new(base.width, base.height, [0.0; 4]);
    let render = |frame: u32, image: &mut Image| {
        // Orbit about the up axis through the view reference (VTK's
        // azimuth), for either projection and with or without --view.
        let settings = RenderSettings {
            camera: Camera {
                azimuth: base.camera.azimuth + 0.5 * frame as f64,
                ..base.camera
            },
            ..base.clone()
        };
        let t0 = Instant::now();
        let parts = match settings.method {
            Method::Fast => {
                let reusing = std::mem::replace(image, Image::new(0, 0, [0.0; 4]));
                let request = FrameRequest::new(&settings).reusing(reusing);
                let (rendered, times) = renderer.render(request)?.image_and_times();
                *image = rendered;
                Some(times)
            }
            Method::Reference => {
                *image = renderer.render(FrameRequest::new(&settings))?.image();
                None
            }
        };
        Ok::<_, volray_core::RenderError>(Timed {
            wall: t0.elapsed().as_secs_f64(),
            parts,
        })
    };
    let start = Instant::now();
    report(0, &render(0, &mut image)?);
    let warm = image.clone();
    while start.elapsed() < WARM_UP {
        render(0, &mut image)?;
    }
    let mut timed = Vec::new();
    for frame in 1..=frames {
        let t = render(frame, &mut image)?;
        report(frame, &t);
        timed.push(t);
    }
    Ok((warm, timed))
}

/// The median of `values` (the mean of the middle two for an even count).
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// Milliseconds of one part of a frame, for the tables.
pub fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// One row of `--json`.
pub struct JsonRow {
    pub dataset: String,
    pub window: usize,
    pub threads: usize,
    pub median_s: f64,
    /// VTK's median on the same workload, when it ran.
    pub vtk_median_s: Option<f64>,
}

/// Writes `rows` to `path` as a JSON list, atomically.
pub fn write_json(path: &Path, rows: &[JsonRow]) -> Result<(), AppError> {
    let list: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            let mut v = serde_json::json!({
                "dataset": r.dataset,
                "window": r.window,
                "threads": r.threads,
                "median_s": r.median_s,
            });
            if let Some(vtk) = r.vtk_median_s {
                v["vtk_median_s"] = vtk.into();
            }
            v
        })
        .collect();
    let text = serde_json::to_string_pretty(&list).expect("plain values serialise");
    volray_io::write_atomically(path, |w| writeln!(w, "{text}"))?;
    Ok(())
}

/// A refusal of the bench's input or flags (exit 1).
fn input(message: String) -> AppError {
    AppError::Refused {
        message,
        bad_input: true,
    }
}

/// A failure of the machine: a file or a process (exit 2).
fn io(message: String) -> AppError {
    AppError::Refused {
        message,
        bad_input: false,
    }
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn the_median_is_the_middle_value_or_the_mean_of_the_middle_two() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(Vec::new()).is_nan());
    }
}
