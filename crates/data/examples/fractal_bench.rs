//! Times fractal generation: the median wall time of several runs.
//!
//! ```text
//! cargo build --release -p volray-data --example fractal_bench
//! target/release/examples/fractal_bench 257 7            # size, runs
//! target/release/examples/fractal_bench 257 7 additions  # Voss's random additions
//! target/release/examples/fractal_bench 257 7 raw        # no post-processing
//! /usr/bin/time -v target/release/examples/fractal_bench 513 1   # peak RSS
//! ```
//!
//! Prints each run's seconds, the median and the fastest (the least
//! disturbed by other work on a shared machine), and the volume's size so
//! the peak resident memory can be compared with one copy of the data.

use std::time::Instant;

use volray_data::fractal::{FractalParams, generate};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let size: usize = args.first().map_or(257, |s| s.parse().expect("SIZE"));
    let runs: usize = args.get(1).map_or(5, |s| s.parse().expect("RUNS"));
    let flag = |name: &str| args.iter().skip(2).any(|s| s == name);
    let params = FractalParams {
        size,
        random_additions: flag("additions"),
        raw_field: flag("raw"),
        ..FractalParams::default()
    };
    let mut times = Vec::with_capacity(runs);
    let mut bytes = 0;
    for seed in 1..=runs as u64 {
        let start = Instant::now();
        let volume = generate(&FractalParams { seed, ..params }).expect("valid parameters");
        let seconds = start.elapsed().as_secs_f64();
        bytes = volume.len() * volume.sample_type().bytes();
        println!("seed {seed}: {seconds:.3} s");
        times.push(seconds);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{params}: median {:.3} s, fastest {:.3} s over {runs} runs on {} threads; data {:.1} MB",
        times[runs / 2],
        times[0],
        rayon::current_num_threads(),
        bytes as f64 / 1e6
    );
}
