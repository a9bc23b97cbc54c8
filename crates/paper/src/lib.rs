//! # volray-paper: the paper's figures and timing table, reproduced
//!
//! N. Ramesh and G. Athithan, "Visualization of three-dimensional data by
//! 'volume rendering'", *Current Science* (1993): Figures 1a, 1b, 1c, 2a,
//! 2b and Table 1, made by volray in one call ([`make`]; on the command
//! line `volray paper [ITEM|all] --out DIR`), so the 1993 results and ours
//! can be put side by side.
//!
//! | item | file | what | module |
//! |---|---|---|---|
//! | Figure 1a | `figure1a.png` | the 21 densities `\|ψ_6lm\|²`, 50³ → 120² each, triangular montage, view point on +x | [`orbitals`] |
//! | Figure 1b | `figure1b.png` | the same from (150, 150, 500) | [`orbitals`] |
//! | Figure 1c | `figure1c.png` | surface renderings of `\|Y_lm\|²` from (150, 150, 500) | [`surfaces`] |
//! | Figure 2a, 2b | `figure2a.png`, `figure2b.png` | fractal clouds, D = 3.7, seeds 1 and 2, 129³ → 480² | [`clouds`] |
//! | Table 1 | `table1.md` | the four timed cases, reference and fast paths, against the paper's seconds | [`table1`], [`machine`] |
//!
//! The montage ([`montage`]) puts `l = 0..5` down and `m = 0..=l` across,
//! each panel under its label `(l,m)` in a small built-in bitmap font
//! ([`font`]). [`Sizes`] holds the paper's sizes or reduced ones for tests.
//! Each module's documentation gives the choices the paper leaves open
//! (opacity window, colours, thresholds) and why. Every file is written
//! atomically; the output directory is created if missing.

pub mod clouds;
mod error;
pub mod font;
pub mod machine;
pub mod montage;
pub mod orbitals;
pub mod sizes;
pub mod surfaces;
pub mod table1;

pub use error::PaperError;
pub use sizes::Sizes;

use std::path::{Path, PathBuf};

use volray_io::BitDepth;

/// The background of every figure and montage: black, as the volume
/// renderings' own.
pub const BACKGROUND: [f32; 3] = [0.0; 3];
/// The colour of the montage labels.
pub const LABEL_COLOR: [f32; 3] = [0.85; 3];

/// One output of the reproduction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Item {
    Figure1a,
    Figure1b,
    Figure1c,
    Figure2a,
    Figure2b,
    Table1,
}

impl Item {
    /// Every item, in the paper's order.
    pub const ALL: [Item; 6] = [
        Item::Figure1a,
        Item::Figure1b,
        Item::Figure1c,
        Item::Figure2a,
        Item::Figure2b,
        Item::Table1,
    ];

    /// The item's name on the command line: `figure1a`, …, `table1`.
    pub fn name(self) -> &'static str {
        match self {
            Item::Figure1a => "figure1a",
            Item::Figure1b => "figure1b",
            Item::Figure1c => "figure1c",
            Item::Figure2a => "figure2a",
            Item::Figure2b => "figure2b",
            Item::Table1 => "table1",
        }
    }

    /// The file it is written to in the output directory.
    pub fn file_name(self) -> &'static str {
        match self {
            Item::Figure1a => "figure1a.png",
            Item::Figure1b => "figure1b.png",
            Item::Figure1c => "figure1c.png",
            Item::Figure2a => "figure2a.png",
            Item::Figure2b => "figure2b.png",
            Item::Table1 => "table1.md",
        }
    }
}

/// Makes `items` (each once, in the paper's order) at `sizes` into the
/// directory `out`, created if missing, calling `progress` with a line
/// about each file written (and each timed case). Returns the paths
/// written. Renders run on the current rayon pool; Table 1 reports its
/// thread count.
pub fn make(
    items: &[Item],
    out: &Path,
    sizes: &Sizes,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<PathBuf>, PaperError> {
    std::fs::create_dir_all(out).map_err(|source| PaperError::OutputDir {
        dir: out.to_path_buf(),
        source,
    })?;
    let wanted = |item: Item| items.contains(&item);
    let mut written = Vec::new();
    let mut write_png = |item: Item, image: &volray_core::Image, note: String| {
        let path = out.join(item.file_name());
        volray_io::write_png(&path, image, BitDepth::Eight)?;
        progress(&format!(
            "wrote {} ({}x{} pixels): {note}",
            path.display(),
            image.width(),
            image.height()
        ));
        written.push(path);
        Ok::<(), PaperError>(())
    };

    if wanted(Item::Figure1a) || wanted(Item::Figure1b) {
        let densities = orbitals::densities(sizes.hydrogen_grid)?;
        let g = sizes.hydrogen_grid;
        for (item, view) in [
            (Item::Figure1a, orbitals::OrbitalView::XAxis),
            (Item::Figure1b, orbitals::OrbitalView::Oblique),
        ] {
            if wanted(item) {
                let image = orbitals::figure(&densities, view, sizes.panel)?;
                let from = view.view_point();
                let note = format!(
                    "|psi_6lm|^2 on {g}^3 grids, viewed from ({}, {}, {})",
                    from.x, from.y, from.z
                );
                write_png(item, &image, note)?;
            }
        }
    }
    if wanted(Item::Figure1c) {
        let image = surfaces::figure(sizes.panel, sizes.surface_theta_steps)?;
        let t = sizes.surface_theta_steps;
        let note = format!(
            "|Y_lm|^2 polar surfaces, {t}x{} cells, viewed from (150, 150, 500)",
            2 * t
        );
        write_png(Item::Figure1c, &image, note)?;
    }
    for (item, seed) in [
        (Item::Figure2a, clouds::SEEDS[0]),
        (Item::Figure2b, clouds::SEEDS[1]),
    ] {
        if wanted(item) {
            let style = clouds::CloudStyle::default();
            let cloud = clouds::cloud(sizes.cloud_grid, seed, &style)?;
            let image = clouds::render(&cloud, &style, sizes.cloud_window)?;
            write_png(item, &image, format!("the cloud {}", cloud.spec()))?;
        }
    }
    if wanted(Item::Table1) {
        let mut rows = Vec::new();
        for case in table1::cases(&sizes.table) {
            let row = table1::measure(&case, sizes.runs)?;
            progress(&format!(
                "table 1: {} ({g}^3 -> {w}^2): reference {} s, fast {} s (paper {} s)",
                case.name,
                table1::significant(row.reference_seconds),
                table1::significant(row.fast_seconds),
                case.paper_seconds,
                g = case.grid,
                w = case.window,
            ));
            rows.push(row);
        }
        let machine = machine::Machine::this(rayon::current_num_threads());
        let text = table1::markdown(&rows, &machine, &machine::today_utc(), sizes.is_reduced());
        let path = out.join(Item::Table1.file_name());
        volray_io::write_atomically(&path, |w| w.write_all(text.as_bytes()))?;
        progress(&format!("wrote {}", path.display()));
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn item_names_and_files() {
        let names: Vec<&str> = Item::ALL.iter().map(|i| i.name()).collect();
        assert_eq!(
            names,
            [
                "figure1a", "figure1b", "figure1c", "figure2a", "figure2b", "table1"
            ]
        );
        for item in Item::ALL {
            assert!(item.file_name().starts_with(item.name()));
        }
        assert_eq!(Item::Table1.file_name(), "table1.md");
    }

    #[test]
    fn an_output_directory_that_is_a_file_is_an_io_failure() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("plain");
        std::fs::write(&file, b"x").unwrap();
        let err = make(&[Item::Figure2a], &file, &Sizes::QUICK, &mut |_| {}).unwrap_err();
        assert!(err.is_io_failure());
        assert!(
            err.to_string()
                .contains("plain: cannot create the output directory")
        );
    }
}
