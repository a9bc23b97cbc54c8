//! Per-sample maths: small inline functions with no allocation and no
//! threads, the one copy every path calls, which a GPU port's shaders
//! mirror and GPU-versus-CPU tests compare against.
//!
//! | kernel | what |
//! |---|---|
//! | [`trilinear`] | a cell's eight voxels to a sample: the `f32` lerp chain (one value or four SIMD lanes) and the `f64` weighted sum of the oracle |
//! | [`gradient`] | central differences (errata 1), in world units |
//! | [`phong`] | the paper's Phong model, two-sided, on one normal or four |
//! | [`composite`] | front-to-back and back-to-front compositing, partial pixels and `over` |
//! | [`blend`] | how a ray's samples make its pixel: composited, or a projection of the scalar |
//! | [`projection`] | the running maximum, minimum or mean of a ray's scalar samples, merged across pieces of a ray |
//! | [`lanes`] | the number type kernels are written over: `f32` or `wide::f32x4` |

pub mod blend;
pub mod composite;
pub mod gradient;
pub mod lanes;
pub mod mix;
pub mod phong;
pub mod projection;
pub mod trilinear;
