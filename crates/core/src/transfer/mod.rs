//! Transfer functions: values to colour and opacity.

pub mod classifier;
pub mod colormap;
pub mod function;
pub mod gradient_opacity;
pub mod iso;
pub mod presets;
