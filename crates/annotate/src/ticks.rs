//! Round numbers for axes: tick values over a window (1, 2 or 5 times a
//! power of ten apart, or whole decades on a log scale), a round length
//! for a scale bar, and numbers written as short as their spacing allows.

/// The spacing of about `count` ticks over `span` > 0: 1, 2 or 5 times a
/// power of ten, the one nearest to `span / count` on a log scale.
pub fn nice_step(span: f64, count: usize) -> f64 {
    let raw = span / count.max(1) as f64;
    let power = 10f64.powf(raw.log10().floor());
    let candidates = [1.0, 2.0, 5.0, 10.0].map(|m| m * power);
    *(candidates.iter())
        .min_by(|a, b| {
            let d = |x: f64| (x.log10() - raw.log10()).abs();
            d(**a).total_cmp(&d(**b))
        })
        .expect("four candidates")
}

/// Ticks over `[lo, hi]`: about `count` multiples of a [`nice_step`]
/// (with the step), or, on a log scale (`lo > 0`), the powers of ten
/// within it (and the step 0).
pub fn ticks(lo: f64, hi: f64, count: usize, log: bool) -> (Vec<f64>, f64) {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return (vec![lo], 0.0);
    }
    if log && lo > 0.0 {
        let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
        let every = ((b - a) / count.max(1) as i32).max(1);
        let decades: Vec<f64> = (a..=b)
            .filter(|k| (k - a) % every == 0)
            .map(|k| 10f64.powi(k))
            .collect();
        if decades.len() >= 2 {
            return (decades, 0.0);
        }
    }
    let step = nice_step(hi - lo, count);
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    ((first..=last).map(|k| k as f64 * step).collect(), step)
}

/// `value` written for a tick `step` apart from its neighbours: as many
/// decimals as the step needs, in scientific notation for very large or
/// small magnitudes (`1e-4`, `2.5e6`), and `0` for a rounding error of it.
pub fn label(value: f64, step: f64) -> String {
    let magnitude = value.abs();
    if step > 0.0 && magnitude < step * 1e-6 {
        return "0".into();
    }
    if magnitude != 0.0 && !(1e-3..1e5).contains(&magnitude) {
        let text = format!("{value:.1e}");
        // 1.0e-4 → 1e-4
        return text.replace(".0e", "e");
    }
    let decimals = if step > 0.0 {
        (-step.log10().floor()).max(0.0) as usize
    } else {
        // A lone value: three significant digits.
        (2 - magnitude.log10().floor() as i64).clamp(0, 6) as usize
    };
    let text = format!("{value:.decimals$}");
    // A minus sign, not a hyphen.
    text.replacen('-', "−", 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_window() {
        let (t, step) = ticks(-1000.0, 3000.0, 5, false);
        assert_eq!(step, 1000.0);
        assert_eq!(t, [-1000.0, 0.0, 1000.0, 2000.0, 3000.0]);
        let (t, step) = ticks(0.013, 0.087, 4, false);
        assert!((step - 0.02).abs() < 1e-12, "{step}");
        assert_eq!(t.len(), 4);
        assert!(t.iter().all(|v| (0.013..=0.087).contains(v)));
        let (t, _) = ticks(1e-4, 1.0, 5, true);
        assert_eq!(t, [1e-4, 1e-3, 1e-2, 1e-1, 1.0]);
    }

    #[test]
    fn labels_are_as_short_as_the_spacing_allows() {
        assert_eq!(label(2000.0, 1000.0), "2000");
        assert_eq!(label(-1000.0, 1000.0), "−1000");
        assert_eq!(label(0.04, 0.02), "0.04");
        assert_eq!(label(0.25, 0.05), "0.25");
        assert_eq!(label(1e-4, 0.0), "1e-4");
        assert_eq!(label(2.5e6, 5e5), "2.5e6");
        assert_eq!(label(1e-17, 0.1), "0");
        assert_eq!(label(4.56789, 0.0), "4.57");
    }

    #[test]
    fn a_nice_step_is_one_two_or_five_times_a_power_of_ten() {
        for (span, count, want) in [
            (10.0, 5, 2.0),
            (1.0, 10, 0.1),
            (7.0, 2, 5.0),
            (300.0, 4, 100.0),
        ] {
            assert!(
                (nice_step(span, count) - want).abs() < 1e-12,
                "{span} {count}"
            );
        }
    }
}
