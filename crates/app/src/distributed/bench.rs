//! `volray bench` under `mpirun`: per-rank times of each stage, medians
//! over the frames (each turned half a degree further, as `bench` does),
//! as a table rank 0 prints.

use super::job::{Job, Words, frame, from_volume};
use super::source::RankSource;
use crate::error::AppError;
use std::fmt::Write;
use std::time::Duration;
use volray_core::{Camera, RenderSettings};
use volray_distributed::frame::{Distributed, RankTimes};
use volray_distributed::mpi::Mpi;
use volray_distributed::transport::Transport;

/// One line of the table, written to `out`.
macro_rules! row {
    ($out:expr, $($arg:tt)*) => {
        writeln!($out, $($arg)*).expect("writing to a String")
    };
}

/// `frames` timed frames of `job`'s input (after a warm-up), split among
/// the ranks: the table of times on rank 0, `None` on the others.
pub fn bench(
    mpi: &Mpi,
    job: &Job,
    frames: usize,
    words: Words<'_>,
) -> Result<Option<String>, AppError> {
    let base = job.settings.clone();
    let source = RankSource::open(mpi, job, words)?;
    let (mode, name) = (source.non_finite, source.name.clone());
    let fail = |e| frame(&name, e);
    let (d, per_frame, walls) = {
        let start = mpi.time();
        let mut d = Distributed::read(mpi, &source, mode).map_err(fail)?;
        let base = from_volume(&d, &job.look, (&name, source.window), base.clone())?;
        let read_wall = mpi.time() - start;
        let mut per_frame: Vec<Vec<RankTimes>> = Vec::new();
        let mut walls = Vec::new();
        // One warm-up frame (classification, caches), then the timed ones.
        for frame in 0..=frames {
            let s = RenderSettings {
                camera: Camera {
                    azimuth: base.camera.azimuth + 0.5 * frame as f64,
                    ..base.camera
                },
                ..base.clone()
            };
            let start = mpi.time();
            let (_, times) = d.render(&s).map_err(fail)?;
            walls.push(mpi.time() - start);
            per_frame.push(d.gather_times(times).map_err(fail)?);
        }
        walls[0] = read_wall;
        (d, per_frame, walls)
    };
    if mpi.rank() != 0 {
        return Ok(None);
    }
    let mut out = String::new();
    print_bench(
        &mut out,
        &name,
        &base,
        &d,
        &per_frame,
        &walls,
        rayon::current_num_threads(),
    );
    Ok(Some(out))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return 0.0;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn print_bench(
    out: &mut String,
    name: &str,
    s: &RenderSettings,
    d: &Distributed<'_, Mpi>,
    per_frame: &[Vec<RankTimes>],
    walls: &[f64],
    threads: usize,
) {
    let ranks = d.decomposition().boxes.len();
    let timed = &per_frame[1..];
    row!(
        out,
        "volray bench (distributed): {name}, {}x{}, {ranks} ranks x {threads} threads, {} frames after a warm-up; medians",
        s.width,
        s.height,
        timed.len()
    );
    row!(
        out,
        "{:>4} {:>12} {:>12} {:>9} {:>9} {:>9} {:>10} {:>9} {:>11}",
        "rank",
        "owned",
        "held",
        "read ms",
        "class ms",
        "cast ms",
        "compose ms",
        "gather ms",
        "sent bytes"
    );
    for r in 0..ranks {
        let col = |f: &dyn Fn(&RankTimes) -> f64| median(timed.iter().map(|t| f(&t[r])).collect());
        let t0 = &per_frame[0][r];
        row!(
            out,
            "{:>4} {:>12} {:>12} {:>9.1} {:>9.2} {:>9.2} {:>10.2} {:>9.2} {:>11.0}",
            r,
            t0.owned_voxels,
            t0.held_voxels,
            ms(t0.read),
            col(&|t| ms(t.classify)),
            col(&|t| ms(t.cast)),
            col(&|t| ms(t.compose.composite)),
            col(&|t| ms(t.compose.gather)),
            col(&|t| t.compose.bytes_sent as f64),
        );
    }
    let compose = median(
        (timed.iter())
            .map(|t| {
                (t.iter())
                    .map(|r| ms(r.compose.composite) + ms(r.compose.gather))
                    .fold(0.0, f64::max)
            })
            .collect(),
    );
    row!(
        out,
        "frame (rank 0, wall): {:.2} ms; compositing and gather (slowest rank): {:.2} ms; read and agree: {:.1} ms",
        median(walls[1..].iter().map(|w| w * 1e3).collect()),
        compose,
        walls[0] * 1e3,
    );
}
