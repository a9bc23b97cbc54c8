//! A colour bar: the transfer function's colours over its value window,
//! top (high) to bottom (low), with its opacity drawn beside it, and ticks
//! labelled in the data's units; or, for a label volume, a legend of each
//! label's colour.
//!
//! Row `r` of a bar `h` rows high, from its top row `t`, shows the value
//! `hi − (r − t)/(h − 1)·(hi − lo)` (its log10 spaced evenly on a log
//! scale), so that a tick at value `v` sits on the row nearest to `v` and
//! the bar's pixel there is the colour of a value within half a row of
//! `v`.

use crate::text::{Font, blend};
use crate::ticks::{label, ticks};
use volray_core::Image;

/// Which side of the frame a bar or legend stands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Side {
    #[default]
    Right,
    Left,
}

/// A transfer function's colour bar.
pub struct ColorBar<'a> {
    /// The values the bar spans, low to high, in the data's units.
    pub window: (f64, f64),
    /// Spaced by log10 (the window's ends must be above 0).
    pub log: bool,
    /// The colour and the opacity the transfer function gives a value.
    pub colour: &'a dyn Fn(f64) -> [f32; 3],
    pub opacity: &'a dyn Fn(f64) -> f32,
    /// The data's unit, written over the bar (`HU`, `e/Å³`).
    pub unit: Option<&'a str>,
    pub side: Side,
}

/// Where a colour bar was drawn: its box (pixels, half-open) and each
/// tick's value and row.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// The left edge of all it drew (strip, bar, ticks, labels).
    pub left: usize,
    pub bar: (usize, usize, usize, usize),
    pub ticks: Vec<(f64, usize)>,
}

/// Sizes that follow the image: text, bar width and margins scale with
/// its smaller side, so that an annotation reads alike at 240² and 4096².
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub text: f32,
    pub margin: usize,
    pub bar: usize,
    pub line: usize,
}

impl Layout {
    pub fn of(image: &Image) -> Self {
        let side = image.width().min(image.height()) as f32;
        Layout {
            text: (side / 30.0).max(10.0),
            margin: (side / 24.0).round().max(4.0) as usize,
            bar: (side / 28.0).round().max(6.0) as usize,
            line: (side / 240.0).round().max(1.0) as usize,
        }
    }
}

impl ColorBar<'_> {
    /// The value shown on row `r` of a bar of rows `top..top + h`.
    fn value(&self, r: usize, top: usize, h: usize) -> f64 {
        let (lo, hi) = self.axis();
        let f = (r - top) as f64 / (h.max(2) - 1) as f64;
        self.value_at(hi - f * (hi - lo))
    }

    /// The window on the bar's axis (log10 of it on a log scale).
    fn axis(&self) -> (f64, f64) {
        let (lo, hi) = self.window;
        if self.log {
            (lo.log10(), hi.log10())
        } else {
            (lo, hi)
        }
    }

    fn value_at(&self, a: f64) -> f64 {
        if self.log { 10f64.powf(a) } else { a }
    }

    fn to_axis(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    /// Draws the bar into `image`, its text and ticks in `ink`.
    pub fn draw(&self, image: &mut Image, ink: [f32; 3]) -> Drawn {
        let font = Font::embedded();
        let l = Layout::of(image);
        let (w, h) = (image.width(), image.height());
        let (lo, hi) = self.window;
        let (values, step) = ticks(lo, hi, 5, self.log);
        let values: Vec<f64> = values
            .into_iter()
            .filter(|v| *v >= lo && *v <= hi)
            .collect();
        let labels: Vec<String> = values.iter().map(|&v| label(v, step)).collect();
        let label_width = (labels.iter())
            .map(|t| font.measure(t, l.text).0)
            .fold(0.0f32, f32::max)
            .ceil() as usize;
        let tick = l.bar / 3;
        let block = 2 * l.bar + tick + l.line + label_width + l.text as usize / 3;
        let left = match self.side {
            Side::Right => w.saturating_sub(l.margin + block),
            Side::Left => l.margin,
        };
        // The opacity strip, then the bar.
        let (strip, bar) = (left, left + l.bar);
        let bar_h = (h as f32 * 0.6) as usize;
        let top = (h - bar_h) / 2;
        let bar_h = bar_h.max(2);
        let max_opacity = (0..bar_h)
            .map(|r| (self.opacity)(self.value(top + r, top, bar_h)))
            .fold(0.0f32, f32::max);
        for r in top..top + bar_h {
            let v = self.value(r, top, bar_h);
            let c = (self.colour)(v);
            for x in bar..bar + l.bar {
                image.set(x, r, [c[0], c[1], c[2], 1.0]);
            }
            // Opacity, relative to its largest over the window, as the
            // length of a line from the bar's side.
            let o = (self.opacity)(v);
            let length = if max_opacity > 0.0 {
                (o / max_opacity * l.bar as f32).round() as usize
            } else {
                0
            };
            for x in bar - length..bar {
                blend(image, x as i64, r as i64, ink, 0.75);
            }
            blend(image, strip as i64, r as i64, ink, 0.35);
        }
        // The frame of the bar, and the ticks with their labels.
        let right = bar + l.bar;
        for x in bar..right {
            for t in 0..l.line {
                blend(image, x as i64, top as i64 - t as i64 - 1, ink, 1.0);
                blend(image, x as i64, (top + bar_h + t) as i64, ink, 1.0);
            }
        }
        let (alo, ahi) = self.axis();
        let mut drawn = Vec::new();
        for (v, text) in values.iter().zip(&labels) {
            let f = (ahi - self.to_axis(*v)) / (ahi - alo);
            let row = top + (f * (bar_h - 1) as f64).round() as usize;
            for x in right..right + tick {
                for t in 0..l.line {
                    blend(
                        image,
                        x as i64,
                        (row + t) as i64 - (l.line / 2) as i64,
                        ink,
                        1.0,
                    );
                }
            }
            let (_, ascent, _) = font.measure(text, l.text);
            let at = (
                (right + tick + l.line) as f32 + 2.0,
                row as f32 + ascent * 0.35,
            );
            font.draw(image, text, l.text, at, ink);
            drawn.push((*v, row));
        }
        if let Some(unit) = self.unit {
            let (uw, _, descent) = font.measure(unit, l.text);
            let x = (bar + l.bar / 2) as f32 - uw / 2.0;
            let y = top as f32 - l.text * 0.5 - descent;
            font.draw(image, unit, l.text, (x.max(1.0), y), ink);
        }
        Drawn {
            left,
            bar: (bar, top, bar + l.bar, top + bar_h),
            ticks: drawn,
        }
    }
}

/// A legend of a label volume's labels: a swatch of each label's colour
/// and its name, one per line, top to bottom; its left edge.
pub fn legend(
    image: &mut Image,
    entries: &[(String, [f32; 3])],
    side: Side,
    ink: [f32; 3],
) -> usize {
    let font = Font::embedded();
    let l = Layout::of(image);
    let (w, h) = (image.width(), image.height());
    let line = (l.text * 1.4).ceil() as usize;
    // As many as fit in the frame's height.
    let shown = entries
        .len()
        .min(h.saturating_sub(2 * l.margin) / line.max(1));
    let width = (entries[..shown].iter())
        .map(|(name, _)| font.measure(name, l.text).0)
        .fold(0.0f32, f32::max)
        .ceil() as usize
        + l.bar
        + l.text as usize / 2;
    let left = match side {
        Side::Right => w.saturating_sub(l.margin + width),
        Side::Left => l.margin,
    };
    let top = (h.saturating_sub(shown * line)) / 2;
    for (i, (name, colour)) in entries[..shown].iter().enumerate() {
        let y = top + i * line;
        let swatch = (l.text * 0.8) as usize;
        for r in y..y + swatch {
            for x in left..left + swatch {
                if x < w && r < h {
                    image.set(x, r, [colour[0], colour[1], colour[2], 1.0]);
                }
            }
        }
        let at = ((left + l.bar) as f32, y as f32 + swatch as f32);
        font.draw(image, name, l.text, at, ink);
    }
    left
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth map from blue to red over [−1000, 3000] and an opacity
    /// ramp over its upper half.
    fn colour(v: f64) -> [f32; 3] {
        let t = ((v + 1000.0) / 4000.0).clamp(0.0, 1.0) as f32;
        [t, 0.2, 1.0 - t]
    }

    fn opacity(v: f64) -> f32 {
        (((v - 1000.0) / 2000.0).clamp(0.0, 1.0)) as f32
    }

    #[test]
    fn the_bars_pixel_at_each_tick_is_the_colour_of_its_value() {
        for side in [240, 1024, 4096] {
            let mut image = Image::new(side, side, [0.0, 0.0, 0.0, 1.0]);
            let bar = ColorBar {
                window: (-1000.0, 3000.0),
                log: false,
                colour: &colour,
                opacity: &opacity,
                unit: Some("HU"),
                side: Side::Right,
            };
            let drawn = bar.draw(&mut image, [1.0; 3]);
            let (x0, _, x1, _) = drawn.bar;
            assert_eq!(
                drawn.ticks.iter().map(|t| t.0).collect::<Vec<_>>(),
                [-1000.0, 0.0, 1000.0, 2000.0, 3000.0]
            );
            for &(v, row) in &drawn.ticks {
                let p = image.get((x0 + x1) / 2, row);
                let want = colour(v);
                for c in 0..3 {
                    assert!(
                        (p[c] - want[c]).abs() <= 1.0 / 255.0,
                        "{side}: {v} {p:?} {want:?}"
                    );
                }
            }
            // Higher values higher up; the bar lies in the frame.
            assert!(drawn.ticks[0].1 > drawn.ticks[4].1);
            assert!(x1 < side);
        }
    }

    #[test]
    fn a_log_bar_places_decades_evenly() {
        let mut image = Image::new(600, 600, [1.0, 1.0, 1.0, 1.0]);
        let grey = |v: f64| [(v.log10() / 4.0 + 1.0) as f32; 3];
        let bar = ColorBar {
            window: (1e-4, 1.0),
            log: true,
            colour: &grey,
            opacity: &|_| 1.0,
            unit: None,
            side: Side::Left,
        };
        let drawn = bar.draw(&mut image, [0.0; 3]);
        let rows: Vec<usize> = drawn.ticks.iter().map(|t| t.1).collect();
        assert_eq!(rows.len(), 5);
        let gaps: Vec<i64> = rows.windows(2).map(|w| w[0] as i64 - w[1] as i64).collect();
        assert!(gaps.iter().all(|g| (g - gaps[0]).abs() <= 1), "{gaps:?}");
        let (x0, _, x1, _) = drawn.bar;
        for &(v, row) in &drawn.ticks {
            let p = image.get((x0 + x1) / 2, row);
            assert!((p[0] - grey(v)[0]).abs() <= 1.0 / 255.0, "{v}: {p:?}");
        }
    }
}
