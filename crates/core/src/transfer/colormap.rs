//! Named colour maps (`--colormap`): the colour half of a transfer
//! function, as a [`PiecewiseLinear`] over the normalised scalar `t`.
//!
//! `viridis`, `magma`, `inferno`, `plasma` and `cividis` (matplotlib's
//! perceptually uniform maps) and `turbo` come from the `colorous` crate's
//! tables; `coolwarm` is Moreland's diverging map, ParaView's default
//! "Cool to Warm": blue (0.230, 0.299, 0.754) through grey 0.865 to red
//! (0.706, 0.016, 0.150), interpolated in Moreland's Msh space
//! (K. Moreland, "Diverging Color Maps for Scientific Visualization",
//! ISVC 2009); `grey` is black to white. The maps' published values are
//! display (sRGB-encoded) values; volray uses them as its colours, as
//! matplotlib, ParaView and VTK do. Each map is sampled at
//! [`SAMPLES`] points and interpolated linearly in between, which stays
//! within 1/255 of the continuous map (2/255 of `colorous`'s evaluations,
//! which are rounded to 8 bits and wobble by a level between its table
//! entries).

use crate::transfer::function::PiecewiseLinear;

/// Samples per map: enough that linear interpolation between them stays
/// within a quantisation level of the continuous map (tested).
pub const SAMPLES: usize = 129;

/// The names `--colormap` accepts.
pub const NAMES: [&str; 8] = [
    "viridis", "magma", "inferno", "plasma", "cividis", "turbo", "coolwarm", "grey",
];

/// The colour map called `name`, or `None` (`gray` is accepted for `grey`).
pub fn colormap(name: &str) -> Option<PiecewiseLinear<3>> {
    let eval: fn(f64) -> [f64; 3] = match name {
        "viridis" => |t| from_colorous(colorous::VIRIDIS, t),
        "magma" => |t| from_colorous(colorous::MAGMA, t),
        "inferno" => |t| from_colorous(colorous::INFERNO, t),
        "plasma" => |t| from_colorous(colorous::PLASMA, t),
        "cividis" => |t| from_colorous(colorous::CIVIDIS, t),
        "turbo" => |t| from_colorous(colorous::TURBO, t),
        "coolwarm" => cool_warm,
        "grey" | "gray" => |t| [t, t, t],
        _ => return None,
    };
    Some(sample(eval))
}

fn sample(eval: impl Fn(f64) -> [f64; 3]) -> PiecewiseLinear<3> {
    let points = (0..SAMPLES)
        .map(|i| {
            let t = i as f64 / (SAMPLES - 1) as f64;
            let c = eval(t);
            (t as f32, [c[0] as f32, c[1] as f32, c[2] as f32])
        })
        .collect();
    PiecewiseLinear::new("color", points).expect("sampled maps are sorted and in [0, 1]")
}

fn from_colorous(g: colorous::Gradient, t: f64) -> [f64; 3] {
    let c = g.eval_continuous(t);
    [c.r, c.g, c.b].map(|v| f64::from(v) / 255.0)
}

/// ParaView's "Cool to Warm": three control points interpolated in Msh.
fn cool_warm(t: f64) -> [f64; 3] {
    const COOL: [f64; 3] = [0.23137254902, 0.298039215686, 0.752941176471];
    const GREY: [f64; 3] = [0.865, 0.865, 0.865];
    const WARM: [f64; 3] = [0.705882352941, 0.0156862745098, 0.149019607843];
    if t <= 0.5 {
        msh::interpolate(COOL, GREY, 2.0 * t)
    } else {
        msh::interpolate(GREY, WARM, 2.0 * t - 1.0)
    }
}

/// Moreland's Msh colour space (polar CIELAB) and his diverging
/// interpolation, after the paper's reference code.
mod msh {
    use std::f64::consts::PI;

    /// D65 white in XYZ.
    const WHITE: [f64; 3] = [0.95047, 1.0, 1.08883];

    fn to_linear(c: f64) -> f64 {
        if c > 0.04045 {
            ((c + 0.055) / 1.055).powf(2.4)
        } else {
            c / 12.92
        }
    }

    fn to_srgb(c: f64) -> f64 {
        if c > 0.0031308 {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        } else {
            12.92 * c
        }
    }

    fn lab_f(t: f64) -> f64 {
        if t > 0.008856 {
            t.cbrt()
        } else {
            7.787 * t + 16.0 / 116.0
        }
    }

    fn lab_f_inv(t: f64) -> f64 {
        if t > 0.206893 {
            t * t * t
        } else {
            (t - 16.0 / 116.0) / 7.787
        }
    }

    pub fn rgb_to_msh(rgb: [f64; 3]) -> [f64; 3] {
        let [r, g, b] = rgb.map(to_linear);
        let x = 0.4124 * r + 0.3576 * g + 0.1805 * b;
        let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        let z = 0.0193 * r + 0.1192 * g + 0.9505 * b;
        let (fx, fy, fz) = (
            lab_f(x / WHITE[0]),
            lab_f(y / WHITE[1]),
            lab_f(z / WHITE[2]),
        );
        let (l, a, bb) = (116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz));
        let m = (l * l + a * a + bb * bb).sqrt();
        let s = if m > 0.0 {
            (l / m).clamp(-1.0, 1.0).acos()
        } else {
            0.0
        };
        let h = if s > 0.0 { bb.atan2(a) } else { 0.0 };
        [m, s, h]
    }

    pub fn msh_to_rgb([m, s, h]: [f64; 3]) -> [f64; 3] {
        let l = m * s.cos();
        let a = m * s.sin() * h.cos();
        let b = m * s.sin() * h.sin();
        let fy = (l + 16.0) / 116.0;
        let (fx, fz) = (fy + a / 500.0, fy - b / 200.0);
        let x = WHITE[0] * lab_f_inv(fx);
        let y = WHITE[1] * lab_f_inv(fy);
        let z = WHITE[2] * lab_f_inv(fz);
        let r = 3.2406 * x - 1.5372 * y - 0.4986 * z;
        let g = -0.9689 * x + 1.8758 * y + 0.0415 * z;
        let bl = 0.0557 * x - 0.2040 * y + 1.0570 * z;
        [r, g, bl].map(|c| to_srgb(c).clamp(0.0, 1.0))
    }

    /// The hue to give an unsaturated colour next to a saturated one.
    fn adjust_hue([m, s, h]: [f64; 3], m_unsat: f64) -> f64 {
        if m >= m_unsat {
            return h;
        }
        let spin = s * (m_unsat * m_unsat - m * m).sqrt() / (m * s.sin());
        if h > -PI / 3.0 { h + spin } else { h - spin }
    }

    /// Moreland's diverging interpolation from `a` (t = 0) to `b` (t = 1).
    pub fn interpolate(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
        let (mut c1, mut c2) = (rgb_to_msh(a), rgb_to_msh(b));
        let mut t = t;
        // Two saturated colours of distant hues pass through white.
        if c1[1] > 0.05 && c2[1] > 0.05 && (c1[2] - c2[2]).abs() > PI / 3.0 {
            let mid = c1[0].max(c2[0]).max(88.0);
            if t < 0.5 {
                c2 = [mid, 0.0, 0.0];
                t *= 2.0;
            } else {
                c1 = [mid, 0.0, 0.0];
                t = 2.0 * t - 1.0;
            }
        }
        if c1[1] < 0.05 && c2[1] > 0.05 {
            c1[2] = adjust_hue(c2, c1[0]);
        } else if c2[1] < 0.05 && c1[1] > 0.05 {
            c2[2] = adjust_hue(c1, c2[0]);
        }
        let lerp = |i: usize| c1[i] + t * (c2[i] - c1[i]);
        msh_to_rgb([lerp(0), lerp(1), lerp(2)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (f64::from(a[i]) - b[i]).abs() <= tol)
    }

    #[test]
    fn every_name_gives_a_map_and_unknown_names_none() {
        for name in NAMES {
            let map = colormap(name).unwrap();
            assert_eq!(map.points().len(), SAMPLES, "{name}");
        }
        assert!(colormap("gray").is_some());
        assert!(colormap("jet").is_none());
    }

    #[test]
    fn published_end_points() {
        // matplotlib's viridis runs from #440154 to #fde725; magma from
        // #000004 to #fcfdbf; grey from black to white.
        let v = colormap("viridis").unwrap();
        assert!(close(
            v.eval(0.0),
            [68.0 / 255.0, 1.0 / 255.0, 84.0 / 255.0],
            1.5 / 255.0
        ));
        assert!(close(
            v.eval(1.0),
            [253.0 / 255.0, 231.0 / 255.0, 37.0 / 255.0],
            1.5 / 255.0
        ));
        let m = colormap("magma").unwrap();
        assert!(close(m.eval(0.0), [0.0, 0.0, 4.0 / 255.0], 1.5 / 255.0));
        assert!(close(
            m.eval(1.0),
            [252.0 / 255.0, 253.0 / 255.0, 191.0 / 255.0],
            1.5 / 255.0
        ));
        let g = colormap("grey").unwrap();
        assert!(close(g.eval(0.3), [0.3; 3], 1e-6));
    }

    #[test]
    fn cool_warm_is_paraviews_map() {
        let c = colormap("coolwarm").unwrap();
        assert!(close(c.eval(0.0), [0.2314, 0.2980, 0.7529], 1e-3));
        assert!(close(c.eval(0.5), [0.865; 3], 1e-3));
        assert!(close(c.eval(1.0), [0.7059, 0.0157, 0.1490], 1e-3));
        // Lightness rises to the middle and falls symmetrically (Moreland's
        // design): compare L* of mirrored points.
        let lightness = |t: f32| {
            msh::rgb_to_msh(c.eval(t).map(f64::from))[0]
                * msh::rgb_to_msh(c.eval(t).map(f64::from))[1].cos()
        };
        for t in [0.1, 0.25, 0.4] {
            assert!(lightness(t) < lightness(t + 0.05), "{t}");
            assert!((lightness(t) - lightness(1.0 - t)).abs() < 3.0, "{t}");
        }
        // Msh round trip.
        for rgb in [[0.2, 0.5, 0.9], [0.9, 0.1, 0.1], [0.5, 0.5, 0.5]] {
            let back = msh::msh_to_rgb(msh::rgb_to_msh(rgb));
            assert!(
                (0..3).all(|i| (back[i] - rgb[i]).abs() < 1e-3),
                "{rgb:?} {back:?}"
            );
        }
    }

    #[test]
    fn sampling_stays_within_a_level_of_the_continuous_map() {
        for name in ["viridis", "turbo", "coolwarm"] {
            let map = colormap(name).unwrap();
            let exact: fn(f64) -> [f64; 3] = match name {
                "viridis" => |t| from_colorous(colorous::VIRIDIS, t),
                "turbo" => |t| from_colorous(colorous::TURBO, t),
                _ => cool_warm,
            };
            // colorous rounds its evaluations to 8 bits, and between its
            // table entries they wobble by a level: allow two.
            let tol = if name == "coolwarm" { 1.0 } else { 2.0 } / 255.0;
            for i in 0..=1000 {
                let t = i as f64 / 1000.0;
                assert!(close(map.eval(t as f32), exact(t), tol), "{name} at {t}");
            }
        }
    }
}
