//! What the page is told first about the volume and the starting view:
//! the [`Hello`] message, with the value histogram the window and the
//! opacity editor are drawn over, and the colours of every colour choice.

use crate::protocol::{Hello, VolumeHello};
use crate::state::{Lighting, START_COLOURS, ViewState, WHITE};
use volray_core::transfer::{auto, colormap};
use volray_core::{Histogram, RenderSettings, Volume};

/// Bins of the histogram drawn under the transfer-function editor.
pub const HISTOGRAM_BINS: usize = 128;

/// Colours per colour choice, evenly spaced over `t` in [0, 1].
pub const COLOUR_SAMPLES: usize = 64;

/// The volume and the starting view as the page's first message.
pub struct Start<'a> {
    /// The input's name, as given.
    pub name: &'a str,
    /// The volume as rendered (log10 of the data's when `log`).
    pub volume: &'a Volume,
    pub log: bool,
    /// The starting state, and the settings it renders with.
    pub state: &'a ViewState,
    pub settings: &'a RenderSettings,
    /// A scene's other volumes, in order: each one's name, volume and
    /// starting settings (whose transfer function its panel starts from).
    pub others: Vec<(&'a str, &'a Volume, &'a RenderSettings)>,
    /// The time points served, `[first, end)` (`Hello::time`).
    pub time: Option<[usize; 2]>,
}

/// What a panel draws over: the value histogram and its range, and the
/// transfer function's starting window (its domain, else the range).
/// Where a few outliers stretch the values' range (volray-core's
/// [`auto::robust_histogram`] refines it, as `--tf auto` does), the
/// histogram and its range are those of the window it refines to, the
/// outliers counted in its end bins: over the whole range the data would
/// be one bar. A label volume's is over its labels.
fn histogram_of(volume: &Volume, settings: &RenderSettings) -> (Vec<u64>, [f32; 2], [f64; 2]) {
    let robust = (!volume.is_labels()).then(|| auto::robust_histogram_of(volume));
    let histogram = match robust.flatten().and_then(|r| r.window) {
        Some(window) => Some(Histogram::of_box(
            volume,
            ([0; 3], volume.dims()),
            window,
            HISTOGRAM_BINS,
        )),
        None => Histogram::of(volume, HISTOGRAM_BINS),
    };
    let range = histogram.as_ref().map_or([0.0, 0.0], |h| [h.min, h.max]);
    let start_window = (settings.transfer_function.domain)
        .map_or([f64::from(range[0]), f64::from(range[1])], |(lo, hi)| {
            [lo, hi]
        });
    (
        histogram.map_or_else(Vec::new, |h| h.counts),
        range,
        start_window,
    )
}

/// `eval` at [`COLOUR_SAMPLES`] evenly spaced `t`.
fn sample(eval: &dyn Fn(f32) -> [f32; 3]) -> Vec<[f32; 3]> {
    (0..COLOUR_SAMPLES)
        .map(|i| eval(i as f32 / (COLOUR_SAMPLES - 1) as f32))
        .collect()
}

/// The starting opacity points of `settings`' transfer function.
fn start_opacity(settings: &RenderSettings) -> Option<Vec<[f32; 2]>> {
    (settings.transfer_function.opacity.as_ref())
        .map(|f| f.points().iter().map(|(t, [a])| [*t, *a]).collect())
}

/// A scene's volume after the first, as its panel is drawn.
fn volume_hello(name: &str, volume: &Volume, settings: &RenderSettings) -> VolumeHello {
    let (histogram, range, start_window) = histogram_of(volume, settings);
    let (p, q) = settings.opacity_ramp;
    VolumeHello {
        name: name.to_string(),
        dims: volume.dims(),
        range,
        histogram,
        opacity_ramp: [p, q],
        start_opacity: start_opacity(settings),
        start_window,
        start_colours: (settings.transfer_function.color.as_ref()).map(|c| sample(&|t| c.eval(t))),
        labels: volume.is_labels(),
    }
}

impl Start<'_> {
    /// The box of every volume.
    fn bounds(&self) -> [[f64; 3]; 2] {
        let (mut lo, mut hi) = self.volume.bounds();
        for (_, volume, _) in &self.others {
            let (a, b) = volume.bounds();
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        [lo.to_array(), hi.to_array()]
    }

    /// The starting lighting, each term the mean of its r, g, b.
    fn lighting(&self) -> Lighting {
        let phong = &self.settings.phong;
        let grey = |c: [f32; 3]| (c[0] + c[1] + c[2]) / 3.0;
        Lighting {
            ambient: grey(phong.ambient),
            diffuse: grey(phong.diffuse),
            specular: grey(phong.specular),
            shininess: phong.shininess,
            light: self.settings.light_direction.map(|d| d.to_array()),
        }
    }

    /// The first message.
    pub fn hello(&self) -> Hello {
        let (histogram, range, start_window) = histogram_of(self.volume, self.settings);
        let tf = &self.settings.transfer_function;
        let mut colormaps = Vec::new();
        if let Some(colour) = &tf.color {
            colormaps.push((START_COLOURS.to_string(), sample(&|t| colour.eval(t))));
        }
        colormaps.push((WHITE.to_string(), sample(&|_| [1.0; 3])));
        for name in colormap::NAMES {
            let map = colormap::colormap(name).expect("a listed colour map");
            colormaps.push((name.to_string(), sample(&|t| map.eval(t))));
        }
        let (p, q) = self.settings.opacity_ramp;
        Hello {
            name: self.name.to_string(),
            dims: self.volume.dims(),
            spacing: self.volume.spacing().to_array(),
            range,
            log: self.log,
            histogram,
            start: self.state.clone(),
            opacity_ramp: [p, q],
            start_opacity: start_opacity(self.settings),
            start_window,
            colormaps,
            levels: None,
            bounds: self.bounds(),
            lighting: self.lighting(),
            fit: false,
            volumes: (self.others.iter())
                .map(|&(name, volume, settings)| volume_hello(name, volume, settings))
                .collect(),
            time: self.time,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::ViewState;
    use volray_core::TransferFunction;

    #[test]
    fn hello_describes_the_volume_and_the_start() {
        let volume = Volume::new([2, 2, 2], (0..8).map(|i| i as f32).collect()).unwrap();
        let labels = Volume::new([2, 2, 2], vec![0.0, 1.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0])
            .unwrap()
            .as_labels();
        let settings = RenderSettings {
            transfer_function: TransferFunction::from_json(
                r#"{"domain": [1, 5], "opacity": [[0, 0], [1, 0.5]], "color": [[0, 1, 0, 0], [1, 0, 0, 1]]}"#,
            )
            .unwrap(),
            ..RenderSettings::default()
        };
        let state = ViewState::default();
        let hello = Start {
            name: "cube",
            volume: &volume,
            log: false,
            state: &state,
            settings: &settings,
            others: vec![("labels", &labels, &RenderSettings::default())],
            time: None,
        }
        .hello();
        assert_eq!(hello.range, [0.0, 7.0]);
        assert_eq!(hello.histogram.len(), HISTOGRAM_BINS);
        assert_eq!(hello.histogram.iter().sum::<u64>(), 8);
        assert_eq!(hello.start_window, [1.0, 5.0]);
        assert_eq!(hello.start_opacity, Some(vec![[0.0, 0.0], [1.0, 0.5]]));
        let names: Vec<&str> = hello.colormaps.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(&names[..3], ["start", "white", "viridis"]);
        let start = &hello.colormaps[0].1;
        assert_eq!(
            (start[0], start[COLOUR_SAMPLES - 1]),
            ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
        );
        assert_eq!(hello.opacity_ramp, [0.0, 0.5]);
        // A scene's second volume: its own histogram and range.
        let second = &hello.volumes[0];
        assert_eq!((second.name.as_str(), second.dims), ("labels", [2, 2, 2]));
        assert_eq!(second.range, [0.0, 2.0]);
        assert_eq!(second.histogram.iter().sum::<u64>(), 8);
        assert!(second.labels && second.start_colours.is_none());
        // The box of both, and the default lighting.
        assert_eq!(hello.bounds, [[0.0; 3], [1.0; 3]]);
        assert_eq!(
            (hello.lighting.diffuse, hello.lighting.light),
            (settings.phong.diffuse[0], None)
        );
        assert_eq!(second.start_window, [0.0, 2.0]);
    }

    #[test]
    fn a_few_hot_pixels_leave_the_histogram_over_the_values_window() {
        // 0..100 (i mod 101) with one voxel at 1e6: the histogram and its
        // range are the refined window's (as `--tf auto` chooses in), the
        // hot pixel in the top bin.
        let data = (0..4096)
            .map(|i| if i == 7 { 1e6 } else { (i % 101) as f32 })
            .collect();
        let volume = Volume::new([16, 16, 16], data).unwrap();
        let settings = RenderSettings::default();
        let state = ViewState::default();
        let hello = Start {
            name: "hot",
            volume: &volume,
            log: false,
            state: &state,
            settings: &settings,
            others: vec![],
            time: None,
        }
        .hello();
        assert_eq!(hello.range, [0.0, 100.0]);
        assert_eq!(hello.histogram.iter().sum::<u64>(), 4096);
        // Evenly spread: no bin holds more than a few times its share.
        assert!(
            hello
                .histogram
                .iter()
                .all(|&c| c < 4 * 4096 / HISTOGRAM_BINS as u64)
        );
        assert_eq!(hello.start_window, [0.0, 100.0]);
    }
}
