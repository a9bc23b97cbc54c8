//! The hydrogen densities against closed forms, an independent
//! recurrence-based evaluation, node counts, normalisation and symmetry
//! (issue 3). Grids stay small so the suite stays fast.

use std::f64::consts::{FRAC_1_SQRT_2, PI, SQRT_2};

use volray_core::glam::DVec3;
use volray_data::DataError;
use volray_data::Volume;
use volray_data::hydrogen::{
    Complex, HydrogenParams, Orbital, Radial, SphericalHarmonic, default_extent, density, generate,
    psi,
};

/// SplitMix64: a small, seeded, portable generator for test points.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A point uniform in the cube [−h, h]³.
    fn in_cube(&mut self, h: f64) -> DVec3 {
        DVec3::new(
            self.uniform(-h, h),
            self.uniform(-h, h),
            self.uniform(-h, h),
        )
    }

    /// A point at a radius uniform in [0, r_max), direction uniform on the
    /// sphere (more points near the nucleus than `in_cube`).
    fn in_shells(&mut self, r_max: f64) -> DVec3 {
        let r = self.uniform(0.0, r_max);
        let z = self.uniform(-1.0, 1.0);
        let phi = self.uniform(-PI, PI);
        let s = (1.0 - z * z).sqrt();
        r * DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

fn params(n: u32, l: u32, m: i32, real: bool) -> HydrogenParams {
    HydrogenParams {
        n,
        l,
        m,
        real,
        ..Default::default()
    }
}

fn orbital(n: u32, l: u32, m: i32, real: bool) -> Orbital {
    params(n, l, m, real).orbital().unwrap()
}

/// Relative difference of two complex values, against the larger.
fn rel_diff(a: Complex, b: Complex) -> f64 {
    let d = Complex::new(a.re - b.re, a.im - b.im).abs();
    d / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

// ---------------------------------------------------------------------------
// Closed forms (Griffiths, Introduction to Quantum Mechanics, tables 4.3 and
// 4.7; Pauling & Wilson), in units of a₀, with the Condon–Shortley phase.

#[test]
fn low_states_match_closed_forms_with_phase() {
    type Closed = fn(DVec3) -> Complex;
    let cases: Vec<(u32, u32, i32, Closed)> = vec![
        (1, 0, 0, |p| {
            Complex::new((-p.length()).exp() / PI.sqrt(), 0.0)
        }),
        (2, 0, 0, |p| {
            let r = p.length();
            Complex::new(
                (2.0 - r) * (-r / 2.0).exp() / (4.0 * (2.0 * PI).sqrt()),
                0.0,
            )
        }),
        (2, 1, 0, |p| {
            Complex::new(
                p.z * (-p.length() / 2.0).exp() / (4.0 * (2.0 * PI).sqrt()),
                0.0,
            )
        }),
        (2, 1, 1, |p| {
            let a = -(-p.length() / 2.0).exp() / (8.0 * PI.sqrt());
            Complex::new(a * p.x, a * p.y)
        }),
        (2, 1, -1, |p| {
            let a = (-p.length() / 2.0).exp() / (8.0 * PI.sqrt());
            Complex::new(a * p.x, -a * p.y)
        }),
        (3, 0, 0, |p| {
            let r = p.length();
            let a = (27.0 - 18.0 * r + 2.0 * r * r) * (-r / 3.0).exp();
            Complex::new(a / (81.0 * (3.0 * PI).sqrt()), 0.0)
        }),
        (3, 2, 0, |p| {
            let r2 = p.length_squared();
            let a = (3.0 * p.z * p.z - r2) * (-p.length() / 3.0).exp();
            Complex::new(a / (81.0 * (6.0 * PI).sqrt()), 0.0)
        }),
        (3, 2, 1, |p| {
            let a = -p.z * (-p.length() / 3.0).exp() / (81.0 * PI.sqrt());
            Complex::new(a * p.x, a * p.y)
        }),
        (3, 2, -1, |p| {
            let a = p.z * (-p.length() / 3.0).exp() / (81.0 * PI.sqrt());
            Complex::new(a * p.x, -a * p.y)
        }),
        (3, 2, 2, |p| {
            let a = (-p.length() / 3.0).exp() / (162.0 * PI.sqrt());
            Complex::new(a * (p.x * p.x - p.y * p.y), a * 2.0 * p.x * p.y)
        }),
        (3, 2, -2, |p| {
            let a = (-p.length() / 3.0).exp() / (162.0 * PI.sqrt());
            Complex::new(a * (p.x * p.x - p.y * p.y), -a * 2.0 * p.x * p.y)
        }),
    ];
    let mut rng = Rng(2024);
    for (n, l, m, closed) in cases {
        let o = orbital(n, l, m, false);
        let h = default_extent(n, l);
        // Relative to the value, plus rounding of the largest |ψ| (nodes).
        let scale = max_density(n, l, m).sqrt();
        for i in 0..500 {
            let p = if i % 2 == 0 {
                rng.in_cube(h)
            } else {
                rng.in_shells(h)
            };
            let (got, want) = (o.psi(p), closed(p));
            let diff = Complex::new(got.re - want.re, got.im - want.im).abs();
            assert!(
                diff <= 1e-13 * want.abs() + 1e-15 * scale,
                "{n}{l}{m} at {p}: {got:?} vs {want:?}"
            );
        }
    }
    // The free functions agree with Orbital.
    let p = params(3, 2, 1, false);
    assert_eq!(
        psi(&p, 0.5, -1.0, 2.0).unwrap(),
        orbital(3, 2, 1, false).psi(DVec3::new(0.5, -1.0, 2.0))
    );
    assert_eq!(
        density(&p, 0.5, -1.0, 2.0).unwrap(),
        psi(&p, 0.5, -1.0, 2.0).unwrap().norm_sqr()
    );
}

#[test]
fn real_orbitals_match_closed_forms() {
    let mut rng = Rng(7);
    let px = orbital(2, 1, 1, true);
    let py = orbital(2, 1, -1, true);
    let pz = orbital(2, 1, 0, true);
    let dxy = orbital(3, 2, -2, true);
    let dx2y2 = orbital(3, 2, 2, true);
    let dz2 = orbital(3, 2, 0, true);
    let c2p = 1.0 / (4.0 * (2.0 * PI).sqrt());
    let c3d = SQRT_2 / (81.0 * PI.sqrt());
    let scale = max_density(3, 2, 2).sqrt().max(max_density(2, 1, 1).sqrt());
    for _ in 0..500 {
        let p = rng.in_cube(15.0);
        let e2 = (-p.length() / 2.0).exp();
        let e3 = (-p.length() / 3.0).exp();
        let checks = [
            (px.psi(p), c2p * p.x * e2),
            (py.psi(p), c2p * p.y * e2),
            (pz.psi(p), c2p * p.z * e2),
            (dxy.psi(p), c3d * p.x * p.y * e3),
            (dx2y2.psi(p), c3d / 2.0 * (p.x * p.x - p.y * p.y) * e3),
            (
                dz2.psi(p),
                (3.0 * p.z * p.z - p.length_squared()) * e3 / (81.0 * (6.0 * PI).sqrt()),
            ),
        ];
        for (i, (got, want)) in checks.into_iter().enumerate() {
            assert_eq!(got.im, 0.0);
            assert!(
                (got.re - want).abs() <= 1e-13 * want.abs() + 1e-15 * scale,
                "orbital {i} at {p}: {} vs {want}",
                got.re
            );
        }
    }
}

// ---------------------------------------------------------------------------
// An independent evaluation: associated Laguerre polynomials by their
// three-term recurrence, associated Legendre functions by the standard upward
// recurrence in m then l, normalisations from factorials in f64, angles from
// atan2 and trigonometry.

fn factorial(n: u32) -> f64 {
    (1..=n).map(f64::from).product()
}

fn oracle_laguerre(k: u32, alpha: f64, x: f64) -> f64 {
    let (mut l0, mut l1) = (1.0, 1.0 + alpha - x);
    if k == 0 {
        return l0;
    }
    for j in 1..k {
        let j = f64::from(j);
        let l2 = ((2.0 * j + 1.0 + alpha - x) * l1 - (j + alpha) * l0) / (j + 1.0);
        (l0, l1) = (l1, l2);
    }
    l1
}

fn oracle_radial(n: u32, l: u32, r: f64) -> f64 {
    let nf = f64::from(n);
    let norm = ((2.0 / nf).powi(3) * factorial(n - l - 1) / (2.0 * nf * factorial(n + l))).sqrt();
    let rho = 2.0 * r / nf;
    norm * (-rho / 2.0).exp()
        * rho.powi(l as i32)
        * oracle_laguerre(n - l - 1, f64::from(2 * l + 1), rho)
}

/// `P_l^m(x)`, `m ≥ 0`, Condon–Shortley phase (Numerical Recipes `plgndr`).
fn oracle_legendre(l: u32, m: u32, x: f64) -> f64 {
    let s = ((1.0 - x) * (1.0 + x)).sqrt();
    let mut pmm = 1.0;
    for i in 1..=m {
        pmm *= -f64::from(2 * i - 1) * s;
    }
    if l == m {
        return pmm;
    }
    let mut pmmp1 = x * f64::from(2 * m + 1) * pmm;
    for ll in m + 2..=l {
        let pll =
            (x * f64::from(2 * ll - 1) * pmmp1 - f64::from(ll + m - 1) * pmm) / f64::from(ll - m);
        pmm = pmmp1;
        pmmp1 = pll;
    }
    pmmp1
}

fn oracle_psi(n: u32, l: u32, m: i32, real: bool, p: DVec3) -> Complex {
    let r = p.length();
    let theta = if r > 0.0 {
        (p.z / r).clamp(-1.0, 1.0).acos()
    } else {
        0.0
    };
    let phi = p.y.atan2(p.x);
    let am = m.unsigned_abs();
    let norm = (f64::from(2 * l + 1) / (4.0 * PI) * factorial(l - am) / factorial(l + am)).sqrt();
    let p_lm = oracle_legendre(l, am, theta.cos());
    let radial = oracle_radial(n, l, r);
    let cs = if am % 2 == 1 { -1.0 } else { 1.0 };
    if real {
        // S_lm = √2 N |P| cos(mφ) / sin(|m|φ), |P| without the CS sign.
        let a = radial * norm * cs * p_lm;
        return Complex::new(
            match m {
                0 => a,
                m if m > 0 => SQRT_2 * a * (f64::from(am) * phi).cos(),
                _ => SQRT_2 * a * (f64::from(am) * phi).sin(),
            },
            0.0,
        );
    }
    // Y_lm = N P e^{imφ} for m ≥ 0; Y_l,−m = (−1)^m conj(Y_lm).
    let y = Complex::new(
        norm * p_lm * (f64::from(am) * phi).cos(),
        norm * p_lm * (f64::from(am) * phi).sin(),
    );
    let y = if m < 0 { y.conj().scale(cs) } else { y };
    y.scale(radial)
}

/// The state's maximum density: `|ψ|²` separates into `R(r)² |Y(θ)|²`, so
/// it is the product of the two maxima (found on fine scans).
fn max_density(n: u32, l: u32, m: i32) -> f64 {
    let reach = 2.0 * default_extent(n, l);
    let radial = (0..=20_000)
        .map(|i| oracle_radial(n, l, reach * f64::from(i) / 20_000.0).powi(2))
        .fold(0.0, f64::max);
    let am = m.unsigned_abs();
    let norm2 = f64::from(2 * l + 1) / (4.0 * PI) * factorial(l - am) / factorial(l + am);
    let angular = (0..=20_000)
        .map(|i| norm2 * oracle_legendre(l, am, (PI * f64::from(i) / 20_000.0).cos()).powi(2))
        .fold(0.0, f64::max);
    // Real orbitals peak √2² = 2 times higher where cos²(mφ) = 1.
    radial * angular * if m != 0 { 2.0 } else { 1.0 }
}

#[test]
fn every_state_up_to_n8_matches_the_recurrence_oracle() {
    // "Tiny": below 1e−8 of the state's maximum density. Above it the
    // densities agree to 1e−9 relative; the amplitudes (with their phases)
    // to 1e−9 of |ψ|.
    let mut rng = Rng(8);
    let mut checked = 0;
    for n in 1..=8u32 {
        for l in 0..n {
            let h = default_extent(n, l);
            for m in -(l as i32)..=l as i32 {
                let peak = max_density(n, l, m);
                for real in [false, true] {
                    let o = orbital(n, l, m, real);
                    for i in 0..400 {
                        let p = if i % 2 == 0 {
                            rng.in_cube(h)
                        } else {
                            rng.in_shells(h)
                        };
                        let (got, want) = (o.psi(p), oracle_psi(n, l, m, real, p));
                        let (dg, dw) = (got.norm_sqr(), want.norm_sqr());
                        if dw < 1e-8 * peak {
                            assert!(dg < 2e-8 * peak, "{n},{l},{m},{real} at {p}");
                            continue;
                        }
                        checked += 1;
                        assert!(
                            (dg - dw).abs() <= 1e-9 * dw,
                            "{n},{l},{m},{real} at {p}: |ψ|² {dg} vs {dw}"
                        );
                        assert!(
                            rel_diff(got, want) <= 1e-9,
                            "{n},{l},{m},{real} at {p}: ψ {got:?} vs {want:?}"
                        );
                    }
                }
            }
        }
    }
    // Most points are not tiny: the comparison really happened.
    assert!(checked > 204 * 2 * 400 / 3, "{checked}");
}

// ---------------------------------------------------------------------------
// Nodes.

#[test]
fn radial_functions_have_n_minus_l_minus_1_sign_changes() {
    for n in 1..=12u32 {
        for l in 0..n {
            let radial = Radial::new(n, l).unwrap();
            let reach = 1.5 * default_extent(n, l);
            let steps = 40_000;
            let mut changes = 0;
            let mut last = radial.value(1e-9);
            for i in 1..=steps {
                let v = radial.value(reach * f64::from(i) / f64::from(steps));
                if v * last < 0.0 {
                    changes += 1;
                }
                if v != 0.0 {
                    last = v;
                }
            }
            assert_eq!(changes, n - l - 1, "n={n} l={l}");
            assert_eq!(radial.nodes(), n - l - 1);
        }
    }
}

/// Interior strict local minima of `values`.
fn interior_minima(values: &[f32]) -> usize {
    values
        .windows(3)
        .filter(|w| w[1] < w[0] && w[1] < w[2])
        .count()
}

#[test]
fn radial_nodes_show_as_minima_along_a_line_in_the_grid() {
    // Odd grids have a centre voxel; walk out from it along a grid line on
    // which the angular part does not vanish: the z axis for m = 0, else
    // the x axis (l − |m| even, so P_l^m(0) ≠ 0) or the body diagonal.
    let cases = [
        (2, 0, 0),
        (3, 0, 0),
        (3, 1, 0),
        (4, 0, 0),
        (4, 1, 1),
        (4, 2, -2),
        (5, 1, 0),
        (5, 2, 1),
        (6, 2, 1),
    ];
    for (n, l, m) in cases {
        let grid = 81;
        let p = HydrogenParams {
            grid,
            ..params(n, l, m, false)
        };
        let v = generate(&p).unwrap();
        let c = grid / 2;
        let y = SphericalHarmonic::new(l, m).unwrap();
        let line: Vec<f32> = if m == 0 {
            (c..grid).map(|k| v.get(c, c, k)).collect()
        } else if (l as i32 - m.abs()) % 2 == 0 {
            assert!(y.norm_sqr(PI / 2.0) > 1e-3);
            (c..grid).map(|i| v.get(i, c, c)).collect()
        } else {
            assert!(y.norm_sqr((1.0f64 / 3f64.sqrt()).acos()) > 1e-3);
            (c..grid).map(|i| v.get(i, i, i)).collect()
        };
        assert_eq!(
            interior_minima(&line) as u32,
            n - l - 1,
            "{n},{l},{m}: {line:?}"
        );
    }
}

#[test]
fn legendre_functions_have_l_minus_m_nodal_cones() {
    for l in 0..=11u32 {
        for m in -(l as i32)..=l as i32 {
            let y = SphericalHarmonic::new(l, m).unwrap();
            let steps = 20_000;
            let mut changes = 0;
            let mut last = y.legendre((1e-7f64).cos());
            for i in 1..steps {
                let v = y.legendre((PI * f64::from(i) / f64::from(steps)).cos());
                if v * last < 0.0 {
                    changes += 1;
                }
                if v != 0.0 {
                    last = v;
                }
            }
            assert_eq!(changes, l - m.unsigned_abs(), "l={l} m={m}");
            assert_eq!(y.nodal_cones(), l - m.unsigned_abs());
        }
    }
}

#[test]
fn nodal_cones_show_in_the_grid() {
    // States without radial nodes (l = n − 1), whose R² peaks at r = n·l.
    // A grid line parallel to z at x = x0 ≥ n·l, y = 0 meets every cone once
    // (θ runs from π to 0 along it) while R² only falls away from z = 0, so
    // the density's interior minima along it are the l − |m| cones.
    for (n, l, m) in [
        (3, 2, 0),
        (3, 2, 1),
        (4, 3, 0),
        (4, 3, 1),
        (5, 4, 0),
        (5, 4, -2),
    ] {
        let grid = 61;
        let v = generate(&HydrogenParams {
            grid,
            ..params(n, l, m, false)
        })
        .unwrap();
        let c = grid / 2;
        let r_peak = f64::from(n * l);
        let i0 = (c..grid)
            .find(|&i| v.world_position(i, c, c).x >= r_peak)
            .unwrap();
        let line: Vec<f32> = (0..grid).map(|k| v.get(i0, c, k)).collect();
        assert_eq!(
            interior_minima(&line) as u32,
            l - m.unsigned_abs(),
            "{n},{l},{m}: {line:?}"
        );
    }
}

// ---------------------------------------------------------------------------
// Normalisation and symmetry.

fn grid_sum(v: &Volume) -> f64 {
    let dv = v.spacing().x.powi(3);
    v.values().iter().map(|&d| f64::from(d)).sum::<f64>() * dv
}

#[test]
fn grid_sums_are_close_to_one() {
    // Σ|ψ|²ΔV over the default cube estimates the probability inside it,
    // which lies in [0.995, 1] (the cube holds the ball of radius R, which
    // holds 99.5%). The rectangle rule adds its own error, measured below
    // 1e−3 for these states at 65³ (sums at 33³, 49³, 65³, 129³ converge
    // to 0.9985–0.9997); the paper's Table 1 state needs 129³ for that (it
    // is 0.9847 at 33³). So: within [0.995 − 1e−3, 1 + 1e−3].
    for (n, l, m, real, grid) in [
        (1, 0, 0, false, 65),
        (2, 1, 1, false, 65),
        (2, 1, 1, true, 65),
        (3, 2, -1, false, 65),
        (3, 2, -2, true, 65),
        (4, 3, 0, false, 65),
        (6, 2, 1, false, 129),
    ] {
        let v = generate(&HydrogenParams {
            grid,
            ..params(n, l, m, real)
        })
        .unwrap();
        let sum = grid_sum(&v);
        assert!(
            (0.995 - 1e-3..=1.0 + 1e-3).contains(&sum),
            "{n},{l},{m},{real}: {sum}"
        );
    }
}

#[test]
fn complex_densities_are_symmetric_about_the_z_axis() {
    let mut rng = Rng(11);
    for n in 1..=6u32 {
        for l in 0..n {
            for m in -(l as i32)..=l as i32 {
                let o = orbital(n, l, m, false);
                let h = default_extent(n, l);
                let peak = max_density(n, l, m);
                for _ in 0..50 {
                    let p = rng.in_shells(h);
                    let a = rng.uniform(-PI, PI);
                    let (s, c) = a.sin_cos();
                    let q = DVec3::new(c * p.x - s * p.y, s * p.x + c * p.y, p.z);
                    let (dp, dq) = (o.density(p), o.density(q));
                    // To rounding: relative, plus rounding of the peak
                    // (near a nodal cone the value is ill-conditioned).
                    assert!(
                        (dp - dq).abs() <= 1e-12 * dp.max(dq) + 1e-14 * peak,
                        "{n},{l},{m}: {dp} vs {dq} at {p} rotated by {a}"
                    );
                }
            }
        }
    }
    // On the grid a quarter turn maps voxels onto voxels: exactly equal.
    for (n, l, m) in [(3, 2, 1), (4, 3, -2), (2, 1, -1)] {
        let v = generate(&HydrogenParams {
            grid: 21,
            ..params(n, l, m, false)
        })
        .unwrap();
        let g = 21;
        for k in 0..g {
            for j in 0..g {
                for i in 0..g {
                    assert_eq!(v.get(i, j, k), v.get(g - 1 - j, i, k), "{i},{j},{k}");
                }
            }
        }
    }
}

#[test]
fn real_orbitals_share_the_complex_norm() {
    // S_lm² + S_l,−m² = 2 |Y_lm|² pointwise, so the pair carries the norm
    // of the complex pair; and the grid sums agree.
    let mut rng = Rng(5);
    for (n, l) in [(2, 1), (3, 2), (4, 3), (5, 2)] {
        let h = default_extent(n, l);
        for m in 1..=l as i32 {
            let (plus, minus) = (orbital(n, l, m, true), orbital(n, l, -m, true));
            let complex = orbital(n, l, m, false);
            for _ in 0..100 {
                let p = rng.in_shells(h);
                let pair = plus.density(p) + minus.density(p);
                let want = 2.0 * complex.density(p);
                assert!((pair - want).abs() <= 1e-13 * want + 1e-300, "{n},{l},{m}");
            }
        }
    }
    // On a cube large enough to hold all but ~1e−5 of either (the default
    // one holds different shares of orbitals of different shapes), the grid
    // sums agree to the rectangle rule's error (measured ≤ 1.6e−6).
    for (n, l, m) in [(2, 1, 1), (3, 2, -2), (3, 2, 1)] {
        let sum = |real| {
            grid_sum(
                &generate(&HydrogenParams {
                    grid: 65,
                    extent: Some(1.6 * default_extent(n, l)),
                    ..params(n, l, m, real)
                })
                .unwrap(),
            )
        };
        let (real, complex) = (sum(true), sum(false));
        assert!(
            (real - complex).abs() < 1e-5,
            "{n},{l},{m}: {real} vs {complex}"
        );
        assert!((real - 1.0).abs() < 1e-4, "{n},{l},{m}: {real}");
    }
}

#[test]
fn p_x_is_p_z_rotated_and_d_xy_is_d_x2y2_rotated() {
    let mut rng = Rng(3);
    let pz = orbital(3, 1, 0, true);
    let px = orbital(3, 1, 1, true);
    let py = orbital(3, 1, -1, true);
    let dxy = orbital(4, 2, -2, true);
    let dx2y2 = orbital(4, 2, 2, true);
    for _ in 0..300 {
        let p = rng.in_shells(25.0);
        let close = |a: Complex, b: Complex| rel_diff(a, b) < 1e-12 || a.abs() < 1e-200;
        // p_x(x, y, z) = p_z(y, z, x); p_y(x, y, z) = p_z(z, x, y).
        assert!(close(px.psi(p), pz.psi(DVec3::new(p.y, p.z, p.x))), "{p}");
        assert!(close(py.psi(p), pz.psi(DVec3::new(p.z, p.x, p.y))), "{p}");
        // d_xy is d_x²−y² turned by 45° about z.
        let q = DVec3::new(
            FRAC_1_SQRT_2 * (p.x - p.y),
            FRAC_1_SQRT_2 * (p.x + p.y),
            p.z,
        );
        let (a, b) = (dxy.psi(q), dx2y2.psi(p));
        assert!(
            (a.re - b.re).abs() <= 1e-12 * b.re.abs().max(1e-3 * 1e-3),
            "{p}"
        );
    }
    // On the grid, p_x is p_z with the axes permuted.
    let g = 25;
    let grid = |m| {
        generate(&HydrogenParams {
            grid: g,
            ..params(2, 1, m, true)
        })
        .unwrap()
    };
    let (vx, vz) = (grid(1), grid(0));
    for k in 0..g {
        for j in 0..g {
            for i in 0..g {
                let (a, b) = (vx.get(i, j, k), vz.get(j, k, i));
                assert!((a - b).abs() <= 1e-6 * a.abs().max(b.abs()), "{i},{j},{k}");
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The grid and the spec.

#[test]
fn grid_geometry_values_and_default_extent() {
    let p = params(3, 2, 1, false);
    let v = generate(&HydrogenParams { grid: 17, ..p }).unwrap();
    let r = default_extent(3, 2);
    assert_eq!(v.dims(), [17, 17, 17]);
    assert_eq!(v.origin(), DVec3::splat(-r));
    assert_eq!(v.spacing(), DVec3::splat(2.0 * r / 16.0));
    let o = p.orbital().unwrap();
    let mut rng = Rng(1);
    for _ in 0..200 {
        let (i, j, k) = (
            (rng.next() % 17) as usize,
            (rng.next() % 17) as usize,
            (rng.next() % 17) as usize,
        );
        let x = |i: usize| -r + 2.0 * r * i as f64 / 16.0;
        let want = o.density(DVec3::new(x(i), x(j), x(k))) as f32;
        let got = v.get(i, j, k);
        assert!((got - want).abs() <= 1e-6 * want.abs(), "{i},{j},{k}");
    }
    // An explicit extent; the paper's default grid from the spec.
    let v = generate(&HydrogenParams {
        grid: 9,
        extent: Some(12.5),
        ..p
    })
    .unwrap();
    assert_eq!(v.origin(), DVec3::splat(-12.5));
    assert_eq!(v.spacing(), DVec3::splat(25.0 / 8.0));
    let v = volray_data::generate("hydrogen:6,2,1").unwrap();
    assert_eq!(v.dims(), [50, 50, 50]);
    assert_eq!(v.origin(), DVec3::splat(-default_extent(6, 2)));
    assert_eq!(v.count_non_finite(), 0);
    assert_eq!(
        v,
        generate(&HydrogenParams {
            n: 6,
            l: 2,
            m: 1,
            ..Default::default()
        })
        .unwrap()
    );
    // At the nucleus only s states are non-zero: |ψ_100(0)|² = 1/π.
    let v = volray_data::generate("hydrogen:1,0,0,grid=5").unwrap();
    assert_eq!(v.get(2, 2, 2), (1.0 / PI) as f32);
    let v = volray_data::generate("hydrogen:2,1,1,grid=5").unwrap();
    assert_eq!(v.get(2, 2, 2), 0.0);
}

#[test]
fn same_values_for_any_thread_count() {
    let p = HydrogenParams {
        grid: 33,
        ..params(5, 3, -2, true)
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| generate(&p).unwrap())
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

#[test]
fn huge_extents_give_zeros_not_nans() {
    let v = generate(&HydrogenParams {
        grid: 3,
        extent: Some(1e200),
        ..params(4, 1, 0, false)
    })
    .unwrap();
    assert_eq!(v.count_non_finite(), 0);
    assert!(v.values().iter().all(|&d| d == 0.0));
}

#[test]
fn invalid_parameters_are_refused_with_the_rule() {
    let err = |p: HydrogenParams| p.validate().unwrap_err().to_string();
    assert_eq!(
        err(params(0, 0, 0, false)),
        "hydrogen:0,0,0,grid=50: n must satisfy 1 <= n <= 12, got n = 0"
    );
    assert_eq!(
        err(params(13, 0, 0, false)),
        "hydrogen:13,0,0,grid=50: n must satisfy 1 <= n <= 12, got n = 13"
    );
    assert_eq!(
        err(params(3, 3, 0, false)),
        "hydrogen:3,3,0,grid=50: l must satisfy 0 <= l < n = 3, got l = 3"
    );
    assert_eq!(
        err(params(3, 1, -2, true)),
        "hydrogen:3,1,-2,grid=50,real=true: m must satisfy |m| <= l = 1, got m = -2"
    );
    assert_eq!(
        err(HydrogenParams {
            grid: 1,
            ..Default::default()
        }),
        "hydrogen:1,0,0,grid=1: grid must have at least 2 points per side, got 1"
    );
    assert_eq!(
        err(HydrogenParams {
            grid: 1026,
            ..Default::default()
        }),
        "hydrogen:1,0,0,grid=1026: grid must have at most 1025 points per side, got 1026"
    );
    for bad in [0.0, -2.0, f64::NAN, f64::INFINITY] {
        let p = HydrogenParams {
            extent: Some(bad),
            ..Default::default()
        };
        assert_eq!(
            err(p),
            format!(
                "hydrogen:1,0,0,grid=50,extent={bad}: extent must be finite and > 0, got {bad}"
            )
        );
        assert!(generate(&p).is_err() && psi(&p, 0.0, 0.0, 1.0).is_err());
        assert!(p.resolved_extent().is_err());
    }
    assert!(HydrogenParams::default().validate().is_ok());
    assert!(generate(&params(13, 0, 0, false)).is_err());
    assert!(density(&params(2, 2, 0, false), 1.0, 0.0, 0.0).is_err());

    // Through the spec, naming the spec as written.
    let spec = |s: &str| volray_data::generate(s).unwrap_err().to_string();
    assert_eq!(
        spec("hydrogen:6,6,0"),
        "hydrogen:6,6,0: l must satisfy 0 <= l < n = 6, got l = 6"
    );
    assert_eq!(
        spec("hydrogen:6,2,3"),
        "hydrogen:6,2,3: m must satisfy |m| <= l = 2, got m = 3"
    );
    assert_eq!(
        spec("hydrogen:99999999999,0,0"),
        "hydrogen:99999999999,0,0: n must satisfy 1 <= n <= 12, got n = 99999999999"
    );
    assert_eq!(
        spec("hydrogen:-1"),
        "hydrogen:-1: n must satisfy 1 <= n <= 12, got n = -1"
    );
    assert_eq!(
        spec("hydrogen:6,2,1,real=yes"),
        "hydrogen:6,2,1,real=yes: real must be true or false, got `yes`"
    );
    assert_eq!(
        spec("hydrogen:6,2,1,extent=-3"),
        "hydrogen:6,2,1,extent=-3: extent must be finite and > 0, got -3"
    );
    assert_eq!(
        spec("hydrogen:6,2,1,grid=1"),
        "hydrogen:6,2,1,grid=1: grid must have at least 2 points per side, got 1"
    );
    assert_eq!(
        spec("hydrogen:6,2,1,grid=big"),
        "hydrogen:6,2,1,grid=big: grid must be a non-negative integer, got `big`"
    );
    assert!(matches!(
        volray_data::generate("hydrogen:6,2,1,seed=3").unwrap_err(),
        DataError::UnknownKey { .. }
    ));
    assert!(matches!(
        volray_data::generate("hydrogen:6,2,1,0").unwrap_err(),
        DataError::SurplusPositional { .. }
    ));
}

#[test]
#[ignore = "benchmark: run by hand with --release --nocapture"]
fn generation_speed() {
    for (n, l, m, grid) in [
        (6, 2, 1, 50),
        (6, 2, 1, 129),
        (12, 0, 0, 129),
        (3, 2, 1, 257),
    ] {
        let p = HydrogenParams {
            grid,
            ..params(n, l, m, false)
        };
        let mut times: Vec<f64> = (0..7)
            .map(|_| {
                let start = std::time::Instant::now();
                std::hint::black_box(generate(&p).unwrap());
                start.elapsed().as_secs_f64()
            })
            .collect();
        times.sort_by(f64::total_cmp);
        println!(
            "{p}: median {:.1} ms (min {:.1}, max {:.1}) on {} threads",
            1e3 * times[3],
            1e3 * times[0],
            1e3 * times[6],
            rayon::current_num_threads()
        );
    }
}
