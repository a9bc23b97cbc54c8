//! The fast path on the CPU.

pub mod bricked;
pub mod lit_bricks;
pub mod post;
pub mod projection;
pub mod tiles;
