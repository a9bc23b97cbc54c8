//! The options a user gives to render a volume, as every front end takes
//! them: the command line (`volray render`, `bench`, `view`), the browser
//! viewer's Command box and the Python module. Each front end fills
//! [`Options`] from its own syntax; this crate checks them together,
//! turns them into volray-core's [`RenderSettings`](volray_core::RenderSettings)
//! with the command line's defaults, and says what is wrong as an
//! [`OptionError`] naming the [`Opt`], which the front end words in its
//! own [`Naming`] (`--no-shading`, `shading=False`). So one set of
//! options gives the same pixels from every front end.
//!
//! The order of use:
//! 1. [`settings()`]: the options alone, checked, before any file is read;
//! 2. [`from_volume`]: what they leave to the volume (labels, or the
//!    transfer function chosen from its histogram);
//! 3. on a render error, [`option_of`] says which option to name.
//!
//! ```
//! use volray_options::{settings, BlendMode, Naming, Opt, Options, Plain};
//!
//! let mut options = Options::default();
//! options.look.blend = BlendMode::Mip;
//! options.look.opacity = Some((0.0, 1.0));
//! let refused = settings(&options).unwrap_err();
//! assert_eq!(
//!     refused.message(&Plain),
//!     "opacity shapes the opacity of blend composite; blend mip projects the interpolated value and has none"
//! );
//! ```

mod blame;
pub mod colors;
mod error;
pub mod level;
mod option;
mod options;
mod settings;
mod volume;

pub use blame::option_of;
pub use error::OptionError;
pub use option::{Naming, Opt, Plain};
pub use options::{BlendMode, CameraOptions, LookOptions, Options, SamplingOptions, Tf};
pub use settings::{named_transfer_function, settings};
pub use volume::{
    apply_auto, auto_log_note, choose_auto, chooses_log, file_window, from_volume,
    label_transfer_function, labels_found, volume_labels,
};
