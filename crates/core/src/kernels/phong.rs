//! Shading: the paper's Phong colour model, per voxel or per sample.
//!
//! `C_β = C_s,β·k_a,β + C_s,β·[k_d,β (N·L) + k_s,β (N·H)^n]` with
//! `H = (V + L)/|V + L|` (Ramesh & Athithan 1993, after Levoy 1988), where
//! `N` is the unit gradient (see [`crate::kernels::gradient`]), `L` the unit direction
//! towards a light at infinity, `V` the unit direction towards the viewer
//! and `C_s` the light's colour. The material colour from the transfer
//! function multiplies the lit colour; with the default white material the
//! paper's model is exact.
//!
//! **Two-sided lighting.** A gradient points towards *increasing* values,
//! which is into a dense object, so its sign says nothing about which side
//! faces the viewer. As is usual for volumes (VTK's two-sided lighting), the
//! normal is first turned to face the viewer (`N := −N` when `N·V < 0`);
//! then a light behind that surface contributes nothing: `N·L < 0` is
//! clamped to 0, and so is the highlight. With the default headlight
//! (`L = V`) every visible surface is lit from the front.
//!
//! **Zero gradient.** Where `|∇f| = 0` the normal is undefined (errata 1):
//! such voxels get the ambient term only.
//!
//! **One copy.** The model is written once, over [`Lanes`]: [`two_sided`]
//! (the diffuse and highlight terms from the normal's dot products) and
//! [`reflect`] (`ka + kd·diffuse + ks·highlight`), with the highlight's
//! [`Exponent`]. [`Phong::shade`] calls them on one gradient (the reference
//! path, post-classified samples, the surface renderer of Figure 1c); the
//! fast path's lighting calls them on four quantised normals at a time,
//! with `C_s` multiplied into the coefficients once per frame.

use crate::kernels::lanes::Lanes;
use glam::Vec3;

/// Phong reflection coefficients and the light, per colour channel (r, g, b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phong {
    pub ambient: [f32; 3],
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
    /// The highlight exponent `n`.
    pub shininess: f32,
    /// `C_s`, the colour of the light source.
    pub light_color: [f32; 3],
}

impl Default for Phong {
    /// ka 0.1, kd 0.7, ks 0.2, n 10 and a white light: the coefficients add
    /// up to 1, so a surface facing the headlight is exactly white.
    fn default() -> Self {
        Phong {
            ambient: [0.1; 3],
            diffuse: [0.7; 3],
            specular: [0.2; 3],
            shininess: 10.0,
            light_color: [1.0; 3],
        }
    }
}

/// The light and viewer directions of one frame, and the half vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightGeometry {
    /// Unit vector towards the light (at infinity).
    pub to_light: Vec3,
    /// Unit vector towards the viewer (orthographic: the same for every voxel).
    pub to_viewer: Vec3,
    /// `H = (V + L)/|V + L|`; zero when the light is exactly behind the viewer's
    /// line of sight, where no highlight can be seen.
    pub half: Vec3,
}

impl LightGeometry {
    pub fn new(to_light: Vec3, to_viewer: Vec3) -> Self {
        let to_light = to_light.normalize();
        let to_viewer = to_viewer.normalize();
        LightGeometry {
            to_light,
            to_viewer,
            half: (to_light + to_viewer).normalize_or_zero(),
        }
    }

    /// A light at the eye: `L = V`.
    pub fn headlight(to_viewer: Vec3) -> Self {
        Self::new(to_viewer, to_viewer)
    }
}

impl Phong {
    /// The lit colour (before the material colour multiplies it) of a voxel
    /// with world-space gradient `gradient`.
    #[inline]
    pub fn shade(&self, gradient: Vec3, light: &LightGeometry) -> [f32; 3] {
        self.shade_reached(gradient, light, Reaching::ALL)
    }

    /// [`Self::shade`] where only the parts `reaching` of the light and of
    /// the ambient light arrive: the light's (shadows) scales
    /// the diffuse and specular terms, the ambient light's (ambient
    /// occlusion) the ambient term.
    #[inline]
    pub fn shade_reached(
        &self,
        gradient: Vec3,
        light: &LightGeometry,
        reaching: Reaching,
    ) -> [f32; 3] {
        let len = gradient.length();
        let (diffuse, highlight) = if len > 0.0 && len.is_finite() {
            let n = gradient / len;
            two_sided(
                n.dot(light.to_viewer),
                n.dot(light.to_light),
                n.dot(light.half),
                Exponent::new(self.shininess),
            )
        } else {
            (0.0, 0.0)
        };
        let (diffuse, highlight) = (diffuse * reaching.light, highlight * reaching.light);
        std::array::from_fn(|c| {
            self.light_color[c]
                * reflect(
                    self.ambient[c] * reaching.ambient,
                    self.diffuse[c],
                    self.specular[c],
                    diffuse,
                    highlight,
                )
        })
    }
}

/// How much of the light and of the ambient light reaches a point, each
/// in `[0, 1]`: the light through the volume towards it (shadows) and
/// the mean over short rays around it (ambient occlusion).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reaching {
    pub light: f32,
    pub ambient: f32,
}

impl Reaching {
    /// All of both: shading as without shadows or ambient occlusion
    /// (multiplying by 1 changes no bit).
    pub const ALL: Reaching = Reaching {
        light: 1.0,
        ambient: 1.0,
    };
}

/// The colour of a voxel or a sample: the lit colour of its `gradient`
/// under `lighting` ([`Phong::shade`]; white where unlit) times its
/// `material` colour, clamped to [0, 1].
#[inline]
pub fn lit_colour(
    lighting: Option<(&Phong, &LightGeometry)>,
    gradient: Vec3,
    material: [f32; 3],
) -> [f32; 3] {
    lit_colour_reached(lighting, gradient, material, Reaching::ALL)
}

/// [`lit_colour`] where only the parts `reaching` of the light and the
/// ambient light arrive ([`Phong::shade_reached`]). Unlit, the material
/// colour is the light from everywhere, and the ambient part scales it.
#[inline]
pub fn lit_colour_reached(
    lighting: Option<(&Phong, &LightGeometry)>,
    gradient: Vec3,
    material: [f32; 3],
    reaching: Reaching,
) -> [f32; 3] {
    let lit = match lighting {
        Some((phong, light)) => Vec3::from(phong.shade_reached(gradient, light, reaching)),
        None => Vec3::splat(reaching.ambient),
    };
    (lit * Vec3::from(material))
        .clamp(Vec3::ZERO, Vec3::ONE)
        .to_array()
}

/// The two-sided Phong terms `(max(N·L, 0), max(N·H, 0)^n)` of a normal
/// `N` from its dot products with the viewer `V`, the light `L` and the
/// half vector `H` (any common scale): the normal is first turned to face
/// the viewer, and where the light is behind the surface (`N·L ≤ 0`) there
/// is no highlight. A zero normal gets `(0, 0)`: ambient light only.
#[inline(always)]
pub fn two_sided<T: Lanes>(n_dot_v: T, n_dot_l: T, n_dot_h: T, exponent: Exponent) -> (T, T) {
    let facing = n_dot_v.facing();
    let diffuse = (n_dot_l * facing).max_zero();
    let highlight = diffuse.where_positive(|| exponent.raise((n_dot_h * facing).max_zero()));
    (diffuse, highlight)
}

/// One channel of the reflected light, `ka + kd·diffuse + ks·highlight`
/// (the light's colour `Cs` is in the coefficients, or multiplies after).
#[inline(always)]
pub fn reflect<T: Lanes>(ka: T, kd: T, ks: T, diffuse: T, highlight: T) -> T {
    ka + kd * diffuse + ks * highlight
}

/// The highlight exponent `n`: whole numbers up to 1024 by repeated
/// squaring (several times faster than `powf`; relative error below about
/// `n·2⁻²³`, as `x`'s own rounding is raised to the `n`), any other by
/// `powf`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exponent {
    Whole(u32),
    Real(f32),
}

impl Exponent {
    pub fn new(n: f32) -> Self {
        if n.fract() == 0.0 && (0.0..=1024.0).contains(&n) {
            Exponent::Whole(n as u32)
        } else {
            Exponent::Real(n)
        }
    }

    /// `x^n` for `x` in [0, 1].
    #[inline(always)]
    pub fn raise<T: Lanes>(self, x: T) -> T {
        match self {
            Exponent::Whole(mut n) => {
                let (mut result, mut power) = (T::ONE, x);
                while n > 0 {
                    if n & 1 == 1 {
                        result = result * power;
                    }
                    power = power * power;
                    n >>= 1;
                }
                result
            }
            Exponent::Real(n) => x.powf(n),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-6)
    }

    #[test]
    fn facing_the_headlight_is_white() {
        let light = LightGeometry::headlight(Vec3::X);
        let phong = Phong::default();
        assert!(close(
            phong.shade(Vec3::new(2.0, 0.0, 0.0), &light),
            [1.0; 3]
        ));
        // The same surface seen from its back (gradient into the object) is
        // lit the same: two-sided lighting.
        assert!(close(
            phong.shade(Vec3::new(-5.0, 0.0, 0.0), &light),
            [1.0; 3]
        ));
    }

    #[test]
    fn closed_form_at_an_oblique_angle() {
        // N at 60° from V = L: N·L = N·H = 0.5.
        let light = LightGeometry::headlight(Vec3::Z);
        let n = Vec3::new(3f32.sqrt() / 2.0, 0.0, 0.5);
        let phong = Phong {
            ambient: [0.1, 0.2, 0.0],
            diffuse: [0.7, 0.5, 0.3],
            specular: [0.2, 0.1, 0.6],
            shininess: 3.0,
            light_color: [1.0, 0.5, 2.0],
        };
        let expect = |c: usize| {
            phong.light_color[c]
                * (phong.ambient[c] + phong.diffuse[c] * 0.5 + phong.specular[c] * 0.125)
        };
        assert!(close(
            phong.shade(n * 4.0, &light),
            [expect(0), expect(1), expect(2)]
        ));
    }

    #[test]
    fn light_behind_the_surface_leaves_only_ambient() {
        // Viewer on +z, light on −z: the surface facing the viewer is unlit.
        let light = LightGeometry::new(-Vec3::Z, Vec3::Z);
        assert_eq!(light.half, Vec3::ZERO);
        assert!(close(Phong::default().shade(Vec3::Z, &light), [0.1; 3]));
    }

    #[test]
    fn zero_gradient_gets_ambient_only() {
        let light = LightGeometry::headlight(Vec3::Y);
        assert!(close(Phong::default().shade(Vec3::ZERO, &light), [0.1; 3]));
    }

    #[test]
    fn half_vector_between_light_and_viewer() {
        // Light along x, viewer along y: H at 45°; a normal along H gets
        // the full highlight and diffuse cos 45°.
        let light = LightGeometry::new(Vec3::X, Vec3::Y);
        let n = Vec3::new(1.0, 1.0, 0.0);
        let c = Phong::default().shade(n, &light);
        let expect = 0.1 + 0.7 * std::f32::consts::FRAC_1_SQRT_2 + 0.2;
        assert!(close(c, [expect; 3]), "{c:?}");
    }

    #[test]
    fn the_exponent_is_powf_for_whole_and_real_exponents() {
        for n in [0.0f32, 1.0, 2.0, 7.0, 10.0, 64.0, 1000.0, 7.5, 0.3] {
            for i in 0..=64 {
                let x = i as f32 / 64.0;
                let (got, want) = (Exponent::new(n).raise(x), x.powf(n));
                assert!(
                    (got - want).abs() <= (n.max(1.0) * 1.2e-7 + 1e-6) * want + 1e-37,
                    "{x}^{n}: {got} vs {want}"
                );
            }
        }
        assert_eq!(Exponent::new(0.0).raise(0.0f32), 1.0);
    }
}
