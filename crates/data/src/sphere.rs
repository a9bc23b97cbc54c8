//! A solid ball with a smooth edge, for closed-form checks.
//!
//! On the cube `[−1, 1]³`, with `r = |p|`, radius `R` and edge width `w`:
//!
//! ```text
//! f(p) = 1 − smoothstep(R − w/2, R + w/2, r)
//! smoothstep(a, b, x) = t²·(3 − 2t),  t = clamp((x − a)/(b − a), 0, 1)
//! ```
//!
//! so `f = 1` for `r ≤ R − w/2`, `f = 0` for `r ≥ R + w/2`, `f = 1/2` at
//! `r = R`, and `f` is C¹ (its gradient is continuous and vanishes at both
//! ends of the edge). The isosurface `f = 1/2` is the sphere of radius `R`,
//! with outward normal `p/|p|`. The volume is mirror symmetric about every
//! plane through the centre. The smoothstep (cubic Hermite) profile is the
//! one of e.g. the GLSL `smoothstep` and D. S. Ebert et al., "Texturing and
//! Modeling: A Procedural Approach", 3rd ed., Morgan Kaufmann, 2003.

use std::fmt;

use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::{Args, DataError, SourceInfo, SourceSpec, grid};

/// The registry entry.
pub const INFO: SourceInfo = SourceInfo {
    name: "sphere",
    usage: "sphere[:N][,radius=R][,edge=W]",
    description: "solid ball of radius R (default 0.8) centred in [-1,1]^3, 1 inside, 0 outside, \
                  smoothstep edge of width W (default 0.1), N points per side (default 64)",
    build,
};

fn build(spec: &SourceSpec) -> Result<Volume, DataError> {
    Sphere::from_spec(spec)?.volume()
}

/// `smoothstep(a, b, x)`: 0 below `a`, 1 above `b`, `t²(3 − 2t)` between.
pub fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The ball sampled on `n³` points over `[−1, 1]³`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Points per side, 2..=1025.
    pub n: usize,
    /// Radius `R` of the `f = 1/2` surface, > 0.
    pub radius: f64,
    /// Width `w` of the edge, `0 < w ≤ 2R`.
    pub edge: f64,
}

impl Default for Sphere {
    fn default() -> Self {
        Sphere {
            n: 64,
            radius: 0.8,
            edge: 0.1,
        }
    }
}

/// The canonical spec, e.g. `sphere:64,radius=0.8,edge=0.1`.
impl fmt::Display for Sphere {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{},radius={},edge={}",
            INFO.name, self.n, self.radius, self.edge
        )
    }
}

impl Sphere {
    /// Reads `sphere[:N][,radius=R][,edge=W]` (or `n=N`) and checks it.
    pub fn from_spec(spec: &SourceSpec) -> Result<Self, DataError> {
        let args = Args::new(spec, &["n"], &["radius", "edge"])?;
        let d = Self::default();
        let sphere = Sphere {
            n: args.usize_or("n", d.n)?,
            radius: args.f64_or("radius", d.radius)?,
            edge: args.f64_or("edge", d.edge)?,
        };
        sphere.check().map_err(DataError::invalid(spec))?;
        Ok(sphere)
    }

    fn check(&self) -> Result<(), String> {
        grid::check_points(self.n)?;
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(format!(
                "radius must be positive and finite, got {}",
                self.radius
            ));
        }
        if !(self.edge.is_finite() && self.edge > 0.0) {
            return Err(format!(
                "edge must be positive and finite, got {}",
                self.edge
            ));
        }
        if self.edge > 2.0 * self.radius {
            return Err(format!(
                "edge {} must not exceed the diameter {}",
                self.edge,
                2.0 * self.radius
            ));
        }
        Ok(())
    }

    /// `f(p)` at world position `p`.
    pub fn density(&self, p: DVec3) -> f64 {
        let half = 0.5 * self.edge;
        1.0 - smoothstep(self.radius - half, self.radius + half, p.length())
    }

    /// The sampled volume: origin `(−1, −1, −1)`, spacing `2/(n − 1)`.
    pub fn volume(&self) -> Result<Volume, DataError> {
        let spec = self.to_string();
        self.check().map_err(DataError::invalid(&spec))?;
        grid::cube_volume(&spec, self.n, 1.0, |p| self.density(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate;

    #[test]
    fn profile_closed_forms() {
        let s = Sphere::default();
        assert_eq!(s.density(DVec3::ZERO), 1.0);
        assert_eq!(s.density(DVec3::new(0.0, 0.75, 0.0)), 1.0);
        assert!((s.density(DVec3::new(0.0, 0.0, 0.8)) - 0.5).abs() < 1e-12);
        assert!((s.density(DVec3::new(0.48, -0.64, 0.0)) - 0.5).abs() < 1e-12);
        assert_eq!(s.density(DVec3::new(0.85, 0.0, 0.0)), 0.0);
        assert_eq!(s.density(DVec3::ONE), 0.0);
        // A quarter into the edge: t = 1/4 → 1 − (1/16)(3 − 1/2) = 27/32.
        assert!((s.density(DVec3::new(0.775, 0.0, 0.0)) - 27.0 / 32.0).abs() < 1e-12);
        assert_eq!(smoothstep(0.0, 1.0, -1.0), 0.0);
        assert_eq!(smoothstep(0.0, 1.0, 2.0), 1.0);
        assert_eq!(smoothstep(0.0, 1.0, 0.5), 0.5);
    }

    #[test]
    fn volume_is_mirror_symmetric_with_solid_centre_and_empty_corners() {
        for spec in ["sphere:33", "sphere:32,radius=0.5,edge=0.3"] {
            let v = generate(spec).unwrap();
            let n = v.dims()[0];
            for k in 0..n {
                for j in 0..n {
                    for i in 0..n {
                        let f = v.get(i, j, k);
                        assert_eq!(f, v.get(n - 1 - i, j, k), "{spec} x mirror at {i},{j},{k}");
                        assert_eq!(f, v.get(i, n - 1 - j, k), "{spec} y mirror at {i},{j},{k}");
                        assert_eq!(f, v.get(i, j, n - 1 - k), "{spec} z mirror at {i},{j},{k}");
                    }
                }
            }
            for c in [0, n - 1] {
                for (i, j, k) in [(c, 0, 0), (c, n - 1, 0), (c, 0, n - 1), (c, n - 1, n - 1)] {
                    assert_eq!(v.get(i, j, k), 0.0, "{spec} corner");
                }
            }
            let m = n / 2;
            assert_eq!(v.get(m, m, m), 1.0, "{spec} centre");
            assert_eq!(v.value_range(), Some((0.0, 1.0)));
        }
    }

    #[test]
    fn voxels_match_the_profile() {
        let v = generate("sphere:41,radius=0.6,edge=0.2").unwrap();
        let s = Sphere {
            n: 41,
            radius: 0.6,
            edge: 0.2,
        };
        for (i, j, k) in [
            (20, 20, 20),
            (20, 20, 32),
            (33, 20, 20),
            (31, 28, 20),
            (5, 6, 7),
        ] {
            let p = v.world_position(i, j, k);
            let r = p.length();
            let t = ((r - 0.5) / 0.2).clamp(0.0, 1.0);
            let expected = 1.0 - t * t * (3.0 - 2.0 * t);
            assert!(
                (v.get(i, j, k) as f64 - expected).abs() < 1e-6,
                "{i},{j},{k}"
            );
            assert!((s.density(p) - expected).abs() < 1e-12);
        }
        // (20, 20, 32) is at r = 0.6 = R: exactly half.
        assert!((v.get(20, 20, 32) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn rejects_bad_parameters() {
        let err = |s: &str| generate(s).unwrap_err().to_string();
        assert_eq!(
            err("sphere:64,radius=-0.5"),
            "sphere:64,radius=-0.5: radius must be positive and finite, got -0.5"
        );
        assert_eq!(
            err("sphere:radius=0"),
            "sphere:radius=0: radius must be positive and finite, got 0"
        );
        assert_eq!(
            err("sphere:radius=inf"),
            "sphere:radius=inf: radius must be a finite number, got `inf`"
        );
        assert_eq!(
            err("sphere:edge=0"),
            "sphere:edge=0: edge must be positive and finite, got 0"
        );
        assert_eq!(
            err("sphere:radius=0.1,edge=0.3"),
            "sphere:radius=0.1,edge=0.3: edge 0.3 must not exceed the diameter 0.2"
        );
        assert_eq!(
            err("sphere:2000"),
            "sphere:2000: grid must have at most 1025 points per side, got 2000"
        );
        assert!(matches!(
            generate("sphere:64,r=0.5"),
            Err(DataError::UnknownKey { .. })
        ));
    }
}
