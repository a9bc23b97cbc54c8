//! Table 1: the paper's four timing cases rendered on the reference path
//! and the fast path, with the paper's IRIS 4D/20 seconds beside ours.
//!
//! | case | data | grid | window | paper |
//! |---|---|---|---|---|
//! | probability density | `\|ψ_621\|²` (errata 5), Figure 1a's settings | 50³ | 120² | 3.35 s |
//! | fractal set I | Figure 2's cloud, seed 1 | 65³ | 240² | 18.7 s |
//! | fractal set II | seed 2 | 65³ | 240² | 16.9 s |
//! | fractal set III | seed 1 (Figure 2a's cloud) | 129³ | 480² | 149.5 s |
//!
//! # What is timed
//!
//! One run is a whole render from the volume in memory to the frame
//! buffer: a new [`Renderer`] (the value range), stage 1 (gradients,
//! shading and classification: on the fast path the min/max macro-cells
//! and the occupied bricks, which a kept `Renderer` would reuse; redone
//! here, as the paper redid everything for every image) and stage 2 (the
//! rays). Not timed: generating the volume, and encoding or writing the
//! image. Warm-up: one untimed run of each path, then further untimed fast
//! runs until a quarter of a second has passed, so the CPU is awake. Then
//! `runs` timed runs of each path, alternating reference and fast so that
//! a change in the machine's load touches both; the table gives medians.
//! The last images of the two paths are compared: their largest
//! difference per channel is reported (the tests hold it within 1/255).

use std::time::{Duration, Instant};
use volray_core::{FrameRequest, Render, Rendered};

use volray_core::{Image, Method, RenderSettings, Renderer, Volume};

use crate::PaperError;
use crate::clouds::{self, CloudStyle};
use crate::machine::Machine;
use crate::orbitals::{self, OrbitalView};

/// One of the paper's cases.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The paper's name for it.
    pub name: &'static str,
    pub data: CaseData,
    /// Points per side.
    pub grid: usize,
    /// Image side, pixels.
    pub window: usize,
    /// The paper's time on the IRIS 4D/20, seconds.
    pub paper_seconds: f64,
}

/// The volume of a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CaseData {
    /// `|ψ_6lm|²` with Figure 1a's settings.
    Hydrogen { l: u32, m: u32 },
    /// A fractal cloud with Figure 2's settings.
    Fractal { seed: u64 },
}

/// The paper's four cases; the grids and windows are the paper's for
/// `scale = 1` and divided (to the next valid size) for reduced runs.
pub fn cases(sizes: &CaseSizes) -> [Case; 4] {
    [
        Case {
            name: "Probability density |ψ_621|²",
            data: CaseData::Hydrogen { l: 2, m: 1 },
            grid: sizes.hydrogen.0,
            window: sizes.hydrogen.1,
            paper_seconds: 3.35,
        },
        Case {
            name: "Fractal set I",
            data: CaseData::Fractal {
                seed: clouds::SEEDS[0],
            },
            grid: sizes.fractal.0,
            window: sizes.fractal.1,
            paper_seconds: 18.7,
        },
        Case {
            name: "Fractal set II",
            data: CaseData::Fractal {
                seed: clouds::SEEDS[1],
            },
            grid: sizes.fractal.0,
            window: sizes.fractal.1,
            paper_seconds: 16.9,
        },
        Case {
            name: "Fractal set III",
            data: CaseData::Fractal {
                seed: clouds::SEEDS[0],
            },
            grid: sizes.large_fractal.0,
            window: sizes.large_fractal.1,
            paper_seconds: 149.5,
        },
    ]
}

/// (grid, window) of the three kinds of case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CaseSizes {
    pub hydrogen: (usize, usize),
    pub fractal: (usize, usize),
    pub large_fractal: (usize, usize),
}

impl CaseSizes {
    /// The paper's: 50³ → 120², 65³ → 240², 129³ → 480².
    pub const PAPER: CaseSizes = CaseSizes {
        hydrogen: (50, 120),
        fractal: (65, 240),
        large_fractal: (129, 480),
    };
}

/// A case's volume, its render settings, and how to name it.
pub struct Prepared {
    pub volume: Volume,
    /// Settings with `method` to be set per path.
    pub settings: RenderSettings,
    /// The `volray-data` spec that makes the volume.
    pub spec: String,
}

/// Makes the volume of `case` and its settings.
pub fn prepare(case: &Case) -> Result<Prepared, PaperError> {
    Ok(match case.data {
        CaseData::Hydrogen { l, m } => {
            let volume = orbitals::density(l, m, case.grid)?;
            let settings =
                orbitals::panel_settings(&volume, OrbitalView::XAxis, case.window, Method::Fast);
            let spec = format!(
                "hydrogen:{},{l},{m},grid={},extent={}",
                orbitals::N,
                case.grid,
                orbitals::common_extent(orbitals::N)
            );
            Prepared {
                volume,
                settings,
                spec,
            }
        }
        CaseData::Fractal { seed } => {
            let style = CloudStyle::default();
            let cloud = clouds::cloud(case.grid, seed, &style)?;
            let settings = clouds::settings(&cloud.volume, &style, case.window, Method::Fast);
            Prepared {
                spec: cloud.spec(),
                volume: cloud.volume,
                settings,
            }
        }
    })
}

/// The timings of one case.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    pub case: Case,
    pub spec: String,
    /// Median seconds per render on each path.
    pub reference_seconds: f64,
    pub fast_seconds: f64,
    /// Timed runs per path.
    pub runs: usize,
    /// Largest difference per channel between the paths' images.
    pub max_difference: f32,
}

/// Untimed warm-up renders last at least this long.
const WARM_UP: Duration = Duration::from_millis(250);

/// One whole render, timed (module docs).
fn timed_render(volume: &Volume, settings: &RenderSettings) -> Result<(f64, Image), PaperError> {
    let start = Instant::now();
    let renderer = Renderer::new(volume).map_err(PaperError::render("table 1"))?;
    let image = renderer
        .render(FrameRequest::new(settings))
        .map(Rendered::image)
        .map_err(PaperError::render("table 1"))?;
    Ok((start.elapsed().as_secs_f64(), image))
}

/// Times `case` on both paths: `runs` timed runs each after the warm-up.
pub fn measure(case: &Case, runs: usize) -> Result<Measured, PaperError> {
    let prepared = prepare(case)?;
    let with = |method| RenderSettings {
        method,
        ..prepared.settings.clone()
    };
    let (reference, fast) = (with(Method::Reference), with(Method::Fast));
    let warm_start = Instant::now();
    timed_render(&prepared.volume, &reference)?;
    while warm_start.elapsed() < WARM_UP {
        timed_render(&prepared.volume, &fast)?;
    }
    let mut times = (Vec::new(), Vec::new());
    let mut images = None;
    for _ in 0..runs.max(1) {
        let (tr, ir) = timed_render(&prepared.volume, &reference)?;
        let (tf, jf) = timed_render(&prepared.volume, &fast)?;
        times.0.push(tr);
        times.1.push(tf);
        images = Some((ir, jf));
    }
    let (ir, jf) = images.expect("at least one run");
    Ok(Measured {
        case: case.clone(),
        spec: prepared.spec,
        reference_seconds: median(times.0),
        fast_seconds: median(times.1),
        runs: runs.max(1),
        max_difference: ir.max_abs_diff(&jf).unwrap_or(f32::NAN),
    })
}

/// The median (the mean of the middle two for an even count; NaN for none).
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// `x` with three significant digits, without an exponent (`0.00123`,
/// `1.23`, `123`, `12300`).
pub fn significant(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let digits = 2 - x.abs().log10().floor() as i32;
    if digits <= 0 {
        let scale = 10f64.powi(-digits);
        format!("{}", (x / scale).round() * scale)
    } else {
        format!("{x:.*}", digits as usize)
    }
}

/// A speed-up `a / b` as `12.3×`.
fn ratio(a: f64, b: f64) -> String {
    format!("{}×", significant(a / b))
}

/// Table 1 as Markdown: the table, then how it was measured.
pub fn markdown(rows: &[Measured], machine: &Machine, date: &str, reduced: bool) -> String {
    let mut s = String::new();
    s.push_str("# Table 1, reproduced\n\n");
    if reduced {
        s.push_str(
            "**Reduced sizes (`--quick`): not the paper's grids and windows; for testing only.**\n\n",
        );
    }
    s.push_str(
        "| Data set | Grid | Window | Paper, IRIS 4D/20 (s) | volray reference (s) | volray fast (s) \
         | Paper / reference | Paper / fast | Reference / fast | Max. difference |\n",
    );
    s.push_str("|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for r in rows {
        let c = &r.case;
        s.push_str(&format!(
            "| {} | {g}×{g}×{g} | {w}×{w} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.name.replace('|', "\\|"),
            c.paper_seconds,
            significant(r.reference_seconds),
            significant(r.fast_seconds),
            ratio(c.paper_seconds, r.reference_seconds),
            ratio(c.paper_seconds, r.fast_seconds),
            ratio(r.reference_seconds, r.fast_seconds),
            significant(f64::from(r.max_difference)),
            g = c.grid,
            w = c.window,
        ));
    }
    let runs = rows.first().map_or(0, |r| r.runs);
    s.push_str(&format!(
        "\nMeasured {date} (UTC) on {} ({} logical CPUs), {} worker thread{}, {}.\n\n",
        machine.cpu,
        machine.logical_cpus,
        machine.threads,
        if machine.threads == 1 { "" } else { "s" },
        crate::machine::build_profile(),
    ));
    s.push_str(&format!(
        "Each time is the median of {runs} run{} per path after a warm-up, in wall-clock \
         seconds, of the render alone: from the volume in memory to the frame buffer, with stage 1 (gradients, shading, \
         classification; the fast path's bricks and macro-cells) redone every run, as the paper \
         redid everything for every image. Generating the volume and writing the image are not \
         timed. Reference and fast runs alternate. \"Max. difference\" is the largest \
         difference per colour channel (0 to 1) between the two paths' images. The paper's \
         times are CPU seconds on one IRIS 4D/20 processor (LINPACK about 0.9 MFLOPS).\n\n",
        if runs == 1 { "" } else { "s" },
    ));
    s.push_str(
        "The volumes, as `volray-data` source specs (`volray render SPEC` renders one, \
         `volray info SPEC` describes it):\n\n",
    );
    for r in rows {
        s.push_str(&format!(
            "- {}: `{}`\n",
            r.case.name.replace('|', "\\|"),
            r.spec
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(vec![5.0, 100.0, 1.0, 2.0, 3.0]), 3.0);
        assert!(median(vec![]).is_nan());
    }

    #[test]
    fn three_significant_digits() {
        assert_eq!(significant(149.5), "150");
        assert_eq!(significant(3.35), "3.35");
        assert_eq!(significant(0.0123456), "0.0123");
        assert_eq!(significant(0.000999), "0.000999");
        assert_eq!(significant(12345.0), "12300");
        assert_eq!(significant(1.0), "1.00");
        assert_eq!(significant(0.0), "0");
    }

    #[test]
    fn the_paper_cases() {
        let c = cases(&CaseSizes::PAPER);
        let seconds: Vec<f64> = c.iter().map(|c| c.paper_seconds).collect();
        assert_eq!(seconds, [3.35, 18.7, 16.9, 149.5]);
        let sizes: Vec<(usize, usize)> = c.iter().map(|c| (c.grid, c.window)).collect();
        assert_eq!(sizes, [(50, 120), (65, 240), (65, 240), (129, 480)]);
        assert_eq!(c[0].data, CaseData::Hydrogen { l: 2, m: 1 });
        assert_ne!(c[1].data, c[2].data);
        assert_eq!(c[3].data, CaseData::Fractal { seed: 1 });
    }

    #[test]
    fn markdown_has_a_row_per_case_with_every_number() {
        let case = cases(&CaseSizes::PAPER)[0].clone();
        let row = Measured {
            case,
            spec: "hydrogen:6,2,1,grid=50".into(),
            reference_seconds: 0.5,
            fast_seconds: 0.01,
            runs: 5,
            max_difference: 0.002,
        };
        let machine = Machine {
            cpu: "Test CPU".into(),
            logical_cpus: 2,
            threads: 2,
        };
        let md = markdown(&[row], &machine, "2025-01-02", false);
        let line = md.lines().find(|l| l.starts_with("| Probability")).unwrap();
        let cells: Vec<&str> = line.trim_matches('|').split(" | ").map(str::trim).collect();
        assert_eq!(
            cells,
            [
                "Probability density \\|ψ_621\\|²",
                "50×50×50",
                "120×120",
                "3.35",
                "0.500",
                "0.0100",
                "6.70×",
                "335×",
                "50.0×",
                "0.00200"
            ]
        );
        assert!(md.contains("2025-01-02 (UTC) on Test CPU (2 logical CPUs), 2 worker threads"));
        assert!(md.contains("median of 5 runs"));
        assert!(!md.contains("Reduced sizes"));
        assert!(md.contains("`hydrogen:6,2,1,grid=50`"));
        let one = Machine {
            threads: 1,
            ..machine
        };
        let md = markdown(&[], &one, "2025-01-02", true);
        assert!(md.contains("2 logical CPUs), 1 worker thread, "), "{md}");
        assert!(md.contains("Reduced sizes"));
    }
}
