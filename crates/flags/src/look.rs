//! How the volume looks: classification (the opacity ramp, a transfer
//! function from `--tf` or `--preset`, its colour map and value window,
//! `--log`, Levoy's `--iso` contour, `--gradient-opacity`,
//! `--post-classification`), shading (the Phong terms, the light,
//! `--no-shading`), and how a ray's samples make its pixel (`--blend`,
//! `--background`). `settings.rs` turns them into volray-core's settings.

use super::parse::{
    LabelList, LabelOpacities, parse_ao_radius, parse_background, parse_direction,
    parse_gradient_opacity, parse_iso_value, parse_label_list, parse_label_opacity, parse_opacity,
    parse_range, parse_rgb, parse_shininess, parse_thickness,
};
use clap::Args;
use std::path::{Path, PathBuf};

/// Classification, shading and compositing.
#[derive(Debug, Args)]
pub struct LookArgs {
    /// The paper's opacity ramp: α = p + t·(q − p) over the normalised value
    /// t, with 0 ≤ p < q ≤ 1 [default: 0,0.5]. Conflicts with an opacity in --tf.
    #[arg(long, value_name = "P,Q", value_parser = parse_opacity, allow_hyphen_values = true)]
    pub opacity: Option<(f32, f32)>,

    /// Transfer function JSON: {"domain": [lo, hi], "opacity": [[t, a], ...],
    /// "color": [[t, r, g, b], ...]}, all keys optional; or `auto`: chosen
    /// from the volume's histogram (the background peak transparent, a
    /// ramp above it, viridis over the range), which is also what
    /// compositing uses when no --tf, --preset, --colormap or --iso is
    /// given (a file named auto: ./auto).
    #[arg(long, value_name = "FILE.json|auto")]
    pub tf: Option<PathBuf>,

    /// A transfer-function preset: ct-bone and ct-soft-tissue (Hounsfield
    /// units), mr and electron-density (relative to the value range).
    /// Conflicts with --tf.
    #[arg(long, value_name = "ct-bone|ct-soft-tissue|mr|electron-density")]
    pub preset: Option<String>,

    /// A named colour map for the colour transfer function, replacing a
    /// preset's colours. Conflicts with a colour in --tf [default: chosen
    /// from the data (--tf auto) when nothing else is named, else white].
    #[arg(
        long,
        value_name = "viridis|magma|inferno|plasma|cividis|turbo|coolwarm|grey"
    )]
    pub colormap: Option<String>,

    /// Render a label volume (a segmentation: integer labels): each label in
    /// its own colour (a categorical table by label value, label 0
    /// transparent), classified by label so that two labels' values are
    /// never blended, and shaded by the gradient of each label's smoothed
    /// indicator rather than of the values. `volray info` suggests it for
    /// integer volumes with at most 256 distinct values.
    #[arg(long, conflicts_with_all = ["preset", "colormap", "opacity", "log", "iso", "post_classification"])]
    pub labels: bool,

    /// With --labels: the opacity of each label named, L:A,... (A per unit
    /// voxel distance, in [0, 1]) [default: 1 for every label but 0].
    #[arg(long, value_name = "L:A,...", value_parser = parse_label_opacity, allow_hyphen_values = true)]
    pub label_opacity: Option<LabelOpacities>,

    /// With --labels: show only these labels, L,... (0 too, if named).
    #[arg(long, value_name = "L,...", value_parser = parse_label_list, allow_hyphen_values = true)]
    pub show_labels: Option<LabelList>,

    /// The value window LO,HI that t = 0..1 spans (values outside are
    /// clamped) [default: the volume's min and max]. Conflicts with a
    /// domain in --tf and with the CT presets, whose window is fixed.
    #[arg(long, value_name = "LO,HI", value_parser = parse_range, allow_hyphen_values = true)]
    pub range: Option<(f64, f64)>,

    /// Ambient reflection k_a: one value or r,g,b.
    #[arg(long, value_name = "A|R,G,B", allow_hyphen_values = true, default_value = "0.1", value_parser = parse_rgb)]
    pub ambient: [f32; 3],

    /// Diffuse reflection k_d: one value or r,g,b.
    #[arg(long, value_name = "D|R,G,B", allow_hyphen_values = true, default_value = "0.7", value_parser = parse_rgb)]
    pub diffuse: [f32; 3],

    /// Specular reflection k_s: one value or r,g,b.
    #[arg(long, value_name = "S|R,G,B", allow_hyphen_values = true, default_value = "0.2", value_parser = parse_rgb)]
    pub specular: [f32; 3],

    /// Specular exponent n.
    #[arg(long, value_name = "N", default_value = "10", value_parser = parse_shininess, allow_hyphen_values = true)]
    pub shininess: f32,

    /// Direction towards the light at infinity [default: a headlight, L = V].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_direction, allow_hyphen_values = true)]
    pub light: Option<[f64; 3]>,

    /// Colour of the light, C_s.
    #[arg(long, value_name = "R,G,B", default_value = "1,1,1", value_parser = parse_rgb, allow_hyphen_values = true)]
    pub light_color: [f32; 3],

    /// Shadows: each point lit by the light that reaches it through the
    /// volume (ambient light stays). Without --light, the light is the
    /// camera's key light, 45° above and 30° left of the view.
    #[arg(long)]
    pub shadows: bool,

    /// Ambient occlusion: the ambient light (an unlit frame's whole colour)
    /// scaled by how much reaches each point along 26 short rays, RADIUS
    /// voxels long [default: 8]. Raise --ambient to see more of it.
    #[arg(long, value_name = "RADIUS", num_args = 0..=1, default_missing_value = "8", value_parser = parse_ao_radius)]
    pub ambient_occlusion: Option<f64>,

    /// No lighting: voxels take their material colour.
    #[arg(long)]
    pub no_shading: bool,

    /// The opaque background colour, components in [0, 1].
    #[arg(long, value_name = "R,G,B", default_value = "0,0,0", value_parser = parse_background, allow_hyphen_values = true)]
    pub background: [f32; 3],

    /// How the samples along a ray make the pixel: composite (the paper's
    /// transparency formula), mip (maximum intensity projection, also
    /// `maximum`), minip (minimum, also `minimum`), average (the mean), or
    /// iso (composite of the --iso contour, as --iso alone). The
    /// projections show the value through the colour map (grey without
    /// one: with --range 0,1 a mip pixel's grey is the ray's maximum),
    /// unshaded and opaque.
    #[arg(
        long,
        value_enum,
        value_name = "MODE",
        default_value = "composite",
        help_heading = "Rendering options"
    )]
    pub blend: BlendMode,

    /// Levoy's isovalue contour (1988, eq. 3): only a shell about the
    /// surface f = VALUE is opaque, with the opacity the transfer function
    /// gives VALUE on it, falling to 0 at --iso-thickness voxels either
    /// side, whatever the steepness of the data.
    #[arg(long, value_name = "VALUE", allow_hyphen_values = true, value_parser = parse_iso_value, help_heading = "Rendering options")]
    pub iso: Option<f32>,

    /// Half-width R of the --iso shell, in voxels of the smallest spacing
    /// [default: 1].
    #[arg(long, value_name = "R", allow_hyphen_values = true, value_parser = parse_thickness, help_heading = "Rendering options")]
    pub iso_thickness: Option<f32>,

    /// Render log10 of the data, for values that span decades (densities);
    /// values <= 0 take the log of the smallest positive value. --range,
    /// --iso and a --tf domain stay in the data's own units (they must
    /// then be positive) and are converted: `--log --range 1e-4,1` spans
    /// four decades.
    #[arg(long, help_heading = "Rendering options")]
    pub log: bool,

    /// Render the data's own values: --tf auto takes the log10 of values
    /// spanning decades (their median under 1 % of their 99.9 % point)
    /// unless this, --range or --log is given.
    #[arg(long, conflicts_with = "log", help_heading = "Rendering options")]
    pub linear: bool,

    /// Opacity times a ramp of the gradient magnitude |∇f|, 0 at LO and 1
    /// at HI, fractions of the volume's largest |∇f| (0 <= LO < HI <= 1):
    /// boundaries show and uniform insides fade.
    #[arg(long, value_name = "LO,HI", value_parser = parse_gradient_opacity, allow_hyphen_values = true, help_heading = "Rendering options")]
    pub gradient_opacity: Option<(f32, f32)>,

    /// Interpolate the scalar (and its gradient) at each sample, then
    /// classify and shade it, instead of the paper's classified voxel
    /// colours: sharper, slower.
    #[arg(long, help_heading = "Rendering options")]
    pub post_classification: bool,
}

/// `--tf auto`.
pub const AUTO: &str = "auto";

impl LookArgs {
    /// The `--tf` file, unless `--tf auto`.
    pub fn tf_file(&self) -> Option<&Path> {
        self.tf.as_deref().filter(|p| *p != Path::new(AUTO))
    }

    /// Whether the transfer function is chosen from the volume's histogram
    /// (volray-core's `transfer::auto`): `--tf auto`, or compositing with
    /// no `--tf`, `--preset`, `--colormap` or `--iso` (volray-options'
    /// `LookOptions::auto_tf` decides).
    pub fn auto_tf(&self) -> bool {
        crate::options::look(self).auto_tf()
    }
}

/// `--blend`: how a ray's samples make its pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BlendMode {
    /// The paper's compositing of classified, shaded samples.
    Composite,
    /// Maximum intensity projection.
    #[value(alias = "maximum")]
    Mip,
    /// Minimum intensity projection.
    #[value(alias = "minimum")]
    Minip,
    /// The mean value along the ray.
    Average,
    /// Composite of Levoy's isovalue contour (needs --iso).
    Iso,
}
