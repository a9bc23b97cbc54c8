//! The fast path on the CPU: the reference's samples, in `f32`, skipping
//! what contributes nothing, in parallel (rayon), bit-identical for any
//! thread count.
//!
//! | module | what |
//! |---|---|
//! | `tiles.rs` | per frame, the occupied bricks each 16² image tile's rays may cross, front to back |
//! | `lit_bricks.rs` | per frame, each occupied brick's voxels lit (Phong × material), as the rays first reach it |
//! | `bricked.rs` | the pre-classified caster (the paper's method, the default): rays through their tile's bricks |
//! | `post/` | the post-classified caster: rays walk the bricks they cross, skipping transparent ones |
//! | `projection.rs` | maximum, minimum and average projections of the scalar |

pub mod bricked;
pub mod lit_bricks;
pub mod post;
pub mod projection;
pub mod tiles;
