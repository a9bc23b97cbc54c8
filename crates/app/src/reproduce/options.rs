//! A page's state as volray-options' [`Options`], for a front end that
//! renders from options rather than from a command line (the Python
//! module's Jupyter widget): the frame the page shows is rendered from
//! the options [`state_options`] gives, and the same options, handed to
//! `volray.render`, render the same frame.
//!
//! The state's look becomes one whole transfer function ([`Tf::Function`]:
//! its window as the domain, the opacity points, the colours), so that
//! the camera and the transfer function read back from the page
//! reproduce the frame on their own. What the page does not set comes
//! from the options the viewer was started with, dropped where the state
//! makes it inapplicable (lighting, shadows and opacity options under a
//! projection or without shading), as volray-app's command words (`crates/app/src/reproduce/command.rs`)
//! drop the flags for `volray view`.

use super::state::{BlendMode, START_COLOURS, ViewState, WHITE, solid_colour};
use super::viewer::Refusal;
use volray_core::transfer::colormap;
use volray_core::{Phong, PiecewiseLinear, Projection, RenderSettings, TransferFunction};
use volray_options::{BlendMode as Blend, Options, Tf};

/// What a state is read against: the options the viewer started with and
/// the transfer function they gave, found from the volume where it was
/// left to it (`tf="auto"`), in the units rendered (log10 of the data's
/// under `log`).
#[derive(Debug, Clone)]
pub struct OptionsStart {
    pub options: Options,
    /// The starting transfer function, as rendered: its window (`None`:
    /// the volume's value range), opacity points (`None`: the opacity
    /// ramp) and colours (the page's [`START_COLOURS`]).
    pub transfer_function: TransferFunction,
}

/// The page's starting state of a viewer started with `options`, whose
/// starting frame `settings` renders.
pub fn start_state(options: &Options, settings: &RenderSettings) -> ViewState {
    let look = &options.look;
    let camera = &settings.camera;
    let colormap = match &look.colormap {
        Some(name) if name == "gray" => "grey".to_string(),
        Some(name) => name.clone(),
        None if settings.transfer_function.color.is_some() => START_COLOURS.to_string(),
        None => WHITE.to_string(),
    };
    ViewState {
        width: settings.width,
        height: settings.height,
        azimuth: camera.azimuth,
        elevation: camera.elevation,
        zoom: camera.zoom,
        look_at: camera.look_at.map(|p| p.to_array()),
        view_point: camera.view_point.map(|p| p.to_array()),
        perspective: match camera.projection {
            Projection::Perspective { fov_degrees } => Some(fov_degrees),
            Projection::Orthographic => None,
        },
        blend: match look.blend {
            Blend::Mip => BlendMode::Mip,
            Blend::Minip => BlendMode::Minip,
            Blend::Average => BlendMode::Average,
            Blend::Iso => BlendMode::Iso,
            Blend::Composite if settings.iso.is_some() => BlendMode::Iso,
            Blend::Composite => BlendMode::Composite,
        },
        iso: settings.iso.map(|iso| iso.value),
        step: settings.step,
        shading: settings.shading,
        background: settings.background,
        window: None,
        opacity: None,
        colormap,
        layers: Vec::new(),
        time: None,
        crop: options.camera.crop.map(|(lo, hi)| [lo, hi]),
        clip: (options.camera.clip.iter())
            .map(|&(point, normal)| [point, normal])
            .collect(),
        lighting: None,
        shadows: look.shadows,
        ambient_occlusion: look.ambient_occlusion,
        figure: super::state::Figure::default(),
    }
}

/// The options of the frame of `state` (checked), the viewer having
/// started as `start` says: the camera and sampling the state sets, and
/// one whole transfer function ([`Tf::Function`], no preset, colour map
/// or range beside it). The state's figure is not among the options: the
/// front end names it as its own annotations (`volray.render`'s
/// `colorbar=`, `title=`, ...).
pub fn state_options(state: &ViewState, start: &OptionsStart) -> Result<Options, Refusal> {
    if !state.layers.is_empty() {
        return Err(Refusal("this viewer shows one volume".into()));
    }
    if state.time.is_some() {
        return Err(Refusal("this viewer serves no time axis".into()));
    }
    let mut options = start.options.clone();
    let log = options.look.log;
    let data_units = |v: f64, what: &str| -> Result<f64, Refusal> {
        if !log {
            return Ok(v);
        }
        let data = 10f64.powf(v);
        match data.is_finite() && data > 0.0 {
            true => Ok(data),
            false => Err(Refusal(format!(
                "{what} 10^{v} is beyond the data's units under log"
            ))),
        }
    };

    let camera = &mut options.camera;
    camera.size = (state.width, state.height);
    camera.view = state.view_point;
    camera.look_at = state.look_at;
    camera.perspective = state.perspective;
    camera.zoom = state.zoom;
    camera.azimuth = state.azimuth;
    camera.elevation = state.elevation;
    camera.clip = state.clip.iter().map(|&[p, n]| (p, n)).collect();
    camera.crop = state.crop.map(|[lo, hi]| (lo, hi));
    options.sampling.step = state.step;

    let look = &mut options.look;
    let projection = state.blend.is_projection();
    look.blend = match state.blend {
        BlendMode::Composite => Blend::Composite,
        BlendMode::Mip => Blend::Mip,
        BlendMode::Minip => Blend::Minip,
        BlendMode::Average => Blend::Average,
        BlendMode::Iso => Blend::Iso,
    };
    if state.blend == BlendMode::Iso {
        let iso = f64::from(state.iso.unwrap_or_default());
        look.iso = Some(data_units(iso, "the isovalue")? as f32);
    } else {
        look.iso = None;
        look.iso_thickness = None;
    }
    let lit = Phong::default();
    let unlit = |look: &mut volray_options::LookOptions| {
        look.ambient = lit.ambient;
        look.diffuse = lit.diffuse;
        look.specular = lit.specular;
        look.shininess = lit.shininess;
        look.light = None;
        look.light_color = lit.light_color;
        look.shadows = false;
    };
    let start_tf = &start.transfer_function;
    let opacity = match &state.opacity {
        _ if projection => None,
        Some(points) => Some(points.iter().map(|&[t, a]| (t, [a])).collect()),
        None => start_tf.opacity.as_ref().map(|f| f.points().to_vec()),
    };
    if projection {
        // As `render` takes a projection: no opacity, no lighting.
        look.opacity = None;
        look.gradient_opacity = None;
        look.post_classification = false;
        look.shading = true;
        look.ambient_occlusion = None;
        unlit(look);
    } else {
        look.shadows = state.shadows;
        look.ambient_occlusion = state.ambient_occlusion;
        if opacity.is_some() {
            look.opacity = None;
        }
        look.shading = state.shading;
        match (state.shading, &state.lighting) {
            (true, Some(l)) => {
                look.ambient = [l.ambient; 3];
                look.diffuse = [l.diffuse; 3];
                look.specular = [l.specular; 3];
                look.shininess = l.shininess;
                look.light = l.light;
            }
            (true, None) => {}
            (false, _) => unlit(look),
        }
    }
    let colours = match state.colormap.as_str() {
        START_COLOURS => match &start_tf.color {
            Some(c) => Some(c.points().to_vec()),
            None => {
                return Err(Refusal(
                    "the starting transfer function has no colours: pick a colour map".into(),
                ));
            }
        },
        WHITE => None,
        name => match solid_colour(name) {
            Some(c) => Some(vec![(0.0, c), (1.0, c)]),
            None => match colormap::colormap(name) {
                Some(map) => Some(map.points().to_vec()),
                None => return Err(Refusal(format!("no colour map is called '{name}'"))),
            },
        },
    };
    let domain = match state.window {
        Some([lo, hi]) => Some((data_units(lo, "the window")?, data_units(hi, "the window")?)),
        None => start_tf
            .domain
            .map(|(lo, hi)| {
                Ok::<_, Refusal>((data_units(lo, "the window")?, data_units(hi, "the window")?))
            })
            .transpose()?,
    };
    let refused =
        |e: volray_core::transfer::function::TransferFunctionError| Refusal(e.to_string());
    look.tf = Some(Tf::Function(TransferFunction {
        domain,
        opacity: opacity
            .map(|points| PiecewiseLinear::new("opacity", points))
            .transpose()
            .map_err(refused)?,
        color: colours
            .map(|points| PiecewiseLinear::new("color", points))
            .transpose()
            .map_err(refused)?,
    }));
    look.preset = None;
    look.colormap = None;
    look.range = None;
    options.look.background = state.background;
    Ok(options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproduce::state::Lighting;

    fn start(options: Options) -> (OptionsStart, ViewState) {
        let mut settings = volray_options::settings(&options).unwrap();
        settings.transfer_function.color = colormap::colormap("viridis");
        let state = start_state(&options, &settings);
        let start = OptionsStart {
            options,
            transfer_function: settings.transfer_function,
        };
        (start, state)
    }

    #[test]
    fn the_starting_state_gives_the_starting_frame_with_the_whole_transfer_function() {
        let mut options = Options::default();
        options.camera.size = (200, 100);
        options.camera.azimuth = 30.0;
        options.look.opacity = Some((0.2, 0.8));
        let (start, state) = start(options.clone());
        assert_eq!(state.colormap, START_COLOURS);
        let got = state_options(&state, &start).unwrap();
        assert_eq!(got.camera, options.camera);
        assert_eq!(got.look.opacity, Some((0.2, 0.8)), "the ramp is kept");
        let Some(Tf::Function(tf)) = &got.look.tf else {
            panic!("{:?}", got.look.tf)
        };
        assert_eq!(tf.color, colormap::colormap("viridis"));
        assert_eq!(tf.opacity, None);
        let settings = volray_options::settings(&got).unwrap();
        let mut want = volray_options::settings(&options).unwrap();
        want.transfer_function.color = colormap::colormap("viridis");
        assert_eq!(settings, want);
    }

    #[test]
    fn the_pages_controls_set_the_options() {
        let (start, mut state) = start(Options::default());
        state.azimuth = 45.0;
        state.zoom = 2.0;
        state.window = Some([0.25, 0.75]);
        state.opacity = Some(vec![[0.0, 0.0], [1.0, 0.5]]);
        state.colormap = "magma".into();
        state.step = 0.5;
        state.background = [0.1, 0.2, 0.3];
        state.lighting = Some(Lighting {
            ambient: 0.3,
            diffuse: 0.5,
            specular: 0.1,
            shininess: 20.0,
            light: Some([1.0, 0.0, 0.0]),
        });
        let got = state_options(&state, &start).unwrap();
        assert_eq!((got.camera.azimuth, got.camera.zoom), (45.0, 2.0));
        assert_eq!(got.sampling.step, 0.5);
        assert_eq!(got.look.background, [0.1, 0.2, 0.3]);
        assert_eq!((got.look.ambient, got.look.shininess), ([0.3; 3], 20.0));
        let Some(Tf::Function(tf)) = &got.look.tf else {
            panic!()
        };
        assert_eq!(tf.domain, Some((0.25, 0.75)));
        assert_eq!(tf.color, colormap::colormap("magma"));
        assert_eq!(
            tf.opacity.as_ref().unwrap().points(),
            &[(0.0, [0.0]), (1.0, [0.5])]
        );
        volray_options::settings(&got).unwrap();

        // A projection drops the opacity, the lighting and the shadows.
        state.shading = true;
        state.shadows = true;
        assert!(state_options(&state, &start).unwrap().look.shadows);
        state.blend = BlendMode::Mip;
        let got = state_options(&state, &start).unwrap();
        let Some(Tf::Function(tf)) = &got.look.tf else {
            panic!()
        };
        assert_eq!(tf.opacity, None);
        assert_eq!(got.look.ambient, Phong::default().ambient);
        assert!(!got.look.shadows);
        volray_options::settings(&got).unwrap();
        // And the ambient occlusion, which an unlit composite keeps (but
        // not its shadows).
        state.ambient_occlusion = Some(4.0);
        let got = state_options(&state, &start).unwrap();
        assert_eq!(got.look.ambient_occlusion, None);
        state.blend = BlendMode::Composite;
        state.shading = false;
        let got = state_options(&state, &start).unwrap();
        assert!(!got.look.shadows);
        assert_eq!(got.look.ambient_occlusion, Some(4.0));
        volray_options::settings(&got).unwrap();
    }

    #[test]
    fn what_the_viewer_cannot_show_is_refused_in_words() {
        let (start, state) = start(Options::default());
        let mut time = state.clone();
        time.time = Some(1);
        assert!(state_options(&time, &start).is_err());
        let mut map = state.clone();
        map.colormap = "nope".into();
        let e = state_options(&map, &start).unwrap_err();
        assert!(e.0.contains("nope"), "{e}");
        let mut log = start.clone();
        log.options.look.log = true;
        let mut far = state;
        far.window = Some([0.0, 400.0]);
        assert!(state_options(&far, &log).is_err());
    }
}
