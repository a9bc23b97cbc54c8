//! `volray paper` at reduced sizes (`--quick`): the structure of the
//! reproduced figures and table, not their pixels. Panels are 40 × 40
//! pixels in a triangular montage (`volray_paper::montage`: 4-pixel gaps,
//! 11-pixel label strips), the clouds 96 × 96.

use std::fs;
use std::path::Path;

use volray_paper::montage::TriangleLayout;

mod common;
use common::{Picture, stderr, stdout, volray};

/// Quick panels are this many pixels square.
const PANEL: usize = 40;

impl Picture {
    /// The `side × side` block with its top-left corner at (x0, y0).
    fn crop(&self, x0: usize, y0: usize, side: usize) -> Picture {
        let pixels = (0..side)
            .flat_map(|y| (0..side).map(move |x| (x, y)))
            .map(|(x, y)| self.at(x0 + x, y0 + y))
            .collect();
        Picture {
            width: side,
            height: side,
            rgb: pixels,
        }
    }

    /// Pixels that are not the black background.
    fn lit(&self) -> usize {
        self.rgb.iter().filter(|p| **p != [0; 3]).count()
    }

    /// Brightness (mean of r, g, b) at a continuous position, bilinear
    /// between pixel centres ((x, y) = (0.5, 0.5) is pixel (0, 0)).
    fn brightness_at(&self, x: f64, y: f64) -> f64 {
        let value = |i: usize, j: usize| {
            let p = self.at(i, j);
            (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0
        };
        let (fx, fy) = (x - 0.5, y - 0.5);
        let (i, j) = (fx.floor() as usize, fy.floor() as usize);
        let (u, v) = (fx - fx.floor(), fy - fy.floor());
        let (i1, j1) = ((i + 1).min(self.width - 1), (j + 1).min(self.height - 1));
        (1.0 - u) * (1.0 - v) * value(i, j)
            + u * (1.0 - v) * value(i1, j)
            + (1.0 - u) * v * value(i, j1)
            + u * v * value(i1, j1)
    }
}

/// Runs `volray paper ITEM --quick --out DIR`, checking it succeeds.
fn paper(item: &str, dir: &Path) {
    let out = volray(&["paper", item, "--quick", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success(), "paper {item}: {}", stderr(&out));
}

/// The quick montage's geometry.
fn layout() -> TriangleLayout {
    TriangleLayout::new(6, PANEL, true)
}

/// Panel (l, m) of a montage.
fn panel(montage: &Picture, l: usize, m: usize) -> Picture {
    let (x, y) = layout().panel_origin(l, m);
    montage.crop(x, y, PANEL)
}

/// The largest spread of brightness around circles about the panel's
/// centre (radii 2..=18 pixels, 48 angles each), over the panel's
/// largest brightness: 0 for an image symmetric under every rotation.
fn rotational_spread(panel: &Picture) -> f64 {
    let c = PANEL as f64 / 2.0;
    let peak = (0..PANEL)
        .flat_map(|y| (0..PANEL).map(move |x| (x, y)))
        .map(|(x, y)| panel.brightness_at(x as f64 + 0.5, y as f64 + 0.5))
        .fold(0.0, f64::max);
    assert!(peak > 0.0);
    let mut worst: f64 = 0.0;
    for r in 2..=18 {
        let values: Vec<f64> = (0..48)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 48.0;
                panel.brightness_at(c + r as f64 * a.cos(), c + r as f64 * a.sin())
            })
            .collect();
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(0.0, f64::max);
        worst = worst.max(hi - lo);
    }
    worst / peak
}

#[test]
fn all_writes_the_five_figures_and_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("new").join("paper");
    let out = volray(&[
        "paper",
        "all",
        "--quick",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut names: Vec<String> = fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "figure1a.png",
            "figure1b.png",
            "figure1c.png",
            "figure2a.png",
            "figure2b.png",
            "table1.md"
        ]
    );
    let said = stdout(&out);
    for name in &names {
        assert!(said.contains(name.as_str()), "{said}");
    }
    // Montages: 6 rows of 40-pixel panels, 4-pixel gaps, 11-pixel labels.
    for name in ["figure1a.png", "figure1b.png", "figure1c.png"] {
        let image = Picture::read(&out_dir.join(name));
        assert_eq!(
            (image.width, image.height),
            (4 + 6 * 44, 4 + 6 * 55),
            "{name}"
        );
    }
    for name in ["figure2a.png", "figure2b.png"] {
        let image = Picture::read(&out_dir.join(name));
        assert_eq!((image.width, image.height), (96, 96), "{name}");
    }

    // Table 1: the paper's four cases, each with its numbers.
    let table = fs::read_to_string(out_dir.join("table1.md")).unwrap();
    let rows: Vec<Vec<String>> = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| Data set"))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 4, "{table}");
    let names: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        names,
        [
            "Probability density \\|ψ_621\\|²",
            "Fractal set I",
            "Fractal set II",
            "Fractal set III"
        ]
    );
    let paper: Vec<&str> = rows.iter().map(|r| r[3].as_str()).collect();
    assert_eq!(paper, ["3.35", "18.7", "16.9", "149.5"]);
    for row in &rows {
        assert_eq!(row.len(), 10, "{row:?}");
        let number = |cell: &str| cell.trim_end_matches('×').parse::<f64>().unwrap();
        let (p, reference, fast) = (number(&row[3]), number(&row[4]), number(&row[5]));
        assert!(reference > 0.0 && fast > 0.0, "{row:?}");
        // The speed-ups are the ratios of the times shown (3 digits each).
        for (cell, want) in [
            (&row[6], p / reference),
            (&row[7], p / fast),
            (&row[8], reference / fast),
        ] {
            let got = number(cell);
            assert!((got / want - 1.0).abs() < 0.02, "{cell} vs {want}: {row:?}");
        }
        // The two paths render the same image (the tests elsewhere hold
        // them within 1/255).
        assert!(number(&row[9]) <= 1.0 / 255.0, "{row:?}");
    }
    assert!(table.contains("Reduced sizes"), "{table}");
    assert!(table.contains("logical CPUs"), "{table}");
    assert!(table.contains("worker threads"), "{table}");
    assert!(table.contains("median of 1 run per path"), "{table}");
}

#[test]
fn montage_has_the_paper_layout_and_every_panel_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    paper("figure1a", dir.path());
    let montage = Picture::read(&dir.path().join("figure1a.png"));
    let layout = layout();
    let strip = layout.label_strip;
    for l in 0..6 {
        for m in 0..6 {
            let (x, y) = layout.panel_origin(l, m);
            let cell = panel(&montage, l, m);
            // The label strip above the panel.
            let label = (y - strip..y)
                .flat_map(|yy| (x..x + PANEL).map(move |xx| (xx, yy)))
                .filter(|&(xx, yy)| montage.at(xx, yy) != [0; 3])
                .count();
            if m <= l {
                // A density fills a good part of its panel.
                let share = cell.lit() as f64 / (PANEL * PANEL) as f64;
                assert!(share > 0.1, "panel ({l},{m}) is {share:.3} lit");
                assert!(label > 0, "panel ({l},{m}) has no label");
            } else {
                assert_eq!(cell.lit(), 0, "empty cell ({l},{m}) is drawn on");
                assert_eq!(label, 0, "empty cell ({l},{m}) has a label");
            }
        }
    }
    // The gaps between cells are background.
    for y in 0..montage.height {
        for x in 0..4 {
            assert_eq!(montage.at(x, y), [0; 3]);
        }
    }
}

#[test]
fn l0_panel_is_rotationally_symmetric_seen_along_x() {
    let dir = tempfile::tempdir().unwrap();
    paper("figure1a", dir.path());
    let montage = Picture::read(&dir.path().join("figure1a.png"));
    // |ψ_600|² is spherically symmetric: its image is the same on every
    // circle about the centre (to the grid's and the pixels' resolution).
    let s = panel(&montage, 0, 0);
    let spread = rotational_spread(&s);
    assert!(spread < 0.08, "(0,0): spread {spread:.3} of the peak");
    // Not so |ψ_610|², whose lobes lie along z: the measure tells them apart.
    let p = panel(&montage, 1, 0);
    let spread_p = rotational_spread(&p);
    assert!(spread_p > 0.4, "(1,0): spread {spread_p:.3} of the peak");
}

#[test]
fn the_two_views_differ() {
    let dir = tempfile::tempdir().unwrap();
    paper("figure1a", dir.path());
    paper("figure1b", dir.path());
    let a = Picture::read(&dir.path().join("figure1a.png"));
    let b = Picture::read(&dir.path().join("figure1b.png"));
    assert_eq!((a.width, a.height), (b.width, b.height));
    // Every non-spherical state looks different from the other view point.
    for (l, m) in [(1, 0), (2, 1), (3, 3), (5, 0), (5, 5)] {
        let (pa, pb) = (panel(&a, l, m), panel(&b, l, m));
        let differing = pa
            .rgb
            .iter()
            .zip(&pb.rgb)
            .filter(|(p, q)| p.iter().zip(q.iter()).any(|(u, v)| u.abs_diff(*v) > 8))
            .count();
        assert!(
            differing > PANEL * PANEL / 10,
            "panel ({l},{m}): only {differing} pixels differ"
        );
    }
}

/// Distance from the centre of `panel` to the edge of its lit region along
/// direction `angle` (radians), in pixels.
fn edge_radius(panel: &Picture, angle: f64) -> f64 {
    let c = PANEL as f64 / 2.0;
    let mut r = 0.0;
    while r < c {
        let (x, y) = (c + (r + 0.1) * angle.cos(), c + (r + 0.1) * angle.sin());
        let (i, j) = (x.floor() as usize, y.floor() as usize);
        if i >= PANEL || j >= PANEL || panel.at(i, j).iter().all(|&v| v < 8) {
            return r;
        }
        r += 0.1;
    }
    c
}

#[test]
fn the_surface_of_y00_is_a_disc_of_uniform_radius() {
    let dir = tempfile::tempdir().unwrap();
    paper("figure1c", dir.path());
    let montage = Picture::read(&dir.path().join("figure1c.png"));
    let disc = panel(&montage, 0, 0);
    let radii: Vec<f64> = (0..72)
        .map(|k| edge_radius(&disc, k as f64 * std::f64::consts::TAU / 72.0))
        .collect();
    let (lo, hi) = radii
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    assert!(hi - lo <= 1.5, "radii from {lo:.2} to {hi:.2}");
    // |Y_00|² = 1/4π is a sphere, framed with an 8% margin: radius
    // 20/1.08 = 18.5 pixels.
    let mean = radii.iter().sum::<f64>() / radii.len() as f64;
    assert!((mean - 20.0 / 1.08).abs() < 1.0, "mean radius {mean:.2}");
    // The disc is filled.
    let area = disc.lit() as f64;
    let want = std::f64::consts::PI * mean * mean;
    assert!((area / want - 1.0).abs() < 0.08, "area {area} vs {want:.0}");
    // |Y_10|² is two lobes along z: far from a disc.
    let lobes = panel(&montage, 1, 0);
    let radii: Vec<f64> = (0..72)
        .map(|k| edge_radius(&lobes, k as f64 * std::f64::consts::TAU / 72.0))
        .collect();
    let (lo, hi) = radii
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    assert!(hi - lo > 3.0, "(1,0) radii from {lo:.2} to {hi:.2}");
}

#[test]
fn the_two_clouds_differ() {
    let dir = tempfile::tempdir().unwrap();
    paper("figure2a", dir.path());
    paper("figure2b", dir.path());
    let a = Picture::read(&dir.path().join("figure2a.png"));
    let b = Picture::read(&dir.path().join("figure2b.png"));
    for cloud in [&a, &b] {
        // A cloud in the middle of a black sky.
        let share = cloud.lit() as f64 / (96.0 * 96.0);
        assert!((0.1..0.8).contains(&share), "lit share {share:.3}");
        for (x, y) in [(0, 0), (95, 0), (0, 95), (95, 95)] {
            assert_eq!(cloud.at(x, y), [0; 3]);
        }
    }
    let differing = a
        .rgb
        .iter()
        .zip(&b.rgb)
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(u, v)| u.abs_diff(*v) > 8))
        .count();
    assert!(differing > 96 * 96 / 10, "only {differing} pixels differ");
}

#[test]
fn bad_arguments_and_unwritable_directories_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = volray(&["paper", "figure3", "--out", dir.path().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("figure3"), "{err}");

    let file = dir.path().join("plain");
    fs::write(&file, b"not a directory").unwrap();
    let out = volray(&[
        "paper",
        "figure2a",
        "--quick",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("plain: cannot create the output directory"),
        "{err}"
    );
    assert_eq!(fs::read(&file).unwrap(), b"not a directory");
}
