//! What makes a frame a figure: `--colorbar`, `--scale-bar`, `--axes`,
//! `--outline`, `--title`, `--label` (and `--units`, the colour bar's), drawn into the image by volray-annotate (`figure.rs` beside
//! `main.rs` says what was rendered).

use clap::Args;

/// Annotations drawn into the image.
#[derive(Debug, Args)]
pub struct FigureArgs {
    /// A colour bar of the transfer function (a legend of the labels for
    /// --labels) on this side: its colours and opacity over the value
    /// window, ticks in the data's units (decades with --log).
    #[arg(long, value_name = "right|left", num_args = 0..=1, default_missing_value = "right", help_heading = "Figures")]
    pub colorbar: Option<ColorBarSide>,

    /// The values' unit, written on the colour bar's ticks ("K",
    /// "counts") [default: HU under a ct- preset, else none].
    #[arg(long, value_name = "UNIT", value_parser = volray_annotate::figure::parse_unit, help_heading = "Figures")]
    pub units: Option<String>,

    /// A scale bar in the volume's units, LENGTH long [default: a round
    /// length, about a fifth of the image]; in perspective it holds at the
    /// depth of the volume's centre and is marked ≈.
    #[arg(long, value_name = "LENGTH", num_args = 0..=1, default_missing_value = "auto", value_parser = parse_length, help_heading = "Figures")]
    pub scale_bar: Option<ScaleLength>,

    /// An orientation triad in a corner: the world's x, y, z (R, A, S or
    /// L, P, S where the file's world is anatomical) turned as the camera
    /// is, red, green, blue.
    #[arg(long, help_heading = "Figures")]
    pub axes: bool,

    /// The volume's box, its twelve edges drawn over the frame as the
    /// camera sees them (each volume's box with --channels or --overlay).
    #[arg(long, help_heading = "Figures")]
    pub outline: bool,

    /// A title over the image.
    #[arg(long, value_name = "TEXT", help_heading = "Figures")]
    pub title: Option<String>,

    /// Text in the image's top left corner (a panel's letter).
    #[arg(long, value_name = "TEXT", help_heading = "Figures")]
    pub label: Option<String>,
}

/// `--colorbar`'s side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ColorBarSide {
    Right,
    Left,
}

/// `--scale-bar`'s length: a round one, or as given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScaleLength {
    Auto,
    Given(f64),
}

fn parse_length(text: &str) -> Result<ScaleLength, String> {
    if text == "auto" {
        return Ok(ScaleLength::Auto);
    }
    match text.trim().parse::<f64>() {
        Ok(l) if l.is_finite() && l > 0.0 => Ok(ScaleLength::Given(l)),
        _ => Err(format!("{text:?} is not a positive length")),
    }
}

impl FigureArgs {
    /// Whether any annotation is asked for.
    pub fn any(&self) -> bool {
        self.colorbar.is_some()
            || self.scale_bar.is_some()
            || self.title.is_some()
            || self.label.is_some()
            || self.axes
            || self.outline
    }

    /// The first annotation flag given, for messages.
    pub fn first_flag(&self) -> &'static str {
        if self.colorbar.is_some() {
            "--colorbar"
        } else if self.scale_bar.is_some() {
            "--scale-bar"
        } else if self.axes {
            "--axes"
        } else if self.outline {
            "--outline"
        } else if self.title.is_some() {
            "--title"
        } else {
            "--label"
        }
    }
}
