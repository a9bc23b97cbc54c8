//! Transfer functions: a voxel's or a sample's value (and gradient) to its
//! material colour and opacity.
//!
//! | module | what |
//! |---|---|
//! | [`classifier`] | the [`Classifier`](classifier::Classifier) every path uses: the paper's opacity ramp or a table, the colour, the step correction, the exact zero-opacity test of empty-space skipping |
//! | [`function`] | piecewise-linear functions and the transfer-function JSON |
//! | [`colormap`] | named colour maps (viridis, magma, ..., cool-to-warm) |
//! | [`presets`] | transfer functions for CT, MR and electron densities |
//! | [`auto`] | a transfer function chosen from a volume's histogram (`--tf auto`) |
//! | [`labels`] | label volumes (segmentations): a colour and an opacity per label |
//! | [`iso`] | Levoy's isovalue contours (1988, eq. 3) |
//! | [`gradient_opacity`] | opacity scaled by a ramp of the gradient magnitude |

pub mod auto;
pub mod classifier;
pub mod colormap;
pub mod function;
pub mod gradient_opacity;
pub mod iso;
pub mod labels;
pub mod presets;
