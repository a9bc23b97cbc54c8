//! Why options were refused: which option (or pair), and the value, as
//! fields; [`OptionError::message`] words it in a front end's
//! [`Naming`], and `Display` in the neutral [`Plain`] one.

use crate::option::{Naming, Opt, Plain};
use std::fmt;
use volray_core::RenderError;

/// Options that cannot be rendered together, or one out of its range.
#[derive(Debug, Clone, PartialEq)]
pub enum OptionError {
    /// A label-volume option without [`Opt::Labels`].
    LabelsOnly(Opt),
    /// The transfer function's JSON (from `source`, a path) is not one.
    TfJson { source: String, error: String },
    /// Two options that each fix the same thing.
    Conflict(Opt, Opt),
    /// The opacity ramp beside the opacity function of `from` (the
    /// transfer function or the preset).
    OpacityConflict { from: Opt },
    /// A colour map beside the colour function of the transfer function.
    ColormapConflict,
    /// A value window beside the one fixed by `from`.
    RangeConflict { from: Opt },
    /// The automatic transfer function asked for a label volume.
    AutoWithLabels,
    /// Label opacities or a shown subset beside a transfer function that
    /// replaces the labels' colours.
    LabelStyleWithTf,
    /// A value window for a label volume, whose window spans its labels.
    RangeWithLabels,
    /// A preset or colour map (`opt`) by a name not known.
    Unknown {
        opt: Opt,
        what: &'static str,
        name: String,
        expected: &'static [&'static str],
    },
    /// With the log of the data, a window (`from`) reaching zero or below.
    LogWindow { from: Opt, lo: f64 },
    /// The isosurface blend without an isovalue.
    IsoNeedsValue,
    /// An option shaping opacity with a projection (`blend` names it).
    NoOpacityInProjection { opt: Opt, blend: &'static str },
    /// A lighting option where nothing is lit: a projection (`Some` of
    /// its name) or shading turned off (`None`).
    Unlit {
        opt: Opt,
        projection: Option<&'static str>,
    },
    /// The isosurface's thickness without its value.
    IsoThicknessAlone,
    /// With the log of the data, an isovalue at zero or below.
    IsoLog { value: f32 },
    /// The volume `volume` is not a label volume, or its labels cannot be
    /// styled as asked; `opts` are the options to blame.
    Labels {
        volume: String,
        opts: &'static [Opt],
        error: String,
    },
    /// A setting or the camera out of range, as volray-core checks it.
    Invalid(RenderError),
}

impl OptionError {
    /// The error in one line, options written as `names` writes them.
    pub fn message(&self, names: &dyn Naming) -> String {
        let o = |opt| names.option(opt);
        use OptionError as E;
        match self {
            E::LabelsOnly(opt) => format!(
                "{} applies to label volumes: give {}",
                o(*opt),
                o(Opt::Labels)
            ),
            E::TfJson { source, error } => format!("{} {source}: {error}", o(Opt::Tf)),
            E::Conflict(a, b) => format!("{} conflicts with {}: give one of them", o(*a), o(*b)),
            E::OpacityConflict { from } => format!(
                "{} conflicts with the opacity function in {}: give one of them",
                o(Opt::Opacity),
                o(*from)
            ),
            E::ColormapConflict => format!(
                "{} conflicts with the colour function in {}: give one of them",
                o(Opt::Colormap),
                o(Opt::Tf)
            ),
            E::RangeConflict { from } => format!(
                "{} conflicts with the value domain fixed by {}: give one of them",
                o(Opt::Range),
                o(*from)
            ),
            E::AutoWithLabels => format!(
                "{} conflicts with {}, which gives each label its colour: give one of them",
                names.with_value(Opt::Tf, "auto"),
                o(Opt::Labels)
            ),
            E::LabelStyleWithTf => format!(
                "{} and {} shape the colours {} gives; {} replaces them: give one of them",
                o(Opt::LabelOpacity),
                o(Opt::ShowLabels),
                o(Opt::Labels),
                o(Opt::Tf)
            ),
            E::RangeWithLabels => format!(
                "{} conflicts with {}, whose window spans the labels: give one of them",
                o(Opt::Range),
                o(Opt::Labels)
            ),
            E::Unknown {
                opt,
                what,
                name,
                expected,
            } => format!(
                "{}: unknown {what} '{name}': expected one of {}",
                o(*opt),
                expected.join(", ")
            ),
            E::LogWindow { from, lo } => format!(
                "{}: with {} the value window is in the data's own units and must be positive, but LO is {lo}",
                o(*from),
                o(Opt::Log)
            ),
            E::IsoNeedsValue => format!(
                "{} needs the isovalue: give {}",
                names.with_value(Opt::Blend, "iso"),
                names.with_value(Opt::Iso, "VALUE")
            ),
            E::NoOpacityInProjection { opt, blend } => format!(
                "{} shapes the opacity of {}; {} projects the interpolated value and has none",
                o(*opt),
                names.with_value(Opt::Blend, "composite"),
                names.with_value(Opt::Blend, blend)
            ),
            E::Unlit { opt, projection } => {
                let why = match projection {
                    Some(name) => format!("{} is unshaded", names.with_value(Opt::Blend, name)),
                    None => format!("{} turns the lighting off", o(Opt::NoShading)),
                };
                let opt = o(*opt);
                format!("{opt} sets the lighting, but {why}: leave {opt} out")
            }
            E::IsoThicknessAlone => format!(
                "{} is the half-width of the {} shell: give {} too",
                o(Opt::IsoThickness),
                o(Opt::Iso),
                names.with_value(Opt::Iso, "VALUE")
            ),
            E::IsoLog { value } => format!(
                "{}: with {} the isovalue is in the data's own units and must be positive, but it is {value}",
                o(Opt::Iso),
                o(Opt::Log)
            ),
            E::Labels {
                volume,
                opts,
                error,
            } => {
                let opts: Vec<String> = opts.iter().map(|&opt| o(opt)).collect();
                format!("{volume}: {}: {error}", opts.join(" / "))
            }
            E::Invalid(e) => e.to_string(),
        }
    }
}

impl fmt::Display for OptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message(&Plain))
    }
}

impl std::error::Error for OptionError {}
