//! Probability densities `|ψ_nlm|²` of the hydrogen atom, the paper's first
//! test data (Ramesh & Athithan 1993, errata 2, 3, 5, 6), sampled exactly
//! and normalised.
//!
//! # The state
//!
//! ```text
//! ψ_nlm(r, θ, φ) = R_nl(r) · Y_lm(θ, φ),   1 ≤ n ≤ 12, 0 ≤ l < n, |m| ≤ l
//! R_nl(r)  = N_nl e^(−ρ/2) ρ^l ₁F₁(−(n − l − 1); 2l + 2; ρ),   ρ = 2r/(n a₀)
//! Y_lm     = N_lm P_l^m(cos θ) e^(imφ),   P_l^m(z) = (−1)^m C (1 − z²)^(m/2) T_(l−m)^m(z)
//! ```
//!
//! - [`radial`]: `R_nl` by the paper's confluent hypergeometric series, term
//!   by term, with the exact normalisation; where the alternating series
//!   cancels (near the radial nodes, and for n ≳ 6 over most of the
//!   oscillatory region: it loses up to three digits by n = 12) the
//!   Laguerre three-term recurrence takes over. The module docs give the
//!   criterion and the measured errors.
//! - [`angular`]: `P_l^m` by the Morse–Feshbach T-series (again with the
//!   upward recurrence where the series cancels, which matters for l ≳ 6),
//!   the complex `Y_lm` (Condon–Shortley phase) and the real harmonics
//!   `S_lm` of chemistry (p_x, p_y, d_xy, …; `real = true`). Public for
//!   surface renderings of `|Y_lm|²` (the paper's figure 1c).
//! - [`extent`]: the default cube half width, the radius holding 99.5% of
//!   the radial probability, by bisection on the exact radial CDF (its
//!   polynomial-times-exponential integral done exactly by
//!   [`gauss_laguerre`] quadrature).
//! - [`orbital`]: `ψ` at Cartesian points, without trigonometry:
//!   `sin^m θ e^(imφ) = ((x + iy)/r)^m`, `cos θ = z/r`.
//!
//! Lengths are in Bohr radii `a₀`, densities in `a₀^(−3)`, so that
//! `∫|ψ|² dV = 1`: the grid sum `Σ|ψ|² ΔV` over a cube that holds the
//! orbital is ≈ 1 (the tests check it).
//!
//! # The grid
//!
//! `grid` = N points per side over `[−R, R]³`, point `i` at `−R + 2R·i/(N − 1)`
//! (computed as in [`grid::coordinate`], exactly mirror symmetric), spacing
//! `2R/(N − 1)`, origin `(−R, −R, −R)`, values `|ψ|²` as `f32`. `R` is
//! `extent`, by default [`default_extent`]`(n, l)`. Slices along z are
//! computed in parallel; every value depends only on its position, so the
//! result is identical for any thread count.
//!
//! # Source spec
//!
//! `hydrogen[:N[,L[,M]]][,grid=G][,extent=R][,real=true|false]`, e.g.
//! `hydrogen:6,2,1` (the paper's Table 1 state, errata 5). `N`, `L`, `M`
//! default to 1, 0, 0 (the ground state), `grid` to 50 (the paper's), `real`
//! to false.
//!
//! ```
//! use volray_data::hydrogen::{HydrogenParams, generate};
//!
//! let params = HydrogenParams { n: 2, l: 1, m: 0, grid: 33, extent: None, real: false };
//! let volume = generate(&params)?;
//! assert_eq!(volume.dims(), [33, 33, 33]);
//! // 2p_z vanishes in the plane z = 0 (the centre slice of an odd grid).
//! assert_eq!(volume.get(5, 20, 16), 0.0);
//! assert_eq!(volume, volray_data::generate("hydrogen:2,1,0,grid=33")?);
//! # Ok::<(), volray_data::DataError>(())
//! ```

pub mod angular;
pub mod extent;
pub mod gauss_laguerre;
pub mod orbital;
pub mod radial;

use std::fmt;

use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::{Args, DataError, SourceInfo, SourceSpec, grid};

pub use angular::{Complex, SphericalHarmonic, real_orbital_label};
pub use extent::default_extent;
pub use orbital::Orbital;
pub use radial::{MAX_N, Radial};

/// Points per side when the spec gives no `grid`: the paper's 50³.
pub const DEFAULT_GRID: usize = 50;

/// The registry entry.
pub const INFO: SourceInfo = SourceInfo {
    name: "hydrogen",
    usage: "hydrogen[:N[,L[,M]]][,grid=G][,extent=R][,real=true|false]",
    description: "hydrogen-atom density |psi_nlm|^2 (a0^-3) on [-R,R]^3 in a0, R holding 99.5% \
                  unless extent=R; N,L,M default 1,0,0, grid 50 (the paper's); \
                  real=true for p_x, d_xy, ...",
    build,
};

fn build(spec: &SourceSpec) -> Result<Volume, DataError> {
    generate(&HydrogenParams::from_spec(spec)?)
}

/// A hydrogen state and the grid to sample its density on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HydrogenParams {
    /// Principal quantum number, `1 ≤ n ≤ 12`.
    pub n: u32,
    /// Angular momentum quantum number, `0 ≤ l < n`.
    pub l: u32,
    /// Magnetic quantum number, `|m| ≤ l`.
    pub m: i32,
    /// Points per side, 2..=1025.
    pub grid: usize,
    /// Half width `R` of the cube `[−R, R]³` in `a₀`, finite and > 0;
    /// `None` for [`default_extent`].
    pub extent: Option<f64>,
    /// The real orbital `R_nl S_lm` (p_x, d_xy, …) instead of the complex
    /// `R_nl Y_lm`.
    pub real: bool,
}

impl Default for HydrogenParams {
    /// The ground state 1s on the paper's 50³ grid with the default extent.
    fn default() -> Self {
        HydrogenParams {
            n: 1,
            l: 0,
            m: 0,
            grid: DEFAULT_GRID,
            extent: None,
            real: false,
        }
    }
}

/// The canonical spec, e.g. `hydrogen:6,2,1,grid=50` (with `extent=` and
/// `real=true` when set), which parses back to the same parameters.
impl fmt::Display for HydrogenParams {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{},{},{},grid={}",
            INFO.name, self.n, self.l, self.m, self.grid
        )?;
        if let Some(extent) = self.extent {
            write!(f, ",extent={extent}")?;
        }
        if self.real {
            f.write_str(",real=true")?;
        }
        Ok(())
    }
}

/// The rules on `(n, l, m)`, on wide integers so that spec values are
/// checked before they are narrowed.
fn check_state(n: i64, l: i64, m: i64) -> Result<(), String> {
    radial::check_n_l(n, l)?;
    angular::check_l_m(l, m)
}

fn check_extent(extent: Option<f64>) -> Result<(), String> {
    match extent {
        Some(r) if !(r.is_finite() && r > 0.0) => {
            Err(format!("extent must be finite and > 0, got {r}"))
        }
        _ => Ok(()),
    }
}

impl HydrogenParams {
    /// Checks `1 ≤ n ≤ 12`, `0 ≤ l < n`, `|m| ≤ l`, `2 ≤ grid ≤ 1025` and a
    /// finite positive extent; the error names the spec and the rule.
    pub fn validate(&self) -> Result<(), DataError> {
        check_state(self.n.into(), self.l.into(), self.m.into())
            .and_then(|()| grid::check_points(self.grid))
            .and_then(|()| check_extent(self.extent))
            .map_err(DataError::invalid(self))
    }

    /// The cube's half width: `extent`, or [`default_extent`] for the state.
    pub fn resolved_extent(&self) -> Result<f64, DataError> {
        self.validate()?;
        Ok(self
            .extent
            .unwrap_or_else(|| default_extent(self.n, self.l)))
    }

    /// The state, ready to evaluate.
    pub fn orbital(&self) -> Result<Orbital, DataError> {
        self.validate()?;
        Orbital::new(self.n, self.l, self.m, self.real).map_err(DataError::invalid(self))
    }

    /// Reads `hydrogen[:N[,L[,M]]][,grid=G][,extent=R][,real=true|false]`
    /// (`N`, `L`, `M` may also be given as `n=`, `l=`, `m=`) and checks it.
    pub fn from_spec(spec: &SourceSpec) -> Result<Self, DataError> {
        let args = Args::new(spec, &["n", "l", "m"], &["grid", "extent", "real"])?;
        let n = args.i64("n")?.unwrap_or(1);
        let l = args.i64("l")?.unwrap_or(0);
        let m = args.i64("m")?.unwrap_or(0);
        check_state(n, l, m).map_err(DataError::invalid(spec))?;
        let narrow = "checked by check_state";
        let params = HydrogenParams {
            n: u32::try_from(n).expect(narrow),
            l: u32::try_from(l).expect(narrow),
            m: i32::try_from(m).expect(narrow),
            grid: args.usize_or("grid", DEFAULT_GRID)?,
            extent: args.f64("extent")?,
            real: args.bool_or("real", false)?,
        };
        grid::check_points(params.grid)
            .and_then(|()| check_extent(params.extent))
            .map_err(DataError::invalid(spec))?;
        Ok(params)
    }
}

/// `ψ_nlm(x, y, z)` in `a₀^(−3/2)` at a point in `a₀` (the real orbital when
/// `params.real`). For many points build an [`Orbital`] once instead.
pub fn psi(params: &HydrogenParams, x: f64, y: f64, z: f64) -> Result<Complex, DataError> {
    Ok(params.orbital()?.psi(DVec3::new(x, y, z)))
}

/// `|ψ_nlm(x, y, z)|²` in `a₀^(−3)` at a point in `a₀`.
pub fn density(params: &HydrogenParams, x: f64, y: f64, z: f64) -> Result<f64, DataError> {
    Ok(params.orbital()?.density(DVec3::new(x, y, z)))
}

/// The density `|ψ|²` on `grid³` points over `[−R, R]³` (module docs).
pub fn generate(params: &HydrogenParams) -> Result<Volume, DataError> {
    let orbital = params.orbital()?;
    let extent = params.resolved_extent()?;
    grid::cube_volume(&params.to_string(), params.grid, extent, |p| {
        orbital.density(p)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_defaults_and_round_trip() {
        let parse = |s: &str| HydrogenParams::from_spec(&SourceSpec::parse(s).unwrap()).unwrap();
        assert_eq!(parse("hydrogen"), HydrogenParams::default());
        let p = parse("hydrogen:6,2,-1,grid=33,extent=40.5,real=true");
        assert_eq!(
            p,
            HydrogenParams {
                n: 6,
                l: 2,
                m: -1,
                grid: 33,
                extent: Some(40.5),
                real: true
            }
        );
        assert_eq!(
            p.to_string(),
            "hydrogen:6,2,-1,grid=33,extent=40.5,real=true"
        );
        assert_eq!(parse(&p.to_string()), p);
        assert_eq!(parse("hydrogen:n=3,m=-1,l=2"), parse("hydrogen:3,2,-1"));
        assert_eq!(
            parse("hydrogen:3"),
            HydrogenParams {
                n: 3,
                ..Default::default()
            }
        );
        assert!(!parse("hydrogen:2,1,real=false").real);
        assert_eq!(
            HydrogenParams::default().to_string(),
            "hydrogen:1,0,0,grid=50"
        );
    }
}
