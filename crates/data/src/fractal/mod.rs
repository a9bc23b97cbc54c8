//! Fractal clouds by 3-D midpoint displacement, the paper's second class of
//! test data (errata 7), with Voss's successive random additions as an
//! option.
//!
//! A [`FractalParams`] names the field; [`generate`] makes it on the cube
//! `[−1, 1]³` (origin `(−1, −1, −1)`, spacing `2/(size − 1)`, like the other
//! built-in sources) with `size = 2^k + 1` points per side:
//!
//! 1. `midpoint`: the 8 corners from `N(0, σ²)`, then per level the cube
//!    centres, face centres and edge midpoints, each the mean of the corners
//!    of its cell, face or edge plus a Gaussian displacement whose size
//!    ([`scaling`]) gives increments of variance ∝ distance^{2H},
//!    `H = 4 − D`. The random number of each point depends only on
//!    (seed, level, point) ([`noise`]), so the bytes do not depend on the
//!    thread count.
//! 2. `postprocess` (unless `raw_field`): scale to `[0, 1]`, multiply by a
//!    ramp that falls to 0 at the inscribed sphere, subtract the threshold,
//!    set negatives to 0.
//!
//! The field is made in place in its final `Vec<f32>`: a 513³ cloud needs
//! its 0.54 GB and a few small vectors. `docs/fractal.md` derives the
//! factors and records the measured statistics.
//!
//! ```
//! use volray_data::fractal::{FractalParams, generate};
//!
//! let params = FractalParams { size: 17, seed: 7, ..FractalParams::default() };
//! let cloud = generate(&params)?;
//! assert_eq!(cloud.dims(), [17, 17, 17]);
//! assert_eq!(cloud.get(0, 8, 8), 0.0); // empty at the boundary
//! let raw = generate(&FractalParams { raw_field: true, ..params })?;
//! assert!(raw.values().iter().any(|&v| v < 0.0)); // mean 0 before post-processing
//! # Ok::<(), volray_data::DataError>(())
//! ```

mod midpoint;
pub mod noise;
mod postprocess;
pub mod scaling;

use std::fmt;

use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::{Args, DataError, SourceInfo, SourceSpec, grid};

/// The registry entry.
pub const INFO: SourceInfo = SourceInfo {
    name: "fractal",
    usage: "fractal[:SIZE][,seed=S][,dim=D][,sigma=X][,ramp=R][,threshold=T][,raw=true][,additions=true]",
    description: "fractal cloud by 3-D midpoint displacement on [-1,1]^3, SIZE = 2^k+1 points per \
                  side (129), fractal dimension D (3.7, H = 4 - D), corner deviation sigma (1), \
                  seed (1), boundary ramp width (0.3) and threshold (0.45) unless raw; \
                  additions=true for Voss's random additions",
    build,
};

fn build(spec: &SourceSpec) -> Result<Volume, DataError> {
    let params = FractalParams::from_spec(spec)?;
    generate_named(&params, spec)
}

/// Smallest grid: one level of refinement, 3 points per side.
pub const MIN_SIZE: usize = 3;

/// What fractal field to make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FractalParams {
    /// Points per side, `2^k + 1` with `1 ≤ k ≤ 10` (3..=1025).
    pub size: usize,
    /// Fractal dimension `D` of the field's graph, `3 ≤ D < 4`; the Hurst
    /// exponent is `H = 4 − D` (errata 7).
    pub dimension: f64,
    /// Standard deviation of the corners, and the scale of every
    /// displacement; finite and positive.
    pub sigma: f64,
    /// Seed of every random number.
    pub seed: u64,
    /// Width of the boundary ramp, as a fraction of the half width:
    /// `0 < ramp ≤ 1` (`postprocess`).
    pub ramp: f64,
    /// Subtracted from the field scaled to `[0, 1]`: `0 ≤ threshold < 1`.
    pub threshold: f64,
    /// Skip the post-processing: the midpoint-displacement field itself,
    /// mean 0.
    pub raw_field: bool,
    /// Voss's successive random additions: new points are plain means, and
    /// every point present after a level gets a random addition.
    pub random_additions: bool,
}

impl Default for FractalParams {
    /// The paper's 129³ clouds (D = 3.7, σ = 1), seed 1, flat out to 70% of
    /// the half width and ramped to 0 over the outer 30%, threshold 0.45
    /// (near the median of the scaled field there, so the cloud has holes
    /// and filaments): about 10–20% of the voxels are non-empty (measured
    /// in `docs/fractal.md`).
    fn default() -> Self {
        FractalParams {
            size: 129,
            dimension: 3.7,
            sigma: 1.0,
            seed: 1,
            ramp: 0.3,
            threshold: 0.45,
            raw_field: false,
            random_additions: false,
        }
    }
}

/// The canonical spec, e.g. `fractal:129,seed=1,dim=3.7,sigma=1,ramp=0.3,
/// threshold=0.45`, with `raw=true` and `additions=true` when set. It parses
/// back to the same parameters.
impl fmt::Display for FractalParams {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{},seed={},dim={},sigma={},ramp={},threshold={}",
            INFO.name, self.size, self.seed, self.dimension, self.sigma, self.ramp, self.threshold
        )?;
        if self.raw_field {
            f.write_str(",raw=true")?;
        }
        if self.random_additions {
            f.write_str(",additions=true")?;
        }
        Ok(())
    }
}

impl FractalParams {
    /// Reads `fractal[:SIZE][,seed=S][,dim=D][,sigma=X][,ramp=R]
    /// [,threshold=T][,raw=true][,additions=true]` (or `size=SIZE`); what is
    /// not given is the [`Default`]. The parameters are validated.
    pub fn from_spec(spec: &SourceSpec) -> Result<Self, DataError> {
        let args = Args::new(
            spec,
            &["size"],
            &[
                "seed",
                "dim",
                "sigma",
                "ramp",
                "threshold",
                "raw",
                "additions",
            ],
        )?;
        let d = Self::default();
        let params = FractalParams {
            size: args.usize_or("size", d.size)?,
            dimension: args.f64_or("dim", d.dimension)?,
            sigma: args.f64_or("sigma", d.sigma)?,
            seed: args.u64("seed")?.unwrap_or(d.seed),
            ramp: args.f64_or("ramp", d.ramp)?,
            threshold: args.f64_or("threshold", d.threshold)?,
            raw_field: args.bool_or("raw", d.raw_field)?,
            random_additions: args.bool_or("additions", d.random_additions)?,
        };
        params.validate().map_err(DataError::invalid(spec))?;
        Ok(params)
    }

    /// The smallest and largest `sigma` [`validate`](Self::validate) takes.
    pub const SIGMA_RANGE: (f64, f64) = (1e-30, 1e30);

    /// Checks every parameter, returning the first problem as a message
    /// (for [`DataError::Invalid`]).
    pub fn validate(&self) -> Result<(), String> {
        grid::check_points(self.size)?;
        if self.size < MIN_SIZE || !(self.size - 1).is_power_of_two() {
            return Err(format!(
                "size must be 2^k + 1 points per side (3, 5, 9, 17, 33, 65, 129, 257, 513 or \
                 1025), got {}",
                self.size
            ));
        }
        // Written so that NaN fails every check.
        if !(self.dimension >= 3.0 && self.dimension < 4.0) {
            return Err(format!(
                "dimension must be at least 3 and below 4 (Hurst exponent H = 4 - D in (0, 1]), \
                 got {}",
                self.dimension
            ));
        }
        // The field is a sum of displacements of a few sigma stored as f32
        // (largest 3.4e38): beyond 1e30 (or below 1e-30, where the ramp and
        // threshold arithmetic underflows) it overflows to infinities or
        // collapses to zeros.
        if !(Self::SIGMA_RANGE.0..=Self::SIGMA_RANGE.1).contains(&self.sigma) {
            return Err(format!(
                "sigma must be between {:e} and {:e} (the field is stored as 32-bit floats), got {}",
                Self::SIGMA_RANGE.0,
                Self::SIGMA_RANGE.1,
                self.sigma
            ));
        }
        if !(self.ramp > 0.0 && self.ramp <= 1.0) {
            return Err(format!(
                "ramp must be above 0 and at most 1 (a fraction of the half width), got {}",
                self.ramp
            ));
        }
        if !(self.threshold >= 0.0 && self.threshold < 1.0) {
            return Err(format!(
                "threshold must be at least 0 and below 1 (on the field scaled to [0, 1]), got {}",
                self.threshold
            ));
        }
        Ok(())
    }

    /// The Hurst exponent `H = 4 − D`.
    pub fn hurst(&self) -> f64 {
        scaling::hurst(self.dimension)
    }
}

/// Generates the fractal field on `[−1, 1]³`; errors name the parameters as
/// their canonical spec.
pub fn generate(params: &FractalParams) -> Result<Volume, DataError> {
    generate_named(params, params)
}

fn generate_named(params: &FractalParams, name: impl fmt::Display) -> Result<Volume, DataError> {
    params.validate().map_err(DataError::invalid(&name))?;
    let n = params.size;
    let mut data = vec![0.0f32; n * n * n];
    midpoint::fill(
        &mut data,
        n,
        &midpoint::Refinement {
            sigma: params.sigma,
            hurst: params.hurst(),
            seed: params.seed,
            random_additions: params.random_additions,
        },
    );
    if !params.raw_field {
        postprocess::apply(&mut data, n, params.ramp, params.threshold);
    }
    Volume::new([n, n, n], data)
        .and_then(|v| v.with_spacing(DVec3::splat(2.0 / (n - 1) as f64)))
        .and_then(|v| v.with_origin(DVec3::splat(-1.0)))
        .map_err(|error| DataError::Volume {
            spec: name.to_string(),
            error,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate as generate_spec;

    #[test]
    fn spec_defaults_are_the_default_params() {
        let spec = SourceSpec::parse("fractal").unwrap();
        assert_eq!(
            FractalParams::from_spec(&spec).unwrap(),
            FractalParams::default()
        );
        let d = FractalParams::default();
        assert_eq!((d.size, d.dimension, d.sigma, d.seed), (129, 3.7, 1.0, 1));
        assert!(d.validate().is_ok());
    }

    #[test]
    fn spec_reads_every_parameter_and_display_round_trips() {
        let spec = SourceSpec::parse(
            "fractal:33,seed=18446744073709551615,dim=3.25,sigma=2.5,ramp=0.75,threshold=0.1,\
             raw=true,additions=true",
        )
        .unwrap();
        let p = FractalParams::from_spec(&spec).unwrap();
        assert_eq!(
            p,
            FractalParams {
                size: 33,
                dimension: 3.25,
                sigma: 2.5,
                seed: u64::MAX,
                ramp: 0.75,
                threshold: 0.1,
                raw_field: true,
                random_additions: true,
            }
        );
        for q in [p, FractalParams::default()] {
            let again = SourceSpec::parse(&q.to_string()).unwrap();
            assert_eq!(FractalParams::from_spec(&again).unwrap(), q);
        }
        assert_eq!(
            FractalParams::default().to_string(),
            "fractal:129,seed=1,dim=3.7,sigma=1,ramp=0.3,threshold=0.45"
        );
        let by_name = SourceSpec::parse("fractal:size=9").unwrap();
        assert_eq!(FractalParams::from_spec(&by_name).unwrap().size, 9);
    }

    #[test]
    fn rejects_bad_parameters_with_one_line_messages() {
        let err = |s: &str| generate_spec(s).unwrap_err().to_string();
        assert_eq!(
            err("fractal:1"),
            "fractal:1: grid must have at least 2 points per side, got 1"
        );
        assert_eq!(
            err("fractal:2"),
            "fractal:2: size must be 2^k + 1 points per side (3, 5, 9, 17, 33, 65, 129, 257, \
             513 or 1025), got 2"
        );
        assert!(err("fractal:128").ends_with("got 128"));
        assert_eq!(
            err("fractal:2049"),
            "fractal:2049: grid must have at most 1025 points per side, got 2049"
        );
        assert_eq!(
            err("fractal:9,dim=4"),
            "fractal:9,dim=4: dimension must be at least 3 and below 4 (Hurst exponent \
             H = 4 - D in (0, 1]), got 4"
        );
        assert!(err("fractal:9,dim=2.99").ends_with("got 2.99"));
        assert_eq!(
            err("fractal:9,sigma=0"),
            "fractal:9,sigma=0: sigma must be between 1e-30 and 1e30 (the field is stored \
             as 32-bit floats), got 0"
        );
        // Past f32's range the field would be all infinities or zeros.
        assert!(err("fractal:5,sigma=1e300").contains("sigma must be between"));
        assert!(err("fractal:5,sigma=1e-31").contains("sigma must be between"));
        for sigma in [1e-30, 1e30] {
            let p = FractalParams {
                size: 5,
                sigma,
                ..FractalParams::default()
            };
            let v = generate(&p).unwrap();
            assert!(v.count_non_finite() == 0, "sigma {sigma}");
        }
        assert_eq!(
            err("fractal:9,ramp=0"),
            "fractal:9,ramp=0: ramp must be above 0 and at most 1 (a fraction of the half \
             width), got 0"
        );
        assert!(err("fractal:9,ramp=1.5").ends_with("got 1.5"));
        assert_eq!(
            err("fractal:9,threshold=1"),
            "fractal:9,threshold=1: threshold must be at least 0 and below 1 (on the field \
             scaled to [0, 1]), got 1"
        );
        assert!(err("fractal:9,threshold=-0.1").ends_with("got -0.1"));
        assert_eq!(
            err("fractal:9,dim=nan"),
            "fractal:9,dim=nan: dim must be a finite number, got `nan`"
        );
        assert_eq!(
            err("fractal:9,raw=yes"),
            "fractal:9,raw=yes: raw must be true or false, got `yes`"
        );
        assert_eq!(
            err("fractal:9,seed=-1"),
            "fractal:9,seed=-1: seed must be a non-negative integer, got `-1`"
        );
        assert!(matches!(
            generate_spec("fractal:9,dimension=3.5"),
            Err(DataError::UnknownKey { .. })
        ));
        // The library entry point validates too, naming the parameters.
        let bad = FractalParams {
            dimension: f64::NAN,
            size: 9,
            ..FractalParams::default()
        };
        assert_eq!(
            generate(&bad).unwrap_err().to_string(),
            "fractal:9,seed=1,dim=NaN,sigma=1,ramp=0.3,threshold=0.45: dimension must be at \
             least 3 and below 4 (Hurst exponent H = 4 - D in (0, 1]), got NaN"
        );
        for size in [3, 5, 1025] {
            let p = FractalParams {
                size,
                ..FractalParams::default()
            };
            assert!(p.validate().is_ok(), "{size}");
        }
    }

    #[test]
    fn geometry_is_the_unit_cube() {
        let v = generate_spec("fractal:9").unwrap();
        assert_eq!(v.dims(), [9, 9, 9]);
        assert_eq!(v.origin(), DVec3::splat(-1.0));
        assert_eq!(v.spacing(), DVec3::splat(0.25));
        assert_eq!(v.count_non_finite(), 0);
    }
}
