//! The numbers a kernel computes with: one `f32`, or four in SIMD lanes
//! (`wide::f32x4`). A kernel written once over [`Lanes`] runs on one
//! sample (the reference-like scalar paths, a GPU port's shader) or on
//! four at once (the fast path's lighting), with the same operations in
//! the same order, so the same rounding lane by lane.

use std::ops::{Add, Mul, Sub};
use wide::f32x4;

/// `f32` arithmetic, on one value or on each SIMD lane.
pub trait Lanes: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    const ONE: Self;

    /// `x` in every lane.
    fn splat(x: f32) -> Self;

    /// `max(self, 0)`.
    fn max_zero(self) -> Self;

    /// `−1` where `self < 0`, else `1`: the sign that turns a normal to
    /// face the side `self` is measured towards.
    fn facing(self) -> Self;

    /// `value()` where `self > 0`, else 0 (`value` may be computed for
    /// every lane, or only when needed).
    fn where_positive(self, value: impl FnOnce() -> Self) -> Self;

    /// `self^n`, lane by lane, by the platform's `powf`.
    fn powf(self, n: f32) -> Self;
}

impl Lanes for f32 {
    const ONE: f32 = 1.0;

    #[inline(always)]
    fn splat(x: f32) -> f32 {
        x
    }

    #[inline(always)]
    fn max_zero(self) -> f32 {
        self.max(0.0)
    }

    #[inline(always)]
    fn facing(self) -> f32 {
        if self < 0.0 { -1.0 } else { 1.0 }
    }

    #[inline(always)]
    fn where_positive(self, value: impl FnOnce() -> f32) -> f32 {
        if self > 0.0 { value() } else { 0.0 }
    }

    #[inline(always)]
    fn powf(self, n: f32) -> f32 {
        f32::powf(self, n)
    }
}

impl Lanes for f32x4 {
    const ONE: f32x4 = f32x4::ONE;

    #[inline(always)]
    fn splat(x: f32) -> f32x4 {
        f32x4::splat(x)
    }

    #[inline(always)]
    fn max_zero(self) -> f32x4 {
        self.fast_max(f32x4::ZERO)
    }

    #[inline(always)]
    fn facing(self) -> f32x4 {
        self.simd_lt(f32x4::ZERO).select(-f32x4::ONE, f32x4::ONE)
    }

    #[inline(always)]
    fn where_positive(self, value: impl FnOnce() -> f32x4) -> f32x4 {
        self.simd_gt(f32x4::ZERO).select(value(), f32x4::ZERO)
    }

    #[inline(always)]
    fn powf(self, n: f32) -> f32x4 {
        f32x4::new(self.to_array().map(|x| x.powf(n)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation gives, lane by lane, what it gives on one `f32`.
    #[test]
    fn simd_lanes_agree_with_scalars() {
        let xs = [-2.5f32, -0.0, 0.0, 0.75];
        let v = f32x4::new(xs);
        let lanes = |v: f32x4| v.to_array();
        for (k, &x) in xs.iter().enumerate() {
            assert_eq!(lanes(v.max_zero())[k], x.max_zero());
            assert_eq!(lanes(v.facing())[k], x.facing());
            assert_eq!(
                lanes(v.where_positive(|| f32x4::splat(9.0)))[k],
                x.where_positive(|| 9.0)
            );
            assert_eq!(
                lanes(Lanes::powf(v.max_zero(), 2.5))[k].to_bits(),
                x.max_zero().powf(2.5).to_bits()
            );
        }
        assert_eq!(xs.map(|x| x.facing()), [-1.0, 1.0, 1.0, 1.0]);
        assert_eq!(xs.map(|x| x.where_positive(|| 9.0)), [0.0, 0.0, 0.0, 9.0]);
    }
}
