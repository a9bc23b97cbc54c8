//! Times the light volume's sweep alone, as `volray bench --peers DIR
//! --shadows` sweeps it: on a peers' volume (its raw `float32` and JSON
//! sidecar), their opacities, the camera's key light turned 0.5° a sweep
//! (seven in turn), shadow rays a voxel apart.
//!
//! ```text
//! cargo run --release -p volray-core --example sweep_bench -- DIR/NAME.raw [SWEEPS] [THREADS]
//! ```
//!
//! It prints the median and the least of `SWEEPS` (20) sweeps on `THREADS`
//! (2) threads, after one untimed. With `SWEEP_DUMP=FILE` it writes the
//! last light volume to FILE (`f32`, x fastest), to compare two builds'.

use std::time::Instant;
use volray_core::glam::DVec3;
use volray_core::key_light;
use volray_core::shadows::light_volume::LightVolume;
use volray_core::shadows::opacities::VoxelOpacities;

fn main() -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1).map(std::path::PathBuf::from) else {
        return Err("usage: sweep_bench DIR/NAME.raw [SWEEPS] [THREADS]".into());
    };
    let sweeps: usize = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let threads: usize = args.get(3).map_or(Ok(2), |s| s.parse())?;
    let side: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path.with_extension("json"))?)?;
    let number = |key: &str| side[key].as_f64().ok_or(format!("no {key} in the sidecar"));
    let dims: Vec<usize> = (side["dims"].as_array().ok_or("no dims in the sidecar")?)
        .iter()
        .filter_map(|d| d.as_u64().map(|d| d as usize))
        .collect();
    let dims: [usize; 3] = dims.try_into().map_err(|_| "dims are not three")?;
    let (min, max) = (number("min")?, number("max")?);
    let values: Vec<f32> = (std::fs::read(&path)?.chunks_exact(4))
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    if values.len() != dims.iter().product::<usize>() {
        return Err(format!("{}: not {dims:?} float32 values", path.display()).into());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    pool.install(|| {
        // The peers' opacity per voxel: 0 to 0.95 over the middle 90 % of
        // the values, for a step of one voxel.
        let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |i, j, k| {
            let v = f64::from(values[i + dims[0] * (j + dims[1] * k)]);
            let t = (v - min) / (max - min);
            (((t - 0.05) / 0.9).clamp(0.0, 1.0) * 0.95) as f32
        });
        let light_at = |n: usize| {
            let angle = ((n % 7) as f64 * 0.5).to_radians();
            key_light(DVec3::new(-angle.cos(), -angle.sin(), 0.0), DVec3::Z)
        };
        let mut light = LightVolume::sweep(DVec3::ONE, light_at(0), &mut opacities);
        let mut times = Vec::new();
        for n in 1..=sweeps {
            let start = Instant::now();
            light.resweep(DVec3::ONE, light_at(n), &mut opacities);
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        if let Ok(out) = std::env::var("SWEEP_DUMP") {
            let [nx, ny, nz] = light.dims();
            let mut bytes = Vec::with_capacity(nx * ny * nz * 4);
            for k in 0..nz {
                for j in 0..ny {
                    for i in 0..nx {
                        bytes.extend_from_slice(&light.at([i, j, k]).to_le_bytes());
                    }
                }
            }
            std::fs::write(out, bytes)?;
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{}: {sweeps} sweeps on {threads} threads: median {:.3} ms, least {:.3}",
            path.display(),
            times[times.len() / 2],
            times[0]
        );
        Ok(())
    })
}
