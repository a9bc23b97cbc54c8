//! The fast path of post-classified compositing: the reference's samples
//! (see [`crate::reference::post`]), in `f32`, front to back, skipping
//! the bricks that are transparent whatever their samples.
//!
//! Each ray takes the samples [`crate::sampling`] gives it (orthographic or
//! perspective, cropped, clipped, jittered), walks the 8³-cell bricks of
//! [`crate::bricks`] it crosses in order, and in every brick that may be
//! visible takes each sample: it interpolates the scalar and the voxels'
//! central-difference gradients ([`crate::kernels::gradient`]) trilinearly, then
//! classifies and shades the sample with the formulas of
//! [`crate::reference::post`] (the classifier's opacity and material,
//! Phong lighting for the frame's one light geometry, the colour clamped
//! to [0, 1]) and composites it front to back ([`crate::kernels::composite`]). The
//! ray stops once its transmittance is below
//! [`TERMINATION_TRANSMITTANCE`](crate::kernels::composite::TERMINATION_TRANSMITTANCE), as on the bricked fast path.
//!
//! **Brick walk.** The ray visits the bricks in the order it crosses them,
//! by the 3-D digital differential analyser of J. Amanatides and A. Woo, "A
//! fast voxel traversal algorithm for ray tracing", *Eurographics* 1987:
//! for each axis the ray parameter `t` of the next brick face it crosses,
//! advanced by a brick's width in `t` as the ray steps into the next brick
//! along that axis. A brick takes the samples whose `t` lies before its
//! exit, each clamped into the brick's box (a sample on a shared face
//! belongs to either brick; clamping moves one only by rounding).
//!
//! **Skipping.** A trilinear sample lies between the smallest and the
//! largest of its cell's voxels, so every sample of a brick has a value in
//! the brick's range ([`crate::bricks::macrocells`]); if
//! [`Classifier::is_transparent_between`] says that range gets zero
//! opacity at every gradient (with Levoy's contour and gradient-magnitude
//! opacity too, see [`crate::transfer::classifier`]), no sample of the brick can add
//! anything and the ray steps over it. In `f32` the interpolated value may
//! stray past the range by rounding, by at most `7.5·ε·max(|lo|, |hi|)`
//! (three nested lerps, each off by at most `2u·|b − a| + u·|result|`,
//! `u = ε/2`); the test is made on the range widened by
//! [`RANGE_MARGIN`]`·ε·max(|lo|, |hi|)`, so skipping never drops a sample
//! that would have been visible. A brick of one value interpolates that
//! value exactly and is tested unwidened. Within a brick, a sample whose
//! value lies in a transparent stretch at either end of the volume's range
//! ([`TransparentValues`], found once per frame with the same exact test)
//! is passed over before it is classified, and a sample whose opacity is
//! zero before it is shaded: either would add exactly nothing. (The
//! gradient is interpolated with the value, in the other three lanes of
//! the same vector lerps, so it costs nothing apart.)
//!
//! **Arithmetic.** The reference's formulas, in `f32`: positions counted
//! from the ray's first sample, the scalar and the gradient interpolated by
//! lerps (a sample on a face between two bricks is interpolated in the
//! brick the walk is in), the classifier's [`Classifier::opacity_at`] and
//! [`Classifier::material`], [`Phong::shade`] with the frame's light (a
//! headlight at infinity along the central view direction, for perspective
//! views too, as on the reference), the colour clamped to [0, 1]. The
//! images agree with the reference's within 1/255, early termination
//! (at most 1/1024) being the largest part of the difference.
//!
//! **Gradients** are the reference's: each voxel's central difference,
//! interpolated trilinearly. The renderer computes them once per volume
//! and keeps them packed with the scalars ([`packed_voxels`]: each voxel
//! as `(gx, gy, gz, f)`, x fastest), so that one 16-byte load per corner
//! and one chain of vector lerps interpolate value and gradient together
//! (the same arithmetic, lane by lane, as separate scalar and vector
//! lerps, so the same values). It costs 16 bytes per voxel, four times the
//! volume itself. (A bricked copy, each brick's 9³ corner voxels together
//! as in [`crate::bricks::occupied`], 22.8 bytes per voxel, measured no faster:
//! the cost is in the arithmetic, not the cache.)
//!
//! **Non-finite voxels** rendered as empty space ([`NonFinite`](crate::NonFinite)):
//! the scene's voxels are the cleaned copy's, and in a brick near a masked
//! voxel each sample is first tested by the reference's rule on the
//! reference's `f64` position, and passed over if skipped. Other bricks,
//! and volumes without non-finite values, pay nothing.
//!
//! Each pixel is computed from its own ray alone, by the same arithmetic
//! whatever thread runs it (rows in parallel), so the image is
//! bit-identical for any thread count.
//!
//! [`Classifier::is_transparent_between`]: crate::transfer::classifier::Classifier::is_transparent_between
//! [`Classifier::opacity_at`]: crate::transfer::classifier::Classifier::opacity_at
//! [`Classifier::material`]: crate::transfer::classifier::Classifier::material
//! [`Phong::shade`]: crate::kernels::phong::Phong::shade
//! [`RANGE_MARGIN`]: skipping::RANGE_MARGIN
//! [`TransparentValues`]: skipping::TransparentValues

mod cast;
mod scene;
pub(crate) mod skipping;
#[cfg(test)]
mod tests;

pub use self::cast::render;
pub(crate) use self::scene::BYTES_PER_VOXEL;
pub use self::scene::{Scene, packed_voxels};
pub(crate) use self::skipping::FRAME_BYTES_PER_BRICK;
