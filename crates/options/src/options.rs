//! The options themselves, plain data with the command line's defaults:
//! the camera ([`CameraOptions`]), how the volume looks
//! ([`LookOptions`]) and how the rays sample it ([`SamplingOptions`]).
//! Each field is one option of `volray render` (its flag in brackets).

use volray_core::{NonFinite, Phong, RenderSettings, TransferFunction};

/// Every option of a frame but the volume.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Options {
    pub camera: CameraOptions,
    pub look: LookOptions,
    pub sampling: SamplingOptions,
}

/// Where the eye stands and what it sees.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraOptions {
    /// Image width and height in pixels (`--size`).
    pub size: (usize, usize),
    /// The eye (`--view`); default: framed from the volume's bounds.
    pub view: Option<[f64; 3]>,
    /// The point looked at (`--look-at`); default: the volume's centre.
    pub look_at: Option<[f64; 3]>,
    /// Up on the screen (`--up`).
    pub up: [f64; 3],
    /// A perspective projection of this vertical field of view in degrees
    /// (`--perspective`); default: orthographic.
    pub perspective: Option<f64>,
    /// Magnification of the framed view (`--zoom`).
    pub zoom: f64,
    /// Orbit about the look-at point around `up`, in degrees (`--azimuth`).
    pub azimuth: f64,
    /// Orbit towards `up`, in degrees (`--elevation`).
    pub elevation: f64,
    /// Clip planes: a point and the normal pointing at the half kept
    /// (`--clip`).
    pub clip: Vec<([f64; 3], [f64; 3])>,
    /// The world box kept, low and high corners (`--crop`).
    pub crop: Option<([f64; 3], [f64; 3])>,
}

impl Default for CameraOptions {
    fn default() -> Self {
        let settings = RenderSettings::default();
        let camera = settings.camera;
        CameraOptions {
            size: (settings.width, settings.height),
            view: None,
            look_at: None,
            up: camera.up.to_array(),
            perspective: None,
            zoom: camera.zoom,
            azimuth: camera.azimuth,
            elevation: camera.elevation,
            clip: Vec::new(),
            crop: None,
        }
    }
}

/// How a ray's samples become a pixel (`--blend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BlendMode {
    /// Front-to-back compositing of classified, shaded samples.
    #[default]
    Composite,
    /// Maximum intensity projection.
    Mip,
    /// Minimum intensity projection.
    Minip,
    /// The mean of the samples.
    Average,
    /// Compositing of Levoy's isovalue contour (needs [`LookOptions::iso`]).
    Iso,
}

impl BlendMode {
    /// The mode's name: `composite`, `mip`, `minip`, `average`, `iso`.
    pub fn name(self) -> &'static str {
        match self {
            BlendMode::Composite => "composite",
            BlendMode::Mip => "mip",
            BlendMode::Minip => "minip",
            BlendMode::Average => "average",
            BlendMode::Iso => "iso",
        }
    }

    /// The mode called `name` (`maximum` and `minimum` too), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "composite" => BlendMode::Composite,
            "mip" | "maximum" => BlendMode::Mip,
            "minip" | "minimum" => BlendMode::Minip,
            "average" => BlendMode::Average,
            "iso" => BlendMode::Iso,
            _ => return None,
        })
    }

    /// The names [`from_name`](Self::from_name) knows, aliases aside.
    pub const NAMES: [&'static str; 5] = ["composite", "mip", "minip", "average", "iso"];
}

/// Where the transfer function comes from (`--tf`).
#[derive(Debug, Clone, PartialEq)]
pub enum Tf {
    /// Chosen from the volume's histogram (`--tf auto`; see
    /// [`LookOptions::auto_tf`] for when it is also the default).
    Auto,
    /// The JSON text of a transfer function, read from `source` (a path,
    /// for messages).
    Json { source: String, text: String },
    /// A transfer function given whole.
    Function(TransferFunction),
}

/// How the volume looks: classification, shading and compositing.
#[derive(Debug, Clone, PartialEq)]
pub struct LookOptions {
    /// The paper's linear opacity ramp over the value range, from P to Q
    /// (`--opacity`).
    pub opacity: Option<(f32, f32)>,
    /// The transfer function (`--tf`).
    pub tf: Option<Tf>,
    /// A named transfer function (`--preset`).
    pub preset: Option<String>,
    /// A named colour map (`--colormap`).
    pub colormap: Option<String>,
    /// The volume holds labels, each shown in its own colour (`--labels`).
    pub labels: bool,
    /// Per-label opacities (`--label-opacity`).
    pub label_opacity: Option<Vec<(i64, f32)>>,
    /// Only these labels shown (`--show-labels`).
    pub show_labels: Option<Vec<i64>>,
    /// The colours the file gives its labels (a DICOM Segmentation's
    /// segments), `(label, sRGB 0..1)`: used by `labels` in place of the
    /// palette's.
    pub label_colours: Vec<(i64, [f32; 3])>,
    /// The value window the transfer function spans, in the data's units
    /// (`--range`).
    pub range: Option<(f64, f64)>,
    /// Phong's ambient, diffuse and specular coefficients per channel
    /// (`--ambient`, `--diffuse`, `--specular`).
    pub ambient: [f32; 3],
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
    /// Phong's exponent (`--shininess`).
    pub shininess: f32,
    /// The direction towards the light (`--light`); default: the eye's.
    pub light: Option<[f64; 3]>,
    /// The light's colour (`--light-color`).
    pub light_color: [f32; 3],
    /// Shadows: the light reaching each point through the volume
    /// (`--shadows`); without `light`, the camera's key light.
    pub shadows: bool,
    /// Ambient occlusion of this radius in voxels
    /// (`--ambient-occlusion [RADIUS]`); `None`: off.
    pub ambient_occlusion: Option<f64>,
    /// Shading on (off: `--no-shading`).
    pub shading: bool,
    /// The colour behind the volume (`--background`).
    pub background: [f32; 3],
    /// How samples become a pixel (`--blend`).
    pub blend: BlendMode,
    /// Levoy's isovalue contour (`--iso`) and its half-width in values'
    /// gradient units (`--iso-thickness`).
    pub iso: Option<f32>,
    pub iso_thickness: Option<f32>,
    /// Render the log10 of the data (`--log`): windows and isovalues stay
    /// in the data's units.
    pub log: bool,
    /// The data's own values, never the log10 that `--tf auto` takes of
    /// values spanning decades ([`crate::chooses_log`]): `--linear`,
    /// Python's `log=False`.
    pub linear: bool,
    /// Opacity scaled by gradient magnitude between these fractions of its
    /// largest (`--gradient-opacity`).
    pub gradient_opacity: Option<(f32, f32)>,
    /// Classify after interpolation (`--post-classification`).
    pub post_classification: bool,
}

impl Default for LookOptions {
    fn default() -> Self {
        let lit = Phong::default();
        LookOptions {
            opacity: None,
            tf: None,
            preset: None,
            colormap: None,
            labels: false,
            label_opacity: None,
            show_labels: None,
            label_colours: Vec::new(),
            range: None,
            ambient: lit.ambient,
            diffuse: lit.diffuse,
            specular: lit.specular,
            shininess: lit.shininess,
            light: None,
            light_color: lit.light_color,
            shadows: false,
            ambient_occlusion: None,
            shading: true,
            background: RenderSettings::default().background,
            blend: BlendMode::Composite,
            iso: None,
            iso_thickness: None,
            log: false,
            linear: false,
            gradient_opacity: None,
            post_classification: false,
        }
    }
}

impl LookOptions {
    /// Whether a transfer function is given (a file or a function), which
    /// fixes what the other classification options would set.
    pub fn tf_given(&self) -> bool {
        matches!(self.tf, Some(Tf::Json { .. } | Tf::Function(_)))
    }

    /// Whether the transfer function is chosen from the volume's
    /// histogram: asked for ([`Tf::Auto`]), or by default when
    /// compositing with none of a transfer function, a preset, a colour
    /// map, labels or an isovalue. `opacity` alone (the paper's ramp)
    /// keeps the choice of colours.
    pub fn auto_tf(&self) -> bool {
        matches!(self.tf, Some(Tf::Auto))
            || (self.tf.is_none()
                && !self.labels
                && self.preset.is_none()
                && self.colormap.is_none()
                && self.iso.is_none()
                && self.blend == BlendMode::Composite)
    }
}

/// How the rays sample the volume.
#[derive(Debug, Clone, PartialEq)]
pub struct SamplingOptions {
    /// Distance between samples in voxels (`--step`).
    pub step: f64,
    /// The paper's reference path (`--reference`), the oracle.
    pub reference: bool,
    /// Each ray's samples offset by a random fraction of a step
    /// (`--jitter`).
    pub jitter: bool,
    /// What NaN and infinite values are (`--nonfinite`).
    pub nonfinite: NonFinite,
}

impl Default for SamplingOptions {
    fn default() -> Self {
        let settings = RenderSettings::default();
        SamplingOptions {
            step: settings.step,
            reference: false,
            jitter: settings.jitter,
            nonfinite: NonFinite::Refuse,
        }
    }
}
