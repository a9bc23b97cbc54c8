//! # volray-annotate: what makes a frame a figure
//!
//! Annotations drawn into a rendered frame ([`volray_core::Image`]), for
//! pictures that go into papers and talks:
//!
//! - [`text`]: text from one embedded open font (DejaVu Sans), rasterised
//!   from its outlines at any size, blended over the frame;
//! - [`colorbar`]: the transfer function's colour bar over its value
//!   window, with its opacity, and ticks labelled in the data's units
//!   (log-spaced for `--log`); a legend for label volumes;
//! - [`scalebar`]: a round length in world units, as many pixels long as
//!   the view's pixel size says;
//! - [`axes`]: an orientation triad, the world's axes turned as the
//!   camera turns them, red, green and blue, named as the file's world is;
//! - [`outline`]: the volume's box, its edges projected through the
//!   frame's own view (orthographic or perspective) and clipped;
//! - [`line`](mod@line): the anti-aliased, clipped segments both draw;
//! - [`ticks`]: round tick values and short labels;
//! - [`figure`]: the annotations a front end asks for, drawn for what was
//!   rendered (one function for the command line, Python and the viewer;
//!   [`figure::annotate_frame`] from the frame's renderer and settings).
//!
//! ## Where each lands
//!
//! The title is centred at the top, the label in the top left corner, the
//! colour bar (or a label volume's legend) on the right or left over the
//! middle three fifths of the height, the scale bar in the bottom left
//! corner, the triad in the bottom right (left of a colour bar there);
//! the outline is drawn first, under the others. Sizes follow the
//! frame's smaller side, so a figure reads alike at 240² and 4096². Ink
//! is white on a dark background and black on a light one ([`figure::ink`]).
//! Nothing asked, nothing drawn: a frame without annotations is the
//! renderer's, bit for bit.
//!
//! ```
//! use volray_annotate::colorbar::{ColorBar, Side};
//! use volray_annotate::scalebar::ScaleBar;
//! use volray_core::Image;
//!
//! let mut frame = Image::new(480, 480, [0.0, 0.0, 0.0, 1.0]);
//! let grey = |v: f64| [(v / 100.0) as f32; 3];
//! let bar = ColorBar {
//!     window: (0.0, 100.0),
//!     log: false,
//!     colour: &grey,
//!     opacity: &|v| (v / 100.0) as f32,
//!     unit: Some("HU"),
//!     side: Side::Right,
//! };
//! let drawn = bar.draw(&mut frame, [1.0; 3]);
//! assert_eq!(drawn.ticks.len(), 6); // 0, 20, ..., 100
//! let scale = ScaleBar { pixel_size: 0.5, length: None, unit: Some("mm"), approximate: false };
//! assert_eq!(scale.draw(&mut frame, [1.0; 3]).length, 50.0); // about a fifth of 240 mm
//! ```

pub mod axes;
pub mod colorbar;
pub mod figure;
pub mod line;
pub mod outline;
pub mod scalebar;
pub mod text;
pub mod ticks;
