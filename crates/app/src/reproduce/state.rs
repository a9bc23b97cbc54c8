//! The view a page asks for: everything the page's controls set (the
//! orbit, zoom and pan; the projection; the blend mode and isovalue; the
//! step, shading and background; the value window, the opacity points and
//! the colours), as one JSON object the page sends whole with every
//! change. Sending the whole state rather than changes makes every message
//! stand alone, so that the server may drop all but the latest.
//!
//! [`ViewState::check`] bounds every field before anything is rendered:
//! a message from a page is untrusted input.

use serde::{Deserialize, Serialize};
use volray_annotate::colorbar::Side;
use volray_annotate::figure::Annotations;
use volray_core::transfer::colormap;

/// The largest side of a frame a page may ask for (the full-quality view
/// and "Save PNG"): 4096² pixels of RGBA `f32` take 256 MiB.
pub const MAX_SIDE: usize = 4096;

/// The smallest and largest step along the rays, in voxels.
pub const STEP_RANGE: (f64, f64) = (1e-3, 64.0);

/// The smallest and largest zoom.
pub const ZOOM_RANGE: (f64, f64) = (1e-3, 1e3);

/// The largest orbit angle, in degrees (as `--azimuth` takes).
pub const MAX_ANGLE: f64 = 1e6;

/// The most points of the opacity function.
pub const MAX_OPACITY_POINTS: usize = 256;

/// The most clip planes.
pub const MAX_CLIP_PLANES: usize = 6;

/// The largest specular exponent the page may set.
pub const MAX_SHININESS: f32 = 1000.0;

/// The colours that are not a named colour map: the starting transfer
/// function's own, and none (white material).
pub const START_COLOURS: &str = "start";
pub const WHITE: &str = "white";

/// How the samples along a ray make its pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BlendMode {
    /// The paper's compositing of classified, shaded samples.
    Composite,
    /// Maximum intensity projection.
    Mip,
    /// Minimum intensity projection.
    Minip,
    /// The mean value along the ray.
    Average,
    /// Compositing of Levoy's isovalue contour ([`ViewState::iso`]).
    Iso,
}

impl BlendMode {
    /// Whether the mode projects the interpolated value (no opacity, no
    /// lighting).
    pub fn is_projection(self) -> bool {
        matches!(self, BlendMode::Mip | BlendMode::Minip | BlendMode::Average)
    }
}

/// Everything the page's controls set. Values are in the units the
/// renderer sees (log10 of the data's when the volume is rendered as its
/// logarithm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewState {
    /// The full-quality frame's size in pixels.
    pub width: usize,
    pub height: usize,
    /// Degrees the eye orbits about the up vector, then rises.
    pub azimuth: f64,
    pub elevation: f64,
    pub zoom: f64,
    /// The view reference (`None`: the volume's centre); panning moves it.
    pub look_at: Option<[f64; 3]>,
    /// The view point before the orbits (`None`: on the +x side of the
    /// reference); panning moves it with the reference.
    pub view_point: Option<[f64; 3]>,
    /// The vertical field of view in degrees; `None`: orthographic.
    pub perspective: Option<f64>,
    pub blend: BlendMode,
    /// Levoy's isovalue, needed by [`BlendMode::Iso`].
    pub iso: Option<f32>,
    /// Sample spacing along the rays, in voxels.
    pub step: f64,
    pub shading: bool,
    /// The opaque background, components in [0, 1].
    pub background: [f32; 3],
    /// The value window `[lo, hi]` the transfer function spans; `None`:
    /// as at the start (the starting function's domain, else the
    /// volume's range).
    pub window: Option<[f64; 2]>,
    /// Opacity points `[t, alpha]`, sorted by `t`; `None`: as at the start.
    pub opacity: Option<Vec<[f32; 2]>>,
    /// A colour map's name, [`START_COLOURS`], [`WHITE`] or one colour
    /// as `#rrggbb` ([`solid_colour`]).
    pub colormap: String,
    /// The other volumes of a scene (`volray view --channels`,
    /// `--overlay`), in their order after the first, whose look is the
    /// fields above; empty for one volume.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layers: Vec<LayerState>,
    /// The time point shown, as the file counts its frames, where the
    /// viewer serves a time axis (`volray view --frames`); `None`: the
    /// one the viewer started with.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<usize>,
    /// The crop box's world corners `[lo, hi]` (`--crop`); `None`: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crop: Option<[[f64; 3]; 2]>,
    /// Clip planes, each a world point and a normal towards the side kept
    /// (`--clip`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clip: Vec<[[f64; 3]; 2]>,
    /// Phong's terms and the light; `None`: as started.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting: Option<Lighting>,
    /// Shadows (`--shadows`), where the frame is lit.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub shadows: bool,
    /// Ambient occlusion's radius in voxels (`--ambient-occlusion`);
    /// `None`: off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient_occlusion: Option<f64>,
    /// What is drawn into the frame (`--colorbar`, `--scale-bar`, ...).
    #[serde(default, skip_serializing_if = "Figure::is_bare")]
    pub figure: Figure,
}

/// The most characters of a title or a label.
pub const MAX_TEXT: usize = 200;

/// The annotations drawn into the frame, as `volray render` draws them
/// (volray-annotate): a colour bar (`"right"` or `"left"`), a scale bar
/// of a round length, the axes' triad, the box's outline, a title and a
/// panel label.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Figure {
    pub colorbar: Option<ColorBarSide>,
    pub scale_bar: bool,
    /// The scale bar's length in world units; `None`: a round one.
    pub scale_length: Option<f64>,
    pub axes: bool,
    pub outline: bool,
    pub title: Option<String>,
    pub label: Option<String>,
}

/// Where the colour bar goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ColorBarSide {
    Right,
    Left,
}

impl Figure {
    /// Nothing drawn.
    pub fn is_bare(&self) -> bool {
        *self == Figure::default()
    }

    /// The figure that draws `what` (a front end's starting figure); its
    /// unit is the viewer's, not the state's.
    pub fn of(what: &Annotations) -> Figure {
        Figure {
            colorbar: what.colorbar.map(|side| match side {
                Side::Right => ColorBarSide::Right,
                Side::Left => ColorBarSide::Left,
            }),
            scale_bar: what.scale_bar.is_some(),
            scale_length: what.scale_bar.flatten(),
            axes: what.axes,
            outline: what.outline,
            title: what.title.clone(),
            label: what.label.clone(),
        }
    }

    /// What volray-annotate draws for this figure (the unit left to the
    /// viewer's `FigureContext`, volray-view).
    pub fn annotations(&self) -> Annotations {
        Annotations {
            colorbar: self.colorbar.map(|side| match side {
                ColorBarSide::Right => Side::Right,
                ColorBarSide::Left => Side::Left,
            }),
            scale_bar: self.scale_bar.then_some(self.scale_length),
            title: self.title.clone(),
            label: self.label.clone(),
            axes: self.axes,
            outline: self.outline,
            units: None,
        }
    }
}

impl ColorBarSide {
    /// `right` or `left`, as `--colorbar` and `colorbar=` take it.
    pub fn name(self) -> &'static str {
        match self {
            ColorBarSide::Right => "right",
            ColorBarSide::Left => "left",
        }
    }
}

/// What the page's lighting controls set: Phong's reflection terms as
/// greys (`--ambient`, `--diffuse`, `--specular`), the exponent
/// (`--shininess`) and the direction towards the light (`--light`;
/// `None`: a headlight).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lighting {
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub shininess: f32,
    pub light: Option<[f64; 3]>,
}

/// What a scene's volume after the first sets in its panel: shown or
/// hidden, and its transfer function as [`ViewState`]'s fields for the
/// first volume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerState {
    pub visible: bool,
    pub window: Option<[f64; 2]>,
    pub opacity: Option<Vec<[f32; 2]>>,
    pub colormap: String,
}

/// The colour of a colour choice written `#rrggbb`, components in [0, 1].
pub fn solid_colour(name: &str) -> Option<[f32; 3]> {
    let hex = name.strip_prefix('#')?;
    if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let c = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map(|v| f32::from(v) / 255.0);
    Some([c(0).ok()?, c(2).ok()?, c(4).ok()?])
}

/// A state that cannot be rendered: which field, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StateError {
    #[error("{field} {value} is outside {lo} to {hi}")]
    OutOfRange {
        field: &'static str,
        value: f64,
        lo: f64,
        hi: f64,
    },
    #[error("{field} must be finite numbers")]
    NotFinite { field: &'static str },
    #[error("blend iso needs an isovalue")]
    NoIsovalue,
    #[error("the value window [{lo}, {hi}] must have lo < hi")]
    EmptyWindow { lo: f64, hi: f64 },
    #[error("opacity point {index}: {problem}")]
    OpacityPoint { index: usize, problem: &'static str },
    #[error("the opacity function needs 1 to {max} points, not {count}")]
    OpacityPoints { count: usize, max: usize },
    #[error("unknown colour map \"{0}\"")]
    Colormap(String),
    #[error("the crop box's {axis} range [{lo}, {hi}] must have lo < hi")]
    EmptyCrop { axis: char, lo: f64, hi: f64 },
    #[error("{field} must not be zero")]
    ZeroDirection { field: &'static str },
    #[error("at most {MAX_CLIP_PLANES} clip planes, not {0}")]
    ClipPlanes(usize),
    #[error("the {0} must be one line of at most {MAX_TEXT} characters")]
    Text(&'static str),
    /// A field of a scene's volume (numbered from 1, the first's being
    /// the state's own fields).
    #[error("volume {0}: {1}")]
    Layer(usize, Box<StateError>),
}

impl ViewState {
    /// Checks every field against its bounds, naming the first that is
    /// out of them.
    pub fn check(&self) -> Result<(), StateError> {
        let side = |field, value: usize| within(field, value as f64, (1.0, MAX_SIDE as f64));
        side("width", self.width)?;
        side("height", self.height)?;
        within("azimuth", self.azimuth, (-MAX_ANGLE, MAX_ANGLE))?;
        within("elevation", self.elevation, (-MAX_ANGLE, MAX_ANGLE))?;
        within("zoom", self.zoom, ZOOM_RANGE)?;
        for (field, point) in [("look_at", self.look_at), ("view_point", self.view_point)] {
            if point.is_some_and(|p| !p.iter().all(|x| x.is_finite())) {
                return Err(StateError::NotFinite { field });
            }
        }
        if let Some(radius) = self.ambient_occlusion {
            let radii = volray_core::shadows::ambient::RADII;
            within("ambient_occlusion", radius, (*radii.start(), *radii.end()))?;
        }
        if let Some(fov) = self.perspective {
            within("perspective", fov, (0.0, 180.0))?;
            if fov == 0.0 || fov == 180.0 {
                return Err(StateError::OutOfRange {
                    field: "perspective",
                    value: fov,
                    lo: 0.0,
                    hi: 180.0,
                });
            }
        }
        match self.iso {
            Some(v) => within(
                "iso",
                f64::from(v),
                (-f64::from(f32::MAX), f64::from(f32::MAX)),
            )?,
            None if self.blend == BlendMode::Iso => return Err(StateError::NoIsovalue),
            None => {}
        }
        within("step", self.step, STEP_RANGE)?;
        for c in self.background {
            within("background", f64::from(c), (0.0, 1.0))?;
        }
        check_look(self.window, self.opacity.as_deref(), &self.colormap)?;
        if let Some([lo, hi]) = self.crop {
            finite("crop", &[lo, hi].concat())?;
            for (axis, name) in ['x', 'y', 'z'].into_iter().enumerate() {
                if lo[axis] >= hi[axis] {
                    return Err(StateError::EmptyCrop {
                        axis: name,
                        lo: lo[axis],
                        hi: hi[axis],
                    });
                }
            }
        }
        if self.clip.len() > MAX_CLIP_PLANES {
            return Err(StateError::ClipPlanes(self.clip.len()));
        }
        for [point, normal] in &self.clip {
            finite("clip", &[*point, *normal].concat())?;
            nonzero("the clip plane's normal", normal)?;
        }
        if let Some(l) = self.figure.scale_length {
            within("scale_length", l, (f64::MIN_POSITIVE, f64::from(f32::MAX)))?;
        }
        for (field, text) in [("title", &self.figure.title), ("label", &self.figure.label)] {
            let text = text.as_deref().unwrap_or("");
            if text.chars().count() > MAX_TEXT || text.chars().any(char::is_control) {
                return Err(StateError::Text(field));
            }
        }
        if let Some(l) = &self.lighting {
            for (field, v) in [
                ("ambient", l.ambient),
                ("diffuse", l.diffuse),
                ("specular", l.specular),
            ] {
                within(field, f64::from(v), (0.0, 1.0))?;
            }
            within(
                "shininess",
                f64::from(l.shininess),
                (1.0, f64::from(MAX_SHININESS)),
            )?;
            if let Some(light) = &l.light {
                finite("light", light)?;
                nonzero("the light's direction", light)?;
            }
        }
        for (i, layer) in self.layers.iter().enumerate() {
            check_look(layer.window, layer.opacity.as_deref(), &layer.colormap)
                .map_err(|e| StateError::Layer(i + 2, Box::new(e)))?;
        }
        Ok(())
    }
}

/// Every number finite.
fn finite(field: &'static str, values: &[f64]) -> Result<(), StateError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(StateError::NotFinite { field })
    }
}

/// A direction, not zero.
fn nonzero(field: &'static str, v: &[f64; 3]) -> Result<(), StateError> {
    if v.iter().all(|c| *c == 0.0) {
        Err(StateError::ZeroDirection { field })
    } else {
        Ok(())
    }
}

/// A volume's window, opacity points and colours.
fn check_look(
    window: Option<[f64; 2]>,
    opacity: Option<&[[f32; 2]]>,
    colours: &str,
) -> Result<(), StateError> {
    if let Some([lo, hi]) = window {
        let bound = f64::from(f32::MAX);
        within("window", lo, (-bound, bound))?;
        within("window", hi, (-bound, bound))?;
        if lo >= hi {
            return Err(StateError::EmptyWindow { lo, hi });
        }
    }
    if let Some(points) = opacity {
        check_opacity(points)?;
    }
    let known = [START_COLOURS, WHITE].contains(&colours)
        || colormap::NAMES.contains(&colours)
        || solid_colour(colours).is_some();
    if !known {
        return Err(StateError::Colormap(colours.to_string()));
    }
    Ok(())
}

/// `value` finite and in `[lo, hi]`.
fn within(field: &'static str, value: f64, (lo, hi): (f64, f64)) -> Result<(), StateError> {
    if !value.is_finite() {
        return Err(StateError::NotFinite { field });
    }
    if !(lo..=hi).contains(&value) {
        return Err(StateError::OutOfRange {
            field,
            value,
            lo,
            hi,
        });
    }
    Ok(())
}

/// Opacity points: 1 to [`MAX_OPACITY_POINTS`], `t` and alpha in [0, 1],
/// sorted by `t`.
fn check_opacity(points: &[[f32; 2]]) -> Result<(), StateError> {
    if points.is_empty() || points.len() > MAX_OPACITY_POINTS {
        return Err(StateError::OpacityPoints {
            count: points.len(),
            max: MAX_OPACITY_POINTS,
        });
    }
    for (index, [t, a]) in points.iter().enumerate() {
        let problem = if !(0.0..=1.0).contains(t) {
            "t must lie in [0, 1]"
        } else if !(0.0..=1.0).contains(a) {
            "opacity must lie in [0, 1]"
        } else if index > 0 && *t < points[index - 1][0] {
            "points must be sorted by t"
        } else {
            continue;
        };
        return Err(StateError::OpacityPoint { index, problem });
    }
    Ok(())
}

/// A valid state: the default view of a 480² frame (white, composited,
/// shaded, the camera and window left to the volume).
impl Default for ViewState {
    fn default() -> Self {
        ViewState {
            width: 480,
            height: 480,
            azimuth: 0.0,
            elevation: 0.0,
            zoom: 1.0,
            look_at: None,
            view_point: None,
            perspective: None,
            blend: BlendMode::Composite,
            iso: None,
            step: 1.0,
            shading: true,
            background: [0.0; 3],
            window: None,
            opacity: None,
            colormap: WHITE.into(),
            layers: Vec::new(),
            time: None,
            crop: None,
            clip: Vec::new(),
            lighting: None,
            shadows: false,
            ambient_occlusion: None,
            figure: Figure::default(),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A valid state: the default view of a 480² frame.
    pub fn sample() -> ViewState {
        ViewState::default()
    }

    #[test]
    fn a_figure_and_its_annotations_are_one_another() {
        let figure = Figure {
            colorbar: Some(ColorBarSide::Left),
            scale_bar: true,
            scale_length: Some(2.5),
            axes: true,
            outline: false,
            title: Some("t".into()),
            label: None,
        };
        let what = figure.annotations();
        assert_eq!(what.colorbar, Some(Side::Left));
        assert_eq!(what.scale_bar, Some(Some(2.5)));
        assert_eq!(Figure::of(&what), figure);
        assert_eq!(
            Figure::of(&Figure::default().annotations()),
            Figure::default()
        );
        assert!(!Figure::default().annotations().any());
    }

    #[test]
    fn a_valid_state_passes_and_round_trips_through_json() {
        let mut s = sample();
        s.opacity = Some(vec![[0.0, 0.0], [0.5, 0.25], [0.5, 0.75], [1.0, 1.0]]);
        s.window = Some([-1.5, 2.0]);
        s.colormap = "viridis".into();
        s.perspective = Some(30.0);
        s.blend = BlendMode::Iso;
        s.iso = Some(0.25);
        assert_eq!(s.check(), Ok(()));
        let json = serde_json::to_value(&s).unwrap();
        // One volume's state says nothing of scenes, time or depth cues.
        for field in ["layers", "time", "shadows", "ambient_occlusion"] {
            assert!(json.get(field).is_none(), "{field}");
        }
        s.shadows = true;
        s.ambient_occlusion = Some(6.0);
        s.layers.push(LayerState {
            visible: false,
            window: Some([0.0, 1.0]),
            opacity: Some(vec![[0.0, 0.5]]),
            colormap: "#FF00ff".into(),
        });
        s.time = Some(3);
        assert_eq!(s.check(), Ok(()));
        assert_eq!(solid_colour("#FF00ff"), Some([1.0, 0.0, 1.0]));
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<ViewState>(&json).unwrap(), s);
    }

    #[test]
    fn every_bound_is_checked() {
        type Spoil = fn(&mut ViewState);
        let bad: Vec<(Spoil, &str)> = vec![
            (|s| s.width = 0, "width 0 is outside 1 to 4096"),
            (|s| s.height = 5000, "height"),
            (|s| s.azimuth = f64::NAN, "azimuth must be finite"),
            (|s| s.elevation = 2e6, "elevation"),
            (|s| s.zoom = 0.0, "zoom"),
            (
                |s| s.ambient_occlusion = Some(0.5),
                "ambient_occlusion 0.5 is outside 1 to 32",
            ),
            (|s| s.look_at = Some([0.0, f64::INFINITY, 0.0]), "look_at"),
            (|s| s.perspective = Some(180.0), "perspective"),
            (|s| s.perspective = Some(0.0), "perspective"),
            (|s| s.blend = BlendMode::Iso, "isovalue"),
            (|s| s.iso = Some(f32::NAN), "iso must be finite"),
            (|s| s.step = 0.0, "step"),
            (|s| s.background = [0.0, 1.5, 0.0], "background"),
            (|s| s.window = Some([2.0, 2.0]), "lo < hi"),
            (|s| s.window = Some([0.0, 1e300]), "window"),
            (|s| s.opacity = Some(vec![]), "1 to 256 points"),
            (|s| s.opacity = Some(vec![[0.0, 2.0]]), "opacity must lie"),
            (|s| s.opacity = Some(vec![[-0.1, 0.0]]), "t must lie"),
            (
                |s| s.opacity = Some(vec![[0.5, 0.0], [0.25, 0.0]]),
                "sorted",
            ),
            (|s| s.colormap = "jet".into(), "unknown colour map \"jet\""),
            (|s| s.colormap = "#ff00f".into(), "unknown colour map"),
            (
                |s| s.figure.title = Some("two\nlines".into()),
                "the title must be one line",
            ),
            (
                |s| s.figure.label = Some("x".repeat(201)),
                "the label must be one line of at most 200 characters",
            ),
            (
                |s| s.crop = Some([[0.0, 0.0, 0.0], [1.0, -1.0, 1.0]]),
                "the crop box's y range [0, -1] must have lo < hi",
            ),
            (
                |s| s.crop = Some([[0.0, f64::NAN, 0.0], [1.0; 3]]),
                "crop must be finite",
            ),
            (
                |s| s.clip = vec![[[0.0; 3], [0.0; 3]]],
                "the clip plane's normal must not be zero",
            ),
            (
                |s| s.clip = vec![[[0.0; 3], [1.0, 0.0, 0.0]]; 7],
                "at most 6 clip planes, not 7",
            ),
            (
                |s| {
                    s.lighting = Some(Lighting {
                        ambient: 0.1,
                        diffuse: 1.5,
                        specular: 0.2,
                        shininess: 10.0,
                        light: None,
                    })
                },
                "diffuse 1.5 is outside 0 to 1",
            ),
            (
                |s| {
                    s.lighting = Some(Lighting {
                        ambient: 0.1,
                        diffuse: 0.5,
                        specular: 0.2,
                        shininess: 10.0,
                        light: Some([0.0; 3]),
                    })
                },
                "the light's direction must not be zero",
            ),
            (
                |s| {
                    let mut layer = LayerState {
                        visible: true,
                        window: None,
                        opacity: None,
                        colormap: "#00ff00".into(),
                    };
                    s.layers.push(layer.clone());
                    layer.window = Some([1.0, 0.0]);
                    s.layers.push(layer);
                },
                "volume 3: the value window [1, 0] must have lo < hi",
            ),
        ];
        for (spoil, expect) in bad {
            let mut s = sample();
            spoil(&mut s);
            let err = s.check().unwrap_err().to_string();
            assert!(err.contains(expect), "{err} (expected {expect})");
        }
    }

    #[test]
    fn unknown_fields_and_nulls_are_refused() {
        let mut json = serde_json::to_value(sample()).unwrap();
        json["colour"] = "red".into();
        assert!(serde_json::from_value::<ViewState>(json).is_err());
        let mut json = serde_json::to_value(sample()).unwrap();
        // JSON.stringify(NaN) is null.
        json["azimuth"] = serde_json::Value::Null;
        assert!(serde_json::from_value::<ViewState>(json).is_err());
    }
}
