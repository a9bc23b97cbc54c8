//! Writing rendered [`Image`](volray_core::Image)s: PNG (8 or 16 bits),
//! OpenEXR (32-bit float) and animations (APNG, GIF, numbered PNG
//! sequences), each written atomically (see [`crate::atomic`]).

pub(crate) mod animation;
pub(crate) mod exr;
pub(crate) mod png;
