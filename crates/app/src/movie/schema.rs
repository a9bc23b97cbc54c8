//! The keyframes file (JSON; `docs/movies.md` is its schema, version 1):
//!
//! ```json
//! {"version": 1, "fps": 30, "time": "hold",
//!  "keyframes": [{"t": 0, "azimuth": 0, "ease": "linear"},
//!                {"t": 4.5, "azimuth": 180, "zoom": 1.5, "look_at": [0, 0, 10]}]}
//! ```
//!
//! Each keyframe holds `volray render` options under the flag's name
//! without its dashes (`-` as `_`), valued as the flag is, in JSON
//! (numbers, `[x, y, z]` arrays or the flag's `"x,y,z"` text, strings,
//! booleans, `null` for "back to the default"), and read into the very
//! option structs the flags produce ([`State`]): a key not given keeps
//! its value from the keyframe before (the first, the command line's).
//! Every keyframe's options are checked as the flags are
//! (`volray_options::settings`), so a bad value is refused before any
//! frame is rendered, in one line naming the file, the keyframe and the
//! key.

use super::interpolate::{Ease, State};
use serde_json::Value;
use std::path::Path;
use volray_options::{BlendMode, Naming, Opt, Tf};

/// How a fractional `frame` (the data's time point) is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimeMode {
    /// The time point last reached (the value rounded down): a
    /// simulation's steps shown as they were computed.
    #[default]
    Hold,
    /// The two time points either side, their values mixed linearly.
    Interpolate,
}

impl TimeMode {
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "hold" => Some(TimeMode::Hold),
            "interpolate" => Some(TimeMode::Interpolate),
            _ => None,
        }
    }
}

/// The version of the schema this reads.
pub const VERSION: u64 = 1;

/// The largest keyframes file read, in bytes.
pub const MAX_BYTES: u64 = 16 << 20;

/// A keyframes file refused: one line naming the file, and where in it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {message}")]
pub struct KeyframesError {
    pub file: String,
    pub message: String,
}

/// One keyframe: its time, the ease of the segment it starts, and every
/// option as it stands there.
#[derive(Debug, Clone, PartialEq)]
pub struct Keyframe {
    pub t: f64,
    pub ease: Ease,
    pub state: State,
}

/// A keyframes file read.
#[derive(Debug, Clone, PartialEq)]
pub struct Keyframes {
    pub fps: Option<f64>,
    pub time: TimeMode,
    pub keyframes: Vec<Keyframe>,
}

/// How the keyframes file names an option in a message: its key.
struct Keys;

impl Naming for Keys {
    fn option(&self, opt: Opt) -> String {
        opt.name().replace('-', "_")
    }

    fn with_value(&self, opt: Opt, value: &str) -> String {
        format!("\"{}\": {value}", self.option(opt))
    }
}

/// The keys a keyframe takes, besides `t` and `ease`.
pub const KEYS: [&str; 32] = [
    "azimuth",
    "elevation",
    "zoom",
    "view",
    "look_at",
    "up",
    "perspective",
    "clip",
    "crop",
    "preset",
    "colormap",
    "tf",
    "range",
    "opacity",
    "gradient_opacity",
    "iso",
    "iso_thickness",
    "blend",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "light",
    "light_color",
    "shadows",
    "ambient_occlusion",
    "shading",
    "background",
    "step",
    "frame",
    "title",
    "label",
];

/// Reads the keyframes file `path` (bounded by [`MAX_BYTES`]), its keys
/// applied over `base` (the command line's options), a `tf` file named
/// relative to the keyframes file's directory.
pub fn read(path: &Path, base: &State) -> Result<Keyframes, KeyframesError> {
    let file = path.display().to_string();
    let fail = |message: String| KeyframesError {
        file: file.clone(),
        message,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if !meta.is_file() {
        return Err(fail("not a file".into()));
    }
    if meta.len() > MAX_BYTES {
        return Err(fail(format!(
            "{} bytes: a keyframes file is at most {MAX_BYTES} bytes",
            meta.len()
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    parse(&file, &text, base, dir)
}

/// Parses a keyframes file's `text` (`file` names it in messages; `dir`
/// is where its `tf` files are found).
pub fn parse(
    file: &str,
    text: &str,
    base: &State,
    dir: &Path,
) -> Result<Keyframes, KeyframesError> {
    let fail = |message: String| KeyframesError {
        file: file.to_string(),
        message,
    };
    let root: Value = serde_json::from_str(text).map_err(|e| fail(format!("not JSON: {e}")))?;
    let Value::Object(root) = root else {
        return Err(fail(
            "expected an object: {\"version\": 1, \"fps\": 30, \"keyframes\": [...]}".into(),
        ));
    };
    for key in root.keys() {
        if !["version", "fps", "time", "keyframes"].contains(&key.as_str()) {
            return Err(fail(format!(
                "unknown key \"{key}\" (a keyframes file holds version, fps, time and keyframes)"
            )));
        }
    }
    match root.get("version") {
        None => {}
        Some(v) if v.as_u64() == Some(VERSION) => {}
        Some(v) => {
            return Err(fail(format!(
                "version {v}: this volray reads keyframes files of version {VERSION}"
            )));
        }
    }
    let fps = match root.get("fps") {
        None => None,
        Some(v) => match v.as_f64() {
            Some(f) if f > 0.0 && f <= 100.0 => Some(f),
            _ => return Err(fail(format!("fps: {v}: expected a number in (0, 100]"))),
        },
    };
    let time = match root.get("time") {
        None => TimeMode::default(),
        Some(v) => match v.as_str().and_then(TimeMode::from_name) {
            Some(mode) => mode,
            None => {
                return Err(fail(format!(
                    "time: {v}: expected \"hold\" or \"interpolate\""
                )));
            }
        },
    };
    let Some(Value::Array(list)) = root.get("keyframes") else {
        return Err(fail("keyframes: expected an array of keyframes".into()));
    };
    if list.is_empty() {
        return Err(fail("keyframes: empty: give at least one keyframe".into()));
    }
    let mut state = base.clone();
    let mut keyframes: Vec<Keyframe> = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        let at = |key: &str, message: String| fail(format!("keyframes[{i}].{key}: {message}"));
        let Value::Object(keys) = item else {
            return Err(fail(format!("keyframes[{i}]: expected an object")));
        };
        let t = match keys.get("t").map(Value::as_f64) {
            Some(Some(t)) if t.is_finite() && t >= 0.0 => t,
            Some(_) => return Err(at("t", "expected a time in seconds, ≥ 0".into())),
            None => {
                return Err(fail(format!(
                    "keyframes[{i}]: no \"t\" (its time in seconds)"
                )));
            }
        };
        if let Some(before) = keyframes.last()
            && t <= before.t
        {
            return Err(at(
                "t",
                format!(
                    "{t} is not after the keyframe before's {}: times must increase",
                    before.t
                ),
            ));
        }
        let ease = match keys.get("ease") {
            None => Ease::default(),
            Some(v) => v.as_str().and_then(Ease::from_name).ok_or_else(|| {
                at(
                    "ease",
                    format!("{v}: expected one of {}", Ease::NAMES.join(", ")),
                )
            })?,
        };
        for (key, value) in keys {
            if key == "t" || key == "ease" {
                continue;
            }
            apply(&mut state, key, value, dir).map_err(|message| at(key, message))?;
        }
        volray_options::settings(&state.options)
            .map_err(|e| fail(format!("keyframes[{i}]: {}", e.message(&Keys))))?;
        keyframes.push(Keyframe {
            t,
            ease,
            state: state.clone(),
        });
    }
    Ok(Keyframes {
        fps,
        time,
        keyframes,
    })
}

/// Sets the option `key` of `state` to `value`, or says what is wrong.
fn apply(state: &mut State, key: &str, value: &Value, dir: &Path) -> Result<(), String> {
    let cam = &mut state.options.camera;
    let look = &mut state.options.look;
    let null = value.is_null();
    match key {
        "azimuth" => cam.azimuth = number(value)?,
        "elevation" => cam.elevation = number(value)?,
        "zoom" => cam.zoom = positive(value)?,
        "view" => cam.view = if null { None } else { Some(vec3(value)?) },
        "look_at" => cam.look_at = if null { None } else { Some(vec3(value)?) },
        "up" => cam.up = vec3(value)?,
        "perspective" => {
            cam.perspective = match value {
                Value::Null | Value::Bool(false) => None,
                v => Some(positive(v)?),
            }
        }
        "clip" => cam.clip = clips(value)?,
        "crop" => {
            cam.crop = if null {
                None
            } else {
                let [x0, x1, y0, y1, z0, z1] = numbers::<6>(value)?;
                Some(([x0, y0, z0], [x1, y1, z1]))
            }
        }
        "preset" => look.preset = text_or_null(value)?,
        "colormap" => look.colormap = text_or_null(value)?,
        "tf" => look.tf = tf(value, dir)?,
        "range" => look.range = if null { None } else { Some(pair(value)?) },
        "opacity" => look.opacity = if null { None } else { Some(pair32(value)?) },
        "gradient_opacity" => {
            look.gradient_opacity = if null { None } else { Some(pair32(value)?) }
        }
        "iso" => {
            look.iso = if null {
                None
            } else {
                Some(number(value)? as f32)
            }
        }
        "iso_thickness" => {
            look.iso_thickness = if null {
                None
            } else {
                Some(positive(value)? as f32)
            }
        }
        "blend" => {
            let name = text(value)?;
            look.blend = BlendMode::from_name(&name).ok_or_else(|| {
                format!(
                    "\"{name}\": expected one of {}",
                    BlendMode::NAMES.join(", ")
                )
            })?
        }
        "ambient" => look.ambient = coefficients(value)?,
        "diffuse" => look.diffuse = coefficients(value)?,
        "specular" => look.specular = coefficients(value)?,
        "shininess" => look.shininess = positive(value)? as f32,
        "light" => look.light = if null { None } else { Some(vec3(value)?) },
        "light_color" => look.light_color = colour(value)?,
        "background" => look.background = colour(value)?,
        "shadows" => look.shadows = boolean(value)?,
        "shading" => look.shading = boolean(value)?,
        "ambient_occlusion" => {
            look.ambient_occlusion = match value {
                Value::Null | Value::Bool(false) => None,
                Value::Bool(true) => Some(8.0),
                v => Some(positive(v)?),
            }
        }
        "step" => state.options.sampling.step = positive(value)?,
        "frame" => {
            let f = number(value)?;
            if f < 0.0 {
                return Err(format!("{f}: a time point, counted from 0"));
            }
            state.frame = Some(f)
        }
        "title" => state.title = text_or_null(value)?,
        "label" => state.label = text_or_null(value)?,
        "size" => {
            return Err(
                "the frame size is one for the whole movie: give --size on the command line".into(),
            );
        }
        "channel_colors" => {
            return Err(
                "colours the channels of --channels, which --keyframes does not render yet".into(),
            );
        }
        _ => {
            return Err(format!(
                "unknown key (a keyframe takes t, ease and {})",
                KEYS.join(", ")
            ));
        }
    }
    Ok(())
}

fn number(v: &Value) -> Result<f64, String> {
    match v {
        Value::Number(n) => n
            .as_f64()
            .filter(|f| f.is_finite())
            .ok_or(format!("{v}: not finite")),
        Value::String(s) => s
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|f| f.is_finite())
            .ok_or(format!("{v}: expected a number")),
        _ => Err(format!("{v}: expected a number")),
    }
}

fn positive(v: &Value) -> Result<f64, String> {
    let f = number(v)?;
    if f > 0.0 {
        Ok(f)
    } else {
        Err(format!("{v}: expected a number > 0"))
    }
}

/// `N` numbers: a JSON array, or the flag's comma-separated text.
fn numbers<const N: usize>(v: &Value) -> Result<[f64; N], String> {
    let items: Vec<f64> = match v {
        Value::Array(items) => items.iter().map(number).collect::<Result<_, _>>()?,
        Value::String(s) => s
            .split(',')
            .map(|p| number(&Value::String(p.to_string())))
            .collect::<Result<_, _>>()?,
        _ => return Err(format!("{v}: expected {N} numbers, as [..] or \"a,b,..\"")),
    };
    items
        .try_into()
        .map_err(|_| format!("{v}: expected {N} numbers"))
}

fn vec3(v: &Value) -> Result<[f64; 3], String> {
    numbers::<3>(v)
}

fn pair(v: &Value) -> Result<(f64, f64), String> {
    let [a, b] = numbers::<2>(v)?;
    Ok((a, b))
}

fn pair32(v: &Value) -> Result<(f32, f32), String> {
    let (a, b) = pair(v)?;
    Ok((a as f32, b as f32))
}

/// A clip plane: a point and its normal.
type Plane = ([f64; 3], [f64; 3]);

/// One clip plane `[x, y, z, nx, ny, nz]`, or a list of them.
fn clips(v: &Value) -> Result<Vec<Plane>, String> {
    let one = |v: &Value| numbers::<6>(v).map(|[x, y, z, a, b, c]| ([x, y, z], [a, b, c]));
    match v {
        Value::Null => Ok(Vec::new()),
        Value::Array(items) if items.iter().all(Value::is_array) => items.iter().map(one).collect(),
        v => Ok(vec![one(v)?]),
    }
}

/// A coefficient for every channel, or one each.
fn coefficients(v: &Value) -> Result<[f32; 3], String> {
    let c = match v {
        Value::Number(_) => [number(v)?; 3],
        v => numbers::<3>(v)?,
    };
    if c.iter().any(|&k| k < 0.0) {
        return Err(format!("{v}: coefficients are ≥ 0"));
    }
    Ok(c.map(|k| k as f32))
}

/// A colour: `[r, g, b]` in [0, 1], `"#rrggbb"` or a name (as the
/// flags take them).
fn colour(v: &Value) -> Result<[f32; 3], String> {
    if let Value::String(s) = v
        && let Some(c) = volray_options::colors::named(s.trim())
    {
        return Ok(c);
    }
    if let Value::String(s) = v
        && let Some(hex) = s.strip_prefix('#')
        && hex.len() == 6
        && let Ok(n) = u32::from_str_radix(hex, 16)
    {
        return Ok([16, 8, 0].map(|shift| ((n >> shift) & 0xff) as f32 / 255.0));
    }
    let c = numbers::<3>(v)?;
    if c.iter().any(|k| !(0.0..=1.0).contains(k)) {
        return Err(format!("{v}: a colour's components are in [0, 1]"));
    }
    Ok(c.map(|k| k as f32))
}

fn boolean(v: &Value) -> Result<bool, String> {
    v.as_bool().ok_or(format!("{v}: expected true or false"))
}

fn text(v: &Value) -> Result<String, String> {
    v.as_str()
        .map(str::to_string)
        .ok_or(format!("{v}: expected a string"))
}

fn text_or_null(v: &Value) -> Result<Option<String>, String> {
    if v.is_null() {
        Ok(None)
    } else {
        text(v).map(Some)
    }
}

/// `tf`: `"auto"`, a transfer-function file (relative to `dir`), a
/// transfer function written in place (an object), or `null`.
fn tf(v: &Value, dir: &Path) -> Result<Option<Tf>, String> {
    match v {
        Value::Null => Ok(None),
        Value::String(s) if s == "auto" => Ok(Some(Tf::Auto)),
        Value::String(s) => {
            let path = dir.join(s);
            let text =
                crate::look::read_tf_file(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            Ok(Some(Tf::Json {
                source: path.display().to_string(),
                text,
            }))
        }
        Value::Object(_) => {
            let f = volray_core::TransferFunction::from_json(&v.to_string())
                .map_err(|e| format!("{e}"))?;
            Ok(Some(Tf::Function(f)))
        }
        _ => Err(format!(
            "{v}: expected \"auto\", a file's name or a transfer function"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<Keyframes, String> {
        parse("k.json", text, &State::default(), Path::new(".")).map_err(|e| e.to_string())
    }

    #[test]
    fn keys_read_into_the_options_the_flags_make_and_hold_until_changed() {
        let k = read_text(
            r##"{"version": 1, "fps": 10, "keyframes": [
                {"t": 0, "azimuth": 30, "range": [0, 100], "ease": "linear"},
                {"t": 2, "zoom": 2, "look_at": "1,2,3", "clip": [0,0,5, 0,0,-1],
                 "background": "#ff0000", "frame": 1.5, "blend": "mip"}]}"##,
        )
        .unwrap();
        assert_eq!(k.fps, Some(10.0));
        let [a, b] = &k.keyframes[..] else { panic!() };
        assert_eq!(a.ease, Ease::Linear);
        assert_eq!(b.ease, Ease::Smooth);
        assert_eq!(b.state.options.camera.azimuth, 30.0);
        assert_eq!(b.state.options.look.range, Some((0.0, 100.0)));
        assert_eq!(b.state.options.camera.look_at, Some([1.0, 2.0, 3.0]));
        assert_eq!(
            b.state.options.camera.clip,
            [([0.0, 0.0, 5.0], [0.0, 0.0, -1.0])]
        );
        assert_eq!(b.state.options.look.background, [1.0, 0.0, 0.0]);
        assert_eq!(b.state.frame, Some(1.5));
        assert_eq!(b.state.options.look.blend, BlendMode::Mip);
        assert_eq!(a.state.options.camera.zoom, 1.0);
    }

    #[test]
    fn bad_files_are_refused_naming_the_key() {
        let bad = |text: &str, says: &str| {
            let e = read_text(text).unwrap_err();
            assert!(e.starts_with("k.json: ") && e.contains(says), "{e}");
            assert!(!e.contains('\n'), "{e}");
        };
        bad(
            r#"{"keyframes": [{"t": 0, "zooom": 2}]}"#,
            "keyframes[0].zooom: unknown key",
        );
        bad(
            r#"{"keyframes": [{"t": 1}, {"t": 1, "zoom": 2}]}"#,
            "keyframes[1].t: 1 is not after",
        );
        bad(
            r#"{"keyframes": [{"t": 0, "zoom": "big"}]}"#,
            "keyframes[0].zoom: \"big\"",
        );
        bad(
            r#"{"keyframes": [{"t": 0, "view": [1, 2]}]}"#,
            "keyframes[0].view",
        );
        bad(r#"{"version": 2, "keyframes": [{"t": 0}]}"#, "version 2");
        bad(r#"{"keyframes": []}"#, "empty");
        bad(r#"{"keyframes": [{"zoom": 1}]}"#, "no \"t\"");
        bad(
            r#"{"keyframes": [{"t": 0, "ease": "fast"}]}"#,
            "keyframes[0].ease",
        );
        bad(r#"{"fps": 0, "keyframes": [{"t": 0}]}"#, "fps");
        // Checked as the flags are: a preset that does not exist.
        bad(
            r#"{"keyframes": [{"t": 0, "preset": "nope"}]}"#,
            "keyframes[0]: ",
        );
        bad(r#"[1, 2]"#, "expected an object");
    }
}
