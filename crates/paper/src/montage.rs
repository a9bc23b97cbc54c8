//! The paper's triangular montage of Figure 1: one panel per state
//! `(l, m)`, `l = 0..rows` down, `m = 0..=l` across, so row `l` holds
//! `l + 1` panels and the cells right of the diagonal stay empty
//! (background). Each panel sits under a strip holding its label `(l,m)`.
//!
//! ```text
//!  gap │ label │ gap │ label │ …        one cell: label strip above a
//!      │ panel │     │ (empty)│            square panel, gap around
//!      │ label │     │ label │
//!      │ panel │     │ panel │
//! ```
//!
//! Geometry, with `P` the panel side, `G` the gap and `S` the label strip
//! (0 without labels): the panel of cell (row `l`, column `m`) has its top
//! left corner at `x = G + m (P + G)`, `y = G + l (S + P + G) + S`; the
//! montage is `G + rows (P + G)` wide and `G + rows (S + P + G)` high.

use crate::font::{self, MissingGlyph};
use thiserror::Error;
use volray_core::Image;

/// Gap between cells and around the montage, in pixels.
pub const GAP: usize = 4;
/// Height of a label strip: the font's height with 2 pixels above and below.
pub const LABEL_STRIP: usize = font::GLYPH_HEIGHT + 4;

/// A montage that cannot be assembled.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MontageError {
    #[error("panel ({row},{col}) is outside the triangle of {rows} rows")]
    OutsideTriangle { row: usize, col: usize, rows: usize },
    #[error(
        "panel ({row},{col}) is {width}x{height} pixels; the montage's panels are {side}x{side}"
    )]
    PanelSize {
        row: usize,
        col: usize,
        width: usize,
        height: usize,
        side: usize,
    },
    #[error("panel ({row},{col}) is given twice")]
    Duplicate { row: usize, col: usize },
    #[error("panel ({row},{col}) is missing")]
    Missing { row: usize, col: usize },
    #[error("label {label:?} of panel ({row},{col}) is {width} pixels wide; the panel is {side}")]
    LabelTooWide {
        row: usize,
        col: usize,
        label: String,
        width: usize,
        side: usize,
    },
    #[error(transparent)]
    Glyph(#[from] MissingGlyph),
}

/// Where the cells of a triangular montage lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TriangleLayout {
    /// Rows: the paper's `n` (6: `l = 0..5`).
    pub rows: usize,
    /// Side of a (square) panel, pixels.
    pub panel: usize,
    /// Height of the label strip above each panel (0: no labels).
    pub label_strip: usize,
    /// Gap between cells and around the montage.
    pub gap: usize,
}

impl TriangleLayout {
    /// `rows` rows of `panel × panel` panels, with label strips if `labels`.
    pub fn new(rows: usize, panel: usize, labels: bool) -> Self {
        TriangleLayout {
            rows,
            panel,
            label_strip: if labels { LABEL_STRIP } else { 0 },
            gap: GAP,
        }
    }

    /// Montage width, pixels.
    pub fn width(&self) -> usize {
        self.gap + self.rows * (self.panel + self.gap)
    }

    /// Montage height, pixels.
    pub fn height(&self) -> usize {
        self.gap + self.rows * (self.label_strip + self.panel + self.gap)
    }

    /// Whether cell (`row`, `col`) holds a panel: `col ≤ row < rows`.
    pub fn is_filled(&self, row: usize, col: usize) -> bool {
        row < self.rows && col <= row
    }

    /// The filled cells in reading order: (0,0), (1,0), (1,1), (2,0), …
    pub fn cells(&self) -> impl Iterator<Item = (usize, usize)> + use<> {
        let rows = self.rows;
        (0..rows).flat_map(|row| (0..=row).map(move |col| (row, col)))
    }

    /// Top-left pixel (x, y) of the panel of cell (`row`, `col`); also
    /// defined for the empty cells right of the diagonal.
    pub fn panel_origin(&self, row: usize, col: usize) -> (usize, usize) {
        (
            self.gap + col * (self.panel + self.gap),
            self.gap + row * (self.label_strip + self.panel + self.gap) + self.label_strip,
        )
    }

    /// Top-left pixel (x, y) of a label of `width` pixels, centred over
    /// the panel of cell (`row`, `col`), 2 pixels down its strip.
    pub fn label_origin(&self, row: usize, col: usize, width: usize) -> (usize, usize) {
        let (x, y) = self.panel_origin(row, col);
        (
            x + self.panel.saturating_sub(width) / 2,
            y - self.label_strip + 2,
        )
    }
}

/// One panel of a montage.
#[derive(Debug, Clone)]
pub struct Panel {
    pub row: usize,
    pub col: usize,
    pub image: Image,
    /// Drawn above the panel when the layout has label strips.
    pub label: String,
}

/// Assembles `panels`, one for each filled cell of `layout`, on a
/// `background` montage, with their labels in `label_color`.
pub fn compose(
    layout: &TriangleLayout,
    panels: &[Panel],
    background: [f32; 3],
    label_color: [f32; 3],
) -> Result<Image, MontageError> {
    let [r, g, b] = background;
    let mut montage = Image::new(layout.width(), layout.height(), [r, g, b, 1.0]);
    let mut seen = vec![false; layout.rows * layout.rows];
    for panel in panels {
        let (row, col, side) = (panel.row, panel.col, layout.panel);
        if !layout.is_filled(row, col) {
            return Err(MontageError::OutsideTriangle {
                row,
                col,
                rows: layout.rows,
            });
        }
        if (panel.image.width(), panel.image.height()) != (side, side) {
            return Err(MontageError::PanelSize {
                row,
                col,
                width: panel.image.width(),
                height: panel.image.height(),
                side,
            });
        }
        if std::mem::replace(&mut seen[row * layout.rows + col], true) {
            return Err(MontageError::Duplicate { row, col });
        }
        let (x0, y0) = layout.panel_origin(row, col);
        for y in 0..side {
            for x in 0..side {
                montage.set(x0 + x, y0 + y, panel.image.get(x, y));
            }
        }
        if layout.label_strip > 0 {
            let width = font::text_width(&panel.label);
            if width > side {
                return Err(MontageError::LabelTooWide {
                    row,
                    col,
                    label: panel.label.clone(),
                    width,
                    side,
                });
            }
            let (lx, ly) = layout.label_origin(row, col, width);
            font::draw_text(&mut montage, lx, ly, &panel.label, label_color)?;
        }
    }
    if let Some((row, col)) = layout.cells().find(|&(r, c)| !seen[r * layout.rows + c]) {
        return Err(MontageError::Missing { row, col });
    }
    Ok(montage)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panels(layout: &TriangleLayout) -> Vec<Panel> {
        layout
            .cells()
            .map(|(row, col)| {
                let shade = 0.1 + 0.04 * (row * layout.rows + col) as f32;
                Panel {
                    row,
                    col,
                    image: Image::new(layout.panel, layout.panel, [shade, 0.0, 0.0, 1.0]),
                    label: format!("({row},{col})"),
                }
            })
            .collect()
    }

    #[test]
    fn geometry_of_the_paper_montage() {
        let layout = TriangleLayout::new(6, 120, true);
        assert_eq!(layout.label_strip, 11);
        assert_eq!(layout.width(), 4 + 6 * 124);
        assert_eq!(layout.height(), 4 + 6 * (11 + 120 + 4));
        assert_eq!(layout.cells().count(), 21);
        assert_eq!(
            layout.cells().take(4).collect::<Vec<_>>(),
            [(0, 0), (1, 0), (1, 1), (2, 0)]
        );
        assert_eq!(layout.cells().last(), Some((5, 5)));
        assert_eq!(layout.panel_origin(0, 0), (4, 15));
        assert_eq!(layout.panel_origin(5, 5), (4 + 5 * 124, 4 + 5 * 135 + 11));
        // The last panel ends one gap before the montage's edges.
        let (x, y) = layout.panel_origin(5, 5);
        assert_eq!(x + 120 + 4, layout.width());
        assert_eq!(y + 120 + 4, layout.height());
        assert!(layout.is_filled(3, 3) && !layout.is_filled(3, 4) && !layout.is_filled(6, 0));
        // Without labels the rows close up.
        let bare = TriangleLayout::new(6, 120, false);
        assert_eq!(bare.height(), bare.width());
        assert_eq!(bare.panel_origin(1, 1), (128, 128));
    }

    #[test]
    fn panels_land_in_their_cells_and_empty_cells_stay_background() {
        let layout = TriangleLayout::new(4, 32, true);
        let background = [0.0, 0.0, 0.25];
        let label = [0.9, 0.9, 0.9];
        let montage = compose(&layout, &panels(&layout), background, label).unwrap();
        assert_eq!(
            (montage.width(), montage.height()),
            (layout.width(), layout.height())
        );
        let mut panel_pixels = 0;
        let mut label_pixels = 0;
        for y in 0..montage.height() {
            for x in 0..montage.width() {
                let [r, g, b, _] = montage.get(x, y);
                if [r, g, b] == background {
                    continue;
                }
                if [r, g, b] == label {
                    label_pixels += 1;
                    continue;
                }
                // Any other colour is a panel's, inside that panel.
                let row = (0..4)
                    .find(|&row| {
                        let (_, y0) = layout.panel_origin(row, 0);
                        (y0..y0 + 32).contains(&y)
                    })
                    .unwrap();
                let col = (0..4)
                    .find(|&col| {
                        let (x0, _) = layout.panel_origin(0, col);
                        (x0..x0 + 32).contains(&x)
                    })
                    .unwrap();
                assert!(col <= row, "pixel ({x},{y}) in empty cell ({row},{col})");
                assert_eq!(r, 0.1 + 0.04 * (row * 4 + col) as f32);
                panel_pixels += 1;
            }
        }
        assert_eq!(panel_pixels, 10 * 32 * 32);
        let bits: u32 = layout
            .cells()
            .flat_map(|(r, c)| format!("({r},{c})").chars().collect::<Vec<_>>())
            .flat_map(|c| font::glyph(c).unwrap())
            .map(u8::count_ones)
            .sum();
        assert_eq!(label_pixels, bits as usize);
    }

    #[test]
    fn labels_sit_centred_in_the_strip_above_their_panel() {
        let layout = TriangleLayout::new(2, 40, true);
        let montage = compose(&layout, &panels(&layout), [0.0; 3], [1.0; 3]).unwrap();
        let (x0, y0) = layout.panel_origin(1, 1);
        let white: Vec<(usize, usize)> = (0..montage.height())
            .flat_map(|y| (0..montage.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| montage.get(x, y)[..3] == [1.0; 3])
            .filter(|&(x, y)| x >= x0 && x < x0 + 40 && y < y0 && y + LABEL_STRIP >= y0)
            .collect();
        assert!(!white.is_empty());
        let left = white.iter().map(|p| p.0).min().unwrap();
        let right = white.iter().map(|p| p.0).max().unwrap();
        // "(1,1)" is 29 pixels wide; '(' starts in its column 1 and ')' ends
        // in its column 3, so the ink spans columns 1..=27 of the text.
        let start = x0 + (40 - 29) / 2;
        assert_eq!((left, right), (start + 1, start + 27));
        assert!(
            white
                .iter()
                .all(|p| p.1 >= y0 - LABEL_STRIP + 2 && p.1 < y0 - 2)
        );
    }

    #[test]
    fn bad_panel_sets_are_refused() {
        let layout = TriangleLayout::new(3, 16, false);
        let good = panels(&layout);
        let bg = [0.0; 3];
        let mut extra = good.clone();
        extra.push(Panel {
            row: 1,
            col: 2,
            ..good[0].clone()
        });
        assert_eq!(
            compose(&layout, &extra, bg, bg).unwrap_err(),
            MontageError::OutsideTriangle {
                row: 1,
                col: 2,
                rows: 3
            }
        );
        let mut twice = good.clone();
        twice.push(good[3].clone());
        assert!(matches!(
            compose(&layout, &twice, bg, bg),
            Err(MontageError::Duplicate { row: 2, col: 0 })
        ));
        assert!(matches!(
            compose(&layout, &good[..5], bg, bg),
            Err(MontageError::Missing { row: 2, col: 2 })
        ));
        let mut small = good.clone();
        small[1].image = Image::new(15, 16, [0.0; 4]);
        assert!(
            compose(&layout, &small, bg, bg)
                .unwrap_err()
                .to_string()
                .contains("15x16")
        );
        let labelled = TriangleLayout::new(3, 16, true);
        assert!(matches!(
            compose(&labelled, &good, bg, bg),
            Err(MontageError::LabelTooWide { .. })
        ));
    }
}
