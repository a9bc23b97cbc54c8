//! A frame made a figure: the annotations a front end asks for
//! ([`Annotations`]: colour bar, scale bar, orientation axes, the
//! volume's outline, title, panel label) drawn
//! for what was rendered ([`Subject`]: the view, the transfer function's
//! colours and opacity over its window, the units), in an ink that reads
//! on the frame's background. The command line, Python and the viewer
//! draw through this one function; [`annotate_frame`] builds the subject
//! from the renderer and settings of the frame, so that they draw the
//! same pixels for the same frame.

use crate::colorbar::{ColorBar, Layout, Side, legend};
use crate::line::width_for;
use crate::scalebar::ScaleBar;
use crate::text::Font;
use volray_core::camera::View;
use volray_core::glam::DVec3;
use volray_core::transfer::classifier::Classifier;
use volray_core::transfer::labels::{MAX_LABELS, labels_of};
use volray_core::{Blend, Image, RenderError, RenderSettings, Renderer};

/// What to draw.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Annotations {
    /// The colour bar (a legend for a label volume), on this side.
    pub colorbar: Option<Side>,
    /// A scale bar: `Some(None)` of a round length, `Some(Some(l))` of
    /// length `l` in world units.
    pub scale_bar: Option<Option<f64>>,
    /// Text over the frame, centred.
    pub title: Option<String>,
    /// Text in the top left corner (a panel's letter).
    pub label: Option<String>,
    /// An orientation triad of the world's axes ([`crate::axes`]).
    pub axes: bool,
    /// The edges of the volume's box ([`crate::outline`]).
    pub outline: bool,
    /// The values' unit on the colour bar, as given (`--units`): it wins
    /// over the one known from how the volume was rendered
    /// ([`Rendered::value_unit`]). Draws nothing by itself.
    pub units: Option<String>,
}

impl Annotations {
    /// Whether anything is drawn.
    pub fn any(&self) -> bool {
        self.colorbar.is_some()
            || self.scale_bar.is_some()
            || self.title.is_some()
            || self.label.is_some()
            || self.axes
            || self.outline
    }
}

/// What was rendered, as the annotations need it.
pub struct Subject<'a> {
    pub view: &'a View,
    /// The volume's box in the world (a perspective scale bar holds at
    /// its centre's depth).
    pub bounds: (DVec3, DVec3),
    /// The values the transfer function spans, in the data's units.
    pub window: (f64, f64),
    /// The data were rendered as log10 (`--log`): the bar's ticks are
    /// decades of the data's own values.
    pub log: bool,
    /// Colour and opacity (per unit voxel distance) of a value in the
    /// data's units.
    pub colour: &'a dyn Fn(f64) -> [f32; 3],
    pub opacity: &'a dyn Fn(f64) -> f32,
    /// A label volume's labels and colours: a legend instead of a bar.
    pub labels: Option<Vec<(String, [f32; 3])>>,
    /// The projection blend mode, if one: the bar then shows the colour
    /// map without opacity.
    pub blend: Blend,
    /// The unit of the values (`HU`) and of lengths (`mm`), if known.
    pub value_unit: Option<&'a str>,
    pub length_unit: Option<&'a str>,
    /// The frame's background colour.
    pub background: [f32; 3],
    /// The names of the world's +x, +y, +z for the triad (`["R", "A",
    /// "S"]` for RAS+), `["x", "y", "z"]` where the volume names none.
    pub axis_names: [&'a str; 3],
    /// The boxes the outline draws: the volume's (`bounds`), or each of a
    /// scene's volumes.
    pub boxes: &'a [(DVec3, DVec3)],
}

/// The ink that reads on `background`: white on dark, black on light
/// (by its luminance, Rec. 709).
pub fn ink(background: [f32; 3]) -> [f32; 3] {
    let [r, g, b] = background;
    if 0.2126 * r + 0.7152 * g + 0.0722 * b > 0.5 {
        [0.0; 3]
    } else {
        [1.0; 3]
    }
}

/// The world size of one pixel where the scale bar holds, and whether it
/// holds only there (perspective: at the depth of the box's centre).
pub fn pixel_size(view: &View, bounds: (DVec3, DVec3)) -> (f64, bool) {
    match view {
        View::Orthographic(v) => (v.pixel_size, false),
        View::Perspective(v) => {
            let centre = (bounds.0 + bounds.1) / 2.0;
            let depth = (centre - v.eye).dot(v.direction).max(f64::MIN_POSITIVE);
            (depth * v.pixel_size, true)
        }
    }
}

/// Draws `what` for `subject` into `image`.
pub fn annotate(image: &mut Image, what: &Annotations, subject: &Subject) {
    let ink = ink(subject.background);
    // The outline first: the other annotations lie over it.
    if what.outline {
        let width = width_for(image);
        for &bounds in subject.boxes {
            crate::outline::draw(image, subject.view, bounds, width, ink);
        }
    }
    // Where the triad's corner ends on the right: before a colour bar
    // there.
    let mut right = image.width() as f64 - Layout::of(image).margin as f64;
    if let Some(side) = what.colorbar {
        let left = match &subject.labels {
            Some(entries) if !entries.is_empty() => legend(image, entries, side, ink),
            _ => {
                let projection = subject.blend != Blend::Composite;
                let opaque = |_: f64| 1.0;
                let bar = ColorBar {
                    window: subject.window,
                    log: subject.log && subject.window.0 > 0.0,
                    colour: subject.colour,
                    opacity: if projection { &opaque } else { subject.opacity },
                    unit: subject.value_unit,
                    side,
                };
                bar.draw(image, ink).left
            }
        };
        if side == Side::Right {
            right = left as f64 - Layout::of(image).margin as f64 / 2.0;
        }
    }
    if let Some(length) = what.scale_bar {
        let (size, approximate) = pixel_size(subject.view, subject.bounds);
        ScaleBar {
            pixel_size: size,
            length,
            unit: subject.length_unit,
            approximate,
        }
        .draw(image, ink);
    }
    if what.axes {
        crate::axes::draw(image, subject.view, subject.axis_names, right);
    }
    let font = Font::embedded();
    let side = image.width().min(image.height()) as f32;
    if let Some(title) = &what.title {
        let size = (side / 22.0).max(11.0);
        let (w, ascent, _) = font.measure(title, size);
        let x = (image.width() as f32 - w) / 2.0;
        font.draw(image, title, size, (x.max(2.0), ascent + side / 40.0), ink);
    }
    if let Some(label) = &what.label {
        let size = (side / 16.0).max(12.0);
        let (_, ascent, _) = font.measure(label, size);
        let margin = side / 40.0;
        font.draw(image, label, size, (margin, ascent + margin), ink);
    }
}

/// The unit of a volume's values under `preset`: Hounsfield units under a
/// CT preset (`ct-bone`, ...), else none known. One rule for `volray
/// render`, `volray view` and Python ([`Rendered::value_unit`]); a unit
/// given ([`Annotations::units`]) wins over it.
pub fn preset_unit(preset: Option<&str>) -> Option<&'static str> {
    preset.is_some_and(|p| p.starts_with("ct-")).then_some("HU")
}

/// A unit as given (`--units`, `units=`): trimmed, 1 to 32 printable
/// characters (it is written beside the colour bar's ticks), or why not.
pub fn parse_unit(text: &str) -> Result<String, String> {
    let unit = text.trim();
    match unit.is_empty() || unit.chars().count() > 32 || unit.chars().any(char::is_control) {
        true => Err(format!(
            "{text:?} is not a unit: give 1 to 32 printable characters"
        )),
        false => Ok(unit.to_string()),
    }
}

/// What a frame was rendered with beyond its renderer and settings.
#[derive(Debug, Clone)]
pub struct Rendered<'a> {
    /// The data were rendered as log10 of themselves (`--log`).
    pub log: bool,
    /// The unit of the values (`HU`) and of lengths (`mm`), if known.
    pub value_unit: Option<&'a str>,
    pub length_unit: Option<&'a str>,
    /// The names of the world's +x, +y, +z ([`Subject::axis_names`]).
    pub axis_names: [&'a str; 3],
    /// The boxes the outline draws (the renderer's volume's, or each of a
    /// scene's volumes).
    pub boxes: &'a [(DVec3, DVec3)],
    /// The box at whose centre a perspective scale bar holds (the
    /// volume's; a series': the box framing every frame).
    pub scale_box: (DVec3, DVec3),
}

impl<'a> Rendered<'a> {
    /// A volume's own: its box, no units, the axes x, y, z.
    pub fn of(bounds: &'a [(DVec3, DVec3)]) -> Self {
        Rendered {
            log: false,
            value_unit: None,
            length_unit: None,
            axis_names: ["x", "y", "z"],
            boxes: bounds,
            scale_box: bounds.first().copied().unwrap_or((DVec3::ZERO, DVec3::ONE)),
        }
    }
}

/// Draws `what` into `image`, a frame `renderer` rendered with
/// `settings`: the view framed as the renderer frames it, the colour bar
/// over the classifier's value window (the data's own values for a log
/// volume), a legend of the labels shown for a label volume.
pub fn annotate_frame(
    image: &mut Image,
    what: &Annotations,
    renderer: &Renderer,
    settings: &RenderSettings,
    rendered: &Rendered,
) -> Result<(), RenderError> {
    if !what.any() {
        return Ok(());
    }
    let volume = renderer.volume();
    let frame = renderer.prepare(settings)?;
    let classifier = Classifier::for_frame(
        settings,
        renderer.value_range(),
        volume.spacing().min_element() as f32,
        || renderer.max_gradient(),
    );
    let (lo, inv) = classifier.normalisation();
    let (lo, hi) = (
        f64::from(lo),
        f64::from(lo) + if inv > 0.0 { 1.0 / f64::from(inv) } else { 0.0 },
    );
    // The data were rendered as log10 of themselves: the bar's values are
    // the data's own.
    let log = rendered.log;
    let value = |v: f64| if log { v.log10() as f32 } else { v as f32 };
    let window = if log {
        (10f64.powf(lo), 10f64.powf(hi))
    } else {
        (lo, hi)
    };
    let projection = settings.blend != Blend::Composite;
    let colour = |v: f64| {
        if projection {
            classifier.projection_colour(value(v))
        } else {
            classifier.material(value(v))
        }
    };
    let opacity = |v: f64| classifier.unit_opacity(value(v));
    let labels = if volume.is_labels() {
        let found = labels_of(volume, MAX_LABELS)
            .ok()
            .flatten()
            .unwrap_or_default();
        Some(
            (found.into_iter())
                .filter(|&l| classifier.unit_opacity(l as f32) > 0.0)
                .map(|l| (l.to_string(), classifier.material(l as f32)))
                .collect(),
        )
    } else {
        None
    };
    let subject = Subject {
        view: &frame.view,
        bounds: rendered.scale_box,
        window,
        log,
        colour: &colour,
        opacity: &opacity,
        labels,
        blend: settings.blend,
        value_unit: what.units.as_deref().or(rendered.value_unit),
        length_unit: rendered.length_unit,
        background: settings.background,
        axis_names: rendered.axis_names,
        boxes: rendered.boxes,
    };
    annotate(image, what, &subject);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::camera::Camera;

    #[test]
    fn the_ink_reads_on_the_background() {
        assert_eq!(ink([0.0; 3]), [1.0; 3]);
        assert_eq!(ink([1.0; 3]), [0.0; 3]);
        assert_eq!(ink([0.1, 0.2, 0.5]), [1.0; 3]);
    }

    #[test]
    fn a_ct_preset_means_hounsfield_units() {
        assert_eq!(preset_unit(Some("ct-bone")), Some("HU"));
        assert_eq!(preset_unit(Some("electron-density")), None);
        assert_eq!(preset_unit(None), None);
        assert_eq!(parse_unit(" mg/mL ").as_deref(), Ok("mg/mL"));
        for bad in ["", "  ", "a\nb", &"x".repeat(33)] {
            assert!(
                parse_unit(bad).unwrap_err().contains("not a unit"),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn a_perspective_pixel_is_measured_at_the_boxs_centre() {
        let bounds = (DVec3::ZERO, DVec3::splat(10.0));
        let camera = Camera {
            view_point: Some(DVec3::new(45.0, 5.0, 5.0)),
            projection: volray_core::Projection::Perspective { fov_degrees: 30.0 },
            ..Camera::default()
        };
        let view = View::frame(&camera, bounds, 200, 200).unwrap();
        let (size, approximate) = pixel_size(&view, bounds);
        let View::Perspective(v) = &view else {
            unreachable!()
        };
        assert!(approximate);
        assert!((size - 40.0 * v.pixel_size).abs() < 1e-9, "{size}");
        let view = View::frame(&Camera::default(), bounds, 200, 200).unwrap();
        assert!(!pixel_size(&view, bounds).1);
    }

    #[test]
    fn the_triad_keeps_left_of_a_colour_bar_on_the_right() {
        let bounds = (DVec3::ZERO, DVec3::ONE);
        let camera = Camera {
            azimuth: 30.0,
            elevation: 20.0,
            ..Camera::default()
        };
        let view = View::frame(&camera, bounds, 240, 240).unwrap();
        let black = |v: f64| [0.0, 0.0, (v as f32).clamp(0.0, 1.0)];
        let subject = Subject {
            view: &view,
            bounds,
            window: (0.0, 1.0),
            log: false,
            colour: &black,
            opacity: &|_| 0.0,
            labels: None,
            blend: Blend::Composite,
            value_unit: None,
            length_unit: None,
            background: [0.0; 3],
            axis_names: ["x", "y", "z"],
            boxes: &[],
        };
        let bar = Annotations {
            colorbar: Some(Side::Right),
            ..Annotations::default()
        };
        let mut with_bar = Image::new(240, 240, [0.0, 0.0, 0.0, 1.0]);
        annotate(&mut with_bar, &bar, &subject);
        // The bar's leftmost ink.
        let left = (0..240)
            .find(|&x| (0..240).any(|y| with_bar.get(x, y) != [0.0, 0.0, 0.0, 1.0]))
            .unwrap();
        let both = Annotations {
            axes: true,
            ..bar.clone()
        };
        let mut image = Image::new(240, 240, [0.0, 0.0, 0.0, 1.0]);
        annotate(&mut image, &both, &subject);
        let mut triad = 0;
        for y in 0..240 {
            for x in 0..240 {
                if image.get(x, y) != with_bar.get(x, y) {
                    assert!(x < left, "({x}, {y}) over the bar, which starts at {left}");
                    triad += 1;
                }
            }
        }
        assert!(triad > 30, "{triad}");
    }

    #[test]
    fn nothing_asked_draws_nothing() {
        let view = View::frame(&Camera::default(), (DVec3::ZERO, DVec3::ONE), 64, 64).unwrap();
        let mut image = Image::new(64, 64, [0.2, 0.2, 0.2, 1.0]);
        let before = image.clone();
        let grey = |v: f64| [v as f32; 3];
        let subject = Subject {
            view: &view,
            bounds: (DVec3::ZERO, DVec3::ONE),
            window: (0.0, 1.0),
            log: false,
            colour: &grey,
            opacity: &|_| 1.0,
            labels: None,
            blend: Blend::Composite,
            value_unit: None,
            length_unit: None,
            background: [0.2; 3],
            axis_names: ["x", "y", "z"],
            boxes: &[(DVec3::ZERO, DVec3::ONE)],
        };
        annotate(&mut image, &Annotations::default(), &subject);
        assert_eq!(image, before);
        let all = Annotations {
            colorbar: Some(Side::Right),
            scale_bar: Some(None),
            title: Some("A title".into()),
            label: Some("a".into()),
            axes: true,
            outline: true,
            units: None,
        };
        assert!(all.any());
        let unit_alone = Annotations {
            units: Some("K".into()),
            ..Annotations::default()
        };
        assert!(!unit_alone.any());
        annotate(&mut image, &all, &subject);
        assert_ne!(image, before);
    }
}
