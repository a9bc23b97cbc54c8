//! The options by name: [`Opt`] says which option an error is about, and
//! a front end's [`Naming`] says how its users write it (`--no-shading`
//! on the command line, `shading=False` in Python). Library messages are
//! put together from these, so that they name no front end's syntax.

/// One option a user gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Opt {
    // The camera.
    Size,
    View,
    LookAt,
    Up,
    Perspective,
    Zoom,
    Azimuth,
    Elevation,
    Clip,
    Crop,
    // Sampling.
    Step,
    NonFinite,
    // Classification.
    Opacity,
    Tf,
    Preset,
    Colormap,
    Labels,
    LabelOpacity,
    ShowLabels,
    Range,
    Log,
    Iso,
    IsoThickness,
    GradientOpacity,
    PostClassification,
    // Shading and compositing.
    Ambient,
    Diffuse,
    Specular,
    Shininess,
    Light,
    LightColor,
    /// Shadows from the light through the volume.
    Shadows,
    /// Ambient occlusion: the ambient light through the volume around.
    AmbientOcclusion,
    /// Shading turned off (the command line's `--no-shading`).
    NoShading,
    Background,
    Blend,
}

impl Opt {
    /// The option's name in lower case with `-` between words, as the
    /// command line spells it without its dashes (`look-at`); front ends
    /// derive their own spelling from it.
    pub fn name(self) -> &'static str {
        match self {
            Opt::Size => "size",
            Opt::View => "view",
            Opt::LookAt => "look-at",
            Opt::Up => "up",
            Opt::Perspective => "perspective",
            Opt::Zoom => "zoom",
            Opt::Azimuth => "azimuth",
            Opt::Elevation => "elevation",
            Opt::Clip => "clip",
            Opt::Crop => "crop",
            Opt::Step => "step",
            Opt::NonFinite => "nonfinite",
            Opt::Opacity => "opacity",
            Opt::Tf => "tf",
            Opt::Preset => "preset",
            Opt::Colormap => "colormap",
            Opt::Labels => "labels",
            Opt::LabelOpacity => "label-opacity",
            Opt::ShowLabels => "show-labels",
            Opt::Range => "range",
            Opt::Log => "log",
            Opt::Iso => "iso",
            Opt::IsoThickness => "iso-thickness",
            Opt::GradientOpacity => "gradient-opacity",
            Opt::PostClassification => "post-classification",
            Opt::Ambient => "ambient",
            Opt::Diffuse => "diffuse",
            Opt::Specular => "specular",
            Opt::Shininess => "shininess",
            Opt::Light => "light",
            Opt::LightColor => "light-color",
            Opt::Shadows => "shadows",
            Opt::AmbientOcclusion => "ambient-occlusion",
            Opt::NoShading => "no-shading",
            Opt::Background => "background",
            Opt::Blend => "blend",
        }
    }
}

/// How a front end writes options in its messages.
pub trait Naming {
    /// The option as its users give it: `--labels`, `labels=True`.
    fn option(&self, opt: Opt) -> String;
    /// The option given `value`: `--blend mip`, `blend='mip'`.
    fn with_value(&self, opt: Opt, value: &str) -> String;
}

/// The neutral naming of [`std::fmt::Display`]: the option's
/// [name](Opt::name), and `name value`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Plain;

impl Naming for Plain {
    fn option(&self, opt: Opt) -> String {
        opt.name().to_string()
    }

    fn with_value(&self, opt: Opt, value: &str) -> String {
        format!("{} {value}", opt.name())
    }
}
