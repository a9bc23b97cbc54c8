//! The polar mesh: a star-shaped surface `r = r(θ, φ)` about the origin,
//! sampled on a regular (θ, φ) grid and triangulated.
//!
//! The grid has `theta_steps` cells in `θ ∈ [0, π]` and `phi_steps` cells in
//! `φ ∈ [0, 2π)`: rows `θ_i = iπ/theta_steps`, columns
//! `φ_j = 2πj/phi_steps`. Each pole is one vertex (`r(0, 0)` and `r(π, 0)`),
//! joined to the first and last rings by triangle fans; the cells between
//! rings are split along their shorter diagonal. Column `phi_steps` wraps to
//! column 0, so the seam and the poles share vertices with their neighbours
//! and the mesh has no cracks.
//!
//! # Normals
//!
//! The surface is the zero set of `F(x) = |x| − r(θ(x), φ(x))`, so its normal
//! is `∇F`; times `r`, in the spherical basis `(u, e_θ, e_φ)`,
//!
//! ```text
//! n = r·u − (∂r/∂θ)·e_θ − (∂r/∂φ)/sin θ · e_φ
//! ```
//!
//! (equivalently `∂P/∂θ × ∂P/∂φ / (r sin θ)` for `P = r·u`), which points
//! outwards. The derivatives are central differences of `r` with steps of
//! 10⁻⁴ of a cell, directions past a pole reflected (`(−θ, φ) = (θ, φ + π)`).
//! Each ring vertex takes this exact normal. Where it is undefined — at the
//! poles (`sin θ = 0`) and where the surface passes through the origin
//! (`r = 0`, e.g. the nodal cones of `|Y_lm|²`) — each triangle takes the
//! limit of the exact normal as the corner is approached from inside the
//! triangle (evaluated 1/100 of the way from the corner to the triangle's
//! centre in (θ, φ)), or the triangle's own plane if that too is undefined.
//! Where these limits agree around the vertex (within 1°: a smooth pole) the
//! vertex gets their average, shared by all its triangles, so shading stays
//! continuous; where they do not (a cusp, such as the pole of `|Y_11|²`,
//! a spike along the axis whose normals all point towards it), each triangle keeps
//! its own.

use std::f64::consts::PI;

use glam::DVec3;
use rayon::prelude::*;

use crate::SurfaceError;

/// The largest grid accepted, in cells (each cell makes two triangles).
pub const MAX_CELLS: usize = 1 << 20;

/// Derivative step, as a fraction of a cell.
const DERIVATIVE_STEP: f64 = 1e-4;
/// How far towards a triangle's centre its corner's limit normal is taken.
const LIMIT_FRACTION: f64 = 0.01;
/// Limit normals around a vertex closer than this to their mean (cos 1°)
/// are averaged into one vertex normal.
const AGREEMENT: f64 = 0.999_847_7;
/// A normal shorter than this times the largest radius is undefined.
const DEGENERATE: f64 = 1e-12;

/// One triangle: indices of its corners into [`PolarSurface::vertices`]
/// and of their normals into [`PolarSurface::normals`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Triangle {
    pub vertices: [u32; 3],
    pub normals: [u32; 3],
}

/// A triangle under construction: its vertex indices and their (θ, φ).
type Corners = ([u32; 3], [(f64, f64); 3]);

/// A closed star-shaped surface `r = r(θ, φ)` about the origin (θ polar
/// from +z, φ azimuth from +x), as a triangle mesh with unit normals.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarSurface {
    vertices: Vec<DVec3>,
    /// Unit normals; the zero vector where none can be found (a triangle
    /// that is a point or a segment), which the shading lights by its
    /// ambient term only.
    normals: Vec<DVec3>,
    triangles: Vec<Triangle>,
    max_radius: f64,
}

/// `r` at any (θ, φ), θ reflected into [0, π].
fn radius_at<R: Fn(f64, f64) -> f64>(r: &R, theta: f64, phi: f64) -> f64 {
    if theta < 0.0 {
        r(-theta, phi + PI)
    } else if theta > PI {
        r(2.0 * PI - theta, phi + PI)
    } else {
        r(theta, phi)
    }
}

/// The point at `(θ, φ)` on the sphere of radius `radius`.
fn point(radius: f64, theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    radius * DVec3::new(st * cp, st * sp, ct)
}

/// The exact outward unit normal at `(θ, φ)` (not a pole), `None` where it
/// is undefined (see the module docs).
fn exact_normal<R: Fn(f64, f64) -> f64>(
    r: &R,
    theta: f64,
    phi: f64,
    steps: (f64, f64),
    scale: f64,
) -> Option<DVec3> {
    let (h_theta, h_phi) = steps;
    let radius = radius_at(r, theta, phi);
    let r_theta =
        (radius_at(r, theta + h_theta, phi) - radius_at(r, theta - h_theta, phi)) / (2.0 * h_theta);
    let r_phi =
        (radius_at(r, theta, phi + h_phi) - radius_at(r, theta, phi - h_phi)) / (2.0 * h_phi);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    let u = DVec3::new(st * cp, st * sp, ct);
    let e_theta = DVec3::new(ct * cp, ct * sp, -st);
    let e_phi = DVec3::new(-sp, cp, 0.0);
    let n = radius * u - r_theta * e_theta - (r_phi / st) * e_phi;
    let length = n.length();
    (length.is_finite() && length > DEGENERATE * scale).then(|| n / length)
}

/// The unit normal of the plane through `corners`, turned away from the
/// origin; zero for a degenerate triangle.
fn face_normal(corners: [DVec3; 3]) -> DVec3 {
    let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
    let n = if n.dot(corners[0] + corners[1] + corners[2]) < 0.0 {
        -n
    } else {
        n
    };
    n.try_normalize().unwrap_or(DVec3::ZERO)
}

impl PolarSurface {
    /// Samples `r` on a (θ, φ) grid of `theta_steps` × `phi_steps` cells and
    /// triangulates it (poles as fans, no cracks), with normals from the
    /// exact surface (see the module docs).
    ///
    /// Refuses grids with fewer than 2 × 3 cells or more than
    /// [`MAX_CELLS`], a sample of `r` that is negative or not finite (the
    /// error names the first such (θ, φ) in grid order), and an `r` that is 0
    /// at every sample.
    pub fn new(
        r: impl Fn(f64, f64) -> f64 + Sync,
        theta_steps: usize,
        phi_steps: usize,
    ) -> Result<Self, SurfaceError> {
        if theta_steps < 2 || phi_steps < 3 {
            return Err(SurfaceError::TooFewSteps {
                theta_steps,
                phi_steps,
            });
        }
        if theta_steps
            .checked_mul(phi_steps)
            .is_none_or(|cells| cells > MAX_CELLS)
        {
            return Err(SurfaceError::TooManySteps {
                theta_steps,
                phi_steps,
                limit: MAX_CELLS,
            });
        }
        let d_theta = PI / theta_steps as f64;
        let d_phi = 2.0 * PI / phi_steps as f64;
        let rings = theta_steps - 1;
        let north = 0usize;
        let south = 1 + rings * phi_steps;
        let vertex_count = south + 1;
        // The (θ, φ) of each vertex; the poles' φ is arbitrary.
        let param = |v: usize| -> (f64, f64) {
            match v {
                0 => (0.0, 0.0),
                v if v == south => (PI, 0.0),
                v => {
                    let (i, j) = ((v - 1) / phi_steps + 1, (v - 1) % phi_steps);
                    (i as f64 * d_theta, j as f64 * d_phi)
                }
            }
        };

        let radii: Vec<f64> = (0..vertex_count)
            .into_par_iter()
            .map(|v| {
                let (theta, phi) = param(v);
                r(theta, phi)
            })
            .collect();
        if let Some(v) = radii.iter().position(|&x| !(x.is_finite() && x >= 0.0)) {
            let (theta, phi) = param(v);
            return Err(SurfaceError::BadRadius {
                theta,
                phi,
                value: radii[v],
            });
        }
        let max_radius = radii.iter().copied().fold(0.0, f64::max);
        if max_radius == 0.0 {
            return Err(SurfaceError::NoSurface);
        }
        let vertices: Vec<DVec3> = (0..vertex_count)
            .map(|v| {
                let (theta, phi) = param(v);
                point(radii[v], theta, phi)
            })
            .collect();

        let steps = (DERIVATIVE_STEP * d_theta, DERIVATIVE_STEP * d_phi);
        let vertex_normals: Vec<Option<DVec3>> = (0..vertex_count)
            .into_par_iter()
            .map(|v| {
                if v == north || v == south {
                    return None;
                }
                let (theta, phi) = param(v);
                exact_normal(&r, theta, phi, steps, max_radius)
            })
            .collect();

        // Triangles with the (θ, φ) of their corners, φ unwrapped across the
        // seam so that each triangle's centre lies inside it.
        let ring = |i: usize, j: usize| (1 + (i - 1) * phi_steps + j % phi_steps) as u32;
        let mut corners: Vec<Corners> = Vec::with_capacity(2 * theta_steps * phi_steps);
        for j in 0..phi_steps {
            let (p0, p1) = (j as f64 * d_phi, (j + 1) as f64 * d_phi);
            let middle = 0.5 * (p0 + p1);
            corners.push((
                [north as u32, ring(1, j), ring(1, j + 1)],
                [(0.0, middle), (d_theta, p0), (d_theta, p1)],
            ));
            let last = rings as f64 * d_theta;
            corners.push((
                [ring(rings, j), south as u32, ring(rings, j + 1)],
                [(last, p0), (PI, middle), (last, p1)],
            ));
        }
        for i in 1..rings {
            let (t0, t1) = (i as f64 * d_theta, (i + 1) as f64 * d_theta);
            for j in 0..phi_steps {
                let (p0, p1) = (j as f64 * d_phi, (j + 1) as f64 * d_phi);
                let (a, b, c, d) = (
                    ring(i, j),
                    ring(i, j + 1),
                    ring(i + 1, j),
                    ring(i + 1, j + 1),
                );
                let (pa, pb, pc, pd) = ((t0, p0), (t0, p1), (t1, p0), (t1, p1));
                let position = |k: u32| vertices[k as usize];
                if position(a).distance_squared(position(d))
                    <= position(b).distance_squared(position(c))
                {
                    corners.push(([a, c, d], [pa, pc, pd]));
                    corners.push(([a, d, b], [pa, pd, pb]));
                } else {
                    corners.push(([a, c, b], [pa, pc, pb]));
                    corners.push(([b, c, d], [pb, pc, pd]));
                }
            }
        }
        // Triangles that are a point or a segment cover no pixel.
        corners.retain(|(v, _)| {
            let p = v.map(|k| vertices[k as usize]);
            (p[1] - p[0]).cross(p[2] - p[0]) != DVec3::ZERO
        });

        // Limit normals of the corners at vertices without an exact normal.
        let limits: Vec<[Option<DVec3>; 3]> = corners
            .par_iter()
            .map(|(v, params)| {
                let centre = (
                    (params[0].0 + params[1].0 + params[2].0) / 3.0,
                    (params[0].1 + params[1].1 + params[2].1) / 3.0,
                );
                let face = face_normal(v.map(|k| vertices[k as usize]));
                std::array::from_fn(|k| {
                    vertex_normals[v[k] as usize].is_none().then(|| {
                        let (theta, phi) = params[k];
                        exact_normal(
                            &r,
                            theta + LIMIT_FRACTION * (centre.0 - theta),
                            phi + LIMIT_FRACTION * (centre.1 - phi),
                            steps,
                            max_radius,
                        )
                        .unwrap_or(face)
                    })
                })
            })
            .collect();
        let mut around: Vec<Vec<DVec3>> = vec![Vec::new(); vertex_count];
        for ((v, _), limit) in corners.iter().zip(&limits) {
            for k in 0..3 {
                if let Some(n) = limit[k] {
                    around[v[k] as usize].push(n);
                }
            }
        }
        let shared: Vec<Option<DVec3>> = vertex_normals
            .iter()
            .zip(&around)
            .map(|(exact, limits)| {
                exact.or_else(|| {
                    let mean = limits.iter().sum::<DVec3>().try_normalize()?;
                    limits
                        .iter()
                        .all(|n| n.dot(mean) >= AGREEMENT)
                        .then_some(mean)
                })
            })
            .collect();

        let mut normals: Vec<DVec3> = shared.iter().map(|n| n.unwrap_or(DVec3::ZERO)).collect();
        let triangles = corners
            .iter()
            .zip(&limits)
            .map(|((v, _), limit)| Triangle {
                vertices: *v,
                normals: std::array::from_fn(|k| match (shared[v[k] as usize], limit[k]) {
                    (None, Some(own)) => {
                        normals.push(own);
                        (normals.len() - 1) as u32
                    }
                    _ => v[k],
                }),
            })
            .collect();
        Ok(PolarSurface {
            vertices,
            normals,
            triangles,
            max_radius,
        })
    }

    /// The largest sampled radius: the mesh lies inside the ball of this
    /// radius about the origin.
    pub fn max_radius(&self) -> f64 {
        self.max_radius
    }

    /// The mesh's vertices (world positions).
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// Unit normals (or zero, see [`PolarSurface`]), indexed by [`Triangle::normals`].
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// The triangles, each with its corners' vertex and normal indices.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_has_radial_normals_and_euler_characteristic_two() {
        let s = PolarSurface::new(|_, _| 2.0, 12, 24).unwrap();
        assert_eq!(s.max_radius(), 2.0);
        // V − E + F = 2 for a closed mesh without cracks: E = 3F/2.
        let (v, f) = (s.vertices().len() as i64, s.triangles().len() as i64);
        assert_eq!(v, 2 + 11 * 24);
        assert_eq!(f, 2 * 24 * 11);
        assert_eq!(v - 3 * f / 2 + f, 2);
        for t in s.triangles() {
            for k in 0..3 {
                let p = s.vertices()[t.vertices[k] as usize];
                let n = s.normals()[t.normals[k] as usize];
                assert!((p.length() - 2.0).abs() < 1e-12);
                assert!((n - p / 2.0).length() < 1e-6, "{p} {n}");
            }
        }
        // The poles' limit normals agree: one shared normal each, no extras.
        assert_eq!(s.normals().len(), s.vertices().len());
    }

    #[test]
    fn every_edge_is_shared_by_two_triangles() {
        // Closed and crack-free: each undirected edge appears exactly twice.
        let s = PolarSurface::new(|t, p| 1.0 + 0.3 * t.cos() * p.sin(), 7, 9).unwrap();
        let mut edges = std::collections::HashMap::new();
        for t in s.triangles() {
            for k in 0..3 {
                let (a, b) = (t.vertices[k], t.vertices[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2));
    }

    #[test]
    fn normals_of_an_ellipsoid_match_its_gradient() {
        // x²/a² + y²/b² + z²/c² = 1: r(θ, φ) = 1/√(sin²θ cos²φ/a² + sin²θ sin²φ/b² + cos²θ/c²),
        // normal ∝ (x/a², y/b², z/c²).
        let (a, b, c) = (1.0, 2.0, 0.5);
        let r = move |t: f64, p: f64| {
            let (st, ct) = t.sin_cos();
            let (sp, cp) = p.sin_cos();
            1.0 / ((st * cp / a).powi(2) + (st * sp / b).powi(2) + (ct / c).powi(2)).sqrt()
        };
        let s = PolarSurface::new(r, 16, 32).unwrap();
        for t in s.triangles() {
            for k in 0..3 {
                let p = s.vertices()[t.vertices[k] as usize];
                let expect = DVec3::new(p.x / (a * a), p.y / (b * b), p.z / (c * c)).normalize();
                let n = s.normals()[t.normals[k] as usize];
                assert!((n - expect).length() < 1e-6, "{p}: {n} vs {expect}");
            }
        }
    }

    #[test]
    fn a_cusp_at_the_pole_keeps_one_normal_per_triangle() {
        // r = sin²θ (|Y_11|² up to a constant) meets the origin at both
        // poles; near them z ≈ θ², ρ ≈ θ³: a spike along the axis, whose
        // outward limit normal is horizontal, towards the axis (the inside
        // is the region away from the axis), at the triangle's φ.
        let s = PolarSurface::new(|t, _| t.sin().powi(2), 8, 12).unwrap();
        let mut seen = 0;
        for t in s.triangles() {
            for k in 0..3 {
                if t.vertices[k] != 0 {
                    continue;
                }
                seen += 1;
                let n = s.normals()[t.normals[k] as usize];
                let others: DVec3 = (0..3)
                    .filter(|&i| i != k)
                    .map(|i| s.vertices()[t.vertices[i] as usize])
                    .sum();
                let radial = DVec3::new(others.x, others.y, 0.0).normalize();
                assert!(n.z.abs() < 0.02 && n.dot(radial) < -0.999, "{n} {radial}");
            }
        }
        assert_eq!(seen, 12);
    }

    #[test]
    fn degenerate_input_is_refused() {
        assert_eq!(
            PolarSurface::new(|_, _| 1.0, 0, 8),
            Err(SurfaceError::TooFewSteps {
                theta_steps: 0,
                phi_steps: 8
            })
        );
        assert!(matches!(
            PolarSurface::new(|_, _| 1.0, 8, 2),
            Err(SurfaceError::TooFewSteps { .. })
        ));
        assert!(matches!(
            PolarSurface::new(|_, _| 1.0, 1 << 12, 1 << 12),
            Err(SurfaceError::TooManySteps { .. })
        ));
        assert!(matches!(
            PolarSurface::new(|_, _| 1.0, usize::MAX, 3),
            Err(SurfaceError::TooManySteps { .. })
        ));
        let err = PolarSurface::new(|t, _| if t > 1.0 { f64::NAN } else { 1.0 }, 4, 4).unwrap_err();
        // The first bad sample in grid order: row 2, θ = π/2.
        assert!(
            matches!(err, SurfaceError::BadRadius { theta, phi, value }
                if theta == PI / 2.0 && phi == 0.0 && value.is_nan()),
            "{err}"
        );
        assert_eq!(
            err.to_string(),
            "r(θ = 1.570796, φ = 0.000000) = NaN: the radius must be finite and >= 0"
        );
        assert!(matches!(
            PolarSurface::new(|_, p| p.cos(), 4, 4),
            Err(SurfaceError::BadRadius { value, .. }) if value < 0.0
        ));
        assert!(matches!(
            PolarSurface::new(|_, _| f64::INFINITY, 4, 4),
            Err(SurfaceError::BadRadius { .. })
        ));
        assert_eq!(
            PolarSurface::new(|_, _| 0.0, 4, 4),
            Err(SurfaceError::NoSurface)
        );
    }
}
