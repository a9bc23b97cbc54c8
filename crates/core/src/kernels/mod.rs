//! Per-sample maths, the one copy every path calls.

pub mod composite;
pub mod gradient;
pub mod lanes;
pub mod phong;
pub mod projection;
pub mod trilinear;
