//! A view's options as the Python module's keywords: the keywords of
//! `volray.render` that render the frame a notebook's viewer shows, and
//! the call itself as Python code (`volray.render(volume, camera=...,
//! tf=...)`), each number written so that Python reads it back to the
//! same value. The options are the page's state as volray-view's
//! `state_options` reads it (the camera, one whole transfer function).

use super::state::Figure;
use std::fmt::Write;
use volray_core::{NonFinite, Phong, RenderSettings};
use volray_options::{BlendMode, CameraOptions, Options, Tf};

/// The keywords beside the options': a chunked file's `level` (`Some(None)`
/// for `"auto"`; `None` for a volume in memory), and the annotations
/// that draw `figure` as the page does, the colour bar's values in
/// `value_unit`.
pub fn figure_keywords(
    level: Option<Option<usize>>,
    value_unit: Option<&str>,
    figure: &Figure,
) -> Vec<(&'static str, Value)> {
    let mut w = Vec::new();
    match level {
        Some(Some(n)) => w.push(("level", Value::Int(n))),
        Some(None) => w.push(("level", Value::Str("auto".into()))),
        None => {}
    }
    if let Some(side) = figure.colorbar {
        w.push(("colorbar", Value::Str(side.name().into())));
        if let Some(unit) = value_unit {
            w.push(("units", Value::Str(unit.to_string())));
        }
    }
    if figure.scale_bar {
        w.push((
            "scale_bar",
            figure.scale_length.map_or(Value::Bool(true), Value::Number),
        ));
    }
    if let Some(title) = &figure.title {
        w.push(("title", Value::Str(title.clone())));
    }
    if let Some(label) = &figure.label {
        w.push(("label", Value::Str(label.clone())));
    }
    if figure.axes {
        w.push(("axes", Value::Bool(true)));
    }
    if figure.outline {
        w.push(("outline", Value::Bool(true)));
    }
    w
}

/// A keyword's value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Camera(CameraOptions),
    Tf(volray_core::TransferFunction),
    Str(String),
    Int(usize),
    Number(f64),
    Bool(bool),
    Numbers(Vec<f64>),
}

/// The volume's keywords beside the options': `scale` where the axes are
/// stretched as given (`scale=`, the command line's `--scale`; the
/// default stretch needs no keyword, `render` applies it again).
pub fn volume_keywords(scale: Option<[f64; 3]>) -> Vec<(&'static str, Value)> {
    scale
        .map(|s| ("scale", Value::Numbers(s.to_vec())))
        .into_iter()
        .collect()
}

/// The keywords of `render` that give `options` (a state's: the look's
/// transfer function whole), the defaults left out.
pub fn keywords(options: &Options) -> Vec<(&'static str, Value)> {
    let look = &options.look;
    let sampling = &options.sampling;
    let lit = Phong::default();
    let rgb = |c: [f32; 3]| match c {
        [r, g, b] if r == g && g == b => Value::Number(f64::from(r)),
        c => Value::Numbers(c.iter().map(|&x| f64::from(x)).collect()),
    };
    let mut w = vec![("camera", Value::Camera(options.camera.clone()))];
    if let Some(Tf::Function(f)) = &look.tf {
        w.push(("tf", Value::Tf(f.clone())));
    }
    if let Some((p, q)) = look.opacity {
        w.push(("opacity", Value::Numbers(vec![f64::from(p), f64::from(q)])));
    }
    if look.blend != BlendMode::Composite {
        w.push(("blend", Value::Str(look.blend.name().into())));
    }
    if let Some(iso) = look.iso {
        w.push(("iso", Value::Number(f64::from(iso))));
    }
    if let Some(r) = look.iso_thickness {
        w.push(("iso_thickness", Value::Number(f64::from(r))));
    }
    if let Some((lo, hi)) = look.gradient_opacity {
        w.push((
            "gradient_opacity",
            Value::Numbers(vec![f64::from(lo), f64::from(hi)]),
        ));
    }
    if look.post_classification {
        w.push(("post_classification", Value::Bool(true)));
    }
    if !look.shading {
        w.push(("shading", Value::Bool(false)));
    }
    for (key, value, default) in [
        ("ambient", look.ambient, lit.ambient),
        ("diffuse", look.diffuse, lit.diffuse),
        ("specular", look.specular, lit.specular),
        ("light_color", look.light_color, lit.light_color),
    ] {
        if value != default {
            w.push((key, rgb(value)));
        }
    }
    if look.shininess != lit.shininess {
        w.push(("shininess", Value::Number(f64::from(look.shininess))));
    }
    if look.shadows {
        w.push(("shadows", Value::Bool(true)));
    }
    if let Some(radius) = look.ambient_occlusion {
        w.push(("ambient_occlusion", Value::Number(radius)));
    }
    if let Some(light) = look.light {
        w.push(("light", Value::Numbers(light.to_vec())));
    }
    if look.background != RenderSettings::default().background {
        w.push(("background", rgb(look.background)));
    }
    if sampling.step != 1.0 {
        w.push(("step", Value::Number(sampling.step)));
    }
    if sampling.jitter {
        w.push(("jitter", Value::Bool(true)));
    }
    if sampling.reference {
        w.push(("reference", Value::Bool(true)));
    }
    if look.log {
        w.push(("log", Value::Bool(true)));
    }
    // A label volume's colours (and the labels shown) are its whole
    // transfer function's, its label table.
    if look.labels {
        w.push(("labels", Value::Bool(true)));
    }
    if sampling.nonfinite == NonFinite::Transparent {
        w.push(("nonfinite", Value::Str("transparent".into())));
    }
    w
}

/// `volray.render(volume, ...)` with `options` and the `figure`'s
/// keywords.
pub fn call(options: &Options, figure: &[(&'static str, Value)]) -> String {
    let mut s = "volray.render(volume".to_string();
    for (key, value) in keywords(options).iter().chain(figure) {
        let _ = write!(s, ", {key}={}", code(value));
    }
    s.push(')');
    s
}

/// A value as Python code.
pub fn code(value: &Value) -> String {
    let tuple = |v: &[f64]| {
        let inner: Vec<String> = v.iter().map(|x| num(*x)).collect();
        format!("({})", inner.join(", "))
    };
    match value {
        // A JSON string is a Python string literal: quotes, backslashes
        // and control characters escaped.
        Value::Str(s) => serde_json::to_string(s).expect("a str serialises"),
        Value::Number(x) => num(*x),
        Value::Int(n) => n.to_string(),
        Value::Bool(b) => if *b { "True" } else { "False" }.to_string(),
        Value::Numbers(v) => tuple(v),
        Value::Camera(c) => {
            let defaults = CameraOptions::default();
            let mut parts = vec![format!("size=({}, {})", c.size.0, c.size.1)];
            let mut v3 = |key: &str, v: Option<[f64; 3]>| {
                if let Some(v) = v {
                    parts.push(format!("{key}={}", tuple(&v)));
                }
            };
            v3("view", c.view);
            v3("look_at", c.look_at);
            v3("up", (c.up != defaults.up).then_some(c.up));
            if let Some(f) = c.perspective {
                parts.push(format!("perspective={}", num(f)));
            }
            parts.push(format!("azimuth={}", num(c.azimuth)));
            parts.push(format!("elevation={}", num(c.elevation)));
            parts.push(format!("zoom={}", num(c.zoom)));
            if !c.clip.is_empty() {
                let planes: Vec<String> = (c.clip.iter())
                    .map(|(p, n)| format!("({}, {})", tuple(p), tuple(n)))
                    .collect();
                parts.push(format!("clip=[{}]", planes.join(", ")));
            }
            if let Some((lo, hi)) = c.crop {
                parts.push(format!(
                    "crop={}",
                    tuple(&[lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]])
                ));
            }
            format!("volray.Camera({})", parts.join(", "))
        }
        Value::Tf(f) => {
            // Colours of a named map are written as its name.
            let named = (f.color.as_ref()).and_then(|c| {
                (volray_core::transfer::colormap::NAMES.iter()).find(|name| {
                    volray_core::transfer::colormap::colormap(name).as_ref() == Some(c)
                })
            });
            let mut parts = Vec::new();
            if let Some(o) = &f.opacity {
                let points: Vec<String> = (o.points().iter())
                    .map(|(t, [a])| format!("({}, {})", num32(*t), num32(*a)))
                    .collect();
                parts.push(format!("opacity=[{}]", points.join(", ")));
            }
            if let (Some(c), None) = (&f.color, named) {
                let points: Vec<String> = (c.points().iter())
                    .map(|(t, [r, g, b])| {
                        format!(
                            "({}, {}, {}, {})",
                            num32(*t),
                            num32(*r),
                            num32(*g),
                            num32(*b)
                        )
                    })
                    .collect();
                parts.push(format!("color=[{}]", points.join(", ")));
            }
            if let Some((lo, hi)) = f.domain {
                parts.push(format!("domain=({}, {})", num(lo), num(hi)));
            }
            let tf = format!("volray.TransferFunction({})", parts.join(", "));
            match named {
                Some(name) => format!("{tf}.with_colormap(\"{name}\")"),
                None => tf,
            }
        }
    }
}

/// A number as Python reads it back to the same `f64`.
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// A number as Python reads it back to the same `f32` (Python's float is
/// an `f64`; the shortest `f32` text rounds back to it).
fn num32(x: f32) -> String {
    format!("{x:?}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::PiecewiseLinear;

    #[test]
    fn the_call_names_only_what_differs_from_the_defaults() {
        let mut options = Options::default();
        options.camera.azimuth = 30.0;
        options.look.shading = false;
        options.look.background = [0.5; 3];
        options.look.ambient = [0.1, 0.2, 0.3];
        options.look.tf = Some(Tf::Function(volray_core::TransferFunction {
            domain: Some((0.0, 0.1)),
            opacity: Some(
                PiecewiseLinear::new("opacity", vec![(0.0, [0.0]), (1.0, [0.5])]).unwrap(),
            ),
            color: volray_core::transfer::colormap::colormap("viridis"),
        }));
        assert_eq!(
            call(&options, &[]),
            "volray.render(volume, camera=volray.Camera(size=(480, 480), azimuth=30.0, \
             elevation=0.0, zoom=1.0), tf=volray.TransferFunction(opacity=[(0.0, 0.0), \
             (1.0, 0.5)], domain=(0.0, 0.1)).with_colormap(\"viridis\"), shading=False, \
             ambient=(0.10000000149011612, 0.20000000298023224, 0.30000001192092896), \
             background=0.5)"
        );
    }

    #[test]
    fn the_figure_is_spelled_as_its_annotation_keywords() {
        let figure = Figure {
            colorbar: Some(crate::reproduce::state::ColorBarSide::Left),
            scale_bar: true,
            scale_length: Some(2.5),
            title: Some("a \"b\"".into()),
            ..Figure::default()
        };
        let w = figure_keywords(Some(None), Some("HU"), &figure);
        let code: Vec<String> = w.iter().map(|(k, v)| format!("{k}={}", code(v))).collect();
        assert_eq!(
            code,
            [
                "level=\"auto\"",
                "colorbar=\"left\"",
                "units=\"HU\"",
                "scale_bar=2.5",
                "title=\"a \\\"b\\\"\""
            ]
        );
        assert!(figure_keywords(None, Some("HU"), &Figure::default()).is_empty());
    }

    #[test]
    fn a_scale_given_is_spelled_as_its_keyword() {
        let w = volume_keywords(Some([1.0, 1.0, 0.5]));
        let code: Vec<String> = w.iter().map(|(k, v)| format!("{k}={}", code(v))).collect();
        assert_eq!(code, ["scale=(1.0, 1.0, 0.5)"]);
        assert!(volume_keywords(None).is_empty());
    }

    #[test]
    fn numbers_are_written_as_python_reads_them_back() {
        for x in [0.1 + 0.2, 1e-300, -2.5, 1e21] {
            assert_eq!(num(x).parse::<f64>().unwrap(), x);
        }
        assert_eq!(num(1.0), "1.0");
        let x = 0.1f32;
        assert_eq!(num32(x).parse::<f32>().unwrap(), x);
    }
}
