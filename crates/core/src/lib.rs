pub mod image;
pub mod volume;

pub use glam;
pub use image::Image;
pub use volume::{Volume, VolumeError};
