//! Colours between keyframes, mixed in OKLab (Björn Ottosson, "A
//! perceptual color space for image processing", 2020,
//! <https://bottosson.github.io/posts/oklab/>): equal steps of the mix
//! look like equal steps of colour, and a fade between two saturated
//! colours does not pass through the grey that mixing sRGB values gives.
//! volray's colours (`--background`, `--light-color`, a transfer
//! function's) are sRGB values in [0, 1].

/// sRGB's transfer function undone (IEC 61966-2-1): display value to
/// linear light.
fn to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light to an sRGB display value.
fn from_linear(c: f64) -> f64 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// An sRGB colour (values in [0, 1]) in OKLab (L, a, b); Ottosson's
/// matrices.
pub fn to_oklab(rgb: [f32; 3]) -> [f64; 3] {
    let [r, g, b] = rgb.map(|c| to_linear(f64::from(c)));
    let l = 0.412_221_470_8 * r + 0.536_332_536_3 * g + 0.051_445_992_9 * b;
    let m = 0.211_903_498_2 * r + 0.680_699_545_1 * g + 0.107_396_956_6 * b;
    let s = 0.088_302_461_9 * r + 0.281_718_837_6 * g + 0.629_978_700_5 * b;
    let [l, m, s] = [l.cbrt(), m.cbrt(), s.cbrt()];
    [
        0.210_454_255_3 * l + 0.793_617_785_0 * m - 0.004_072_046_8 * s,
        1.977_998_495_1 * l - 2.428_592_205_0 * m + 0.450_593_709_9 * s,
        0.025_904_037_1 * l + 0.782_771_766_2 * m - 0.808_675_766_0 * s,
    ]
}

/// An OKLab colour back in sRGB, clamped to [0, 1].
pub fn from_oklab([l, a, b]: [f64; 3]) -> [f32; 3] {
    let l_ = l + 0.396_337_777_4 * a + 0.215_803_757_3 * b;
    let m_ = l - 0.105_561_345_8 * a - 0.063_854_172_8 * b;
    let s_ = l - 0.089_484_177_5 * a - 1.291_485_548_0 * b;
    let [l, m, s] = [l_ * l_ * l_, m_ * m_ * m_, s_ * s_ * s_];
    let r = 4.076_741_662_1 * l - 3.307_711_591_3 * m + 0.230_969_929_2 * s;
    let g = -1.268_438_004_6 * l + 2.609_757_401_1 * m - 0.341_319_396_5 * s;
    let b = -0.004_196_086_3 * l - 0.703_418_614_7 * m + 1.707_614_701_0 * s;
    [r, g, b].map(|c| from_linear(c).clamp(0.0, 1.0) as f32)
}

/// The colour a fraction `s` of the way from `a` to `b`, mixed in OKLab;
/// exactly `a` at 0 and `b` at 1 (and where they are equal), so a
/// keyframe's colour is the colour its flag gives.
pub fn mix(a: [f32; 3], b: [f32; 3], s: f64) -> [f32; 3] {
    if a == b || s <= 0.0 {
        return a;
    }
    if s >= 1.0 {
        return b;
    }
    let (p, q) = (to_oklab(a), to_oklab(b));
    from_oklab([0, 1, 2].map(|i| p[i] + (q[i] - p[i]) * s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_and_black_are_oklabs_ends_and_colours_survive_the_round_trip() {
        // Ottosson's reference values: white is L = 1, a = b = 0.
        let white = to_oklab([1.0, 1.0, 1.0]);
        assert!((white[0] - 1.0).abs() < 1e-4 && white[1].abs() < 1e-4 && white[2].abs() < 1e-4);
        assert_eq!(to_oklab([0.0; 3]), [0.0; 3]);
        for rgb in [[0.2, 0.5, 0.9], [1.0, 0.0, 0.0], [0.0, 1.0, 0.3]] {
            let back = from_oklab(to_oklab(rgb));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-4, "{rgb:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn a_mix_holds_its_ends_and_greys_stay_grey() {
        let (red, blue) = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(mix(red, blue, 0.0), red);
        assert_eq!(mix(red, blue, 1.0), blue);
        // Half way between black and white in OKLab is L = 0.5, whose
        // sRGB grey is (0.5³ linear) = 0.125 → 0.3896 (sRGB encoded).
        let grey = mix([0.0; 3], [1.0; 3], 0.5);
        let expect = from_linear(0.125) as f32;
        for c in grey {
            assert!((c - expect).abs() < 1e-3, "{grey:?} vs {expect}");
        }
    }
}
